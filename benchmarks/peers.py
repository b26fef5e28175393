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
from beltsim.physics import reference
from beltsim.physics.friction import is_exact
from beltsim.problem.drive import Drive
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
    """A CSC matrix of fixed pattern: a weighted sum of constant matrices plus entries that
    change per call.

    What a careful scipy user does to keep scipy.sparse's bookkeeping (pattern merging,
    index checks) out of every Jacobian: the pattern and the slots of the changing
    entries are found once; a call sums the constant parts with its weights and adds
    ``values[take] * scale`` of the ``values`` it is given (entries in one slot add).
    """

    def __init__(self, shape, parts, var_rows, var_cols, take=None, scale=1.0):
        nr = shape[0]
        keys_c = [cols.astype(np.int64) * nr + rows for rows, cols, _ in parts]
        key_v = var_cols.astype(np.int64) * nr + var_rows
        keys = np.unique(np.concatenate([*keys_c, key_v]))
        self.shape = shape
        self._take = np.arange(key_v.size) if take is None else take
        self._scale = scale
        self._base = np.zeros((len(parts), keys.size))
        for base, key, (_, _, vals) in zip(self._base, keys_c, parts):
            np.add.at(base, np.searchsorted(keys, key), vals)
        self._slot = np.searchsorted(keys, key_v)
        self._indices = (keys % nr).astype(np.int32)
        counts = np.bincount(keys // nr, minlength=shape[1])
        self._indptr = np.concatenate([[0], np.cumsum(counts)]).astype(np.int32)

    def matrix(self, values, weights=(1.0,)):
        from scipy.sparse import csc_matrix

        data = np.asarray(weights, dtype=float) @ self._base
        data += np.bincount(self._slot, values[self._take] * self._scale,
                            minlength=data.size)
        return csc_matrix((data, self._indices, self._indptr), shape=self.shape)


def coo_parts(matrix, row_scale=None, row_offset=0, columns=None):
    """(rows, cols, vals) of a sparse matrix's entries in its first ``columns`` columns,
    each row times ``row_scale`` and moved down by ``row_offset``."""
    m = matrix.tocoo()
    keep = m.col < (m.shape[1] if columns is None else columns)
    rows, cols, vals = m.row[keep], m.col[keep], m.data[keep]
    if row_scale is not None:
        vals = vals * row_scale[rows]
    return rows + row_offset, cols, vals


class PeerModel:
    """The semi-discrete forces and their sparse Jacobian (:mod:`beltsim.physics.reference`).

    The boundary nodes 0 and N are held at zero, so their columns drop out. Unknowns
    y = (q, q'), q = (u_1, theta_1, u_2, ...) the n = N - 1 interior nodes interleaved
    (the reference's order). The Jacobian is a constant part (elastic, shear,
    gyroscopic and damping terms) plus the friction's, which depends on the state
    through the slope of the friction law.
    """

    def __init__(self, sim: Simulation):
        from scipy.sparse import hstack

        self.disc = d = sim.disc
        self.scales = d.scales
        p = d.model
        if is_exact(p.law):  # y' = f(y) needs a single-valued law
            raise SceneError('numerics.friction_law: the peers take the regularised laws, '
                             'not "exact" (a method-of-lines right-hand side is single-valued)')
        N = d.grid.n_elements
        self.n = N - 1
        self._full = [np.zeros(N + 1) for _ in range(4)]
        self.operators = ops = reference.operators(d.mesh, p)
        # -df/d(q, q') without friction, and where friction enters it
        self.static = hstack([ops.stiffness, ops.damping]).tocsr()
        self.friction = reference.friction_pattern(d.mesh, p)

    def unpack(self, y):
        """Full nodal arrays u, theta, u_t, theta_t (boundary zeros) of the values in y;
        rates absent from y (the steady problem's q) are zero."""
        n2 = 2 * self.n
        for k in range(4):
            part = y[(k // 2) * n2:(k // 2 + 1) * n2]
            self._full[k][1:-1] = part[k % 2::2] if part.size else 0.0
        return self._full

    def forces(self, t, y, drive=None, p=None):
        """(f, F): the forces f (2n, interleaved) of the state y and the nodal frictions."""
        d = self.disc
        f, F = reference.forces(*self.unpack(y), t, d.mesh, p or d.model, drive or d.drive)
        return f.ravel(), F

    def friction_entries(self, t, y, drive=None, p=None):
        """The friction's entries of -df/d(q, q') at the pattern ``self.friction``."""
        d = self.disc
        p, drive = p or d.model, drive or d.drive
        vrel = reference.slip_velocity(*self.unpack(y), t, d.mesh, p, drive)
        _, k = reference.friction(vrel, t, d.mesh, p, drive)
        return k[self.friction.node] * self.friction.coef

    def pattern(self, row_scale, columns=4, row_offset=0, extra=None):
        """A :class:`FixedPattern` of df/d(q, q') (first ``columns`` blocks of n columns),
        rows scaled by ``row_scale`` and moved down by ``row_offset``; ``extra`` (rows,
        cols, vals) adds constant entries. Its ``matrix`` takes the values of
        :meth:`friction_entries`."""
        width, fr = columns * self.n, self.friction
        part = coo_parts(self.static, -row_scale, row_offset, width)
        if extra is not None:
            part = tuple(np.concatenate(x) for x in zip(part, extra))
        take = np.flatnonzero(fr.cols < width)
        shape = (2 * self.n + row_offset, width)
        return FixedPattern(shape, [part], fr.rows[take] + row_offset, fr.cols[take], take,
                            -row_scale[fr.rows[take]])


class PeerSystem(PeerModel):
    """y' = f(t, y) with y = (q, q') at the interior nodes."""

    def __init__(self, sim: Simulation):
        if not sim.params.inertia:
            raise ValueError("the method-of-lines peer needs an inertial scene")
        super().__init__(sim)
        n2 = 2 * self.n
        self.m = self.operators.mass
        drift = np.arange(n2)  # q' = q'
        self._pattern = self.pattern(1.0 / self.m, row_offset=n2,
                                     extra=(drift, drift + n2, np.ones(n2)))

    def rhs(self, t, y):
        f, _ = self.forces(t, y)
        return np.concatenate([y[2 * self.n:], f / self.m])

    def jacobian(self, t, y):
        """df/dy, (4n, 4n) CSC (what Radau and BDF factorise)."""
        return self._pattern.matrix(self.friction_entries(t, y))

    def total_friction(self, t, y):
        return self.forces(t, y)[1].sum()


def _state_scale(sim: Simulation, n: int) -> np.ndarray:
    """Scale of each unknown: u, theta (as Newton's norms) and their rates (c times them)."""
    P, sc = sim.params, sim.disc.scales
    vel = P.c * sc.theta
    return np.concatenate([np.tile([sc.u, sc.theta], n), np.tile([vel, vel / P.L], n)])


def step_to_steady(solver, steady, check, cap, start, measure):
    """Step a scipy ``OdeSolver`` (Radau, BDF) by hand, as ``solve_ivp`` does, testing the
    run's steady state at its check times k ``check`` on the dense output:
    ``steady.update(t, *measure(t, y))``, measure giving (rate, monitor). Stops steady,
    at the solver's end or failure, or ``cap`` s of wall time after ``start``. Returns
    (converged, reason, steps, t, y): t, y the last state checked (y None: none)."""
    k, converged, reason, steps, t, y = 1, False, "not steady by t_end", 0, 0.0, None
    while solver.status == "running":
        if time.perf_counter() - start > cap:
            reason = f"stopped at the {cap:g} s wall-time cap at t = {solver.t:.4g} s"
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
                converged = steady.update(t, *measure(t, y))
                k += 1
            if converged:
                reason = "steady"
                break
    return converged, reason, steps, t, y


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
    totals = [0.0]

    def measure(t, y):
        totals[0] = sysm.total_friction(t, y)
        rates = y[2 * n:]
        return (max(np.abs(rates[0::2]).max(), P.L * np.abs(rates[1::2]).max()) / vel,
                totals[0])

    converged, reason, steps, _, _ = step_to_steady(solver, steady, check, max_wall, start,
                                                    measure)
    total = totals[0]
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
    row_scale = np.tile([sc.force, sc.moment], n)
    jac = model.pattern(1.0 / row_scale, columns=2)
    x_scale = _state_scale(sim, n)[:2 * n]
    tol = num.newton_tol
    target = d.model.regularisation
    x = np.zeros(2 * n)
    iterations = factorisations = evaluations = 0

    def residual(x, p):
        return model.forces(0.0, x, drive, p)[0] / row_scale

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
    done = regularisation = max(target, abs(P.v - P.c))
    first = True
    while True:
        trial = solve_stage(x, d.model._replace(regularisation=regularisation),
                            tol if regularisation <= target else inner_tol)
        if trial is not None:
            x, done, first = trial, regularisation, False
            if regularisation <= target:
                converged = True
                break
        elif first:
            reason = f"Newton failed at v_reg = {regularisation:.3g} m/s"
            break
        else:
            factor = math.sqrt(factor)
            if factor < 1.01:
                reason = f"Newton failed below v_reg = {done:.3g} m/s"
                break
        regularisation = max(target, done / factor)
    total = float(model.forces(0.0, x, drive)[1].sum())
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
