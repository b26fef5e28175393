"""The explicit scheme's friction at one node: a monotone scalar equation.

In a kick, node j's friction force is -wf_j S_j g(s), s its slip velocity's estimate over
v_reg (the module notes of :mod:`beltsim.solvers.explicit`). That estimate is affine in
the node's own force, so s solves s + kappa g(s) = s_pred: s_pred the estimate without
the node's friction, kappa its slope. The laws with a closed form (linear, ramp, and the
exact laws by projection) are solved by it, the smooth ones (tanh, sqrt) by a safeguarded
Newton iteration from a warm start. Both layouts' sweeps (the open layout's in
:mod:`beltsim.solvers.explicit`, a loop's in :mod:`beltsim.solvers.explicit_loop`) call
these.
"""

from __future__ import annotations

import math

from numba import njit

from ..physics.friction import ADHESION, EXACT, LINEAR, RAMP, SQRT, TANH, law

SMALL_STEP = 1e-5  # relative Newton step below which the friction solve stops
# fast-math flags that keep NaN and inf semantics (a failing run must still show them)
SAFE_FASTMATH = {"reassoc", "contract", "arcp"}
# friction's velocity estimate (module notes): consistency needs A_EST - C_EST = 1/2
C_EST = 1.0 / 16.0
A_EST = 0.5 + C_EST
ALPHA = 0.5

# |s| beyond which tanh(s) rounds to +-1 and its slope to 0 (exp(-2 s) < 2^-54)
TANH_SATURATED = 19.0


# tanh(s) = s + s z P(z) / Q(z), z = s^2, for |s| < TANH_RATIONAL (Cephes' tanh, within
# an ulp; (1 - e) / (1 + e), e = exp(-2 |s|), cancels there: 3e-13 relative at s = 1e-4)
TANH_RATIONAL = 0.625
TANH_P = (-9.64399179425052238628e-1, -9.92877231001918586564e1, -1.61468768441708447952e3)
TANH_Q = (1.12811678491632931402e2, 2.23548839060100448583e3, 4.84406305325125486048e3)


@njit(cache=True, fastmath=SAFE_FASTMATH)
def _law(code, s):
    """friction.law, with tanh without a call to libm near s = 0 (stick, where the friction
    solves run most) and where it is saturated (exp would underflow: libm's slow path;
    1 and 0 are what it gives)."""
    if code == TANH:
        if abs(s) > TANH_SATURATED:
            return math.copysign(1.0, s), 0.0
        if abs(s) < TANH_RATIONAL:
            z = s * s
            num = (TANH_P[0] * z + TANH_P[1]) * z + TANH_P[2]
            den = ((z + TANH_Q[0]) * z + TANH_Q[1]) * z + TANH_Q[2]
            g = s + s * z * num / den
            return g, 1.0 - g * g
    return law(code, s)


@njit(cache=True, inline="always")
def _closed_form(code, s_pred, kappa):
    """Solve s + kappa g(s) = s_pred for the laws with a closed form (linear, exact,
    ramp); returns (s, g(s)) (for an exact law, g(s) in its set)."""
    if code == LINEAR:
        s = s_pred / (1.0 + kappa)
        return s, s
    # the exact laws, by projection: the node sticks (s = 0) if its ratio s_pred / kappa
    # can hold it (always for adhesion), else slides with the ratio on the bound
    if code == ADHESION or (code == EXACT and abs(s_pred) <= kappa):
        return 0.0, s_pred / kappa
    if code == RAMP and abs(s_pred) <= 1.0 + kappa:
        s = s_pred / (1.0 + kappa)
        return s, s
    return (s_pred - kappa, 1.0) if s_pred > 0 else (s_pred + kappa, -1.0)


@njit(cache=True)
def _friction_scalar(code, s_pred, kappa, s0):
    """Solve s + kappa g(s) = s_pred; returns (s, g(s)) (for an exact law, g(s) in its set).

    The laws with a closed form by it, the smooth ones by _newton from s0.
    """
    if code != TANH and code != SQRT:
        return _closed_form(code, s_pred, kappa)
    g0, gp0 = _law(code, s0)
    return _newton(code, s_pred, kappa, s0, g0, gp0)


@njit(cache=True, fastmath=SAFE_FASTMATH)
def _newton(code, s_pred, kappa, s0, g0, gp0):
    """Solve s + kappa g(s) = s_pred for a smooth law; g0, gp0: g, g' at s0.

    g is odd, increasing and |g| <= 1, so the root lies in [s_pred - kappa, s_pred +
    kappa]. Newton from s0 (the node's value at the previous step, so one or two
    iterations in a settled state), safeguarded by bisection. A sliding node's root lies
    at the edge of that interval, to round-off: s0 is clamped into it, not replaced, and
    a converged step may end on the edge (strict bounds sent a third of the steps of
    sliding nodes to bisection, 10-20 iterations).
    """
    lo, hi = s_pred - kappa, s_pred + kappa
    s = min(max(s0, lo), hi)
    g, gp = (g0, gp0) if s == s0 else _law(code, s)
    tol = 1e-13 * (abs(s_pred) + kappa)
    edge = 1e-15 * (abs(s_pred) + kappa)  # round-off of lo and hi
    last_step = hi - lo
    for _ in range(100):
        r = s + kappa * g - s_pred
        ds = -r / (1.0 + kappa * gp)
        if abs(ds) <= SMALL_STEP * (1.0 + abs(s)) and lo - edge <= s + ds <= hi + edge:
            # g linearised over the step: error g'' ds^2 / 2 < 1e-10, and none at a
            # fixed point; in a settled run this is the first iteration (ds ~ 1e-7)
            ds = min(max(s + ds, lo), hi) - s
            return s + ds, g + gp * ds
        if abs(r) <= tol:
            return s, g
        if r > 0.0:
            hi = s
        else:
            lo = s
        # bisection when Newton leaves the bracket or stops halving its steps (it can
        # cycle across the inflection at s = 0 when it starts far out)
        if not (lo < s + ds < hi) or abs(ds) > 0.5 * last_step:
            ds = 0.5 * (lo + hi) - s
        last_step = abs(ds)
        s += ds
        g, gp = _law(code, s)
    return s, g


@njit(cache=True, fastmath=SAFE_FASTMATH, inline="always")
def _warm_start(code, s, kappa):
    """(g, g', 1 / (1 + kappa g'), gc, gs) at a node's warm start s: the law, its slope
    and the response to s_pred predicted from it, g ~ gc + gs s_pred: for a smooth law
    the first Newton iteration of _friction_scalar (written out), for the others the
    closed form in the warm start's regime (stick or slide, linear part or bound)."""
    if code == TANH or code == SQRT:
        g, gp = _law(code, s)
    else:
        bound = 1.0 if code == RAMP else 0.0
        if code == LINEAR or (code == RAMP and abs(s) <= bound):
            return 0.0, 0.0, 0.0, 0.0, 1.0 / (1.0 + kappa)
        if code == ADHESION or (code == EXACT and s == 0.0):
            return 0.0, 0.0, 0.0, 0.0, 1.0 / kappa
        return 0.0, 0.0, 0.0, math.copysign(1.0, s), 0.0
    inv = 1.0 / (1.0 + kappa * gp)
    gs = gp * inv
    return g, gp, inv, g - gs * (s + kappa * g), gs


@njit(cache=True, fastmath=SAFE_FASTMATH, inline="always")
def _predicted(code, s_pred, kappa, s0, g0, gp, inv):
    """(ok, s, g): the root of s + kappa g(s) = s_pred if the warm start's prediction
    (_warm_start) holds, else ok is False. For a smooth law: the first Newton iteration
    from s0 when it converges (most node-steps), for the others: the closed form when
    the node stays in its regime."""
    if code == TANH or code == SQRT:
        ds = (s_pred - s0 - kappa * g0) * inv
        edge = 1e-15 * (abs(s_pred) + kappa)  # round-off of the bracket's ends
        if (abs(s0 - s_pred) <= kappa and abs(ds) <= SMALL_STEP * (1.0 + abs(s0))
                and abs(s0 + ds - s_pred) <= kappa + edge):
            ds = min(max(s0 + ds, s_pred - kappa), s_pred + kappa) - s0
            return True, s0 + ds, g0 + gp * ds
        return False, 0.0, 0.0
    s, g = _closed_form(code, s_pred, kappa)
    if code == LINEAR or code == ADHESION:
        return True, s, g
    bound = 1.0 if code == RAMP else 0.0
    same = (abs(s) <= bound) == (abs(s0) <= bound) and (abs(s) <= bound or s * s0 > 0.0)
    return same, s, g
