"""The closed drive's beam, piece by piece: the exact solution on each piece of the loop
(span, stick, slip) and the damped Newton iteration that closes it.

The equations, the pieces and how the problem closes are described in
:mod:`beltsim.beltdrive.beam`, which finds the steady state from its starts; the solution
it returns is :class:`beltsim.beltdrive.beam_solution.BeamSolution`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import NoSolutionError
from .params import DriveParams

#: Newton stops when its scaled step falls below this ...
STEP_TOL = 1e-13
#: ... or below this where no step lowers the residual (its round-off floor).
FLOOR_STEP = 1e-7
#: Newton iterations at most (a start from the string converges in a handful) ...
MAX_ITERATIONS = 30
#: ... and damped steps (below 1/8 of Newton's) in a row before it gives up.
MAX_DAMPED = 4
#: Gauss-Legendre points on each piece of the graded quadrature.
_GAUSS = np.polynomial.legendre.leggauss(16)


class _NotConverged(Exception):
    """Newton did not converge from this start (internal: the caller tries another)."""


def _expm1_ratio(z):
    """E(z) = (exp(z) - 1) / z, with E(0) = 1, accurate for small abs(z)."""
    z = np.asarray(z, dtype=float)
    small = np.abs(z) < 1e-3
    zs = np.where(small, 1.0, z)
    with np.errstate(over="ignore"):
        big = np.expm1(zs) / zs
    return np.where(small, 1.0 + z / 2 * (1.0 + z / 3 * (1.0 + z / 4 * (1.0 + z / 5))), big)


def _psi(lam, beta, L, t, der):
    """The slip arc's particular solution psi (der 0) or psi' (der 1) at t in [0, L]."""
    if lam > 0:
        w = L - t
        E = _expm1_ratio((lam - beta) * w)
        ex = np.exp(lam * t)
        if der == 0:
            return -ex * w * E / (lam + beta)
        return ex * (1.0 - beta * w * E) / (lam + beta)
    E = _expm1_ratio(-(lam + beta) * t)
    ex = np.exp(lam * t)
    if der == 0:
        return ex * t * E / (lam - beta)
    return ex * (1.0 - beta * t * E) / (lam - beta)


@dataclass(frozen=True)
class _Seg:
    """A piece [p, q] of the loop: "stick", "slip" or "span", on arc 0, 1 or none (-1)."""

    p: float
    q: float
    kind: str
    arc: int
    k: float  # theta's decay rate: alpha in stick, beta elsewhere
    lam: float = 0.0  # slip: n = N - rho c^2 grows as exp(lam t)
    g: float = 0.0  # slip: theta'' - beta^2 theta = g n
    sign: float = 0.0  # slip: the sign of f

    @property
    def length(self) -> float:
        """q - p (m)."""
        return self.q - self.p


class _Loop:
    """The pieces and the unknowns' layout at belt speed c and slip arcs d (None: adhesion).

    Unknowns z: theta's (P, Q) of piece i at 2i, 2i + 1; then the strain at the start of
    each slip and span piece (``ia``); then e_1, e_2 (``ie``); with adhesion, F_1, F_2
    (``iF``). A form is a row r of n + 1 numbers, the value r[:n] @ z + r[n].
    """

    def __init__(self, P: DriveParams, lever: float, c: float, d=None):
        g = P.geometry
        self.P, self.l, self.c = P, lever, c
        self.rc = P.rho * c * c
        self.B = P.b1 - self.rc
        self.A = P.a - P.I * c * c
        if not self.B > 0:
            raise NoSolutionError(f"drive.driver_speed: the belt speed {c:.6g} m/s reaches "
                                  f"the critical speed sqrt(b1 / rho)")
        if not self.A > 0 and lever > 0:  # solve_beam refuses such drives up front
            raise NoSolutionError(f"drive.driver_speed: a - I c^2 <= 0 at the belt speed "
                                  f"{c:.6g} m/s")
        # without a lever theta is not forced and vanishes: any decay rate serves
        A = self.A if self.A > 0 else P.a
        self.beta = math.sqrt(P.b2 / A)
        self.alpha = math.sqrt(P.b2 / (A + lever * lever * self.B))
        self.coulomb = d is not None
        e = g.bounds
        segs = []
        for arc in (0, 1):
            p, q, R = e[2 * arc], e[2 * arc + 1], g.radii[arc]
            s = q - d[arc] if self.coulomb else q
            segs.append(_Seg(p, s, "stick", arc, self.alpha))
            if self.coulomb:
                sign = 1.0 if arc == 0 else -1.0
                segs.append(_Seg(s, q, "slip", arc, self.beta,
                                 lam=-sign * P.mu * P.b1 / (self.B * R),
                                 g=-lever * sign * P.mu / (self.A * R), sign=sign))
            segs.append(_Seg(q, e[2 * arc + 2], "span", -1, self.beta))
        self.segs = segs
        n = 2 * len(segs)
        self.ia = {}
        for i, seg in enumerate(segs):
            if seg.kind != "stick":
                self.ia[i] = n
                n += 1
        self.ie = (n, n + 1)
        n += 2
        self.iF = (n, n + 1) if not self.coulomb else None
        self.n = n + (2 if not self.coulomb else 0)

    # forms -------------------------------------------------------------------------
    def _zero(self, t):
        return np.zeros((len(t), self.n + 1))

    def theta(self, i, t, der=0):
        """theta (der 0) or theta' (der 1) on piece i at local t (array)."""
        seg = self.segs[i]
        t = np.atleast_1d(np.asarray(t, dtype=float))
        out = self._zero(t)
        e1, e2 = np.exp(-seg.k * t), np.exp(-seg.k * (seg.length - t))
        out[:, 2 * i], out[:, 2 * i + 1] = (e1, e2) if der == 0 else (-seg.k * e1, seg.k * e2)
        if seg.kind == "slip":
            psi = seg.g * _psi(seg.lam, seg.k, seg.length, t, der)
            out[:, self.ia[i]] += self.P.b1 * psi  # n(p) = b1 eps(p) + N0 - rho c^2
            out[:, -1] += (self.P.N0 - self.rc) * psi
        return out

    def eps(self, i, t):
        """The strain eps on piece i at local t."""
        seg = self.segs[i]
        t = np.atleast_1d(np.asarray(t, dtype=float))
        out = self._zero(t)
        if seg.kind == "stick":
            out = -self.l * self.theta(i, t, 1)
            out[:, self.ie[seg.arc]] += 1.0
        elif seg.kind == "slip":
            out[:, self.ia[i]] = np.exp(seg.lam * t)
            out[:, -1] = (self.P.N0 - self.rc) * np.expm1(seg.lam * t) / self.P.b1
        else:
            out[:, self.ia[i]] = 1.0
        return out

    def int_eps(self, i, t):
        """The integral of eps over [0, t] of piece i."""
        seg = self.segs[i]
        t = np.atleast_1d(np.asarray(t, dtype=float))
        out = self._zero(t)
        if seg.kind == "stick":
            out = -self.l * (self.theta(i, t) - self.theta(i, 0.0))
            out[:, self.ie[seg.arc]] += t
        elif seg.kind == "slip":
            tE = t * _expm1_ratio(seg.lam * t)
            out[:, self.ia[i]] = tE
            out[:, -1] = (self.P.N0 - self.rc) * (tE - t) / self.P.b1
        else:
            out[:, self.ia[i]] = t
        return out

    def friction(self, i, t):
        """The distributed friction f on piece i at local t."""
        seg = self.segs[i]
        t = np.atleast_1d(np.asarray(t, dtype=float))
        if seg.kind == "stick":
            return self.B * self.l * self.alpha**2 * self.theta(i, t)
        if seg.kind == "slip":
            R = self.P.geometry.radii[seg.arc]
            n = self.P.b1 * self.eps(i, t)
            n[:, -1] += self.P.N0 - self.rc
            return seg.sign * self.P.mu / R * n
        return self._zero(t)

    def pressure(self, i, t):
        """The contact pressure (N - rho c^2) / R on arc piece i at local t."""
        R = self.P.geometry.radii[self.segs[i].arc]
        out = self.P.b1 / R * self.eps(i, t)
        out[:, -1] += (self.P.N0 - self.rc) / R
        return out

    def fibre_speed(self, i, t):
        """The bottom fibre's speed c (1 + N0/b1 + eps + l theta') on piece i at t."""
        out = self.c * (self.eps(i, t) + self.l * self.theta(i, t, 1))
        out[:, -1] += self.c * (1.0 + self.P.N0 / self.P.b1)
        return out

    # conditions --------------------------------------------------------------------
    def conditions(self, omega1, M2):
        """All conditions as forms (rows) and the indices of the three (Coulomb) or one
        (adhesion) closing residual among them, with each row's scale (N)."""
        P, segs, b1 = self.P, self.segs, self.P.b1
        R1, R2 = P.geometry.radii
        rows, scales = [], []
        for i, seg in enumerate(segs):
            j = (i + 1) % len(segs)
            L = seg.length
            th = self.theta(j, 0.0) - self.theta(i, L)
            dth = self.theta(j, 0.0, 1) - self.theta(i, L, 1)
            ep = self.eps(j, 0.0) - self.eps(i, L)
            if not self.coulomb and seg.kind == "stick":  # an arc's exit
                dth[0, self.iF[seg.arc]] += self.l / self.A
                ep[0, self.iF[seg.arc]] += 1.0 / self.B
            rows += [th[0], dth[0], ep[0]]
            scales += [1.0, 1.0, b1]
        closure = len(rows) - 1  # the strain's continuity at x = Lambda = 0
        length = sum(self.int_eps(i, seg.length)[0] for i, seg in enumerate(segs))
        balance = self._zero([0.0])[0]
        for i, seg in enumerate(segs):
            if seg.arc == 1:
                balance -= self.B * (self.eps(i, seg.length)[0] - self.eps(i, 0.0)[0])
        if not self.coulomb:
            balance[self.iF[1]] += 1.0
        balance[-1] += M2 / R2
        pin = self._zero([0.0])[0]
        pin[self.ie[0]] = 1.0
        pin[-1] = -(omega1 * R1 / self.c - 1.0 - P.N0 / b1)
        rows += [length, balance, pin]
        scales += [b1 / P.geometry.loop_length, 1.0, b1]
        residual = [closure, len(rows) - 3, len(rows) - 2] if self.coulomb else [closure]
        return np.array(rows), np.array(scales), residual

    def solve(self, omega1, M2):
        """The constants z and the closing residuals (N) at this c and these slip arcs."""
        rows, scales, res = self.conditions(omega1, M2)
        inner = np.setdiff1d(np.arange(len(rows)), res)
        M = rows[inner, :-1]
        b = -rows[inner, -1]
        rs = np.max(np.abs(M), axis=1)
        rs[rs == 0] = 1.0
        M, b = M / rs[:, None], b / rs
        cs = np.max(np.abs(M), axis=0)
        cs[cs == 0] = 1.0
        z = np.linalg.solve(M / cs, b) / cs
        zz = np.append(z, 1.0)
        return z, (rows[res] @ zz) * scales[res]


# --------------------------------------------------------------------------------------
# Newton on the nonlinear unknowns


def _unpack(P, mode, y):
    """(c, d, M2 or None) of the iterated unknowns y in ``mode``."""
    g = P.geometry
    R1, R2 = g.radii
    arcs = g.arcs
    if mode == "stick":
        return y[0], None, None
    if mode == "load":
        return y[0], (y[1] * R1 / P.mu, y[2] * R2 / P.mu), None
    if mode == "cap1":  # the driver slides on its whole wrap; the load is unknown
        return y[0], (arcs[0], y[2] * R2 / P.mu), y[1] * R2 * P.N0
    return y[0], (y[1] * R1 / P.mu, arcs[1]), y[2] * R2 * P.N0


def _newton(P, lever, omega1, M2, mode, y0):
    """Damped Newton on the closing residuals with a central-difference Jacobian; the
    unknowns other than c (slip-arc variables, a load) are kept >= 0.

    Converged when the scaled step falls below STEP_TOL, or below FLOOR_STEP where no
    step lowers the residual any more (its round-off floor, which the exponentials'
    range raises when the slack side's pressure nearly vanishes). Returns (loop, z, y).
    """
    y = np.array(y0, dtype=float)
    scale = np.array([y[0]] + [1.0] * (len(y) - 1))

    def evaluate(y):
        c, d, m2 = _unpack(P, mode, y)
        try:
            with np.errstate(all="ignore"):
                loop = _Loop(P, lever, c, d)
                z, r = loop.solve(omega1, M2 if m2 is None else m2)
        except (NoSolutionError, np.linalg.LinAlgError):
            return None
        r = r / P.N0
        return (loop, z, r) if np.all(np.isfinite(r)) and np.all(np.isfinite(z)) else None

    current = evaluate(y)
    if current is None:
        raise _NotConverged("no state at the start")
    damped = 0
    for _ in range(MAX_ITERATIONS):
        r = current[2]
        J = np.empty((len(r), len(y)))
        for j in range(len(y)):
            h = 1e-6 * scale[j]
            yp, ym = y.copy(), y.copy()
            yp[j] += h
            ym[j] -= h
            ep, em = evaluate(yp), evaluate(ym)
            if ep is None or em is None:
                raise _NotConverged("no state near the iterate")
            J[:, j] = (ep[2] - em[2]) / (2 * h)
        try:
            dy = np.linalg.solve(J, -r)
        except np.linalg.LinAlgError:
            raise _NotConverged("singular Jacobian") from None
        n0, step, new = float(np.linalg.norm(r)), 1.0, None
        while step >= 1e-4:
            trial = y + step * dy
            trial[1:] = np.maximum(trial[1:], 0.0)
            new = evaluate(trial)
            if new is not None and float(np.linalg.norm(new[2])) < (1 - 1e-4 * step) * n0:
                break
            new = None
            step /= 2
        size = float(np.max(np.abs(dy) / scale))
        if new is None:
            if size < FLOOR_STEP and n0 < 1e-6:
                return current[0], current[1], y
            raise _NotConverged("no step lowers the residual")
        size = float(np.max(np.abs(trial - y) / scale))
        y, current = trial, new
        if size < STEP_TOL:
            return current[0], current[1], y
        damped = damped + 1 if step < 0.125 else 0
        if damped >= MAX_DAMPED:
            raise _NotConverged("Newton stalls on damped steps")
    raise _NotConverged(f"no convergence in {MAX_ITERATIONS} iterations")


def _converge(P, omega1, M2, mode, y0):
    """Newton at the full lever, falling back on a continuation in the lever from the
    string (lever 0), where y0 is exact."""
    lever = P.lever
    try:
        return _newton(P, lever, omega1, M2, mode, y0)
    except _NotConverged:
        if lever == 0.0:
            raise
    t, dt, y = 0.0, 0.25, np.array(y0, dtype=float)
    while t < 1.0:
        dt = min(dt, 1.0 - t)
        try:
            loop, z, y_new = _newton(P, (t + dt) * lever, omega1, M2, mode, y)
        except _NotConverged:
            dt /= 2
            if dt < 1.0 / 16:
                raise
            continue
        t, y, dt = t + dt, y_new, 2 * dt
    return loop, z, y


def _graded(seg: _Seg):
    """Gauss nodes t and weights on [0, L] of a piece, on sub-intervals that grow
    geometrically from both ends (theta's boundary layers decay as exp(-k t))."""
    L = seg.length
    if L <= 0:
        return np.zeros(0), np.zeros(0)
    marks = [0.0]
    step = 0.25 / seg.k
    while step < 0.5 * L:
        marks.append(step)
        step *= 2
    marks = np.array(marks)
    br = np.unique(np.concatenate([marks, [0.5 * L], L - marks]))
    xg, wg = _GAUSS
    a, b = br[:-1, None], br[1:, None]
    t = (0.5 * (b - a) * xg + 0.5 * (a + b)).ravel()
    w = (0.5 * (b - a) * wg).ravel()
    return t, w
