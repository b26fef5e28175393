"""The discrete model once more, vectorised: the reference the numba kernels are checked against.

numpy and scipy.sparse over all nodes at once, for the tests, the linear stability
analysis (:mod:`.modes`) and the generic peers and numpy port in ``benchmarks/``. The
semi-discrete model of :mod:`beltsim.physics.model` reads

    M q'' = f(q, q', t),   q = (u_1, theta_1, u_2, theta_2, ..., u_{N-1}, theta_{N-1}),

the interior nodes' unknowns interleaved as in the kernels' 2x2 blocks, M = diag(rho
hbar_j, I hbar_j) the lumped masses and f the elastic, shear, gyroscopic, damping,
friction and load forces (:func:`forces`). Its linearisation M z'' + C z' + K z = 0,
C = -df/dq' and K = -df/dq (:func:`linearisation`), gives the rest: the backward-Euler
residual of :func:`beltsim.physics.model.assemble`

    R = M (q' - q'_old) inv_dt - f(q, q', t),   q' = (q - q_old) inv_dt

(:func:`residual`; inv_dt = 0 is the steady problem) and its Jacobian inv_dt^2 M +
inv_dt C + K (:func:`jacobian`), the peers' method-of-lines system and the stability
analysis's matrix polynomial.

Friction: a regularised law in the primal form, lam = g(v_rel / v_reg) of the state.
Given ``ratios`` (at the nodes) replace g: the exact laws' multipliers, whose
linearisation has the slope of :func:`beltsim.physics.model.add_stick_penalty` at the
stuck nodes and none at the sliding ones.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from ..problem.drive import friction_factor, mismatch, value, value_at
from .arm import table_values
from .discrete import CENTRAL, Mesh, ModelParams, State, hermite_weights
from .friction import ADHESION, AUGMENTATION, is_exact, law_numpy
from .model import POWER_TERMS

if TYPE_CHECKING:  # scipy.sparse is imported where a matrix is built: a run reads
    import scipy.sparse as sp  # only this module's strains, and scipy.sparse costs 0.1 s


class Operators(NamedTuple):
    """The parts of the linearisation that do not depend on the state (friction aside)."""

    mass: np.ndarray  # M: the lumped masses (2n,), interleaved
    stiffness: sp.csr_matrix  # -df/dq of the elastic and shear terms (2n, 2n)
    damping: sp.csr_matrix  # -df/dq' of the gyroscopic and damping terms (2n, 2n)


class FrictionPattern(NamedTuple):
    """Where friction enters -df/d(q, q') (2n, 4n: the q columns, then the q' columns).

    Entry e is ``k[node[e]] * coef[e]``, k_j = -dF_j/dv_rel the friction stiffness of
    contact node c0 + node[e] (:func:`friction`). Entries may repeat a position (they add).
    """

    rows: np.ndarray
    cols: np.ndarray
    node: np.ndarray
    coef: np.ndarray


def interleave(a, b) -> np.ndarray:
    """(a_1, b_1, a_2, b_2, ...) of two nodal arrays of the interior nodes."""
    return np.column_stack([a, b]).ravel()


def contact_nodes(mesh: Mesh) -> np.ndarray:
    """The friction nodes c0 .. j2."""
    return np.arange(mesh.c0, mesh.j2 + 1)


def strain(ub, sw, j):
    """d/dx u_b at the friction nodes j (array) from the stencil weights sw."""
    j = np.asarray(j)
    return np.sum(sw[j] * ub[j[..., None] + np.arange(-2, 1)], axis=-1)


def slip_velocity(u, th, ud, td, t, mesh: Mesh, p: ModelParams, drive=None):
    """v_rel = d/dt u_b + c d/dx u_b - (v(t) - c) at the friction nodes (without a drive,
    the part linear in the state: v(t) - c left out)."""
    j, hh = contact_nodes(mesh), p.half_height
    vrel = ud[j] + hh * td[j] + p.speed * strain(u + hh * th, mesh.sw, j)
    return vrel if drive is None else vrel - mismatch(drive, t)


def friction(vrel, t, mesh: Mesh, p: ModelParams, drive, ratios=None, slopes=None):
    """(F, k): the nodal friction forces F (N + 1) and the friction stiffnesses
    k = -dF_j/dv_rel of the friction nodes at their slip velocities ``vrel``.

    The ratio is g(v_rel / v_reg) for a regularised law; ``ratios`` (N + 1) given, it is
    theirs, with the slope g' at vrel for a regularised law and, for an exact law, the
    stick penalty's slope AUGMENTATION (per unit v_rel / v_aug) where the node sticks.
    ``slopes`` (the friction nodes') replace those slopes.
    """
    j = contact_nodes(mesh)
    s = vrel / p.regularisation
    if is_exact(p.law):
        if ratios is None:
            raise ValueError("an exact friction law's ratios are unknowns: pass ratios")
        lam = ratios[j]
        stick = (p.law == ADHESION) | (np.abs(lam + s) < 1.0)
        slope = np.where(stick, AUGMENTATION, 0.0)
    else:
        lam, slope = law_numpy(p.law, s)
        if ratios is not None:
            lam = ratios[j]
    if slopes is not None:
        slope = slopes
    fs = p.friction_scale * friction_factor(drive, t)
    F = np.zeros(len(mesh.hb))
    F[j] = -mesh.wf[j] * fs * lam
    return F, mesh.wf[j] * fs * slope / p.regularisation


def loads_at(loads, t, n_nodes):
    """(q_u, q_theta) of the distributed loads at t (N + 1 each; zeros without loads)."""
    if loads is None or not len(loads.times):
        return np.zeros(n_nodes), np.zeros(n_nodes)
    k, *wts = hermite_weights(loads.times, t)
    return tuple(np.dot(wts, [q[k], q[k + 1], dq[k], dq[k + 1]])
                 for q, dq in ((loads.qu, loads.dqu), (loads.qt, loads.dqt)))


def gyroscopic(mesh: Mesh, p: ModelParams):
    """(g0, gl, gu): the gyroscopic term 2 c v_x over each interior node's control volume
    per unit mass, g0 v_j + gl v_{j-1} + gu v_{j+1}: upwind, or the skew Galerkin form."""
    n = len(mesh.he) - 1
    if p.gyro == CENTRAL:
        return np.zeros(n), np.full(n, -p.speed), np.full(n, p.speed)
    g = 2.0 * p.speed * mesh.hb[1:-1] / mesh.he[:-1]
    return g, -g, np.zeros(n)


def _gyro_force(v, g):
    """The gyroscopic term of the nodal rates v (N + 1) at the interior nodes."""
    g0, gl, gu = g
    return g0 * v[1:-1] + gl * v[:-2] + gu * v[2:]


def forces(u, th, ud, td, t, mesh: Mesh, p: ModelParams, drive, loads=None, ratios=None):
    """f of M q'' = f: the forces on u and the moments on theta at the interior nodes
    (n, 2), all but the inertia terms; and the nodal friction forces F (N + 1).

    u, th, ud, td: the nodal fields and their local rates (N + 1, boundary zeros).
    """
    B, A, b2 = p.B, p.A, p.shear
    rho, I, hh = p.mass, p.rotary_inertia, p.half_height
    he, hb = mesh.he, mesh.hb
    F, _ = friction(slip_velocity(u, th, ud, td, t, mesh, p, drive), t, mesh, p, drive,
                    ratios)
    sl = slice(1, -1)
    g = gyroscopic(mesh, p)
    qu, qt = loads_at(loads, t, len(u))
    f = np.empty((len(u) - 2, 2))
    f[:, 0] = (B * np.diff(np.diff(u) / he) - rho * _gyro_force(ud, g)
               - p.damping * rho * hb[sl] * ud[sl] + F[sl] + hb[sl] * qu[sl])
    f[:, 1] = (A * np.diff(np.diff(th) / he) - b2 * hb[sl] * th[sl]
               - I * _gyro_force(td, g) - p.damping * I * hb[sl] * td[sl]
               + hh * F[sl] + hb[sl] * qt[sl])
    return f, F


def _fields(n, offset, u_entries, t_entries):
    """(rows, cols, vals) of entries (2n, 2n) coupling each field's node i to node
    i + offset: u_entries in the u rows, t_entries in the theta rows (n values each)."""
    i = np.arange(max(0, -offset), min(n, n - offset))
    rows = np.concatenate([2 * i, 2 * i + 1])
    cols = np.concatenate([2 * (i + offset), 2 * (i + offset) + 1])
    vals = np.concatenate([np.broadcast_to(u_entries, n)[i], np.broadcast_to(t_entries, n)[i]])
    return rows, cols, vals


def _matrix(n, parts):
    import scipy.sparse as sp

    rows, cols, vals = (np.concatenate(x) for x in zip(*parts))
    return sp.csr_matrix((vals, (rows, cols)), shape=(2 * n, 2 * n))


def operators(mesh: Mesh, p: ModelParams) -> Operators:
    """M, and the stiffness and damping matrices without friction."""
    he, hb = mesh.he, mesh.hb
    n = len(he) - 1
    hl, hr, hbi = he[:-1], he[1:], hb[1:-1]
    rho, I = p.mass, p.rotary_inertia
    g0, gl, gu = gyroscopic(mesh, p)
    stiffness = _matrix(n, [_fields(n, 0, p.B * (1.0 / hl + 1.0 / hr),
                                    p.A * (1.0 / hl + 1.0 / hr) + p.shear * hbi),
                            _fields(n, -1, -p.B / hl, -p.A / hl),
                            _fields(n, 1, -p.B / hr, -p.A / hr)])
    damping = _matrix(n, [_fields(n, 0, rho * g0 + p.damping * rho * hbi,
                                  I * g0 + p.damping * I * hbi),
                          _fields(n, -1, rho * gl, I * gl), _fields(n, 1, rho * gu, I * gu)])
    return Operators(interleave(rho * hbi, I * hbi), stiffness, damping)


def friction_pattern(mesh: Mesh, p: ModelParams) -> FrictionPattern:
    """The friction's entries in -df/d(q, q'): node j's force F_j(v_rel,j) acts on its u
    row and, times h/2, its theta row; v_rel,j depends on u_b = u + (h/2) theta at
    j - 2 .. j through the transport c sw[j] and on d/dt u_b at j."""
    n = len(mesh.he) - 1
    j = contact_nodes(mesh)
    node, i = np.arange(j.size), j - 1
    hh = p.half_height
    # (row node, column node, contact node, d v_rel / d u_b): q' columns from 2n on
    links = [(i, np.full(j.size, n) + i, node, np.ones(j.size))]
    for o in range(3):
        k = i - 2 + o
        w = p.speed * mesh.sw[j, o]
        ok = (k >= 0) & (w != 0.0)
        links.append((i[ok], k[ok], node[ok], w[ok]))
    rows, cols, nodes, coefs = [], [], [], []
    for r, col, a, w in links:
        for fr, fc, lever in ((0, 0, 1.0), (0, 1, hh), (1, 0, hh), (1, 1, hh * hh)):
            rows.append(2 * r + fr)
            cols.append(2 * col + fc)
            nodes.append(a)
            coefs.append(lever * w)
    return FrictionPattern(*(np.concatenate(x) for x in (rows, cols, nodes, coefs)))


def friction_matrices(k, pattern: FrictionPattern, n):
    """The friction's parts (K_f, C_f) of -df/dq and -df/dq' at stiffnesses k (2n, 2n)."""
    import scipy.sparse as sp

    vals = k[pattern.node] * pattern.coef
    full = sp.csr_matrix((vals, (pattern.rows, pattern.cols)), shape=(2 * n, 4 * n))
    return full[:, :2 * n], full[:, 2 * n:]


def linearisation(u, th, ud, td, t, mesh: Mesh, p: ModelParams, drive, ratios=None):
    """(M, C, K) of the model linearised about the state (sparse; M diagonal)."""
    import scipy.sparse as sp

    ops = operators(mesh, p)
    _, k = friction(slip_velocity(u, th, ud, td, t, mesh, p, drive), t, mesh, p, drive,
                    ratios)
    Kf, Cf = friction_matrices(k, friction_pattern(mesh, p), len(ops.mass) // 2)
    return sp.diags(ops.mass).tocsr(), (ops.damping + Cf).tocsr(), (ops.stiffness + Kf).tocsr()


def _rates(u, th, old: State, inv_dt):
    return (u - old.u) * inv_dt, (th - old.theta) * inv_dt


def residual(u, th, old: State, inv_dt, t, mesh: Mesh, p: ModelParams, drive, loads=None,
             ratios=None):
    """The residual (n, 2) of :func:`beltsim.physics.model.assemble` (the primal form) and
    the nodal friction forces (N + 1); old: the previous step's state."""
    ud, td = _rates(u, th, old, inv_dt)
    f, F = forces(u, th, ud, td, t, mesh, p, drive, loads, ratios)
    sl, hb = slice(1, -1), mesh.hb
    R = np.empty_like(f)
    R[:, 0] = p.mass * hb[sl] * (ud[sl] - old.ud[sl]) * inv_dt - f[:, 0]
    R[:, 1] = p.rotary_inertia * hb[sl] * (td[sl] - old.td[sl]) * inv_dt - f[:, 1]
    return R, F


def jacobian(u, th, old: State, inv_dt, t, mesh: Mesh, p: ModelParams, drive, ratios=None):
    """d residual / dq = inv_dt^2 M + inv_dt C + K (2n, 2n, CSR)."""
    ud, td = _rates(u, th, old, inv_dt)
    M, C, K = linearisation(u, th, ud, td, t, mesh, p, drive, ratios)
    return (inv_dt * inv_dt * M + inv_dt * C + K).tocsr()


def power_terms(state: State, t, mesh: Mesh, p: ModelParams, drive, loads=None):
    """The power terms of POWER_TERMS (W) of a state at t, as
    :func:`beltsim.physics.model.power_terms` gives them."""
    u, th, ud, td, F = state.u, state.theta, state.ud, state.td, state.fnode
    c, hh, hb = p.speed, p.half_height, mesh.hb
    j = contact_nodes(mesh)
    target = mismatch(drive, t)
    strain_b = strain(u + hh * th, mesh.sw, j)
    vrel = ud[j] + hh * td[j] + c * strain_b - target
    sl = slice(1, -1)
    qu, qt = loads_at(loads, t, len(u))
    g = gyroscopic(mesh, p)
    terms = {
        "surface": target * F[j].sum(),
        "transport": -c * np.sum(F[j] * strain_b),
        "loads": np.sum(hb[sl] * (qu[sl] * ud[sl] + qt[sl] * td[sl])),
        "slip": -np.sum(F[j] * vrel),
        "damping": p.damping * np.sum(hb[sl] * (p.mass * ud[sl] ** 2
                                                + p.rotary_inertia * td[sl] ** 2)),
        "gyroscopic": np.sum(p.mass * ud[sl] * _gyro_force(ud, g)
                             + p.rotary_inertia * td[sl] * _gyro_force(td, g)),
    }
    return np.array([terms[name] for name in POWER_TERMS])


# -- a closed layout (a loop) ----------------------------------------------------------
# The same equations on a periodic grid, with np.roll for the neighbours
# (np.roll(v, 1)[j] = v[j - 1]) and the loop's global unknowns g = (c, omega_k ...): the
# belt's c_t in the axial rows, the stiffnesses b1 - rho c^2 and a - I c^2, the pressure
# bound mu (N0 + b1 u_x - rho c^2) / R and the creep c (1 + N0 / b1) in the slip velocity,
# the gauge (the mean of u) and each free pulley's J omega_t + M(t) + R sum F.


def loop_residual(u, th, lam, g, old, inv_dt, t, mesh: Mesh, p: ModelParams, drive,
                  loads=None):
    """(R, Rg): the rows (N, 2) and the global rows of a loop's backward-Euler residual,
    as :func:`beltsim.physics.model.assemble` writes them; and F, the nodal friction.

    A regularised law takes the ratio of the state's slip velocity (the primal form); an
    exact law takes ``lam`` as it is (its ratios are unknowns).
    """
    rho, I, hh = p.mass, p.rotary_inertia, p.half_height
    c = g[0]
    B, A = p.b1 - rho * c * c, p.a - I * c * c
    he, hb, sw = mesh.he, mesh.hb, mesh.sw
    hl = np.roll(he, 1)
    ud, td = (u - old.u) * inv_dt, (th - old.theta) * inv_dt
    acc_u = (ud - old.ud) * inv_dt + p.damping * ud
    acc_t = (td - old.td) * inv_dt + p.damping * td
    if p.gyro == CENTRAL:
        g0, gl, gu = 0.0, -c, c
    else:
        g0 = 2.0 * c * hb / hl
        gl, gu = -g0, 0.0

    def gyro(v):
        return g0 * v + gl * np.roll(v, 1) + gu * np.roll(v, -1)

    def lap(v):
        return (np.roll(v, -1) - v) / he - (v - np.roll(v, 1)) / hl

    def stencil(v):
        return sw[:, 0] * np.roll(v, 2) + sw[:, 1] * np.roll(v, 1) + sw[:, 2] * v

    on = mesh.seg >= 0
    seg = np.maximum(mesh.seg, 0)
    K = np.where(on, mesh.seg_speed[seg], -1)
    R = np.where(on, mesh.seg_radius[seg], 1.0)
    rim = np.where(K >= 1, g[np.maximum(K, 0)] * R, value(drive.speed, t))
    hh = hh * mesh.face  # the lever of the face in contact, node by node
    ub, ubo = u + hh * th, old.u + hh * old.theta
    vrel = (ub - ubo) * inv_dt + c * stencil(ub) - (rim - c * (1.0 + p.N0 / p.b1))
    mu = mesh.seg_mu[seg]
    fs = p.friction_scale * friction_factor(drive, t)
    S = np.where(mu > 0.0, mu * (p.N0 + p.b1 * stencil(u) - rho * c * c) / R, fs)
    ratio = lam if is_exact(p.law) else law_numpy(p.law, vrel / p.regularisation)[0]
    F = np.where(on, -mesh.wf * S * ratio, 0.0)
    qu, qt = loads_at(loads, t, len(u))
    e, arm = _arm_stretch(g, mesh)
    out = np.empty((len(u), 2))
    out[:, 0] = (rho * hb * acc_u + rho * gyro(ud) - B * (lap(u) + e - np.roll(e, 1))
                 + rho * hb * (c - old.g[0]) * inv_dt - hb * qu - F)
    out[:, 1] = (I * hb * acc_t + I * gyro(td) - A * lap(th) + p.shear * hb * th
                 - hb * qt - hh * F)
    Rg = np.empty(len(g))
    Rg[0] = np.sum(hb * u) / mesh.loop_length
    for k in range(1, len(g)):
        Rg[k] = (mesh.inertia[k] * (g[k] - old.g[k]) * inv_dt + value_at(drive.load, k, t)
                 + np.sum(R[K == k] * F[K == k]))
    if arm is not None:
        ib, ia, jb = mesh.arm_idx
        kt, tau0, damp, turn = mesh.arm_par[:4]
        slope = arm[1]
        axial = p.N0 + p.b1 * ((np.roll(u, -1) - u) / he + e) - rho * c * c
        Rg[ib] -= g[ib + 1]
        Rg[ib + 1] += (damp * g[ib + 1] - tau0 + kt * (turn + g[ib]) + axial[ia] * slope[0]
                       + axial[jb] * slope[1])
    return out, Rg, F


def _arm_stretch(g, mesh: Mesh):
    """A tensioner's stretch strain of each element and (delta, slope) of its two spans
    (:mod:`beltsim.physics.arm`); zeros and None without an arm."""
    if mesh.arm_idx.shape[0] == 0:
        return np.zeros(len(mesh.he)), None
    la, lb = mesh.arm_par[6:8]
    delta, slope, _ = table_values(g[mesh.arm_idx[0]], mesh)
    span = mesh.arm_el
    e = np.where(span >= 0, delta[np.maximum(span, 0)] / np.where(span == 1, lb, la), 0.0)
    return e, (delta, slope)
