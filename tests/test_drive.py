"""Drive profiles: tables and sines of the surface speed and the friction limit, their
validation, the runs they drive, and the slip power."""

import math

import numpy as np
import pytest

import beltsim
from beltsim.errors import SceneError
from beltsim.problem.drive import Profile, drive_of, friction_factor, mismatch, value
from helpers import ERROR_FACTOR, assert_errors_near, scene_path

COARSE = "numerics.elements=300"


def _scene(*overrides):
    return beltsim.load_scene(scene_path("paper_slip"), list(overrides))


@pytest.mark.unit
def test_table_value_is_numpys_interpolation_held_at_both_ends():
    times, vals = np.array([0.01, 0.02, 0.05]), np.array([3.0, -1.0, 2.0])
    prof = Profile(times, vals, 0.0, 0.0, 0.0, 0.0)
    for t in np.linspace(-0.01, 0.08, 97):
        assert value(prof, t) == pytest.approx(np.interp(t, times, vals), abs=1e-15)


@pytest.mark.unit
def test_sine_and_number_values():
    sine = Profile(np.zeros(0), np.zeros(0), 1.5, 0.25, 0.04, 0.0)
    for t in (0.0, 0.013, 0.5):
        assert value(sine, t) == pytest.approx(1.5 + 0.25 * math.sin(2 * math.pi * t / 0.04))
    ramped = Profile.constant(2.0, 0.1)
    assert value(ramped, 0.0) == 0.0 and value(ramped, 0.1) == 2.0
    assert value(ramped, 0.05) == pytest.approx(2.0 * 0.5)  # the smoothstep's midpoint


@pytest.mark.unit
def test_scene_tables_become_the_drive():
    scene = _scene("motion.surface_speed=[[0.0, 120.0], [0.01, 121.2]]",
                   "contact.max_friction=[[0.0, 1e6], [0.02, 1e5]]")
    P = scene.params
    assert P.v == 121.2 and P.fstar == 1e5  # the final values
    d = drive_of(scene, ramp_time=0.5)  # a table is not ramped
    assert mismatch(d, 0.005) == pytest.approx(0.6)
    assert friction_factor(d, 0.0) == pytest.approx(10.0)
    assert friction_factor(d, 0.01) == pytest.approx(5.5)
    assert friction_factor(d, 1.0) == pytest.approx(1.0)
    # written back and read again unchanged (scene.toml beside a run)
    import tomllib
    assert beltsim.Scene(tomllib.loads(scene.to_toml())).to_dict() == scene.to_dict()


@pytest.mark.unit
@pytest.mark.parametrize("override, message", [
    ("motion.surface_speed=[]", "motion.surface_speed: a table needs at least one"),
    ("motion.surface_speed=[[0, 120], [0, 121]]", "row 2: times must increase strictly"),
    ("motion.surface_speed=[[0, 120], 3]", "row 2: must be a [time, value] pair"),
    ("motion.surface_speed=[[0, true]]", "row 1 value: must be a number"),
    ("motion.surface_speed=[[0, inf]]", "row 1 value: must be finite"),
    ("motion.surface_speed=[[0, -1]]", "row 1 value: must be > 0"),
    ("motion.surface_speed=[[0, 120], [1, 200]]", "below both critical speeds"),
    ("motion.surface_speed={mean=121, amplitude=1, period=0}", "period: must be > 0"),
    ("motion.surface_speed={mean=121, amplitude=1, period=1, phase=0}",
     "motion.surface_speed.phase: unknown key of a sine"),
    ("contact.max_friction=[[0, 1e5], [1, -1e5]]", "contact.max_friction row 2 value"),
    ("contact.max_friction={mean=1e5, amplitude=1e5, period=1}", "must stay > 0"),
])
def test_profile_rules_name_key_row_and_rule(override, message):
    with pytest.raises(SceneError, match=None) as info:
        _scene(override)
    assert message in str(info.value) and "\n" not in str(info.value)


@pytest.mark.unit
def test_two_sines_must_share_their_period():
    with pytest.raises(SceneError, match="must equal motion.surface_speed.period"):
        _scene("motion.surface_speed={mean=121.2, amplitude=0.1, period=0.02}",
               "contact.max_friction={mean=1e5, amplitude=1e4, period=0.03}")


@pytest.mark.verification
def test_a_table_ending_at_the_constant_value_reaches_the_same_state():
    """A start-up written as a table (linear, 2 transit times) against the default
    smoothstep ramp: both end on the same steady state, to the steady tolerance."""
    const = beltsim.run(_scene(COARSE))
    table = beltsim.run(_scene(COARSE, "motion.surface_speed=[[0, 120], [0.0167, 121.2]]"))
    assert const.converged and table.converged
    F = const.solution.total_friction
    assert abs(table.solution.total_friction - F) / abs(F) < 1e-5
    assert np.max(np.abs(table.solution.u - const.solution.u)) < 1e-5 * np.max(
        np.abs(const.solution.u))
    # the steady test starts after the last row
    assert table.simulated_time > 0.0167


@pytest.mark.verification
def test_a_drop_of_the_friction_limit_ends_on_the_analytic_state_of_the_final_limit():
    """f* from 1e6 to 1e5 N/m after the start-up: the creep zone grows to the f* = 1e5
    state, which the run meets to the discretisation error of its grid (300 elements,
    second order: measured below; slip start in m)."""
    res = beltsim.run(_scene(COARSE, "contact.max_friction=[[0.05, 1e6], [0.0501, 1e5]]"))
    assert_errors_near(res, {"total_friction": 4.6e-5, "u": 3.9e-5, "theta": 1.3e-4,
                             "slip_power": 4.7e-5, "slip_start": 2.8e-6})
    # the history shows the short slip zone of f* = 1e6 before the drop
    h = res.history
    before = h["slip_start"][h["t"] <= 0.05][-1]
    assert before > res.reference.x_star + 0.02


@pytest.mark.verification
@pytest.mark.parametrize("speed, measured, law", [(121.2, 7.4e-6, 4.7e-4),
                                                  (119.9, 1.4e-5, 0.12)])
def test_slip_power_matches_the_analytic_value(speed, measured, law):
    """The summary's slip power (steady energy balance) on the default grid (600
    elements), paper slip and a reversed scene (v < c): measured 7.4e-6 and 1.4e-5,
    about second order in the element size (1200 elements: 1.8e-6 and 4.5e-6)."""
    res = beltsim.run(_scene(f"motion.surface_speed={speed}", "numerics.integrator=steady"))
    assert res.errors()["slip_power"] < ERROR_FACTOR * measured
    # the friction law's own dissipation is the same power, with a larger error on this
    # grid: measured 4.7e-4 and 0.12 (1200 elements: 1.2e-4 and 2.1e-2); bound 2x
    sol = res.solution
    assert abs(sol.slip_power - res.reference.slip_power) < 2 * law * res.reference.slip_power


@pytest.mark.unit
def test_history_slip_power_is_the_kernels_slip_term():
    """The numpy reading of the history agrees with physics.model.power_terms."""
    from beltsim.physics.model import POWER_TERMS, power_terms
    from beltsim.simulation.controller import Simulation

    sim = Simulation(_scene(COARSE, "numerics.t_end=0.02"))
    sim.run()
    out = np.zeros(len(POWER_TERMS))
    d = sim.disc
    power_terms(sim.state, sim.t, d.mesh, d.model, d.drive, d.loads, out)
    assert sim.solution().slip_power == pytest.approx(out[POWER_TERMS.index("slip")],
                                                      rel=1e-12)


@pytest.mark.verification
def test_periodic_drive_stops_at_its_periodic_state_and_reports_the_last_period():
    """A sine of the surface speed: the run ends when two periods agree within the
    steady tolerance, and the summary gives the last period's extremes and means."""
    res = beltsim.run(_scene(COARSE, "motion.surface_speed={mean=121.2, amplitude=0.3, "
                             "period=0.02}"), raise_on_failure=False)
    assert res.converged, res.reason
    per = res.summary()["periodic"]
    assert per["period"] == 0.02 and per["change"] < 1e-6
    tf, xs = per["total_friction"], per["slip_start"]
    assert tf["min"] < tf["mean"] < tf["max"] and xs["min"] < xs["max"]
    # the friction breathes with the speed: at the mean speed the analytic total lies
    # inside the period's range
    ref = beltsim.solve(_scene())
    assert tf["min"] < ref.total_friction < tf["max"]
    assert res.reference is None  # a periodic drive has no steady state to compare
