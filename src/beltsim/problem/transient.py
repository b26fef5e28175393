"""Exact transient of the thin quasistatic belt: the axially moving bar in frictional contact.

Limit case
----------
``physics.inertia = false`` and a thin belt, ``beam.height`` h -> 0, while
``[stiffness]`` holds a, b1, b2 fixed. The belt's height enters the model only
through the lever h/2 of the friction in the rotation equation and through the
bottom fibre u_b = u + (h/2) theta of the slip velocity. The rotation equation
a theta'' - b2 theta + (h/2) f = 0 (theta = 0 at 0, L) gives theta = O(h f / b2),
or O(h F / (a beta)) at a concentrated force F, so u_b - u and the bottom-fibre
strain correction (h/2) theta' are O(h^2): in the limit theta = 0, u_b = u, and
the belt is an axially moving bar (B = b1, no mass)::

    b1 u_xx + f = 0 on (0, L),   u(0, t) = u(L, t) = 0,   u = 0 for t <= 0,
    f = 0 off [x1, x2];  on [x1, x2] Coulomb's law for f and the slip velocity
    v_rel = u_t + c u_x - m(t),   m(t) = v(t) - c = (v - c) s(t / T),

s the C2 smoothstep of :mod:`beltsim.problem.drive` (s(r) = r^3 (10 - 15 r + 6 r^2)
on [0, 1]), T = ``numerics.ramp_time`` (default 2 L / c, as in
:func:`beltsim.solvers.settings.resolve`). Stick: v_rel = 0, any f ("stick" scenes,
perfect adhesion) or abs(f) <= f* ("coulomb"); slip: f = -f* sign(v_rel).

How thin is thin: the O(h^2) deviations are, relative to the strain scale abs(e0) =
abs(v/c - 1) (total friction, strains)::

    eta = (h/2)^2 max(b1 / a,  f* / (abs(e0) sqrt(a b2)))

(the first from a concentrated force or a stick layer, whose theta jumps by
(h/2) F / a in slope; the second from the slip zone, where theta ~ h f* / (2 b2)
varies over 1/beta = sqrt(a / b2); without f* only the first). A scene counts as
thin when eta <= ``THIN_TOL`` = 1e-6, far below any grid error the comparison
resolves; the paper's data with h = 1e-6 m and [stiffness] from h = 0.1 m give
eta = 3e-10. The deviation is O(eta), as the exact steady solutions
(:mod:`beltsim.problem.analytic`, any h) confirm against this limit. Without
[stiffness] a, b1, b2 follow h, b1 / a = 12 / h^2, and eta >= 3 whatever h: such a
scene is refused.

Derivation
----------
Free spans (f = 0): u is linear in x. With eps = u_x::

    u = eps_in(t) x on [0, x1],   u = -eps_out(t) (L - x) on [x2, L].

Stick: v_rel = 0 means Du/Dt = u_t + c u_x = m(t): a stuck particle moves with the
surface, and (d/dx) gives eps_t + c eps_x = 0: it carries the strain it entered the
contact with. The friction is bounded at x1, so u and eps are continuous there, and
the stick condition at x1 with u_t(x1, t) = x1 eps_in'(t) gives the inlet ODE::

    x1 eps_in' = m(t) - c eps_in,   eps_in(0) = 0,                        (1)

a first-order filter of m / c with rate k = c / x1. The particle at x in
[x1, x*] at time t entered at tau = t - (x - x1) / c (tau < 0: it was at rest), so::

    eps(x, t) = eps_in(tau),   u(x, t) = x1 eps_in(tau) + M(t) - M(tau),
    f(x, t) = -b1 eps_x = b1 eps_in'(tau) / c,   M(t) = integral of m over [0, t].   (2)

Closed forms: with q = x1 / (c T) and r = t / T, for 0 < t <= T the polynomial
particular solution of (1) minus its value at 0 times e^{-k t},

    eps_in = p(t) - p(0) e^{-k t},   p(t) = (v - c)/c  sum_{n=0..5} (-q)^n s^(n)(r),

(used for q <= 1; for q > 1, a ramp shorter than 1/k, the sum cancels and
eps_in is the convolution (k/c) int_0^t e^{-k (t - t')} m(t') dt' by 40-point
Gauss-Legendre quadrature, exact to round-off for k t < 1); for t > T
eps_in = e0 + (eps_in(T) - e0) e^{-k (t - T)}, and for T = 0 eps_in = e0 (1 - e^{-k t}).
M(t) = (v - c) (t - T R(t / T)), R(r) = r - 5/2 r^4 + 3 r^5 - r^6 on [0, 1], R = 1/2
beyond; differences of M are formed from R, without cancellation. The outlet strain
follows from u(L) = 0, i.e. the integral of eps over [0, L] vanishes (material length).
The equilibrium of the whole bar gives the total friction on the belt (distributed
traction plus any concentrated force) as the jump of the tension across the contact::

    total friction = b1 (eps_in - eps_out).                                 (3)

Perfect adhesion ("stick"): stick on all of [x1, x2]; the tension jumps at x2 by a
concentrated force F. With u2 = u(x2, t) from (2) at x = x2 (tau2 = t - (x2 - x1)/c)::

    eps_out = -u2 / (L - x2),   F = b1 (eps_in(tau2) - eps_out),
    distributed friction = b1 (eps_in(t) - eps_in(tau2)).

Coulomb: the adhesion solution's F > 0 (for every t > 0) is a traction no finite
f* can carry, so a slip zone (x*, x2] opens from x2 at once, in which f = s f*,
s = sign(v - c), and eps_x = -s f* / b1; eps is continuous at x* and at x2 (no
concentrated force), so with e* = eps_in(tau*), tau* = t - (x* - x1) / c and
d = x2 - x*::

    eps = e* - s f* (x - x*) / b1 on [x*, x2],   eps_out = e* - s f* d / b1,
    G(x*, t) = u(x*, t) + (L - x*) e* - s (f* / b1) d (d / 2 + L - x2) = 0,        (4)

(4) being u(L) = 0. dG/dx* = (L - x*) (s f* / b1 - eps_in'(tau*) / c) has the sign
of s under (A2) below, and s G(x2, t) = s (L - x2) F(t) / b1 > 0 for t > 0, so (4) has
exactly one root in [x1, x2] under (A3); it is found by Brent's method to 1e-15 L.
Then, from (3)::

    stick friction = b1 (eps_in(t) - e*),   slip friction = s f* d.

Assumptions (checked; a scene outside them raises SceneError naming the key):

* (A1) monotone loading: the drive ramps monotonically (the smoothstep does), so m'
  has one sign, and by (1) so does eps_in' (the filter of m' / c); abs(eps_in) grows
  monotonically to abs(e0).
* (A2) the stick traction stays below the limit: b1 max abs(eps_in') / c < f*.
* (A3) a stick zone remains: L abs(e0) < (f* / b1) l (l / 2 + L - x2), l = x2 - x1
  (else the whole contact slides in the end, the stick condition at x1 that gives (1)
  is lost, and this solution does not apply).

Under them the fields built here meet every condition of the problem (the tests
also check them by finite differences of u, not by these formulas): the traction in
stick b1 eps_in'(tau) / c has the sign of s and stays below f* (A1, A2);
in the slip zone d v_rel / dx = (1 - x*'/c) (eps_in'(tau*) - s c f* / b1) has the
sign of -s, so v_rel (zero at x*) opposes f there; dG/dt = m - c e* + (L - x*)
eps_in'(tau*) has the sign of s by (1) and (A1), so x*' = -G_t / G_x* <= 0: the slip
zone only grows, no material ever re-sticks, and every stuck particle has been stuck
since x1, as (2) assumes. With (A3) the inlet never slides (s G(x1, t) < 0).

What is exact: eps_in, M and everything in the stick scene are closed forms; x*(t)
is the root of the closed-form scalar equation (4), to 1e-15 L; the totals follow from
it in closed form. "Exact" refers to the limit problem: h -> 0 (the O(eta) of the
scene's actual h is left out), unregularised Coulomb friction (v_reg -> 0) and perfect
adhesion (adhesion layer delta -> 0); a simulation carries the errors of its v_reg and
delta on top of its grid and time-step errors. The derivation is also written out in
docs/theory/exact-solutions.md, "The thin-belt transient".
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq, minimize_scalar

from ..errors import SceneError
from .scene import Scene
from .validation import Params

#: Largest eta = (h/2)^2 max(b1/a, f*/(|e0| sqrt(a b2))) of a thin belt (relative
#: O(h^2) deviation of strains and friction totals from the bar limit).
THIN_TOL = 1e-6

# 40-point Gauss-Legendre nodes and weights on [0, 1] (short ramps, k T < 1)
_GL_X, _GL_W = np.polynomial.legendre.leggauss(40)
_GL_X = 0.5 * (_GL_X + 1.0)
_GL_W = 0.5 * _GL_W


def smoothstep_derivatives(r):
    """s(r) and its five derivatives (rows 0..5) at r in [0, 1]."""
    r = np.asarray(r, dtype=float)
    one = np.ones_like(r)
    return np.array([
        r**3 * (10.0 - 15.0 * r + 6.0 * r * r),
        30.0 * r * r * (1.0 - r) ** 2,
        60.0 * r - 180.0 * r * r + 120.0 * r**3,
        60.0 - 360.0 * r + 360.0 * r * r,
        -360.0 + 720.0 * r,
        720.0 * one,
    ])


class ThinBeltTransient:
    """The exact transient of a thin quasistatic scene (see the module docstring).

    Built by :func:`thin_belt`, which checks the scene; methods take arrays of times.
    """

    def __init__(self, params: Params, ramp_time: float):
        self.params = P = params
        self.T = float(ramp_time)
        self.dv = P.v - P.c  # v - c
        self.s = float(np.sign(self.dv))
        self.e0 = self.dv / P.c
        self.k = P.c / P.x1  # rate of the inlet filter (1)
        self.ell = P.x2 - P.x1
        self.coulomb = P.friction == "coulomb"
        if self.T > 0.0:
            self.q = P.x1 / (P.c * self.T)  # = 1 / (k T)
            self._p0 = self._particular(np.zeros(1))[0]
            self._eps_T = float(self._eps_ramp(np.array([self.T]))[0])

    # drive --------------------------------------------------------------
    def mismatch(self, t):
        """m(t) = v(t) - c."""
        t = np.asarray(t, dtype=float)
        if self.T <= 0.0:
            return np.where(t > 0.0, self.dv, 0.0)
        r = np.clip(t / self.T, 0.0, 1.0)
        return self.dv * smoothstep_derivatives(r)[0]

    def _R(self, t):
        """M(t) = (v - c) (t - T R(t / T)) with R bounded (no cancellation)."""
        r = np.asarray(t, dtype=float) / self.T
        rc = np.clip(r, 0.0, 1.0)
        inner = rc - 2.5 * rc**4 + 3.0 * rc**5 - rc**6
        return np.where(r <= 0.0, r, np.where(r >= 1.0, 0.5, inner))

    def mismatch_integral(self, t0, t1):
        """M(t1) - M(t0), the surface's extra travel between t0 and t1 (m(t) = 0 for t < 0)."""
        t0 = np.asarray(t0, dtype=float)
        t1 = np.asarray(t1, dtype=float)
        if self.T <= 0.0:
            return self.dv * (np.maximum(t1, 0.0) - np.maximum(t0, 0.0))
        return self.dv * ((t1 - t0) - self.T * (self._R(t1) - self._R(t0)))

    # inlet strain ------------------------------------------------------
    def _particular(self, t):
        r = np.asarray(t, dtype=float) / self.T
        ds = smoothstep_derivatives(r)
        weights = (-self.q) ** np.arange(6)
        return self.e0 * (weights @ ds)

    def _eps_ramp(self, t):
        """eps_in on 0 <= t <= T."""
        t = np.asarray(t, dtype=float)
        if self.q <= 1.0:
            return self._particular(t) - self._p0 * np.exp(-self.k * t)
        # convolution (k/c) int_0^t e^{-k (t - t')} m(t') dt', t' = t sigma
        tt = t[..., None]
        tp = tt * _GL_X
        vals = np.exp(-self.k * (tt - tp)) * self.mismatch(tp)
        return (self.k / self.params.c) * t * (vals @ _GL_W)

    def inlet_strain(self, t):
        """eps_in(t), the strain of the inlet span [0, x1] (0 for t <= 0)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        out = np.zeros_like(t)
        pos = t > 0.0
        if self.T <= 0.0:
            out[pos] = self.e0 * -np.expm1(-self.k * t[pos])
            return out
        ramp = pos & (t <= self.T)
        out[ramp] = self._eps_ramp(t[ramp])
        after = t > self.T
        out[after] = self.e0 + (self._eps_T - self.e0) * np.exp(-self.k * (t[after] - self.T))
        return out

    def inlet_strain_rate(self, t):
        """eps_in'(t) = (m(t) - c eps_in(t)) / x1, from (1)."""
        P = self.params
        return (self.mismatch(t) - P.c * self.inlet_strain(t)) / P.x1

    def max_inlet_strain_rate(self):
        """max abs(eps_in') over t > 0 (attained during the ramp; then it decays)."""
        if self.T <= 0.0:
            return abs(self.dv) / self.params.x1  # at t = 0+
        ts = np.linspace(0.0, self.T, 4001)
        rate = np.abs(self.inlet_strain_rate(ts))
        i = int(np.argmax(rate))
        lo, hi = ts[max(i - 1, 0)], ts[min(i + 1, len(ts) - 1)]
        res = minimize_scalar(lambda x: -abs(self.inlet_strain_rate(x)[0]), bounds=(lo, hi),
                              method="bounded", options={"xatol": 1e-12 * self.T})
        return max(float(rate[i]), -float(res.fun))

    # stick zone ---------------------------------------------------------
    def stick_displacement(self, x, t):
        """u(x, t) of (2) for a particle stuck since x1 (x in [x1, x*])."""
        P = self.params
        tau = np.asarray(t, dtype=float) - (np.asarray(x, dtype=float) - P.x1) / P.c
        return P.x1 * self.inlet_strain(tau) + self.mismatch_integral(tau, t)

    def _length_residual(self, x_star, t):
        """s G(x*, t) of (4), relative to L abs(e0)."""
        P = self.params
        d = P.x2 - x_star
        e_star = self.inlet_strain(t - (x_star - P.x1) / P.c)[0]
        u_star = self.stick_displacement(x_star, t)[0]
        G = u_star + (P.L - x_star) * e_star - self.s * P.fstar * d * (0.5 * d + P.L - P.x2) / P.b1
        return self.s * G / (P.L * abs(self.e0))

    def slip_start(self, t):
        """x*(t): the root of (4); x2 at t <= 0 (no slip zone yet)."""
        P = self.params
        t = np.atleast_1d(np.asarray(t, dtype=float))
        out = np.full_like(t, P.x2)
        if self.dv == 0.0:
            return out
        for i, ti in enumerate(t):
            if ti <= 0.0:
                continue
            g2 = self._length_residual(P.x2, ti)
            if g2 <= 0.0:  # u(x2) and eps_in below round-off: no slip zone yet
                continue
            out[i] = brentq(self._length_residual, P.x1, P.x2, args=(ti,), xtol=1e-15 * P.L,
                            rtol=1e-15, maxiter=200)
        return out

    # histories ----------------------------------------------------------
    def history(self, times) -> dict:
        """The totals against time (arrays; forces in N, strains, positions in m)."""
        P = self.params
        t = np.atleast_1d(np.asarray(times, dtype=float))
        eps_in = self.inlet_strain(t)
        out = {"t": t, "inlet_strain": eps_in}
        if self.coulomb:
            xs = self.slip_start(t)
            d = P.x2 - xs
            e_star = self.inlet_strain(t - (xs - P.x1) / P.c)
            stick = P.b1 * (eps_in - e_star)
            slip = self.s * P.fstar * d
            out.update(slip_start=xs, stick_friction=stick, slip_friction=slip,
                       outlet_strain=e_star - self.s * P.fstar * d / P.b1,
                       total_friction=stick + slip)
        else:
            u2 = self.stick_displacement(np.full_like(t, P.x2), t)
            eps_out = -u2 / (P.L - P.x2)
            eps2 = self.inlet_strain(t - self.ell / P.c)
            out.update(outlet_strain=eps_out,
                       concentrated_force=P.b1 * (eps2 - eps_out),
                       distributed_friction=P.b1 * (eps_in - eps2),
                       total_friction=P.b1 * (eps_in - eps_out))
        return out

    def steady(self) -> dict:
        """The t -> infinity limits: total friction, and slip start (coulomb)."""
        P = self.params
        if not self.coulomb:
            return {"total_friction": P.b1 * self.e0 * P.L / (P.L - P.x2), "slip_start": None}
        # (4) with e* = eps_in = e0: d (d/2 + a) = X, the root without cancellation
        a, X = P.L - P.x2, P.b1 * abs(self.e0) * P.L / P.fstar
        d = 2.0 * X / (a + math.sqrt(a * a + 2.0 * X))
        return {"total_friction": self.s * P.fstar * d, "slip_start": P.x2 - d}

    # fields -------------------------------------------------------------
    def fields(self, x, t) -> dict:
        """u, strain and traction f at the points x and one time t (the concentrated
        force of a stick scene is not in f; x* = x2 there)."""
        P = self.params
        x = np.atleast_1d(np.asarray(x, dtype=float))
        eps_in = self.inlet_strain(t)[0]
        xs = self.slip_start(t)[0] if self.coulomb else P.x2
        tau = t - (x - P.x1) / P.c
        u = np.zeros_like(x)
        eps = np.zeros_like(x)
        f = np.zeros_like(x)
        inlet = x <= P.x1
        u[inlet], eps[inlet] = eps_in * x[inlet], eps_in
        stick = (x > P.x1) & (x <= xs)
        u[stick] = self.stick_displacement(x[stick], t)
        eps[stick] = self.inlet_strain(tau[stick])
        f[stick] = P.b1 * self.inlet_strain_rate(tau[stick]) / P.c
        e_star = self.inlet_strain(t - (xs - P.x1) / P.c)[0]
        u_star = self.stick_displacement(xs, t)[0]
        slip = (x > xs) & (x <= P.x2)
        if np.any(slip):
            dx = x[slip] - xs
            fs = self.s * P.fstar
            u[slip] = u_star + e_star * dx - fs * dx * dx / (2.0 * P.b1)
            eps[slip] = e_star - fs * dx / P.b1
            f[slip] = fs
        outlet = x > P.x2
        eps_out = self.history([t])["outlet_strain"][0]
        u[outlet], eps[outlet] = -eps_out * (P.L - x[outlet]), eps_out
        return {"u": u, "strain": eps, "friction": f}


def default_ramp_time(P: Params) -> float:
    """numerics.ramp_time's default, 2 L / c (as beltsim.solvers.settings.resolve sets it)."""
    return 2.0 * P.L / P.c


def thin_parameter(P: Params) -> float:
    """eta = (h/2)^2 max(b1/a, f*/(abs(e0) sqrt(a b2))): the relative O(h^2) deviation scale."""
    eta = P.b1 / P.a
    if P.friction == "coulomb" and P.e0 != 0.0:
        eta = max(eta, P.fstar / (abs(P.e0) * math.sqrt(P.a * P.b2)))
    return (0.5 * P.h) ** 2 * eta


def thin_belt(scene: Scene) -> ThinBeltTransient:
    """The exact thin-belt transient of a scene; SceneError if the scene is not of that kind."""
    P = scene.params
    if P.inertia:
        raise SceneError("physics.inertia: the thin-belt transient needs physics.inertia = "
                         "false (quasistatic), got true")
    data = scene.to_dict()
    for key, raw in (("motion.surface_speed", data["motion"]["surface_speed"]),
                     ("contact.max_friction", data["contact"].get("max_friction", 0.0))):
        if not isinstance(raw, float):
            raise SceneError(f"{key}: the thin-belt transient is derived for a number (the "
                             f"smooth start-up at constant f*), got a profile")
    eta = thin_parameter(P)
    if eta > THIN_TOL:
        raise SceneError(
            f"beam.height: the thin-belt transient needs eta = (h/2)^2 max(b1/a, f*/(|e0| "
            f"sqrt(a b2))) <= {THIN_TOL:g}, got {eta:.3g} (keep a, b1, b2 in [stiffness] and "
            f"take h -> 0)")
    T = scene.numerics.get("ramp_time", default_ramp_time(P))
    sol = ThinBeltTransient(P, T)
    if P.friction == "coulomb" and P.e0 != 0.0:
        ell = P.x2 - P.x1
        stick_max = P.b1 * sol.max_inlet_strain_rate() / P.c
        if stick_max >= P.fstar:
            raise SceneError(
                f"contact.max_friction: the inlet's stick traction b1 max|eps_in'|/c = "
                f"{stick_max:.6g} N/m reaches f* = {P.fstar:.6g} N/m (slip inside the stick "
                f"zone: outside the thin-belt transient's regime; lengthen numerics.ramp_time)")
        need = P.b1 * P.L * abs(P.e0) / (ell * (0.5 * ell + P.L - P.x2))
        if P.fstar <= need:
            raise SceneError(
                f"contact.max_friction: the whole contact slides in the end for f* <= "
                f"b1 L |e0| / (l (l/2 + L - x2)) = {need:.6g} N/m, got {P.fstar:.6g} N/m "
                f"(outside the thin-belt transient's regime)")
    return sol


def thin_belt_transient(scene: Scene, times) -> dict:
    """Exact total friction of a thin quasistatic scene at ``times`` (s).

    Returns arrays over ``times``: ``t``, ``total_friction`` (N, on the belt),
    ``inlet_strain``, ``outlet_strain``, and for coulomb scenes ``slip_start`` (m),
    ``stick_friction``, ``slip_friction`` (N), for stick scenes
    ``concentrated_force`` and ``distributed_friction`` (N). Raises SceneError when
    the scene is not of the limit type (see the module docstring).
    """
    return thin_belt(scene).history(times)
