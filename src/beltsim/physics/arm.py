"""A tensioner's arm in the loop model: the two globals of its angle beta (from the
grid's reference) and its rate, the stretch its angle puts on the two spans at its
pulley, and its equation (the geometry and the derivation: :mod:`beltsim.beltdrive.arm`).

Turning the arm by beta lengthens span a (arriving at the pulley) by delta_a(beta) and
span b (leaving it) by delta_b(beta). The grid keeps its nodes, and each span's elements
but its last two carry the stretch as a strain e = delta / l (``Mesh.arm_el``; l their
length): an element's axial flux is B (u_x + e), so the belt's strain u_x + e stays
continuous where the grid is stretched, and the friction stencils of the next arc, which
reach two elements back, never see e. The globals' rows::

    beta' - omega = 0
    J omega' + d omega - tau0 + k_t (turn + beta) + (T_a - rho c^2) delta_a'
                                                   + (T_b - rho c^2) delta_b' = 0

with T_a the axial force of span a's last element (at the pulley's entry) and T_b that
of span b's first.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.polynomial.chebyshev import chebval

# Mesh.arm_par's entries
STIFFNESS, PRELOAD, DAMPING, TURN, LO, HI, LENGTH_A, LENGTH_B = range(8)
# ArmTable.coef's rows: delta_a, delta_b, their first and second derivatives
DELTA, SLOPE, CURVATURE = 0, 2, 4


@njit(cache=True)
def chebyshev(coef, row, x):
    """Row ``row`` of the Chebyshev series ``coef`` at x in [-1, 1] (Clenshaw)."""
    b1 = 0.0
    b2 = 0.0
    for k in range(coef.shape[1] - 1, 0, -1):
        b1, b2 = 2.0 * x * b1 - b2 + coef[row, k], b1
    return x * b1 - b2 + coef[row, 0]


@njit(cache=True)
def chebyshev_values(beta, coef, par):
    """:func:`arm_values` of the Mesh's arm_coef and arm_par."""
    x = (2.0 * beta - par[LO] - par[HI]) / (par[HI] - par[LO])
    out = np.empty((3, 2))
    for r in range(3):
        for s in range(2):
            out[r, s] = chebyshev(coef, 2 * r + s, x)
    return out[0], out[1], out[2]


@njit(cache=True)
def arm_values(beta, mesh):
    """(delta, slope, curvature): arrays (2) of delta_a, delta_b and their first and
    second derivatives at beta (rad from the reference)."""
    return chebyshev_values(beta, mesh.arm_coef, mesh.arm_par)


@njit(cache=True, inline="always")
def stretch(j, delta, slope, mesh):
    """(e, de/dbeta): element j's stretch strain from :func:`arm_values`' delta and slope
    (0, 0 off the stretched elements)."""
    s = mesh.arm_el[j]
    if s < 0:
        return 0.0, 0.0
    ln = mesh.arm_par[LENGTH_A] if s == 0 else mesh.arm_par[LENGTH_B]
    return delta[s] / ln, slope[s] / ln


@njit(cache=True, no_cpython_wrapper=True)
def span_tensions(u, delta, slope, mesh, p):
    """(T_a, T_b, de_a, de_b): the axial forces of span a's last element and span b's
    first, and those elements' stretch slopes in the angle."""
    ia, jb = mesh.arm_idx[1], mesh.arm_idx[2]
    n = u.shape[0]
    ia1 = ia + 1 if ia + 1 < n else 0
    jb1 = jb + 1 if jb + 1 < n else 0
    ea, dea = stretch(ia, delta, slope, mesh)
    eb, deb = stretch(jb, delta, slope, mesh)
    return (p.N0 + p.b1 * ((u[ia1] - u[ia]) / mesh.he[ia] + ea),
            p.N0 + p.b1 * ((u[jb1] - u[jb]) / mesh.he[jb] + eb), dea, deb)


@njit(cache=True, inline="always")
def arm_torque(beta, omega, ta, tb, slope, mesh):
    """The torque on the arm but its inertia's: the spring's tau0 - k_t (turn + beta),
    the damper's -d omega and the belt's -(ta delta_a' + tb delta_b') (ta, tb: the two
    spans' tensions less rho c^2)."""
    par = mesh.arm_par
    return (par[PRELOAD] - par[STIFFNESS] * (par[TURN] + beta) - par[DAMPING] * omega
            - ta * slope[0] - tb * slope[1])


@njit(cache=True, no_cpython_wrapper=True)
def arm_stretch(bd, g, arm_idx, arm_coef, arm_par):
    """(delta, slope) of :func:`arm_values` at the arm's angle in the globals g; zeros
    without an arm (``arm_*``: the Mesh's).

    ``bd`` is the workspace's border: None on an open layout's, which has no arm; its
    type prunes the body, so an open layout compiles none of the arm's kernels. (The
    mesh's arrays, not the mesh: a kernel's compile grows with the arrays its arguments
    hold.)
    """
    if bd is None:
        return np.zeros(2), np.zeros(2)
    if arm_idx.shape[0] == 0:
        return np.zeros(2), np.zeros(2)
    delta, slope, _ = chebyshev_values(g[arm_idx[0]], arm_coef, arm_par)
    return delta, slope


@njit(cache=True, no_cpython_wrapper=True)
def arm_rows(u, g, mesh, p, w, bd, want_jac):
    """Add the arm's two global rows (their rates excepted: assemble's, through
    ``mesh.inertia``) and their slopes (``bd`` as in :func:`arm_stretch`)."""
    if bd is None:
        return
    ib, ia, jb = mesh.arm_idx[0], mesh.arm_idx[1], mesh.arm_idx[2]
    iw = ib + 1
    par = mesh.arm_par
    n = u.shape[0]
    he = mesh.he
    beta, omega = g[ib], g[iw]
    c = g[0]
    rc = p.mass * c * c
    delta, slope, curv = arm_values(beta, mesh)
    ia1 = ia + 1 if ia + 1 < n else 0
    jb1 = jb + 1 if jb + 1 < n else 0
    Ta, Tb, dea, deb = span_tensions(u, delta, slope, mesh, p)
    w.Rg[ib] -= omega
    w.Rg[iw] -= arm_torque(beta, omega, Ta - rc, Tb - rc, slope, mesh)
    if not want_jac:
        return
    w.Gd[ib, iw] -= 1.0
    w.Gd[iw, iw] += par[DAMPING]
    w.Gd[iw, ib] += (par[STIFFNESS] + (Ta - rc) * curv[0] + (Tb - rc) * curv[1]
                     + p.b1 * (dea * slope[0] + deb * slope[1]))
    w.Gd[iw, 0] -= 2.0 * p.mass * c * (slope[0] + slope[1])
    ka = p.b1 * slope[0] / he[ia]
    kb = p.b1 * slope[1] / he[jb]
    w.Gr[iw, ia1, 0] += ka
    w.Gr[iw, ia, 0] -= ka
    w.Gr[iw, jb1, 0] += kb
    w.Gr[iw, jb, 0] -= kb


def table_values(beta, mesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`arm_values` in numpy, for Python callers (the kernels' arrays stay in
    numba: a compiled function's array returned to Python after a run in the same process
    can fail in numba's runtime)."""
    par = mesh.arm_par
    x = (2.0 * float(beta) - par[LO] - par[HI]) / (par[HI] - par[LO])
    rows = chebval(x, mesh.arm_coef.T)
    return rows[0:2], rows[2:4], rows[4:6]


def element_stretches(mesh, g, slope: bool = False) -> np.ndarray:
    """Each element's stretch strain e (N) at the globals ``g``, or with ``slope`` its
    derivative in the arm's angle (zeros without an arm)."""
    e = np.zeros(len(mesh.he))
    if mesh.arm_idx.shape[0] == 0:
        return e
    values = table_values(g[mesh.arm_idx[0]], mesh)[1 if slope else 0]
    ln = mesh.arm_par[[LENGTH_A, LENGTH_B]]
    on = mesh.arm_el >= 0
    e[on] = values[mesh.arm_el[on]] / ln[mesh.arm_el[on]]
    return e


def stencil_stretch(mesh, g) -> np.ndarray:
    """What the stretch adds to the three-point strain stencil ``mesh.sw`` at each node:
    sw_2 h_{j-1} e_{j-1} + (sw_1 + sw_2) h_{j-2} e_{j-2} (the stencil reads the
    differences of u over elements j - 1 and j - 2)."""
    if mesh.arm_idx.shape[0] == 0:  # no arm: zeros, without the rolls (read every check)
        return np.zeros(len(mesh.he))
    e = element_stretches(mesh, g)
    sw, he = mesh.sw, mesh.he
    e1, h1 = np.roll(e, 1), np.roll(he, 1)
    e2, h2 = np.roll(e, 2), np.roll(he, 2)
    return sw[:, 2] * h1 * e1 + (sw[:, 1] + sw[:, 2]) * h2 * e2
