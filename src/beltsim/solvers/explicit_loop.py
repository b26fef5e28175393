"""The explicit scheme on a closed layout (a loop): the same step as the open layout's.

:mod:`beltsim.solvers.explicit` describes the step: the velocity terms (gyroscopic and
damping) by the trapezoidal rule with the drift, then the kick with friction implicit in
each friction node's own velocity, swept in the direction of the flow. On a loop
(``mesh.off`` = 0, :class:`beltsim.physics.discrete.Mesh`) four things differ.

* Periodic sweeps. The velocity system (2/dt + d + G) vm = (2/dt) v_a is lower
  bidiagonal with one entry across the closure: cyclic. Its solution is one pass from
  node 0 with vm_{-1} = 0, y, plus z vm_{N-1}, z_j the product of the pass's factors
  Q_0 .. Q_j (the homogeneous solution); at j = N - 1 that closes as vm_{N-1} = y_{N-1} /
  (1 - z_{N-1}), exact, and a second pass from that start gives every vm_j. Each contact
  arc's friction is swept from the arc's entry, whose upstream neighbours (the stencil's
  j - 1, j - 2) are free-span nodes whose increments are the kick's without friction.

* The belt speed c (global 0). The axial rows carry rho hbar_j c_t and the gauge row
  sum hbar_j u_j = 0 (physics.model.assemble): c_t is the multiplier that keeps the gauge.
  Each part of the step is followed by the uniform velocity correction that restores
  sum hbar_j v_j = 0, and c takes what it removes: in the kick Delta c = sum hbar_j
  Delta v_j / Lambda = dt sum F_j / (rho Lambda) (the elastic forces sum to zero round the
  loop), in the trapezoidal part the gyroscopic term's sum (zero on a uniform grid; a
  constant is in the kernel of G, so the correction solves the part exactly). c is a
  velocity: it is advanced with v (c after a kick is c at the half step), and at the
  kick c ~ c_before + Delta c_last / 2 (second order, as the velocity estimate) enters
  the stiffnesses b1 - rho c^2, a - I c^2, the transport, the target and the pressure.
  A change of c with its correction moves the material by only (N0 / b1 + eps_b) of it,
  which is why the slip velocity, written with the total velocity v_j + c, depends on
  this kick's Delta c so weakly that taking the last kick's is stable. The round-off of
  the gauge sum hbar u is removed at the next drift, so it stays at one step's.

* A tensioner's arm (:mod:`beltsim.physics.arm`): its angle drifts with its rate as u
  does, its spans' stretch enters the kick's fluxes, and its rate takes the kick of its
  torque (the damper's at the rate before the kick: its rate d / J is far below 1 / dt).

* Free pulleys (globals 1..): J omega_t = -M(t) - R sum of its arc's F_j. Their speeds
  enter the slip velocities of their arcs as the nodes' velocities do (omega_b + A_EST
  Delta omega - C_EST Delta omega_last), and the arc's friction is solved together with
  the pulley's increment: its total G solves G = sum F_j(rim(G)), monotone in G, by
  Newton's method with the sweep's derivative carried along the arc (safeguarded by
  bisection). A pulley speed lagging one step grew a slow oscillation with the stuck arc.

The kernels divide with numpy's error model: a run that diverges (a step above the
limit) ends in inf or nan, which the run's guard reports, not in an exception.

The fixed point is the semi-discrete steady state of the model (all increments vanish:
every row, the gauge and the pulleys' balance hold), the one the steady scheme solves.
A node whose pressure is not positive (the belt lifts off; the run reports it) carries
no friction.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..physics.arm import arm_torque, arm_values, span_tensions, stretch
from ..physics.discrete import hermite_weights, load_at
from ..physics.friction import ADHESION, EXACT, LINEAR, RAMP, SQRT, TANH
from ..physics.model import wrap
from ..problem.drive import friction_factor, value, value_at
from .explicit_friction import A_EST, ALPHA, C_EST, SAFE_FASTMATH, _friction_scalar, _law

# columns of the arcs' trial array (a row per node): a sweep's results, committed when
# its pulley's Newton iteration accepts them
T_F, T_S, T_G, T_D = 0, 1, 2, 3  # the force, v_rel / v_reg, the ratio, the increment
N_T = 4
# relative change of an arc's friction total below which its Newton iteration stops
ARC_TOL = 1e-13
# columns of the per-node coefficients of an advance (a row per node)
C_IH, C_KM, C_KI = 0, 1, 2  # 1 / h_j, dt / (rho hbar_j), dt / (I hbar_j)
N_C = 3


def gh_size(n_globals: int) -> int:
    """The length of History.gh on a loop of ``n_globals`` globals: their values after
    the last kick, their last kick's increments, each free pulley's arc's last friction
    total (index 0 unused) and the gauge mean to remove at the next drift."""
    return 3 * n_globals + 1


@njit(cache=True)
def loop_arcs(mesh):
    """(entry node, node count, segment) of each contact arc, a row each."""
    seg = mesh.seg
    n = seg.shape[0]
    count = 0
    for j in range(n):
        if seg[j] >= 0 and seg[wrap(j - 1, n)] != seg[j]:
            count += 1
    arcs = np.zeros((count, 3), dtype=np.int64)
    k = 0
    for j in range(n):
        s = seg[j]
        if s >= 0 and seg[wrap(j - 1, n)] != s:
            m = 0
            while m < n and seg[wrap(j + m, n)] == s:
                m += 1
            arcs[k, 0], arcs[k, 1], arcs[k, 2] = j, m, s
            k += 1
    return arcs


@njit(cache=True, fastmath=SAFE_FASTMATH, error_model="numpy")
def _loop_drift(u, th, va, wa, vb, wb, pq, co, c, dt, gauge, mesh, p):
    """The velocity terms over dt with the drift, on the loop; returns c's change.

    (2/dt + d + G) vm + c_t = (2/dt) v_a for both fields (c_t in the axial one only),
    G the upwind gyroscopic term at the belt speed c: the cyclic solve (module notes),
    then the uniform correction to sum hbar vm = 0. vb, wb receive the velocities after
    the part (2 vm - v_a), u, theta drift by dt vm, and u loses ``gauge`` (the last
    kick's round-off of sum hbar u / Lambda). pq: (N, 2) scratch; co: the advance's
    coefficients (C_*).
    """
    hb = mesh.hb
    n = u.shape[0]
    s2 = 2.0 / dt
    base = s2 + p.damping
    yu = 0.0
    yt = 0.0
    z = 1.0
    for j in range(n):
        g = 2.0 * c * co[wrap(j - 1, n), C_IH]
        inv = 1.0 / (base + g)
        P = s2 * inv
        Q = g * inv
        pq[j, 0] = P
        pq[j, 1] = Q
        yu = P * va[j] + Q * yu
        yt = P * wa[j] + Q * yt
        z *= Q
    # the closure: vm_{N-1} = y_{N-1} + z_{N-1} vm_{N-1}, and the pass again from it
    mv = yu / (1.0 - z)
    mw = yt / (1.0 - z)
    total = 0.0
    for j in range(n):
        mv = pq[j, 0] * va[j] + pq[j, 1] * mv
        mw = pq[j, 0] * wa[j] + pq[j, 1] * mw
        vb[j] = mv
        wb[j] = mw
        total += hb[j] * mv
    kap = total / mesh.loop_length
    for j in range(n):
        vm = vb[j] - kap
        wm = wb[j]
        u[j] += dt * vm - gauge
        th[j] += dt * wm
        vb[j] = 2.0 * vm - va[j]
        wb[j] = 2.0 * wm - wa[j]
    # c_t = kap (2/dt + d) over dt (G annihilates the constant correction)
    return kap * (2.0 + p.damping * dt)


@njit(cache=True, fastmath=SAFE_FASTMATH, inline="always", error_model="numpy")
def _ratio_slope(code, sp, kap, s):
    """d g / d s_pred of the root of s + kappa g(s) = s_pred (the sweep's derivative)."""
    if code == EXACT:
        return 1.0 / kap if abs(sp) <= kap else 0.0
    if code == ADHESION:
        return 1.0 / kap
    if code == LINEAR or (code == RAMP and abs(s) <= 1.0):
        return 1.0 / (1.0 + kap)
    if code == TANH or code == SQRT:
        gp = _law(code, s)[1]
        return gp / (1.0 + kap * gp)
    return 0.0


@njit(cache=True, fastmath=SAFE_FASTMATH, error_model="numpy")
def _arc_sweep(j0, count, rim, ce, ff, u, th, bb, eb, db, sv, trial, co, dt, mesh, p):
    """One contact arc's friction in the direction of the flow at the rim speed ``rim``
    (ce the belt speed of the kick; ff the friction factor): each node's scalar equation
    (explicit_friction) into ``trial``. Returns the arc's total force and its derivative
    in ``rim``, carried along the sweep through the transport of the increments."""
    n = u.shape[0]
    hh, code, reg = p.half_height, p.law, p.regularisation
    sw, wf = mesh.sw, mesh.wf
    inv_reg = 1.0 / reg
    s = mesh.seg[j0]
    hh = hh * mesh.face[j0]  # the lever of the arc's face in contact
    mu = mesh.seg_mu[s]
    mu_r = mu / mesh.seg_radius[s]
    creep = ce * p.N0 / p.b1  # the target's part beyond the belt's total velocity
    pressure0 = p.N0 - p.mass * ce * ce
    al = ALPHA * dt
    d_l2 = eb[wrap(j0 - 2, n)]  # upstream of the entry: free nodes, the kick without friction
    d_l1 = eb[wrap(j0 - 1, n)]
    e_l2 = 0.0  # the increments' derivatives in rim
    e_l1 = 0.0
    k2, k1 = wrap(j0 - 2, n), wrap(j0 - 1, n)
    b_l2 = u[k2] + hh * th[k2]
    b_l1 = u[k1] + hh * th[k1]
    total = 0.0
    slope = 0.0
    for i in range(count):
        j = wrap(j0 + i, n)
        b_j = u[j] + hh * th[j]
        t0, t1, t2 = ce * sw[j, 0], ce * sw[j, 1], ce * sw[j, 2]
        est_c = A_EST + al * t2
        kb = co[j, C_KM] + hh * hh * co[j, C_KI]
        if mu == 0.0:
            bound = p.friction_scale * ff
        else:
            eps = sw[j, 0] * u[k2] + sw[j, 1] * u[k1] + sw[j, 2] * u[j]
            bound = mu_r * (pressure0 + p.b1 * eps)
        fh = wf[j] * max(bound, 0.0)
        est = (bb[j] + est_c * eb[j] - C_EST * db[j] + t0 * b_l2 + t1 * b_l1 + t2 * b_j
               + creep - rim)
        sp = (est + al * t0 * d_l2 + al * t1 * d_l1) * inv_reg
        kap = est_c * kb * fh * inv_reg
        if kap > 0.0:
            sj, g = _friction_scalar(code, sp, kap, sv[j])
            dg = _ratio_slope(code, sp, kap, sj)
        else:
            sj, g, dg = sp, 0.0, 0.0
        F = -fh * g
        dF = -fh * dg * (al * t0 * e_l2 + al * t1 * e_l1 - 1.0) * inv_reg
        d_j = eb[j] + kb * F
        trial[j, T_F] = F
        trial[j, T_S] = sj
        trial[j, T_G] = g
        trial[j, T_D] = d_j
        total += F
        slope += dF
        d_l2, d_l1 = d_l1, d_j
        e_l2, e_l1 = e_l1, kb * dF
        b_l2, b_l1 = b_l1, b_j
        k2, k1 = k1, j
    return total, slope


@njit(cache=True, error_model="numpy")
def _commit(j0, count, trial, va, wa, db, sv, fnode, lam, co, p, face):
    """Apply an arc's accepted sweep: the forces' kick, the increments, the warm starts,
    the ratios (state.lam) and the nodal forces."""
    n = va.shape[0]
    hh = p.half_height
    for i in range(count):
        j = wrap(j0 + i, n)
        F = trial[j, T_F]
        va[j] += co[j, C_KM] * F
        wa[j] += co[j, C_KI] * hh * face[j] * F
        db[j] = trial[j, T_D]
        sv[j] = trial[j, T_S]
        lam[j] = trial[j, T_G]
        fnode[j] = F


@njit(cache=True, fastmath=SAFE_FASTMATH, error_model="numpy")
def _loop_kick(u, th, va, wa, vb, wb, bb, eb, db, sv, fnode, lam, trial, co, arcs, gb, dgp,
               gtot, dg, t, dt, mesh, p, drive, loads):
    """The kick at t from the velocities vb, wb and globals gb before it (dgp: the last
    kick's increments of the globals, gtot: the free pulleys' arcs' last totals).

    va, wa receive the velocities after it (the gauge restored), dg the globals'
    increments; db, sv, fnode, lam the friction nodes' increments, warm starts, forces
    and ratios. Returns sum hbar u / Lambda (the gauge's round-off, removed at the next
    drift).
    """
    n = u.shape[0]
    hb, hh = mesh.hb, p.half_height
    rho, rot = p.mass, p.rotary_inertia
    ce = gb[0] + 0.5 * dgp[0]  # c at t: second order, as the velocities' estimate
    B = p.b1 - rho * ce * ce
    A = p.a - rot * ce * ce
    lk, l0, l1, m0, m1 = hermite_weights(loads.times, t)
    arm = mesh.arm_idx.shape[0] > 0
    if arm:  # a tensioner's arm: its spans' stretch at its angle (physics.arm)
        adelta, aslope, _ = arm_values(gb[mesh.arm_idx[0]], mesh)
    else:
        adelta = aslope = np.zeros(2)
    gauge = 0.0
    for j in range(n):
        jm = wrap(j - 1, n)
        jp = wrap(j + 1, n)
        ih, il = co[j, C_IH], co[jm, C_IH]
        eu = co[j, C_KM] * B * ((u[jp] - u[j]) * ih - (u[j] - u[jm]) * il)
        if arm and (mesh.arm_el[j] >= 0 or mesh.arm_el[jm] >= 0):
            eu += co[j, C_KM] * B * (stretch(j, adelta, aslope, mesh)[0]
                                     - stretch(jm, adelta, aslope, mesh)[0])
        et = co[j, C_KI] * (A * ((th[jp] - th[j]) * ih - (th[j] - th[jm]) * il)
                            - p.shear * hb[j] * th[j])
        if lk >= 0:
            eu += dt / rho * load_at(loads.qu, loads.dqu, lk, l0, l1, m0, m1, j)
            et += dt / rot * load_at(loads.qt, loads.dqt, lk, l0, l1, m0, m1, j)
        va[j] = vb[j] + eu
        wa[j] = wb[j] + et
        eb[j] = eu + hh * mesh.face[j] * et  # the face in contact's (or next to come)
        bb[j] = vb[j] + hh * mesh.face[j] * wb[j] + gb[0]  # its velocity: v + c
        fnode[j] = 0.0
        gauge += hb[j] * u[j]
    ff = friction_factor(drive, t)
    rim1 = value(drive.speed, t)
    for k in range(1, dg.shape[0]):
        dg[k] = 0.0
    for a in range(arcs.shape[0]):
        j0, count, s = arcs[a, 0], arcs[a, 1], arcs[a, 2]
        K = mesh.seg_speed[s]
        if K < 1:
            _arc_sweep(j0, count, rim1, ce, ff, u, th, bb, eb, db, sv, trial, co, dt, mesh, p)
        else:
            # the arc with its pulley's increment: G = sum F_j(rim(G)), rim(G) =
            # R (omega_b + A_EST dt (-M - R G) / J - C_EST Delta omega_last)
            R, J = mesh.seg_radius[s], mesh.inertia[K]
            load = value_at(drive.load, K, t)
            rim0 = R * (gb[K] + A_EST * dt * (-load) / J - C_EST * dgp[K])
            drim = -A_EST * dt * R * R / J
            G = gtot[K]
            lo, hi = -np.inf, np.inf
            for _ in range(100):
                tot, dtot = _arc_sweep(j0, count, rim0 + drim * G, ce, ff, u, th, bb, eb,
                                       db, sv, trial, co, dt, mesh, p)
                phi = G - tot
                step = phi / (1.0 - dtot * drim)  # the slope is >= 1: monotone
                if phi > 0.0:
                    hi = min(hi, G)
                else:
                    lo = max(lo, G)
                if abs(step) <= ARC_TOL * (abs(G) + abs(tot)) or step == 0.0:
                    break
                G -= step
                if not lo < G < hi:
                    G = 0.5 * (lo + hi)  # Newton left the bracket (it is finite then)
            gtot[K] = tot
            dg[K] = dt * (-load - R * tot) / J
        _commit(j0, count, trial, va, wa, db, sv, fnode, lam, co, p, mesh.face)
    if arm:  # the arm's kick, its damper explicit (its rate far below 1 / dt)
        ib = mesh.arm_idx[0]
        ta, tb, _, _ = span_tensions(u, adelta, aslope, mesh, p)
        rc = rho * ce * ce
        dg[ib] = 0.0
        dg[ib + 1] = dt * arm_torque(gb[ib], gb[ib + 1], ta - rc, tb - rc, aslope,
                                     mesh) / mesh.inertia[ib + 1]
    # the gauge: the uniform correction to sum hbar v = 0 is c's increment
    total = 0.0
    for j in range(n):
        total += hb[j] * va[j]
    dg[0] = total / mesh.loop_length
    for j in range(n):
        va[j] -= dg[0]
    return gauge / mesh.loop_length


@njit(cache=True, fastmath=SAFE_FASTMATH, error_model="numpy")
def advance_loop(state, hist, fresh, t, t_stop, dt, max_steps, mesh, p, drive, loads):
    """Steps of the explicit scheme on a loop from t until t >= t_stop (or max_steps).
    Returns (t, steps); explicit.advance_explicit describes the history and the state
    on return. On a loop state.lam holds the friction ratios (as the Newton schemes'),
    state.g the globals at t (the mean of their values before and after the last kick)
    and state.gd their rates; hist.sv the warm starts v_rel / v_reg, hist.gh the globals'
    history (:func:`gh_size`)."""
    u, th, ud, td, fnode, lam, g, gd = (state.u, state.theta, state.ud, state.td,
                                        state.fnode, state.lam, state.g, state.gd)
    va, wa, db, sv, gh = hist.va, hist.wa, hist.db, hist.sv, hist.gh
    n, ng = u.shape[0], g.shape[0]
    ga, dgp, gtot = gh[:ng], gh[ng:2 * ng], gh[2 * ng:3 * ng]
    arcs = loop_arcs(mesh)
    vb, wb, bb, eb = np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n)
    trial = np.zeros((n, N_T))
    pq = np.zeros((n, 2))
    co = np.zeros((n, N_C))
    for j in range(n):
        co[j, C_IH] = 1.0 / mesh.he[j]
        co[j, C_KM] = dt / (p.mass * mesh.hb[j])
        co[j, C_KI] = dt / (p.rotary_inertia * mesh.hb[j])
    gb = np.zeros(ng)
    dg = np.zeros(ng)
    if fresh:
        # the history from the state: a kick at t from u_t, then again from half a kick
        # before it, as on the open layout
        db[:] = 0.0
        sv[:] = 0.0
        dgp[:] = 0.0
        gtot[:] = 0.0
        vb[:] = ud
        wb[:] = td
        gb[:] = g
        for _ in range(2):
            gauge = _loop_kick(u, th, va, wa, vb, wb, bb, eb, db, sv, fnode, lam, trial, co,
                               arcs, gb, dgp, gtot, dg, t, dt, mesh, p, drive, loads)
            for j in range(n):
                vb[j] = 1.5 * ud[j] - 0.5 * va[j]
                wb[j] = 1.5 * td[j] - 0.5 * wa[j]
            for k in range(ng):
                ga[k] = gb[k] + dg[k]
                gb[k] = 1.5 * g[k] - 0.5 * ga[k]
                dgp[k] = dg[k]
        gh[3 * ng] = gauge
    steps = 0
    t_reached = t_stop - 1e-9 * dt
    while t < t_reached and steps < max_steps:
        dc = _loop_drift(u, th, va, wa, vb, wb, pq, co, ga[0], dt, gh[3 * ng], mesh, p)
        gb[:] = ga
        gb[0] += dc
        if mesh.arm_idx.shape[0] > 0:  # the arm's angle drifts with its rate, as u
            gb[mesh.arm_idx[0]] += dt * ga[mesh.arm_idx[0] + 1]
        t += dt
        steps += 1
        gh[3 * ng] = _loop_kick(u, th, va, wa, vb, wb, bb, eb, db, sv, fnode, lam, trial, co,
                                arcs, gb, dgp, gtot, dg, t, dt, mesh, p, drive, loads)
        for k in range(ng):
            ga[k] = gb[k] + dg[k]
            dgp[k] = dg[k]
    if steps > 0:
        for j in range(n):
            ud[j] = 0.5 * (vb[j] + va[j])
            td[j] = 0.5 * (wb[j] + wa[j])
        for k in range(ng):
            g[k] = gb[k] + 0.5 * dg[k]
            gd[k] = dg[k] / dt
        if mesh.arm_idx.shape[0] > 0:  # the arm's angle is a position: its rate, the rate
            gd[mesh.arm_idx[0]] = g[mesh.arm_idx[0] + 1]
    return t, steps
