"""The discrete model of any layout linearised about a steady state, from the numba kernel.

About a steady state y0 (zero rates) the kernel's backward-Euler Jacobian
(:func:`beltsim.physics.model.assemble`) at step rate s = 1/dt is a quadratic in s,

    J(s) = s^2 M + s C + K,

over the unknowns z = (u_1, theta_1, u_2, theta_2, ..., g): M the lumped masses, C the
damping, gyroscopic and friction-rate terms (a loop's c_t in its axial rows, each free
pulley's J omega_t), K the rest. The semi-discrete model linearised about y0 is then
M z'' + C z' + K z = 0 on every layout: a loop's globals are first-order unknowns (no
column of M) and its gauge row is algebraic (no row of M or C). J is evaluated at three
rates and the quadratic read off; the rates are chosen where s^2 M and K are of one size,
so that no part is lost in round-off.

The exact laws' stuck nodes enter with the penalty slope of
:func:`beltsim.physics.model.add_stick_penalty` (a stiff viscous stand-in for v_rel = 0),
sliding nodes with the slope of their bound, as the straight belt's vectorised reference
(:func:`beltsim.physics.reference.linearisation`) has it; the tests compare the two.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp

from ..physics.friction import is_exact
from ..physics.model import add_stick_penalty, assemble
from .newton import Workspace

#: A part's entry below this fraction of its row's largest term in J(3 sigma) is
#: round-off of the quadratic's reading (about 30 ulp of the largest term)
ROUND_OFF = 1e-14


def jacobian_matrix(w, closed: bool) -> sp.csr_matrix:
    """The Jacobian the kernel left in ``w`` (a Newton workspace's 2x2 blocks, or the exact
    laws' 3x3 saddle blocks) as one sparse matrix over each node's unknowns, then the
    globals: its block bands, which stop at an open layout's ends and wrap round a loop,
    and a loop's border (global columns Gc, rows Gr, block Gd)."""
    n, b, ng = w.Db.shape[0], w.Db.shape[1], w.Gd.shape[0]
    rows, cols, vals = [], [], []
    i = np.arange(n)
    for band, o in ((w.L2, -2), (w.Lb, -1), (w.Db, 0), (w.Ub, 1)):
        q = i + o
        keep = slice(None) if closed else (q >= 0) & (q < n)
        q = q % n
        for a in range(b):
            for c in range(b):
                rows.append(b * i[keep] + a)
                cols.append(b * q[keep] + c)
                vals.append(band[keep, a, c])
    if ng:
        for a in range(b):
            for k in range(ng):
                rows += [b * i + a, np.full(n, b * n + k)]
                cols += [np.full(n, b * n + k), b * i + a]
                vals += [w.Gc[:, a, k], w.Gr[k, :, a]]
        gk = np.arange(ng)
        rows.append(np.repeat(b * n + gk, ng))
        cols.append(np.tile(b * n + gk, ng))
        vals.append(w.Gd.ravel())
    size = b * n + ng
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(size, size))


def highest_frequency(disc) -> float:
    """The grid's highest axial frequency sqrt(b1 / rho) / h (rad/s; 1 / h when
    quasistatic): the scale of the linearisation's step rates and of a pencil's
    largest finite eigenvalues."""
    P, h = disc.params, float(np.min(disc.mesh.he))
    return math.sqrt(P.b1 / P.rho) / h if P.rho > 0 else 1.0 / h


def linearisation(disc, state):
    """(M, C, K) of the layout's semi-discrete model about its steady ``state`` (sparse,
    over (u, theta) of each unknown node, then the globals), with the scene's own damping
    (numerics.acceleration belongs to the pseudo scheme's path)."""
    sigma = highest_frequency(disc)  # s where s^2 rho h and b1 / h balance
    J = []
    for s in (sigma, 2.0 * sigma, 3.0 * sigma):
        w, _ = _assembled(disc, state, s)
        J.append(jacobian_matrix(w, disc.closed))
    second = (J[2] - 2.0 * J[1] + J[0]) / 2.0
    first = J[1] - J[0] - 3.0 * second
    zero = ROUND_OFF * abs(J[2]).max(axis=1).toarray().ravel()
    return tuple(_clean(part / scale, zero / scale)
                 for part, scale in ((second, sigma * sigma), (first, sigma),
                                     (J[0] - first - second, 1.0)))


def _assembled(disc, state, s):
    """The kernel's workspace assembled about the steady ``state`` at step rate s (the
    primal form, the scene's own damping, an exact law's stuck nodes with their penalty
    slope), and the model's parameters it took."""
    P = disc.params
    # the primal form: the Jacobian is then the residual's whole derivative
    p = disc.model._replace(damping=P.damping, dual=0)
    old = state._replace(ud=np.zeros_like(state.ud), td=np.zeros_like(state.td),
                         gd=np.zeros_like(state.gd))
    w = Workspace.allocate(disc.grid.n_elements, is_exact(p.law), disc.closed,
                           disc.n_globals)
    assemble(state.u.copy(), state.theta.copy(), state.lam.copy(), state.g.copy(),
             np.zeros_like(state.u), old, s, 0.0, disc.mesh, p, disc.steady_drive(),
             disc.loads, w, True)
    if is_exact(p.law):
        c = state.g[0] if disc.closed else p.speed
        add_stick_penalty(w, s, p.friction_scale, c, disc.mesh, p)
    return w, p


def driver_forcing(disc, state) -> np.ndarray:
    """-dR/d(omega_d): the linearised loop's forcing per unit of the driver's speed
    (rad/s), over the unknowns of :func:`linearisation` (a perturbation omega_d + delta
    e^{i w t} drives (-w^2 M + i w C + K) z = f delta).

    The driver's speed enters only the slip velocity of its arc's nodes, as -r_d omega_d:
    a node's force F_j = -k_j v_rel,j (k_j its friction slope: a regularised law's, or an
    exact law's stuck node's penalty, as the linearisation has them) gives its axial row
    -k_j r_d and its rotation row, times the lever of its face.
    """
    if not disc.closed:
        raise ValueError("driver_forcing: a closed drive's (an open layout has no driver)")
    w, p = _assembled(disc, state, 1.0)
    mesh, P = disc.mesh, disc.params
    n, b = w.Db.shape[0], w.Db.shape[1]
    out = np.zeros(b * n + disc.n_globals)
    r = P.pulleys[P.driver].radius
    driver_segment = int(np.flatnonzero(disc.speed_global < 0)[0])
    for j in mesh.cn:
        if mesh.seg[j] != driver_segment:
            continue
        k = mesh.wf[j] * w.bs[j] * w.sg[j] / p.regularisation
        out[b * j] = k * r
        out[b * j + 1] = p.half_height * mesh.face[j] * k * r
    return out


def _clean(A, zero) -> sp.csr_matrix:
    """A without the entries below its rows' round-off ``zero`` (a loop's globals have
    no mass: their rows and columns of M must be empty, not 1e-19)."""
    A = sp.coo_matrix(A)
    keep = np.abs(A.data) > zero[A.row]
    return sp.csr_matrix((A.data[keep], (A.row[keep], A.col[keep])), shape=A.shape)
