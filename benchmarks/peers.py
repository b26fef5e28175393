"""Generic peers of beltsim's schemes: what a skilled scipy user would write instead.

Every peer works on beltsim's own semi-discretisation, on the same grid: the numpy twin
:func:`beltsim.physics.model.forces_numpy` of the model and its analytic Jacobian
(:meth:`PeerModel.force_jacobian`, derived here from ``forces_numpy`` term by term, not
taken from the numba kernels), and stops on the same tests as beltsim:

* transient peers (:func:`run_transient_peer`): ``scipy.integrate.Radau`` and ``BDF``,
  the classes behind ``solve_ivp(method=...)``, on the method-of-lines system y' = f(y)
  with y = (u, theta, u_t, theta_t) at the interior nodes and the analytic sparse
  Jacobian, from rest to the steady criterion of a run (the run's
  :class:`~beltsim.simulation.trackers.SteadyStateTracker`, fed at the run's check
  times from the solver's dense output). They are stepped by hand, as ``solve_ivp``
  does internally, only so that the steady test can stop them;
* the steady peer (:func:`run_steady_peer`): Newton on the steady residual
  (``forces_numpy`` with zero rates and the final drive) with scipy.sparse's direct
  solver, a backtracking line search and continuation in the regularisation velocity
  v_reg, converged to the update tolerance of beltsim's Newton (``numerics.newton_tol``).

Wall times include building the peer's system (cheap) and exclude nothing else.
"""

from __future__ import annotations

import math
import time
from typing import NamedTuple

import numpy as np

from beltsim.errors import SceneError
from beltsim.physics.friction import is_exact, law_numpy
from beltsim.physics.model import forces_numpy, strain_numpy
from beltsim.problem.drive import Drive, friction_factor, mismatch
from beltsim.simulation.controller import Simulation
from beltsim.solvers.newton import ROUNDOFF_FLOOR

#: The loosest rtol of RTOL_LADDER with which each transient peer reached beltsim's
#: steady state on the paper slip scene, 250 elements (``beltsim bench --elements 250
#: --search-rtol``): BDF at 1e-6 rang on to t_end, its orders 3-5 not being A-stable.
#: They do not carry over to finer grids: on 1000 elements Radau at 1e-4 covered 0.1 s
#: of the transient in 900 s and BDF at 1e-7 rang on to t_end, while Radau at 1e-5 and
#: BDF at 1e-9 settled (``--search-rtol`` searches the bench's own grid).
DEFAULT_RTOL = {"Radau": 1e-4, "BDF": 1e-7}
#: The lists :func:`loosest_tolerance` searches, loosest first.
RTOL_LADDER = {"Radau": (1e-4, 3e-5, 1e-5, 3e-6, 1e-6, 3e-7, 1e-7),
               "BDF": (1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11)}
#: Two steady states are "the same" when their total frictions differ by less than this
#: (relative). The steady test bounds the change per transit time L/c by 1e-6, and the
#: slowest mode decays by ~8% a transit (10 1/s), so a run may stop ~1e-5 short of its
#: limit; the grid error of the bench grids is 3e-4 to 1.4e-3.
SAME_STATE = 1e-5
#: The steady peer accepts a stalled update (beltsim's round-off floor) only with its
#: scaled residual below this, beltsim's own steady states' is ~1e-10: a primal Newton
#: iteration can stall by a kink of the friction law far from a solution (residual 8e-5
#: seen on 1000 elements), which beltsim's primal-dual iteration does not.
RESIDUAL_FLOOR = 1e-8


class PeerResult(NamedTuple):
    total_friction: float
    wall_time: float
    converged: bool
    reason: str  # "steady", or why not
    tolerance: float
    simulated_time: float | None = None  # transient peers
    rhs_evaluations: int = 0
    jacobian_evaluations: int = 0
    factorisations: int = 0
    steps: int = 0  # accepted steps (transient), Newton iterations (steady)


class FixedPattern:
    """A CSC matrix of fixed pattern: constant entries plus entries that change per call.

    What a careful scipy user does to keep scipy.sparse's bookkeeping (pattern merging,
    index checks) out of every Jacobian: the pattern and the slots of the changing
    entries are found once; a call copies the constant values and adds the others,
    ``values[take] * scale`` of the ``values`` it is given.
    """

    def __init__(self, shape, rows, cols, vals, var_rows, var_cols, take, scale):
        nr = shape[0]
        key_c = cols.astype(np.int64) * nr + rows
        key_v = var_cols.astype(np.int64) * nr + var_rows
        keys = np.unique(np.concatenate([key_c, key_v]))
        self.shape, self._take, self._scale = shape, take, scale
        self._base = np.zeros(keys.size)
        np.add.at(self._base, np.searchsorted(keys, key_c), vals)
        self._slot = np.searchsorted(keys, key_v)
        if np.unique(self._slot).size != self._slot.size:
            raise ValueError("the changing entries must sit in distinct slots")
        self._indices = (keys % nr).astype(np.int32)
        counts = np.bincount(keys // nr, minlength=shape[1])
        self._indptr = np.concatenate([[0], np.cumsum(counts)]).astype(np.int32)

    def matrix(self, values):
        from scipy.sparse import csc_matrix

        data = self._base.copy()
        data[self._slot] += values[self._take] * self._scale
        return csc_matrix((data, self._indices, self._indptr), shape=self.shape)


class PeerModel:
    """The semi-discrete forces and their analytic sparse Jacobian, interior nodes only.

    The boundary nodes 0 and N are held at zero, so their columns drop out. Unknown
    order: (u, theta, u_t, theta_t), n = N - 1 values each. The Jacobian is a constant
    part (elastic, shear, gyroscopic and damping terms) plus the friction's, which
    depends on the state through the slope of the friction law.
    """

    def __init__(self, sim: Simulation):
        from scipy.sparse import bmat, diags

        self.disc = d = sim.disc
        self.scales = d.scales
        p, he, hb = d.model, d.mesh.he, d.mesh.hb
        if is_exact(p.law):  # y' = f(y) needs a single-valued law
            raise SceneError('numerics.friction_law: the peers take the regularised laws, '
                             'not "exact" (a method-of-lines right-hand side is single-valued)')
        N = d.grid.n_elements
        self.n = n = N - 1
        self._full = [np.zeros(N + 1) for _ in range(4)]
        lo, hi = 1.0 / he[:-1], 1.0 / he[1:]  # 1/h_{j-1}, 1/h_j at interior nodes j
        second = diags([lo[1:], -(lo + hi), hi[:-1]], [-1, 0, 1])
        hbi = hb[1:-1]
        gyro = 2.0 * p.speed * hbi * lo  # the upwind 2 c u_xt: g_j (v_j - v_{j-1})
        upwind = diags([gyro, -gyro[1:]], [0, -1])
        fu_ud = -p.mass * upwind - diags(p.damping * p.mass * hbi)
        ft_th = p.bending_eff * second - diags(p.shear * hbi)
        ft_td = -p.rotary_inertia * upwind - diags(p.damping * p.rotary_inertia * hbi)
        self.static = bmat([[p.tension_eff * second, None, fu_ud, None],
                            [None, ft_th, None, ft_td]], format="coo")
        # friction: node j's force F_j(v_rel) with v_rel = u_t,j + hh theta_t,j
        # + c sum_o sw[j, o] u_b,{j-2+o} (physics.model.contact_stencil) enters the u row
        # of j and, times hh, its theta row
        m = d.mesh
        j = np.arange(m.c0, m.j2 + 1)
        self.contact = j
        hh, c = p.half_height, p.speed
        i = j - 1
        cols, dvrel = [2 * n + i, 3 * n + i], [np.ones(j.size), np.full(j.size, hh)]
        for o in range(4):
            k = i - 2 + o  # interior index of node j - 2 + o
            w = np.where((k >= 0) & (k < n), c * m.sw[j, o], 0.0)
            cols += [k, n + k]
            dvrel += [w, hh * w]
        cols, dvrel = np.stack(cols), np.stack(dvrel)
        keep = (cols >= 0) & (cols < 4 * n) & (dvrel != 0.0)
        self.fric_cols = np.concatenate([cols[keep], cols[keep]])
        self.fric_rows = np.concatenate([np.broadcast_to(i, cols.shape)[keep],
                                         np.broadcast_to(n + i, cols.shape)[keep]])
        self._fnode = np.concatenate([np.broadcast_to(np.arange(j.size), cols.shape)[keep]] * 2)
        self._fcoef = np.concatenate([dvrel[keep], hh * dvrel[keep]])
        self._wf = m.wf[j]

    def unpack(self, y):
        """Full nodal arrays (boundary zeros) of the interior values in y; rates absent
        from y (the steady problem's (u, theta)) are zero."""
        n = self.n
        for k in range(len(y) // n):
            self._full[k][1:-1] = y[k * n:(k + 1) * n]
        for k in range(len(y) // n, 4):
            self._full[k][:] = 0.0
        return self._full

    def forces(self, t, y, drive=None, p=None):
        """forces_numpy of the state y (u, theta, and optionally u_t, theta_t)."""
        d = self.disc
        u, th, ud, td = self.unpack(y)
        return forces_numpy(u, th, ud, td, t, d.mesh, p or d.model, drive or d.drive)

    def friction_entries(self, t, y, drive=None, p=None):
        """The friction's Jacobian entries at (fric_rows, fric_cols) of the state y."""
        d = self.disc
        p, drive = p or d.model, drive or d.drive
        u, th, ud, td = self.unpack(y)
        j, hh, c = self.contact, p.half_height, p.speed
        ub = u + hh * th
        vrel = ud[j] + hh * td[j] + c * strain_numpy(ub, d.mesh.sw, j) - mismatch(drive, t)
        fs = p.friction_scale * friction_factor(drive, t)
        slope = law_numpy(p.law, vrel / p.v_reg)[1]
        k = self._wf * fs * slope / p.v_reg  # -dF_j/dv_rel
        return -k[self._fnode] * self._fcoef

    def force_jacobian(self, t, y, drive=None, p=None):
        """d(force on u, moment on theta)/d(u, theta, u_t, theta_t), (2n, 4n) CSR."""
        from scipy.sparse import coo_matrix

        fric = coo_matrix((self.friction_entries(t, y, drive, p),
                           (self.fric_rows, self.fric_cols)), shape=self.static.shape)
        return (self.static + fric).tocsr()

    def pattern(self, row_scale, columns=4, row_offset=0, extra=None):
        """A :class:`FixedPattern` of the force Jacobian's first ``columns`` blocks of n
        columns, rows scaled by ``row_scale`` and moved down by ``row_offset``; ``extra``
        (rows, cols, vals) adds constant entries. Its ``matrix`` takes the values of
        :meth:`friction_entries`."""
        s, width = self.static, columns * self.n
        keep = s.col < width
        rows, cols, vals = s.row[keep], s.col[keep], s.data[keep] * row_scale[s.row[keep]]
        take = np.flatnonzero(self.fric_cols < width)
        fr = self.fric_rows[take]
        if extra is not None:
            rows = np.concatenate([rows + row_offset, extra[0]])
            cols = np.concatenate([cols, extra[1]])
            vals = np.concatenate([vals, extra[2]])
        else:
            rows = rows + row_offset
        shape = (2 * self.n + row_offset, width)
        return FixedPattern(shape, rows, cols, vals, fr + row_offset, self.fric_cols[take],
                            take, row_scale[fr])


class PeerSystem(PeerModel):
    """y' = f(t, y) with y = (u, theta, u_t, theta_t) at the interior nodes."""

    def __init__(self, sim: Simulation):
        if not sim.params.inertia:
            raise ValueError("the method-of-lines peer needs an inertial scene")
        super().__init__(sim)
        d, n = self.disc, self.n
        self.m = d.params.rho * d.mesh.hb[1:-1]
        self.mi = d.params.I * d.mesh.hb[1:-1]
        drift = np.arange(2 * n)  # (u, theta)' = (u_t, theta_t)
        self._pattern = self.pattern(np.concatenate([1.0 / self.m, 1.0 / self.mi]),
                                     row_offset=2 * n,
                                     extra=(drift, drift + 2 * n, np.ones(2 * n)))

    def rhs(self, t, y):
        fu, ft, _ = self.forces(t, y)
        n = self.n
        return np.concatenate([y[2 * n:3 * n], y[3 * n:], fu / self.m, ft / self.mi])

    def jacobian(self, t, y):
        """df/dy, (4n, 4n) CSC (what Radau and BDF factorise)."""
        return self._pattern.matrix(self.friction_entries(t, y))

    def friction(self, t, y):
        return self.forces(t, y)[2].sum()


def _state_scale(sim: Simulation, n: int) -> np.ndarray:
    """Scale of each unknown: u, theta (as Newton's norms) and their rates (c times them)."""
    P, sc = sim.params, sim.disc.scales
    vel = P.c * sc.theta
    return np.concatenate([np.full(n, sc.u), np.full(n, sc.theta), np.full(n, vel),
                           np.full(n, vel / P.L)])


def run_transient_peer(sim: Simulation, method: str = "Radau", rtol: float | None = None,
                       max_wall: float = 600.0, atol_factor: float = 1.0) -> PeerResult:
    """scipy's Radau or BDF with the analytic sparse Jacobian, from rest to steady state.

    rtol defaults to DEFAULT_RTOL; atol is ``atol_factor`` rtol times the scale of each
    unknown (the displacement and rotation scales of beltsim's Newton norms, c times them
    for the rates). The steady test is the run's, at the run's check times (every
    L / (4 c)), on states from the dense output. Stops unconverged at t_end, on a solver
    failure or after ``max_wall`` seconds.
    """
    from scipy.integrate import BDF, Radau

    solver_class = {"Radau": Radau, "BDF": BDF}[method]
    rtol = DEFAULT_RTOL[method] if rtol is None else rtol
    start = time.perf_counter()
    P = sim.params
    sysm = PeerSystem(sim)
    n = sysm.n
    vel = P.c * sim.disc.scales.theta
    steady, check, t_end = sim.steady, sim.check, sim.numerics.t_end
    solver = solver_class(sysm.rhs, 0.0, np.zeros(4 * n), t_end, rtol=rtol,
                          atol=atol_factor * rtol * _state_scale(sim, n), jac=sysm.jacobian)
    k, total, converged, reason, steps = 1, 0.0, False, "not steady by t_end", 0
    while solver.status == "running":
        if time.perf_counter() - start > max_wall:
            reason = f"stopped at the {max_wall:g} s wall-time cap at t = {solver.t:.4g} s"
            break
        solver.step()
        steps += 1
        if solver.status == "failed":
            reason = f"solver failed at t = {solver.t:.4g} s"
            break
        if solver.t >= k * check:
            dense = solver.dense_output()
            while k * check <= solver.t and not converged:
                t = k * check
                y = dense(t)
                total = sysm.friction(t, y)
                rate = max(np.abs(y[2 * n:3 * n]).max(), P.L * np.abs(y[3 * n:]).max()) / vel
                converged = steady.update(t, rate, total)
                k += 1
            if converged:
                reason = "steady"
                break
    wall = time.perf_counter() - start
    return PeerResult(total, wall, converged, reason, rtol, solver.t, solver.nfev,
                      solver.njev, solver.nlu, steps)


def run_steady_peer(sim: Simulation, stage_factor: float = 5.0, inner_tol: float = 1e-4,
                    max_iterations: int = 50) -> PeerResult:
    """Sparse Newton on the steady residual: line search, continuation in v_reg.

    From rest, v_reg starts at |v - c| (where the friction law is gentle) and falls by
    ``stage_factor`` per stage down to the scene's; a stage that fails is undone and
    retried with the square root of the factor, which then stays. Each Newton step takes
    its direction from scipy.sparse.linalg.spsolve and is halved until the scaled
    residual norm decreases (Armijo). The last stage has converged when a full step's
    update is below ``numerics.newton_tol`` (scaled max norm, as beltsim's Newton), or
    below 1e3 times that once the update has stopped halving (beltsim's round-off floor)
    with the scaled residual below RESIDUAL_FLOOR; the stages before it stop at
    ``inner_tol``, since they only give the next one its start.
    """
    from scipy.sparse.linalg import spsolve

    start = time.perf_counter()
    d = sim.disc
    P, num, sc = d.params, d.numerics, d.scales
    model = PeerModel(sim)
    n = model.n
    drive = Drive.constant(P.v - P.c)
    row_scale = np.concatenate([np.full(n, sc.force), np.full(n, sc.moment)])
    jac = model.pattern(1.0 / row_scale, columns=2)
    x_scale = _state_scale(sim, n)[:2 * n]
    tol = num.newton_tol
    target = d.model.v_reg
    x = np.zeros(2 * n)
    iterations = factorisations = evaluations = 0

    def residual(x, p):
        fu, ft, _ = model.forces(0.0, x, drive, p)
        return np.concatenate([fu, ft]) / row_scale

    def solve_stage(x, p, stage_tol):
        nonlocal iterations, factorisations, evaluations
        r = residual(x, p)
        evaluations += 1
        merit = r @ r
        last = math.inf
        for _ in range(max_iterations):
            dx = spsolve(jac.matrix(model.friction_entries(0.0, x, drive, p)), -r)
            iterations += 1
            factorisations += 1
            if not np.all(np.isfinite(dx)):
                return None
            step = np.abs(dx / x_scale).max()
            a = 1.0
            while True:
                trial = x + a * dx
                r_try = residual(trial, p)
                evaluations += 1
                m_try = r_try @ r_try
                if m_try <= (1.0 - 1e-4 * a) * merit or a < 1e-6:
                    break
                a *= 0.5
            if a < 1e-6:
                return None
            x, r, merit = trial, r_try, m_try
            stalled = step < ROUNDOFF_FLOOR * stage_tol and step > 0.5 * last
            small = np.abs(r).max() < RESIDUAL_FLOOR
            if a == 1.0 and (step < stage_tol or (stalled and small)):
                return x
            last = step if a == 1.0 else math.inf
        return None

    factor, converged, reason = stage_factor, False, "steady"
    done = v_reg = max(target, abs(P.v - P.c))
    first = True
    while True:
        trial = solve_stage(x, d.model._replace(v_reg=v_reg),
                            tol if v_reg <= target else inner_tol)
        if trial is not None:
            x, done, first = trial, v_reg, False
            if v_reg <= target:
                converged = True
                break
        elif first:
            reason = f"Newton failed at v_reg = {v_reg:.3g} m/s"
            break
        else:
            factor = math.sqrt(factor)
            if factor < 1.01:
                reason = f"Newton failed below v_reg = {done:.3g} m/s"
                break
        v_reg = max(target, done / factor)
    total = float(model.forces(0.0, x, drive)[2].sum())
    wall = time.perf_counter() - start
    return PeerResult(total, wall, converged, reason, tol, None, evaluations, iterations,
                      factorisations, iterations)


def loosest_tolerance(make_sim, method: str, reference_total: float,
                      rtols=None, max_wall: float = 600.0, log=print):
    """The loosest rtol in ``rtols`` (default RTOL_LADDER) whose run reaches the steady
    state of ``reference_total`` (beltsim's, within SAME_STATE); ``make_sim()`` gives a
    fresh Simulation (the steady test keeps state). Returns (rtol or None, results)."""
    results = {}
    for rtol in rtols or RTOL_LADDER[method]:
        res = run_transient_peer(make_sim(), method, rtol, max_wall)
        same = abs(res.total_friction - reference_total) <= SAME_STATE * abs(reference_total)
        results[rtol] = res
        log(f"  {method} rtol {rtol:g}: {res.reason}, wall {res.wall_time:.3g} s, "
            f"t = {res.simulated_time:.4g} s, total friction {res.total_friction:.8g} N"
            f"{'' if same or not res.converged else ' (not the same steady state)'}")
        if res.converged and same:
            return rtol, results
    return None, results
