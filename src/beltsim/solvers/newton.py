"""Newton's method on the discrete equations, shared by the implicit and steady schemes.

The residual of :func:`beltsim.physics.model.assemble` at one time level (or at
steady state, ``inv_dt`` = 0) is solved for (u, theta) and, for saturating friction
laws, the friction ratios. A plain Newton step cycles on sharp friction (slope
f*/v_reg ~ 1e8 or more): the primal form is globalised by a backtracking line
search on a scaled residual norm; the primal-dual form (friction ratio as an
unknown, kept inside (-1, 1)) converges with full steps.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from ..errors import FailureKind, NumericalError
from ..physics.friction import EXACT, is_exact
from ..physics.model import (
    JACOBIAN,
    add_stick_penalty,
    assemble,
    bound_scale,
    loop_speed,
)
from ..problem.drive import friction_factor
from .base import Scheme
from .border import Border, block_substitute_many, finish, gather, schur
from .dual import release_stuck_ratios, update_multipliers
from .ssn import Saddle, project, saddle_factorise, saddle_resolve, saddle_system

# status codes of the time-stepping kernels that solve with Newton
OK, FAILED, NONFINITE = 0, 1, 2
# How far above the tolerance a stalled Newton update may be and still count as
# converged: 1e3 * 1e-9 = 1e-6, an order below the discretisation error of the finest
# grids (docs/theory/discretisation.md, "Newton's method").
ROUNDOFF_FLOOR = 1e3
# Largest ratio of successive updates (the rate) with which the error an update leaves
# is estimated as rate / (1 - rate) times the update: Newton stops when that is below
# tol, one iteration before the update itself would be
CONTRACTION = 0.5
# A scaled residual of root mean square below 1e-13 per row is at round-off
ROUNDOFF_MERIT = 1e-26
# full semi-smooth Newton steps before a step whose stick/slip pattern still changes is
# damped (a cycle between patterns, each one's full step landing in the other), and the
# most halvings of such a step
CYCLE_ITERATIONS = 8
MAX_HALVINGS = 8
# The primal-dual iteration keeps its factorisation for the next iteration (a chord
# step: the residual and the friction slopes are assembled anew) while its updates shrink
# by this factor or more: the Jacobian then changes too little to matter, and the
# bordered factorisation is half of an iteration's cost. A slower contraction, or a
# growing update, factorises again.
CHORD = 0.2

#: Counters a scheme accumulates, one record the kernels update in place.
STATS_DTYPE = np.dtype([("newton_iterations", np.int64), ("failed_steps", np.int64),
                        ("line_search_cuts", np.int64), ("merit", np.float64)])


class NewtonSettings(NamedTuple):
    """Newton's stopping rule: the tolerance and the most iterations; and whether the
    caller needs the factors of the converged Jacobian (an error estimate's)."""

    tol: float  # scaled max norm of the update
    max_iterations: int
    # False: an exact law's solve skips the factorisation it would leave for the caller
    factors: bool = True


class Workspace(NamedTuple):
    """Preallocated arrays of the Newton kernels (n rows: N - 1 open, N closed)."""

    R: np.ndarray  # residual (n, 2)
    Lb: np.ndarray  # Jacobian blocks (n, 2, 2)
    L2: np.ndarray  # second lower band (the friction stencil reaches node j - 2)
    Db: np.ndarray
    Ub: np.ndarray
    C: np.ndarray  # block LU of the Jacobian (block_factor): inverse pivots (n, 2, 2),
    W: np.ndarray  # multipliers,
    W2: np.ndarray  # those of the second lower band,
    U: np.ndarray  # upper blocks (a line search assembles Ub anew)
    dx: np.ndarray  # Newton update (n, 2)
    u_try: np.ndarray  # line-search trial (nodes)
    th_try: np.ndarray
    rl: np.ndarray  # friction equation residuals (nodes)
    sg: np.ndarray  # friction slopes (nodes)
    sgf: np.ndarray  # those of the factorised Jacobian
    lam0: np.ndarray  # friction ratios before the last update (nodes)
    stats: np.ndarray  # one record of STATS_DTYPE
    saddle: Saddle | None  # the exact laws' 3x3 system (None for the regularised ones)
    bs: np.ndarray  # friction bound S_j of each friction node at the last assembly
    vc: np.ndarray  # a loop's d v_rel / dc at each friction node
    Rg: np.ndarray  # a loop's global rows: residual (ng), slopes (physics.model.assemble)
    Gc: np.ndarray  # (n, 2, ng)
    Gr: np.ndarray  # (ng, n, 2)
    Gd: np.ndarray  # (ng, ng)
    dg: np.ndarray  # the globals' Newton update
    g_try: np.ndarray  # their line-search trial
    border: Border | None  # a loop's bordered solve (None when open)

    @classmethod
    def allocate(cls, n_elements: int, exact: bool = False, closed: bool = False,
                 n_globals: int = 0) -> Workspace:
        """The arrays for a grid of ``n_elements`` (``exact``: an exact law's too;
        ``closed``: a loop with ``n_globals`` global unknowns)."""
        N = n_elements
        nodes, n = (N, N) if closed else (N + 1, N - 1)
        ng = n_globals
        z = np.zeros
        return cls(R=z((n, 2)), Lb=z((n, 2, 2)), L2=z((n, 2, 2)), Db=z((n, 2, 2)),
                   Ub=z((n, 2, 2)), C=z((n, 2, 2)), W=z((n, 2, 2)), W2=z((n, 2, 2)),
                   U=z((n, 2, 2)), dx=z((n, 2)), u_try=z(nodes), th_try=z(nodes),
                   rl=z(nodes), sg=z(nodes), sgf=z(nodes), lam0=z(nodes),
                   stats=np.zeros(1, STATS_DTYPE),
                   saddle=Saddle.allocate(n, ng if closed else 0, closed) if exact
                   else None,
                   bs=z(nodes), vc=z(nodes), Rg=z(ng), Gc=z((n, 2, ng)), Gr=z((ng, n, 2)),
                   Gd=z((ng, ng)), dg=z(ng), g_try=z(ng),
                   border=Border.allocate(n, 2, ng) if closed else None)


@njit(cache=True, no_cpython_wrapper=True)
def merit(R, Rg, scales):
    """The squared residual norm, each row's force and moment over their scales, each
    global row over its own."""
    m = 0.0
    for i in range(R.shape[0]):
        a = R[i, 0] / scales.force
        b = R[i, 1] / scales.moment
        m += a * a + b * b
    for k in range(Rg.shape[0]):
        a = Rg[k] / scales.gres[k]
        m += a * a
    return m


@njit(cache=True, error_model="numpy")  # a zero pivot gives inf, and False, not an exception
def block_factor(Lb, Db, Ub, w):
    """Block LU of a block-banded matrix (2x2 blocks; two lower bands, L2 in w.L2, one
    upper) for :func:`block_substitute`.

    With W2_i = L2_i S_{i-2}^{-1}, L'_i = L_i - W2_i U_{i-2}, the pivots S_0 = D_0,
    S_i = D_i - W_i U_{i-1}, W_i = L'_i S_{i-1}^{-1} (no fill: upper band stays one): w.C
    receives the inverses S_i^{-1}, w.W the W_i, w.U a copy of the U_i. The factors
    serve two right-hand sides: the Newton update and the step's error estimate
    (implicit.filtered_error). Returns False on a singular pivot.
    """
    C, W, U, W2, L2 = w.C, w.W, w.U, w.W2, w.L2
    n = Db.shape[0]
    q00 = q01 = q10 = q11 = 0.0  # S_{i-1}^{-1}
    regular = True  # (a flag, not a branch out of the loop: that costs a third of the time)
    for i in range(n):
        s00, s01, s10, s11 = Db[i, 0, 0], Db[i, 0, 1], Db[i, 1, 0], Db[i, 1, 1]
        if i > 0:
            l00, l01, l10, l11 = Lb[i, 0, 0], Lb[i, 0, 1], Lb[i, 1, 0], Lb[i, 1, 1]
            if i > 1:
                # second band: W2_i = L2_i S_{i-2}^{-1}, L_i <- L_i - W2_i U_{i-2}
                a00, a01, a10, a11 = L2[i, 0, 0], L2[i, 0, 1], L2[i, 1, 0], L2[i, 1, 1]
                p00, p01, p10, p11 = C[i - 2, 0, 0], C[i - 2, 0, 1], C[i - 2, 1, 0], C[i - 2, 1, 1]
                v00 = a00 * p00 + a01 * p10
                v01 = a00 * p01 + a01 * p11
                v10 = a10 * p00 + a11 * p10
                v11 = a10 * p01 + a11 * p11
                W2[i, 0, 0], W2[i, 0, 1], W2[i, 1, 0], W2[i, 1, 1] = v00, v01, v10, v11
                u00, u01, u10, u11 = U[i - 2, 0, 0], U[i - 2, 0, 1], U[i - 2, 1, 0], U[i - 2, 1, 1]
                l00 -= v00 * u00 + v01 * u10
                l01 -= v00 * u01 + v01 * u11
                l10 -= v10 * u00 + v11 * u10
                l11 -= v10 * u01 + v11 * u11
            else:
                W2[i, 0, 0] = W2[i, 0, 1] = W2[i, 1, 0] = W2[i, 1, 1] = 0.0
            w00 = l00 * q00 + l01 * q10
            w01 = l00 * q01 + l01 * q11
            w10 = l10 * q00 + l11 * q10
            w11 = l10 * q01 + l11 * q11
            u00, u01, u10, u11 = Ub[i - 1, 0, 0], Ub[i - 1, 0, 1], Ub[i - 1, 1, 0], Ub[i - 1, 1, 1]
            U[i - 1, 0, 0], U[i - 1, 0, 1], U[i - 1, 1, 0], U[i - 1, 1, 1] = u00, u01, u10, u11
            s00 -= w00 * u00 + w01 * u10
            s01 -= w00 * u01 + w01 * u11
            s10 -= w10 * u00 + w11 * u10
            s11 -= w10 * u01 + w11 * u11
            W[i, 0, 0], W[i, 0, 1], W[i, 1, 0], W[i, 1, 1] = w00, w01, w10, w11
        det = s00 * s11 - s01 * s10
        regular = regular & (abs(det) > 0.0) & (abs(det) < math.inf)
        g = 1.0 / det
        q00, q01, q10, q11 = s11 * g, -s01 * g, -s10 * g, s00 * g
        C[i, 0, 0], C[i, 0, 1], C[i, 1, 0], C[i, 1, 1] = q00, q01, q10, q11
    return regular


@njit(cache=True)
def block_substitute(w, r, x):
    """Solve with the factors of :func:`block_factor`: x (n, 2) from r (n, 2); r is kept."""
    C, W, Ub, W2 = w.C, w.W, w.U, w.W2
    n = r.shape[0]
    y0 = y1 = 0.0
    for i in range(n):  # forward: y_i = r_i - W_i y_{i-1} - W2_i y_{i-2}, kept in x
        if i > 0:
            z0 = r[i, 0] - W[i, 0, 0] * y0 - W[i, 0, 1] * y1
            z1 = r[i, 1] - W[i, 1, 0] * y0 - W[i, 1, 1] * y1
            if i > 1:
                z0 -= W2[i, 0, 0] * x[i - 2, 0] + W2[i, 0, 1] * x[i - 2, 1]
                z1 -= W2[i, 1, 0] * x[i - 2, 0] + W2[i, 1, 1] * x[i - 2, 1]
            y0, y1 = z0, z1
        else:
            y0, y1 = r[0, 0], r[0, 1]
        x[i, 0], x[i, 1] = y0, y1
    x0 = x1 = 0.0
    for i in range(n - 1, -1, -1):  # backward: x_i = S_i^{-1} (y_i - U_i x_{i+1})
        z0, z1 = x[i, 0], x[i, 1]
        if i < n - 1:
            z0 -= Ub[i, 0, 0] * x0 + Ub[i, 0, 1] * x1
            z1 -= Ub[i, 1, 0] * x0 + Ub[i, 1, 1] * x1
        x0 = C[i, 0, 0] * z0 + C[i, 0, 1] * z1
        x1 = C[i, 1, 0] * z0 + C[i, 1, 1] * z1
        x[i, 0], x[i, 1] = x0, x1


@njit(cache=True)
def factorise(w, mesh):
    """Factorise w's Jacobian blocks (bordered on a loop); keep the friction slopes
    they hold (w.sgf)."""
    for j in mesh.cn:
        w.sgf[j] = w.sg[j]
    if mesh.off == 1:
        return block_factor(w.Lb, w.Db, w.Ub, w)
    return factorise_bordered(w, w.border)


@njit(cache=True, no_cpython_wrapper=True)
def factorise_bordered(w, bd):
    """A loop's part of :func:`factorise`: the band without the border, then the border.

    An open layout's workspace has no border (``bd`` None) and never comes here; its
    type prunes the body, so an open layout compiles none of the border's kernels.
    """
    if bd is None:
        return False
    ni = w.Db.shape[0] - 2
    if not block_factor(w.Lb[:ni], w.Db[:ni], w.Ub[:ni], w):
        return False
    gather(w.Lb, w.L2, w.Db, w.Ub, w.Gc, w.Gr, w.Gd, bd)
    block_substitute_many(w, bd.Bm, bd.X)
    return schur(bd)


@njit(cache=True)
def linear_solve(w, mesh, r, rg, x, dg):
    """x (n, 2) and dg (ng) from the right-hand sides r, rg with the factors of
    :func:`factorise`; r and rg are kept."""
    if mesh.off == 1:
        block_substitute(w, r, x)
        return
    ni = r.shape[0] - 2
    block_substitute(w, r[:ni], x[:ni])
    finish(w.border, r, rg, x, dg)


@njit(cache=True, no_cpython_wrapper=True)
def friction_forces(lam, fnode, u, g, t, mesh, p, drive):
    """The nodal friction forces of the friction ratios lam, as
    :func:`~beltsim.physics.model.assemble` sets them."""
    fs = p.friction_scale * friction_factor(drive, t)
    c = loop_speed(g, mesh, p)
    for j in mesh.cn:
        S, _, _ = bound_scale(mesh.seg[j], j, u, c, fs, mesh, p)
        fnode[j] = -mesh.wf[j] * S * lam[j]


@njit(cache=True, inline="always")
def update_converged(update, previous, it, tol):
    """Newton's stopping rule on the size of an update (see :func:`newton`): below tol;
    or at the round-off floor (below ROUNDOFF_FLOOR tol, no longer halving); or the
    error it leaves, rate / (1 - rate) times the update, below tol."""
    rate = update / previous if it > 0 and previous > 0.0 else 1.0
    return (update < tol or (update < ROUNDOFF_FLOOR * tol and update > 0.5 * previous)
            or (rate < CONTRACTION and rate / (1.0 - rate) * update < tol))


@njit(cache=True, inline="always")  # one compile inside each scheme, not two
def newton(state, old, inv_dt, t, mesh, p, drive, loads, scales, settings, w):
    """Solve the step's residual for (u, theta, lam) of ``state`` in place, from their values.

    Converged when the update is below settings.tol (scaled max norm; absolute for
    lam), when the error it leaves is: rate / (1 - rate) times the update, the rate
    being the ratio of successive updates (below CONTRACTION), or when it has reached
    the round-off floor: below ROUNDOFF_FLOOR * tol and no longer halving. The floor
    grows with the condition number of the Jacobian, ~ (L / h_min)^2, and on very fine
    grids lies above a fixed tol. None of these counts while a friction ratio is stuck
    at +-1 (:func:`beltsim.solvers.dual.release_stuck_ratios`). The primal-dual form
    keeps the last factorisation for an iteration after an update that shrank by CHORD
    or more.

    On return, w holds the block LU of the Jacobian last factorised (block_factor)
    and the friction slopes it was assembled with (w.sgf), for the step's error
    estimate. Returns True on convergence.
    """
    if p.law >= EXACT:
        return newton_exact(w.saddle, state, old, inv_dt, t, mesh, p, drive, loads, scales,
                            settings, w)
    u, th, lam, fnode, g = state.u, state.theta, state.lam, state.fnode, state.g
    R, dx, u_try, th_try = w.R, w.dx, w.u_try, w.th_try
    Rg, dg, g_try = w.Rg, w.dg, w.g_try
    off = mesh.off
    ng = g.shape[0]
    st = w.stats[0]
    tol = settings.tol
    n = R.shape[0]
    assemble(u, th, lam, g, fnode, old, inv_dt, t, mesh, p, drive, loads, w, JACOBIAN)
    m0 = merit(R, Rg, scales)
    if m0 == 0.0:
        return factorise(w, mesh)  # the factors are the step's (its error estimate's)
    previous = np.inf
    reuse = False
    for it in range(settings.max_iterations):
        st.newton_iterations += 1
        for i in range(n):
            R[i, 0] = -R[i, 0]
            R[i, 1] = -R[i, 1]
        for k in range(ng):
            Rg[k] = -Rg[k]
        if not reuse and not factorise(w, mesh):
            st.merit = merit(R, Rg, scales)
            return False
        linear_solve(w, mesh, R, Rg, dx, dg)
        step = update_size(dx, dg, scales)
        if not np.isfinite(step):
            st.merit = merit(R, Rg, scales)
            return False
        if p.dual:
            for j in mesh.cn:
                w.lam0[j] = lam[j]
            dlam = update_multipliers(lam, dx, dg, inv_dt, loop_speed(g, mesh, p), mesh, p, w)
            for i in range(n):
                u[i + off] += dx[i, 0]
                th[i + off] += dx[i, 1]
            for k in range(ng):
                g[k] += dg[k]
            if not np.isfinite(dlam):  # a ratio started on the bound, where g^-1 is not
                st.merit = merit(R, Rg, scales)
                return False
            update = max(step, dlam)
            converged = update_converged(update, previous, it, tol)
            # a stuck ratio: sought at convergence, and wherever the updates grow (a
            # ratio near the bound coming back slowly); sought at every iteration, its
            # moves cycled with the updates that take it to the bound
            if converged or update > previous:
                moved = release_stuck_ratios(lam, w, mesh, p.law, not converged)
                if moved > 0.0:
                    update = max(update, moved)
                    converged = False
            if converged:
                friction_forces(lam, fnode, u, g, t, mesh, p, drive)
                return True
            assemble(u, th, lam, g, fnode, old, inv_dt, t, mesh, p, drive, loads, w, JACOBIAN)
            reuse = it >= 1 and update < CHORD * previous
            previous = update
            continue
        alpha = 1.0
        accepted = False
        m = m0
        while alpha >= 1.0 / 4096.0:
            for i in range(n):
                u_try[i + off] = u[i + off] + alpha * dx[i, 0]
                th_try[i + off] = th[i + off] + alpha * dx[i, 1]
            for k in range(ng):
                g_try[k] = g[k] + alpha * dg[k]
            assemble(u_try, th_try, lam, g_try, fnode, old, inv_dt, t, mesh, p, drive, loads,
                     w, JACOBIAN)
            m = merit(R, Rg, scales)
            if m <= (1.0 - 1e-4 * alpha) * m0:
                accepted = True
                break
            alpha *= 0.5
            st.line_search_cuts += 1
        if not accepted:
            # no decrease possible: fine if already at round-off, else a failure
            assemble(u, th, lam, g, fnode, old, inv_dt, t, mesh, p, drive, loads, w, JACOBIAN)
            st.merit = m0
            return step < ROUNDOFF_FLOOR * tol
        for i in range(n):
            u[i + off] = u_try[i + off]
            th[i + off] = th_try[i + off]
        for k in range(ng):
            g[k] = g_try[k]
        m0 = m
        st.merit = m
        if alpha * step < tol or m < 1e-30:
            return True
    st.merit = merit(R, Rg, scales)
    return False


@njit(cache=True, no_cpython_wrapper=True)
def update_size(dx, dg, scales):
    """The scaled max norm of a Newton update of the rows (dx) and the globals (dg)."""
    step = 0.0
    for i in range(dx.shape[0]):
        s = max(abs(dx[i, 0]) / scales.u, abs(dx[i, 1]) / scales.theta)
        if s > step:
            step = s
        elif not s <= step:  # NaN: max and > pass it over
            return np.inf
    for k in range(dg.shape[0]):
        s = abs(dg[k]) / scales.glob[k]
        if not s <= step and not s > step:
            return np.inf
        step = max(step, s)
    return step


@njit(cache=True, no_cpython_wrapper=True)
def newton_exact(s, state, old, inv_dt, t, mesh, p, drive, loads, scales, settings, w):
    """Semi-smooth Newton on (u, theta, lam) and the globals for the exact laws (:mod:`.ssn`),
    on their system ``s`` (w.saddle).

    Full steps; converged when the update passes :func:`newton`'s tests and the
    stick/slip state of every friction node is the one the last step was solved with.
    The ratios are not projected onto [-1, 1] between iterations: a stuck node whose
    update overshoots the bound must count as sliding at the next assembly, and clipped
    to the bound it would sit on the switch (lam + v_rel / v_aug = +-1 with v_rel ~ 0)
    and be read as stuck or sliding by round-off.
    On return, w holds the block LU of the 2x2 Jacobian with the stuck nodes' slope
    f_s AUGMENTATION / v_aug, the default regularisation's (a penalty standing in for
    their constraint), for the step's error estimate, as :func:`newton` leaves its own
    (unless settings.factors is False: an ESDIRK scheme's stages before the last).
    While the stick/slip pattern holds, an iteration of a time step (inv_dt > 0) after
    one whose update shrank by CHORD or more (or after the first) keeps the factors (a
    chord step): the factorisation with the border's columns is most of an iteration's
    cost, and with the pattern fixed the Jacobian changes only through the bounds
    S(u_x, c) and the belt speed.

    A regularised law's workspace has no such system (``s`` None) and never comes here;
    its type prunes the body, so a regularised scene compiles none of the exact laws'
    kernels.
    """
    if s is None:
        return False
    u, th, lam, fnode, g = state.u, state.theta, state.lam, state.fnode, state.g
    st = w.stats[0]
    tol = settings.tol
    n = w.R.shape[0]
    ng = g.shape[0]
    fs = p.friction_scale * friction_factor(drive, t)
    for j in range(s.active.shape[0]):
        s.active[j] = -1.0
    assemble(u, th, lam, g, fnode, old, inv_dt, t, mesh, p, drive, loads, w, JACOBIAN)
    saddle_system(lam, loop_speed(g, mesh, p), inv_dt, fs, mesh, p, w, s)
    previous = np.inf
    reuse = False
    for it in range(settings.max_iterations):
        st.newton_iterations += 1
        if not reuse and not saddle_factorise(s, mesh):
            st.merit = merit(w.R, w.Rg, scales)
            return False
        saddle_resolve(s, mesh)
        step = update_size(s.dx, s.dg, scales)
        dlam = 0.0
        for i in range(n):
            dlam = max(dlam, abs(s.dx[i, 2]))
        if not (np.isfinite(step) and np.isfinite(dlam)):
            st.merit = merit(w.R, w.Rg, scales)
            return False
        damped = it >= CYCLE_ITERATIONS
        m_before = saddle_merit(s, scales) if damped else 0.0
        alpha = 1.0
        shift_saddle(state, s, mesh, alpha)
        assemble(u, th, lam, g, fnode, old, inv_dt, t, mesh, p, drive, loads, w, JACOBIAN)
        changed = saddle_system(lam, loop_speed(g, mesh, p), inv_dt, fs, mesh, p, w, s)
        # past CYCLE_ITERATIONS a pattern that still changes is cycling: the step is
        # halved until the whole residual (the friction rows' too) decreases
        for _ in range(MAX_HALVINGS if damped and changed > 0 else 0):
            if saddle_merit(s, scales) < m_before:
                break
            alpha *= 0.5
            shift_saddle(state, s, mesh, -alpha)
            st.line_search_cuts += 1
            assemble(u, th, lam, g, fnode, old, inv_dt, t, mesh, p, drive, loads, w, JACOBIAN)
            changed = saddle_system(lam, loop_speed(g, mesh, p), inv_dt, fs, mesh, p, w, s)
        update = alpha * max(step, dlam)
        # a front node may flip between stick and slip at round-off: a residual at its
        # floor ends the iteration whatever the pattern did
        settled = changed == 0 or merit(w.R, w.Rg, scales) < ROUNDOFF_MERIT * (n + ng)
        done = settled and update_converged(update, previous, it, tol)
        # a chord step next while the stick/slip pattern holds and the updates shrink; not
        # at steady state (inv_dt = 0), whose solve is the reference the runs are held to,
        # converged quadratically to round-off
        reuse = (inv_dt > 0.0 and changed == 0 and alpha == 1.0
                 and (it == 0 or update < CHORD * previous))
        previous = update
        if done:
            project(lam, mesh, p.law)  # the sliding ratios, off +-1 by round-off
            friction_forces(lam, fnode, u, g, t, mesh, p, drive)
            if not settings.factors:
                return True
            add_stick_penalty(w, inv_dt, fs, loop_speed(g, mesh, p), mesh, p)
            return factorise(w, mesh)
    st.merit = merit(w.R, w.Rg, scales)
    return False


@njit(cache=True, no_cpython_wrapper=True)
def on_path(g, g_start, scales):
    """Whether a step kept a loop's globals within their scales (the rim speed, the
    pulley's speed) of the step's start: one that moved them further converged on another
    branch of the exact laws' equations (the belt sliding backwards over every arc), not
    on the path, and is cut like a failed one. Always true on an open layout."""
    for k in range(g.shape[0]):
        if not abs(g[k] - g_start[k]) <= scales.glob[k]:
            return False
    return True


@njit(cache=True, no_cpython_wrapper=True)
def shift_saddle(state, s, mesh, alpha):
    """(u, theta, the friction ratios, the globals) += alpha times the semi-smooth
    Newton update in s."""
    off = mesh.off
    for i in range(s.dx.shape[0]):
        state.u[i + off] += alpha * s.dx[i, 0]
        state.theta[i + off] += alpha * s.dx[i, 1]
    for k in range(state.g.shape[0]):
        state.g[k] += alpha * s.dg[k]
    for j in mesh.cn:
        state.lam[j] += alpha * s.dx[j - off, 2]


@njit(cache=True, no_cpython_wrapper=True)
def saddle_merit(s, scales):
    """The squared norm of the semi-smooth system's residual: :func:`merit` of its force,
    moment and global rows, plus its friction rows (ratios, already dimensionless)."""
    m = merit(s.R, s.Rg, scales)
    for i in range(s.R.shape[0]):
        m += s.R[i, 2] * s.R[i, 2]
    return m


class NewtonScheme(Scheme):
    """The workspace, Newton settings and counters of the schemes that solve with Newton."""

    def __init__(self, disc):
        super().__init__(disc)
        num = self.numerics
        #: Workspace.allocate's arguments (a scratch workspace of the same numba type)
        self.workspace_shape = (disc.grid.n_elements, is_exact(disc.model.law),
                                disc.mesh.off == 0, disc.n_globals)
        self.work = Workspace.allocate(*self.workspace_shape)
        self.settings = NewtonSettings(num.newton_tol, num.newton_max_iterations)
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
                f"dt = {dt:.3g} s (residual norm {self.work.stats[0]['merit']:.3g})",
                kind=FailureKind.NEWTON, t=t, quantity="newton")
        if status == NONFINITE:
            raise NumericalError(f"non-finite displacement or rotation at t = {t:.6g} s",
                                 kind=FailureKind.NON_FINITE, t=t, quantity="u/theta")
