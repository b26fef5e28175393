"""The closed drive's discrete model once more, vectorised: the reference that
:func:`beltsim.beltdrive.model.assemble` is checked against.

Written from the equations of :mod:`beltsim.beltdrive.model`'s docstring, over all nodes
at once: numpy with ``np.roll`` for the periodic neighbours
(``np.roll(v, 1)[j] = v[j - 1]``) for the residual, and scipy.sparse operators for the
Jacobian, composed block by block in the unknowns' field order (u, theta, lam, c,
omega2) and then moved to the kernel's interleaved layout
(:class:`beltsim.beltdrive.discrete.Layout`). The two share the grid, the coefficients
and the layout, not the algebra.

The discrete equations, with the local rates u_t = a0 u + hu, u_tt = a0 u_t + hv (theta
alike with ht, hw), c_t = a0 c + hc, omega2_t = a0 omega2 + h2 and the periodic
operators (D^- v)_j = v_j - v_{j-1}, (L v)_j = (v_{j+1} - v_j) / h_j - (v_j - v_{j-1}) /
h_{j-1} and (G v)_j = sw_j . (v_{j-2}, v_{j-1}, v_j)::

    axial    rho hb (c_t + u_tt + d u_t) + 2 rho c D^- u_t - B L u - F = 0
    bending  I hb (theta_tt + d theta_t) + 2 I c D^- theta_t - A L theta + b2 hb theta
             - l F = 0
    ratio    the friction law's equation in lam and s = v_rel / v_s at each contact node
    gauge    sum(hb u) / Lambda = 0
    pulley   J2 omega2_t + M2 + R2 sum over the driven arc of F = 0

with F_j = -wf_j S_j lam_j, S_j = mu (N0 + b1 (G u)_j - rho c^2) / R_j (or p_ref for
perfect adhesion, mu = 0) and v_rel = c (1 + N0 / b1) + u_b,t + c G u_b - omega_i R_i,
u_b = u + l theta.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from ..physics.friction import ADHESION, EXACT, LAW_CODES, law_inverse_numpy
from .discrete import Layout, layout_of
from .model import DRIVE_LAWS, LoopMesh, LoopParams, Rates

_DRIVE_CODES = tuple(LAW_CODES[name] for name in DRIVE_LAWS)


class Fields(NamedTuple):
    """The unknowns of a state split by field, with their rates."""

    u: np.ndarray
    theta: np.ndarray
    lam: np.ndarray  # the contact nodes' friction ratios, in the order of contact_nodes
    c: float
    omega2: float
    ut: np.ndarray  # u_t
    tt: np.ndarray  # theta_t
    utt: np.ndarray
    ttt: np.ndarray
    ct: float
    omega2t: float


def contact_nodes(mesh: LoopMesh) -> np.ndarray:
    """The node of each friction ratio, in the ratios' order (lidx)."""
    j = np.flatnonzero(mesh.lidx >= 0)
    return j[np.argsort(mesh.lidx[j])]


def fields(y, rates: Rates, mesh: LoopMesh) -> Fields:
    """The state's fields and their rates (a0 y + history)."""
    lay = layout_of(mesh)
    if np.shape(y) != (lay.size,):
        raise ValueError(f"y: must have 2 N + M + 2 = {lay.size} entries for this grid, "
                         f"got shape {np.shape(y)}")
    u, th = lay.u(y), lay.theta(y)
    a0 = rates.a0
    ut, tt = a0 * u + rates.hu, a0 * th + rates.ht
    return Fields(u, th, lay.lam(y), float(y[lay.c]), float(y[lay.omega2]), ut, tt,
                  a0 * ut + rates.hv, a0 * tt + rates.hw, a0 * y[lay.c] + rates.hc,
                  a0 * y[lay.omega2] + rates.h2)


def derivative(v, mesh: LoopMesh) -> np.ndarray:
    """d/dx v at every node by the upwind three-point stencil over j - 2, j - 1, j."""
    sw = mesh.sw
    return sw[:, 0] * np.roll(v, 2) + sw[:, 1] * np.roll(v, 1) + sw[:, 2] * v


def laplacian(v, mesh: LoopMesh) -> np.ndarray:
    """(v_{j+1} - v_j) / h_j - (v_j - v_{j-1}) / h_{j-1}: hb times d2v/dx2."""
    he = mesh.he
    return (np.roll(v, -1) - v) / he - (v - np.roll(v, 1)) / np.roll(he, 1)


def slip_velocity(y, rates: Rates, rim1, mesh: LoopMesh, p: LoopParams) -> np.ndarray:
    """v_rel at the contact nodes: c (1 + N0 / b1) + D u_b / Dt - omega_i R_i."""
    f = fields(y, rates, mesh)
    j = contact_nodes(mesh)
    ub = f.u + p.lever * f.theta
    ubt = f.ut + p.lever * f.tt
    rim = np.where(mesh.arc[j] == 1, f.omega2 * p.R2, rim1)
    return f.c * (1.0 + p.N0 / p.b1) + ubt[j] + f.c * derivative(ub, mesh)[j] - rim


def friction_scale(u, c, mesh: LoopMesh, p: LoopParams):
    """(S, dS/du_x, dS/dc) at the contact nodes: mu p = mu (N0 + b1 u_x - rho c^2) / R,
    or the constant p_ref for perfect adhesion (mu = 0)."""
    j = contact_nodes(mesh)
    if p.mu == 0.0:
        return np.full(j.size, p.p_ref), np.zeros(j.size), np.zeros(j.size)
    R = mesh.radius[j]
    N = p.N0 + p.b1 * derivative(u, mesh)[j]
    return p.mu * (N - p.rho * c * c) / R, p.mu * p.b1 / R, -2.0 * p.mu * p.rho * c / R


def ratio_equation(lam, s, law: int):
    """(r, dr/dlam, dr/ds): the friction law's equation in the ratio lam and s = v_rel / v_s.

    Exact Coulomb: lam - proj(lam + s) onto [-1, 1] (= -s where abs(lam + s) < 1); adhesion:
    -s; a regularised law lam = g(s): s - g^{-1}(lam).
    """
    if law not in _DRIVE_CODES:
        raise ValueError(f"params.law: must be one of the drive's laws {DRIVE_LAWS} "
                         f"(codes {_DRIVE_CODES}), got {law!r}")
    one, zero = np.ones_like(s), np.zeros_like(s)
    if law == ADHESION:
        return -s, zero, -one
    if law == EXACT:
        z = lam + s
        stick = np.abs(z) < 1.0
        return (np.where(stick, -s, lam - np.sign(z)), np.where(stick, 0.0, 1.0),
                np.where(stick, -1.0, 0.0))
    gi, dgi = law_inverse_numpy(law, lam)
    return s - gi, -dgi, one


def nodal_friction(y, rates: Rates, mesh: LoopMesh, p: LoopParams) -> np.ndarray:
    """F at every node (N; zero on the spans): -wf S lam on the contact nodes."""
    f = fields(y, rates, mesh)
    j = contact_nodes(mesh)
    F = np.zeros(len(mesh.x))
    F[j] = -mesh.wf[j] * friction_scale(f.u, f.c, mesh, p)[0] * f.lam
    return F


def _order(lay: Layout) -> np.ndarray:
    """The position in y of each unknown in the field order (u, theta, lam, c, omega2)."""
    nodes = np.arange(lay.N)
    return np.concatenate([2 * nodes, 2 * nodes + 1, 2 * lay.N + np.arange(lay.M),
                           [lay.c, lay.omega2]])


def residual(y, rates: Rates, rim1, load, mesh: LoopMesh, p: LoopParams,
             q=None) -> np.ndarray:
    """The residual of :func:`beltsim.beltdrive.model.assemble` (the kernel's layout).

    rim1: the driver's rim speed omega1 R1; load: the load torque M2; q: distributed loads
    (2N: q_u, q_theta at each node), entering as hbar_j q (none by default).
    """
    lay = layout_of(mesh)
    f = fields(y, rates, mesh)
    hb = mesh.hb
    B = p.b1 - p.rho * f.c**2
    A = p.a - p.I * f.c**2
    F = nodal_friction(y, rates, mesh, p)
    axial = (p.rho * hb * (f.ct + f.utt + p.damping * f.ut)
             + 2.0 * p.rho * f.c * (f.ut - np.roll(f.ut, 1)) - B * laplacian(f.u, mesh) - F)
    bending = (p.I * hb * (f.ttt + p.damping * f.tt)
               + 2.0 * p.I * f.c * (f.tt - np.roll(f.tt, 1)) - A * laplacian(f.theta, mesh)
               + p.b2 * hb * f.theta - p.lever * F)
    s = slip_velocity(y, rates, rim1, mesh, p) / p.v_scale
    ratio = ratio_equation(f.lam, s, p.law)[0]
    if q is not None:
        axial = axial - hb * q[0::2]
        bending = bending - hb * q[1::2]
    gauge = np.sum(hb * f.u) / np.sum(hb)
    pulley = p.J2 * f.omega2t + load + p.R2 * np.sum(F[mesh.arc == 1])
    out = np.empty(lay.size)
    out[_order(lay)] = np.concatenate([axial, bending, ratio, [gauge, pulley]])
    return out


def _operators(mesh: LoopMesh):
    """(I, D^-, L, G, E) as sparse matrices: identity, backward difference, Laplacian,
    the contact nodes' stencil derivative (M x N) and the contact nodes' scatter (N x M)."""
    N = len(mesh.x)
    nodes = np.arange(N)
    eye = sp.identity(N, format="csr")
    back = sp.csr_matrix((np.ones(N), (nodes, (nodes - 1) % N)), shape=(N, N))  # v_{j-1}
    hm = np.roll(mesh.he, 1)
    lap = sp.diags(1.0 / mesh.he) @ (back.T - eye) - sp.diags(1.0 / hm) @ (eye - back)
    j = contact_nodes(mesh)
    sw = mesh.sw
    grad = (sp.diags(sw[:, 0]) @ back @ back + sp.diags(sw[:, 1]) @ back
            + sp.diags(sw[:, 2]))
    scatter = sp.csr_matrix((np.ones(j.size), (j, np.arange(j.size))), shape=(N, j.size))
    return eye, eye - back, lap.tocsr(), (scatter.T @ grad).tocsr(), scatter


def _col(v) -> sp.csr_matrix:
    return sp.csr_matrix(np.reshape(v, (-1, 1)))


def _row(v) -> sp.csr_matrix:
    return sp.csr_matrix(np.reshape(v, (1, -1)))


def jacobian(y, rates: Rates, rim1, load, mesh: LoopMesh, p: LoopParams) -> sp.csr_matrix:
    """d residual / dy (CSR, the kernel's layout), composed from sparse blocks."""
    lay = layout_of(mesh)
    f = fields(y, rates, mesh)
    a0, hb, lev = rates.a0, mesh.hb, p.lever
    _, dback, lap, grad, scatter = _operators(mesh)
    j = contact_nodes(mesh)
    c = f.c
    B = p.b1 - p.rho * c * c
    A = p.a - p.I * c * c
    # the nodal friction F = -E (wf S lam) and its derivatives
    S, dS_dux, dS_dc = friction_scale(f.u, c, mesh, p)
    wf = mesh.wf[j]
    dF_du = -(scatter @ sp.diags(wf * f.lam * dS_dux) @ grad)
    dF_dlam = -(scatter @ sp.diags(wf * S))
    dF_dc = -(scatter @ (wf * f.lam * dS_dc))
    driven = (mesh.arc == 1).astype(float)

    # the rates' slopes d u_t / du = a0, d u_tt / du = a0^2; dB/dc = -2 rho c (A alike)
    uu = (sp.diags(p.rho * hb * (a0 * a0 + p.damping * a0)) + 2.0 * p.rho * c * a0 * dback
          - B * lap - dF_du)
    uc = (p.rho * hb * a0 + 2.0 * p.rho * (dback @ f.ut) + 2.0 * p.rho * c * (lap @ f.u)
          - dF_dc)
    tt = (sp.diags(p.I * hb * (a0 * a0 + p.damping * a0) + p.b2 * hb)
          + 2.0 * p.I * c * a0 * dback - A * lap)
    tc = 2.0 * p.I * (dback @ f.tt) + 2.0 * p.I * c * (lap @ f.theta) - lev * dF_dc

    # the ratios' equations through v_rel and lam
    s = slip_velocity(y, rates, rim1, mesh, p) / p.v_scale
    _, r_lam, r_s = ratio_equation(f.lam, s, p.law)
    dv = sp.diags(r_s / p.v_scale)
    dvrel_du = a0 * scatter.T + c * grad  # d v_rel / d u_b
    dvrel_dc = 1.0 + p.N0 / p.b1 + grad @ (f.u + lev * f.theta)
    dvrel_dw = -p.R2 * driven[j]

    blocks = [
        [uu, None, -dF_dlam, _col(uc), None],
        [-lev * dF_du, tt, -lev * dF_dlam, _col(tc), None],
        [dv @ dvrel_du, lev * (dv @ dvrel_du), sp.diags(r_lam), _col(dv @ dvrel_dc),
         _col(dv @ dvrel_dw)],
        [_row(hb / np.sum(hb)), None, None, None, None],
        [_row(p.R2 * (driven @ dF_du)), None, _row(p.R2 * (driven @ dF_dlam)),
         _col(p.R2 * (driven @ dF_dc)), _col(p.J2 * a0)],
    ]
    Jf = sp.bmat(blocks, format="coo")
    order = _order(lay)
    return sp.csr_matrix((Jf.data, (order[Jf.row], order[Jf.col])), shape=(lay.size,) * 2)
