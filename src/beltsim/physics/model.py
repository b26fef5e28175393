"""The discrete model: residual and Jacobian of the transient equations.

Fields u, theta at the nodes of a fixed grid; the material flows through at
speed c, and D/Dt = d/dt + c d/dx. With B = b1 - rho c^2 and A = a - I c^2::

    rho (u_tt + 2 c u_xt) + d rho u_t = B u_xx + f
    I (theta_tt + 2 c theta_xt) + d I theta_t = A theta_xx - b2 theta + (h/2) f
    f = -f_s g(v_rel / v_reg),  v_rel = d/dt u_b + c d/dx u_b - (v(t) - c),  u_b = u + (h/2) theta

Space: linear elements with lumped mass and shear (node-centred control
volumes). The gyroscopic term 2 c u_xt has two forms (numerics.gyroscopic): upwind,
2 rho c hbar_j (v_j - v_{j-1}) / h_{j-1}, first order, which damps the spans' modes
numerically; or the Galerkin form of linear elements, rho c (v_{j+1} - v_{j-1}), skew,
second order and without numerical damping. The exact spectrum (physics.continuum) has
growing modes at the paper's steady states: the central form reproduces them, the upwind
one damps them, and that is why the paper's scenes settle with it. Both vanish at steady
state. The transport c d/dx u_b in the slip velocity is evaluated at
the contact nodes x1 .. x2 with the one-sided three-point (BDF2) derivative over
x_{j-2}, x_{j-1}, x_j (second order on any grid; upwind, so its parasitic solution
decays by ~1/3 per node downstream and never alternates), and the friction of node j
acts on the contact part of its control volume (half volumes at x1 and x2: trapezoidal
quadrature). Treated centrally this term makes the friction alternate in sign from node
to node in stick zones; the two-point upwind form is smooth but first order. The
stencil reaches node j - 2, so the Jacobian has a second lower block band. The damping
d acts on local time derivatives only, so it vanishes at steady state (damping of the
material strain rate would not, and would change the answer). See
docs/theory/discretisation.md.

Time: the residual is written for backward Euler with ``inv_dt`` = 1/dt; with
``inv_dt`` = 0 it is the discrete steady problem. Interior nodes 1..N-1 carry
the unknowns (u_j, theta_j); the Jacobian is block banded with 2x2 blocks (two lower
bands, one upper: the friction stencil's j - 2).

What the kernels read (the coefficients, the layout on its grid, the state and the
loads) is defined in :mod:`beltsim.physics.discrete`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..problem.drive import friction_factor, mismatch, value, value_at
from .arm import arm_rows, arm_stretch, stretch

# Loads and State are not used here: numba's cache indexes written before they moved to
# physics.discrete name them here, and unpickling such an index must find them, or every
# cached kernel fails to load
from .discrete import (  # noqa: F401
    CENTRAL,
    Loads,
    Mesh,
    ModelParams,
    State,
    hermite_weights,
    load_at,
)
from .friction import AUGMENTATION, EXACT, law, law_inverse

# |lam| bound in the primal-dual iteration: the friction of a fully sliding node is
# then f* (1 - 1e-14), and g^{-1} stays finite
LAM_MAX = 1.0 - 1e-14

#: :func:`assemble`'s ``want_jac``, with or without the Jacobian. numba compiles a kernel
#: once for each literal True or False it is called with; these numpy booleans are typed
#: as plain ``bool``, so every caller shares one compiled assemble.
JACOBIAN, RESIDUAL = np.bool_(True), np.bool_(False)



@njit(cache=True, inline="always")
def wrap(k, n):
    """Node k of a periodic grid of n nodes (k >= -n)."""
    return k + n if k < 0 else (k - n if k >= n else k)


@njit(cache=True, no_cpython_wrapper=True)
def bottom_strain(u, th, hh, sw, j):
    """d/dx u_b at friction node j from the stencil weights sw[j] (periodic on a loop)."""
    e = 0.0
    n = u.shape[0]
    for o in range(3):
        k = j - 2 + o
        if sw[j, o] != 0.0:
            k = wrap(k, n)
            e += sw[j, o] * (u[k] + hh * th[k])
    return e


@njit(cache=True, inline="always")
def gyro_weights(hbj, hl, c, gyro):
    """(diagonal, lower, upper) weights of the gyroscopic term 2 c v_x over node j's
    control volume, per unit mass: upwind 2 c hbar_j (v_j - v_{j-1}) / h_{j-1}, or the
    Galerkin form of linear elements c (v_{j+1} - v_{j-1}), skew-symmetric on any grid."""
    if gyro == CENTRAL:
        return 0.0, -c, c
    g = 2.0 * c * hbj / hl
    return g, -g, 0.0


@njit(cache=True, inline="always")
def rate_blocks(hbj, hl, inv_dt, c, p):
    """The terms in inv_dt of interior row j's Jacobian (its time-derivative part), but
    for friction: the lumped inertia and damping m_j (inv_dt^2 + d inv_dt) and the
    gyroscopic term (:func:`gyro_weights`) times inv_dt, m_j = rho hbar_j in the u row
    and I hbar_j in the theta row. Returns the (diagonal, lower, upper) entries of the u
    row and of the theta row."""
    kin = inv_dt * inv_dt + p.damping * inv_dt  # d(acc + damp * vel)/dy
    g0, gl, gu = gyro_weights(hbj, hl, c, p.gyro)
    rho, I = p.mass, p.rotary_inertia
    return (rho * hbj * kin + rho * g0 * inv_dt, rho * gl * inv_dt, rho * gu * inv_dt,
            I * hbj * kin + I * g0 * inv_dt, I * gl * inv_dt, I * gu * inv_dt)


@njit(cache=True, inline="always")
def own_rate_slope(o, inv_dt):
    """d v_rel,j / d u_b at node j - 2 + o through the rate d/dt u_b,j: inv_dt at j itself."""
    return inv_dt if o == 2 else 0.0


@njit(cache=True, inline="always")
def slip_velocity_slope(sw, j, o, c, inv_dt):
    """d v_rel,j / d u_b at node j - 2 + o (o = 0..2): transport, and the rate at j."""
    return c * sw[j, o] + own_rate_slope(o, inv_dt)


@njit(cache=True, inline="always")
def friction_stiffness(wfj, fs, sgj, p):
    """k = -dF_j/dv_rel of node j: weight wf_j, friction scale fs, slope sg_j of the ratio."""
    return wfj * fs * sgj / p.regularisation


@njit(cache=True, inline="always")
def loop_speed(g, mesh, p):
    """The belt speed c: a loop's first global unknown, or the open layout's constant."""
    return g[0] if mesh.off == 0 else p.speed


@njit(cache=True, inline="always")
def contact_target(s, c, g, rim, open_target, mesh, p):
    """v_rel's target at a node of segment s: v(t) - c on an open layout; on a loop the
    rim speed (prescribed, or the free pulley's) less the material speed c (1 + N0 / b1)."""
    if mesh.off == 1:
        return open_target
    k = mesh.seg_speed[s]
    r = rim if k < 0 else g[k] * mesh.seg_radius[s]
    return r - c * (1.0 + p.N0 / p.b1)


@njit(cache=True, inline="always")
def bound_scale(s, j, u, c, fs, mesh, p):
    """(S_j, dS/du_x, dS/dc): the friction bound of node j on segment s, f_s on a plate,
    mu p_j = mu (N0 + b1 u_x - rho c^2) / R on a pulley's arc (u_x from the stencil)."""
    mu = mesh.seg_mu[s]
    if mu == 0.0:
        return fs, 0.0, 0.0
    n = u.shape[0]
    eps = 0.0
    for o in range(3):
        eps += mesh.sw[j, o] * u[wrap(j - 2 + o, n)]
    R = mesh.seg_radius[s]
    return (mu * (p.N0 + p.b1 * eps - p.mass * c * c) / R, mu * p.b1 / R,
            -2.0 * mu * p.mass * c / R)


@njit(cache=True)
def assemble(u, th, lam, g, fnode, old, inv_dt, t, mesh, p, drive, loads, w, want_jac):
    """Residual w.R (n, 2) of the rows and, if want_jac, the Jacobian blocks.

    u, th, lam: trial values at t (open: N+1 with boundary zeros; closed: N); g: the
    trial global unknowns (a loop's c and free pulleys' speeds; empty when open); old:
    the State at the previous step (its values and local velocities). fnode receives the
    nodal friction forces of the trial state.

    Friction ratio lam = g(v_rel / v_reg) at each contact node: in the primal
    form (p.dual = 0) it is computed from the trial state; in the primal-dual form
    it is an unknown with the equation rl = v_rel / v_reg - g^{-1}(lam) = 0,
    condensed node by node into the (u, theta) rows so the Jacobian keeps its
    block band (two lower block bands from the friction stencil, one upper). w.sg
    receives the slope dlam/d(v_rel / v_reg) used by
    :func:`beltsim.solvers.dual.update_multipliers`.

    The exact laws (friction.EXACT, ADHESION; p.regularisation is then the
    augmentation velocity v_aug) keep lam as a full unknown of a semi-smooth Newton
    iteration (:mod:`beltsim.solvers.ssn`): its force enters as it is (its slope in
    lam is the saddle system's); rl receives v_rel / v_aug and sg 1 where lam + rl
    projects inside [-1, 1] (stick) and 0 where it slides.

    A loop (mesh.off = 0) adds its global rows and columns: w.Rg the gauge (the mean of
    u, in metres) and each free pulley's J omega_t + M(t) + R (sum of its arc's F),
    w.Gc (n, 2, ng) the rows' slopes in the globals, w.Gr (ng, n, 2) the global rows'
    slopes in the nodes' unknowns, w.Gd (ng, ng); the belt's c_t enters every axial row.
    Its rows wrap round the loop: the band blocks Lb, L2 of rows 0 and 1 and Ub of the
    last row couple to nodes across the closure (solvers.border solves with them).

    :mod:`beltsim.physics.reference` writes the same equations with numpy.
    """
    nn = u.shape[0]
    off = mesh.off
    closed = off == 0
    n = nn - 2 * off
    rho, I, hh = p.mass, p.rotary_inertia, p.half_height
    c = loop_speed(g, mesh, p)
    if closed:
        B, A = p.b1 - rho * c * c, p.a - I * c * c
        cd = (c - old.g[0]) * inv_dt
    else:
        B, A = p.B, p.A
        cd = 0.0
    b2 = p.shear
    damp = p.damping
    fs = p.friction_scale * friction_factor(drive, t)
    he, hb = mesh.he, mesh.hb
    wf, sw = mesh.wf, mesh.sw
    uo, tho, udo, tdo = old.u, old.theta, old.ud, old.td
    R, Lb, Db, Ub, rl, sg = w.R, w.Lb, w.Db, w.Ub, w.rl, w.sg
    L2 = w.L2
    target = mismatch(drive, t)
    rim = value(drive.speed, t)
    lk, l0, l1, m0, m1 = hermite_weights(loads.times, t)
    code, dual = p.law, p.dual
    arm = mesh.arm_idx.shape[0] > 0
    # a tensioner's arm: its spans' stretch
    adelta, aslope = arm_stretch(w.border, g, mesh.arm_idx, mesh.arm_coef, mesh.arm_par)
    for j in range(nn):
        fnode[j] = 0.0
    if closed:
        start_global_rows(w.border, w.Rg, w.Gc, w.Gr, w.Gd, g, old.g, inv_dt, t,
                          mesh.inertia, drive.load, want_jac)
    for i in range(n):
        j = i + off
        jm = j - 1 if j > 0 else nn - 1
        jp = j + 1 if j < nn - 1 else 0
        hl, hr, hbj = he[jm], he[j], hb[j]
        udj = (u[j] - uo[j]) * inv_dt
        tdj = (th[j] - tho[j]) * inv_dt
        ud_l = (u[jm] - uo[jm]) * inv_dt
        td_l = (th[jm] - tho[jm]) * inv_dt
        ud_r = (u[jp] - uo[jp]) * inv_dt
        td_r = (th[jp] - tho[jp]) * inv_dt
        g0, gl, gu = gyro_weights(hbj, hl, c, p.gyro)  # 2 c u_xt over the control volume
        acc_u = (udj - udo[j]) * inv_dt + damp * udj
        acc_t = (tdj - tdo[j]) * inv_dt + damp * tdj
        lap_u = (u[jp] - u[j]) / hr - (u[j] - u[jm]) / hl
        lap_t = (th[jp] - th[j]) / hr - (th[j] - th[jm]) / hl
        ru = rho * hbj * acc_u + rho * (g0 * udj + gl * ud_l + gu * ud_r) - B * lap_u
        rt = (I * hbj * acc_t + I * (g0 * tdj + gl * td_l + gu * td_r) - A * lap_t
              + b2 * hbj * th[j])
        if closed:
            ru += rho * hbj * cd
        if arm and (mesh.arm_el[j] >= 0 or mesh.arm_el[jm] >= 0):
            sr, dsr = stretch(j, adelta, aslope, mesh)  # the elements right and left of j
            sl, dsl = stretch(jm, adelta, aslope, mesh)
            ru -= B * (sr - sl)
        if lk >= 0:
            ru -= hbj * load_at(loads.qu, loads.dqu, lk, l0, l1, m0, m1, j)
            rt -= hbj * load_at(loads.qt, loads.dqt, lk, l0, l1, m0, m1, j)
        s = mesh.seg[j]
        if want_jac:
            if s >= 0:
                # friction adds to these rows' couplings and second band; elsewhere they
                # keep the zeros they were allocated with (the blocks' other entries)
                for a_ in range(2):
                    for b_ in range(2):
                        Lb[i, a_, b_] = 0.0
                        L2[i, a_, b_] = 0.0
                        Db[i, a_, b_] = 0.0
                        Ub[i, a_, b_] = 0.0
            du, lu, uu, dt_, lt, ut = rate_blocks(hbj, hl, inv_dt, c, p)
            Db[i, 0, 0] = du + B * (1.0 / hl + 1.0 / hr)
            Lb[i, 0, 0] = lu - B / hl
            Ub[i, 0, 0] = uu - B / hr
            Db[i, 1, 1] = dt_ + A * (1.0 / hl + 1.0 / hr) + b2 * hbj
            Lb[i, 1, 1] = lt - A / hl
            Ub[i, 1, 1] = ut - A / hr
            if closed:
                # d/dc: the c_t term, the gyroscopic term (linear in c) and B(c), A(c)
                e0, el, eu = gyro_weights(hbj, hl, 1.0, p.gyro)
                w.Gc[i, 0, 0] = (rho * hbj * inv_dt + rho * (e0 * udj + el * ud_l + eu * ud_r)
                                 + 2.0 * rho * c * lap_u)
                w.Gc[i, 1, 0] = I * (e0 * tdj + el * td_l + eu * td_r) + 2.0 * I * c * lap_t
                w.Gr[0, i, 0] = hbj / mesh.loop_length
                if arm and (mesh.arm_el[j] >= 0 or mesh.arm_el[jm] >= 0):
                    w.Gc[i, 0, 0] += 2.0 * rho * c * (sr - sl)
                    w.Gc[i, 0, mesh.arm_idx[0]] = -B * (dsr - dsl)
        if closed:
            w.Rg[0] += hbj * u[j] / mesh.loop_length
        if s >= 0:
            # slip velocity at node j (stencil sw[j]), friction on its weight wf[j]; the
            # lever of the face in contact (the top fibre's on a back-side idler)
            hh = p.half_height * mesh.face[j]
            ub = u[j] + hh * th[j]
            ubo = uo[j] + hh * tho[j]
            eb = bottom_strain(u, th, hh, sw, j)
            vrel = ((ub - ubo) * inv_dt + c * eb
                    - contact_target(s, c, g, rim, target, mesh, p))
            S, dSe, dSc = bound_scale(s, j, u, c, fs, mesh, p)
            w.bs[j] = S
            if closed:
                w.vc[j] = 1.0 + p.N0 / p.b1 + eb
            if code >= EXACT:
                # lam is the semi-smooth Newton's own unknown (solvers.ssn): its force
                # enters as it is; rl: v_rel / v_aug; sg: 1 where proj(lam + rl) sticks
                rl[j] = vrel / p.regularisation
                z = lam[j] + rl[j]
                sg[j] = 0.0 if code == EXACT and abs(z) >= 1.0 else 1.0
                fnode[j] = -wf[j] * S * lam[j]
                ru += wf[j] * S * lam[j]
                rt += hh * wf[j] * S * lam[j]
                if closed:
                    loop_friction(w, w.border, i, j, s, lam[j], 0.0, dSe, dSc, S, inv_dt, c, hh,
                                  mesh, p, want_jac)
                R[i, 0] = ru
                R[i, 1] = rt
                continue
            if dual:
                gi, dgi = law_inverse(code, lam[j])
                rl[j] = vrel / p.regularisation - gi
                sg[j] = 1.0 / dgi
            else:
                lam[j], sg[j] = law(code, vrel / p.regularisation)
                rl[j] = 0.0
            wj = wf[j]
            fnode[j] = -wj * S * lam[j]
            ru += wj * S * (lam[j] + sg[j] * rl[j])
            rt += hh * wj * S * (lam[j] + sg[j] * rl[j])
            if want_jac:
                add_friction_slope(L2, Lb, Db, i, j, friction_stiffness(wj, S, sg[j], p),
                                   inv_dt, c, hh, sw)
            if closed:
                loop_friction(w, w.border, i, j, s, lam[j] + sg[j] * rl[j],
                              friction_stiffness(wj, S, sg[j], p), dSe, dSc, S, inv_dt, c, hh,
                              mesh, p, want_jac)
        R[i, 0] = ru
        R[i, 1] = rt
    if arm:
        arm_rows(u, g, mesh, p, w, w.border, want_jac)


@njit(cache=True, no_cpython_wrapper=True)
def start_global_rows(bd, Rg, Gc, Gr, Gd, g, g_old, inv_dt, t, inertia, loads, want_jac):
    """A loop's global rows before its nodes' terms: the free pulleys' J omega_t and
    loads (``loads``: the drive's), and the slopes' start. ``bd`` is the workspace's
    border: None on an open layout's, which never comes here; its type prunes the body.
    (The workspace's arrays, not the workspace: a kernel's compile grows with the arrays
    its arguments hold.)"""
    if bd is None:
        return
    ng = g.shape[0]
    Rg[0] = 0.0
    for k in range(1, ng):
        Rg[k] = inertia[k] * (g[k] - g_old[k]) * inv_dt + value_at(loads, k, t)
    if want_jac:
        Gc[:, :, :] = 0.0
        Gr[:, :, :] = 0.0
        Gd[:, :] = 0.0
        for k in range(1, ng):
            Gd[k, k] = inertia[k] * inv_dt


@njit(cache=True, no_cpython_wrapper=True)
def loop_friction(w, bd, i, j, s, m, k, dSe, dSc, S, inv_dt, c, hh, mesh, p, want_jac):
    """A loop's friction terms at node j (row i) beyond the open layout's: the slopes of
    its force wf S m (m the ratio, condensed for a regularised law) through the pressure
    bound S(u_x, c) and through v_rel in the globals (k = -dF/dv_rel), and the force's
    moment on its free pulley's row with all its slopes.

    ``bd`` is w.border: None on an open layout's workspace, which never comes here; its
    type prunes the body, so an open layout does not compile it.
    """
    if bd is None:
        return
    wj = mesh.wf[j]
    K = mesh.seg_speed[s]
    Rs = mesh.seg_radius[s]
    n = w.R.shape[0]
    if K >= 1:
        w.Rg[K] -= Rs * wj * S * m
    if not want_jac:
        return
    gc = k * w.vc[j] + wj * m * dSc  # d(force)/dc
    w.Gc[i, 0, 0] += gc
    w.Gc[i, 1, 0] += hh * gc
    if K >= 1:
        w.Gc[i, 0, K] -= k * Rs
        w.Gc[i, 1, K] -= hh * k * Rs
        w.Gd[K, 0] -= Rs * gc
        w.Gd[K, K] += Rs * k * Rs
    for o in range(3):
        q = wrap(j - 2 + o, n)
        dp = wj * m * dSe * mesh.sw[j, o]  # through the pressure, u only
        if dp != 0.0:
            blk = stencil_band(o, w.L2, w.Lb, w.Db)
            blk[i, 0, 0] += dp
            blk[i, 1, 0] += hh * dp
        if K >= 1:
            dv = k * slip_velocity_slope(mesh.sw, j, o, c, inv_dt)
            w.Gr[K, q, 0] -= Rs * (dv + dp)
            w.Gr[K, q, 1] -= Rs * dv * hh


@njit(cache=True)
def rate_part(e, eg, a0, fs, sg, bs, c, mesh, p, out, outg):
    """(out, outg) = T (e, eg): T the time-derivative part of assemble's Jacobian at
    inv_dt = a0, the terms in a0 (rate_blocks, and friction through the node's own
    rate) with the friction slopes sg and the friction scale fs (a loop's nodes: their
    bounds bs), on the rows (e, out: (n, 2)) and a loop's globals (eg, outg: (ng)):
    the belt's c_t in the axial rows and each free pulley's J omega_t. c: the belt speed."""
    he, hb, hh = mesh.he, mesh.hb, p.half_height
    off = mesh.off
    n = e.shape[0]
    for i in range(n):
        j = i + off
        jm = j - 1 if j > 0 else n - 1
        du, lu, uu, dt_, lt, ut = rate_blocks(hb[j], he[jm], a0, c, p)
        il = i - 1 if i > 0 else (n - 1 if off == 0 else -1)
        ir = i + 1 if i + 1 < n else (0 if off == 0 else -1)
        ul = e[il, 0] if il >= 0 else 0.0
        tl = e[il, 1] if il >= 0 else 0.0
        ur = e[ir, 0] if ir >= 0 else 0.0
        tr = e[ir, 1] if ir >= 0 else 0.0
        out[i, 0] = du * e[i, 0] + lu * ul + uu * ur
        out[i, 1] = dt_ * e[i, 1] + lt * tl + ut * tr
        if mesh.seg[j] >= 0:
            S = fs if off == 1 else bs[j]
            k = friction_stiffness(mesh.wf[j], S, sg[j], p) * own_rate_slope(2, a0)
            hf = hh * mesh.face[j]
            eb = e[i, 0] + hf * e[i, 1]
            out[i, 0] += k * eb
            out[i, 1] += hf * k * eb
        if off == 0:
            out[i, 0] += p.mass * hb[j] * a0 * eg[0]
    for k in range(eg.shape[0]):
        outg[k] = mesh.inertia[k] * a0 * eg[k]


@njit(cache=True)
def add_stick_penalty(w, inv_dt, fs, c, mesh, p):
    """After an exact law's assembly: the stuck nodes' constraint v_rel = 0 as the slope
    f_s AUGMENTATION / v_aug (the default regularisation's) in the 2x2 Jacobian blocks,
    w.sg scaled to match. The 2x2 stand-in of the semi-smooth Newton's 3x3 system, for
    what needs a 2x2 Jacobian: the implicit scheme's error filter, the linearisation.
    (fs: the open layout's friction scale; a loop's nodes take their bounds w.bs, and
    their slopes reach its globals: c the belt speed of the assembly.)"""
    for j in mesh.cn:
        w.sg[j] *= AUGMENTATION
        S = fs if mesh.off == 1 else w.bs[j]
        k = friction_stiffness(mesh.wf[j], S, w.sg[j], p)
        hf = p.half_height * mesh.face[j]
        add_friction_slope(w.L2, w.Lb, w.Db, j - mesh.off, j, k, inv_dt, c, hf, mesh.sw)
        if mesh.off == 0:
            loop_friction(w, w.border, j, j, mesh.seg[j], 0.0, k, 0.0, 0.0, S, inv_dt, c,
                          hf, mesh, p, JACOBIAN)


# a call, not inline="always": inlined, this choice made assemble three times slower
@njit(cache=True, no_cpython_wrapper=True)
def stencil_band(o, L2, Lb, Db):
    """The Jacobian block band of row j's column j - 2 + o."""
    if o == 0:
        return L2
    if o == 1:
        return Lb
    return Db


@njit(cache=True, no_cpython_wrapper=True)
def add_friction_slope(L2, Lb, Db, i, j, k, inv_dt, c, hh, sw):
    """Add to row block i of the Jacobian's bands the slope of a nodal force -k v_rel,j
    (k = -dF_j/dv_rel). (The bands, not the workspace: a kernel's compile grows with the
    arrays its arguments hold, and the workspace holds some thirty.)"""
    for o in range(3):
        dd = k * slip_velocity_slope(sw, j, o, c, inv_dt)
        if dd == 0.0:
            continue
        blk = stencil_band(o, L2, Lb, Db)
        blk[i, 0, 0] += dd
        blk[i, 0, 1] += dd * hh
        blk[i, 1, 0] += dd * hh
        blk[i, 1, 1] += dd * hh * hh


def traction(fnode, wf):
    """Traction f (N/m) at each friction node: F_j / wf_j, 0 off contact.

    wf: the friction weights of :class:`~beltsim.physics.discrete.Mesh`
    (:func:`~beltsim.physics.discrete.contact_stencil`). Works on stacks of
    states (last axis: nodes).
    """
    f = np.zeros_like(fnode)
    on = wf > 0.0
    f[..., on] = fnode[..., on] / wf[on]
    return f


# Power balance of the semi-discrete model. Multiplying the equations of motion by the
# local velocities:
#     dE/dt = P_surface + P_transport + P_loads - D_slip - D_damping - D_gyroscopic
# with E = 1/2 sum hbar (rho u_t^2 + I theta_t^2) + 1/2 (B sum (du)^2/h + A sum (dtheta)^2/h
# + b2 sum hbar theta^2) (B, A: the effective stiffnesses of the moving belt), and, with
# the nodal friction F_j and u_b = u + (h/2) theta, sum F_j d/dt u_b,j split along
# v_rel = d/dt u_b + c d/dx u_b - (v(t) - c): the slip dissipation D_slip = -sum F v_rel
# (>= 0), the surface's power P_surface = (v(t) - c) sum F, and the transport part
# P_transport = -c sum F d/dx u_b (the strain carried through the contact), and
# D_gyroscopic = sum v_j G_j(v) (+ theta), G the gyroscopic term (gyro_weights): the
# upwind form's dissipation plus the flux out at x = L (>= 0 on a uniform grid), or 0 for
# the skew central form.
POWER_TERMS = ("surface", "transport", "loads", "slip", "damping", "gyroscopic")


@njit(cache=True)
def power_terms(state, t, mesh, p, drive, loads, out):
    """The six power terms of POWER_TERMS (W) of a state at time t, into ``out``.

    On a loop (whose own balance adds the belt's and the pulleys' kinetic energy and the
    driver's and the load's power) the terms are those of its rows, in the same form.
    """
    u, th, ud, td, F, g = state.u, state.theta, state.ud, state.td, state.fnode, state.g
    he, hb, hh = mesh.he, mesh.hb, p.half_height
    c = loop_speed(g, mesh, p)
    target = mismatch(drive, t)
    rim = value(drive.speed, t)
    surface = 0.0
    transport = 0.0
    slip = 0.0
    for j in mesh.cn:
        hf = hh * mesh.face[j]
        strain_b = bottom_strain(u, th, hf, mesh.sw, j)
        tj = contact_target(mesh.seg[j], c, g, rim, target, mesh, p)
        vrel = ud[j] + hf * td[j] + c * strain_b - tj
        surface += tj * F[j]
        transport -= c * F[j] * strain_b
        slip -= F[j] * vrel
    damping = 0.0
    load = 0.0
    gyro = 0.0
    lk, l0, l1, m0, m1 = hermite_weights(loads.times, t)
    nn = u.shape[0]
    for i in range(nn - 2 * mesh.off):
        j = i + mesh.off
        jm = j - 1 if j > 0 else nn - 1
        jp = j + 1 if j < nn - 1 else 0
        damping += p.damping * hb[j] * (p.mass * ud[j] * ud[j]
                                        + p.rotary_inertia * td[j] * td[j])
        if lk >= 0:
            load += hb[j] * (load_at(loads.qu, loads.dqu, lk, l0, l1, m0, m1, j) * ud[j]
                             + load_at(loads.qt, loads.dqt, lk, l0, l1, m0, m1, j) * td[j])
        g0, gl, gu = gyro_weights(hb[j], he[jm], c, p.gyro)
        gyro += (p.mass * ud[j] * (g0 * ud[j] + gl * ud[jm] + gu * ud[jp])
                 + p.rotary_inertia * td[j] * (g0 * td[j] + gl * td[jm] + gu * td[jp]))
    out[0], out[1], out[2], out[3], out[4], out[5] = (surface, transport, load, slip,
                                                      damping, gyro)


def stored_energy(state, mesh: Mesh, p: ModelParams) -> float:
    """Kinetic plus elastic energy E of the power balance (J)."""
    hb, he = mesh.hb, mesh.he
    kinetic = 0.5 * np.sum(hb * (p.mass * state.ud**2 + p.rotary_inertia * state.td**2))
    elastic = 0.5 * (p.B * np.sum(np.diff(state.u) ** 2 / he)
                     + p.A * np.sum(np.diff(state.theta) ** 2 / he)
                     + p.shear * np.sum(hb * state.theta**2))
    return float(kinetic + elastic)
