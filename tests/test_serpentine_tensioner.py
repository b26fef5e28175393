"""A tensioner's arm on a serpentine drive: the [tensioner] table, its rules, and the
steady state with the arm at rest, against the creep theory's arm and the arm's own
torque balance."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from beltsim import load_scene
from beltsim.beltdrive.arm import arm_table
from beltsim.beltdrive.creep import solve_serpentine
from beltsim.beltdrive.exact import serpentine_data
from beltsim.beltdrive.figures import hub_loads
from beltsim.beltdrive.scene import DriveScene
from beltsim.errors import SceneError
from beltsim.physics.model import assemble
from beltsim.simulation.controller import Simulation, run
from beltsim.solvers import discretise
from beltsim.solvers.newton import Workspace

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
def test_the_arms_table_is_the_layouts_geometry():
    """The tabled length changes are the turned layouts' (Chebyshev to round-off), sum to
    the loop's length change, and their slopes are the spans' directions dotted with the
    pulley's velocity (virtual work, from the layout's own tangents), to 1e-9 m/rad."""
    P = accessory().params.at_arm(0.1)
    table = arm_table(P)
    ten = P.tensioner
    for beta in (-0.2, -0.03, 0.0, 0.07, 0.2):
        moved = ten.turned(P.layout, beta)
        assert table(beta, 0) + table(beta, 1) == pytest.approx(
            moved.loop_length - P.layout.loop_length, abs=1e-14)
        a, alpha, s = ten.arm(moved)
        dP = s * a * np.array([-math.sin(alpha), math.cos(alpha)])  # the centre's velocity
        t = moved.span_directions
        k = ten.index
        assert table(beta, 2) == pytest.approx(float(t[k - 1] @ dP), abs=1e-9)
        assert table(beta, 3) == pytest.approx(-float(t[k] @ dP), abs=1e-9)


@pytest.mark.unit
def test_the_state_at_rest_is_an_equilibrium_and_the_creep_theorys():
    """A transient starts from the arm at rest: the discrete residual there (no speed,
    no load) vanishes to round-off of the rows' forces, and its rest angle is the creep
    theory's with the drive unloaded at a crawl. The model's belt takes the loop's
    stretch as a strain of the grid's length (small strain), the creep theory's of the
    unstretched belt: they differ by the installation strain's share, N0 / b1 = 0.4 %,
    of the arm's turn from the grid's angle."""
    scene = accessory(integrator="esdirk3")
    d = discretise(scene)
    state = d.new_state()
    w = Workspace.allocate(len(d.mesh.hb), False, True, d.n_globals)
    assemble(state.u, state.theta, state.lam, state.g, state.fnode, state, 1e3, 0.0, d.mesh,
             d.model, d.drive, d.loads, w, True)
    P = d.params
    assert np.abs(w.R[:, 0]).max() < 1e-10 * P.N0
    assert np.abs(w.Rg[1:]).max() < 1e-10 * P.N0 * 0.08
    rest = d.params.arm_turn + d.arm_rest  # from the drawn angle
    crawl = replace(serpentine_data(scene.params), omega=1e-3,
                    loads=(0.0,) * len(P.pulleys))
    creep = solve_serpentine(crawl).arm_travel
    assert rest == pytest.approx(creep, abs=2 * P.N0 / P.b1 * abs(d.arm_rest) + 1e-9)
    assert abs(d.arm_rest) > 0.01  # the running drive's rest angle is another


@pytest.mark.unit
def test_a_start_up_moves_the_arm_to_the_exact_rest_angle():
    """From the arm at rest, the drive runs up and the arm turns to its running rest
    angle: the end state is the creep theory's to the grid's error, as the steady solve's
    (both read on the grid laid at the creep theory's angle; the transient's end within
    its steady tolerance of it), and the path leaves the rest angle."""
    r = run(accessory(integrator="esdirk3", elements=200))
    assert r.converged
    e = r.errors()
    steady_e = steady(200).errors()
    # the transient's end is the discrete steady state, to its steady tolerance
    assert abs(e["arm_travel"] - steady_e["arm_travel"]) < 0.05 * abs(steady_e["arm_travel"])
    assert e["span_tension"] < 1e-4
    travel = r.history["arm_travel"]
    d = r.solution.disc
    rest = d.params.arm_turn + d.arm_rest
    # the first check comes a quarter transit after the start, early in the run-up
    assert abs(travel[0] - rest) < 0.5 * abs(travel[-1] - rest)
    assert travel[-1] == pytest.approx(r.summary()["arm_travel"], abs=1e-12)


@pytest.mark.unit
def test_a_transient_arm_needs_inertia():
    with pytest.raises(SceneError, match=r"^tensioner.inertia: must be > 0"):
        Simulation(accessory({k: v for k, v in ARM.items() if k != "inertia"},
                             integrator="esdirk3"))


@pytest.mark.verification
@pytest.mark.long
@pytest.mark.parametrize("scheme", ["explicit", "implicit"])
def test_every_transient_scheme_moves_the_arm_to_one_steady_state(scheme):
    """The explicit scheme (the arm's angle drifting with its rate, its rate kicked by
    its torque) and backward Euler end where esdirk3 ends: the semi-discrete steady state
    of the same grid, whatever the path, to the runs' steady tolerance (measured on 200
    elements: the explicit scheme's arm travel within 4e-12 rad of esdirk3's)."""
    ref = run(accessory(integrator="esdirk3", elements=200))
    r = run(accessory(integrator=scheme, elements=200))
    assert r.converged and ref.converged
    travel, want = r.summary()["arm_travel"], ref.summary()["arm_travel"]
    assert travel == pytest.approx(want, abs=1e-7)
    np.testing.assert_allclose(r.solution.span_tensions(), ref.solution.span_tensions(),
                               rtol=1e-6)


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
