"""The one model on a closed layout: the loop's residual and Jacobian (global unknowns,
wrapped band, pressure bound) against finite differences, the bordered solves against
dense ones, and the loop's steady state against the deleted drive engine's."""

import numpy as np
import pytest

from beltsim.api import load_scene
from beltsim.physics.discrete import Loads, State
from beltsim.physics.friction import LAW_CODES
from beltsim.physics.layout import LoopGrid, loop_mesh, loop_params
from beltsim.physics.model import assemble
from beltsim.problem.drive import Drive, Profile, Profiles
from beltsim.solvers.newton import Workspace, factorise, linear_solve
from beltsim.solvers.ssn import saddle_solve, saddle_system
from helpers import dense_jacobian

pytestmark = pytest.mark.unit


def _loop(law="tanh", elements=40, overrides=()):
    P = load_scene("drive_flat", list(overrides)).params
    g = P.geometry
    mesh = loop_mesh(LoopGrid.build(g.lengths, elements), [(0, g.R1, -1), (2, g.R2, 1)],
                     [0.0 if P.mu is None else P.mu] * 2, (0.0, P.J2))
    prm = loop_params(a=P.a, b1=P.b1, b2=P.b2, rho=P.rho, I=P.I, lever=P.lever,
                      damping=P.damping, N0=P.N0, law=LAW_CODES[law], dual=0,
                      regularisation=0.05)
    return P, mesh, prm


def _random(P, mesh, seed=1):
    rng = np.random.default_rng(seed)
    N = len(mesh.hb)
    strain = P.N0 / P.b1
    u = 0.01 * strain * P.geometry.loop_length * rng.standard_normal(N)
    th = 0.1 * strain * rng.standard_normal(N)
    lam = np.where(mesh.seg >= 0, rng.uniform(-1.5, 1.5, N), 0.0)
    g = np.array([12.0, 70.0])
    old = State(u + 1e-3 * strain * rng.standard_normal(N), th.copy(), np.zeros(N),
                1e-3 * rng.standard_normal(N), 1e-3 * rng.standard_normal(N), np.zeros(N),
                g - np.array([0.01, 0.1]), np.zeros(2))
    return u, th, lam, g, old


DRIVE = Drive(Profile.constant(12.1), Profile.constant(1.0),
              Profiles.constants((0.0, 40.0)))
INV_DT = 50.0


def _fd(fun, x0, n_fields):
    """Central differences of fun at x0 (steps relative to each unknown's size)."""
    J = np.zeros((len(fun(x0)), len(x0)))
    for k in range(len(x0)):
        h = 1e-7 * max(abs(x0[k]), 1e-6 if k < n_fields else 1.0)
        xp, xm = x0.copy(), x0.copy()
        xp[k] += h
        xm[k] -= h
        J[:, k] = (fun(xp) - fun(xm)) / (2.0 * h)
    return J


def test_loop_jacobian_matches_finite_differences_and_the_bordered_solve_a_dense_one():
    P, mesh, prm = _loop("tanh")
    u, th, _, g, old = _random(P, mesh)
    N = len(mesh.hb)
    w = Workspace.allocate(N, False, True, 2)

    def res(x):
        lam, f = np.zeros(N), np.zeros(N)
        assemble(x[0:2 * N:2], x[1:2 * N:2], lam, x[2 * N:], f, old, INV_DT, 0.3, mesh, prm,
                 DRIVE, Loads.none(N), w, True)
        return np.concatenate([w.R.ravel(), w.Rg])

    x0 = np.concatenate([np.column_stack([u, th]).ravel(), g])
    Jfd = _fd(res, x0, 2 * N)
    res(x0)
    J = dense_jacobian(w, closed=True)
    # central differences with relative steps 1e-7: truncation and round-off ~1e-7 of a
    # row's largest entry
    scale = np.abs(Jfd).max(axis=1, keepdims=True)
    assert np.max(np.abs(J - Jfd) / scale) < 1e-6
    # the globals' columns and rows are there (not trivially matched zeros)
    assert np.abs(w.Gc[:, 0, 0]).max() > 0 and np.abs(w.Gc[:, 0, 1]).max() > 0
    assert factorise(w, mesh)
    rng = np.random.default_rng(7)
    r, rg = rng.standard_normal((N, 2)), rng.standard_normal(2)
    x, dg = np.zeros((N, 2)), np.zeros(2)
    linear_solve(w, mesh, r, rg, x, dg)
    want = np.linalg.solve(J, np.concatenate([r.ravel(), rg]))
    got = np.concatenate([x.ravel(), dg])
    assert np.max(np.abs(got - want)) < 1e-10 * np.max(np.abs(want))


def test_loop_semismooth_system_matches_finite_differences_and_its_bordered_solve():
    P, mesh, prm = _loop("exact")
    u, th, lam, g, old = _random(P, mesh)
    N = len(mesh.hb)
    w = Workspace.allocate(N, True, True, 2)
    s = w.saddle

    def res(x, active=None):
        f = np.zeros(N)
        uu, tt, ll, gg = x[0:3 * N:3], x[1:3 * N:3], x[2:3 * N:3].copy(), x[3 * N:]
        assemble(uu, tt, ll, gg, f, old, INV_DT, 0.3, mesh, prm, DRIVE, Loads.none(N), w,
                 True)
        if active is not None:  # differences within one stick/slip pattern
            s.active[:] = active
        saddle_system(ll, gg[0], INV_DT, 1.0, mesh, prm, w, s)
        return np.concatenate([-s.R.ravel(), -s.Rg])

    x0 = np.concatenate([np.column_stack([u, th, lam]).ravel(), g])
    res(x0)
    active = s.active.copy()
    assert 0 < active[mesh.cn].sum() < len(mesh.cn)  # both stuck and sliding nodes
    Jfd = _fd(lambda x: res(x, active), x0, 3 * N)
    res(x0)
    J = dense_jacobian(s, closed=True)
    scale = np.abs(Jfd).max(axis=1, keepdims=True)
    assert np.max(np.abs(J - Jfd) / scale) < 1e-6
    rhs = np.concatenate([s.R.ravel(), s.Rg])
    assert saddle_solve(s, mesh)
    want = np.linalg.solve(J, rhs)
    got = np.concatenate([s.dx.ravel(), s.dg])
    assert np.max(np.abs(got - want)) < 1e-10 * np.max(np.abs(want))


#: drive_flat's steady state on 800 elements, as the drive's own engine (deleted when the
#: drive became a layout of the one model; commit 6acb393, beltdrive.run.solve_steady)
#: computed it: belt speed c (m/s), driven speed omega2 (rad/s), max |u|, u at x = 0 (m),
#: and the sum of the nodal friction ratios over the grid.
OLD_ENGINE = {
    ("beam", "exact"): (11.92299484062713, 74.80587460772686, 0.0005929433593115082,
                        0.00038166838803963037, 44.95202706190137),
    ("beam", "tanh"): (11.92307667008414, 74.80578840948576, 0.0005891402468812885,
                       0.00038665317213481415, 45.021734238458976),
    ("string", "exact"): (11.922995685541443, 74.80587459396091, 0.0005930347603204758,
                          0.0003815794155957329, 44.95407341086089),
    ("string", "tanh"): (11.923078651548103, 74.80579650071408, 0.0005892588159763615,
                         0.00038653552692902003, 45.02258433433034),
}


@pytest.mark.parametrize("model", ["beam", "string"])
@pytest.mark.parametrize("law", ["exact", "tanh"])
def test_loop_steady_state_is_the_old_drive_engines(model, law):
    """The one model's steady state of drive_flat (the steady scheme: Newton from the
    creep theory's state, an exact law through its regularised twin) is the one the
    drive's separate engine computed, to the Newton tolerance: both solve the same
    discrete equations, written and assembled independently."""
    import beltsim

    scene = load_scene("drive_flat", [f'physics.model="{model}"',
                                      f'numerics.friction_law="{law}"',
                                      "numerics.integrator=steady",
                                      "numerics.elements=800"])
    r = beltsim.run(scene)
    assert r.converged
    c, omega2, umax, u0, ratios = OLD_ENGINE[model, law]
    s, f = r.solution, r.solution.all_fields
    # Newton stops at a scaled residual of 1e-9 (both engines): the state agrees to
    # about that, relative; the speeds, set by the whole loop, to round-off
    assert s.c == pytest.approx(c, rel=1e-11)
    assert s.omega2 == pytest.approx(omega2, rel=1e-11)
    assert np.max(np.abs(f["u"])) == pytest.approx(umax, rel=1e-9)
    assert f["u"][0] == pytest.approx(u0, rel=1e-9)
    assert np.sum(f["ratio"]) == pytest.approx(ratios, rel=1e-9)
