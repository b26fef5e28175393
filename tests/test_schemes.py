"""Explicit, implicit and direct steady schemes: one discretisation, one steady state."""

import numpy as np
import pytest

import beltsim
from beltsim.physics.friction import law_numpy
from beltsim.physics.model import State
from beltsim.problem.scene import Scene
from beltsim.simulation.controller import Simulation
from beltsim.simulation.trackers import GROWTH_LIMIT
from beltsim.solvers import Discretisation
from beltsim.solvers.explicit import (
    _friction_scalar,
    advance_explicit,
    explicit_amplification,
    explicit_stable_dt,
)
from helpers import scene_path


def _scene(name, *overrides):
    return beltsim.load_scene(scene_path(name), ["numerics.elements=300", *overrides])


@pytest.fixture(scope="module")
def slip_by_scheme():
    return {s: beltsim.run(_scene("paper_slip", f"numerics.integrator={s}"))
            for s in ("implicit", "explicit", "steady")}


def test_all_schemes_land_on_the_same_discrete_steady_state(slip_by_scheme):
    """The schemes share the semi-discretisation, so they differ by the steady tolerance
    (1e-6 relative change per window) only, far below the grid error (~1e-3)."""
    ref = slip_by_scheme["steady"].solution
    scale_u = np.abs(ref.u).max()
    for name in ("implicit", "explicit"):
        res = slip_by_scheme[name]
        assert res.converged, res.reason
        assert res.solution.total_friction == pytest.approx(ref.total_friction, rel=1e-5)
        assert np.max(np.abs(res.solution.u - ref.u)) < 1e-5 * scale_u
        assert res.solution.slip_start == ref.slip_start


@pytest.mark.parametrize("name", ["quasistatic", "inertia", "slip"])
def test_steady_solver_meets_the_bounds(name):
    res = beltsim.run(_scene(f"paper_{name}", "numerics.integrator=steady",
                             "numerics.elements=500"))
    assert res.converged
    errs = res.errors()
    # the acceptance bounds of the simulator (see test_simulation.BOUNDS)
    assert errs["total_friction"] < 5e-3 and errs["u"] < 2e-2 and errs["theta"] < 2e-2


def test_steady_solver_continues_through_a_large_mismatch():
    """v/c - 1 = 0.05 slides over most of the contact: continuation in v - c needed."""
    res = beltsim.run(_scene("paper_slip", "numerics.integrator=steady",
                             "motion.surface_speed=126"))
    assert res.converged
    assert res.errors()["total_friction"] < 5e-3


def test_requested_step_above_the_explicit_limit_is_refused():
    sim = Simulation(_scene("paper_inertia", "numerics.integrator=explicit"))
    limit = sim.numerics.dt / 0.9
    with pytest.raises(beltsim.SceneError, match=r"numerics\.dt: .* exceeds the explicit"):
        Simulation(_scene("paper_inertia", "numerics.integrator=explicit",
                          f"numerics.dt={1.01 * limit}"))


def test_explicit_without_damping_is_refused():
    with pytest.raises(beltsim.SceneError, match=r"physics\.damping"):
        Simulation(_scene("paper_inertia", "numerics.integrator=explicit",
                          "physics.damping=0"))


def test_explicit_limit_is_sharp():
    """Independent check of the von Neumann limit: just below it the explicit kernel
    stays bounded, 30% above it the same run grows without bound. v = c, so nothing
    but the initial noise drives the state."""
    def run_with(dt_factor):
        sc = _scene("paper_inertia", "numerics.grading=1", "numerics.elements=200",
                    "motion.surface_speed=120")
        d = Discretisation(sc)
        limit = explicit_stable_dt(d.params, d.grid.h_min, d.model.damping)
        state = d.new_state()
        rng = np.random.default_rng(0)
        state.u[1:-1] = 1e-6 * rng.standard_normal(len(state.u) - 2)
        state.theta[1:-1] = 1e-6 * rng.standard_normal(len(state.u) - 2)
        advance_explicit(state, 0.0, 1.0, dt_factor * limit, 20000, d.mesh, d.model, d.drive,
                         d.loads)
        return np.abs(state.u).max() / 1e-6
    assert run_with(0.95) < 10.0
    assert not run_with(1.3) < GROWTH_LIMIT  # overflowed or grew by > 1e4


def test_amplification_is_one_for_a_tiny_step_and_exceeds_one_beyond_cfl():
    P = Scene.load(scene_path("paper_inertia")).params
    h = 1e-3
    assert explicit_amplification(P, h, 1e-12, 651.0) <= 1.0 + 1e-12
    speed = P.c + np.sqrt(P.b1 / P.rho)
    assert explicit_amplification(P, h, 1.5 * h / speed, 651.0) > 1.01


def _explicit_step_numpy(u, th, v, w, dt, mesh, P, num):
    """Numpy twin of one explicit step (without the per-node scalar solver's shortcut)."""
    from scipy.optimize import brentq
    c, hh, d = P.c, 0.5 * P.h, P.damping
    he, hb = mesh.he, mesh.hb
    m, mi = P.rho * hb, P.I * hb
    vn, wn = v.copy(), w.copy()
    j = np.arange(1, len(u) - 1)
    hl, hr = he[j - 1], he[j]
    vn[j] = v[j] + dt / m[j] * (P.B * ((u[j + 1] - u[j]) / hr - (u[j] - u[j - 1]) / hl)
                                - 2 * P.rho * c * hb[j] * (v[j] - v[j - 1]) / hl - d * m[j] * v[j])
    wn[j] = w[j] + dt / mi[j] * (P.A * ((th[j + 1] - th[j]) / hr - (th[j] - th[j - 1]) / hl)
                                 - P.b2 * hb[j] * th[j] - 2 * P.I * c * hb[j] * (w[j] - w[j - 1])
                                 / hl - d * mi[j] * w[j])
    ub = u + hh * th
    target = P.v - P.c  # the scene has no ramp
    F = np.zeros_like(u)
    for k in range(mesh.j1 + 1, mesh.j2 + 1):
        h = he[k - 1]
        base = vn[k] + hh * wn[k] + c * (ub[k] - ub[k - 1]) / h - target
        # v_rel = base + dt F (1/m + hh^2/mi), F = -h f* g(v_rel / v_reg)
        kfac = dt * (1 / m[k] + hh * hh / mi[k])

        def eq(vr):
            return vr - base + kfac * h * num.fs * law_numpy(num.law_code, vr / num.vreg)[0]
        span = kfac * h * num.fs + abs(base) + 1.0
        vr = brentq(eq, -span, span, xtol=1e-16, rtol=1e-15)
        F[k] = -h * num.fs * law_numpy(num.law_code, vr / num.vreg)[0]
        vn[k] += dt * F[k] / m[k]
        wn[k] += dt * hh * F[k] / mi[k]
    return u + dt * vn, th + dt * wn, vn, wn, F


def test_explicit_step_matches_numpy_twin():
    sc = _scene("paper_slip", "numerics.integrator=explicit", "numerics.elements=60",
                "numerics.ramp_time=0")
    sim = Simulation(sc)
    d, dt = sim.disc, sim.numerics.dt
    rng = np.random.default_rng(5)
    n = len(sim.grid.x)
    u, th, v, w = (1e-4 * rng.standard_normal(n) for _ in range(4))
    for a in (u, th, v, w):
        a[[0, -1]] = 0.0
    ref = _explicit_step_numpy(u, th, v, w, dt, d.mesh, sc.params, sim.numerics)
    state = State(u.copy(), th.copy(), np.zeros(n), v.copy(), w.copy(), np.zeros(n))
    advance_explicit(state, 0.0, 1e-30, dt, 1, d.mesh, d.model, d.drive, d.loads)
    got = (state.u, state.theta, state.ud, state.td, state.fnode)
    for got, want in zip(got, ref):
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12 * np.abs(want).max())


@pytest.mark.parametrize("code", [0, 1, 2, 3])
def test_friction_scalar_solves_its_equation(code):
    rng = np.random.default_rng(code)
    for _ in range(300):
        s_pred = rng.standard_normal() * 10 ** rng.uniform(-3, 5)
        kappa = 10 ** rng.uniform(-2, 4)
        s0 = rng.standard_normal() * 10 ** rng.uniform(-3, 3)
        s, g = _friction_scalar(code, s_pred, kappa, s0)
        gs = law_numpy(code, s)[0]
        assert g == pytest.approx(gs, abs=1e-9)
        assert s + kappa * gs == pytest.approx(s_pred, abs=1e-9 * (abs(s_pred) + kappa))
