"""numba kernels against their numpy twins and independent checks."""

import numpy as np
import pytest

from beltsim.friction import LAW_CODES, LINEAR, RAMP, SQRT, TANH, law, law_inverse, law_numpy
from beltsim.grid import make_grid
from beltsim.integrators import Workspace, newton
from beltsim.model import (I_DUAL, assemble, block_solve, blocks_to_dense, ramp, residual_numpy,
                           update_multipliers)
from beltsim.numerics import build_grid, pack, resolve, scales
from beltsim.scene import Scene

PAPER = "runs/paper_slip.toml"


def _setup(overrides=(), N=40):
    sc = Scene.load(PAPER).with_overrides([f"numerics.elements={N}", *overrides])
    num = resolve(sc)
    grid = build_grid(sc, num)
    prm, iprm = pack(sc.params, num, grid)
    return sc, num, grid, prm, iprm


def _random_state(grid, seed, amp=1e-3):
    rng = np.random.default_rng(seed)
    n = len(grid.x)
    arrs = [amp * rng.standard_normal(n) for _ in range(6)]
    for a in arrs:
        a[0] = a[-1] = 0.0
    return arrs


def _assemble(u, th, lam, old, inv_dt, t, grid, prm, iprm):
    N = grid.n_elements
    w = Workspace(N)
    assemble(u, th, lam, *old, inv_dt, t, grid.he, grid.hbar, prm, iprm, w.R, w.Lb, w.Db, w.Ub,
             w.fnode, w.rl, w.sg, True)
    return w


@pytest.mark.parametrize("law_name", ["tanh", "sqrt", "ramp"])
@pytest.mark.parametrize("inertia", [True, False])
def test_residual_matches_numpy_twin(law_name, inertia):
    sc, num, grid, prm, iprm = _setup([f"numerics.friction_law={law_name}",
                                       f"physics.inertia={str(inertia).lower()}"])
    iprm[I_DUAL] = 0
    u, th, uo, tho, udo, tdo = _random_state(grid, 1)
    lam = np.zeros_like(u)
    w = _assemble(u, th, lam, (uo, tho, udo, tdo), 1e4, 0.005, grid, prm, iprm)
    R, F = residual_numpy(u, th, uo, tho, udo, tdo, 1e4, 0.005, grid.he, grid.hbar, prm, iprm)
    np.testing.assert_allclose(w.R, R, rtol=1e-12, atol=1e-9 * np.abs(R).max())
    np.testing.assert_allclose(w.fnode, F, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("law_name", ["tanh", "sqrt"])
def test_dual_residual_equals_primal_when_multiplier_consistent(law_name):
    """With lam = g(v_rel/v_reg) the condensed (dual) residual is the primal one."""
    sc, num, grid, prm, iprm = _setup([f"numerics.friction_law={law_name}"])
    u, th, uo, tho, udo, tdo = _random_state(grid, 2, amp=1e-6)
    iprm[I_DUAL] = 0
    lam = np.zeros_like(u)
    wp = _assemble(u, th, lam, (uo, tho, udo, tdo), 1e4, 1.0, grid, prm, iprm)
    iprm[I_DUAL] = 1
    lam_d = np.clip(lam, -0.999, 0.999)  # keep inside the dual's domain
    keep = np.abs(lam) < 0.999
    wd = _assemble(u, th, lam_d, (uo, tho, udo, tdo), 1e4, 1.0, grid, prm, iprm)
    rows = keep[1:-1]
    np.testing.assert_allclose(wd.R[rows], wp.R[rows], rtol=1e-7,
                               atol=1e-7 * np.abs(wp.R).max())


@pytest.mark.parametrize("law_name", ["tanh", "sqrt", "ramp"])
@pytest.mark.parametrize("inv_dt", [0.0, 3e3])
def test_jacobian_matches_finite_differences(law_name, inv_dt):
    sc, num, grid, prm, iprm = _setup([f"numerics.friction_law={law_name}",
                                       "numerics.regularisation=0.05"])
    iprm[I_DUAL] = 0
    u, th, uo, tho, udo, tdo = _random_state(grid, 3, amp=1e-4)
    lam = np.zeros_like(u)
    w = _assemble(u, th, lam, (uo, tho, udo, tdo), inv_dt, 1.0, grid, prm, iprm)
    J = blocks_to_dense(w.Lb, w.Db, w.Ub)
    n = grid.n_elements - 1
    Jfd = np.zeros_like(J)
    y = np.column_stack([u[1:-1], th[1:-1]]).ravel()
    for k in range(2 * n):
        # central differences: truncation O(step^2 g''') is far below the 1e-5 tolerance
        step = 1e-9
        res = []
        for sgn in (1, -1):
            yy = y.copy()
            yy[k] += sgn * step
            uu, tt = u.copy(), th.copy()
            uu[1:-1], tt[1:-1] = yy[0::2], yy[1::2]
            res.append(residual_numpy(uu, tt, uo, tho, udo, tdo, inv_dt, 1.0, grid.he,
                                      grid.hbar, prm, iprm)[0].ravel())
        Jfd[:, k] = (res[0] - res[1]) / (2 * step)
    scale = np.abs(J).max(axis=1, keepdims=True)
    np.testing.assert_allclose(J / scale, Jfd / scale, atol=1e-5)


def test_block_solve_matches_dense():
    rng = np.random.default_rng(4)
    n = 30
    Lb, Db, Ub = (rng.standard_normal((n, 2, 2)) for _ in range(3))
    Db += 6 * np.eye(2)  # diagonally dominant like the model's blocks
    r = rng.standard_normal((n, 2))
    x = np.zeros((n, 2))
    assert block_solve(Lb, Db, Ub, r, x, np.zeros((n, 2, 2)))
    ref = np.linalg.solve(blocks_to_dense(Lb, Db, Ub), r.ravel())
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
    sc, num, grid, prm, iprm = _setup(N=200)
    assert iprm[I_DUAL] == 1
    N = grid.n_elements
    w = Workspace(N)
    u, th, lam = np.zeros(N + 1), np.zeros(N + 1), np.zeros(N + 1)
    zeros = np.zeros(N + 1)
    sca = scales(sc.params)
    # a large step from rest at full surface speed: stick and slip nodes side by side
    ok = newton(u, th, lam, zeros, zeros, zeros, zeros, 1.0 / 2e-3, 1.0, grid.he, grid.hbar,
                prm, iprm, sca, 1e-11, 60, w.R, w.Lb, w.Db, w.Ub, w.C, w.dx, w.u_try,
                w.th_try, w.fnode, w.rl, w.sg, w.stats)
    assert ok
    iprm[I_DUAL] = 0
    R, F = residual_numpy(u, th, zeros, zeros, zeros, zeros, 1.0 / 2e-3, 1.0, grid.he,
                          grid.hbar, prm, iprm)
    # forces per node are O(f* h) ~ 1e2 N; round-off of the 1e-11 Newton tolerance
    assert np.abs(R[:, 0]).max() < 1e-6 * sca[0]
    np.testing.assert_allclose(w.fnode, F, atol=1e-9 * sc.params.fstar * grid.he.max())
    sliding = np.abs(lam[grid.j1 + 1:grid.j2 + 1]) > 0.99
    assert sliding.sum() >= 2 and (~sliding).sum() >= 2


def test_update_multipliers_stays_inside_and_follows_linearisation():
    sc, num, grid, prm, iprm = _setup(N=20)
    lam = np.zeros(len(grid.x))
    lam[grid.j1 + 1:grid.j2 + 1] = 0.5
    rl = np.zeros_like(lam)
    sg = np.ones_like(lam) * 0.75
    dx = np.zeros((grid.n_elements - 1, 2))
    # a huge push towards +1: the 99% fraction-to-boundary rule applies
    rl[grid.j1 + 1:grid.j2 + 1] = 100.0
    big = update_multipliers(lam, dx, 0.0, grid.he, prm, iprm, rl, sg)
    contact = slice(grid.j1 + 1, grid.j2 + 1)
    np.testing.assert_allclose(lam[contact], 0.5 + 0.99 * 0.5)
    assert big == pytest.approx(0.495)
    # a small push: the linearised update sg * rl
    lam[contact] = 0.0
    rl[contact] = 0.1
    update_multipliers(lam, dx, 0.0, grid.he, prm, iprm, rl, sg)
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


def test_law_codes_cover_scene_choices():
    from beltsim.scene import SCHEMA
    assert set(SCHEMA["numerics"]["friction_law"].choices) <= set(LAW_CODES)
