"""Pseudo-transient scheme: backward Euler at a fixed nominal step, Newton at every step.

The fast way to a steady state when the path does not matter: backward Euler's
first-order dissipation, and ``numerics.acceleration`` on top of the scene's damping,
shape the path, not the steady state (both act on local rates only). A step whose
Newton iteration fails, or a loop's step that moves its belt speed or a pulley's speed
by more than their scales, is retried with a quarter of the time step; after a run of
four successes the step grows back towards its nominal value. The same kernel serves
inertial and quasistatic scenes: with rho = I = 0 the residual is algebraic except
for the slip velocity, an index-1 DAE that backward Euler handles as is.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .newton import FAILED, NONFINITE, OK, NewtonScheme, newton, on_path
from .registry import register


@njit(cache=True)
def copy_step(dst, src):
    """``dst`` = ``src`` in the fields, their rates, the friction unknowns and a loop's
    globals: a step's start saved, or put back."""
    for j in range(dst.u.shape[0]):
        dst.u[j], dst.theta[j] = src.u[j], src.theta[j]
        dst.ud[j], dst.td[j], dst.lam[j] = src.ud[j], src.td[j], src.lam[j]
    for k in range(dst.g.shape[0]):
        dst.g[k], dst.gd[k] = src.g[k], src.gd[k]


@njit(cache=True)
def advance_backward_euler(state, old, t, t_stop, dt, dt_nominal, max_steps, mesh, p, drive,
                           loads, scales, settings, w):
    """Backward-Euler steps from t until t >= t_stop (or max_steps).

    Updates ``state`` in place; ``old`` is workspace for the previous step. Returns
    (status, t, dt, steps).
    """
    u, th, ud, td = state.u, state.theta, state.ud, state.td
    uo, tho, udo, tdo = old.u, old.theta, old.ud, old.td
    g, gd, go, gdo = state.g, state.gd, old.g, old.gd
    N = u.shape[0] - 1
    off = mesh.off
    steps = 0
    good = 0
    dt_min = dt_nominal * 1e-7
    while t < t_stop and steps < max_steps:
        copy_step(old, state)
        h = dt
        inv = 1.0 / h
        # predictor: constant local velocity over the step
        for j in range(off, N + 1 - off):
            u[j] = uo[j] + h * udo[j]
            th[j] = tho[j] + h * tdo[j]
        for k in range(g.shape[0]):
            g[k] = go[k] + h * gdo[k]
        ok = (newton(state, old, inv, t + h, mesh, p, drive, loads, scales, settings, w)
              and on_path(g, go, scales))
        if ok:
            finite = True
            for j in range(N + 1):
                ud[j] = (u[j] - uo[j]) * inv
                td[j] = (th[j] - tho[j]) * inv
                if not (np.isfinite(u[j]) and np.isfinite(th[j])):
                    finite = False
            for k in range(g.shape[0]):
                gd[k] = (g[k] - go[k]) * inv
                if not np.isfinite(g[k]):
                    finite = False
            if not finite:
                copy_step(state, old)
                return NONFINITE, t, dt, steps
            t += h
            steps += 1
            good += 1
            if good >= 4 and dt < dt_nominal:
                dt = min(2.0 * dt, dt_nominal)
                good = 0
        else:
            w.stats[0].failed_steps += 1
            copy_step(state, old)
            dt *= 0.25
            good = 0
            if dt < dt_min:
                return FAILED, t, dt, steps
    return OK, t, dt, steps


@register
class PseudoScheme(NewtonScheme):
    """Backward Euler with step cutting on Newton failure; not time-accurate."""

    name = "pseudo"
    time_accurate = False
    accelerated = True

    def __init__(self, disc):
        super().__init__(disc)
        self._dt = self.numerics.dt

    @property
    def dt(self) -> float:
        return self._dt

    def advance(self, state, t, t_stop, max_steps=10**9):
        d = self.disc
        status, t, dt, steps = advance_backward_euler(
            state, self.old, t, t_stop, self._dt, self.numerics.dt, max_steps, d.mesh, d.model,
            d.drive, d.loads, d.scales, self.settings, self.work)
        self._dt, self.steps = dt, self.steps + steps
        self.check_status(status, t, dt)
        return t

    def checkpoint(self) -> dict:
        return {**super().checkpoint(), "dt": np.array(self._dt)}

    def restore(self, data: dict) -> None:
        super().restore(data)
        self._dt = float(data["dt"])
