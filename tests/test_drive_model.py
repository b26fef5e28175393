"""The one discrete model on a closed layout: the numba kernel
(:func:`beltsim.physics.model.assemble`, a loop's rows, global rows and blocks) against
the vectorised reference (:func:`beltsim.physics.reference.loop_residual`), its Jacobian
against central differences of the reference's residual, and the loop's balances on a
non-uniform grid.

Comparisons are made in the units of each row's terms: row i's scale T_i is the largest
change of the row for a typical change of one unknown (max_k |J_ik| m_k, m_k the random
state's magnitude of unknown k) or the row's value, whichever is larger. The random
old states are of the size of a time step's, so T_i is the size of the row's largest
term, and round-off is ~1e-16 of it.
"""

import numpy as np
import pytest

from beltsim.beltdrive.scene import DriveScene
from beltsim.physics import reference
from beltsim.physics.discrete import CENTRAL, UPWIND, Loads, State
from beltsim.physics.layout import LoopGrid
from beltsim.physics.model import assemble
from beltsim.problem.drive import Drive, Profile
from beltsim.solvers import LoopDiscretisation
from beltsim.solvers.newton import Workspace
from helpers import scene_path

pytestmark = pytest.mark.unit

#: elements on the loop (about 60 nodes, 26 of them in contact)
ELEMENTS = 60
#: a time step's 1 / dt (dt = 2e-4 s, about a thousandth of the belt's transit time)
INV_DT = 1.0 / 2e-4
#: the kernel's agreement with the reference in the rows' term units: the same terms
#: summed in another order agree to round-off, ~1e-16 of a row's largest term; 1e-12
#: leaves room for the cancellation of terms up to 1e4 times the row's result
TOL = 1e-12
LAWS = ("tanh", "sqrt", "exact", "adhesion")


def _disc(law, model="beam", inertia=True, gyro="upwind", grid=None):
    scene = DriveScene.load(scene_path("drive_flat"))
    if law == "adhesion":
        data = scene.to_dict()
        data["contact"] = {"friction": "stick"}
        scene = DriveScene.from_dict(data)
    over = {"physics.model": model, "physics.inertia": inertia,
            "numerics.elements": ELEMENTS, "numerics.gyroscopic": gyro}
    if law in ("tanh", "sqrt"):
        # half the creep speed: the random slip velocities reach the saturated part
        over.update({"numerics.friction_law": law, "numerics.regularisation": 0.03})
    d = LoopDiscretisation(scene.with_overrides(over), grid)
    # the primal form: the kernel's Jacobian is then the residual's whole derivative
    d.model = d.model._replace(dual=0)
    return d


def _state(d, seed, step):
    """(u, theta, lam, g, old, inv_dt, m): a random trial state, a previous step (or the
    steady problem's) and the magnitudes m of (u, theta, g)."""
    rng = np.random.default_rng(seed)
    P = d.params
    N = len(d.mesh.hb)
    strain = P.N0 / P.b1
    rim = P.omega1 * P.geometry.R1
    # u: a strain of strain / 2 over an element keeps the pressure positive
    mu_, mt = 0.25 * strain * float(np.min(d.mesh.he)), strain
    mg = np.array([rim, rim / P.geometry.R2])
    u, th = mu_ * rng.uniform(-1, 1, N), mt * rng.uniform(-1, 1, N)
    g = np.array([rim / (1.0 + strain) * (1.0 + 1e-3 * rng.uniform(-1, 1)),
                  mg[1] * (1.0 + 1e-2 * rng.uniform(-1, 1))])
    lam = np.where(d.mesh.seg >= 0, 2.0 * rng.uniform(-1, 1, N), 0.0)
    inv_dt = INV_DT if step else 0.0
    old = State(u - mu_ * rng.uniform(-1, 1, N), th - mt * rng.uniform(-1, 1, N),
                np.zeros(N), INV_DT * mu_ * rng.uniform(-1, 1, N),
                INV_DT * mt * rng.uniform(-1, 1, N), np.zeros(N),
                g * (1.0 - 1e-3 * rng.uniform(-1, 1, 2)), np.zeros(2))
    return u, th, lam, g, old, inv_dt, (mu_, mt, mg)


DRIVE = Drive(Profile.constant(12.1), Profile.constant(0.9), Profile.constant(40.0))


def _kernel(d, u, th, lam, g, old, inv_dt, loads=None):
    N = len(d.mesh.hb)
    w = Workspace.allocate(N, False, True, 2)
    f = np.zeros(N)
    assemble(u.copy(), th.copy(), lam.copy(), g.copy(), f, old, inv_dt, 0.3, d.mesh, d.model,
             DRIVE, loads or Loads.none(N), w, True)
    return w, f


def _dense(w):
    n, ng = w.Db.shape[0], w.Gd.shape[0]
    J = np.zeros((2 * n + ng, 2 * n + ng))
    for i in range(n):
        for band, o in ((w.L2, -2), (w.Lb, -1), (w.Db, 0), (w.Ub, 1)):
            q = (i + o) % n
            J[2 * i:2 * i + 2, 2 * q:2 * q + 2] += band[i]
        J[2 * i:2 * i + 2, 2 * n:] = w.Gc[i]
        J[2 * n:, 2 * i:2 * i + 2] = w.Gr[:, i, :]
    J[2 * n:, 2 * n:] = w.Gd
    return J


def _reference(d, u, th, lam, g, old, inv_dt, loads=None):
    R, Rg, F = reference.loop_residual(u, th, lam, g, old, inv_dt, 0.3, d.mesh, d.model,
                                       DRIVE, loads)
    return np.concatenate([R.ravel(), Rg]), F


def _reference_jacobian(d, u, th, lam, g, old, inv_dt, m):
    """Central differences of the reference's residual (steps 1e-7 of each unknown's
    magnitude)."""
    N = len(u)
    x0 = np.concatenate([np.column_stack([u, th]).ravel(), g])
    scale = np.concatenate([np.tile([m[0], m[1]], N), m[2]])
    J = np.zeros((len(x0), len(x0)))
    for k in range(len(x0)):
        h = 1e-7 * scale[k]
        xp, xm = x0.copy(), x0.copy()
        xp[k] += h
        xm[k] -= h
        rp = _reference(d, xp[0:2 * N:2], xp[1:2 * N:2], lam, xp[2 * N:], old, inv_dt)[0]
        rm = _reference(d, xm[0:2 * N:2], xm[1:2 * N:2], lam, xm[2 * N:], old, inv_dt)[0]
        J[:, k] = (rp - rm) / (2 * h)
    return J, scale


@pytest.mark.parametrize("law", LAWS)
@pytest.mark.parametrize("step", [False, True])
@pytest.mark.parametrize("model", ["beam", "string"])
@pytest.mark.parametrize("gyro", ["upwind", "central"])
def test_kernel_residual_is_the_references(law, step, model, gyro):
    d = _disc(law, model, gyro=gyro)
    u, th, lam, g, old, inv_dt, _ = _state(d, 7, step)
    w, f = _kernel(d, u, th, lam, g, old, inv_dt)
    want, F = _reference(d, u, th, lam, g, old, inv_dt)
    got = np.concatenate([w.R.ravel(), w.Rg])
    # the rows' term scale: the residual's size, or its change for a typical change of
    # an unknown (the elastic and inertia terms' slopes set it; friction's too where the
    # law is regularised)
    mu_, mt, mg = _state(d, 7, step)[6]
    m = np.concatenate([np.tile([mu_, mt], len(u)), mg])
    T = np.maximum(np.max(np.abs(_dense(w)) * m, axis=1), np.abs(want))
    assert np.max(np.abs(got - want) / T) < TOL
    np.testing.assert_allclose(f, F, rtol=0, atol=1e-13 * np.abs(F).max())
    assert np.abs(w.Rg[1]) > 0 and np.any(F != 0)


@pytest.mark.parametrize("law", ["tanh", "sqrt"])
@pytest.mark.parametrize("step", [False, True])
@pytest.mark.parametrize("model", ["beam", "string"])
def test_kernel_jacobian_is_the_derivative_of_the_references_residual(law, step, model):
    """The kernel's blocks, global columns and rows, against central differences of the
    reference (truncation and round-off ~1e-7 of a row's terms)."""
    d = _disc(law, model)
    u, th, lam, g, old, inv_dt, m = _state(d, 3, step)
    w, _ = _kernel(d, u, th, lam, g, old, inv_dt)
    J = _dense(w)
    J_ref, scale = _reference_jacobian(d, u, th, lam, g, old, inv_dt, m)
    T = np.max(np.abs(J_ref) * scale, axis=1)
    assert np.max(np.abs(J - J_ref) * scale / T[:, None]) < 1e-6
    # both the pressure's and the speeds' slopes are there
    assert np.abs(w.Gc[:, :, 0]).max() > 0 and np.abs(w.Gc[:, :, 1]).max() > 0


def test_the_comparison_detects_a_coefficient_changed_by_1e_7():
    d = _disc("tanh")
    u, th, lam, g, old, inv_dt, m = _state(d, 5, True)
    want, _ = _reference(d, u, th, lam, g, old, inv_dt)
    d.model = d.model._replace(b1=d.model.b1 * (1 + 1e-7))
    w, _ = _kernel(d, u, th, lam, g, old, inv_dt)
    got = np.concatenate([w.R.ravel(), w.Rg])
    J_ref, scale = _reference_jacobian(d, u, th, lam, g, old, inv_dt, m)
    T = np.maximum(np.max(np.abs(J_ref) * scale, axis=1), np.abs(want))
    assert np.max(np.abs(got - want) / T) > 1e3 * TOL


def _jittered(d, seed):
    """The drive on a grid whose nodes inside each segment are moved by up to 30% of an
    element (the segments' ends stay nodes)."""
    rng = np.random.default_rng(seed)
    grid = d.grid
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
    d = _disc("exact", gyro="central")
    d = _disc("exact", gyro="central", grid=_jittered(d, 11))
    assert d.model.gyro == CENTRAL
    he = d.mesh.he
    assert np.ptp(he) > 0.2 * np.mean(he)
    u, th, lam, g, old, inv_dt, _ = _state(d, 12, True)
    if impl == "kernel":
        w, F = _kernel(d, u, th, lam, g, old, inv_dt)
        R = w.R
    else:
        R, _, F = reference.loop_residual(u, th, lam, g, old, inv_dt, 0.3, d.mesh, d.model,
                                          DRIVE)
    P = d.params
    ct = (g[0] - old.g[0]) * inv_dt
    ud = (u - old.u) * inv_dt
    want = (P.rho * P.geometry.loop_length * ct - np.sum(F)
            + P.rho * np.sum(d.mesh.hb * ((ud - old.ud) * inv_dt + P.damping * ud)))
    terms = np.sum(np.abs(R[:, 0])) + abs(want)
    assert abs(np.sum(R[:, 0]) - want) < 1e-12 * terms * len(u)
    assert np.median(np.abs(R[:, 0])) > 1e-3 * np.max(np.abs(R[:, 0]))
    assert UPWIND != CENTRAL


def test_gauge_row_is_the_mean_of_u():
    """The gauge row is the periodic trapezoidal mean of u on a non-uniform grid (a
    constant: itself), and no other unknown enters it."""
    d = _disc("tanh")
    d = _disc("tanh", grid=_jittered(d, 21))
    u, th, lam, g, old, inv_dt, _ = _state(d, 22, True)
    w, _ = _kernel(d, u, th, lam, g, old, inv_dt)
    L = d.params.geometry.loop_length
    mean = np.trapezoid(np.append(u, u[0]), np.append(d.grid.x, L)) / L
    assert w.Rg[0] == pytest.approx(mean, rel=1e-12, abs=1e-15 * np.abs(u).max())
    J = _dense(w)
    n = len(u)
    assert np.allclose(J[2 * n, 0:2 * n:2], d.mesh.hb / L, rtol=1e-14, atol=0.0)
    assert np.count_nonzero(J[2 * n]) == n
    w, _ = _kernel(d, np.full(n, 3.25e-4), th, lam, g, old, inv_dt)
    assert w.Rg[0] == pytest.approx(3.25e-4, rel=1e-14)
