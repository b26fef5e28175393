"""numba kernels against the vectorised reference (physics.reference) and independent checks."""

import numpy as np
import pytest

from beltsim.physics import reference
from beltsim.physics.discrete import CENTRAL, UPWIND, Loads, State, hermite_weights, load_at
from beltsim.physics.friction import (
    ADHESION,
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
    blocks_to_dense,
    power_terms,
    rate_part,
    update_multipliers,
)
from beltsim.problem.drive import friction_factor, ramp
from beltsim.problem.scene import Scene
from beltsim.solvers import Discretisation
from beltsim.solvers.newton import (
    NewtonSettings,
    Workspace,
    block_factor,
    block_substitute,
    newton,
)
from helpers import scene_path

pytestmark = pytest.mark.unit


def _setup(overrides=(), N=40, dual=0):
    sc = Scene.load(scene_path("paper_slip")).with_overrides([f"numerics.elements={N}",
                                                              *overrides])
    d = Discretisation(sc)
    return d, d.grid, d.model._replace(dual=dual)


def _random_state(grid, seed, amp=1e-3):
    """Trial (u, theta) and a previous step (values and local velocities)."""
    rng = np.random.default_rng(seed)
    n = len(grid.x)
    arrs = [amp * rng.standard_normal(n) for _ in range(6)]
    for a in arrs:
        a[0] = a[-1] = 0.0
    u, th, uo, tho, udo, tdo = arrs
    zero = np.zeros(n)
    return u, th, State(uo, tho, zero.copy(), udo, tdo, zero.copy())


def _assemble(d, u, th, lam, old, inv_dt, t, p, loads=None):
    w = Workspace.allocate(d.grid.n_elements)
    fnode = np.zeros_like(u)
    assemble(u, th, lam, np.zeros(0), fnode, old, inv_dt, t, d.mesh, p, d.drive,
             d.loads if loads is None else loads, w, True)
    return w, fnode


def _random_loads(n, seed):
    rng = np.random.default_rng(seed)
    return Loads(np.array([0.0, 0.004, 0.01]),
                 *(1e3 * rng.standard_normal((3, n)) for _ in range(4)))


# Every law in its primal form (the kernels' primal-dual form is checked against it
# below); the regularisation is set so that the random slip velocities (~5 m/s) fall on
# the steep part of the saturating laws and the exact law's stick test goes both ways.
LAWS = {"linear": LINEAR, "tanh": TANH, "sqrt": SQRT, "ramp": RAMP, "exact": EXACT,
        "adhesion": ADHESION}


def _kernel_and_reference(code, inertia, inv_dt, loads, seed=1, gyro=UPWIND):
    """(kernel, reference, k) at a random state: residual, nodal friction and dense
    Jacobian of each, and the reference's friction stiffnesses."""
    d, grid, p = _setup([f"physics.inertia={str(inertia).lower()}"])
    p = p._replace(law=code, regularisation=5.0, gyro=gyro)
    u, th, old = _random_state(grid, seed, amp=1e-4)
    rng = np.random.default_rng(seed + 100)
    lam = 1.5 * rng.uniform(-1.0, 1.0, len(u))  # the exact laws' multipliers: stick and slip
    t = 0.005
    ld = _random_loads(len(u), seed + 7) if loads else Loads.none(len(u))
    w, fnode = _assemble(d, u, th, lam, old, inv_dt, t, p, ld)
    ratios = None
    if code >= EXACT:
        add_stick_penalty(w, inv_dt, p.friction_scale * friction_factor(d.drive, t), p.speed,
                          d.mesh, p)
        ratios = lam
    R, F = reference.residual(u, th, old, inv_dt, t, d.mesh, p, d.drive, ld, ratios)
    J = reference.jacobian(u, th, old, inv_dt, t, d.mesh, p, d.drive, ratios).toarray()
    vrel = reference.slip_velocity(u, th, (u - old.u) * inv_dt, (th - old.theta) * inv_dt, t,
                                   d.mesh, p, d.drive)
    k = reference.friction(vrel, t, d.mesh, p, d.drive, ratios)[1]
    return (w.R, fnode, blocks_to_dense(w.Lb, w.Db, w.Ub, w.L2)), (R, F, J), k


@pytest.mark.parametrize("law_name", list(LAWS))
@pytest.mark.parametrize("inv_dt", [0.0, 3e3])
@pytest.mark.parametrize("inertia, loads, gyro", [(True, True, UPWIND), (True, False, UPWIND),
                                                  (False, True, UPWIND),
                                                  (True, False, CENTRAL)])
def test_residual_and_jacobian_match_the_reference(law_name, inv_dt, inertia, loads, gyro):
    """assemble (primal form; exact laws with their stick penalty) is the reference's
    residual and sparse Jacobian, with either gyroscopic form: the same sums in another
    order, so they agree to round-off, ~1e-16 of the largest term of a row (1e-12 leaves
    room for the cancellation of terms up to 1e4 times the row's result)."""
    (Rk, Fk, Jk), (R, F, J), k = _kernel_and_reference(LAWS[law_name], inertia, inv_dt, loads,
                                                       gyro=gyro)
    np.testing.assert_allclose(Rk, R, rtol=0, atol=1e-12 * np.abs(R).max())
    np.testing.assert_allclose(Fk, F, rtol=0, atol=1e-13 * np.abs(F).max())
    scale = np.abs(J).max(axis=1, keepdims=True)  # rows in units of their largest entry
    np.testing.assert_allclose(Jk / scale, J / scale, rtol=0, atol=1e-12)
    # the friction's slopes are exercised: contact nodes away from saturation (for the
    # exact law, stuck and sliding ones side by side)
    assert np.count_nonzero(k > 0.1 * k.max()) >= 5
    assert law_name != "exact" or np.count_nonzero(k == 0.0) >= 3


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
    u, th, old = _random_state(grid, 2, amp=1e-6)
    lam = np.zeros_like(u)
    wp, _ = _assemble(d, u, th, lam, old, 1e4, 1.0, p)
    lam_d = np.clip(lam, -0.999, 0.999)  # keep inside the dual's domain
    keep = np.abs(lam) < 0.999
    wd, _ = _assemble(d, u, th, lam_d, old, 1e4, 1.0, p._replace(dual=1))
    rows = keep[1:-1]
    np.testing.assert_allclose(wd.R[rows], wp.R[rows], rtol=1e-7,
                               atol=1e-7 * np.abs(wp.R).max())


@pytest.mark.parametrize("law_name", ["linear", "tanh", "sqrt", "ramp"])
@pytest.mark.parametrize("inv_dt", [0.0, 3e3])
def test_reference_jacobian_is_the_derivative_of_its_residual(law_name, inv_dt):
    """The reference's sparse Jacobian against central differences of its residual (which
    the kernels match, test above), at a state whose slip velocities lie on the steep
    part of the law (v_reg 5 m/s against ~5 m/s)."""
    d, grid, p = _setup()
    p = p._replace(law=LAWS[law_name], regularisation=5.0)
    u, th, old = _random_state(grid, 3, amp=1e-4)
    loads = _random_loads(len(u), 3)
    J = reference.jacobian(u, th, old, inv_dt, 0.005, d.mesh, p, d.drive).toarray()
    n = grid.n_elements - 1
    Jfd = np.zeros_like(J)
    y = np.column_stack([u[1:-1], th[1:-1]]).ravel()
    for k in range(2 * n):
        # step 1e-9 against values ~1e-4: the truncation, O(step^2) of the law's third
        # derivative over the slip velocity's scale, and the round-off of R / step are
        # both below 1e-7 of a row's largest entry
        step = 1e-9
        res = []
        for sgn in (1, -1):
            yy = y.copy()
            yy[k] += sgn * step
            uu, tt = u.copy(), th.copy()
            uu[1:-1], tt[1:-1] = yy[0::2], yy[1::2]
            res.append(reference.residual(uu, tt, old, inv_dt, 0.005, d.mesh, p, d.drive,
                                          loads)[0].ravel())
        Jfd[:, k] = (res[0] - res[1]) / (2 * step)
    scale = np.abs(J).max(axis=1, keepdims=True)
    np.testing.assert_allclose(J / scale, Jfd / scale, rtol=0, atol=1e-6)


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
    loads = _random_loads(n_nodes, 12)
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
    ref = np.linalg.solve(blocks_to_dense(Lb, Db, Ub), r.ravel())
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
    ref = np.linalg.solve(blocks_to_dense(w.Lb, w.Db, w.Ub, w.L2), r.ravel())
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
