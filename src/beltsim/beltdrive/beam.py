"""Steady state of the closed drive: the shear-deformable beam, solved exactly.

The loop x in [0, Lambda) runs driver arc, slack span, driven arc, tight span. At steady
state, with B = b1 - rho c^2, A = a - I c^2 and the friction's lever l (h/2 for the beam,
0 for the string)::

    B eps' + f = 0,     A theta'' - b2 theta + l f = 0,     N = N0 + b1 eps.

On arc i (rim speed omega_i R_i) the bottom fibre slides at
v_rel = c (1 + N0/b1 + eps + l theta') - omega_i R_i against the contact pressure
p = (N - rho c^2) / R_i. Each arc sticks from its entry to s_i and slides from s_i to its
exit with f = s_i mu p (s_1 = +1 on the driver, s_2 = -1 on the driven pulley). Per piece:

* span: f = 0, eps constant, theta'' = beta^2 theta with beta^2 = b2 / A;
* stick: v_rel = 0 gives eps = e_i - l theta' (e_i = omega_i R_i / c - 1 - N0/b1), so
  f = B l theta'' and theta'' = alpha^2 theta, alpha^2 = b2 / (A + l^2 B);
* slip: n = N - rho c^2 obeys n' = lam n with lam = -s_i mu b1 / (B R_i), and
  theta'' - beta^2 theta = g n with g = -l s_i mu / (A R_i).

On a piece [p, q] of length L, theta = P e^{-k t} + Q e^{-k (L - t)} (+ g n(p) psi(t) on a
slip arc), t = x - p: both exponentials stay bounded however long the piece. psi solves
psi'' - beta^2 psi = e^{lam t} and is anchored where the forcing resonates (psi(L) = 0 when
lam > 0, psi(0) = 0 when lam < 0), which with E(z) = (e^z - 1)/z reads

    lam > 0:  psi = -e^{lam t} (L - t) E((lam - beta)(L - t)) / (lam + beta)
    lam < 0:  psi =  e^{lam t} t E(-(lam + beta) t) / (lam - beta)

finite and accurate through lam = +-beta, which a growing mu crosses.

Closing the problem. For given c and slip-arc lengths d_i = e_i - s_i the problem is
linear in 18 constants (theta's 12, the strain at the start of each slip arc and in each
span, e_1 and e_2). Its 21 conditions are the continuity of theta, theta' and eps at the six
interfaces, the fixed length (integral of eps over the loop = 0), the driven pulley's
balance (integral of f over its arc = -M2/R2) and e_1's definition by c. Eighteen of them
fix the constants; the other three (the strain's continuity where the loop closes at x = 0,
the length and the balance) are the residuals of a damped Newton iteration on (c, d_1, d_2).
Perfect adhesion (mu None) sticks on the whole arc, with a concentrated force F_i at each
exit where [[B eps]] = -F_i and [[A theta']] = -l F_i; then only c is iterated. omega_2
follows from e_2.

Starts. Newton starts from the string's closed-form state (exact at l = 0, so a
continuation in l backs it up); near the capacity from the beam's capacity state; failing
both, from a continuation in the load from the unloaded drive (uniform strain, no slip),
which also tells gross slip (a slip arc leaves its wrap) from lift-off (the continuation
stalls as the slack side's pressure vanishes). Where the tension ratio across the slip
arcs is huge (the slack side nearly without pressure) the exponentials' range raises the
residual's round-off floor, and Newton stops there (FLOOR_STEP).

Power. Multiplying B eps' + f = 0 by eps and the moment balance by theta' and integrating
over the loop (periodic fields) gives integral f (eps + l theta') = 0, and integral f = 0,
so integral f v_b = 0 for the fibre speed v_b = c (1 + N0/b1 + eps + l theta'). Hence
M1 omega1 - M2 omega2 = integral of f omega_i R_i = -integral of f v_rel: the slip power.
With perfect adhesion the concentrated forces act where v_rel jumps from 0 to
c [[eps + l theta']] = -c F_i (1/B + l^2/A); the same integration, with the jumps, charges
each of them F_i times minus the mean of the sliding speeds on its two sides,
(c/2) F_i^2 (1/B + l^2/A).

Capacity. Gross slip sets in when a slip arc covers its whole wrap; the beam's capacity is
the load at which it does, solved for in the same model (:func:`capacity`), not the string's
(the two differ by O(l)).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from ..errors import NoSolutionError
from . import analytic
from .analytic import GrossSlipError, LiftOffError, solve_string
from .params import DriveParams

#: Newton stops when its scaled step falls below this ...
STEP_TOL = 1e-13
#: ... or below this where no step lowers the residual (its round-off floor).
FLOOR_STEP = 1e-7
#: Newton iterations at most (a start from the string converges in a handful) ...
MAX_ITERATIONS = 30
#: ... and damped steps (below 1/8 of Newton's) in a row before it gives up.
MAX_DAMPED = 4
#: A load continuation that stalls with the slack side's N - rho c^2 below this fraction of
#: the tight side's is taken for lift-off: the slip arcs grow as ln(1 / p) there and, with
#: a large mu, reach the wrap only as p -> 0.
LIFT_OFF_MARGIN = 0.05
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


# --------------------------------------------------------------------------------------
# The solution


class BeamSolution:
    """The beam's steady state of a drive (SI units; arcs in rad); the interface of
    :class:`~beltsim.beltdrive.analytic.StringSolution` where it applies.

    Fields take loop coordinates x (taken modulo Lambda) and give the value downstream at
    a jump.
    """

    def __init__(self, P: DriveParams, omega1: float, M2: float, loop: _Loop, z):
        self.P, self.omega1, self.M2 = P, omega1, M2
        self._loop = loop
        self._zz = np.append(z, 1.0)
        self._starts = np.array([seg.p for seg in loop.segs])
        # u at each piece's start: the integral of eps from 0
        ends = [float(loop.int_eps(i, seg.length)[0] @ self._zz)
                for i, seg in enumerate(loop.segs)]
        self._u0 = np.concatenate([[0.0], np.cumsum(ends)[:-1]])
        xq, wq = self._quadrature()
        self._u_mean = float(np.sum(wq * self._field(xq, "u"))) / P.geometry.loop_length

    # scalars -----------------------------------------------------------------------
    @property
    def c(self) -> float:
        """The belt speed c (m/s)."""
        return self._loop.c

    @property
    def lever(self) -> float:
        """The friction's lever l (m) the solution was computed with."""
        return self._loop.l

    @property
    def strain_constants(self) -> tuple[float, float]:
        """(e_1, e_2): the stick zones' eps + l theta' on the driver and the driven arc."""
        return tuple(float(self._zz[i]) for i in self._loop.ie)

    @property
    def omega2(self) -> float:
        """The driven pulley's speed (rad/s): its rim moves with the stuck belt's fibre."""
        P = self.P
        return self.c * (1.0 + P.N0 / P.b1 + self.strain_constants[1]) / P.geometry.R2

    @property
    def speed_ratio(self) -> float:
        """omega2 R2 / (omega1 R1)."""
        R1, R2 = self.P.geometry.radii
        return self.omega2 * R2 / (self.omega1 * R1)

    @property
    def stick_ends(self) -> tuple[float, float]:
        """Loop coordinates where the driver's and the driven arc's slip arcs begin (the
        arcs' exits for perfect adhesion)."""
        segs = self._loop.segs
        return segs[0].q, segs[3 if self._loop.coulomb else 2].q

    @property
    def slip_arcs(self) -> tuple[float, float]:
        """The slip arcs (rad) of the driver and the driven pulley."""
        g = self.P.geometry
        e = g.bounds
        s1, s2 = self.stick_ends
        return (e[1] - s1) / g.R1, (e[3] - s2) / g.R2

    @property
    def concentrated(self) -> tuple[float, float]:
        """Concentrated friction forces (N) at the driver's and the driven arc's exits:
        nonzero for perfect adhesion only."""
        if self._loop.coulomb:
            return 0.0, 0.0
        return tuple(float(self._zz[i]) for i in self._loop.iF)

    def _arc_force(self, arc) -> float:
        """The friction force (N) on arc 0 or 1, distributed and concentrated."""
        loop = self._loop
        total = self.concentrated[arc]
        for i, seg in enumerate(loop.segs):
            if seg.arc == arc:
                total -= loop.B * float((loop.eps(i, seg.length)[0]
                                         - loop.eps(i, 0.0)[0]) @ self._zz)
        return total

    @property
    def driver_torque(self) -> float:
        """M1 = R1 times the friction force on the driver's arc (N m)."""
        return self.P.geometry.R1 * self._arc_force(0)

    @property
    def efficiency(self) -> float:
        """M2 omega2 / (M1 omega1) (1 when unloaded)."""
        return self.M2 * self.omega2 / (self.driver_torque * self.omega1) \
            if self.M2 > 0 else 1.0

    @property
    def slip_power(self) -> float:
        """The friction's dissipation (W): minus the integral of f v_rel over the slip
        arcs, and for perfect adhesion each concentrated force times minus the mean of
        the sliding speeds on the two sides of its exit (the module docstring)."""
        loop = self._loop
        if loop.coulomb:
            total = 0.0
            for i, seg in enumerate(loop.segs):
                if seg.kind == "slip" and seg.length > 0:
                    t, w = _graded(seg)
                    rim = self._rim(seg.arc)
                    f = loop.friction(i, t) @ self._zz
                    v = loop.fibre_speed(i, t) @ self._zz - rim
                    total -= float(np.sum(w * f * v))
            return total
        total = 0.0
        for arc, i in ((0, 0), (1, 2)):
            seg = loop.segs[i]
            rim = self._rim(arc)
            before = float(loop.fibre_speed(i, seg.length)[0] @ self._zz) - rim
            after = float(loop.fibre_speed(i + 1, 0.0)[0] @ self._zz) - rim
            total -= self.concentrated[arc] * 0.5 * (before + after)
        return total

    def _rim(self, arc) -> float:
        R = self.P.geometry.radii[arc]
        return (self.omega1 if arc == 0 else self.omega2) * R

    def _span_mean(self, i) -> float:
        seg = self._loop.segs[i]
        mean_eps = float(self._loop.int_eps(i, seg.length)[0] @ self._zz) / seg.length
        return self.P.N0 + self.P.b1 * mean_eps

    @property
    def tight_tension(self) -> float:
        """The mean axial force N (N) over the tight span (constant there: no friction acts
        on a span, so B eps' = 0; theta's boundary layers at its ends leave N alone)."""
        return self._span_mean(len(self._loop.segs) - 1)

    @property
    def slack_tension(self) -> float:
        """The mean axial force N (N) over the slack span."""
        return self._span_mean(2 if self._loop.coulomb else 1)

    def summary(self) -> dict:
        """The drive's figures, under the run summary's names."""
        arcs = self.slip_arcs
        out = {
            "tight_tension": self.tight_tension, "slack_tension": self.slack_tension,
            "belt_speed": self.c, "driven_speed": self.omega2,
            "speed_ratio": self.speed_ratio, "slip_arc_driver": arcs[0],
            "slip_arc_driven": arcs[1], "driver_torque": self.driver_torque,
            "efficiency": self.efficiency, "slip_power": self.slip_power,
        }
        return {k: float(v) for k, v in out.items()}

    # fields ------------------------------------------------------------------------
    def _field(self, x, name):
        loop = self._loop
        x = np.asarray(x, dtype=float)
        xs = np.mod(x.ravel(), self.P.geometry.loop_length)
        idx = np.clip(np.searchsorted(self._starts, xs, side="right") - 1, 0,
                      len(loop.segs) - 1)
        out = np.zeros_like(xs)
        for i, seg in enumerate(loop.segs):
            on = idx == i
            if not np.any(on):
                continue
            t = xs[on] - seg.p
            if name == "u":
                out[on] = self._u0[i] + loop.int_eps(i, t) @ self._zz
            elif name == "theta":
                out[on] = loop.theta(i, t) @ self._zz
            elif name == "dtheta":
                out[on] = loop.theta(i, t, 1) @ self._zz
            elif name == "eps":
                out[on] = loop.eps(i, t) @ self._zz
            elif name == "friction":
                out[on] = loop.friction(i, t) @ self._zz
            elif name == "v_rel":
                out[on] = (loop.fibre_speed(i, t) @ self._zz - self._rim(seg.arc)
                           if seg.arc >= 0 else 0.0)
        return out.reshape(x.shape)

    def strain(self, x) -> np.ndarray:
        """eps = u_x at x."""
        return self._field(x, "eps")

    def tension(self, x) -> np.ndarray:
        """The axial force N = N0 + b1 eps (N) at x."""
        return self.P.N0 + self.P.b1 * self._field(x, "eps")

    def friction(self, x) -> np.ndarray:
        """Distributed friction f (N/m) on the belt at x (the concentrated forces of
        perfect adhesion excluded: see :attr:`concentrated`)."""
        return self._field(x, "friction")

    def pressure(self, x) -> np.ndarray:
        """Contact pressure (N - rho c^2) / R_i (N/m) on the arcs, 0 on the spans."""
        g = self.P.geometry
        seg = g.segment_of(x)
        R = np.where(seg == 0, g.R1, g.R2)
        return np.where(seg % 2 == 0, (self.tension(x) - self._loop.rc) / R, 0.0)

    def theta(self, x) -> np.ndarray:
        """The cross-section's rotation theta (rad) at x."""
        return self._field(x, "theta")

    def moment(self, x) -> np.ndarray:
        """A theta' = (a - I c^2) theta' (N m) at x: the moment flux that is continuous
        across the Coulomb solution's interfaces (a theta' is the elastic moment)."""
        return self._loop.A * self._field(x, "dtheta")

    def slip_velocity(self, x) -> np.ndarray:
        """v_rel = c (1 + N0/b1 + eps + l theta') - omega_i R_i (m/s) on the arcs, 0 on
        the spans (no rim there)."""
        return self._field(x, "v_rel")

    def displacement(self, x) -> np.ndarray:
        """u (m) at x: the integral of eps from 0, less its mean over the loop (the gauge)."""
        return self._field(x, "u") - self._u_mean

    def grid(self, n: int = 400) -> np.ndarray:
        """Sorted loop coordinates that resolve every boundary layer: n even points and
        the graded quadrature's nodes."""
        lam = self.P.geometry.loop_length
        return np.unique(np.concatenate([np.linspace(0.0, lam, n, endpoint=False),
                                         self._quadrature()[0]]))

    def _quadrature(self):
        """Nodes and weights over the loop, graded towards every piece's ends."""
        xs, ws = [], []
        for seg in self._loop.segs:
            if seg.length > 0:
                t, w = _graded(seg)
                xs.append(seg.p + t)
                ws.append(w)
        return np.concatenate(xs), np.concatenate(ws)

    # admissibility -----------------------------------------------------------------
    def _check(self):
        """Raise where the solution breaks its model: no contact pressure, a slip arc
        outside its wrap, friction above mu p in a stick zone or sliding along f."""
        loop, P, g = self._loop, self.P, self.P.geometry
        names = ("driver", "driven")
        for arc in (0, 1):
            for i, seg in enumerate(loop.segs):
                if seg.arc != arc:
                    continue
                t = np.concatenate([[0.0, seg.length], _graded(seg)[0]])
                p = loop.pressure(i, t) @ self._zz
                if not np.min(p) > 0:
                    raise LiftOffError(
                        f"drive.installation_tension: {P.N0:g} N leaves the {names[arc]} arc "
                        f"without contact pressure (min {np.min(p):.4g} N/m) at this load and "
                        f"speed: the belt would lift off, which this model does not describe")
                if not loop.coulomb:
                    continue
                f = loop.friction(i, t) @ self._zz
                if seg.kind == "stick":
                    ratio = np.max(np.abs(f) / (P.mu * p))
                    if ratio > 1.0 + 1e-9:
                        raise NoSolutionError(
                            f"beam drive: the {names[arc]} arc's stick zone needs friction "
                            f"{ratio:.6g} times mu p: the stick-then-slip layout does not "
                            f"hold")
                else:
                    v = loop.fibre_speed(i, t) @ self._zz - self._rim(arc)
                    # the creep's scale, and the round-off of v_rel as a difference of speeds
                    tol = self.c * (1e-9 * abs(np.diff(self.strain_constants)[0]) + 1e-13)
                    if np.max(seg.sign * v) > tol:
                        raise NoSolutionError(
                            f"beam drive: the belt slides along its friction on the "
                            f"{names[arc]} arc's slip arc (v_rel {np.max(seg.sign * v):.3g} "
                            f"m/s the wrong way): the stick-then-slip layout does not hold")
        if loop.coulomb:
            tol = 1e-12 * g.loop_length
            for arc, d in enumerate(self.slip_arcs):
                if not -tol <= d * g.radii[arc] <= g.arcs[arc] + tol:
                    raise NoSolutionError(f"beam drive: the {names[arc]} slip arc "
                                          f"{d:.6g} rad lies outside its wrap")


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


# --------------------------------------------------------------------------------------
# Solvers


def _defaults(P, omega1, M2):
    omega1 = P.omega1 if omega1 is None else float(omega1)
    M2 = P.M2 if M2 is None else float(M2)
    if not omega1 > 0:
        raise ValueError(f"omega1: must be > 0, got {omega1!r}")
    if not M2 >= 0:
        raise ValueError(f"M2: must be >= 0, got {M2!r}")
    return omega1, M2


def _check_bending(P: DriveParams, omega1: float):
    """Refuse a drive whose belt, near the rim speed, has A = a - I c^2 <= 0: there theta's
    equation loses its decaying solutions and the beam has no steady state."""
    c = omega1 * P.geometry.R1 / (1.0 + P.N0 / P.b1)  # the unloaded belt speed
    if P.lever > 0 and not P.a - P.I * c * c > 0:
        raise NoSolutionError(
            f"drive.driver_speed: at the belt speed {c:.6g} m/s the rotary inertia I c^2 = "
            f"{P.I * c * c:.4g} N m^2 reaches the bending stiffness a = {P.a:.4g} N m^2: "
            f"the beam has no steady state (a - I c^2 <= 0)")


def _fits(P: DriveParams, d) -> bool:
    """Whether both slip arcs of lengths d (m) lie within their wraps."""
    return all(d[k] <= P.geometry.arcs[k] for k in (0, 1))


def _string_start(P: DriveParams, omega1: float, M2: float):
    """The iterated unknowns (c, w1, w2) of the string's state, or None where the string
    has none (its gross slip or lift-off, or its root bracket failing near lift-off)."""
    try:
        s = solve_string(P, omega1, M2)
    except ValueError:  # NoSolutionError included
        return None
    return s.c, P.mu * s.phi_s, P.mu * s.phi_s


def _lowest_pressure(loop: _Loop, z) -> float:
    """The smallest contact pressure (N/m) on the arcs (the pieces' ends and the graded
    quadrature's nodes)."""
    zz = np.append(z, 1.0)
    low = math.inf
    for i, seg in enumerate(loop.segs):
        if seg.arc >= 0:
            t = np.concatenate([[0.0, seg.length], _graded(seg)[0]])
            low = min(low, float(np.min(loop.pressure(i, t) @ zz)))
    return low


def _march(P: DriveParams, omega1: float, target: float):
    """Continuation in the load from the unloaded drive (exact: uniform strain, c from the
    driver's rim, no slip) towards ``target`` (may be inf), the step doubling while Newton
    converges to an admissible state (both slip arcs inside their wraps, the pressure
    positive) and halving otherwise.

    Returns
    -------
    (M, y, found, status)
        The last load reached, its unknowns and its (loop, z) (None if only the unloaded
        drive); ``status`` "done" (M is the target), "over" (a slip arc leaves its wrap
        beyond M), "lift" (the pressure vanishes beyond M) or "stall" (Newton fails).
    """
    g = P.geometry
    c0 = omega1 * g.R1 / (1.0 + P.N0 / P.b1)
    if not P.N0 > P.rho * c0 * c0:
        return 0.0, None, None, "lift"
    M, y = 0.0, np.array([c0, 0.0, 0.0])
    dM = min(target, 0.1 * g.R2 * P.N0)
    found, status = None, "stall"
    while M < target:
        trial = min(M + dM, target)
        try:
            loop, z, y_new = _newton(P, P.lever, omega1, trial, "load", y)
            ok = _fits(P, _unpack(P, "load", y_new)[1]) or "over"
            if ok is True and not _lowest_pressure(loop, z) > 0:
                ok = "lift"
        except _NotConverged:
            ok = "stall"
        if ok is True:
            M, y, found = trial, y_new, (loop, z)
            if status == "stall":
                dM *= 2
            continue
        if status == "stall":
            status = ok
        dM /= 2
        if dM < 1e-3 * M or dM < 1e-9 * g.R2 * P.N0:
            if status == "stall" and found is not None and _margin(found) < LIFT_OFF_MARGIN:
                status = "lift"  # Newton fails as the slack side's pressure vanishes
            return M, y, found, status
    return M, y, found, "done"


def _capacity_near(P: DriveParams, omega1: float, M: float, y):
    """(capacity, loop, z) by Newton with a slip arc pinned to its whole wrap and the load
    unknown, started from an admissible state (load M, unknowns y) close below it."""
    g = P.geometry
    c, d, _ = _unpack(P, "load", y)
    w = (y[1], y[2])
    first = 0 if d[0] / g.arcs[0] >= d[1] / g.arcs[1] else 1
    failures = []
    for arc in (first, 1 - first):
        mode = ("cap1", "cap2")[arc]
        y0 = [c, w[0], w[1]]
        y0[1 + arc] = M / (g.R2 * P.N0)
        try:
            loop, z, y_cap = _newton(P, P.lever, omega1, 0.0, mode, y0)
        except (_NotConverged, NoSolutionError) as exc:
            failures.append(str(exc))
            continue
        _, d_cap, cap = _unpack(P, mode, y_cap)
        if d_cap[1 - arc] <= g.arcs[1 - arc] * (1.0 + 1e-12):
            return cap, loop, z
    raise NoSolutionError(f"beam drive: no capacity found at {omega1:g} rad/s "
                          f"({'; '.join(failures) or 'no slip arc fits its wrap'})")


def _capacity_by_string(P: DriveParams, omega1: float):
    """(capacity, loop, z) started from the string's state just below the string's
    capacity (the two differ by O(l)), or None where the string gives no such state."""
    try:
        cap_s = analytic.capacity(P, omega1)
    except ValueError:  # the string's bracket can fail where the belt lifts off
        return None
    start = _string_start(P, omega1, cap_s * (1.0 - 1e-9))
    if start is None:
        return None
    try:
        return _capacity_near(P, omega1, cap_s, np.array(start))
    except NoSolutionError:
        return None


def _capacity_state(P: DriveParams, omega1: float):
    """(capacity, loop, z): the load at which a slip arc first covers its whole wrap; from
    the string's capacity, else from the end of a load continuation."""
    found = _capacity_by_string(P, omega1)
    if found is not None:
        return found
    M, y, _, status = _march(P, omega1, math.inf)
    if status != "over":
        raise NoSolutionError(f"beam drive: no capacity found at {omega1:g} rad/s (the "
                              f"load continuation stops at {M:.6g} N m before gross slip)")
    return _capacity_near(P, omega1, M, y)


def capacity(P: DriveParams, omega1: float | None = None) -> float:
    """The largest load torque M2 (N m) the beam drive carries at the driver speed omega1:
    a slip arc then covers its whole wrap (inf for perfect adhesion).

    The string's capacity (:func:`beltsim.beltdrive.analytic.capacity`) is its l -> 0
    limit; this one is solved in the beam's own model.
    """
    if P.mu is None:
        return math.inf
    omega1, _ = _defaults(P, omega1, 0.0)
    _check_bending(P, omega1)
    return float(_capacity_state(P, omega1)[0])


def _gross_slip(P, omega1, M2, cap):
    return GrossSlipError(f"drive.load_torque: {M2:g} N m exceeds the beam drive's capacity "
                          f"{cap:.6g} N m at {omega1:g} rad/s (gross slip: no steady state)",
                          cap)


def _solve_coulomb(P: DriveParams, omega1: float, M2: float):
    """(loop, z) of the Coulomb solution, or GrossSlipError / NoSolutionError."""
    start = _string_start(P, omega1, M2)
    if start is not None:
        try:
            loop, z, y = _converge(P, omega1, M2, "load", start)
            if _fits(P, _unpack(P, "load", y)[1]):
                return loop, z
        except _NotConverged:
            pass
    # near or beyond the capacity: the beam's capacity from the string's, and below it a
    # start from the capacity state
    found = _capacity_by_string(P, omega1)
    if found is not None:
        cap, loop, _ = found
        if M2 > cap:
            raise _gross_slip(P, omega1, M2, cap)
        d = [seg.length for seg in loop.segs if seg.kind == "slip"]
        try:
            loop, z, y = _newton(P, P.lever, omega1, M2, "load",
                                 (loop.c, d[0] * P.mu / P.geometry.R1,
                                  d[1] * P.mu / P.geometry.R2))
            if _fits(P, _unpack(P, "load", y)[1]):
                return loop, z
        except _NotConverged:
            pass
    M, y, found, status = _march(P, omega1, M2)
    if status == "done":
        return found
    if status == "over":
        cap = _capacity_near(P, omega1, M, y)[0]
        if M2 > cap:
            raise _gross_slip(P, omega1, M2, cap)
    elif status == "lift" and not P.N0 > P.rho * (omega1 * P.geometry.R1) ** 2 / (
            1.0 + P.N0 / P.b1) ** 2:
        c0 = omega1 * P.geometry.R1 / (1.0 + P.N0 / P.b1)
        raise LiftOffError(
            f"drive.installation_tension: {P.N0:g} N does not exceed the centrifugal "
            f"tension rho c^2 = {P.rho * c0 * c0:.4g} N: the belt lifts off even unloaded")
    elif status == "lift":
        raise LiftOffError(
            f"drive.installation_tension: {P.N0:g} N leaves the belt without contact "
            f"pressure beyond {M:.4g} N m, below the load {M2:g} N m: it would lift off, "
            f"which this model does not describe")
    raise NoSolutionError(f"beam drive: no steady state found at {M2:g} N m (the load "
                          f"continuation stops at {M:.6g} N m)")


def _margin(found) -> float:
    """(T2 - rho c^2) / (T1 - rho c^2) of a state (loop, z): the slack side's share."""
    loop, z = found
    zz = np.append(z, 1.0)
    n = [float(loop.pressure(i, 0.0)[0] @ zz) * loop.P.geometry.radii[seg.arc]
         for i, seg in enumerate(loop.segs) if seg.kind == "stick"]
    return n[1] / n[0]


def solve_beam(P: DriveParams, omega1: float | None = None,
               M2: float | None = None) -> BeamSolution:
    """The shear-deformable beam's steady state at driver speed omega1 and load M2 (the
    scene's final values by default); ``P.lever`` = 0 (the string model) gives the string.

    Newton starts from the string's closed-form state; where that fails, from a
    continuation in the load.

    Raises
    ------
    GrossSlipError
        The load exceeds the beam drive's capacity (:func:`capacity`, in the message).
    LiftOffError
        The contact pressure does not stay positive on the arcs.
    NoSolutionError
        No steady state of the assumed layout (the message names what fails).
    """
    omega1, M2 = _defaults(P, omega1, M2)
    g = P.geometry
    _check_bending(P, omega1)
    if P.mu is None:
        try:
            c0 = solve_string(P, omega1, M2).c
        except ValueError:  # the string lifts off: start from the unloaded belt speed
            c0 = omega1 * g.R1 / (1.0 + P.N0 / P.b1)
        try:
            loop, z, _ = _converge(P, omega1, M2, "stick", (c0,))
        except _NotConverged as exc:
            raise NoSolutionError(f"beam drive: no steady state found ({exc})") from None
    else:
        loop, z = _solve_coulomb(P, omega1, M2)
    sol = BeamSolution(P, omega1, M2, loop, z)
    sol._check()
    return sol


def slip_collapse(P: DriveParams, mus, omega1: float | None = None,
                  M2: float | None = None) -> dict:
    """The slip arcs' collapse onto the exits as mu grows (the drive's Fig. 7).

    For each friction coefficient the Coulomb solution is compared with perfect adhesion
    on a grid resolving both. The tension's difference is taken outside the slip arcs:
    inside them the Coulomb tension runs across the jump that adhesion concentrates at
    the exit, so its maximum there stays near the concentrated force however narrow the
    arc; its integral (``tension_diff_l1``) covers the whole loop.

    Returns
    -------
    dict
        Arrays over ``mu``: ``slip_arc_driver``, ``slip_arc_driven`` (rad),
        ``tight_tension``, ``slack_tension`` (N), ``theta_diff`` (max abs theta difference,
        rad), ``tension_diff`` (N, outside the slip arcs), ``tension_diff_l1`` (N m); and
        ``adhesion``, the perfect-adhesion summary.
    """
    stick = solve_beam(dataclasses.replace(P, mu=None, friction="stick"), omega1, M2)
    keys = ("slip_arc_driver", "slip_arc_driven", "tight_tension", "slack_tension",
            "theta_diff", "tension_diff", "tension_diff_l1")
    out = {k: [] for k in keys}
    mus = np.asarray(mus, dtype=float)
    e = P.geometry.bounds
    for mu in mus:
        sol = solve_beam(dataclasses.replace(P, mu=float(mu), friction="coulomb"),
                         omega1, M2)
        sm = sol.summary()
        for k in keys[:4]:
            out[k].append(sm[k])
        x = np.unique(np.concatenate([sol.grid(), stick.grid()]))
        out["theta_diff"].append(float(np.max(np.abs(sol.theta(x) - stick.theta(x)))))
        dN = np.abs(sol.tension(x) - stick.tension(x))
        s1, s2 = sol.stick_ends
        outside = ~(((x >= s1) & (x < e[1])) | ((x >= s2) & (x < e[3])))
        out["tension_diff"].append(float(np.max(dN[outside])))
        xq, wq = _loop_quadrature(sol, stick)
        out["tension_diff_l1"].append(float(np.sum(
            wq * np.abs(sol.tension(xq) - stick.tension(xq)))))
    res = {k: np.array(v) for k, v in out.items()}
    res["mu"] = mus
    res["adhesion"] = stick.summary()
    return res


def _loop_quadrature(*sols):
    """Graded Gauss nodes over the loop, split at every piece end of the solutions."""
    breaks = np.unique(np.concatenate([[seg.p for seg in s._loop.segs] + [
        s.P.geometry.loop_length] for s in sols]))
    k = max(s._loop.alpha for s in sols) + max(s._loop.beta for s in sols)
    xs, ws = [], []
    for a, b in zip(breaks[:-1], breaks[1:]):
        if b > a:
            t, w = _graded(_Seg(a, b, "span", -1, k))
            xs.append(a + t)
            ws.append(w)
    return np.concatenate(xs), np.concatenate(ws)


__all__ = ["BeamSolution", "capacity", "slip_collapse", "solve_beam"]
