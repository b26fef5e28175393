"""Generic peers of the closed drive's steady scheme and start-up: the same discrete
equations solved by generic tools.

Every peer works on beltsim's own discretisation of the drive (a
:class:`~beltsim.solvers.base.LoopDiscretisation`: the same grid, coefficients and
layout) through the vectorised reference of the kernel's residual,
:func:`beltsim.physics.reference.loop_residual` (numpy; tests/test_drive_model.py
compares it with the numba kernel). What it does not hold, the peer writes in the
generic way:

* the exact (Coulomb) law's friction ratios are unknowns; the reference takes them as
  they are, and the peer adds their equations as the usual projection (NCP) function
  lam - proj_[-1, 1](lam + v_rel / v_aug) = 0 (:meth:`LoopProblem.residual`; v_rel as
  the reference computes it, checked against the kernel by :func:`check_slip_velocity`),
  solved by semi-smooth Newton: their rows of the Jacobian are the projection's
  generalised derivative (e_lam where a node slides, -ds/dx where it sticks);
* the Jacobian of the smooth rest is taken by finite differences with the sparsity
  pattern of the stencil (``scipy.optimize._numdiff.approx_derivative`` with
  ``sparsity=``, its columns grouped once), the scaled slip velocities s among the
  differenced outputs (differences of the projection itself, across its kink, made
  Newton crawl). The loop's global rows are dense (the gauge is the mean of u, each
  pulley's row sums the friction of its arc), which would put every column in a group
  of its own: they are taken by the chain rule instead, the gauge's row as it is
  written (hb / L) and each pulley's as the sum of its arc's nodal frictions' rows,
  which the differences give (the nodal frictions are outputs of the differenced
  function).

Peers:

* :func:`run_newton_peer`: Newton on the steady residual (inv_dt = 0, the final drive:
  the steady scheme's form) with ``scipy.sparse.linalg.spsolve`` and a backtracking line
  search, from the creep theory's state (:func:`beltsim.solvers.steady.creep_state`, our
  steady scheme's start); with ``twin``, first the regularised twin (tanh at
  LOOP_REGULARISATION times the creep speed) as our steady scheme does;
* :func:`run_root_peer`: ``scipy.optimize.root`` ("krylov", Jacobian-free
  Newton-Krylov; "hybr", MINPACK's Powell hybrid with its own dense differences) on the
  scaled steady residual from the same start;
* :func:`run_bdf2_peer`: the start-up from rest by variable-step BDF2 (written in the
  reference's backward-Euler form with a shifted history) under the exact law, a
  simplified Newton iteration per step on the sparse differenced Jacobian factorised by
  ``scipy.sparse.linalg.splu`` (refreshed when it stalls), a local error estimate from a
  quadratic predictor, and our run's steady test at our run's check times;
* :func:`run_ode_peer`: ``solve_ivp``'s Radau or BDF from rest on the method-of-lines
  ODE of the tanh law (:class:`DriveODE`), dense differenced Jacobian, our run's steady
  test on its dense output.

A peer counts only if it reaches our state: each span tension and each global (the belt's
and the pulleys' speeds) within SAME_STEADY (the steady peers, against our steady
scheme's state) or SAME_RUN (the start-up, which stops at the steady test's tolerance)
relative. Wall times are of the whole call; every peer is stopped at ``cap`` seconds.
"""

from __future__ import annotations

import math
import time
from typing import NamedTuple

import numpy as np

from beltsim.physics import reference
from beltsim.physics.discrete import State
from beltsim.physics.friction import ADHESION, EXACT, TANH, is_exact
from beltsim.problem.drive import value

from .peers import step_to_steady

#: a steady peer's span tensions and globals within this of our steady state (relative)
SAME_STEADY = 1e-8
#: the start-up's: our own run stops ~1e-8 to 1e-7 from the steady state (steady_tol 1e-7)
SAME_RUN = 1e-6
#: the BDF2 peer's local error tolerance: our BDF2 scheme's on a loop
#: (solvers.settings.LOOP_TIME_TOLS["implicit"])
BDF2_TOL = 1e-3


class PeerResult(NamedTuple):
    name: str
    wall_time: float  # s, the whole call
    converged: bool  # its own test passed
    reason: str  # "converged", or why not
    state: State | None  # its final state (for the comparison with ours)
    statistics: dict
    simulated_time: float | None = None  # the start-up


class _WallCap(Exception):
    """Raised inside a scipy call to stop it at the wall-time cap."""


class LoopProblem:
    """The reference's loop residual as a function of one vector of unknowns
    x = (u (N), theta (N), lam (the contact nodes', an exact law only), g (the globals)),
    and its sparse Jacobian by grouped finite differences.

    ``model`` replaces the discretisation's (the regularised twin).
    """

    def __init__(self, d, model=None):
        self.d = d
        self.mesh = m = d.mesh
        self.p = p = d.model if model is None else model
        self.N = N = len(m.hb)
        self.cn = cn = np.asarray(m.cn)
        self.M = M = len(cn)
        self.exact = is_exact(p.law)
        self.nl = M if self.exact else 0
        self.ng = ng = d.n_globals
        self.size = 2 * N + self.nl + ng
        self.evaluations = 0
        self.jacobians = 0
        seg = np.maximum(m.seg, 0)
        self._K = np.where(m.seg >= 0, m.seg_speed[seg], -1)
        self._R = np.where(m.seg >= 0, m.seg_radius[seg], 1.0)
        # each free pulley's row: the sum of R_j F_j over its arc (rows k >= 1)
        K = self._K[cn]
        rows = K[K >= 1]
        self._arc = _csr((self._R[cn][K >= 1], (rows, np.flatnonzero(K >= 1))), (ng, M))
        self._gauge = m.hb / m.loop_length
        self._pattern()

    # -- unknowns --------------------------------------------------------------------
    def pack(self, st: State) -> np.ndarray:
        parts = [st.u, st.theta] + ([st.lam[self.cn]] if self.exact else []) + [st.g]
        return np.concatenate(parts).astype(float)

    def unpack(self, x):
        N = self.N
        lam = np.zeros(N)
        if self.exact:
            lam[self.cn] = x[2 * N:2 * N + self.M]
        return x[:N], x[N:2 * N], lam, x[2 * N + self.nl:]

    def scale(self) -> np.ndarray:
        """Each unknown's scale (our Newton's: the displacement and rotation scales, 1 for
        a ratio, the globals' speed scales)."""
        sc = self.d.scales
        return np.concatenate([np.full(self.N, sc.u), np.full(self.N, sc.theta),
                               np.ones(self.nl), sc.glob])

    def row_scale(self) -> np.ndarray:
        """Each row's scale: force, moment (interleaved), 1 (the NCP rows), the globals'."""
        sc = self.d.scales
        return np.concatenate([np.tile([sc.force, sc.moment], self.N), np.ones(self.nl),
                               sc.gres])

    # -- the equations ---------------------------------------------------------------
    def slip_velocity(self, u, th, g, old, inv_dt, t, drive):
        """v_rel at the contact nodes, as :func:`reference.loop_residual` computes it."""
        p, m, cn = self.p, self.mesh, self.cn
        c = g[0]
        hh = p.half_height * m.face
        ub, ubo = u + hh * th, old.u + hh * old.theta
        sw = m.sw
        st = sw[:, 0] * np.roll(ub, 2) + sw[:, 1] * np.roll(ub, 1) + sw[:, 2] * ub
        rim = np.where(self._K >= 1, g[np.maximum(self._K, 0)] * self._R,
                       value(drive.speed, t))
        v = (ub - ubo) * inv_dt + c * st - (rim - c * (1.0 + p.N0 / p.b1))
        return v[cn]

    def local(self, x, old, inv_dt, t, drive):
        """The rows the differences take (all smooth): the nodes' rows (interleaved), the
        contact nodes' scaled slip velocities v_rel / v_aug (an exact law), their
        frictions F; and (Rg, F) as the reference gave them."""
        self.evaluations += 1
        u, th, lam, g = self.unpack(x)
        R, Rg, F = reference.loop_residual(u, th, lam, g, old, inv_dt, t, self.mesh,
                                           self.p, drive)
        parts = [R.ravel()]
        if self.exact:
            parts.append(self.slip_velocity(u, th, g, old, inv_dt, t, drive)
                         / self.p.regularisation)
        parts.append(F[self.cn])
        return np.concatenate(parts), Rg, F

    def _ncp(self, x, s):
        """The exact law's rows lam - proj_[-1, 1](lam + s) (adhesion: -s) and the
        stuck nodes (where the projection is inside)."""
        lc = x[2 * self.N:2 * self.N + self.M]
        if self.p.law == ADHESION:
            return -s, np.ones(self.M, bool)
        z = lc + s
        return lc - np.clip(z, -1.0, 1.0), np.abs(z) < 1.0

    def residual(self, x, old, inv_dt, t, drive):
        """The whole residual: the nodes' rows, the NCP rows, the global rows."""
        loc, Rg, _ = self.local(x, old, inv_dt, t, drive)
        self._last = (x.copy(), loc)  # the differences' f0 when the Jacobian is taken here
        parts = [loc[:2 * self.N]]
        if self.exact:
            parts.append(self._ncp(x, loc[2 * self.N:2 * self.N + self.M])[0])
        return np.concatenate([*parts, Rg])

    def _pattern(self):
        """The local rows' dependence on the unknowns (node j's rows on u, theta at
        j - 2 .. j + 1 round the loop, its own ratio, every global), and its column
        groups."""
        from scipy.optimize._numdiff import group_columns

        N, M, nl, ng, cn = self.N, self.M, self.nl, self.ng, self.cn
        rows, cols = [], []
        # the local row index of each node's rows
        r_u, r_t = 2 * np.arange(N), 2 * np.arange(N) + 1
        pos = np.full(N, -1)
        pos[cn] = np.arange(M)
        r_n = 2 * N + pos[cn]  # the slip velocities' rows (an exact law)
        r_f = 2 * N + nl + pos[cn]  # the frictions' rows
        for o in (-2, -1, 0, 1):
            k = (np.arange(N) + o) % N
            for col in (k, N + k):
                rows += [r_u, r_t]
                cols += [col, col]
            kc = (cn + o) % N
            if o <= 0:
                for col in (kc, N + kc):
                    for r in ([r_n] if nl else []) + [r_f]:
                        rows.append(r)
                        cols.append(col)
        if nl:
            lc = 2 * N + np.arange(M)
            for r in (r_u[cn], r_t[cn], r_n, r_f):
                rows.append(r)
                cols.append(lc)
        n_loc = 2 * N + nl + M
        for k in range(ng):
            rows.append(np.arange(n_loc))
            cols.append(np.full(n_loc, 2 * N + nl + k))
        r, c = np.concatenate(rows), np.concatenate(cols)
        self.sparsity = _csr((np.ones(r.size), (r, c)), (n_loc, self.size))
        self.sparsity.data[:] = 1.0
        self.groups = group_columns(self.sparsity)

    def jacobian(self, x, old, inv_dt, t, drive, f0=None):
        """d residual / dx (CSC): the local rows by grouped differences, the global rows by
        the chain rule."""
        from scipy.optimize._numdiff import approx_derivative
        from scipy.sparse import csr_matrix, vstack

        self.jacobians += 1
        last = getattr(self, "_last", None)
        if f0 is None and last is not None and np.array_equal(last[0], x):
            f0 = last[1]
        if f0 is None:
            f0 = self.local(x, old, inv_dt, t, drive)[0]
        J = approx_derivative(lambda y: self.local(y, old, inv_dt, t, drive)[0], x,
                              method="2-point", f0=f0, sparsity=(self.sparsity, self.groups))
        J = csr_matrix(J)
        N, nl, M = self.N, self.nl, self.M
        dF = J[-M:]
        rows = [J[:2 * N]]
        if self.exact:
            # the projection's generalised derivative (semi-smooth Newton): e_lam - stuck
            # (e_lam + ds/dx), ds/dx by the differences
            _, stuck = self._ncp(x, f0[2 * N:2 * N + M])
            e = csr_matrix((np.ones(M), (np.arange(M), 2 * N + np.arange(M))),
                           shape=(M, self.size))
            ds = J[2 * N:2 * N + M]
            if self.p.law == ADHESION:
                rows.append(-ds)
            else:
                rows.append(e - _diag(stuck) @ (e + ds))
        gauge = csr_matrix((self._gauge, (np.zeros(N, int), np.arange(N))),
                           shape=(1, self.size))
        pulleys = (self._arc @ dF)[1:]
        own = np.asarray(self.mesh.inertia[1:self.ng]) * inv_dt
        if own.any():
            gi = 2 * N + nl + np.arange(1, self.ng)
            pulleys = pulleys + csr_matrix((own, (np.arange(self.ng - 1), gi)),
                                           shape=pulleys.shape)
        return vstack([*rows, gauge, pulleys]).tocsc()

    def state(self, x, F=None, rates=None) -> State:
        """x as a State (rates zero unless given; fnode F)."""
        u, th, lam, g = self.unpack(x)
        N = self.N
        ud, td, gd = rates if rates is not None else (np.zeros(N), np.zeros(N),
                                                      np.zeros(self.ng))
        lam_full = lam.copy()
        return State(u.copy(), th.copy(), lam_full, ud, td,
                     np.zeros(N) if F is None else F.copy(), g.copy(), gd)


def _diag(mask):
    from scipy.sparse import diags

    return diags(mask.astype(float)).tocsr()


def _csr(data, shape):
    from scipy.sparse import csr_matrix

    return csr_matrix(data, shape=shape)


def check_slip_velocity(d, state, inv_dt=0.0) -> float:
    """The largest difference of :meth:`LoopProblem.slip_velocity` from the kernel's
    (its w.rl times v_aug, exact law) at a state, relative to the creep speed."""
    from beltsim.physics.model import assemble
    from beltsim.solvers.newton import Workspace

    p = d.model._replace(law=EXACT, dual=0)
    N = len(d.mesh.hb)
    w = Workspace.allocate(N, False, True, d.n_globals)
    drive = d.steady_drive()
    assemble(state.u.copy(), state.theta.copy(), state.lam.copy(), state.g.copy(),
             np.zeros(N), state, inv_dt, 0.0, d.mesh, p, drive, d.loads, w, False)
    prob = LoopProblem(d, p)
    v = prob.slip_velocity(state.u, state.theta, state.g, state, inv_dt, 0.0, drive)
    cn = prob.cn
    creep = d.params.driver_rim_speed * d.params.N0 / d.params.b1
    return float(np.abs(v - w.rl[cn] * p.regularisation).max() / creep)


def _newton(prob, x, old, inv_dt, t, drive, tol, max_iterations, deadline, stats,
            linear="spsolve", refresh=True):
    """Newton with a backtracking line search on the scaled residual; converged when a
    full step's scaled update is below tol. Returns (x, converged, reason)."""
    from scipy.sparse.linalg import spsolve

    xs, rs = prob.scale(), prob.row_scale()
    r = prob.residual(x, old, inv_dt, t, drive)
    merit = float(np.sum((r / rs) ** 2))
    for _ in range(max_iterations):
        if time.perf_counter() > deadline:
            raise _WallCap
        J = prob.jacobian(x, old, inv_dt, t, drive)
        dx = spsolve(J, -r)
        stats["newton_iterations"] = stats.get("newton_iterations", 0) + 1
        if not np.all(np.isfinite(dx)):
            return x, False, "singular Jacobian"
        step = float(np.abs(dx / xs).max())
        a = 1.0
        while True:
            trial = x + a * dx
            r_try = prob.residual(trial, old, inv_dt, t, drive)
            m_try = float(np.sum((r_try / rs) ** 2))
            if m_try <= (1.0 - 1e-4 * a) * merit or a < 1.0 / 256 or m_try < 1e-26:
                break
            a *= 0.5
        x, r, merit = trial, r_try, m_try
        if a == 1.0 and step < tol:
            return x, True, "converged"
    return x, False, f"not converged in {max_iterations} Newton iterations (scaled " \
                     f"residual {math.sqrt(merit):.3g})"


def _steady_start(d, cap, tol):
    """What a steady peer starts from: the clock and its deadline ``cap`` s on, the
    tolerance (default our Newton's), the creep theory's state, the steady drive and an
    old state (unused at inv_dt = 0)."""
    from beltsim.solvers.steady import creep_state

    start = time.perf_counter()
    tol = d.numerics.newton_tol if tol is None else tol
    st = d.new_state()
    creep_state(d, st)
    return start, start + cap, tol, st, d.steady_drive(), d.new_state()


def run_newton_peer(d, twin: bool = False, cap: float = 300.0, tol: float | None = None,
                    max_iterations: int = 100) -> PeerResult:
    """Newton on the steady residual, sparse differenced Jacobian, spsolve, from the
    creep theory's state; ``twin``: first the regularised twin, then the exact law from
    its state (our steady scheme's stages)."""
    from beltsim.beltdrive.analytic import creep_speed
    from beltsim.solvers.settings import LOOP_REGULARISATION

    name = ("Newton, reference residual, sparse FD Jacobian (grouped), spsolve"
            + (", tanh twin first" if twin else ""))
    start, deadline, tol, st, drive, old = _steady_start(d, cap, tol)
    stats: dict = {}
    model = d.model
    x = None
    try:
        if twin and model.law == EXACT:
            p2 = model._replace(law=TANH, dual=0,
                                regularisation=LOOP_REGULARISATION * creep_speed(d.params))
            tp = LoopProblem(d, p2)
            xt, ok, why = _newton(tp, tp.pack(st), old, 0.0, 0.0, drive, tol,
                                  max_iterations, deadline, stats)
            if not ok:
                return PeerResult(name, time.perf_counter() - start, False,
                                  f"the twin: {why}", tp.state(xt), stats)
            # the twin's ratios g(v_rel / v_reg) as the exact law's start
            u, th, _, g = tp.unpack(xt)
            v = tp.slip_velocity(u, th, g, old, 0.0, 0.0, drive)
            st = tp.state(xt)
            st.lam[tp.cn] = np.tanh(v / p2.regularisation)
            stats["twin_evaluations"] = tp.evaluations
        prob = LoopProblem(d, model)
        x, ok, why = _newton(prob, prob.pack(st), old, 0.0, 0.0, drive, tol,
                             max_iterations, deadline, stats)
    except _WallCap:
        return PeerResult(name, time.perf_counter() - start, False,
                          f"stopped at the {cap:g} s cap", None, stats)
    wall = time.perf_counter() - start
    stats.update(evaluations=prob.evaluations, jacobians=prob.jacobians,
                 groups=int(prob.groups.max() + 1))
    _, _, F = prob.local(x, old, 0.0, 0.0, drive)
    return PeerResult(name, wall, ok, why, prob.state(x, F), stats)


def run_root_peer(d, method: str = "krylov", cap: float = 300.0,
                  tol: float | None = None) -> PeerResult:
    """``scipy.optimize.root`` on the scaled steady residual (the exact law with its NCP
    rows) from the creep theory's state: "krylov" (Newton-Krylov, LGMRES, Jacobian-free)
    or "hybr" (MINPACK, its own dense forward differences)."""
    from scipy.optimize import root


    name = {"krylov": "scipy.optimize.root krylov (Newton-LGMRES, Jacobian-free)",
            "hybr": "scipy.optimize.root hybr (MINPACK, dense FD Jacobian)",
            "lm": "scipy.optimize.root lm (MINPACK, dense FD Jacobian)"}[method]
    start, deadline, tol, st, drive, old = _steady_start(d, cap, tol)
    prob = LoopProblem(d)
    xs, rs = prob.scale(), prob.row_scale()

    def fun(z):
        if time.perf_counter() > deadline:
            raise _WallCap
        return prob.residual(z * xs, old, 0.0, 0.0, drive) / rs

    opts = {"krylov": {"fatol": 1e-12, "xtol": tol, "maxiter": 1000},
            "hybr": {"xtol": tol}, "lm": {"xtol": tol}}[method]
    try:
        sol = root(fun, prob.pack(st) / xs, method=method, options=opts)
    except _WallCap:
        return PeerResult(name, time.perf_counter() - start, False,
                          f"stopped at the {cap:g} s cap", None,
                          {"evaluations": prob.evaluations})
    wall = time.perf_counter() - start
    x = sol.x * xs
    ok = bool(sol.success)
    reason = "converged" if ok else f"not converged: {' '.join(str(sol.message).split())}"
    _, _, F = prob.local(x, old, 0.0, 0.0, drive)
    res = float(np.abs(prob.residual(x, old, 0.0, 0.0, drive) / rs).max())
    return PeerResult(name, wall, ok, reason, prob.state(x, F),
                      {"evaluations": prob.evaluations, "scaled_residual": res})


def run_bdf2_peer(sim, cap: float = 300.0, tol: float = BDF2_TOL,
                  max_newton: int = 8) -> PeerResult:
    """The start-up from rest by variable-step BDF2 under the scene's law (exact: NCP
    rows), stopped by our run's steady test (``sim.steady``) at our check times.

    BDF2 in the reference's backward-Euler form: with step h and ratio w = h / h_prev,
    y' = a (y - y~), a = (1 + 2w) / ((1 + w) h), y~ = ((1 + w) y_n - w^2 / (1 + w)
    y_{n-1}) / (a h): the reference's ``old`` holds y~ for u, theta, the globals and the
    rates u_t, theta_t (the first step is backward Euler). Each step: a simplified Newton
    iteration from the quadratic predictor with the Jacobian (differences) factorised
    once by splu, refreshed (at most twice) when the update does not contract by half or
    gives no descent, its steps cut back on the scaled residual norm (a semi-smooth step
    can cycle between stick and slip);
    the local error 2/7 |y - y_pred| (BDF2's error constant against the predictor's) in
    the scaled max norm of u, theta and the globals; h_new = h min(2, max(0.2, 0.9
    (tol / err)^(1/3))), a step whose error exceeds tol or whose Newton fails is redone
    with a smaller one. Steps land on the check times.
    """
    from scipy.sparse.linalg import splu

    name = f"BDF2 steps (tol {tol:g}), reference residual, sparse FD Jacobian, splu"
    start = time.perf_counter()
    deadline = start + cap
    d = sim.disc
    prob = LoopProblem(d)
    num = d.numerics
    N, ng, nl = prob.N, prob.ng, prob.nl
    xs, rs = prob.scale(), prob.row_scale()
    err_mask = np.ones(prob.size, bool)
    err_mask[2 * N:2 * N + nl] = False  # the ratios jump at stick/slip: not in the error
    x = prob.pack(d.new_state())
    v = np.zeros(2 * N + ng)  # rates of u, theta and the globals
    hist: list = [(0.0, x.copy(), v.copy())]
    t, h = 0.0, num.dt
    steady, check, t_end = sim.steady, sim.check, num.t_end
    k_check = 1
    stats = {"steps": 0, "rejected": 0, "newton_iterations": 0, "jacobians": 0}
    converged, reason, F = False, "not steady by t_end", np.zeros(N)
    pos = np.r_[0:2 * N, 2 * N + nl:prob.size]  # the unknowns with rates
    lu = None

    def rate_state(xv, vv, Fv):
        ud, td, gd = vv[:N], vv[N:2 * N], vv[2 * N:]
        return prob.state(xv, Fv, (ud, td, gd))

    try:
        while t < t_end:
            if time.perf_counter() > deadline:
                reason = f"stopped at the {cap:g} s cap at t = {t:.4g} s"
                break
            h = min(h, k_check * check - t)
            t1 = t + h
            # history: BE on the first step, BDF2 after
            if len(hist) >= 2:
                t0_, x0_, v0_ = hist[-2]
                w = h / (t - t0_)
            else:
                w = 0.0
            a = (1.0 + 2.0 * w) / ((1.0 + w) * h)
            vn = hist[-1][2]
            if len(hist) >= 2:
                xt_ = ((1.0 + w) * x[pos] - w * w / (1.0 + w) * x0_[pos]) / (a * h)
                vt_ = ((1.0 + w) * vn - w * w / (1.0 + w) * v0_) / (a * h)
            else:
                xt_, vt_ = x[pos].copy(), vn.copy()
            old = State(xt_[:N], xt_[N:2 * N], np.zeros(N), vt_[:N], vt_[N:2 * N],
                        np.zeros(N), xt_[2 * N:], vt_[2 * N:])
            # the predictor: quadratic through the last three points (fewer at the start)
            ts = [p[0] for p in hist[-3:]]
            pred = np.zeros_like(x)
            for i, (ti, xi, _) in enumerate(hist[-3:]):
                li = 1.0
                for m, tm in enumerate(ts):
                    if m != i:
                        li *= (t1 - tm) / (ti - tm)
                pred += li * xi
            y = pred.copy()
            ok, refreshes, last, fresh = False, 0, math.inf, False
            r = prob.residual(y, old, a, t1, d.drive)
            merit = float(np.sum((r / rs) ** 2))
            for it in range(3 * max_newton):
                if lu is None:
                    stats["jacobians"] += 1
                    try:
                        lu = splu(prob.jacobian(y, old, a, t1, d.drive))
                    except RuntimeError:  # "Factor is exactly singular": a smaller step
                        stats["singular"] = stats.get("singular", 0) + 1
                        break
                    last, fresh = math.inf, True
                dy = lu.solve(-r)
                stats["newton_iterations"] += 1
                if not np.all(np.isfinite(dy)):
                    break
                # backtracking on the scaled residual norm (semi-smooth steps can cycle)
                lam_ = 1.0
                while True:
                    trial = y + lam_ * dy
                    r_try = prob.residual(trial, old, a, t1, d.drive)
                    m_try = float(np.sum((r_try / rs) ** 2))
                    if m_try <= (1.0 - 1e-4 * lam_) * merit or lam_ < 1.0 / 128:
                        break
                    lam_ *= 0.5
                if lam_ < 1.0 / 128 and m_try > merit:
                    if fresh or refreshes >= 2:
                        break
                    lu, refreshes = None, refreshes + 1  # no descent: a fresh Jacobian
                    continue
                y, r, merit, fresh = trial, r_try, m_try, False
                step = lam_ * float(np.abs(dy / xs).max())
                if lam_ == 1.0 and step < num.newton_tol * 1e3:
                    ok = True
                    break
                if step > 0.5 * last or (it + 1) % max_newton == 0:
                    if refreshes >= 2:
                        break
                    lu, refreshes = None, refreshes + 1
                last = step
            if not ok:
                stats["rejected"] += 1
                lu = None
                h *= 0.25
                if h < 1e-12:
                    reason = f"step size collapsed at t = {t:.4g} s"
                    break
                continue
            err = (2.0 / 7.0) * float(np.abs((y - pred) / xs)[err_mask].max()) \
                if len(hist) >= 3 else 0.0
            if err > tol:
                stats["rejected"] += 1
                h *= max(0.2, 0.9 * (tol / err) ** (1.0 / 3.0))
                continue
            vnew = a * (y[pos] - xt_)
            t, x, v = t1, y, vnew
            hist = (hist + [(t, x.copy(), v.copy())])[-3:]
            stats["steps"] += 1
            grow = 2.0 if err == 0.0 else min(2.0, max(0.2, 0.9 * (tol / err) ** (1 / 3)))
            h *= grow
            if t >= k_check * check * (1 - 1e-12):
                _, _, F = prob.local(x, old, a, t, d.drive)
                st = rate_state(x, v, F)
                done = steady.update(t, sim.readout.rate(st), sim.readout.monitor(st))
                k_check += 1
                if done:
                    converged, reason = True, "steady"
                    break
    except _WallCap:
        reason = f"stopped at the {cap:g} s cap at t = {t:.4g} s"
    wall = time.perf_counter() - start
    stats["evaluations"] = prob.evaluations
    return PeerResult(name, wall, converged, reason, rate_state(x, v, F), stats, t)


def difference(d, state: State, ours: State) -> float:
    """The largest relative difference of the span tensions and the globals (the belt's
    and the free pulleys' speeds) of two states."""
    from beltsim.simulation.loop_solution import LoopSolution

    if state is None or not np.all(np.isfinite(state.u)):
        return math.inf
    a = LoopSolution(d, state).span_tensions()
    b = LoopSolution(d, ours).span_tensions()
    out = float(np.max(np.abs(a - b) / np.abs(b)))
    return max(out, float(np.max(np.abs(state.g - ours.g) / np.abs(ours.g))))


class DriveODE:
    """The drive's semi-discretisation as y' = f(t, y) for a regularised law (the ratio
    lam = g(v_rel / v_reg) is then of the state): y = (u, theta, g, u_t, theta_t).

    The reference's residual with the rates as history and zero accelerations (inv_dt
    = 1, old = (u - u_t, theta - theta_t, rates u_t, theta_t, globals g)) is the forces'
    imbalance R0; then rho hb (u_tt + c_t) = -R0 (axial rows), I hb theta_tt = -R0
    (bending rows), J_k omega_k' = -Rg_k (each free pulley), and the gauge (the mean of u
    stays 0) gives c_t = -sum(R0 axial) / (rho sum hb). c_t enters every axial row: the
    Jacobian is dense, and scipy's integrators take it by dense differences.
    """

    def __init__(self, d):
        p = d.model
        if is_exact(p.law):
            raise ValueError("the ODE form needs a regularised friction law")
        if p.rotary_inertia <= 0.0 or np.any(np.asarray(d.mesh.inertia[1:]) <= 0.0):
            raise ValueError("the ODE form needs rotary inertia and every free pulley's")
        self.d, self.p, self.mesh = d, p, d.mesh
        self.N = N = len(d.mesh.hb)
        self.ng = ng = d.n_globals
        self.size = 4 * N + ng
        self.mu = p.mass * d.mesh.hb
        self.mt = p.rotary_inertia * d.mesh.hb
        self.J = np.asarray(d.mesh.inertia[1:ng], float)
        self.evaluations = 0

    def parts(self, y):
        N, ng = self.N, self.ng
        return (y[:N], y[N:2 * N], y[2 * N:2 * N + ng], y[2 * N + ng:3 * N + ng],
                y[3 * N + ng:])

    def forces(self, t, y, drive=None):
        """(R, Rg, F) of the reference at zero accelerations."""
        u, th, g, ud, td = self.parts(y)
        old = State(u - ud, th - td, np.zeros(self.N), ud, td, np.zeros(self.N), g,
                    np.zeros(self.ng))
        return reference.loop_residual(u, th, np.zeros(self.N), g, old, 1.0, t, self.mesh,
                                       self.p, self.d.drive if drive is None else drive)

    def rhs(self, t, y):
        self.evaluations += 1
        R, Rg, _ = self.forces(t, y)
        N, ng = self.N, self.ng
        ct = -R[:, 0].sum() / self.mu.sum()
        out = np.empty(self.size)
        out[:2 * N] = y[2 * N + ng:]
        out[2 * N] = ct
        out[2 * N + 1:2 * N + ng] = -Rg[1:] / self.J
        out[2 * N + ng:3 * N + ng] = -R[:, 0] / self.mu - ct
        out[3 * N + ng:] = -R[:, 1] / self.mt
        return out

    def scale(self) -> np.ndarray:
        """Each unknown's scale: our Newton's, and for the rates the creep speed (u_t)
        and it over the loop length (theta_t)."""
        sc, P = self.d.scales, self.d.params
        creep = P.driver_rim_speed * P.N0 / P.b1
        N = self.N
        return np.concatenate([np.full(N, sc.u), np.full(N, sc.theta), sc.glob,
                               np.full(N, creep),
                               np.full(N, creep / self.mesh.loop_length)])

    def state(self, t, y) -> State:
        u, th, g, ud, td = self.parts(y)
        _, _, F = self.forces(t, y)
        gd = self.rhs(t, y)[2 * self.N:2 * self.N + self.ng]
        return State(u.copy(), th.copy(), np.zeros(self.N), ud.copy(), td.copy(), F, g.copy(),
                     gd)


def run_ode_peer(sim, method: str = "Radau", rtol: float = 1e-3,
                 cap: float = 300.0) -> PeerResult:
    """scipy's Radau or BDF (the classes behind ``solve_ivp(method=...)``) from rest on
    :class:`DriveODE` with scipy's dense finite-difference Jacobian, atol rtol times each
    unknown's scale; stepped by hand, as ``solve_ivp`` does, only so that our run's steady
    test (``sim.steady``, at our check times, on the dense output) can stop it."""
    from scipy.integrate import BDF, Radau

    name = f"solve_ivp {method} (rtol {rtol:g}), tanh law, dense FD Jacobian"
    start = time.perf_counter()
    d = sim.disc
    ode = DriveODE(d)
    num = d.numerics
    solver = {"Radau": Radau, "BDF": BDF}[method](
        ode.rhs, 0.0, np.zeros(ode.size), num.t_end, rtol=rtol, atol=rtol * ode.scale())
    steady, check = sim.steady, sim.check

    def measure(t, y):
        st = ode.state(t, y)
        return sim.readout.rate(st), sim.readout.monitor(st)

    converged, reason, steps, t, y = step_to_steady(solver, steady, check, cap, start,
                                                    measure)
    wall = time.perf_counter() - start
    if not converged and reason.startswith("not steady"):
        # at rtol 1e-3 the end state is close, but its rates (the light pulleys'
        # accelerations) stay above the steady test's tolerance
        reason += f" (its rate {steady.rate:.1e} against the test's {steady.tol:g})"
    if not converged:
        t, y = solver.t, solver.y
    stats = {"steps": steps, "evaluations": solver.nfev, "jacobians": solver.njev,
             "factorisations": solver.nlu}
    return PeerResult(name, wall, converged, reason, ode.state(t, y), stats, t)
