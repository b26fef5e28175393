"""numba kernels against the vectorised reference (physics.reference) and independent checks."""

import numpy as np
import pytest

from beltsim.physics import reference
from beltsim.physics.discrete import CENTRAL, UPWIND, State, hermite_weights, load_at
from beltsim.physics.friction import (
    EXACT,
    LAW_CODES,
    LINEAR,
    RAMP,
    SQRT,
    TANH,
    law,
    law_inverse,
    law_numpy,
)
from beltsim.physics.grid import bisect, make_grid
from beltsim.physics.model import (
    POWER_TERMS,
    add_stick_penalty,
    assemble,
    power_terms,
    rate_part,
)
from beltsim.problem.drive import friction_factor, ramp
from beltsim.problem.scene import Scene
from beltsim.solvers import Discretisation
from beltsim.solvers.dual import update_multipliers
from beltsim.solvers.newton import (
    NewtonSettings,
    Workspace,
    block_factor,
    block_substitute,
    newton,
)
from helpers import (
    LAWS,
    LAYOUTS,
    dense_jacobian,
    kernel_case,
    kernel_residual,
    random_loads,
    reference_derivative,
    reference_residual,
    row_terms,
    scene_path,
    straight_state,
)

pytestmark = pytest.mark.unit


def _setup(overrides=(), N=40, dual=0):
    sc = Scene.load(scene_path("paper_slip")).with_overrides([f"numerics.elements={N}",
                                                              *overrides])
    d = Discretisation(sc)
    return d, d.grid, d.model._replace(dual=dual)


def _assemble(d, u, th, lam, old, inv_dt, t, p, loads=None):
    w = Workspace.allocate(d.grid.n_elements)
    fnode = np.zeros_like(u)
    assemble(u, th, lam, np.zeros(0), fnode, old, inv_dt, t, d.mesh, p, d.drive,
             d.loads if loads is None else loads, w, True)
    return w, fnode


# -- the kernel against the reference, on both layouts ----------------------------------
# A case is (layout, law, step, gyro, inertia, loads, model): helpers.kernel_case. Every
# law in its primal form (the kernels' primal-dual form is checked against it below).

#: the kernel's agreement with the reference in the units of each row's terms
#: (helpers.row_terms): the same terms summed in another order agree to round-off,
#: ~1e-16 of a row's largest term; 1e-12 leaves room for the cancellation of terms up to
#: 1e4 times the row's result
TOL = 1e-12

#: The straight belt's cases: every law, with and without inertia and loads, and the
#: skew (central) gyroscopic form.
STRAIGHT_CASES = [(law, step, gyro, inertia, loads, "beam")
                  for law in LAWS for step in (False, True)
                  for inertia, loads, gyro in ((True, True, "upwind"),
                                               (True, False, "upwind"),
                                               (False, True, "upwind"),
                                               (True, False, "central"))]

#: The loop's cases: its laws, the beam and the string, both gyroscopic forms.
LOOP_CASES = [(law, step, gyro, True, False, model)
              for law in ("tanh", "sqrt", "exact", "adhesion") for step in (False, True)
              for model in ("beam", "string") for gyro in ("upwind", "central")]


def _params(layout, cases):
    """pytest parameters (layout, *case), named after what they set."""
    def name(law, step, gyro, inertia, loads, model):
        return "-".join([layout, law, "step" if step else "steady", gyro,
                         "inertia" if inertia else "quasistatic",
                         *(["loads"] if loads else []), model])
    return [pytest.param(layout, *case, id=name(*case)) for case in cases]


CASE = "layout, law, step, gyro, inertia, loads, model"


@pytest.mark.parametrize(CASE, _params("straight", STRAIGHT_CASES)
                         + _params("loop", LOOP_CASES) + _params("serpentine", LOOP_CASES)
                         + _params("tensioner", LOOP_CASES))
def test_kernel_residual_is_the_references(layout, law, step, gyro, inertia, loads, model):
    """assemble's residual (the rows', and a loop's global rows) and nodal friction forces
    are the reference's, to TOL of each row's terms."""
    case = kernel_case(layout, law, step, 7, gyro, inertia, loads, model)
    w, got, F = kernel_residual(case)
    want, F_ref = reference_residual(case)
    T = row_terms(case, dense_jacobian(w, layout != "straight"), want)
    assert np.max(np.abs(got - want) / T) < TOL
    np.testing.assert_allclose(F, F_ref, rtol=0, atol=1e-13 * np.abs(F_ref).max())
    # friction and the global rows are exercised: contact nodes away from saturation (for
    # the exact law, stuck and sliding ones side by side)
    sg = w.sg[case.mesh.cn]
    assert np.count_nonzero(sg > 0.1 * sg.max()) >= 5
    assert law != "exact" or np.count_nonzero(sg == 0.0) >= 3
    assert np.all(w.Rg != 0.0)


@pytest.mark.parametrize(CASE, _params("straight", STRAIGHT_CASES))
def test_kernel_jacobian_is_the_references_sparse_jacobian(layout, law, step, gyro, inertia,
                                                           loads, model):
    """On the straight belt the reference has a sparse Jacobian of its own (its
    linearisation, which the stability analysis reads): assemble's blocks (exact laws with
    their stick penalty) are it, rows in units of their largest entry, to 1e-12. (The
    loop's reference is its residual only: the next test checks the loop's blocks.)"""
    case = kernel_case(layout, law, step, 7, gyro, inertia, loads, model)
    w, _, _ = kernel_residual(case)
    p, ratios = case.p, None
    if p.law >= EXACT:
        add_stick_penalty(w, case.inv_dt, p.friction_scale * friction_factor(case.drive, case.t),
                          p.speed, case.mesh, p)
        ratios = case.lam
    J = reference.jacobian(case.u, case.th, case.old, case.inv_dt, case.t, case.mesh, p,
                           case.drive, ratios).toarray()
    scale = np.abs(J).max(axis=1, keepdims=True)
    np.testing.assert_allclose(dense_jacobian(w) / scale, J / scale, rtol=0, atol=1e-12)


@pytest.mark.parametrize(CASE, _params("straight", [
    (law, step, "upwind", True, True, "beam") for law in ("linear", "tanh", "sqrt", "ramp")
    for step in (False, True)]) + [p for layout in ("loop", "serpentine", "tensioner")
                                   for p in _params(
        layout, [(law, step, "upwind", True, False, model) for law in ("tanh", "sqrt")
                 for step in (False, True) for model in ("beam", "string")])])
def test_kernel_jacobian_is_the_derivative_of_the_references_residual(layout, law, step, gyro,
                                                                      inertia, loads, model):
    """assemble's blocks (and a loop's global columns, rows and block) against central
    differences of the reference's residual (helpers.reference_derivative: truncation and
    round-off ~1e-7 of a row's terms), at states whose slip velocities lie on the steep
    part of the law."""
    case = kernel_case(layout, law, step, 3, gyro, inertia, loads, model)
    w, _, _ = kernel_residual(case)
    J = dense_jacobian(w, layout != "straight")
    J_ref = reference_derivative(case)
    T = np.max(np.abs(J_ref) * case.m, axis=1)
    assert np.max(np.abs(J - J_ref) * case.m / T[:, None]) < 1e-6
    # on a loop, both the pressure's and the speeds' slopes are there (and the arm's
    # angle's, through its spans' stretch: its rate enters its own rows only)
    cols = np.abs(w.Gc).max(axis=(0, 1), initial=0.0)
    if case.mesh.arm_idx.shape[0]:
        cols = np.delete(cols, case.mesh.arm_idx[0] + 1)
    assert np.all(cols > 0)


@pytest.mark.parametrize("layout", LAYOUTS)
def test_the_comparison_detects_a_coefficient_changed_by_1e_7(layout):
    """The residual test's measure sees a tension stiffness changed by 1e-7 (on a loop b1,
    from which its B = b1 - rho c^2 follows the speed c) at 1e3 times its tolerance."""
    case = kernel_case(layout, "tanh", True, 5)
    want, _ = reference_residual(case)
    name = "B" if layout == "straight" else "b1"
    stiffer = case._replace(p=case.p._replace(**{name: getattr(case.p, name) * (1 + 1e-7)}))
    _, got, _ = kernel_residual(stiffer)
    T = row_terms(case, reference_derivative(case), want)
    assert np.max(np.abs(got - want) / T) > 1e3 * TOL


def test_hermite_loads_interpolate_cubics_exactly():
    """Cubic Hermite interpolation is exact for a cubic in time, and held outside."""
    times = np.array([0.0, 0.3, 1.0])
    q = lambda t: 2.0 - t + 3.0 * t**2 - 1.5 * t**3  # noqa: E731
    dq = lambda t: -1.0 + 6.0 * t - 4.5 * t**2  # noqa: E731
    table = np.array([[q(t)] for t in times]), np.array([[dq(t)] for t in times])
    for t in (0.0, 0.1, 0.3, 0.77, 1.0):
        k, *wts = hermite_weights(times, t)
        got = load_at(table[0], table[1], k, *wts, 0)
        assert got == pytest.approx(q(t), rel=1e-13)
    k, *wts = hermite_weights(times, 5.0)
    assert load_at(table[0], table[1], k, *wts, 0) == pytest.approx(q(1.0), rel=1e-13)


@pytest.mark.parametrize("law_name", ["tanh", "sqrt"])
def test_dual_residual_equals_primal_when_multiplier_consistent(law_name):
    """With lam = g(v_rel/v_reg) the condensed (dual) residual is the primal one."""
    d, grid, p = _setup([f"numerics.friction_law={law_name}"])
    u, th, old = straight_state(len(grid.x), 2, 1e-6)
    lam = np.zeros_like(u)
    wp, _ = _assemble(d, u, th, lam, old, 1e4, 1.0, p)
    lam_d = np.clip(lam, -0.999, 0.999)  # keep inside the dual's domain
    keep = np.abs(lam) < 0.999
    wd, _ = _assemble(d, u, th, lam_d, old, 1e4, 1.0, p._replace(dual=1))
    rows = keep[1:-1]
    np.testing.assert_allclose(wd.R[rows], wp.R[rows], rtol=1e-7,
                               atol=1e-7 * np.abs(wp.R).max())


@pytest.mark.parametrize("gyro", [UPWIND, CENTRAL])
def test_rate_part_is_the_references_time_derivative_part(gyro):
    """The implicit scheme's error filter applies T = a0^2 M + a0 C (the Jacobian's terms
    in inv_dt = a0, friction at given slopes): the kernel rate_part against the
    reference's operators, with a load and friction nodes of all slopes."""
    d, grid, p = _setup()
    p = p._replace(gyro=gyro)
    n = grid.n_elements - 1
    rng = np.random.default_rng(11)
    e = rng.standard_normal((n, 2))
    sg = rng.uniform(0.0, 1.0, len(grid.x))
    a0, fs = 2.7e3, 0.8 * p.friction_scale
    out = np.empty_like(e)
    rate_part(e, np.zeros(0), a0, fs, sg, sg, p.speed, d.mesh, p, out, np.zeros(0))
    ops = reference.operators(d.mesh, p)
    j = reference.contact_nodes(d.mesh)
    k = d.mesh.wf[j] * fs * sg[j] / p.regularisation
    _, Cf = reference.friction_matrices(k, reference.friction_pattern(d.mesh, p), n)
    want = a0 * a0 * ops.mass * e.ravel() + a0 * ((ops.damping + Cf) @ e.ravel())
    np.testing.assert_allclose(out.ravel(), want, rtol=1e-13, atol=1e-13 * np.abs(want).max())


@pytest.mark.parametrize("gyro", [UPWIND, CENTRAL])
def test_power_terms_match_the_reference(gyro):
    d, grid, p = _setup()
    p = p._replace(gyro=gyro)
    rng = np.random.default_rng(12)
    n_nodes = len(grid.x)
    state = State(*(1e-3 * rng.standard_normal(n_nodes) for _ in range(6)))
    for a in state[:6]:
        a[[0, -1]] = 0.0
    loads = random_loads(n_nodes, 12)
    out = np.zeros(len(POWER_TERMS))
    power_terms(state, 0.005, d.mesh, p, d.drive, loads, out)
    want = reference.power_terms(state, 0.005, d.mesh, p, d.drive, loads)
    np.testing.assert_allclose(out, want, rtol=1e-12, atol=1e-14 * np.abs(want).max())
    if gyro == CENTRAL:  # the skew form does no work: round-off of sums of ~1e-3 terms
        assert abs(out[POWER_TERMS.index("gyroscopic")]) < 1e-12 * np.abs(want).max()


def test_block_factor_matches_dense_on_a_tridiagonal_system():
    """Newton's block LU without the second lower band (a stick or quasistatic row)."""
    rng = np.random.default_rng(4)
    n = 30
    w = Workspace.allocate(n + 1)
    Lb, Db, Ub = w.Lb, w.Db, w.Ub
    for a in (Lb, Db, Ub):
        a[:] = rng.standard_normal((n, 2, 2))
    w.L2[:] = 0.0
    Db += 6 * np.eye(2)  # diagonally dominant like the model's blocks
    r = rng.standard_normal((n, 2))
    x = np.zeros((n, 2))
    assert block_factor(Lb, Db, Ub, w)
    block_substitute(w, r, x)
    ref = np.linalg.solve(dense_jacobian(w), r.ravel())  # w.L2 = 0
    np.testing.assert_allclose(x.ravel(), ref, rtol=1e-10, atol=1e-12)


def test_banded_block_factor_matches_dense():
    """Newton's block LU with the second lower band (the friction stencil's j - 2)."""
    rng = np.random.default_rng(5)
    n = 30
    w = Workspace.allocate(n + 1)
    for a in (w.Lb, w.L2, w.Db, w.Ub):
        a[:] = rng.standard_normal((n, 2, 2))
    w.Db[:] += 8 * np.eye(2)
    r = rng.standard_normal((n, 2))
    x = np.zeros((n, 2))
    assert block_factor(w.Lb, w.Db, w.Ub, w)
    block_substitute(w, r, x)
    ref = np.linalg.solve(dense_jacobian(w), r.ravel())
    np.testing.assert_allclose(x.ravel(), ref, rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("code", [LINEAR, TANH, SQRT, RAMP])
def test_law_matches_numpy_twin_and_derivative(code):
    s = np.linspace(-4, 4, 161) + 0.013
    g, gp = law_numpy(code, s)
    for si, gi, gpi in zip(s, g, gp):
        a, b = law(code, si)
        assert a == pytest.approx(gi, abs=1e-15) and b == pytest.approx(gpi, abs=1e-15)
    h = 1e-6
    fd = (law_numpy(code, s + h)[0] - law_numpy(code, s - h)[0]) / (2 * h)
    np.testing.assert_allclose(gp, fd, atol=1e-8)
    if code != LINEAR:
        assert np.all(np.abs(g) <= 1.0) and np.all(np.diff(g) >= 0)


@pytest.mark.parametrize("code", [LINEAR, TANH, SQRT])
def test_law_inverse_inverts_law(code):
    for lam in np.linspace(-0.999, 0.999, 41):
        s, ds = law_inverse(code, lam)
        g, gp = law(code, s)
        assert g == pytest.approx(lam, abs=1e-12)
        assert ds == pytest.approx(1.0 / gp, rel=1e-9)


def test_dual_newton_solution_satisfies_primal_equations():
    """Independent check of the condensed solve and update_multipliers: the converged
    state of a hard implicit step satisfies the primal residual of the numpy twin."""
    d, grid, _ = _setup(N=200)
    p = d.model
    assert p.dual == 1
    w = Workspace.allocate(grid.n_elements)
    state, rest = d.new_state(), d.new_state()
    # a large step from rest at full surface speed: stick and slip nodes side by side
    ok = newton(state, rest, 1.0 / 2e-3, 1.0, d.mesh, p, d.drive, d.loads, d.scales,
                NewtonSettings(1e-11, 60), w)
    assert ok
    R, F = reference.residual(state.u, state.theta, rest, 1.0 / 2e-3, 1.0, d.mesh,
                              p._replace(dual=0), d.drive)
    # forces per node are O(f* h) ~ 1e2 N; round-off of the 1e-11 Newton tolerance
    assert np.abs(R[:, 0]).max() < 1e-6 * d.scales.force
    np.testing.assert_allclose(state.fnode, F, atol=1e-9 * d.params.fstar * grid.he.max())
    lam = state.lam
    sliding = np.abs(lam[d.mesh.c0:grid.j2 + 1]) > 0.99
    assert sliding.sum() >= 2 and (~sliding).sum() >= 2


def test_update_multipliers_stays_inside_and_follows_linearisation():
    d, grid, p = _setup(N=20, dual=1)
    w = Workspace.allocate(grid.n_elements)
    lam = np.zeros(len(grid.x))
    contact = slice(d.mesh.c0, grid.j2 + 1)
    lam[contact] = 0.5
    rl, sg = w.rl, w.sg
    sg[:] = 0.75
    dx = np.zeros((grid.n_elements - 1, 2))
    # a huge push towards +1: the 99% fraction-to-boundary rule applies
    rl[contact] = 100.0
    big = update_multipliers(lam, dx, np.zeros(0), 0.0, p.speed, d.mesh, p, w)
    np.testing.assert_allclose(lam[contact], 0.5 + 0.99 * 0.5)
    assert big == pytest.approx(0.495)
    # a small push: the linearised update sg * rl
    lam[contact] = 0.0
    rl[contact] = 0.1
    update_multipliers(lam, dx, np.zeros(0), 0.0, p.speed, d.mesh, p, w)
    np.testing.assert_allclose(lam[contact], 0.075)


def test_update_multipliers_takes_the_law_near_the_bound():
    """A ratio the dual update leaves near the bound takes the law at its linearised slip
    velocity when that lies on its side of zero, nearer zero; else the dual update."""
    d, grid, p = _setup(N=20, dual=1)
    assert p.law == TANH
    w = Workspace.allocate(grid.n_elements)
    lam = np.zeros(len(grid.x))
    contact = slice(d.mesh.c0, grid.j2 + 1)
    dx = np.zeros((grid.n_elements - 1, 2))
    start = 0.99999
    dual_slope = 1.0 - start**2
    for s, expected in ((1.0, np.tanh(1.0)),  # slowed down: the law
                        (-1.0, None),  # turned round: the dual update
                        (20.0, None)):  # deeper in slip: the dual update
        lam[contact] = start
        w.sg[contact] = dual_slope
        w.rl[contact] = s - np.arctanh(start)
        dual = start + dual_slope * (s - np.arctanh(start))
        dual = min(dual, start + 0.99 * (1.0 - start))
        big = update_multipliers(lam, dx, np.zeros(0), 0.0, p.speed, d.mesh, p, w)
        want = dual if expected is None else expected
        np.testing.assert_allclose(lam[contact], want, rtol=1e-12)
        assert big == pytest.approx(abs(want - start), rel=1e-9)


def test_ramp_is_smooth_and_monotone():
    ts = np.linspace(-0.1, 1.2, 500)
    r = np.array([ramp(t, 1.0) for t in ts])
    assert r[0] == 0.0 and r[-1] == 1.0 and np.all(np.diff(r) >= 0)
    assert ramp(0.5, 1.0) == pytest.approx(0.5)
    assert ramp(0.3, 0.0) == 1.0


@pytest.mark.parametrize("grading", [1.0, 4.0, 20.0])
def test_grid_has_nodes_at_contact_ends(grading):
    g = make_grid(1.0, 1 / 3, 2 / 3, 300, grading)
    assert g.n_elements == 300
    assert g.x[g.j1] == 1 / 3 and g.x[g.j2] == 2 / 3
    assert g.x[0] == 0.0 and g.x[-1] == 1.0 and np.all(np.diff(g.x) > 0)
    he = g.he
    # smallest element next to x2; size ratio about the grading (piecewise rounding)
    if grading > 1:
        assert np.argmin(he) in (g.j2 - 1, g.j2)
    assert he.max() / he.min() == pytest.approx(grading, rel=0.1)
    np.testing.assert_allclose(g.hbar.sum(), 1.0)


@pytest.mark.parametrize("grading", [1.0, 5.0])
def test_grid_has_a_node_at_an_inner_refinement_point(grading):
    """The expected slip start inside the contact is a node, kept by bisection; one
    within two elements of x2 is only graded towards (no sliver elements)."""
    x_star = 0.634134
    g = make_grid(1.0, 1 / 3, 2 / 3, 600, grading, refine_at=(x_star,))
    assert g.n_elements == 600 and np.all(np.diff(g.x) > 0)
    assert g.x[g.j1] == 1 / 3 and g.x[g.j2] == 2 / 3
    k = int(np.argmin(np.abs(g.x - x_star)))
    assert g.x[k] == x_star and g.j1 < k < g.j2
    he = g.he  # the anchor does not disturb the grading: neighbours within 10%
    assert he[k] / he[k - 1] == pytest.approx(1.0, rel=0.1)
    assert np.isin(x_star, bisect(g).x)
    h_min = make_grid(1.0, 1 / 3, 2 / 3, 600, grading).h_min
    near = 2 / 3 - 1.5 * h_min  # 1.5 smallest elements from x2
    g2 = make_grid(1.0, 1 / 3, 2 / 3, 600, grading, refine_at=(near,))
    assert not np.isin(near, g2.x) and g2.h_min > 0.9 * h_min


def test_law_codes_cover_scene_choices():
    from beltsim.problem.scene import SCHEMA
    assert set(SCHEMA["numerics"]["friction_law"].choices) <= set(LAW_CODES)


def test_bounds_checked_kernels_keep_their_own_cache():
    """A bounds-checked session must not fill the source tree's numba cache (conftest):
    ordinary runs would load its slower kernels."""
    import os

    import numba

    if os.environ.get("NUMBA_BOUNDSCHECK", "0") in ("", "0"):
        pytest.skip("only a bounds-checked session caches apart")
    assert numba.config.BOUNDSCHECK
    assert numba.config.CACHE_DIR and "beltsim-numba-boundscheck" in numba.config.CACHE_DIR
