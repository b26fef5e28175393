"""Explicit scheme (inertial scenes): second order in time, stable without damping.

Each step is a Strang splitting of the semi-discrete model into two parts:

* the velocity terms (gyroscopic 2 c u_xt and damping d u_t), advanced over dt by the
  trapezoidal rule together with the drift u' = v: the midpoint velocity
  vm = (v_a + v_b) / 2 solves (2/dt + d) vm + G vm = (2/dt) v_a, with G the
  gyroscopic operator over the lumped mass (lower bidiagonal, one pass in the
  direction of the flow for both fields), then v_b = 2 vm - v_a and u += dt vm. The
  trapezoidal rule is A-stable, so G sets no step limit, damping or not;
* the kick at t_n: elastic, shear, load and friction forces of u_n, v += dt f / m.
  The half kicks of consecutive Strang steps merge into this one, so between steps
  the state is (u_n, v after the kick), and u_t(t_n) is the mean of the velocities
  before and after it (second order).

Only the kick's stiffness terms are explicit: the step is limited by the waves. Both
parts vanish at rest, so the fixed point is the semi-discrete steady state of the
implicit schemes. G is upwind, 2 rho c hbar_j (v_j - v_{j-1}) / h_{j-1}, as in the
model the Newton schemes solve (physics.model), so all schemes share the
semi-discretisation; why upwind: docs/theory/discretisation.md, "The gyroscopic term".

Friction is implicit in each friction node's own velocity. Its slope f* / v_reg is
enormous, so the velocity it sees must damp the friction relaxation (the mean of the
velocities before and after the kick, trapezoidal, rings with amplification -1 and,
with the transport term, diverges in stick) yet be second order (the velocity after
the kick, backward Euler, is first order). The slip velocity of node j (c0 .. j2, the
model's friction nodes, physics.discrete.contact_stencil) is taken as

    b_before + A_EST delta_j - C_EST delta_j^{n-1}
    + c sum_k sw[j, k] (ub_k + ALPHA dt delta_k) - (v - c),   k = j-2, j-1, j

with b = u_t + (h/2) theta_t the bottom-fibre velocity, delta its kick increment (this
step's, and the previous step's for C_EST), sw the model's one-sided three-point
(second-order) transport stencil, and A_EST - C_EST = 1/2 (consistency); the node's
friction force is wf_j f* g, wf_j the contact part of its control volume. The
corrections are dt times changes of increments: O(dt^2) where friction is smooth,
zero at steady state. C_EST = 1/16 puts the roots of the stiff limit at -1/3 (a
double root, the smallest reachable); ALPHA makes the stick-zone transport (upwind,
explicit in u_n) stable at large Courant numbers c dt / h. delta_{j-1} and
delta_{j-2} are known first in a sweep in the direction of the flow, so each node is
one monotone scalar equation.

The exact laws (numerics.friction_law = "exact") are the stiff limit of that scalar
equation, solved by projection: the node sticks (its estimated slip velocity is 0) when
the ratio that holds it is within [-1, 1] (always for adhesion), else it slides with
the ratio on the bound.

The step is EXPLICIT_SAFETY of the limit found by a von Neumann analysis of this
scheme (both fields, friction at all slopes with its transport) on the smallest
element; a requested step above the limit is refused. See docs/theory/time-schemes.md.
"""

from __future__ import annotations

import dataclasses
import math
from typing import NamedTuple

import numpy as np
from numba import njit

from ..errors import SceneError
from ..physics.discrete import hermite_weights, load_at
from ..physics.friction import SQRT, TANH
from ..problem.drive import friction_factor, mismatch
from .base import Scheme
from .explicit_friction import (  # noqa: F401 (the scheme's constants and solves, as tests read them)
    A_EST,
    ALPHA,
    C_EST,
    SAFE_FASTMATH,
    TANH_SATURATED,
    _closed_form,
    _friction_scalar,
    _law,
    _newton,
    _predicted,
    _warm_start,
)
from .explicit_loop import advance_loop, gh_size
from .explicit_stability import (  # noqa: F401 (as tests read them)
    explicit_amplification,
    explicit_stable_dt,
    loop_stable_dt,
)
from .registry import register
from .settings import EXPLICIT_LOOP_RATE, EXPLICIT_RATE

EXPLICIT_SAFETY = 0.9  # default explicit step as a fraction of the stability limit
# a loop's: its limit leaves out the belt speed's and the pulleys' coupling; random drive
# 0 of seed 1 (validation.random_drives) on 200 elements rang on in a limit cycle at 0.9
# of it (the belt speed +-0.1 % at t = 12 s) and settled at 0.75 and 0.5
LOOP_SAFETY = 0.6


class History(NamedTuple):
    """What the scheme carries from step to step besides the State."""

    va: np.ndarray  # u_t, theta_t after the last kick (a node each)
    wa: np.ndarray
    db: np.ndarray  # the last kick's bottom-fibre increments (contact nodes)
    # a loop's (empty on the open layout): each contact node's v_rel / v_reg (the warm
    # start; its state.lam holds the ratio) and its globals' history (explicit_loop.gh_size)
    sv: np.ndarray = np.zeros(0)
    gh: np.ndarray = np.zeros(0)

    @classmethod
    def zeros(cls, n_nodes, n_globals=0):
        """All zero on ``n_nodes`` nodes with ``n_globals`` globals (a loop's)."""
        loop = n_globals > 0
        return cls(np.zeros(n_nodes), np.zeros(n_nodes), np.zeros(n_nodes),
                   np.zeros(n_nodes if loop else 0),
                   np.zeros(gh_size(n_globals) if loop else 0))


# numba tests a signed index for a negative value (and wraps it) at every access, a
# branch and a select that cost more than the arithmetic in the sweeps below: their
# indices are unsigned
_1, _2 = np.uint64(1), np.uint64(2)


# columns of Coefficients.fr, the friction nodes' coefficients: a row per node, so the
# sweep reads them from one pointer (as 11 arrays their pointers spilled to the stack)
FR_EST = 0  # A_EST + ALPHA dt c sw[j, 2]: this kick's increment at j in the estimate
FR_T0, FR_T1, FR_T2 = 1, 2, 3  # c sw[j, 0..2], the transport c d/dx u_b at node j from
# u_b at j-2, j-1, j (mesh.sw, physics.discrete.contact_stencil)
FR_A0, FR_A1 = 4, 5  # ALPHA dt c sw[j, 0..1]: the transport of the increments at j-2, j-1
FR_FH = 6  # wf_j f_s: the node's friction weight times the friction scale
FR_FM, FR_FI = 7, 8  # dt / m_j, dt (h/2) / m_I,j: a nodal force's kick
FR_KB = 9  # FR_FM + (h/2) FR_FI: the bottom-fibre kick of a unit force
FR_KAP = 10  # FR_EST FR_KB FR_FH / v_reg: the scalar friction equation's kappa
N_FR = 11


class Coefficients(NamedTuple):
    """Per-node coefficients of one step (precomputed for a step size)."""

    P: np.ndarray  # the velocity system solved for 2 vm (times 2 is exact, and 2 vm - v_a
    Ql: np.ndarray  # then a subtraction): 2 vm_j = P_j v_a,j + Ql_j 2 vm_{j-1}
    ar: np.ndarray  # dt B / (m_j h_j), dt B / (m_j h_{j-1}): the axial kick
    al: np.ndarray
    br: np.ndarray  # the same for the bending term
    bl: np.ndarray
    fr: np.ndarray  # (N + 1, N_FR): the friction nodes' coefficients, columns FR_*


@njit(cache=True)
def coefficients(dt, mesh, p):
    """The Coefficients of steps of size dt (once per advance, O(N))."""
    N = mesh.he.shape[0]
    he, hb, sw, wf = mesh.he, mesh.hb, mesh.sw, mesh.wf
    rho, rot, c, hh = p.mass, p.rotary_inertia, p.speed, p.half_height
    z = np.zeros
    co = Coefficients(z(N + 1), z(N + 1), z(N + 1), z(N + 1), z(N + 1), z(N + 1),
                      z((N + 1, N_FR)))
    for j in range(1, N):
        m, mi = rho * hb[j], rot * hb[j]
        # row j of (2/dt + d + G) vm = (2/dt) v_a over the lumped mass, with
        # G v_j = g_j (v_j - v_{j-1}), g_j = 2 c / h_{j-1}
        g = 2.0 * c / he[j - 1]
        piv = 2.0 / dt + p.damping + g
        co.P[j] = 2.0 * ((2.0 / dt) / piv)
        co.Ql[j] = g / piv
        co.ar[j] = dt * p.B / (m * he[j])
        co.al[j] = dt * p.B / (m * he[j - 1])
        co.br[j] = dt * p.A / (mi * he[j])
        co.bl[j] = dt * p.A / (mi * he[j - 1])
    for j in range(mesh.c0, mesh.j2 + 1):
        f = co.fr[j]
        m, mi = rho * hb[j], rot * hb[j]
        f[FR_FM] = dt / m
        f[FR_FI] = dt * hh / mi
        f[FR_KB] = f[FR_FM] + hh * f[FR_FI]
        f[FR_T0], f[FR_T1], f[FR_T2] = c * sw[j, 0], c * sw[j, 1], c * sw[j, 2]
        f[FR_A0], f[FR_A1] = ALPHA * dt * f[FR_T0], ALPHA * dt * f[FR_T1]
        f[FR_EST] = A_EST + ALPHA * dt * f[FR_T2]
        f[FR_FH] = wf[j] * p.friction_scale
        f[FR_KAP] = f[FR_EST] * f[FR_KB] * f[FR_FH] / p.regularisation
    return co



# columns of the friction pass's work array (a row per node): what the sweep needs of
# node j that does not depend on the nodes before it
W_EST = 0  # the slip velocity's estimate but for this kick's increments at j-2 .. j
W_D0, W_D1, W_D2 = 1, 2, 3  # the predicted increment d_j = D0 - D1 d_{j-2} - D2 d_{j-1}
W_G0, W_GP, W_INV = 4, 5, 6  # the law at the warm start (_warm_start)
N_W = 7


@njit(cache=True, fastmath=SAFE_FASTMATH)
def _friction_pass(u, th, va, wa, bb, eb, db, sfr, fnode, work, target, ff, co, mesh, p):
    """The kick's friction at the friction nodes c0..j2, in the direction of the flow.

    On entry va, wa hold the kick without friction, bb the bottom-fibre velocity
    before the kick and eb its increment without friction; db the previous kick's
    bottom increments, replaced by this kick's. ff: f*(t) / f* of the drive. The
    transport reaches nodes j-2 and j-1 (mesh.sw): their increments of this kick are
    known when node j is solved (upstream of c0, the kick without friction). ``work``:
    (N + 1, N_W) scratch.

    The sweep's chain from node to node is the increment d_{j-1} in the slip velocity
    of node j. Node j's response predicted from its warm start (_warm_start) is affine
    in that slip velocity, so the chain carries d_j = D0 - D1 d_{j-2} - D2 d_{j-1}, two
    multiply-adds, while the check of the prediction (_predicted) and the full solve where
    it fails (_newton, _closed_form: _friction_scalar's) run beside it. What does not
    depend on the chain (the estimate, the law at the warm start, D0..D2) is computed
    first, in a pass without a chain, so that its latency (two divisions) does not hold
    the sweep.
    """
    c0, j2, hh, code = np.uint64(mesh.c0), np.uint64(mesh.j2), p.half_height, p.law
    inv_reg = 1.0 / p.regularisation
    fr = co.fr
    b_l2 = u[c0 - _2] + hh * th[c0 - _2]  # bottom-fibre displacements at j-2, j-1
    b_l1 = u[c0 - _1] + hh * th[c0 - _1]
    for j in range(c0, j2 + _1):
        b_j = u[j] + hh * th[j]
        work[j, W_EST] = bb[j] + (fr[j, FR_EST] * eb[j] - C_EST * db[j]
                                  + fr[j, FR_T0] * b_l2 + fr[j, FR_T1] * b_l1
                                  + fr[j, FR_T2] * b_j - target)
        g0, gp, inv, gc, gs = _warm_start(code, sfr[j], fr[j, FR_KAP] * ff)
        kf = fr[j, FR_KB] * fr[j, FR_FH] * ff
        slope = kf * gs * inv_reg  # d_j's derivative in the estimate
        work[j, W_D0] = (eb[j] - kf * gc) - slope * work[j, W_EST]
        work[j, W_D1] = slope * fr[j, FR_A0]
        work[j, W_D2] = slope * fr[j, FR_A1]
        work[j, W_G0] = g0
        work[j, W_GP] = gp
        work[j, W_INV] = inv
        b_l2, b_l1 = b_l1, b_j
    d_l2 = eb[c0 - _2]  # nodes upstream of the friction nodes carry no friction
    d_l1 = eb[c0 - _1]
    for j in range(c0, j2 + _1):
        s0, kap, fhf = sfr[j], fr[j, FR_KAP] * ff, fr[j, FR_FH] * ff
        d_pred = (work[j, W_D0] - work[j, W_D1] * d_l2) - work[j, W_D2] * d_l1
        sp = (work[j, W_EST] + fr[j, FR_A0] * d_l2 + fr[j, FR_A1] * d_l1) * inv_reg
        ok, s, g = _predicted(code, sp, kap, s0, work[j, W_G0], work[j, W_GP], work[j, W_INV])
        if ok:
            d_next = d_pred
        elif code == TANH and work[j, W_GP] == 0.0 and abs(sp) - kap > TANH_SATURATED and \
                sp * s0 > 0.0:
            # a saturated node whose bracket [sp - kap, sp + kap] is saturated on the
            # same side: the full solve's g is the predicted one, and the chain need
            # not wait for it
            s, g = _newton(code, sp, kap, s0, work[j, W_G0], work[j, W_GP])
            d_next = d_pred
        else:
            if code == TANH or code == SQRT:
                s, g = _newton(code, sp, kap, s0, work[j, W_G0], work[j, W_GP])
            else:
                s, g = _closed_form(code, sp, kap)
            d_next = eb[j] + fr[j, FR_KB] * (-fhf * g)
        F = -fhf * g
        va[j] += fr[j, FR_FM] * F
        wa[j] += fr[j, FR_FI] * F
        db[j] = eb[j] + fr[j, FR_KB] * F
        sfr[j] = s
        fnode[j] = F
        d_l2, d_l1 = d_l1, d_next


@njit(cache=True, fastmath=SAFE_FASTMATH)
def _add_loads(va, wa, eb, t, dt, p, loads):
    """The kick of the distributed loads at t: dt hbar q / (rho hbar)."""
    lk, l0, l1, m0, m1 = hermite_weights(loads.times, t)
    if lk < 0:
        return
    hh = p.half_height
    su, st = dt / p.mass, dt / p.rotary_inertia
    for j in range(1, va.shape[0] - 1):
        du = su * load_at(loads.qu, loads.dqu, lk, l0, l1, m0, m1, j)
        dw = st * load_at(loads.qt, loads.dqt, lk, l0, l1, m0, m1, j)
        va[j] += du
        wa[j] += dw
        eb[j] += du + hh * dw


@njit(cache=True, fastmath=SAFE_FASTMATH)
def _kick_from(u, th, va, wa, vb, wb, bb, eb, co, spring, hh):
    """The kick without friction and loads from the velocities vb, wb (a fresh start)."""
    for k in range(1, u.shape[0] - 1):
        eu = co.ar[k] * (u[k + 1] - u[k]) - co.al[k] * (u[k] - u[k - 1])
        et = (co.br[k] * (th[k + 1] - th[k]) - co.bl[k] * (th[k] - th[k - 1])
              - spring * th[k])
        bb[k] = vb[k] + hh * wb[k]
        eb[k] = eu + hh * et
        va[k] = vb[k] + eu
        wa[k] = wb[k] + et


@njit(cache=True, fastmath=SAFE_FASTMATH)
def _drift_and_kick(u, th, va, wa, bb, eb, ud, td, last, co, dt, spring, hh):
    """The velocity terms with the drift, then the kick without friction and loads.

    The velocity system is lower bidiagonal: one pass in the direction of the flow,
    which kicks node j - 1 once its neighbours have drifted. The drifted u, theta and
    the velocities of nodes j - 2 .. j stay in registers (stores to one array could
    alias another for the compiler, which would reload them), so the pass's only chain
    from node to node is the recurrence of each field's midpoint velocity. Node N passes
    through with zero coefficients. With ``last``, ud, td receive the velocities before
    the kick.
    """
    P, Ql, ar, al, br, bl = co.P, co.Ql, co.ar, co.al, co.br, co.bl
    n = np.uint64(u.shape[0])
    hdt = 0.5 * dt
    mv = P[1] * va[1]  # node 1: twice the midpoint velocities
    mw = P[1] * wa[1]
    u_l, u_k = u[0], u[1] + hdt * mv  # nodes k - 1, k = j - 1 (drifted)
    t_l, t_k = th[0], th[1] + hdt * mw
    v_k = mv - va[1]  # node k's velocities after the drift
    w_k = mw - wa[1]
    u[1] = u_k
    th[1] = t_k
    for j in range(_2, n):
        k = j - _1
        # the chain's product first: the compiler fuses a sum's first product into the
        # multiply-add, so the chain from node to node is that one operation
        mv = Ql[j] * mv + P[j] * va[j]
        mw = Ql[j] * mw + P[j] * wa[j]
        u_j = u[j] + hdt * mv
        t_j = th[j] + hdt * mw
        v_j = mv - va[j]
        w_j = mw - wa[j]
        u[j] = u_j
        th[j] = t_j
        eu = ar[k] * (u_j - u_k) - al[k] * (u_k - u_l)
        et = br[k] * (t_j - t_k) - bl[k] * (t_k - t_l) - spring * t_k
        if last:
            ud[k] = v_k
            td[k] = w_k
        bb[k] = v_k + hh * w_k
        eb[k] = eu + hh * et
        va[k] = v_k + eu
        wa[k] = w_k + et
        u_l, u_k, t_l, t_k, v_k, w_k = u_k, u_j, t_k, t_j, v_j, w_j
    va[n - _1] = v_k
    wa[n - _1] = w_k


@njit(cache=True, fastmath=SAFE_FASTMATH)
def advance_explicit(state, hist, fresh, t, t_stop, dt, max_steps, mesh, p, drive, loads):
    """Steps from t until t >= t_stop (or max_steps). Returns (t, steps).

    ``hist`` holds the velocities after the last kick and its bottom-fibre increments;
    with ``fresh`` they are first rebuilt from the state (u, theta, u_t, theta_t at t)
    by two kicks at t, the second from the velocities half a kick before u_t, so a
    start from any state is second order. On return state.ud, state.td hold u_t,
    theta_t at t (the mean of the velocities before and after the last kick),
    state.fnode that kick's friction and state.lam each contact node's v_rel / v_reg
    (the warm start of its scalar solve). A loop (``mesh.off`` = 0) is stepped by
    :func:`beltsim.solvers.explicit_loop.advance_loop`.
    """
    if mesh.off == 0:
        return advance_loop(state, hist, fresh, t, t_stop, dt, max_steps, mesh, p, drive,
                            loads)
    u, th, sfr, fnode, ud, td = state.u, state.theta, state.lam, state.fnode, state.ud, state.td
    va, wa, db = hist.va, hist.wa, hist.db
    N = u.shape[0] - 1
    hh = p.half_height
    spring = dt * p.shear / p.rotary_inertia
    co = coefficients(dt, mesh, p)
    bb = np.zeros(N + 1)
    eb = np.zeros(N + 1)
    yv = np.zeros(N + 1)  # a fresh start's velocities before the kick
    yw = np.zeros(N + 1)
    work = np.zeros((N + 1, N_W))
    if fresh:
        for j in range(N + 1):
            fnode[j] = 0.0
            db[j] = 0.0
        target = mismatch(drive, t)
        for rep in range(2):
            _kick_from(u, th, va, wa, yv if rep else ud, yw if rep else td, bb, eb, co,
                       spring, hh)
            _add_loads(va, wa, eb, t, dt, p, loads)
            _friction_pass(u, th, va, wa, bb, eb, db, sfr, fnode, work, target,
                           friction_factor(drive, t), co, mesh, p)
            for j in range(1, N):  # u_t - delta / 2
                yv[j] = 1.5 * ud[j] - 0.5 * va[j]
                yw[j] = 1.5 * td[j] - 0.5 * wa[j]
    steps = 0
    # t accumulates round-off: a stop within 1e-9 dt counts as reached, or a run of
    # t_stop / dt steps could take one more
    t_reached = t_stop - 1e-9 * dt
    while t < t_reached and steps < max_steps:
        last = t + dt >= t_reached or steps + 1 >= max_steps
        _drift_and_kick(u, th, va, wa, bb, eb, ud, td, last, co, dt, spring, hh)
        t += dt
        steps += 1
        _add_loads(va, wa, eb, t, dt, p, loads)
        _friction_pass(u, th, va, wa, bb, eb, db, sfr, fnode, work, mismatch(drive, t),
                       friction_factor(drive, t), co, mesh, p)
        if last:
            for j in range(1, N):
                ud[j] = 0.5 * (ud[j] + va[j])
                td[j] = 0.5 * (td[j] + wa[j])
    return t, steps


def _duration(seconds: float) -> str:
    for unit, size in (("days", 86400.0), ("hours", 3600.0), ("minutes", 60.0)):
        if seconds >= 2 * size:
            return f"{seconds / size:.3g} {unit}"
    return f"{seconds:.3g} s"


@register
class ExplicitScheme(Scheme):
    """Trapezoidal velocity terms and an explicit kick (module notes), at EXPLICIT_SAFETY
    of the von Neumann limit (inertial scenes)."""

    name = "explicit"
    needs_inertia = True

    def __init__(self, disc):
        super().__init__(disc)
        P, num, grid = disc.params, self.numerics, disc.grid
        if disc.closed:
            from ..beltdrive.scene import max_rim_speed

            speed = max_rim_speed(disc.scene.to_dict())  # c stays below it
            limit = loop_stable_dt(P, grid.h_min, disc.model.damping, speed)
            where = f"at belt speeds 0 .. {speed:.4g} m/s, "
        else:
            limit = explicit_stable_dt(P, grid.h_min, disc.model.damping)
            where = ""
        if not limit > 0.0:
            raise SceneError("numerics.integrator", "the explicit scheme has no stable step "
                             "for this scene; use the implicit integrator")
        requested = disc.scene.numerics.get("dt")
        if requested is not None and requested > limit:
            raise SceneError(
                "numerics.dt", f"{requested:.6g} s exceeds the explicit stability limit "
                f"{limit:.6g} s (von Neumann, on the smallest element, {grid.h_min:.3g} m, "
                f"{where}the waves of both fields with the shear, gyroscopic and friction "
                f"terms)")
        safety = LOOP_SAFETY if disc.closed else EXPLICIT_SAFETY
        dt = requested if requested is not None else safety * limit
        steps = math.ceil(num.t_end / dt)
        nodes = len(disc.mesh.hb)
        work = steps * float(nodes)
        rate = EXPLICIT_LOOP_RATE if disc.closed else EXPLICIT_RATE
        if work > num.max_work:
            raise SceneError(
                "numerics.max_work", f"this explicit run may need {work:.3g} node-steps "
                f"({steps:.3g} steps of {dt:.3g} s to t_end = {num.t_end:.4g} s, "
                f"{nodes} nodes; about {_duration(work / rate)} at "
                f"{rate:.0e} node-steps/s), above max_work = {num.max_work:.3g}; "
                f'use numerics.integrator = "implicit", or raise numerics.max_work')
        self.numerics = dataclasses.replace(num, dt=dt)
        self.hist = History.zeros(nodes, disc.n_globals)
        self.hist_at = (math.nan, math.nan)  # the (t, dt) the history belongs to

    @property
    def dt(self) -> float:
        return self.numerics.dt

    def _compile(self, state) -> None:
        # on copies: a resumed run's history must survive the warm-up
        self._kernel(state.copy(), History.zeros(len(state.u), len(state.g)), True, 0.0, 0.0,
                     0)

    def _kernel(self, state, hist, fresh, t, t_stop, max_steps):
        d = self.disc
        return advance_explicit(state, hist, fresh, t, t_stop, self.numerics.dt, max_steps,
                                d.mesh, d.model, d.drive, d.loads)

    def advance(self, state, t, t_stop, max_steps=10**9):
        # a history from another time or step (a new run, a state set from outside, a
        # changed dt) is rebuilt from the state
        fresh = self.hist_at != (t, self.numerics.dt)
        t, steps = self._kernel(state, self.hist, fresh, t, t_stop, max_steps)
        self.hist_at = (t, self.numerics.dt)
        self.steps += steps
        return t

    def checkpoint(self) -> dict:
        return {**super().checkpoint(), "hist_at": np.array(self.hist_at),
                **{f"hist_{k}": a.copy() for k, a in zip(History._fields, self.hist)}}

    def restore(self, data: dict) -> None:
        super().restore(data)
        if "hist_at" not in data:  # a checkpoint of the first-order scheme: start afresh
            self.hist_at = (math.nan, math.nan)
            return
        self.hist_at = tuple(float(v) for v in data["hist_at"])
        for k, a in zip(History._fields, self.hist):
            if f"hist_{k}" in data:  # an open layout's checkpoint has no loop fields
                a[:] = data[f"hist_{k}"]
