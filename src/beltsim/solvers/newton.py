"""Newton's method on the discrete equations, shared by the implicit and steady schemes.

The residual of :func:`beltsim.physics.model.assemble` at one time level (or at
steady state, ``inv_dt`` = 0) is solved for (u, theta) and, for saturating friction
laws, the friction ratios. A plain Newton step cycles on sharp friction (slope
f*/v_reg ~ 1e8 or more): the primal form is globalised by a backtracking line
search on a scaled residual norm; the primal-dual form (friction ratio as an
unknown, kept inside (-1, 1)) converges with full steps.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from ..errors import NumericalError
from ..physics.model import assemble, block_solve, update_multipliers
from .base import Scheme

# status codes of the time-stepping kernels that solve with Newton
OK, FAILED, NONFINITE = 0, 1, 2
# How far above the tolerance a stalled Newton update may be and still count as
# converged: 1e3 * 1e-9 = 1e-6, an order below the discretisation error of the finest
# grid tried (1.4e-5 on 20,000 elements).
ROUNDOFF_FLOOR = 1e3

#: Counters a scheme accumulates, one record the kernels update in place.
STATS_DTYPE = np.dtype([("newton_iterations", np.int64), ("failed_steps", np.int64),
                        ("line_search_cuts", np.int64), ("merit", np.float64)])


class NewtonSettings(NamedTuple):
    tol: float  # scaled max norm of the update
    max_iterations: int


class Workspace(NamedTuple):
    """Preallocated arrays of the Newton kernels (grid of N elements)."""

    R: np.ndarray  # residual (n, 2), n = N - 1 interior nodes
    Lb: np.ndarray  # Jacobian blocks (n, 2, 2)
    Db: np.ndarray
    Ub: np.ndarray
    C: np.ndarray  # block Thomas pivots
    dx: np.ndarray  # Newton update (n, 2)
    u_try: np.ndarray  # line-search trial (N + 1)
    th_try: np.ndarray
    rl: np.ndarray  # friction equation residuals (N + 1)
    sg: np.ndarray  # friction slopes (N + 1)
    stats: np.ndarray  # one record of STATS_DTYPE

    @classmethod
    def allocate(cls, n_elements: int) -> "Workspace":
        N, n = n_elements, n_elements - 1
        return cls(R=np.zeros((n, 2)), Lb=np.zeros((n, 2, 2)), Db=np.zeros((n, 2, 2)),
                   Ub=np.zeros((n, 2, 2)), C=np.zeros((n, 2, 2)), dx=np.zeros((n, 2)),
                   u_try=np.zeros(N + 1), th_try=np.zeros(N + 1), rl=np.zeros(N + 1),
                   sg=np.zeros(N + 1), stats=np.zeros(1, STATS_DTYPE))


@njit(cache=True)
def merit(R, scales):
    m = 0.0
    for i in range(R.shape[0]):
        a = R[i, 0] / scales.force
        b = R[i, 1] / scales.moment
        m += a * a + b * b
    return m


@njit(cache=True)
def newton(state, old, inv_dt, t, mesh, p, drive, loads, scales, settings, w):
    """Solve the step's residual for (u, theta, lam) of ``state`` in place, from their values.

    Converged when the update is below settings.tol (scaled max norm; absolute for
    lam), or when it has reached the round-off floor: below ROUNDOFF_FLOOR * tol and no
    longer halving. The floor grows with the condition number of the Jacobian,
    ~ (L / h_min)^2: on 20,000 elements the update stalls near 1e-8 and a fixed 1e-9
    failed every step. Returns True on convergence.
    """
    u, th, lam, fnode = state.u, state.theta, state.lam, state.fnode
    R, dx, u_try, th_try = w.R, w.dx, w.u_try, w.th_try
    st = w.stats[0]
    tol = settings.tol
    n = R.shape[0]
    assemble(u, th, lam, fnode, old, inv_dt, t, mesh, p, drive, loads, w, True)
    m0 = merit(R, scales)
    if m0 == 0.0:
        return True
    previous = np.inf
    for it in range(settings.max_iterations):
        st.newton_iterations += 1
        for i in range(n):
            R[i, 0] = -R[i, 0]
            R[i, 1] = -R[i, 1]
        if not block_solve(w.Lb, w.Db, w.Ub, R, dx, w.C):
            return False
        step = 0.0
        for i in range(n):
            s = max(abs(dx[i, 0]) / scales.u, abs(dx[i, 1]) / scales.theta)
            if s > step:
                step = s
        if not np.isfinite(step):
            return False
        if p.dual:
            dlam = update_multipliers(lam, dx, inv_dt, mesh, p, w)
            for i in range(n):
                u[i + 1] += dx[i, 0]
                th[i + 1] += dx[i, 1]
            assemble(u, th, lam, fnode, old, inv_dt, t, mesh, p, drive, loads, w, True)
            st.merit = merit(R, scales)
            update = max(step, dlam)
            if update < tol or (update < ROUNDOFF_FLOOR * tol and update > 0.5 * previous):
                return True
            previous = update
            continue
        alpha = 1.0
        accepted = False
        m = m0
        while alpha >= 1.0 / 4096.0:
            for i in range(n):
                u_try[i + 1] = u[i + 1] + alpha * dx[i, 0]
                th_try[i + 1] = th[i + 1] + alpha * dx[i, 1]
            assemble(u_try, th_try, lam, fnode, old, inv_dt, t, mesh, p, drive, loads, w, True)
            m = merit(R, scales)
            if m <= (1.0 - 1e-4 * alpha) * m0:
                accepted = True
                break
            alpha *= 0.5
            st.line_search_cuts += 1
        if not accepted:
            # no decrease possible: fine if already at round-off, else a failure
            assemble(u, th, lam, fnode, old, inv_dt, t, mesh, p, drive, loads, w, True)
            st.merit = m0
            return step < ROUNDOFF_FLOOR * tol
        for i in range(n):
            u[i + 1] = u_try[i + 1]
            th[i + 1] = th_try[i + 1]
        m0 = m
        st.merit = m
        if alpha * step < tol or m < 1e-30:
            return True
    return False


class NewtonScheme(Scheme):
    """The workspace, Newton settings and counters of the schemes that solve with Newton."""

    def __init__(self, disc):
        super().__init__(disc)
        num = self.numerics
        self.work = Workspace.allocate(disc.grid.n_elements)
        self.settings = NewtonSettings(num.newton_tol, num.newton_max_it)
        # the previous step's state (with inv_dt = 0, the steady equations ignore it)
        self.old = disc.new_state()

    def statistics(self) -> dict:
        st = self.work.stats[0]
        return {"steps": self.steps, "newton_iterations": int(st["newton_iterations"]),
                "rejected_steps": int(st["failed_steps"]),
                "line_search_cuts": int(st["line_search_cuts"])}

    def checkpoint(self) -> dict:
        return {**super().checkpoint(), "stats": self.work.stats.copy()}

    def restore(self, data: dict) -> None:
        super().restore(data)
        self.work.stats[:] = data["stats"]

    def check_status(self, status, t, dt) -> None:
        """Raise NumericalError for a kernel's FAILED or NONFINITE status."""
        if status == FAILED:
            raise NumericalError(
                f"Newton iteration failed at t = {t:.6g} s even with the step cut to "
                f"dt = {dt:.3g} s (residual norm {self.work.stats[0]['merit']:.3g})", t=t,
                quantity="newton")
        if status == NONFINITE:
            raise NumericalError(f"non-finite displacement or rotation at t = {t:.6g} s",
                                 t=t, quantity="u/theta")
