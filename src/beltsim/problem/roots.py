"""Brent's root finder on a bracket: scipy.optimize.brentq's algorithm, step for step.

scipy.optimize takes 0.3 to 0.5 s to import (it brings scipy.linalg, scipy.sparse and the
parsing of its docstrings), more than the whole solve of a straight belt's steady state,
which needs nothing from it but this one function. This is a line-for-line port of
scipy's C code (``scipy/optimize/Zeros/brentq.c``, by Charles Harris): the same
iterates, so the same root to the last bit and the same number of calls of ``f``
(tests/test_roots.py checks both against scipy on the analytic solutions' residuals).
"""

from __future__ import annotations

import math

#: scipy's smallest rtol: 4 machine epsilons
RTOL = 4 * 2.220446049250313e-16


def brentq(f, a, b, args=(), xtol=2e-12, rtol=RTOL, maxiter=100, full_output=False):
    """A root of ``f`` in [a, b], where f(a) and f(b) differ in sign.

    Parameters and results as scipy.optimize.brentq's: the root x0 is within
    ``xtol + rtol * abs(x0)`` of a true root of the float function.

    Returns
    -------
    float, or (float, int, int) with full_output
        The root; with its iterations and calls of ``f``.

    Raises
    ------
    ValueError
        f(a) and f(b) have the same sign, ``f`` returns NaN, or a tolerance is too small.
    RuntimeError
        No convergence in ``maxiter`` iterations.
    """
    if not isinstance(args, tuple):
        args = (args,)
    if xtol <= 0:
        raise ValueError(f"xtol too small ({xtol:g} <= 0)")
    if rtol < RTOL:
        raise ValueError(f"rtol too small ({rtol:g} < {RTOL:g})")

    def call(x):
        fx = float(f(x, *args))
        if math.isnan(fx):
            raise ValueError(f"the function value at x={x} is NaN; solver cannot continue.")
        return fx

    xpre, xcur = float(a), float(b)
    xblk = fblk = spre = scur = 0.0
    fpre, fcur = call(xpre), call(xcur)
    calls, iterations = 2, 0

    def done(x):
        return (x, iterations, calls) if full_output else x

    if fpre == 0.0:
        return done(xpre)
    if fcur == 0.0:
        return done(xcur)
    if math.copysign(1.0, fpre) == math.copysign(1.0, fcur):
        raise ValueError("f(a) and f(b) must have different signs")
    for _ in range(maxiter):
        iterations += 1
        if fpre != 0.0 and fcur != 0.0 and (
                math.copysign(1.0, fpre) != math.copysign(1.0, fcur)):
            xblk, fblk = xpre, fpre
            spre = scur = xcur - xpre
        if abs(fblk) < abs(fcur):
            xpre, xcur, xblk = xcur, xblk, xcur
            fpre, fcur, fblk = fcur, fblk, fcur
        delta = (xtol + rtol * abs(xcur)) / 2
        sbis = (xblk - xcur) / 2
        if fcur == 0.0 or abs(sbis) < delta:
            return done(xcur)
        if abs(spre) > delta and abs(fcur) < abs(fpre):
            if xpre == xblk:  # interpolate
                stry = -fcur * (xcur - xpre) / (fcur - fpre)
            else:  # extrapolate
                dpre = (fpre - fcur) / (xpre - xcur)
                dblk = (fblk - fcur) / (xblk - xcur)
                stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
            if 2 * abs(stry) < min(abs(spre), 3 * abs(sbis) - delta):  # good short step
                spre, scur = scur, stry
            else:  # bisect
                spre = scur = sbis
        else:  # bisect
            spre = scur = sbis
        xpre, fpre = xcur, fcur
        xcur += scur if abs(scur) > delta else (delta if sbis > 0 else -delta)
        fcur = call(xcur)
        calls += 1
    raise RuntimeError(f"brentq: failed to converge after {maxiter} iterations, "
                       f"value is {xcur}")
