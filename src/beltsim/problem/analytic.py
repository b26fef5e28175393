"""Analytic steady solutions (Oborin & Vetyukov 2019, Sects. 2-4), derived afresh.

Steady equations with B = b1 - rho c^2 and A = a - I c^2 (rho = I = 0 when
quasistatic)::

    B eps' + f = 0,     A theta'' - b2 theta + (h/2) f = 0

* free segment (f = 0): eps constant, theta'' = beta^2 theta, beta^2 = b2/A;
* stick (eps + (h/2) theta' = e0 = v/c - 1): f = B (h/2) theta'',
  theta'' = alpha^2 theta, alpha^2 = 4 b2 / (4 A + B h^2);
* slip (f = s f*, s = sign(e0)): eps' = -s f*/B,
  theta'' = beta^2 (theta - s h f* / (2 b2)).

theta = 0 at x = 0, L; theta, A theta' and eps continuous except at x2 in the
perfect-adhesion model, where the concentrated force F makes
[[B eps]] = -F and [[A theta']] = -(h/2) F; the integral of eps over [0, L]
is zero (material length). The printed formulas carry misprints, so nothing
here is copied from them: in eq. (7) f_stick has a "+" between the exponentials
(f = B (h/2) theta''); in eqs. (10) and (14) "cosh(beta x1)" must read
1/sinh(beta x1) (and 1/sinh(beta (L - x2))); eq. (26) reads
theta'' - beta^2 theta + beta^2 h f* / (2 b2) = 0; eq. (29) lacks "= 0".

On each segment [p, q] theta = P e^{-k(x-p)} + Q e^{-k(q-x)} + theta_p: the
two basis functions stay bounded for long segments (large k L) and well
conditioned for vanishing ones, so one small linear system serves every
case. For a given slip start x* the problem is linear; x* is the root of the
material-length residual, bracketed over (x1, x2) on a grid that is dense
near x2 (short slip zones at large f*).

Slip power. The bottom fibre (eps_b = eps + (h/2) theta') moves at c (1 + eps_b) over a
surface moving at v = c (1 + e0): it slides at c (eps_b - e0), and friction dissipates
D = -integral of f c (eps_b - e0) >= 0. Nothing in stick (eps_b = e0). On the slip zone
[x*, x2] of length l, f = s f* and the sliding opposes it (s (eps_b - e0) <= 0); eps falls
linearly and theta is the segment's exponentials, so exactly

    D = f* c [f* l^2 / (2B) - s (h/2) (theta(x2) - theta(x*) - l theta'(x*)) - s g* l],

g* = eps_b(x*) - e0 (zero unless the whole contact slides). Multiplying B eps' + f = 0 by
eps and the moment balance by theta' and integrating over [0, L] gives, for both models,
the global balance D = c e0 F_tot + (c/2) [B eps^2 + A theta'^2] from 0 to L, jumps
included. In perfect adhesion eps_b jumps at x2 by [[eps_b]] = -F (1/B + h^2/(4A)), so the
material leaves the surface sliding, and the balance gives D = (c/2) F^2 (1/B + h^2/(4A)):
F times the mean of the sliding speeds on either side, 0 and c abs([[eps_b]]). It is the
f* -> infinity limit of the slip zone, of width F/f*, across which eps_b - e0 runs
linearly from 0 to [[eps_b]].
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from ..errors import NoSolutionError
from .roots import brentq
from .scene import Scene
from .validation import Params

FIELDS = ("u", "theta", "strain", "tension", "moment", "friction")


@dataclass(frozen=True)
class Segment:
    """A segment [p, q] of the steady solution: free, stick or slip, with its decay rate."""

    p: float
    q: float
    kind: str  # "free", "stick", "slip"
    k: float
    theta_p: float  # particular solution (slip only)

    @property
    def length(self):
        """q - p (m)."""
        return self.q - self.p


def decay_rates(P: Params):
    """alpha and beta (1/m): theta decays as exp(-alpha x) in stick, exp(-beta x) elsewhere."""
    beta = math.sqrt(P.b2 / P.A)
    alpha = math.sqrt(4.0 * P.b2 / (4.0 * P.A + P.B * P.h**2))
    return alpha, beta


def _basis(seg: Segment, x):
    """phi1, phi2 and their derivatives on a segment (x may be an array)."""
    x = np.asarray(x, dtype=float)
    e1 = np.exp(-seg.k * (x - seg.p))
    e2 = np.exp(-seg.k * (seg.q - x))
    return e1, e2, -seg.k * e1, seg.k * e2


def _exp_rem2(t):
    """exp(-t) - 1 + t, accurate for small t."""
    if t >= 0.1:
        return math.expm1(-t) + t
    return sum((-t) ** n / math.factorial(n) for n in range(2, 17))


def _exp_rem2b(t):
    """1 - (1 + t) exp(-t), accurate for small t."""
    if t >= 0.1:
        return -math.expm1(-t) - t * math.exp(-t)
    return sum((-1) ** n * (n - 1) * t**n / math.factorial(n) for n in range(2, 17))


class _System:
    """Affine forms (row, constant) over the unknowns [P0, Q0, ..., G, phi]."""

    def __init__(self, segments, with_jump):
        self.segments = segments
        self.n = 2 * len(segments) + 1 + (1 if with_jump else 0)
        self.iG = 2 * len(segments)
        self.iphi = self.iG + 1 if with_jump else None

    def zero(self):
        return np.zeros(self.n), 0.0

    def theta(self, i, x):
        seg = self.segments[i]
        e1, e2, _, _ = _basis(seg, x)
        r = np.zeros(self.n)
        r[2 * i], r[2 * i + 1] = e1, e2
        return r, seg.theta_p

    def dtheta(self, i, x):
        seg = self.segments[i]
        _, _, d1, d2 = _basis(seg, x)
        r = np.zeros(self.n)
        r[2 * i], r[2 * i + 1] = d1, d2
        return r, 0.0


def _assemble(P: Params, segments, s, jump_at_x2, material_length_eq):
    """Build the linear system; returns (M, rhs, residual_form, eps_forms, u_forms)."""
    sysm = _System(segments, jump_at_x2)
    rows, rhs = [], []
    half_h = 0.5 * P.h

    def add(form):
        r, c0 = form
        rows.append(r)
        rhs.append(-c0)

    def sub(f1, f2):
        return f1[0] - f2[0], f1[1] - f2[1]

    add(sysm.theta(0, 0.0))
    add(sysm.theta(len(segments) - 1, P.L))
    for i in range(len(segments) - 1):
        x = segments[i].q
        add(sub(sysm.theta(i, x), sysm.theta(i + 1, x)))
        r, c0 = sub(sysm.dtheta(i, x), sysm.dtheta(i + 1, x))
        if jump_at_x2 and x == P.x2:
            r = r.copy()
            r[sysm.iphi] -= half_h * P.B / P.A  # A [[theta']] = -(h/2) F, F = B phi
        add((r, c0))

    # strain propagation, left to right, as affine forms
    eps = np.zeros(sysm.n)
    eps[sysm.iG] = 1.0
    eps = (eps, 0.0)
    integral = sysm.zero()
    eps_start, u_start = [], []
    for i, seg in enumerate(segments):
        u_start.append(integral)
        ell = seg.length
        if seg.kind == "stick":
            r, _ = sysm.dtheta(i, seg.p)
            stick_eps = (-half_h * r, P.e0)
            add(sub(eps, stick_eps))  # strain continuous where material enters stick
            eps_start.append(stick_eps)
            t_q, t_p = sysm.theta(i, seg.q), sysm.theta(i, seg.p)
            integral = (integral[0] - half_h * (t_q[0] - t_p[0]), integral[1] + P.e0 * ell)
            r, _ = sysm.dtheta(i, seg.q)
            eps = (-half_h * r, P.e0)
        elif seg.kind == "slip":
            eps_start.append(eps)
            integral = (integral[0] + ell * eps[0],
                        integral[1] + ell * eps[1] - s * P.fstar * ell * ell / (2.0 * P.B))
            eps = (eps[0], eps[1] - s * P.fstar * ell / P.B)
        else:
            eps_start.append(eps)
            integral = (integral[0] + ell * eps[0], integral[1] + ell * eps[1])
        if jump_at_x2 and seg.q == P.x2:
            r = eps[0].copy()
            r[sysm.iphi] -= 1.0
            eps = (r, eps[1])
    if material_length_eq:
        add(integral)
    M = np.array(rows)
    b = np.array(rhs)
    return sysm, M, b, integral, eps_start, u_start


def _solve_linear(M, b):
    scale = np.max(np.abs(M), axis=1)
    scale[scale == 0] = 1.0
    return np.linalg.solve(M / scale[:, None], b / scale)


class AnalyticSolution:
    """A steady solution: fields at any x and the friction totals.

    ``model`` is "stick" (perfect adhesion, concentrated force at x2) or
    "slip" (stick on [x1, x*], sliding on (x*, x2]). ``full_slip`` is True
    when the whole contact slides (x* = x1).
    """

    def __init__(self, params: Params, model, segments, z, sysm, s, x_star=None,
                 full_slip=False):
        self.params = params
        self.model = model
        self.segments = segments
        self.z = z
        self._sys = sysm
        self.s = s
        self.x_star = x_star
        self.full_slip = full_slip
        P = params
        # strain and displacement at each segment start, for field evaluation
        _, _, _, _, eps_start, u_start = _assemble(P, segments, s, model == "stick",
                                                   model == "stick" or full_slip)
        self._eps0 = [float(f[0] @ z + f[1]) for f in eps_start]
        self._u0 = [float(f[0] @ z + f[1]) for f in u_start]
        self.concentrated_force = (P.B * z[sysm.iphi]) if model == "stick" else 0.0
        stick = slip = 0.0
        for i, seg in enumerate(segments):
            if seg.kind == "stick":
                dq = self._theta_prime(i, seg.q)
                dp = self._theta_prime(i, seg.p)
                stick += P.B * 0.5 * P.h * (dq - dp)
            elif seg.kind == "slip":
                slip += s * P.fstar * seg.length
        self.stick_friction = float(stick)
        self.slip_friction = float(slip)

    # pieces -----------------------------------------------------------
    def _theta(self, i, x):
        seg = self.segments[i]
        e1, e2, _, _ = _basis(seg, x)
        return self.z[2 * i] * e1 + self.z[2 * i + 1] * e2 + seg.theta_p

    def _theta_prime(self, i, x):
        seg = self.segments[i]
        _, _, d1, d2 = _basis(seg, x)
        return self.z[2 * i] * d1 + self.z[2 * i + 1] * d2

    # totals -----------------------------------------------------------
    @property
    def distributed_friction(self) -> float:
        """Friction carried by the distributed traction (stick zone plus slip zone)."""
        return self.stick_friction + self.slip_friction

    @property
    def total_friction(self) -> float:
        """The friction force on the belt (N): distributed plus concentrated."""
        return self.distributed_friction + self.concentrated_force

    @property
    def slip_power(self) -> float:
        """Power dissipated by sliding (W, >= 0); the derivation is in the module docstring.

        Slip model: the closed-form integral of f* c abs(eps_b - e0) over the slip zone.
        Perfect adhesion: the distributed traction does no work (no sliding where it
        acts), but the concentrated force acts where the sliding speed jumps from 0 to
        c abs([[eps_b]]) and dissipates (c/2) F^2 (1/B + h^2/(4A)).
        """
        P = self.params
        if self.model == "stick":
            F = self.concentrated_force
            return float(0.5 * P.c * F * F * (1.0 / P.B + P.h**2 / (4.0 * P.A)))
        power = 0.0
        for i, seg in enumerate(self.segments):
            if seg.kind != "slip" or seg.length <= 0.0:
                continue
            ell, t = seg.length, seg.k * seg.length
            g_start = self._eps0[i] + 0.5 * P.h * self._theta_prime(i, seg.p) - P.e0
            # theta(q) - theta(p) - l theta'(p) in the basis, without the cancellation of
            # theta_p (large at large f*) and of exp(-t) ~ 1 - t in short slip zones
            bend = self.z[2 * i] * _exp_rem2(t) + self.z[2 * i + 1] * _exp_rem2b(t)
            power += P.fstar * P.c * (P.fstar * ell * ell / (2.0 * P.B)
                                      - self.s * (0.5 * P.h * bend + g_start * ell))
        # admissibility makes s (eps_b - e0) <= 0 on the slip zone, so the signed integral
        # is that of |eps_b - e0|; the clamp only absorbs round-off of vanishing zones
        return max(0.0, float(power))

    def summary(self) -> dict:
        """The totals as summary.json holds them (keys that do not apply are None).

        Returns
        -------
        dict
            ``model``, ``inertia``, ``total_friction``, ``concentrated_force`` and
            ``distributed_friction`` (perfect adhesion), ``stick_friction``,
            ``slip_friction`` and ``slip_start`` (stick and slip), ``slip_power``.
        """
        stick_model = self.model == "stick"
        return {
            "model": self.model,
            "inertia": self.params.inertia,
            "total_friction": self.total_friction,
            "concentrated_force": self.concentrated_force if stick_model else None,
            "distributed_friction": self.distributed_friction if stick_model else None,
            "stick_friction": None if stick_model else self.stick_friction,
            "slip_friction": None if stick_model else self.slip_friction,
            "slip_start": None if stick_model else self.x_star,
            "slip_power": self.slip_power,
        }

    # fields -----------------------------------------------------------
    def segment_index(self, x, side="right"):
        """Segment of each x; at a breakpoint, ``side`` picks the one-sided limit."""
        x = np.atleast_1d(np.asarray(x, dtype=float))
        starts = np.array([seg.p for seg in self.segments])
        ends = np.array([seg.q for seg in self.segments])
        if side == "right":
            idx = np.searchsorted(starts, x, side="right") - 1
            # zero-length segments are never the one-sided limit
            idx = np.clip(idx, 0, len(self.segments) - 1)
        else:
            idx = np.searchsorted(ends, x, side="left")
            idx = np.clip(idx, 0, len(self.segments) - 1)
        return idx

    def fields(self, x, side="right") -> dict:
        """u, theta, strain, tension, moment and friction at x (arrays)."""
        P = self.params
        x = np.atleast_1d(np.asarray(x, dtype=float))
        idx = self.segment_index(x, side)
        out = {k: np.zeros_like(x) for k in FIELDS}
        half_h = 0.5 * P.h
        for i, seg in enumerate(self.segments):
            m = idx == i
            if not np.any(m):
                continue
            xs = x[m]
            th = self._theta(i, xs)
            dth = self._theta_prime(i, xs)
            eps0, u0 = self._eps0[i], self._u0[i]
            if seg.kind == "stick":
                eps = P.e0 - half_h * dth
                u = u0 + P.e0 * (xs - seg.p) - half_h * (th - self._theta(i, seg.p))
                f = P.B * half_h * seg.k**2 * th
            elif seg.kind == "slip":
                d = xs - seg.p
                eps = eps0 - self.s * P.fstar * d / P.B
                u = u0 + eps0 * d - self.s * P.fstar * d * d / (2.0 * P.B)
                f = np.full_like(xs, self.s * P.fstar)
            else:
                eps = np.full_like(xs, eps0)
                u = u0 + eps0 * (xs - seg.p)
                f = np.zeros_like(xs)
            out["u"][m] = u
            out["theta"][m] = th
            out["strain"][m] = eps
            out["tension"][m] = P.b1 * eps
            out["moment"][m] = P.a * dth
            out["friction"][m] = f
        return out

    def breakpoints(self):
        """The points where a field's derivative may jump: x1, x2 and the slip start."""
        pts = [self.params.x1, self.params.x2]
        if self.model == "slip" and self.x_star is not None:
            pts.append(self.x_star)
        return sorted(set(pts))

    def sample(self, n=801):
        """A grid over [0, L] with both one-sided limits at x1, x* and x2.

        Returns (x, fields); breakpoints appear twice, left limit first.
        """
        P = self.params
        xs = np.linspace(0.0, P.L, n)
        bps = self.breakpoints()
        xs = np.setdiff1d(xs, bps)
        parts_x, parts_f = [], []
        left = self.fields(np.array(bps), side="left")
        right = self.fields(np.array(bps), side="right")
        body = self.fields(xs)
        allx = np.concatenate([xs, bps, bps])
        order_key = np.concatenate([np.zeros(len(xs)), np.zeros(len(bps)), np.ones(len(bps))])
        order = np.lexsort((order_key, allx))
        for name in FIELDS:
            parts_f.append(np.concatenate([body[name], left[name], right[name]])[order])
        parts_x = allx[order]
        return parts_x, dict(zip(FIELDS, parts_f))


# ---------------------------------------------------------------------------
# Solvers


def _segments(P: Params, kinds_and_ends, s):
    alpha, beta = decay_rates(P)
    out, p = [], 0.0
    for kind, q in kinds_and_ends:
        k = alpha if kind == "stick" else beta
        tp = s * P.h * P.fstar / (2.0 * P.b2) if kind == "slip" else 0.0
        out.append(Segment(p, q, kind, k, tp))
        p = q
    return out


def solve_stick(P: Params) -> AnalyticSolution:
    """Perfect adhesion on [x1, x2] with the concentrated force at x2 (Sects. 2-3)."""
    s = float(np.sign(P.e0))
    segs = _segments(P, [("free", P.x1), ("stick", P.x2), ("free", P.L)], s)
    sysm, M, b, _, _, _ = _assemble(P, segs, s, True, True)
    z = _solve_linear(M, b)
    return AnalyticSolution(P, "stick", segs, z, sysm, s)


def _slip_system(P, x_star, s):
    segs = _segments(P, [("free", P.x1), ("stick", x_star), ("slip", P.x2), ("free", P.L)], s)
    sysm, M, b, integral, _, _ = _assemble(P, segs, s, False, False)
    z = _solve_linear(M, b)
    return segs, sysm, z, float(integral[0] @ z + integral[1])


def _full_slip(P, s):
    segs = _segments(P, [("free", P.x1), ("slip", P.x2), ("free", P.L)], s)
    sysm, M, b, _, _, _ = _assemble(P, segs, s, False, True)
    z = _solve_linear(M, b)
    return AnalyticSolution(P, "slip", segs, z, sysm, s, x_star=P.x1, full_slip=True)


def solve_slip(P: Params) -> AnalyticSolution:
    """Stick on [x1, x*], sliding on (x*, x2] with traction f* sign(v - c) (Sect. 4).

    The slip length d = x2 - x* is the root of the material-length residual.
    Roots are bracketed on a grid geometric towards d = 0 (slip zones down to
    1e-13 of the contact length) and refined with Brent's method. When no stick
    zone can carry the load the whole contact slides (x* = x1) and that state is
    returned if the slip direction is consistent; otherwise NoSolutionError.
    """
    if P.fstar is None:
        raise NoSolutionError("contact.max_friction: the slip solution needs a friction limit")
    ell = P.x2 - P.x1
    if P.e0 == 0.0:
        segs = _segments(P, [("free", P.x1), ("stick", P.x2), ("slip", P.x2), ("free", P.L)], 0.0)
        sysm = _System(segs, False)
        return AnalyticSolution(P, "slip", segs, np.zeros(sysm.n), sysm, 0.0, x_star=P.x2)
    s = float(np.sign(P.e0))

    def resid(d):
        return _slip_system(P, P.x2 - d, s)[3]

    ds = np.unique(np.concatenate([[0.0], ell * np.logspace(-13, 0, 131),
                                   np.linspace(0.0, ell, 65)]))
    rs = np.array([resid(d) for d in ds])
    if not np.all(np.isfinite(rs)):
        raise NoSolutionError("slip solution: non-finite material-length residual")
    candidates = []
    for j in range(len(ds) - 1):
        if rs[j] == 0.0:
            candidates.append(ds[j])
        elif rs[j] * rs[j + 1] < 0.0:
            candidates.append(brentq(resid, ds[j], ds[j + 1], xtol=1e-15 * ell, rtol=1e-15,
                                     maxiter=200))
    if rs[-1] == 0.0:
        candidates.append(ds[-1])
    admissible = []
    for d in candidates:
        segs, sysm, z, _ = _slip_system(P, P.x2 - d, s)
        sol = AnalyticSolution(P, "slip", segs, z, sysm, s, x_star=P.x2 - d)
        if _admissible(sol):
            admissible.append(sol)
    if admissible:
        # the stick zone is the longest admissible one (smallest slip zone)
        return min(admissible, key=lambda sol: P.x2 - sol.x_star)
    full = _full_slip(P, s)
    if _admissible(full):
        return full
    raise NoSolutionError(
        f"slip solution: no admissible slip start x* in [{P.x1:.6g}, {P.x2:.6g}] "
        f"(f* = {P.fstar:.6g} N/m, v/c - 1 = {P.e0:.6g}; {len(candidates)} root(s) found, "
        f"none with |f| <= f* in stick and consistent sliding direction)")


def _admissible(sol: AnalyticSolution, rtol=1e-7) -> bool:
    """Coulomb's law holds: abs(f) <= f* in stick, and sliding opposes the traction."""
    P = sol.params
    for i, seg in enumerate(sol.segments):
        if seg.length <= 0.0:
            continue
        xs = np.linspace(seg.p, seg.q, 201)
        if seg.kind == "stick":
            f = P.B * 0.5 * P.h * seg.k**2 * sol._theta(i, xs)
            if np.max(np.abs(f)) > P.fstar * (1.0 + rtol):
                return False
        elif seg.kind == "slip":
            eps = sol._eps0[i] - sol.s * P.fstar * (xs - seg.p) / P.B
            eps_b = eps + 0.5 * P.h * sol._theta_prime(i, xs)
            # the sliding velocity c (eps_b - e0) must oppose the traction s f*; the
            # bound allows the round-off of theta_p ~ h f*/(2 b2) at huge f*
            tol = 10 * rtol * abs(P.e0) + 1e-13 * P.h * seg.k * abs(seg.theta_p)
            if np.min(sol.s * (P.e0 - eps_b)) < -tol:
                return False
    return True


def solve(scene_or_params, model: str | None = None) -> AnalyticSolution:
    """The analytic steady solution of a scene.

    model: "stick" or "slip"; default follows contact.friction ("stick" ->
    perfect adhesion, "coulomb" -> stick and slip).
    """
    P = scene_or_params.params if isinstance(scene_or_params, Scene) else scene_or_params
    if model is None:
        model = "stick" if P.friction == "stick" else "slip"
    if model not in ("stick", "slip"):
        raise ValueError(f"model: must be 'stick' or 'slip', got {model!r}")
    return _solved(P, model)


def clear_cache() -> None:
    """Forget the steady states solved so far (:func:`solve` keeps the last 64), so that
    the next solve of each is done again."""
    _solved.cache_clear()


@functools.lru_cache(maxsize=64)
def _solved(P: Params, model: str) -> AnalyticSolution:
    """One solve per physics: a run asks for its exact state up to three times (its
    error block, its stability check, its slip-start estimate)."""
    return solve_stick(P) if model == "stick" else solve_slip(P)
