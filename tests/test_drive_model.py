"""The closed drive's discrete model: the numba kernel (beltdrive.model.assemble) against
its vectorised reference (beltdrive.reference), the reference's Jacobian against central
differences of its residual, and the loop's balances on a non-uniform grid.

Comparisons are made in the units of each row's terms: row i's scale T_i is the largest
change of the row for a typical change of one unknown (max_k |J_ik| m_k, m_k the random
state's magnitude of unknown k) or the row's value, whichever is larger, and Jacobian
entry (i, k) is compared as J_ik m_k / T_i. The random histories are of the size a0 y,
so T_i is the size of the row's largest term, and round-off is ~1e-16 of it.
"""

import math

import numpy as np
import pytest

from beltsim.beltdrive import reference
from beltsim.beltdrive.discrete import creep_speed, layout_of, loop_mesh, loop_params
from beltsim.beltdrive.model import DRIVE_LAWS, LoopParams, Rates
from beltsim.beltdrive.scene import DriveScene
from beltsim.beltdrive.solver import make_system, steady_rates
from beltsim.physics.friction import LAW_CODES
from helpers import scene_path

#: elements on the loop (about 60 nodes, 26 of them in contact)
ELEMENTS = 60
#: a regularised law's v_reg in units of the creep speed: the random slip velocities
#: (s up to ~20) reach the saturated part of tanh and sqrt
REGULARISATION = 0.5
#: BDF2's a0 = 1.5 / dt at dt = 2e-4 s (about a thousandth of the belt's transit time)
A0 = 1.5 / 2e-4
#: the exact law's lam + s is kept this far from the kink |lam + s| = 1
KINK_MARGIN = 0.2


def _drive(law, model="beam", inertia=True, elements=ELEMENTS):
    """(DriveParams, LoopMesh, LoopParams) of drive_flat with a law, a model and inertia."""
    scene = DriveScene.load(scene_path("drive_flat"))
    if law == "adhesion":
        data = scene.to_dict()
        data["contact"] = {"friction": "stick"}
        scene = DriveScene.from_dict(data)
    scene = scene.with_overrides([("physics.model", model), ("physics.inertia", inertia)])
    P = scene.params
    reg = REGULARISATION * creep_speed(P) if law in ("tanh", "sqrt") else None
    return P, loop_mesh(P.geometry, elements), loop_params(P, law, reg)


def _magnitudes(P, mesh):
    """Typical sizes of the unknowns (u, theta, lam, c, omega2) of the random states."""
    strain = P.N0 / P.b1
    rim = P.omega1 * P.geometry.R1
    # u: a strain of strain / 2 over an element keeps the pressure positive
    return (0.25 * strain * float(np.min(mesh.he)), strain, 1.0, rim, rim / P.geometry.R2)


def _state(P, mesh, params, step, seed, law):
    """(y, rates, m): a random state, steady rates or a time step's with random history
    arrays, and the magnitudes m of the unknowns."""
    rng = np.random.default_rng(seed)
    lay = layout_of(mesh)
    N, M = lay.N, lay.M
    mu, mt, ml, mc, mw = _magnitudes(P, mesh)
    y = np.zeros(lay.size)
    y[0:2 * N:2] = mu * rng.uniform(-1.0, 1.0, N)
    y[1:2 * N:2] = mt * rng.uniform(-1.0, 1.0, N)
    y[lay.c] = mc / (1.0 + P.N0 / P.b1) * (1.0 + 1e-3 * rng.uniform(-1.0, 1.0))
    y[lay.omega2] = mw * (1.0 + 1e-2 * rng.uniform(-1.0, 1.0))
    if step:
        rates = Rates(A0, *(A0 * m * rng.uniform(-1.0, 1.0, N)
                            for m in (mu, mt, A0 * mu, A0 * mt)),
                      A0 * mc * rng.uniform(-0.1, 0.1), A0 * mw * rng.uniform(-0.1, 0.1))
    else:
        rates = steady_rates(N)
    rim1 = P.omega1 * P.geometry.R1
    if law == "exact":
        # lam + s in stick (|.| < 1 - margin) at half the nodes, sliding at the others
        s = reference.slip_velocity(y, rates, rim1, mesh, params) / params.v_scale
        z = np.where(rng.uniform(size=M) < 0.5,
                     rng.uniform(-1.0 + KINK_MARGIN, 1.0 - KINK_MARGIN, M),
                     rng.choice([-1.0, 1.0], M) * rng.uniform(1.0 + KINK_MARGIN, 3.0, M))
        lam = z - s
    elif law == "adhesion":
        lam = 2.0 * rng.uniform(-1.0, 1.0, M)  # the reaction over p_ref: any size
    else:
        lam = 0.9 * rng.uniform(-1.0, 1.0, M)  # g^{-1}(lam) finite and smooth
    y[2 * N:2 * N + M] = lam
    m = np.empty(lay.size)
    m[0:2 * N:2], m[1:2 * N:2], m[2 * N:2 * N + M] = mu, mt, ml
    m[lay.c], m[lay.omega2] = mc, mw
    return y, rates, m


def _kernel(P, mesh, params, y, rates):
    """The kernel's (R, dense J) through the solver's System."""
    sys_ = make_system(mesh, params, layout_of(mesh), P)
    R, J = sys_.jacobian(y, rates, P.omega1 * P.geometry.R1, P.M2)
    return R, J.toarray()


def _reference(P, mesh, params, y, rates):
    args = (y, rates, P.omega1 * P.geometry.R1, P.M2, mesh, params)
    return reference.residual(*args), reference.jacobian(*args).toarray()


def _row_scale(R, J, m):
    """T_i: the size of row i's terms (see the module's docstring)."""
    return np.maximum(np.max(np.abs(J) * m, axis=1), np.abs(R))


def _mismatch(R, J, R_ref, J_ref, m):
    """The largest difference of (R, J) from (R_ref, J_ref) in the rows' term units."""
    T = _row_scale(R_ref, J_ref, m)
    dR = np.abs(R - R_ref) / T
    dJ = np.abs(J - J_ref) * m / T[:, None]
    return max(float(dR.max()), float(dJ.max()))


#: the kernel's agreement with the reference in the rows' term units: the same terms
#: summed in another order agree to round-off, ~1e-16 of a row's largest term; 1e-12
#: leaves room for the cancellation of terms up to 1e4 times the row's result
TOL = 1e-12

CASES = [(law, step, model, inertia) for law in DRIVE_LAWS for step in (False, True)
         for model in ("beam", "string") for inertia in (True, False)]


@pytest.mark.unit
@pytest.mark.parametrize("case", range(len(CASES)), ids=["-".join(map(str, c)) for c in CASES])
def test_kernel_is_the_reference(case):
    """assemble's residual and COO Jacobian are the reference's, to TOL. Every nonzero
    entry is at least 1e-7 of its row's scale on these states (measured: 1.6e-6), so TOL
    holds each entry to 1e-5 of its own size or better."""
    law, step, model, inertia = CASES[case]
    P, mesh, params = _drive(law, model, inertia)
    assert (params.lever > 0) == (model == "beam") and (params.rho > 0) == inertia
    y, rates, m = _state(P, mesh, params, step, seed=case, law=law)
    Rk, Jk = _kernel(P, mesh, params, y, rates)
    R, J = _reference(P, mesh, params, y, rates)
    assert _mismatch(Rk, Jk, R, J, m) < TOL
    scaled = np.abs(J) * m / _row_scale(R, J, m)[:, None]
    assert scaled[J != 0.0].min() > 1e-7
    # the same sparsity: no entry of one is a structural zero of the other's slot
    assert np.array_equal(Jk != 0.0, J != 0.0)


@pytest.mark.unit
@pytest.mark.parametrize("law", DRIVE_LAWS)
@pytest.mark.parametrize("step", [False, True])
@pytest.mark.parametrize("model", ["beam", "string"])
def test_reference_jacobian_is_the_derivative_of_its_residual(law, step, model):
    """Central differences with steps 1e-6 m_k: truncation ~1e-12 times the rows' third
    derivatives in scaled units (c enters quadratically, atanh at |lam| <= 0.9 has ~1e3)
    and round-off ~1e-16 / 1e-6; 1e-8 bounds both with room. lam + s stays 0.2 from the
    exact law's kink, which no step (ds < 1e-3) crosses."""
    P, mesh, params = _drive(law, model)
    y, rates, m = _state(P, mesh, params, step, seed=7, law=law)
    args = (rates, P.omega1 * P.geometry.R1, P.M2, mesh, params)
    R, J = reference.residual(y, *args), reference.jacobian(y, *args).toarray()
    fd = np.empty_like(J)
    for k in range(len(y)):
        dy = np.zeros_like(y)
        dy[k] = 1e-6 * m[k]
        fd[:, k] = (reference.residual(y + dy, *args)
                    - reference.residual(y - dy, *args)) / (2.0 * dy[k])
    assert _mismatch(R, fd, R, J, m) < 1e-8


FIELDS = [f for f in LoopParams._fields if f != "law"]


@pytest.mark.unit
@pytest.mark.parametrize("field", FIELDS)
def test_the_comparison_detects_a_coefficient_changed_by_1e_7(field):
    """The kernel given params with one coefficient 1e-7 larger (relative) than the
    reference's fails the comparison of test_kernel_is_the_reference. Each coefficient
    enters a time step of the beam with inertia and exact friction (p_ref: perfect
    adhesion); the damping's terms are the smallest (d a0 is 0.3% of a0^2 in the mass
    terms), and its change still shows as a mismatch of 5e-11, 50 times TOL."""
    law = "adhesion" if field == "p_ref" else "exact"
    P, mesh, params = _drive(law)
    y, rates, m = _state(P, mesh, params, True, seed=3, law=law)
    changed = params._replace(**{field: getattr(params, field) * (1.0 + 1e-7)})
    Rk, Jk = _kernel(P, mesh, changed, y, rates)
    R, J = _reference(P, mesh, params, y, rates)
    assert _mismatch(Rk, Jk, R, J, m) > 10 * TOL


@pytest.mark.unit
def test_the_comparison_detects_another_law():
    P, mesh, params = _drive("tanh")
    y, rates, m = _state(P, mesh, params, False, seed=4, law="tanh")
    Rk, Jk = _kernel(P, mesh, params._replace(law=LAW_CODES["sqrt"]), y, rates)
    R, J = _reference(P, mesh, params, y, rates)
    assert _mismatch(Rk, Jk, R, J, m) > 1e-3


@pytest.mark.unit
def test_reference_refuses_a_law_the_drive_does_not_know_and_a_y_of_another_grid():
    P, mesh, params = _drive("exact")
    y, rates, _ = _state(P, mesh, params, False, seed=5, law="exact")
    with pytest.raises(ValueError, match=r"^params.law: must be one of") as info:
        reference.residual(y, rates, 12.0, 0.0, mesh, params._replace(law=LAW_CODES["ramp"]))
    assert "\n" not in str(info.value)
    with pytest.raises(ValueError, match=r"^y: must have 2 N \+ M \+ 2 = \d+ entries"):
        reference.jacobian(y[:-1], rates, 12.0, 0.0, mesh, params)


def _jittered(mesh, loop_length, seed):
    """The grid with every node but the first moved by up to 30% of its smaller element,
    the derivative weights solved from exactness on 1, x, x^2 and random friction
    weights on the contact nodes."""
    rng = np.random.default_rng(seed)
    N = len(mesh.x)
    he = mesh.he
    room = 0.3 * np.minimum(he, np.roll(he, 1))
    x = mesh.x + np.where(np.arange(N) > 0, room * rng.uniform(-1.0, 1.0, N), 0.0)
    he = np.diff(np.append(x, loop_length))
    hb = 0.5 * (he + np.roll(he, 1))
    # offsets of x_{j-2}, x_{j-1} from x_j across the periodic seam
    d1 = -np.roll(he, 1)
    d2 = d1 - np.roll(he, 2)
    V = np.stack([np.stack([np.ones(N)] * 3, axis=1), np.stack([d2, d1, 0 * d1], axis=1),
                  np.stack([d2**2, d1**2, 0 * d1], axis=1)], axis=1)
    sw = np.ascontiguousarray(
        np.linalg.solve(V, np.tile([0.0, 1.0, 0.0], (N, 1))[..., None])[..., 0])
    wf = np.where(mesh.arc >= 0, hb * rng.uniform(0.5, 1.0, N), 0.0)
    return mesh._replace(x=x, he=he, hb=hb, sw=sw, wf=wf)


def _balance_state(P, mesh, params, seed):
    """A time step's random state whose u, u_t and u_tt have zero mean (the gauge and its
    rates), so that the mass terms of the axial rows add up to rho Lambda c_t."""
    y, rates, m = _state(P, mesh, params, True, seed, law="exact")
    lay = layout_of(mesh)
    w = mesh.hb / np.sum(mesh.hb)
    y[0:2 * lay.N:2] -= np.dot(w, lay.u(y))
    rates = rates._replace(hu=rates.hu - np.dot(w, rates.hu),
                           hv=rates.hv - np.dot(w, rates.hv))
    return y, rates, m


IMPLEMENTATIONS = {"kernel": _kernel, "reference": _reference}


@pytest.mark.unit
@pytest.mark.parametrize("impl", IMPLEMENTATIONS)
def test_axial_rows_add_up_to_the_loops_momentum_balance(impl):
    """On a non-uniform grid the elastic and gyroscopic fluxes cancel in the sum of the
    axial rows, which is rho Lambda c_t - sum F (F_j = -wf_j mu p_j lam_j, p_j from the
    stencil's u_x); round-off of the N rows' terms, 1e-12 of their sum."""
    P, mesh, params = _drive("exact")
    L = P.geometry.loop_length
    mesh = _jittered(mesh, L, seed=11)
    assert np.ptp(mesh.he) > 0.2 * np.mean(mesh.he)
    y, rates, m = _balance_state(P, mesh, params, seed=12)
    R, J = IMPLEMENTATIONS[impl](P, mesh, params, y, rates)
    lay = layout_of(mesh)
    u, lam, c = lay.u(y), lay.lam(y), y[lay.c]
    N = lay.N
    j = np.flatnonzero(mesh.lidx >= 0)
    assert np.array_equal(mesh.lidx[j], np.arange(lay.M))
    ux = sum(mesh.sw[j, o] * u[(j - 2 + o) % N] for o in range(3))
    p = (P.N0 + P.b1 * ux - P.rho * c * c) / mesh.radius[j]
    F = -mesh.wf[j] * P.mu * p * lam
    ct = A0 * c + rates.hc
    want = P.rho * L * ct - np.sum(F)
    T = _row_scale(*_reference(P, mesh, params, y, rates), m)
    axial = np.arange(0, 2 * N, 2)
    assert abs(np.sum(R[axial]) - want) < 1e-12 * np.sum(T[axial])
    # the balance is not the cancellation of small rows: the rows are of the terms' size
    assert np.median(np.abs(R[axial]) / T[axial]) > 0.1


@pytest.mark.unit
@pytest.mark.parametrize("impl", IMPLEMENTATIONS)
def test_gauge_row_is_the_mean_of_u(impl):
    """The gauge row is the periodic trapezoidal mean of u on a non-uniform grid (a
    constant: itself), and no other unknown enters it."""
    P, mesh, params = _drive("tanh")
    L = P.geometry.loop_length
    mesh = _jittered(mesh, L, seed=21)
    y, rates, _ = _state(P, mesh, params, True, seed=22, law="tanh")
    lay = layout_of(mesh)
    u = lay.u(y)
    R, J = IMPLEMENTATIONS[impl](P, mesh, params, y, rates)
    mean = np.trapezoid(np.append(u, u[0]), np.append(mesh.x, L)) / L
    assert R[lay.c] == pytest.approx(mean, rel=1e-12, abs=1e-15 * np.abs(u).max())
    assert np.allclose(J[lay.c, 0:2 * lay.N:2], mesh.hb / L, rtol=1e-14, atol=0.0)
    assert np.count_nonzero(J[lay.c]) == lay.N
    y[0:2 * lay.N:2] = 3.25e-4
    R, _ = IMPLEMENTATIONS[impl](P, mesh, params, y, rates)
    assert math.isclose(R[lay.c], 3.25e-4, rel_tol=1e-14)
