"""The numpy/scipy.sparse port of the default scheme takes beltsim's steps exactly.

An independent check of the numba kernels (assemble, the primal-dual Newton with its
block LU, the filtered BDF2 error estimate, the step control): the port writes the
same equations with array operations and a general sparse LU.
"""

import numpy as np
import pytest

from beltsim.api import load_scene
from beltsim.physics.discrete import Loads
from beltsim.simulation.controller import Simulation
from benchmarks import port
from helpers import scene_path

pytestmark = pytest.mark.lab


def _runs(overrides, solver="splu"):
    # the port is of BDF2, "implicit" (the default scheme is esdirk3)
    scene = load_scene(scene_path("paper_slip"), ["numerics.integrator=implicit", *overrides])
    return Simulation(scene).run(), port.port_simulation(scene, solver=solver).run()


def test_port_takes_the_implicit_schemes_steps():
    ours, theirs = _runs(["numerics.elements=100", "numerics.t_end=0.1"])
    assert ours.simulated_time == theirs.simulated_time == pytest.approx(0.1)
    np.testing.assert_array_equal(ours.history["t"], theirs.history["t"])
    np.testing.assert_allclose(theirs.history["total_friction"], ours.history["total_friction"],
                               rtol=1e-8, atol=1e-8 * abs(ours.solution.total_friction))
    for key in ("steps", "newton_iterations", "rejected_steps"):
        assert theirs.statistics[key] == ours.statistics[key], key
    assert ours.steps > 100
    a, b = ours.solution.total_friction, theirs.solution.total_friction
    assert abs(a - b) <= 1e-8 * abs(a)
    np.testing.assert_allclose(theirs.solution.u, ours.solution.u, rtol=0,
                               atol=1e-8 * np.abs(ours.solution.u).max())
    for key, value in ours.power_balance.items():
        if isinstance(value, float):
            assert theirs.power_balance[key] == pytest.approx(value, rel=1e-6, abs=1e-9), key


def test_banded_port_takes_the_same_steps():
    ours, theirs = _runs(["numerics.elements=40", "numerics.t_end=0.03"], solver="banded")
    np.testing.assert_array_equal(ours.history["t"], theirs.history["t"])
    assert theirs.statistics["steps"] == ours.statistics["steps"]
    a, b = ours.solution.total_friction, theirs.solution.total_friction
    assert abs(a - b) <= 1e-8 * abs(a)


def test_port_takes_the_same_steps_under_distributed_loads():
    scene = load_scene(scene_path("paper_slip"), ["numerics.elements=40", "numerics.t_end=0.03",
                                                  "numerics.integrator=implicit"])
    ours, theirs = Simulation(scene), port.port_simulation(scene)
    x = ours.grid.x
    shape = np.sin(np.pi * x / x[-1])
    # a load growing over the run: 2 kN/m on u and 20 N m/m on theta at the end
    qu, qt = np.outer([0.0, 2e3], shape), np.outer([0.0, 20.0], shape)
    loads = Loads(np.array([0.0, 0.03]), qu, qt, np.zeros_like(qu), np.zeros_like(qt))
    for sim in (ours, theirs):
        sim.disc.loads = loads
    a, b = ours.run(), theirs.run()
    np.testing.assert_array_equal(a.history["t"], b.history["t"])
    assert a.statistics["steps"] == b.statistics["steps"]
    assert a.power_balance["load_work"] != 0.0
    for key in ("load_work", "stored_energy_change"):
        assert b.power_balance[key] == pytest.approx(a.power_balance[key], rel=1e-8), key
    np.testing.assert_allclose(b.solution.u, a.solution.u, rtol=0,
                               atol=1e-8 * np.abs(a.solution.u).max())


def test_port_refuses_what_it_does_not_implement():
    scene = load_scene(scene_path("paper_slip"), ["numerics.elements=20",
                                                  "numerics.integrator=explicit"])
    with pytest.raises(ValueError, match="implicit"):
        port.port_simulation(scene)
