"""Explicit, implicit and direct steady schemes: one discretisation, one steady state."""

import numpy as np
import pytest

import beltsim
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
        # read inside the cell: continuous in the state, so equal to the steady tolerance
        assert res.solution.slip_start == pytest.approx(ref.slip_start, abs=1e-6)


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
