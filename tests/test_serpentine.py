"""Serpentine drives: a belt on N pulleys with back-side idlers, as a layout of the one
belt engine, against the N-pulley creep theory (beltsim.beltdrive.creep)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from beltsim import load_scene
from beltsim.beltdrive.analytic import GrossSlipError, solve_string
from beltsim.beltdrive.exact import string_state
from beltsim.errors import SceneError
from beltsim.simulation.controller import run
from beltsim.solvers import discretise
from helpers import BACK_IDLER, SERPENTINE_PULLEYS, serpentine_scene


def solve_steady(scene, elements=None):
    """The drive's discrete steady state, by the steady scheme."""
    over = {"numerics.integrator": "steady"}
    if elements:
        over["numerics.elements"] = elements
    return run(scene.with_overrides(over))


def _shorthand_as_pulleys():
    """drive_flat written out as [[pulley]] tables, rotated by 30 degrees about (0.1, 0.2)
    (a rigid motion changes nothing but the hub loads' directions)."""
    d = load_scene("drive_flat").to_dict()["drive"]
    a = math.radians(30.0)
    o = np.array([0.1, 0.2])
    rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    c2 = o + rot @ np.array([d["centre_distance"], 0.0])
    return [{"name": "driver", "centre": list(map(float, o)), "radius": d["driver_radius"],
             "speed": d["driver_speed"]},
            {"name": "driven", "centre": list(map(float, c2)), "radius": d["driven_radius"],
             "inertia": d["driven_inertia"], "load_torque": d["load_torque"]}], rot


@pytest.mark.unit
def test_the_two_pulley_shorthand_is_that_layout_written_out():
    """The shorthand and the same drive as rotated [[pulley]] tables: one steady state
    (to round-off: the wraps come from atan2 instead of pi -+ 2 b), the same creep
    theory, and hub loads rotated with the layout."""
    tables, rot = _shorthand_as_pulleys()
    flat = load_scene("drive_flat", {"physics.model": "string"})
    laid = serpentine_scene(tables, model="string")
    assert laid.params.two_pulley
    a, b = solve_steady(flat), solve_steady(laid)
    sa, sb = a.summary(), b.summary()
    for key in ("tight_tension", "slack_tension", "belt_speed", "driven_speed",
                "driver_torque", "slip_arc_driver", "slip_arc_driven"):
        assert sb[key] == pytest.approx(sa[key], rel=1e-9, abs=1e-12), key
    for pa, pb in zip(sa["pulleys"], sb["pulleys"]):
        np.testing.assert_allclose(pb["hub_load"], rot @ np.array(pa["hub_load"]),
                                   rtol=1e-9, atol=1e-9 * abs(sa["tight_tension"]))
    ex = solve_string(flat.params).summary()
    assert string_state(laid.params).summary()["tight_tension"] == pytest.approx(
        ex["tight_tension"], rel=1e-12)


def _steady_errors(scene, elements):
    return solve_steady(scene, elements).errors()


@pytest.mark.unit
@pytest.mark.parametrize("pulleys", [BACK_IDLER, SERPENTINE_PULLEYS],
                         ids=["back-idler", "four-inner"])
def test_the_string_on_n_pulleys_converges_to_the_creep_theory(pulleys):
    """The discrete string's steady state tends to the N-pulley creep theory at second
    order in the element size: span tensions, hub loads and speed losses (the slip arcs'
    fronts, located within a cell, are checked at the 1/N level)."""
    scene = serpentine_scene(pulleys, model="string")
    coarse, fine = _steady_errors(scene, 200), _steady_errors(scene, 400)
    for key in ("span_tension", "hub_load", "speed_loss"):
        order = math.log2(abs(coarse[key]) / abs(fine[key]))
        assert order > 1.8, (key, coarse[key], fine[key])
    assert fine["span_tension"] < 1e-4
    assert abs(fine["slip_arc"]) < 4.0 / 400  # a few cells of the loop, over the wrap


@pytest.mark.unit
def test_the_shipped_accessory_drive_starts_up_to_the_creep_theory():
    """The car accessory drive (seven pulleys, two back-side idlers) from rest to its
    steady state by the default scheme: within the default grid's error of the creep
    theory (measured 7e-6 for the tensions, 1e-5 for the hub loads)."""
    res = run(load_scene("serpentine_accessory"))
    assert res.status.name == "CONVERGED"
    err = res.errors()
    assert abs(err["span_tension"]) < 1e-4 and abs(err["hub_load"]) < 1e-4
    s = res.summary()
    assert [sp["from"] for sp in s["spans"]] == [p.name for p in res.scene.params.pulleys]
    # the semi-discrete power balance closes (measured 7e-11 of the driver's power);
    # the slip power and the transport term, which vanishes with the element size,
    # together are the creep theory's slip power (measured 2e-7 apart)
    balance = (s["driver_power"] - s["load_power"] - s["slip_power"] - s["damping_power"]
               - s["gyroscopic_power"] + s["transport_power"])
    assert abs(balance) < 1e-8 * s["driver_power"]
    exact = string_state(res.scene.params).slip_power
    assert s["slip_power"] - s["transport_power"] == pytest.approx(exact, rel=1e-5)


@pytest.mark.unit
def test_gross_slip_names_the_pulley():
    """A load beyond the alternator's capacity (its friction coefficient lowered to 0.12):
    the creep theory refuses it naming the pulley and its capacity, its rated load times
    its slip margin."""
    worn = {"pulley.alternator.friction_coefficient": 0.12}
    scene = load_scene("serpentine_accessory", worn | {"pulley.alternator.load_torque": 4.0})
    with pytest.raises(GrossSlipError) as info:
        string_state(scene.params)
    assert "alternator" in str(info.value) and "\n" not in str(info.value)
    rated = string_state(load_scene("serpentine_accessory", worn).params).summary()
    assert info.value.capacity == pytest.approx(2.5 * rated["pulleys"][3]["slip_margin"],
                                                rel=1e-9)


@pytest.mark.unit
def test_a_transient_names_the_pulley_that_slips():
    """From rest with the alternator loaded past its capacity: gross slip at the
    alternator, a physical outcome."""
    scene = load_scene("serpentine_accessory", {"pulley.alternator.friction_coefficient": 0.12,
                                                "pulley.alternator.load_torque": 4.0})
    res = run(scene, raise_on_failure=False)
    assert res.status.name == "GROSS_SLIP"
    assert "alternator" in res.reason


@pytest.mark.unit
@pytest.mark.parametrize("change, key, rule", [
    (lambda ps: ps[2].update(speed=100.0) or ps[2].pop("inertia"), "pulley.idler.speed",
     "second driver"),
    (lambda ps: ps[0].pop("speed") and ps[0].update(inertia=1.0), "pulley", "no driver"),
    (lambda ps: ps[1].update(centre=[0.1, 0.0]), "pulley", "overlap"),
    (lambda ps: ps[2].pop("inertia"), "pulley.idler.inertia", "missing"),
    (lambda ps: ps[0].update(inertia=1.0), "pulley.motor.inertia", "driver"),
    (lambda ps: ps[1].update(radius=-0.1), "pulley.mill.radius", "> 0"),
    (lambda ps: ps[1].update(colour="red"), "pulley.mill.colour", "unknown key"),
    (lambda ps: ps[2].update(name="mill"), "pulley.mill.name", "unique"),
    (lambda ps: ps[1].update(side="left"), "pulley.mill.side", "one of"),
    (lambda ps: ps[1].update(centre=[0.6]), "pulley.mill.centre", "pair"),
])
def test_bad_layouts_name_the_key_and_the_rule(change, key, rule):
    tables = [dict(p) for p in BACK_IDLER]
    change(tables)
    with pytest.raises(SceneError) as info:
        serpentine_scene(tables, model="string")
    msg = str(info.value)
    assert key in msg and rule in msg and "\n" not in msg, msg


@pytest.mark.unit
def test_the_shorthand_stays_apart():
    with pytest.raises(SceneError, match="drive.driver_radius: the two-pulley shorthand"):
        serpentine_scene(BACK_IDLER, model="string", **{"drive.driver_radius": 0.1})


@pytest.mark.unit
def test_belt_length_fixes_the_installation_tension():
    """An unstretched belt length L0 gives N0 = b1 (Lambda - L0) / Lambda; one longer than
    the loop is refused."""
    scene = serpentine_scene(BACK_IDLER, model="string")
    P = scene.params
    L0 = P.layout.loop_length * (1.0 - P.N0 / P.b1)
    data = scene.to_dict()
    data["drive"] = {"belt_length": L0}
    again = type(scene).from_dict(data)
    assert again.params.N0 == pytest.approx(P.N0, rel=1e-12)
    data["drive"] = {"belt_length": 1.01 * P.layout.loop_length}
    with pytest.raises(SceneError, match="drive.belt_length: must be shorter"):
        type(scene).from_dict(data)


@pytest.mark.unit
def test_a_scene_with_pulleys_round_trips_through_toml():
    scene = load_scene("serpentine_accessory")
    again = type(scene).loads(scene.to_toml())
    assert again == scene


@pytest.mark.unit
def test_every_free_pulley_is_a_global_with_its_load():
    """The loop's globals: c, then each pulley's speed but the driver's, with its inertia
    and its load."""
    d = discretise(load_scene("serpentine_accessory"))
    P = d.params
    free = [p for p in P.pulleys if p.role != "driver"]
    assert d.n_globals == 1 + len(free)
    np.testing.assert_array_equal(d.mesh.inertia[1:], [p.inertia for p in free])
    loads = [d.drive.load.profile(k).level for k in range(1, d.n_globals)]
    assert loads == [p.final_load for p in free]


@pytest.mark.unit
def test_the_beam_on_a_back_side_idler_tends_to_the_string_and_balances_its_power():
    """The beam's friction on a back-side idler acts on its outer face (lever -h/2). Its
    steady state differs from the string's creep theory by the beam's own physics, of
    first order in h: a belt four times thinner (b1 held by E h; each compared with its
    own string, whose mass per length falls with h) brings the slip arcs about four times closer
    (measured 0.026 and 0.0058 rad on 1600 elements; the tensions 1e-5 and 1e-6). At
    steady state the power terms balance to round-off of the driver's power, which a
    lever of one sign in the moment and the other in the slip velocity would break."""
    gaps = []
    for k in (1, 4):
        scene = serpentine_scene(BACK_IDLER, model="beam")
        belt = scene.to_dict()["belt"]
        scene = scene.with_overrides({
            "belt.height": belt["height"] / k, "belt.youngs_modulus": belt["youngs_modulus"] * k})
        res = solve_steady(scene, 1600)
        assert res.converged
        s, ex = res.summary(), string_state(scene.params).summary()
        gaps.append(max(abs(a["slip_arc"] - b["slip_arc"])
                        for a, b in zip(s["pulleys"], ex["pulleys"])))
        balance = (s["driver_power"] - s["load_power"] - s["slip_power"] - s["damping_power"]
                   - s["gyroscopic_power"] + s["transport_power"])
        assert abs(balance) < 1e-9 * s["driver_power"]
    assert 0 < gaps[1] < gaps[0] / 3


@pytest.mark.verification
def test_a_load_step_on_one_accessory_moves_the_drive_and_the_arm_between_exact_states():
    """The accessory drive with its tensioner: the alternator's load steps from 2.5 to
    4 N m half a second after the start-up's ramp. Before the step the history passes
    through the creep theory's state with the old load, though the grid's arcs are laid
    at the final arm angle, 8e-3 rad away (measured: span tensions within 3.6e-5, the arm
    within 4.5e-5 rad; bounds 2e-4), and the run ends on the new loads' state to the
    grid's error (400 elements: 2.3e-6; bound 1e-5)."""
    over = {"numerics.integrator": "esdirk3", "numerics.elements": 400,
            "numerics.ramp_time": 0.3,
            "pulley.alternator.load_torque": [[0.0, 0.0], [0.3, 2.5], [0.8, 2.5],
                                              [0.81, 4.0]]}
    scene = load_scene("serpentine_tensioner").with_overrides(over)
    r = run(scene)
    assert r.converged
    e = r.errors()
    assert e["span_tension"] < 1e-5 and abs(e["arm_travel"]) < 1e-4
    old = string_state(scene.with_overrides(
        {"pulley.alternator.load_torque": 2.5}).params)
    new = string_state(scene.params)
    t = r.history["t"]
    before = int(np.argmin(np.abs(t - 0.8)))
    names = scene.params.layout.names
    keys = [f"tension[{a}-{b}]" for a, b in zip(names, names[1:] + names[:1])]
    got = np.array([r.history[k][before] for k in keys])
    np.testing.assert_allclose(got, old.tensions, rtol=2e-4)
    # the step moves the tensions and the arm by far more than that
    assert np.max(np.abs(new.tensions / old.tensions - 1)) > 0.02
    assert r.history["arm_travel"][before] == pytest.approx(old.arm_travel, abs=2e-4)
    assert abs(new.arm_travel - old.arm_travel) > 5e-3
