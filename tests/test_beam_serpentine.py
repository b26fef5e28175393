"""The beam's exact steady state on N pulleys (beltdrive.beam on a [[pulley]] layout):
the two-pulley solution as its N = 2 case, its own balance laws on layouts with idlers,
back-side idlers and a tensioner, its string limit, and the numerical model converging
to it."""

import math

import numpy as np
import pytest

from beltsim.beltdrive.exact import exact_state, string_state
from beltsim.beltdrive.scene import DriveScene
from helpers import (
    BACK_IDLER,
    ROOT,
    SERPENTINE_BACK,
    SERPENTINE_PULLEYS,
    scene_path,
    serpentine_scene,
)

#: Newton's closing residuals stop at a scaled step of 1e-13 (beam_loop.STEP_TOL), and the
#: linear solve's conditioning (exponentials over the wraps) costs a few digits more:
#: identities of one solution hold to this relative tolerance.
IDENTITY = 1e-9


def _runs_scene(name, **over) -> DriveScene:
    """A shipped run's scene (runs/NAME.toml) with the beam model and ``over``."""
    path = ROOT / "runs" / f"{name}.toml"
    return DriveScene.load(str(path)).with_overrides({"physics.model": "beam", **over})


def _layouts():
    """Beam drives on 3, 4, 5 and 7 pulleys, with back-side idlers on 3, 5 and 7."""
    return {
        "back_idler_3": serpentine_scene(BACK_IDLER),
        "inner_4": serpentine_scene(SERPENTINE_PULLEYS),
        "back_5": serpentine_scene(SERPENTINE_BACK),
        "accessory_7": _runs_scene("serpentine_accessory"),
    }


@pytest.mark.unit
def test_two_pulleys_listed_driven_first_are_the_two_pulley_solution():
    # the drive_flat drive as [[pulley]] tables listed from the driven pulley: not the
    # two-pulley shorthand's order, so the N-pulley path solves it
    data = DriveScene.load(scene_path("drive_flat")).to_dict()
    ref = exact_state(DriveScene.from_dict(data).params)
    P2 = DriveScene.from_dict(data).params
    pulleys = [{"name": "driven", "centre": list(P2.pulleys[1].centre),
                "radius": P2.pulleys[1].radius, "inertia": P2.pulleys[1].inertia,
                "load_torque": P2.M2},
               {"name": "driver", "centre": list(P2.pulleys[0].centre),
                "radius": P2.pulleys[0].radius, "speed": P2.omega1}]
    data["drive"] = {"installation_tension": data["drive"]["installation_tension"]}
    data["pulley"] = pulleys
    P = DriveScene.from_dict(data).params
    assert P.model == "beam" and not P.two_pulley
    sol = exact_state(P)
    # the same loop started at the other pulley: spans and pulleys swap places
    np.testing.assert_allclose(sol.tensions, ref.tensions[::-1], rtol=IDENTITY)
    np.testing.assert_allclose(sol.speeds, ref.speeds[::-1], rtol=IDENTITY)
    np.testing.assert_allclose(sol.slip_arcs, ref.slip_arcs[::-1], rtol=1e-8)
    assert sol.c == pytest.approx(ref.c, rel=1e-12)
    assert sol.driver_torque == pytest.approx(ref.driver_torque, rel=IDENTITY)
    assert sol.slip_power == pytest.approx(ref.slip_power, rel=1e-8)


@pytest.mark.unit
@pytest.mark.parametrize("name", ["back_idler_3", "inner_4", "back_5", "accessory_7"])
@pytest.mark.parametrize("friction", ["coulomb", "stick"])
def test_balance_laws_on_n_pulleys(name, friction):
    scene = _layouts()[name]
    if friction == "stick":
        data = scene.to_dict()
        data["contact"] = {"friction": "stick"}
        scene = DriveScene.from_dict(data)
    P = scene.params
    sol = exact_state(P)
    loads = np.array([p.final_load for p in P.pulleys])
    d, lay = P.driver, P.layout
    roles = np.array(P.roles)
    # each pulley's friction takes its load (idlers none); the frictions sum to zero, so
    # the driver supplies r_d sum M_i / r_i as on the string
    rest = np.arange(len(loads)) != d
    top = sol.driver_torque
    np.testing.assert_allclose(sol.torques[rest], loads[rest], atol=IDENTITY * top)
    assert top == pytest.approx(lay.radii[d] * np.sum(loads / lay.radii), rel=IDENTITY)
    # power: what the driver puts in less what the loads take is the slip power
    # (integral f v_b = 0 round the loop, the module docstring of beam), which the
    # graded Gauss quadrature of the slip arcs integrates to round-off
    loss = top * sol.speeds[d] - np.dot(loads[rest], sol.speeds[rest])
    assert sol.slip_power > 0
    assert loss == pytest.approx(sol.slip_power, rel=1e-8)
    # hub loads: from the span tensions, summing to zero (each span once with each sign)
    hubs = sol.hub_loads
    assert np.max(np.abs(hubs.sum(axis=0))) < 1e-12 * np.max(np.abs(hubs))
    summary = sol.summary()
    assert [p["hub_load"] for p in summary["pulleys"]] == hubs.tolist()
    # contact pressure on every arc, slip arcs inside their wraps
    x = sol.grid(4000)
    on_arc = lay.segment_of(x) % 2 == 0
    assert np.min(sol.pressure(x)[on_arc]) > 0
    arcs = np.array(sol.slip_arcs)
    assert np.all(arcs >= 0) and np.all(arcs <= lay.wraps)
    if friction == "coulomb":
        # loaded pulleys slip over most of what the string's do; an idler's slip arc
        # balances only its stick zone's friction, the boundary layers' tail: tiny
        string = string_state(P)
        loaded = roles != "idler"
        assert np.all(arcs[loaded] > 0.3 * string.phi_s[loaded])
        assert np.all(arcs[~loaded] < 1e-3)
        assert sol.slip_signs[d] == 1.0
    else:
        # the exits' concentrated forces brake the belt at loaded pulleys; an idler's
        # balances its stick zone's friction (the boundary layers' tail)
        conc = np.array(sol.concentrated)
        idler = roles == "idler"
        assert np.all(arcs == 0) and np.all(conc[rest & ~idler] < 0) and conc[d] > 0
        assert np.all(np.abs(conc[idler]) < 1e-6 * conc[d])


@pytest.mark.unit
def test_back_side_lever_changes_the_sign_of_the_friction_moment():
    # on a back-side arc the friction acts on the belt's outer face: theta there has the
    # opposite sign to an inner arc's under friction of the same sign. The pressing idler
    # of SERPENTINE_BACK lies on the motor-mill span; the stick-zone friction B l_i
    # alpha^2 theta and the moment l_i f keep the same sign relation on both faces
    P = serpentine_scene(SERPENTINE_BACK).params
    sol = exact_state(P)
    loop = sol._loop
    for i, seg in enumerate(loop.segs):
        if seg.kind == "stick":
            assert seg.lever == pytest.approx(loop.l * P.layout.sides[seg.arc])
            t = np.linspace(0.0, seg.length, 7)
            f = loop.friction(i, t) @ sol._zz
            th = loop.theta(i, t) @ sol._zz
            # f = B l_i alpha^2 theta: the same sign as l_i theta
            assert np.all(f * seg.lever * th >= 0)


@pytest.mark.unit
def test_thin_belt_tends_to_the_creep_theory():
    """h scaled down at fixed b1, b2 and rho (a and I as h^2) on the five-pulley layout
    with a back-side idler: the tensions approach the creep theory's at second order in
    h and the loaded pulleys' slip arcs at first order (as on two pulleys,
    test_drive_beam.test_thin_belt_tends_to_the_string)."""
    P0 = serpentine_scene(SERPENTINE_BACK).params
    errors = []
    for s in (1.0, 0.5, 0.25, 0.125):
        stiff = {"stiffness.bending": P0.a * s * s, "stiffness.tension": P0.b1,
                 "stiffness.shear": P0.b2, "stiffness.mass": P0.rho,
                 "stiffness.rotary_inertia": P0.I * s * s, "belt.height": P0.h * s}
        P = serpentine_scene(SERPENTINE_BACK, **stiff).params
        got, want = exact_state(P), string_state(P)
        loaded = np.array([p.final_load > 0 or r == "driver"
                           for p, r in zip(P.pulleys, P.roles)])
        errors.append([np.max(np.abs(got.tensions / want.tensions - 1.0)),
                       np.max(np.abs(np.array(got.slip_arcs)[loaded] / want.phi_s[loaded]
                                     - 1.0))])
    errors = np.array(errors)
    rates = np.log2(errors[:-1] / errors[1:])
    np.testing.assert_allclose(rates[:, 0], 2.0, atol=0.1)
    np.testing.assert_allclose(rates[:, 1], 1.0, atol=0.1)


@pytest.mark.unit
def test_tensioner_arm_rests_near_the_creep_theorys():
    P = _runs_scene("serpentine_tensioner").params
    sol = exact_state(P)
    k = P.tensioner.index
    # the arm's torque vanishes at the beam's rest angle
    Q = sol.P
    assert Q.tensioner.torque(Q.layout, Q.arm_turn, sol.hub_loads[k]) == pytest.approx(
        0.0, abs=1e-9 * abs(P.tensioner.preload) + 1e-9)
    # and the beam's angle is the string's but for O(l): the tensions differ by ~1e-5
    travel = sol.summary()["arm_travel"]
    assert travel == pytest.approx(string_state(P).arm_travel, rel=1e-2)


# -- the numerical model converges to the exact solution -------------------------------

#: The machine drive's steady beam runs: relative errors (span tension and hub load over
#: the largest span tension, speed loss over the largest, slip arc over the wrap)
#: measured on 200, 400 and 800 elements. Second order but uneven from grid to grid
#: (the slip fronts' place within their cells): 1.8 to 2.3 between these grids.
MACHINE_ERRORS = {200: {"span_tension": 3.3e-5, "hub_load": 6.6e-5, "speed_loss": 3.5e-7},
                  400: {"span_tension": 6.9e-6, "hub_load": 1.4e-5, "speed_loss": 7.3e-8},
                  800: {"span_tension": 2.0e-6, "hub_load": 4.0e-6, "speed_loss": 2.1e-8}}


@pytest.mark.verification
def test_model_converges_to_the_exact_beam_on_three_pulleys_with_a_back_side_idler():
    import beltsim

    base = _runs_scene("serpentine_machine", **{"numerics.integrator": "steady"})
    errs = {}
    for n in MACHINE_ERRORS:
        r = beltsim.run(base.with_overrides({"numerics.elements": n}))
        assert r.converged, r.reason
        errs[n] = r.errors()
    for key in MACHINE_ERRORS[200]:
        e = np.array([abs(errs[n][key]) for n in MACHINE_ERRORS])
        order = np.polyfit(np.log([200, 400, 800]), np.log(e), 1)[0]
        assert -order > 1.8, (key, e)
        # within 3x of the measured errors (helpers.ERROR_FACTOR's margin)
        assert np.all(e <= 3.0 * np.array([MACHINE_ERRORS[n][key] for n in MACHINE_ERRORS]))
    # the slip arcs' readout locates each front within its cell; on these cells, wider
    # than the stick layer, the error scatters with the fronts' places in their cells
    # (test_slip_front holds its order): below a cell's share of the wrap
    assert abs(errs[800]["slip_arc"]) < 2 * math.pi * 0.3 / 800


def _slip_onset(scene, key, lo, hi, rtol):
    """The load ``key`` at which the exact beam state gives way to gross slip, by
    bisection on solve_beam's own answer (a state, or GrossSlipError)."""
    from beltsim.beltdrive import GrossSlipError
    from beltsim.beltdrive.beam import solve_beam

    while hi - lo > rtol * hi:
        mid = 0.5 * (lo + hi)
        try:
            solve_beam(scene.with_overrides({key: mid}).params)
            lo = mid
        except GrossSlipError:
            hi = mid
    return 0.5 * (lo + hi)


#: bisection's tolerance on the load; layout_capacity's root is to 1e-12
ONSET_RTOL = 1e-6
#: the beam's capacity against the creep theory's (its l -> 0 limit): measured 7.9e-6
#: (the motor) and 2.2e-5 (the mill, the motor's mu at 0.6) relative on
#: serpentine_machine, l / R = 0.019
STRING_CAPACITY = 1e-4


@pytest.mark.verification
@pytest.mark.long  # 10 to 20 s each on a quiet machine: CI's budget
@pytest.mark.parametrize("motor_mu", [0.3, 0.6])
def test_beam_capacity_on_n_pulleys_is_the_onset_of_gross_slip(motor_mu):
    # serpentine_machine, its mill's load raised: at the scene's mu the motor slips
    # first (its capacity in driver torque, every load raised together), with the
    # motor's mu at 0.6 the mill (its own load)
    from beltsim.beltdrive import GrossSlipError
    from beltsim.beltdrive.beam import _defaults, layout_capacity, solve_beam
    from beltsim.beltdrive.creep import serpentine_data, solve_serpentine

    scene = _runs_scene("serpentine_machine",
                        **{"pulley.motor.friction_coefficient": motor_mu})
    P = scene.params
    omega1 = _defaults(P, None, 0.0)[0]
    motor, mill = P.layout.names.index("motor"), P.layout.names.index("mill")
    i = motor if motor_mu == 0.3 else mill
    cap = layout_capacity(P, omega1, i)
    # in the mill's load: the driver's torque is r_motor M_mill / r_mill
    ratio = P.layout.radii[mill] / P.layout.radii[motor] if i == motor else 1.0
    onset = _slip_onset(scene, "pulley.mill.load_torque", 30.0, 80.0, ONSET_RTOL)
    assert cap * ratio == pytest.approx(onset, rel=ONSET_RTOL)
    # the gross-slip error names the pulley and carries its capacity
    with pytest.raises(GrossSlipError, match=P.layout.names[i]) as err:
        solve_beam(scene.with_overrides({"pulley.mill.load_torque": 80.0}).params)
    assert err.value.capacity == pytest.approx(cap, rel=1e-9)
    # the string limit: the creep theory's slip margin times the load it scales
    string = solve_serpentine(serpentine_data(
        scene.with_overrides({"physics.model": "string"}).params))
    now = 30.0 / ratio
    assert cap == pytest.approx(string.slip_margins[i] * now, rel=STRING_CAPACITY)
