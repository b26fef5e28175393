"""The one model on a closed layout: the loop's residual and Jacobian (global unknowns,
wrapped band, pressure bound) against finite differences, the bordered solves against
dense ones, and the loop's steady state against the creep theory's drive engine."""

import numpy as np
import pytest

from beltsim.api import load_scene
from beltsim.physics.friction import LAW_CODES, TANH
from beltsim.physics.layout import LoopGrid, loop_mesh, loop_params
from beltsim.physics.model import Loads, State, assemble
from beltsim.problem.drive import Drive, Profile
from beltsim.solvers.base import Scales
from beltsim.solvers.newton import NewtonSettings, Workspace, factorise, linear_solve, newton
from beltsim.solvers.ssn import saddle_solve, saddle_system

pytestmark = pytest.mark.unit


def _loop(law="tanh", elements=40, overrides=()):
    P = load_scene("drive_flat", list(overrides)).params
    g = P.geometry
    mesh = loop_mesh(LoopGrid.build(g.lengths, elements), [(0, g.R1, -1), (2, g.R2, 1)],
                     0.0 if P.mu is None else P.mu, (0.0, P.J2))
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


DRIVE = Drive(Profile.constant(12.1), Profile.constant(1.0), Profile.constant(40.0))
INV_DT = 50.0


def _dense(Lb, L2, Db, Ub, Gc, Gr, Gd):
    """The whole Jacobian of a loop from its wrapped bands and global blocks."""
    n, b, ng = Db.shape[0], Db.shape[1], Gd.shape[0]
    J = np.zeros((b * n + ng, b * n + ng))
    for i in range(n):
        for band, o in ((L2, -2), (Lb, -1), (Db, 0), (Ub, 1)):
            q = (i + o) % n
            J[b * i:b * i + b, b * q:b * q + b] += band[i]
        J[b * i:b * i + b, b * n:] = Gc[i]
        J[b * n:, b * i:b * i + b] = Gr[:, i, :]
    J[b * n:, b * n:] = Gd
    return J


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
    J = _dense(w.Lb, w.L2, w.Db, w.Ub, w.Gc, w.Gr, w.Gd)
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
    J = _dense(s.Lb, s.L2, s.Db, s.Ub, s.Gc, s.Gr, s.Gd)
    scale = np.abs(Jfd).max(axis=1, keepdims=True)
    assert np.max(np.abs(J - Jfd) / scale) < 1e-6
    rhs = np.concatenate([s.R.ravel(), s.Rg])
    assert saddle_solve(s, mesh)
    want = np.linalg.solve(J, rhs)
    got = np.concatenate([s.dx.ravel(), s.dg])
    assert np.max(np.abs(got - want)) < 1e-10 * np.max(np.abs(want))


@pytest.mark.parametrize("model", ["beam", "string"])
@pytest.mark.parametrize("law", ["exact", "tanh"])
def test_loop_steady_state_is_the_drive_engines(model, law):
    """The one model's steady state of drive_flat (Newton from the creep theory's state,
    an exact law through its regularised twin) is the drive engine's, to round-off."""
    from beltsim.beltdrive import discrete
    from beltsim.beltdrive import run as drun
    from beltsim.beltdrive.analytic import solve_string

    over = [f'physics.model="{model}"', f'numerics.friction_law="{law}"']
    scene = load_scene("drive_flat", over)
    P = scene.params
    num = drun.resolve(scene)
    ref = drun.solve_steady(scene)
    P_, mesh, _ = _loop(law, num.elements, over)
    omesh = discrete.loop_mesh(P.geometry, num.elements)
    lay = discrete.layout_of(omesh)
    oprm = discrete.loop_params(P, num.friction_law, num.regularisation)
    code = LAW_CODES[law]
    prm = loop_params(a=P.a, b1=P.b1, b2=P.b2, rho=P.rho, I=P.I, lever=P.lever,
                      damping=P.damping, N0=P.N0, law=code, dual=int(code == TANH),
                      regularisation=oprm.v_scale, friction_scale=oprm.p_ref)
    N = len(mesh.hb)
    y = discrete.string_guess(solve_string(P), omesh, lay)
    st = State.zeros(N, 2)
    st.u[:] = lay.u(y)
    st.lam[mesh.cn] = lay.lam(y)
    st.g[:] = [y[lay.c], y[lay.omega2]]
    rim1 = P.omega1 * P.geometry.R1
    drive = Drive(Profile.constant(rim1), Profile.constant(1.0), Profile.constant(P.M2))
    strain = P.N0 / P.b1
    L = P.geometry.loop_length
    sc = Scales(P.N0, P.N0 * P.h, L * strain, strain, np.array([rim1, rim1 / P.geometry.R2]),
                np.array([L * strain, P.N0 * P.geometry.R2]))
    settings = NewtonSettings(1e-10, 40)
    rest = State.zeros(N, 2)
    twin = prm._replace(law=TANH, dual=1, regularisation=0.1 * prm.regularisation)
    if code != TANH:
        w = Workspace.allocate(N, False, True, 2)
        assert newton(st, rest, 0.0, 0.0, mesh, twin, drive, Loads.none(N), sc, settings, w)
    w = Workspace.allocate(N, code != TANH, True, 2)
    assert newton(st, rest, 0.0, 0.0, mesh, prm, drive, Loads.none(N), sc, settings, w)
    f = ref.fields
    assert st.g[0] == pytest.approx(ref.summary["belt_speed"], rel=1e-11)
    assert st.g[1] == pytest.approx(ref.summary["driven_speed"], rel=1e-11)
    assert np.max(np.abs(st.u - f["u"])) < 1e-10 * np.max(np.abs(f["u"]))
    if model == "beam":
        assert np.max(np.abs(st.theta - f["theta"])) < 1e-9 * np.max(np.abs(f["theta"]))
    assert np.max(np.abs(st.lam - f["ratio"])) < 1e-9
