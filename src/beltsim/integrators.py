"""Time integrators (numba kernels on plain arrays).

Implicit: backward Euler on the residual of :mod:`beltsim.model`, solved by
Newton with a backtracking line search on a scaled residual norm. A plain
Newton step cycles on sharp friction (slope f*/v_reg ~ 1e8 or more; NOTES,
trap 2); the line search globalises it. A step whose Newton iteration fails is
retried with a quarter of the time step; after a run of successes the step
grows back towards its nominal value. The same kernel serves inertial and
quasistatic scenes: with rho = I = 0 the residual is algebraic except for the
slip velocity, an index-1 DAE that backward Euler handles as is.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .model import I_DUAL, assemble, block_solve, update_multipliers

# status codes of advance_implicit
OK, FAILED, NONFINITE = 0, 1, 2


class Workspace:
    """Preallocated arrays for the implicit kernels (grid of N elements)."""

    def __init__(self, N):
        n = N - 1
        self.R = np.zeros((n, 2))
        self.Lb = np.zeros((n, 2, 2))
        self.Db = np.zeros((n, 2, 2))
        self.Ub = np.zeros((n, 2, 2))
        self.C = np.zeros((n, 2, 2))
        self.dx = np.zeros((n, 2))
        self.uo = np.zeros(N + 1)
        self.tho = np.zeros(N + 1)
        self.udo = np.zeros(N + 1)
        self.tdo = np.zeros(N + 1)
        self.u_try = np.zeros(N + 1)
        self.th_try = np.zeros(N + 1)
        self.fnode = np.zeros(N + 1)
        self.lamo = np.zeros(N + 1)
        self.rl = np.zeros(N + 1)
        self.sg = np.zeros(N + 1)
        self.stats = np.zeros(4)  # newton iterations, failed steps, line-search cuts, last merit

    def arrays(self):
        return (self.R, self.Lb, self.Db, self.Ub, self.C, self.dx, self.uo, self.tho, self.udo,
                self.tdo, self.lamo, self.u_try, self.th_try, self.fnode, self.rl, self.sg,
                self.stats)

    def newton_arrays(self):
        return (self.R, self.Lb, self.Db, self.Ub, self.C, self.dx, self.u_try, self.th_try,
                self.fnode, self.rl, self.sg, self.stats)


@njit(cache=True)
def merit(R, scales):
    m = 0.0
    for i in range(R.shape[0]):
        a = R[i, 0] / scales[0]
        b = R[i, 1] / scales[1]
        m += a * a + b * b
    return m


@njit(cache=True)
def newton(u, th, lam, uo, tho, udo, tdo, inv_dt, t, he, hb, prm, iprm, scales, tol, max_it,
           R, Lb, Db, Ub, C, dx, u_try, th_try, fnode, rl, sg, stats):
    """Solve the step's residual for (u, th, lam) in place, starting from their values.

    scales = [force scale, moment scale, u scale, theta scale]. Converged when the
    update is below tol (scaled max norm; absolute for lam), or the residual is at
    round-off. Primal form: backtracking line search on the scaled residual norm.
    Primal-dual form: full steps, lam kept inside (-1, 1). Returns True on convergence.
    """
    n = R.shape[0]
    dual = iprm[I_DUAL] != 0
    assemble(u, th, lam, uo, tho, udo, tdo, inv_dt, t, he, hb, prm, iprm, R, Lb, Db, Ub, fnode,
             rl, sg, True)
    m0 = merit(R, scales)
    if m0 == 0.0:
        return True
    for it in range(max_it):
        stats[0] += 1
        for i in range(n):
            R[i, 0] = -R[i, 0]
            R[i, 1] = -R[i, 1]
        if not block_solve(Lb, Db, Ub, R, dx, C):
            return False
        step = 0.0
        for i in range(n):
            s = max(abs(dx[i, 0]) / scales[2], abs(dx[i, 1]) / scales[3])
            if s > step:
                step = s
        if not np.isfinite(step):
            return False
        if dual:
            dlam = update_multipliers(lam, dx, inv_dt, he, prm, iprm, rl, sg)
            for i in range(n):
                u[i + 1] += dx[i, 0]
                th[i + 1] += dx[i, 1]
            assemble(u, th, lam, uo, tho, udo, tdo, inv_dt, t, he, hb, prm, iprm, R, Lb, Db, Ub,
                     fnode, rl, sg, True)
            stats[3] = merit(R, scales)
            if max(step, dlam) < tol:
                return True
            continue
        alpha = 1.0
        accepted = False
        m = m0
        while alpha >= 1.0 / 4096.0:
            for i in range(n):
                u_try[i + 1] = u[i + 1] + alpha * dx[i, 0]
                th_try[i + 1] = th[i + 1] + alpha * dx[i, 1]
            assemble(u_try, th_try, lam, uo, tho, udo, tdo, inv_dt, t, he, hb, prm, iprm,
                     R, Lb, Db, Ub, fnode, rl, sg, True)
            m = merit(R, scales)
            if m <= (1.0 - 1e-4 * alpha) * m0:
                accepted = True
                break
            alpha *= 0.5
            stats[2] += 1
        if not accepted:
            # no decrease possible: fine if already at round-off, else a failure
            assemble(u, th, lam, uo, tho, udo, tdo, inv_dt, t, he, hb, prm, iprm,
                     R, Lb, Db, Ub, fnode, rl, sg, True)
            stats[3] = m0
            return step < 1e3 * tol
        for i in range(n):
            u[i + 1] = u_try[i + 1]
            th[i + 1] = th_try[i + 1]
        m0 = m
        stats[3] = m
        if alpha * step < tol or m < 1e-30:
            return True
    return False


@njit(cache=True)
def advance_implicit(u, th, lam, ud, td, t, t_stop, dt, dt_nominal, max_steps, he, hb, prm,
                     iprm, scales, tol, max_it, R, Lb, Db, Ub, C, dx, uo, tho, udo, tdo, lamo,
                     u_try, th_try, fnode, rl, sg, stats):
    """Backward-Euler steps from t until t >= t_stop (or max_steps).

    Updates u, th, lam, ud, td in place. Returns (status, t, dt, steps).
    """
    N = u.shape[0] - 1
    steps = 0
    good = 0
    dt_min = dt_nominal * 1e-7
    while t < t_stop and steps < max_steps:
        for j in range(N + 1):
            uo[j] = u[j]
            tho[j] = th[j]
            udo[j] = ud[j]
            tdo[j] = td[j]
            lamo[j] = lam[j]
        h = dt
        inv = 1.0 / h
        # predictor: constant local velocity over the step
        for j in range(1, N):
            u[j] = uo[j] + h * udo[j]
            th[j] = tho[j] + h * tdo[j]
        ok = newton(u, th, lam, uo, tho, udo, tdo, inv, t + h, he, hb, prm, iprm, scales, tol,
                    max_it, R, Lb, Db, Ub, C, dx, u_try, th_try, fnode, rl, sg, stats)
        if ok:
            finite = True
            for j in range(N + 1):
                ud[j] = (u[j] - uo[j]) * inv
                td[j] = (th[j] - tho[j]) * inv
                if not (np.isfinite(u[j]) and np.isfinite(th[j])):
                    finite = False
            if not finite:
                for j in range(N + 1):
                    u[j], th[j], ud[j], td[j], lam[j] = uo[j], tho[j], udo[j], tdo[j], lamo[j]
                return NONFINITE, t, dt, steps
            t += h
            steps += 1
            good += 1
            if good >= 4 and dt < dt_nominal:
                dt = min(2.0 * dt, dt_nominal)
                good = 0
        else:
            stats[1] += 1
            for j in range(N + 1):
                u[j], th[j], ud[j], td[j], lam[j] = uo[j], tho[j], udo[j], tdo[j], lamo[j]
            dt *= 0.25
            good = 0
            if dt < dt_min:
                return FAILED, t, dt, steps
    return OK, t, dt, steps


@njit(cache=True)
def solve_steady(u, th, lam, he, hb, prm, iprm, scales, tol, max_it, uo, tho, udo, tdo,
                 R, Lb, Db, Ub, C, dx, u_try, th_try, fnode, rl, sg, stats):
    """Newton on the discrete steady equations (inv_dt = 0) from the given state."""
    return newton(u, th, lam, uo, tho, udo, tdo, 0.0, 1e300, he, hb, prm, iprm, scales, tol,
                  max_it, R, Lb, Db, Ub, C, dx, u_try, th_try, fnode, rl, sg, stats)
