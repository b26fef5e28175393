"""A tensioner's arm on a serpentine drive: the [tensioner] table, its rules, and the
steady state with the arm at rest, against the creep theory's arm and the arm's own
torque balance."""

from __future__ import annotations

import math

import numpy as np
import pytest

from beltsim import load_scene
from beltsim.beltdrive.figures import hub_loads
from beltsim.beltdrive.scene import DriveScene
from beltsim.errors import SceneError
from beltsim.simulation.controller import Simulation, run

#: An arm of 81 mm about a pivot up and to the left of the accessory drive's tensioner
#: pulley, with data in the range of automotive tensioners (20 to 60 N m/rad, 15 to 40 N m
#: preload); this preload turns the arm by about 0.17 rad into the belt.
ARM = {"pulley": "tensioner", "pivot": [-0.12, 0.40], "stiffness": 40.0, "preload": 35.0,
       "inertia": 1e-4, "damping": 0.1}


def accessory(tensioner=ARM, **over):
    """The shipped accessory drive with the tensioner's arm and numerics overrides."""
    data = load_scene("serpentine_accessory").to_dict()
    if tensioner is not None:
        data["tensioner"] = dict(tensioner)
    scene = DriveScene(data)
    return scene.with_overrides({f"numerics.{k}": v for k, v in over.items()}) if over \
        else scene


def steady(elements=None, **arm):
    over = {"integrator": "steady"}
    if elements:
        over["elements"] = elements
    return run(accessory({**ARM, **arm}, **over))


@pytest.mark.unit
def test_the_arm_rests_where_its_torques_cancel():
    """The discrete steady state's own hub load on the turned layout balances the
    spring: tau0 - k beta + s (P - O) x F = 0, to the root search's tolerance."""
    r = steady()
    assert r.converged
    P = r.solution.params
    ten = P.tensioner
    F = hub_loads(P.layout, P.rho, r.solution.c, r.solution.span_tensions())[ten.index]
    arm = P.layout.centres[ten.index] - np.array(ARM["pivot"])
    belt = arm[0] * F[1] - arm[1] * F[0]
    _, _, s = ten.arm(P.layout)
    beta = r.summary()["arm_travel"]
    # brentq's xtol 1e-12 rad on beta, times the arm's stiffness (spring and belt) of
    # order k + |F| a = 40 + 80 N m/rad: 1e-10 N m
    assert abs(ARM["preload"] - ARM["stiffness"] * beta + s * belt) < 1e-9
    assert beta == pytest.approx(P.arm_turn, abs=0)
    assert math.dist(P.layout.centres[ten.index], ARM["pivot"]) == pytest.approx(
        math.dist([-0.05, 0.36], ARM["pivot"]), rel=1e-14)
    assert r.statistics["arm_solves"] >= 2


@pytest.mark.unit
def test_the_arm_converges_to_the_creep_theorys_at_the_grids_order():
    """The arm's travel against the creep theory's: the error follows the tensions'
    (second order in the element size, with the slip fronts' jitter between grid
    nodes), so from 200 to 800 elements it falls by at least 8 (order >= 1.5)."""
    errs = []
    for n in (200, 800):
        r = steady(n)
        e = r.errors()
        errs.append(abs(e["arm_travel"]))
        assert e["span_tension"] < 1e-4
    travel = r.summary()["arm_travel"]
    assert 0.1 < travel < 0.25  # the arm moved into the belt (the preload exceeds the belt's)
    assert errs[1] < errs[0] / 8
    assert errs[1] < 1e-5 * abs(travel) * 10


@pytest.mark.unit
def test_a_transient_with_an_arm_is_refused_with_the_reason():
    with pytest.raises(SceneError, match=r"tensioner: .*steady solves only"):
        Simulation(accessory(integrator="esdirk3"))


@pytest.mark.unit
@pytest.mark.parametrize("change, key, rule", [
    ({"pulley": "crankshaft"}, "tensioner.pulley", "must be an idler"),
    ({"pulley": "alternator"}, "tensioner.pulley", "must be an idler"),
    ({"pulley": "nowhere"}, "tensioner.pulley", "must name one of the pulleys"),
    ({"pivot": [-0.05, 0.36]}, "tensioner.pivot", "must differ"),
    ({"pivot": [1.0]}, "tensioner.pivot", "pair"),
    ({"stiffness": -1.0}, "tensioner.stiffness", ">= 0"),
    ({"spring": 3.0}, "tensioner.spring", "unknown key"),
    ({"preload": -80.0}, "tensioner.preload", "no equilibrium"),
])
def test_bad_arms_name_the_key_and_the_rule(change, key, rule):
    with pytest.raises(SceneError, match=rf"^{key}: .*{rule}"):
        accessory({**ARM, **change})


@pytest.mark.unit
def test_a_missing_key_and_the_shorthand():
    arm = dict(ARM)
    del arm["stiffness"]
    with pytest.raises(SceneError, match=r"^tensioner.stiffness: missing key"):
        accessory(arm)
    data = load_scene("drive_flat").to_dict()
    data["tensioner"] = dict(ARM)
    with pytest.raises(SceneError, match=r"^\[tensioner\]: only in a scene with"):
        DriveScene(data)


@pytest.mark.unit
def test_an_arm_round_trips_through_toml_and_reports_its_role():
    scene = accessory()
    assert DriveScene.loads(scene.to_toml()) == scene
    assert scene.params.roles[5] == "tensioner"
    assert scene.with_overrides({"tensioner.preload": 30.0}).params.tensioner.preload == 30.0
