"""The one discrete model on a closed layout: the loop's own balances on a non-uniform
grid, in the numba kernel (:func:`beltsim.physics.model.assemble`) and in the vectorised
reference (:func:`beltsim.physics.reference.loop_residual`). The kernel's residual and
Jacobian against the reference's, on the loop as on the straight belt, are in
tests/test_kernels.py.
"""

import numpy as np
import pytest

from beltsim.physics import reference
from beltsim.physics.discrete import CENTRAL, UPWIND
from beltsim.physics.layout import LoopGrid
from helpers import dense_jacobian, kernel_case, kernel_residual

pytestmark = pytest.mark.unit


def _jittered(case, seed):
    """The drive on a grid whose nodes inside each segment are moved by up to 30% of an
    element (the segments' ends stay nodes)."""
    rng = np.random.default_rng(seed)
    grid = case.disc.grid
    x = grid.x.copy()
    he = grid.he
    inner = np.ones(len(x), bool)
    inner[grid.first[:-1]] = False
    x[inner] += 0.3 * he[inner] * rng.uniform(-1, 1, inner.sum())
    return LoopGrid(x, grid.loop_length, grid.first)


@pytest.mark.parametrize("impl", ["kernel", "reference"])
def test_axial_rows_add_up_to_the_loops_momentum_balance(impl):
    """With the skew (central) gyroscopic form, on a non-uniform grid, the elastic and
    gyroscopic fluxes cancel in the sum of the axial rows, which is rho Lambda c_t - sum F:
    round-off of the N rows' terms, 1e-12 of their sum. (The upwind form's weights
    2 c hbar_j / h_{j-1} sum to zero on uniform segments only.)"""
    case = kernel_case("loop", "exact", True, 12, gyro="central")
    case = kernel_case("loop", "exact", True, 12, gyro="central", grid=_jittered(case, 11))
    assert case.p.gyro == CENTRAL
    he = case.mesh.he
    assert np.ptp(he) > 0.2 * np.mean(he)
    u, g, old, inv_dt = case.u, case.g, case.old, case.inv_dt
    if impl == "kernel":
        w, _, F = kernel_residual(case)
        R = w.R
    else:
        R, _, F = reference.loop_residual(u, case.th, case.lam, g, old, inv_dt, case.t,
                                          case.mesh, case.p, case.drive)
    P = case.disc.params
    ct = (g[0] - old.g[0]) * inv_dt
    ud = (u - old.u) * inv_dt
    want = (P.rho * P.geometry.loop_length * ct - np.sum(F)
            + P.rho * np.sum(case.mesh.hb * ((ud - old.ud) * inv_dt + P.damping * ud)))
    terms = np.sum(np.abs(R[:, 0])) + abs(want)
    assert abs(np.sum(R[:, 0]) - want) < 1e-12 * terms * len(u)
    assert np.median(np.abs(R[:, 0])) > 1e-3 * np.max(np.abs(R[:, 0]))
    assert UPWIND != CENTRAL


def test_gauge_row_is_the_mean_of_u():
    """The gauge row is the periodic trapezoidal mean of u on a non-uniform grid (a
    constant: itself), and no other unknown enters it."""
    case = kernel_case("loop", "tanh", True, 22)
    case = kernel_case("loop", "tanh", True, 22, grid=_jittered(case, 21))
    u = case.u
    w, _, _ = kernel_residual(case)
    L = case.disc.params.geometry.loop_length
    mean = np.trapezoid(np.append(u, u[0]), np.append(case.disc.grid.x, L)) / L
    assert w.Rg[0] == pytest.approx(mean, rel=1e-12, abs=1e-15 * np.abs(u).max())
    J = dense_jacobian(w, closed=True)
    n = len(u)
    assert np.allclose(J[2 * n, 0:2 * n:2], case.mesh.hb / L, rtol=1e-14, atol=0.0)
    assert np.count_nonzero(J[2 * n]) == n
    w, _, _ = kernel_residual(case._replace(u=np.full(n, 3.25e-4)))
    assert w.Rg[0] == pytest.approx(3.25e-4, rel=1e-14)
