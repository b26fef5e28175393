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


def _frame(P: DriveParams):
    """The loop's bounds, radii and arcs: the two-pulley drive's closed-form
    :class:`~beltsim.beltdrive.geometry.Geometry`, which its other solutions and figures
    share (the layout's agrees with it to round-off), else the layout's."""
    return P.geometry if P.two_pulley else P.layout


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
    """A piece [p, q] of the loop: "stick", "slip" or "span", on arc ``arc`` (-1: a
    span)."""

    p: float
    q: float
    kind: str
    arc: int
    k: float  # theta's decay rate: alpha in stick, beta elsewhere
    lam: float = 0.0  # slip: n = N - rho c^2 grows as exp(lam t)
    g: float = 0.0  # slip: theta'' - beta^2 theta = g n
    sign: float = 0.0  # slip: the sign of f
    lever: float = 0.0  # arcs: the friction's signed lever, l times the pulley's side

    @property
    def length(self) -> float:
        """q - p (m)."""
        return self.q - self.p


class _Loop:
    """The pieces and the unknowns' layout at belt speed c and signed slip arcs d (None:
    adhesion).

    Arc i (pulley i of ``P.layout``, in the belt's order) is a stick piece, a slip piece
    of length abs(d[i]) at its exit where f = sign(d[i]) mu_i p (Coulomb only) and the
    span to pulley i + 1. A back-side pulley (side -1) touches the belt's other face:
    the friction's lever about the middle line is -l there, in the moment (l f), the
    bottom fibre's speed (l theta') and so in every piece's solution; alpha, which sees
    l^2, is the same on every arc.

    Unknowns z: theta's (P, Q) of piece i at 2i, 2i + 1; then the strain at the start of
    each slip and span piece (``ia``); then each arc's e_i (``ie``); with adhesion, each
    exit's F_i (``iF``). A form is a row r of n + 1 numbers, the value r[:n] @ z + r[n].
    """

    def __init__(self, P: DriveParams, lever: float, c: float, d=None):
        lay = P.layout
        self.P, self.l, self.c = P, lever, c
        frame = _frame(P)
        self.bounds, self.radii = frame.bounds, np.asarray(frame.radii)
        self.arcs, self.loop_length = np.asarray(frame.arcs), frame.loop_length
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
        e, n_arcs = self.bounds, len(lay)
        segs = []
        for arc in range(n_arcs):
            p, q, R = e[2 * arc], e[2 * arc + 1], self.radii[arc]
            lv = lever * float(lay.sides[arc])
            s = q - abs(d[arc]) if self.coulomb else q
            segs.append(_Seg(p, s, "stick", arc, self.alpha, lever=lv))
            if self.coulomb:
                # the sign of a zero-length slip piece is immaterial: its (P, Q) absorb it
                sign = 1.0 if d[arc] > 0 else -1.0
                mu = P.mus[arc]
                segs.append(_Seg(s, q, "slip", arc, self.beta,
                                 lam=-sign * mu * P.b1 / (self.B * R),
                                 g=-lv * sign * mu / (self.A * R), sign=sign, lever=lv))
            segs.append(_Seg(q, e[2 * arc + 2], "span", -1, self.beta))
        self.segs = segs
        n = 2 * len(segs)
        self.ia = {}
        for i, seg in enumerate(segs):
            if seg.kind != "stick":
                self.ia[i] = n
                n += 1
        self.ie = tuple(range(n, n + n_arcs))
        n += n_arcs
        self.iF = tuple(range(n, n + n_arcs)) if not self.coulomb else None
        self.n = n + (n_arcs if not self.coulomb else 0)

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
            out = -seg.lever * self.theta(i, t, 1)
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
            out = -seg.lever * (self.theta(i, t) - self.theta(i, 0.0))
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
            return self.B * seg.lever * self.alpha**2 * self.theta(i, t)
        if seg.kind == "slip":
            n = self.P.b1 * self.eps(i, t)
            n[:, -1] += self.P.N0 - self.rc
            return seg.sign * self.P.mus[seg.arc] / self.radii[seg.arc] * n
        return self._zero(t)

    def pressure(self, i, t):
        """The contact pressure (N - rho c^2) / R on arc piece i at local t."""
        R = self.radii[self.segs[i].arc]
        out = self.P.b1 / R * self.eps(i, t)
        out[:, -1] += (self.P.N0 - self.rc) / R
        return out

    def fibre_speed(self, i, t, lever=None):
        """The contact fibre's speed c (1 + N0/b1 + eps + l_i theta') on piece i at t,
        l_i the arc's signed lever (``lever``: another's, e.g. for the fibre that left an
        arc, on the span after it)."""
        lever = self.segs[i].lever if lever is None else lever
        out = self.c * (self.eps(i, t) + lever * self.theta(i, t, 1))
        out[:, -1] += self.c * (1.0 + self.P.N0 / self.P.b1)
        return out

    def arc_force(self, arc):
        """The friction's resultant on ``arc`` (N) as a form: -B times the strain's rise
        over its pieces, and with adhesion its exit's concentrated force."""
        out = self._zero([0.0])[0]
        for i, seg in enumerate(self.segs):
            if seg.arc == arc:
                out -= self.B * (self.eps(i, seg.length)[0] - self.eps(i, 0.0)[0])
        if not self.coulomb:
            out[self.iF[arc]] += 1.0
        return out

    # conditions --------------------------------------------------------------------
    def conditions(self, omega_d, loads):
        """All conditions as forms (rows) and the indices of the closing residuals among
        them (Coulomb: the closure, the length and each non-driver pulley's balance;
        adhesion: the closure), with each row's scale (N).

        ``omega_d`` is the driver's speed, ``loads`` each pulley's load torque M_i (N m;
        0 at idlers, the driver's entry ignored)."""
        P, segs, b1 = self.P, self.segs, self.P.b1
        drv = P.driver
        rows, scales = [], []
        for i, seg in enumerate(segs):
            j = (i + 1) % len(segs)
            L = seg.length
            th = self.theta(j, 0.0) - self.theta(i, L)
            dth = self.theta(j, 0.0, 1) - self.theta(i, L, 1)
            ep = self.eps(j, 0.0) - self.eps(i, L)
            if not self.coulomb and seg.kind == "stick":  # an arc's exit
                dth[0, self.iF[seg.arc]] += seg.lever / self.A
                ep[0, self.iF[seg.arc]] += 1.0 / self.B
            rows += [th[0], dth[0], ep[0]]
            scales += [1.0, 1.0, b1]
        closure = len(rows) - 1  # the strain's continuity at x = Lambda = 0
        rows.append(sum(self.int_eps(i, seg.length)[0] for i, seg in enumerate(segs)))
        scales.append(b1 / self.loop_length)
        residual = [closure, len(rows) - 1]
        for arc in range(len(self.radii)):
            if arc != drv:  # the friction's resultant takes the load: R_i F_i = -M_i
                balance = self.arc_force(arc)
                balance[-1] += loads[arc] / self.radii[arc]
                residual.append(len(rows))
                rows.append(balance)
                scales.append(1.0)
        pin = self._zero([0.0])[0]
        pin[self.ie[drv]] = 1.0
        pin[-1] = -(omega_d * self.radii[drv] / self.c - 1.0 - P.N0 / b1)
        rows.append(pin)
        scales.append(b1)
        return np.array(rows), np.array(scales), residual if self.coulomb else [closure]

    def solve(self, omega_d, loads):
        """The constants z and the closing residuals (N) at this c and these slip arcs."""
        rows, scales, res = self.conditions(omega_d, loads)
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


def _signs(P: DriveParams, loads) -> np.ndarray:
    """Each arc's slip sign: +1 on the driver (f drives the belt), -1 on a loaded pulley
    (f brakes it), 0 where the sign is itself unknown: an unloaded pulley of a drive on
    more than two pulleys (an idler). Its stick zone's friction B l_i theta'' has a
    resultant of either sign, which the slip arc balances; its slip variable is signed
    and passes through 0 (a slip arc of length 0, whose sign is immaterial)."""
    out = np.where(np.asarray(loads, dtype=float) > 0, -1.0, 0.0)
    if P.two_pulley:  # the two-pulley drive's driven pulley slips backwards, even unloaded
        out[:] = -1.0
    out[P.driver] = 1.0
    return out


def _unpack(P, mode, y, loads):
    """(c, signed slip arcs d, loads) of the iterated unknowns y in ``mode``: "stick"
    (y = c), "load" (y = c and mu_i d_i / R_i per pulley), or the two-pulley drive's
    capacity modes "cap1" and "cap2" (a slip arc over its whole wrap, the load
    M2 = y[1 + k] R2 N0 unknown in its place)."""
    if mode == "stick":
        return y[0], None, loads
    frame = _frame(P)
    mus = np.asarray(P.mus, dtype=float)
    sg = _signs(P, loads)
    d = np.where(sg == 0, 1.0, sg) * np.asarray(y[1:]) * frame.radii / mus
    if mode == "load":
        return y[0], d, loads
    k = 0 if mode == "cap1" else 1  # the two-pulley drive's driver sliding, or its driven
    d[k] = sg[k] * frame.arcs[k]
    return y[0], d, (0.0, y[1 + k] * frame.radii[1] * P.N0)


def _newton(P, lever, omega1, loads, mode, y0):
    """Damped Newton on the closing residuals with a central-difference Jacobian; the
    unknowns other than c (slip-arc variables, a load) are kept >= 0 but for the signed
    slip variables of idlers (:func:`_signs`).

    Converged when the scaled step falls below STEP_TOL, or below FLOOR_STEP where no
    step lowers the residual any more (its round-off floor, which the exponentials'
    range raises when the slack side's pressure nearly vanishes). Returns (loop, z, y).
    """
    y = np.array(y0, dtype=float)
    scale = np.array([y[0]] + [1.0] * (len(y) - 1))
    keep = np.ones(len(y), bool)
    keep[0] = False
    if mode == "load":
        keep[1:] = _signs(P, loads) != 0

    def evaluate(y):
        c, d, m = _unpack(P, mode, y, loads)
        try:
            with np.errstate(all="ignore"):
                loop = _Loop(P, lever, c, d)
                z, r = loop.solve(omega1, m)
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
            trial[keep] = np.maximum(trial[keep], 0.0)
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


def _converge(P, omega1, loads, mode, y0):
    """Newton at the full lever, falling back on a continuation in the lever from the
    string (lever 0), where y0 is exact."""
    lever = P.lever
    try:
        return _newton(P, lever, omega1, loads, mode, y0)
    except _NotConverged:
        if lever == 0.0:
            raise
    t, dt, y = 0.0, 0.25, np.array(y0, dtype=float)
    while t < 1.0:
        dt = min(dt, 1.0 - t)
        try:
            loop, z, y_new = _newton(P, (t + dt) * lever, omega1, loads, mode, y)
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
