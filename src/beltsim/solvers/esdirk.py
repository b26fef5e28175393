"""ESDIRK scheme: Kennedy and Carpenter's ESDIRK3(2)4L[2]SA, third order, adaptive steps.

The semi-discrete model is integrated as a first-order system in y = (q, v), q = (u,
theta), v = q_t, by a four-stage explicit-first-stage, singly diagonally implicit
Runge-Kutta method: stage i solves

    Y_i = y_n + h sum_{j<i} a_ij Y'_j + h gamma Y'_i,

that is v_i = (q_i - q~_i) / (gamma h) and M (v_i - v~_i) / (gamma h) = f(q_i, v_i,
t_n + c_i h), with (q~_i, v~_i) = (q_n, v_n) + h sum_{j<i} a_ij (v_j, a_j). That is the
backward-Euler residual of :func:`beltsim.physics.model.assemble` with ``inv_dt`` =
1 / (gamma h) and the old state (q~_i, v~_i): one Newton solve per implicit stage, three
a step. The first stage is y_n itself with its derivative (v_n, a_n), and the method is
stiffly accurate (the last stage is y_{n+1}, b = the last row of A), so a_n is the last
stage's acceleration of the step before; only the first step computes it from the model
(:func:`initial_acceleration`). The method is L-stable (stiff friction relaxation and
unresolved frequencies are damped as by BDF2) with stage order 2; the coefficients are
the implicit tableau of Kennedy and Carpenter's ARK3(2)4L[2]SA (Appl. Numer. Math. 44,
2003), given as rationals that satisfy the order conditions to about 1e-12.

Local error: the embedded second-order solution b^ gives e = h sum_i (b_i - b^_i) v_i
for q, filtered as the implicit scheme's (J e_f = T e with the last stage's Newton
matrix, :func:`beltsim.solvers.implicit.filtered_error`) so that the stiff components
the method damps drop out, and measured in the same scaled max norm against
``time_tol``. The step advances with the third-order solution; the next step is
h (SAFETY time_tol / err)^(1/3), within [MIN_SHRINK, MAX_GROWTH] times the last. A
rejected step or a failed Newton solve is retried smaller; steps end exactly at the
controller's checks. The power terms are integrated over the step with the method's
own quadrature (weights b at the stage times), third order like the scheme.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from ..physics.friction import EXACT, LINEAR, RAMP, law
from ..physics.model import (
    LAM_MAX,
    RESIDUAL,
    assemble,
    bottom_strain,
    contact_target,
    loop_speed,
    power_terms,
)
from ..problem.drive import friction_factor, mismatch, value
from .implicit import (
    AdaptiveScheme,
    copy_globals,
    copy_state,
    filtered_error,
    landing_step,
    predict_friction,
    step_factor,
)
from .newton import FAILED, NONFINITE, OK, NewtonSettings, newton, on_path
from .registry import register

GAMMA = 1767732205903.0 / 4055673282236.0
A31, A32 = 2746238789719.0 / 10658868560708.0, -640167445237.0 / 6845629431997.0
B1, B2 = 1471266399579.0 / 7840856788654.0, -4482444167858.0 / 7529755066697.0
B3, B4 = 11266239266428.0 / 11593286722821.0, GAMMA
#: the embedded second-order weights
E1, E2 = 2756255671327.0 / 12835298489170.0, -10771552573575.0 / 22201958757719.0
E3, E4 = 9247589265047.0 / 10645013368117.0, 2193209047091.0 / 5459859503100.0
C2, C3 = 2.0 * GAMMA, 0.6
#: the tableau as arrays (tests read them): A (4, 4), b, the embedded b^, c
TABLEAU_A = np.array([[0.0, 0.0, 0.0, 0.0], [GAMMA, GAMMA, 0.0, 0.0],
                      [A31, A32, GAMMA, 0.0], [B1, B2, B3, B4]])
TABLEAU_B = np.array([B1, B2, B3, B4])
TABLEAU_B_HAT = np.array([E1, E2, E3, E4])
TABLEAU_C = np.array([0.0, C2, C3, 1.0])

MAX_GROWTH = 3.0  # a one-step method: no zero-stability bound on the step ratio


class Rates(NamedTuple):
    """What a step starts from beside the state: the accelerations at t_n (the first
    stage's derivative) and the friction ratios at t_{n-1} (the predictor's)."""

    au: np.ndarray
    at: np.ndarray
    lam_prev: np.ndarray

    @classmethod
    def zeros(cls, n_nodes):
        """All zero on ``n_nodes`` nodes."""
        return cls(*(np.zeros(n_nodes) for _ in cls._fields))


def initial_acceleration(state, base, t, mesh, p, drive, loads, w, au, at):
    """The accelerations of ``state`` at t from the model, into au, at (the first step's
    first stage).

    The residual of :func:`~beltsim.physics.model.assemble` with ``inv_dt`` = 1 and the
    old state (u - u_t, theta - theta_t) at the same rates is the equation of motion
    at zero acceleration, so a = -R / (m hbar) (zero where the mass m is). The
    friction ratios are first set from the state's slip velocities
    (:func:`initial_ratios`). A loop's globals keep their rates (state.gd): the old
    globals are g - g_t.

    Called once a run, it is Python around two kernels, the ratios and the same compiled
    assemble that Newton calls: a kernel of its own would compile assemble's code once
    more. Its own arithmetic is elementwise, the kernel's to the bit.
    """
    u, th, ud, td, g = state.u, state.theta, state.ud, state.td, state.g
    initial_ratios(state, t, mesh, p, drive)
    base.u[:] = u - ud
    base.theta[:] = th - td
    base.ud[:] = ud
    base.td[:] = td
    base.g[:] = g - state.gd
    assemble(u, th, state.lam, g, state.fnode, base, 1.0, t, mesh, p, drive, loads, w,
             RESIDUAL)
    n, off = w.R.shape[0], mesh.off
    hb = mesh.hb[off:off + n]
    au[:] = 0.0
    at[:] = 0.0
    if p.mass > 0.0:
        au[off:off + n] = -w.R[:, 0] / (p.mass * hb)
    if p.rotary_inertia > 0.0:
        at[off:off + n] = -w.R[:, 1] / (p.rotary_inertia * hb)


@njit(cache=True)
def initial_ratios(state, t, mesh, p, drive):
    """The friction ratios of ``state`` at t from its slip velocities: by a regularised
    law, or projected as the exact Coulomb law's iteration does (a sliding node then
    carries +-1; a sticking node's ratio and adhesion's are reactions and keep their
    values)."""
    u, th, lam, ud, td, g = state.u, state.theta, state.lam, state.ud, state.td, state.g
    hh, code = p.half_height, p.law
    c = loop_speed(g, mesh, p)
    target = mismatch(drive, t)
    rim = value(drive.speed, t)
    for j in mesh.cn:
        hf = hh * mesh.face[j]
        vrel = (ud[j] + hf * td[j] + c * bottom_strain(u, th, hf, mesh.sw, j)
                - contact_target(mesh.seg[j], c, g, rim, target, mesh, p))
        s = vrel / p.regularisation
        if code == EXACT:
            lam[j] = min(1.0, max(-1.0, lam[j] + s))
        elif code < EXACT:
            gr = law(code, s)[0]
            lam[j] = gr if code == LINEAR or code == RAMP else min(LAM_MAX, max(-LAM_MAX, gr))


@njit(cache=True)
def advance_esdirk(state, rates, base, t, t_stop, h_prev, h_next, h_min, h_max, tol, max_steps,
                   mesh, p, drive, loads, scales, settings, w, power, work):
    """Adaptive ESDIRK3(2)4L[2]SA steps from t until t_stop (reached exactly) or max_steps.

    ``state`` holds u, theta, the friction unknowns and u_t, theta_t at t (and a loop's
    globals with their rates, the globals' first stage derivative); ``rates`` the
    accelerations at t and the friction ratios of the step before (h_prev = 0: there is
    none); ``base`` is workspace for the stages' old state (q~, v~); ``power`` holds the
    power terms at t (physics.model.POWER_TERMS) and ``work`` accumulates their
    integrals over the accepted steps. Returns (status, t, h_prev, h_next, steps,
    rejected).
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
    # the second stage's (u, theta, lam), for the later stages' predictor
    u_2 = np.empty(nodes)
    th_2 = np.empty(nodes)
    lam_2 = np.empty(nodes)
    g_2 = np.empty(ng)
    vu = np.zeros((4, nodes))  # stage velocities and accelerations
    vt = np.zeros((4, nodes))
    au = np.zeros((4, nodes))
    at = np.zeros((4, nodes))
    vg = np.zeros((4, ng))  # the globals' stage rates
    ps = np.empty((4, power.shape[0]))  # power terms at the stages
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
        a0 = 1.0 / (GAMMA * h)
        copy_state(u_n, th_n, ud_n, td_n, lam_n, u, th, ud, td, lam)
        copy_globals(g_n, gd_n, g, gd)
        for j in range(nodes):
            vu[0, j], vt[0, j] = ud[j], td[j]
            au[0, j], at[0, j] = rates.au[j], rates.at[j]
        for k in range(ng):
            vg[0, k] = gd[k]
        for k in range(power.shape[0]):
            ps[0, k] = power[k]
        ok = True
        finite = True
        for i in range(1, 4):
            ci = C2 if i == 1 else (C3 if i == 2 else 1.0)
            # the old state of the stage: y_n + h sum_{j<i} a_ij Y'_j
            if i == 1:
                c0_, c1_, c2_ = GAMMA, 0.0, 0.0
            elif i == 2:
                c0_, c1_, c2_ = A31, A32, 0.0
            else:
                c0_, c1_, c2_ = B1, B2, B3
            for j in range(nodes):
                base.u[j] = u_n[j] + h * (c0_ * vu[0, j] + c1_ * vu[1, j] + c2_ * vu[2, j])
                base.theta[j] = th_n[j] + h * (c0_ * vt[0, j] + c1_ * vt[1, j]
                                               + c2_ * vt[2, j])
                base.ud[j] = ud_n[j] + h * (c0_ * au[0, j] + c1_ * au[1, j] + c2_ * au[2, j])
                base.td[j] = td_n[j] + h * (c0_ * at[0, j] + c1_ * at[1, j] + c2_ * at[2, j])
            for k in range(ng):
                base.g[k] = g_n[k] + h * (c0_ * vg[0, k] + c1_ * vg[1, k] + c2_ * vg[2, k])
            # predictor: Taylor at the second stage; the cubic through (q_n, v_n) and the
            # second stage's (q, v) after it. Friction ratios: linear in time.
            s = ci * h
            if i == 1:
                for r in range(n):
                    j = r + off
                    u[j] = u_n[j] + s * ud_n[j] + 0.5 * s * s * au[0, j]
                    th[j] = th_n[j] + s * td_n[j] + 0.5 * s * s * at[0, j]
                for k in range(ng):
                    g[k] = g_n[k] + s * gd_n[k]
                if h_prev > 0.0:
                    predict_friction(lam, rates.lam_prev, s / h_prev, mesh, p.law)
            else:
                s1 = C2 * h
                x = s / s1
                h00 = (1.0 + 2.0 * x) * (1.0 - x) * (1.0 - x)
                h10 = x * (1.0 - x) * (1.0 - x) * s1
                h01 = x * x * (3.0 - 2.0 * x)
                h11 = x * x * (x - 1.0) * s1
                for r in range(n):
                    j = r + off
                    u[j] = h00 * u_n[j] + h10 * ud_n[j] + h01 * u_2[j] + h11 * vu[1, j]
                    th[j] = h00 * th_n[j] + h10 * td_n[j] + h01 * th_2[j] + h11 * vt[1, j]
                for k in range(ng):
                    g[k] = h00 * g_n[k] + h10 * gd_n[k] + h01 * g_2[k] + h11 * vg[1, k]
                for j in range(nodes):
                    lam[j] = lam_2[j]
                predict_friction(lam, lam_n, x - 1.0, mesh, p.law)
            # only the last stage's factors serve (the error estimate)
            ok = (newton(state, base, a0, t + s, mesh, p, drive, loads, scales,
                         NewtonSettings(settings.tol, settings.max_iterations, i == 3), w)
                  and on_path(g, g_n, scales))
            if not ok:
                break
            for j in range(nodes):
                vu[i, j] = a0 * (u[j] - base.u[j])
                vt[i, j] = a0 * (th[j] - base.theta[j])
                au[i, j] = a0 * (vu[i, j] - base.ud[j])
                at[i, j] = a0 * (vt[i, j] - base.td[j])
                ud[j], td[j] = vu[i, j], vt[i, j]
                if not (np.isfinite(u[j]) and np.isfinite(th[j])):
                    finite = False
            for k in range(ng):
                vg[i, k] = a0 * (g[k] - base.g[k])
                gd[k] = vg[i, k]
                if not np.isfinite(g[k]):
                    finite = False
            if not finite:
                break
            if i == 1:
                for j in range(nodes):
                    u_2[j], th_2[j], lam_2[j] = u[j], th[j], lam[j]
                for k in range(ng):
                    g_2[k] = g[k]
            power_terms(state, t + s, mesh, p, drive, loads, ps[i])
        if ok and not finite:
            copy_state(u, th, ud, td, lam, u_n, th_n, ud_n, td_n, lam_n)
            copy_globals(g, gd, g_n, gd_n)
            return NONFINITE, t, h_prev, h_next, steps, rejected
        err = 0.0
        if ok:
            d0, d1, d2, d3 = B1 - E1, B2 - E2, B3 - E3, B4 - E4
            for r in range(n):
                j = r + off
                e[r, 0] = h * (d0 * vu[0, j] + d1 * vu[1, j] + d2 * vu[2, j] + d3 * vu[3, j])
                e[r, 1] = h * (d0 * vt[0, j] + d1 * vt[1, j] + d2 * vt[2, j] + d3 * vt[3, j])
            for k in range(ng):
                eg[k] = h * (d0 * vg[0, k] + d1 * vg[1, k] + d2 * vg[2, k] + d3 * vg[3, k])
            filtered_error(e, eg, a0, p.friction_scale * friction_factor(drive, t + h),
                           loop_speed(g, mesh, p), mesh, p, w, te, teg)
            for r in range(n):
                err = max(err, abs(e[r, 0]) / scales.u, abs(e[r, 1]) / scales.theta)
            for k in range(ng):
                err = max(err, abs(eg[k]) / scales.glob[k])
            if not math.isfinite(err):
                err = np.inf
        if ok and err <= tol:
            for j in range(nodes):
                rates.au[j], rates.at[j] = au[3, j], at[3, j]
                rates.lam_prev[j] = lam_n[j]
            t = t_stop if parts == 1 else t + h  # the last part lands on t_stop exactly
            steps += 1
            h_prev = h
            for k in range(power.shape[0]):
                work[k] += h * (B1 * ps[0, k] + B2 * ps[1, k] + B3 * ps[2, k] + B4 * ps[3, k])
                power[k] = ps[3, k]
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


@register
class EsdirkScheme(AdaptiveScheme):
    """ESDIRK3(2)4L[2]SA with local error control: third order, three Newton solves a
    step; the time-accurate default."""

    name = "esdirk3"

    def __init__(self, disc):
        super().__init__(disc)
        self.rates = Rates.zeros(len(disc.mesh.hb))
        self.started = False  # whether rates.au, rates.at hold the state's accelerations

    def _compile(self, state) -> None:
        super()._compile(state)
        # the first step's kernels too, on copies, so that the warm-up holds all the
        # compiling and the run's wall time none (assemble is compiled by then)
        d = self.disc
        initial_ratios(state.copy(), 0.0, d.mesh, d.model, d.drive)
        power_terms(state.copy(), 0.0, d.mesh, d.model, d.drive, d.loads,
                    np.zeros_like(self.power))

    def advance(self, state, t, t_stop, max_steps=10**9):
        d, num = self.disc, self.numerics
        if not self.started and t_stop > t and max_steps > 0:
            initial_acceleration(state, self.old, t, d.mesh, d.model, d.drive, d.loads,
                                 self.work, self.rates.au, self.rates.at)
            power_terms(state, t, d.mesh, d.model, d.drive, d.loads, self.power)
            self.started = True
        h_max = min(t_stop - t, self.max_step) if t_stop > t else num.dt
        status, t, self.h_prev, self.h_next, steps, _ = advance_esdirk(
            state, self.rates, self.old, t, t_stop, self.h_prev, self.h_next, num.dt * 1e-7,
            h_max, num.time_tol, max_steps, d.mesh, d.model,
            d.drive, d.loads, d.scales, self.settings, self.work, self.power, self.work_done)
        self.steps += steps
        self.check_status(status, t, self.h_next)
        return t

    def checkpoint(self) -> dict:
        return {**super().checkpoint(), "started": np.array(self.started),
                **{f"rates_{k}": a.copy() for k, a in zip(Rates._fields, self.rates)}}

    def restore(self, data: dict) -> None:
        super().restore(data)
        self.started = bool(data["started"])
        for k, a in zip(Rates._fields, self.rates):
            a[:] = data[f"rates_{k}"]
