"""Implicit scheme: variable-step BDF2, second order in time, with adaptive steps.

The semi-discrete model is second order in time; BDF2 is applied to it as a first-
order system in (u, v = u_t): with the step h_n and the ratio r = h_n / h_{n-1},

    y'_{n+1} = a0 (y_{n+1} - y*),  a0 = (1 + 2r) / ((1 + r) h_n),
    y* = ((1 + r)^2 y_n - r^2 y_{n-1}) / (1 + 2r)

for y = u, theta (giving the velocities) and y = v, w (giving the accelerations).
That is the residual of :func:`beltsim.physics.model.assemble` with ``inv_dt`` = a0
and the previous state replaced by y*, so one Newton solve per step, as for backward
Euler (which is the first step, with no history). BDF2 is A- and L-stable: the stiff
friction relaxation and the unresolved high frequencies are damped, the resolved
ones carry an error of order h^2. Zero-stability of the variable-step formula needs
r < 1 + sqrt(2); the controller keeps r <= MAX_GROWTH.

Local error: BDF2's leading term is (2/9) h^3 y''' at a constant step; u''' is
estimated from the change of the computed acceleration over the step,
e = (2/9) h^2 (a_{n+1} - a_n) (for the first, backward-Euler step: h^2/2 (a_1 - a_0)).
Raw, that estimate is large for stiff components (high-frequency modes, the friction
relaxation) that BDF2 damps and need not follow: it is filtered as in Hairer and
Wanner's Radau code, solving J e_f = T e with the step's Newton matrix J and its
time-derivative part T (a0^2 M + a0 (d M + G + friction)), so resolved components
(J ~ T) keep their estimate and stiff ones (J >> T) drop out. The step is accepted
when the scaled max norm of e_f (u over e0 L, theta over e0) is below ``time_tol``;
the next one is h (SAFETY time_tol / err)^(1/3), within [MIN_SHRINK, MAX_GROWTH]
times the last. A rejected step or a failed Newton solve is
retried with a smaller step. Steps end exactly at the controller's checks, so runs
with different tolerances can be compared at the same times.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from ..physics.friction import EXACT
from ..physics.model import LAM_MAX, POWER_TERMS, loop_speed, power_terms, rate_part
from ..problem.drive import friction_factor
from .newton import FAILED, NONFINITE, OK, NewtonScheme, linear_solve, newton, on_path
from .registry import register

SAFETY = 0.8
MAX_GROWTH = 2.0  # largest ratio of successive steps (zero-stable below 1 + sqrt(2))
MIN_SHRINK = 0.2
BDF2_ERROR = 2.0 / 9.0  # leading error constant of BDF2 at a constant step
NEWTON_CUT = 0.25  # step factor after a failed Newton solve


@njit(cache=True, no_cpython_wrapper=True)
def step_factor(err, tol, ok, max_growth):
    """The next step over this one under local error control (error ~ h^3): after a
    converged step with error estimate err, SAFETY (tol / err)^(1/3) within [MIN_SHRINK,
    max_growth]; after a failed Newton solve (ok false), NEWTON_CUT."""
    if not ok:
        return NEWTON_CUT
    if err == 0.0:
        return max_growth
    return min(max_growth, max(MIN_SHRINK, SAFETY * (tol / err) ** (1.0 / 3.0)))


@njit(cache=True, no_cpython_wrapper=True)
def copy_state(u, th, ud, td, lam, u_n, th_n, ud_n, td_n, lam_n):
    """(u, th, ud, td, lam) = (u_n, ...): the state saved at t_n, or a rejected step's
    state back to t_n."""
    for j in range(u.shape[0]):
        u[j], th[j], ud[j], td[j], lam[j] = u_n[j], th_n[j], ud_n[j], td_n[j], lam_n[j]


@njit(cache=True, no_cpython_wrapper=True)
def copy_globals(g, gd, g_n, gd_n):
    """(g, gd) = (g_n, gd_n): a loop's global unknowns and their rates."""
    for k in range(g.shape[0]):
        g[k], gd[k] = g_n[k], gd_n[k]


@njit(cache=True, no_cpython_wrapper=True)
def landing_step(remaining, h_next, h_max):
    """The step that ends on the stop time: the remaining span in equal parts of at most
    min(h_next, h_max)."""
    parts = math.ceil(remaining / min(h_next, h_max) * (1.0 - 1e-12))
    return remaining / parts, parts


class History(NamedTuple):
    """What BDF2 keeps of the past: the previous step's state and the accelerations now."""

    u: np.ndarray  # u, theta, u_t, theta_t at t_{n-1}
    theta: np.ndarray
    ud: np.ndarray
    td: np.ndarray
    au: np.ndarray  # u_tt, theta_tt at t_n
    at: np.ndarray
    lam: np.ndarray  # the friction unknowns at t_{n-1} (the Newton predictor's)
    g: np.ndarray = np.zeros(0)  # a loop's globals and their rates at t_{n-1}
    gd: np.ndarray = np.zeros(0)

    @classmethod
    def zeros(cls, n_nodes, n_globals=0):
        """All zero on ``n_nodes`` nodes with ``n_globals`` globals."""
        return cls(*(np.zeros(n_nodes) for _ in range(7)), np.zeros(n_globals),
                   np.zeros(n_globals))


@njit(cache=True, no_cpython_wrapper=True)
def filtered_error(e, eg, a0, fs, c, mesh, p, w, out, outg):
    """Solve J e_f = T e in place of ``e`` (n, 2) and a loop's ``eg`` (ng); J: the step's
    Newton matrix, T: its a0 part.

    J is applied through the block LU the Newton solve left in ``w``, T
    (:func:`beltsim.physics.model.rate_part`) takes the friction slopes of that J
    (w.sgf); fs: the friction scale at the step's time (f* times the profile's factor),
    c the belt speed. ``out`` (and ``outg``) receive T e.
    """
    rate_part(e, eg, a0, fs, w.sgf, w.bs, c, mesh, p, out, outg)
    linear_solve(w, mesh, out, outg, e, eg)


@njit(cache=True, no_cpython_wrapper=True)
def predict_friction(lam, lam_prev, r, mesh, code):
    """Extrapolate the friction ratios lam (at t_n, in place) linearly to t_n + r (t_n - t_{n-1}).

    Kept inside the bounds of the primal-dual iteration (+-LAM_MAX): a node that
    reaches slip in the step starts there, and one that the extrapolation takes to
    the bound wrongly is caught by Newton's check of the ratios at the bound
    (:func:`beltsim.solvers.dual.release_stuck_ratios`). The exact laws take the
    extrapolation as it is: a Coulomb ratio beyond +-1 starts the semi-smooth Newton
    with the node sliding (its first update puts it on the bound), which saves
    iterations where the slip front moves fast.
    """
    bound = math.inf if code >= EXACT else LAM_MAX
    for j in mesh.cn:
        lam[j] = min(bound, max(-bound, lam[j] + r * (lam[j] - lam_prev[j])))


@njit(cache=True)
def advance_bdf2(state, hist, base, t, t_stop, h_prev, h_next, h_min, h_max, tol, max_steps,
                 mesh, p, drive, loads, scales, settings, w, power, work):
    """Adaptive BDF2 steps from t until t_stop (reached exactly) or max_steps.

    ``state`` holds u, theta, the friction unknowns and u_t, theta_t at t (and a loop's
    globals with their rates); ``hist`` the previous step (h_prev = 0: there is none,
    the next step is backward Euler); ``base`` is workspace for y*; ``power`` holds the
    power terms at t (physics.model.POWER_TERMS) and ``work`` accumulates their
    integrals over the accepted steps (trapezoidal rule, second order like the scheme).
    A loop's globals are first-order unknowns: their local error (2/9) h^3 g^(3) comes
    from the change of their rates over the last two steps. Returns (status, t, h_prev,
    h_next, steps, rejected).
    """
    u, th, lam, ud, td = state.u, state.theta, state.lam, state.ud, state.td
    g, gd = state.g, state.gd
    nodes = u.shape[0]
    off = mesh.off
    n = w.R.shape[0]
    ng = g.shape[0]
    steps = 0
    rejected = 0
    u_n = np.empty(nodes)
    th_n = np.empty(nodes)
    ud_n = np.empty(nodes)
    td_n = np.empty(nodes)
    lam_n = np.empty(nodes)
    g_n = np.empty(ng)
    gd_n = np.empty(ng)
    au_new = np.empty(nodes)
    at_new = np.empty(nodes)
    p_new = np.empty(power.shape[0])
    e = np.empty((n, 2))
    te = np.empty((n, 2))
    eg = np.empty(ng)
    teg = np.empty(ng)
    while t < t_stop and steps < max_steps:
        remaining = t_stop - t
        if remaining <= 1e-9 * h_next:  # round-off of the caller's times, not a step
            t = t_stop
            break
        h, parts = landing_step(remaining, h_next, h_max)
        copy_state(u_n, th_n, ud_n, td_n, lam_n, u, th, ud, td, lam)
        copy_globals(g_n, gd_n, g, gd)
        if h_prev > 0.0:
            r = h / h_prev
            a0 = (1.0 + 2.0 * r) / ((1.0 + r) * h)
            cn = (1.0 + r) * (1.0 + r) / (1.0 + 2.0 * r)
            cp = r * r / (1.0 + 2.0 * r)
            for j in range(nodes):
                base.u[j] = cn * u_n[j] - cp * hist.u[j]
                base.theta[j] = cn * th_n[j] - cp * hist.theta[j]
                base.ud[j] = cn * ud_n[j] - cp * hist.ud[j]
                base.td[j] = cn * td_n[j] - cp * hist.td[j]
            for k in range(ng):
                base.g[k] = cn * g_n[k] - cp * hist.g[k]
            err_const = BDF2_ERROR
        else:
            a0 = 1.0 / h
            for j in range(nodes):
                base.u[j], base.theta[j] = u_n[j], th_n[j]
                base.ud[j], base.td[j] = ud_n[j], td_n[j]
            for k in range(ng):
                base.g[k] = g_n[k]
            err_const = 0.5
        # predictor: second-order Taylor step with the current accelerations
        for i in range(n):
            j = i + off
            u[j] = u_n[j] + h * ud_n[j] + 0.5 * h * h * hist.au[j]
            th[j] = th_n[j] + h * td_n[j] + 0.5 * h * h * hist.at[j]
        for k in range(ng):
            g[k] = g_n[k] + h * gd_n[k]
        if h_prev > 0.0:
            predict_friction(lam, hist.lam, h / h_prev, mesh, p.law)
        ok = (newton(state, base, a0, t + h, mesh, p, drive, loads, scales, settings, w)
              and on_path(g, g_n, scales))
        err = 0.0
        finite = True
        if ok:
            for j in range(nodes):
                ud[j] = a0 * (u[j] - base.u[j])
                td[j] = a0 * (th[j] - base.theta[j])
                au_new[j] = a0 * (ud[j] - base.ud[j])
                at_new[j] = a0 * (td[j] - base.td[j])
                if not (np.isfinite(u[j]) and np.isfinite(th[j])):
                    finite = False
            for k in range(ng):
                gd[k] = a0 * (g[k] - base.g[k])
                if not np.isfinite(g[k]):
                    finite = False
                # the third derivative from the rates at t_{n-1}, t_n, t_{n+1}
                eg[k] = 0.0
                if h_prev > 0.0:
                    g3 = ((gd[k] - gd_n[k]) / h - (gd_n[k] - hist.gd[k]) / h_prev) \
                        / (0.5 * (h + h_prev))
                    eg[k] = err_const * h * h * h * g3
            for i in range(n):
                j = i + off
                e[i, 0] = err_const * h * h * (au_new[j] - hist.au[j])
                e[i, 1] = err_const * h * h * (at_new[j] - hist.at[j])
            filtered_error(e, eg, a0, p.friction_scale * friction_factor(drive, t + h),
                           loop_speed(g, mesh, p), mesh, p, w, te, teg)
            for i in range(n):
                err = max(err, abs(e[i, 0]) / scales.u, abs(e[i, 1]) / scales.theta)
            for k in range(ng):
                err = max(err, abs(eg[k]) / scales.glob[k])
            if not math.isfinite(err):
                err = np.inf
        if ok and not finite:
            copy_state(u, th, ud, td, lam, u_n, th_n, ud_n, td_n, lam_n)
            copy_globals(g, gd, g_n, gd_n)
            return NONFINITE, t, h_prev, h_next, steps, rejected
        if ok and err <= tol:
            for j in range(nodes):
                hist.u[j], hist.theta[j] = u_n[j], th_n[j]
                hist.ud[j], hist.td[j] = ud_n[j], td_n[j]
                hist.au[j], hist.at[j] = au_new[j], at_new[j]
                hist.lam[j] = lam_n[j]
            copy_globals(hist.g, hist.gd, g_n, gd_n)
            t = t_stop if parts == 1 else t + h  # the last part lands on t_stop exactly
            steps += 1
            h_prev = h
            power_terms(state, t, mesh, p, drive, loads, p_new)
            for k in range(power.shape[0]):
                work[k] += 0.5 * h * (power[k] + p_new[k])
                power[k] = p_new[k]
            # ok (true here), not the literal True: one compile of step_factor for both calls
            h_next = h * step_factor(err, tol, ok, MAX_GROWTH)
            continue
        # rejected: back to t_n with a smaller step
        rejected += 1
        w.stats[0].failed_steps += 1
        copy_state(u, th, ud, td, lam, u_n, th_n, ud_n, td_n, lam_n)
        copy_globals(g, gd, g_n, gd_n)
        h_next = h * step_factor(err, tol, ok, MAX_GROWTH)
        if h_next < h_min:
            return FAILED, t, h_prev, h_next, steps, rejected
    return OK, t, h_prev, h_next, steps, rejected


class AdaptiveScheme(NewtonScheme):
    """What the adaptive time-accurate schemes share: the last and the next step, and the
    power terms with their time integrals (the power balance)."""

    def __init__(self, disc):
        super().__init__(disc)
        self.h_prev = 0.0  # no previous step
        self.h_next = self.numerics.dt
        #: the longest step (s): a physical transient's limit (simulation.stability)
        self.max_step = math.inf
        self.power = np.zeros(len(POWER_TERMS))  # at the current time
        self.work_done = np.zeros(len(POWER_TERMS))  # integrals since the start

    @property
    def dt(self) -> float:
        return self.h_next

    def statistics(self) -> dict:
        """The counters, and ``last_step``: the last step taken (s)."""
        return super().statistics() | {"last_step": self.h_prev}

    def work_integrals(self) -> dict:
        """The time integrals (J) of the power terms since the start of the run."""
        return dict(zip(POWER_TERMS, (float(v) for v in self.work_done)))

    def checkpoint(self) -> dict:
        return {**super().checkpoint(), "h": np.array([self.h_prev, self.h_next]),
                "power": self.power.copy(), "work_done": self.work_done.copy()}

    def restore(self, data: dict) -> None:
        super().restore(data)
        self.h_prev, self.h_next = (float(v) for v in data["h"])
        self.power[:], self.work_done[:] = data["power"], data["work_done"]


@register
class ImplicitScheme(AdaptiveScheme):
    """Variable-step BDF2 with local error control (the first step backward Euler)."""

    name = "implicit"

    def __init__(self, disc):
        super().__init__(disc)
        self.hist = History.zeros(len(disc.mesh.hb), disc.n_globals)

    def advance(self, state, t, t_stop, max_steps=10**9):
        d, num = self.disc, self.numerics
        h_max = min(t_stop - t, self.max_step) if t_stop > t else num.dt
        status, t, self.h_prev, self.h_next, steps, _ = advance_bdf2(
            state, self.hist, self.old, t, t_stop, self.h_prev, self.h_next, num.dt * 1e-7,
            h_max, num.time_tol, max_steps, d.mesh, d.model,
            d.drive, d.loads, d.scales, self.settings, self.work, self.power, self.work_done)
        self.steps += steps
        self.check_status(status, t, self.h_next)
        return t

    def checkpoint(self) -> dict:
        return {**super().checkpoint(),
                **{f"hist_{k}": a.copy() for k, a in zip(History._fields, self.hist)}}

    def restore(self, data: dict) -> None:
        super().restore(data)
        for k, a in zip(History._fields, self.hist):
            # a checkpoint of an earlier version has no friction ratios at t_{n-1}: zeros
            # give the next step's Newton solve a worse start, nothing else
            a[:] = data[f"hist_{k}"] if k != "lam" or "hist_lam" in data else 0.0
