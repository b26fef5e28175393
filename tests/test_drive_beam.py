"""The beam's exact steady state of the closed drive (beltdrive.beam): its equations,
interface conditions, length and balance, the string limit, the collapse of the slip arcs
onto perfect adhesion, the power balance and gross slip."""

import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import quad

from beltsim.beltdrive import analytic, beam
from beltsim.beltdrive.scene import DriveScene
from beltsim.errors import NoSolutionError
from helpers import scene_path

pytestmark = pytest.mark.unit

CASES = [("coulomb", True), ("coulomb", False), ("stick", True), ("stick", False)]


def _scene(friction="coulomb", inertia=True, **sections) -> DriveScene:
    """drive_flat with its friction and inertia switched, and sections' keys replaced."""
    data = DriveScene.load(scene_path("drive_flat")).to_dict()
    if friction == "stick":
        data["contact"] = {"friction": "stick"}
    data["physics"] = {"inertia": inertia}
    for section, keys in sections.items():
        data.setdefault(section, {}).update(keys)
    return DriveScene.from_dict(data)


def _coefficients(P, sol):
    """B, A, alpha, beta and l at the solution's belt speed, from the parameters."""
    c = sol.c
    B, A, lever = P.b1 - P.rho * c * c, P.a - P.I * c * c, P.lever
    return B, A, math.sqrt(P.b2 / (A + lever * lever * B)), math.sqrt(P.b2 / A), lever


def _pieces(P, sol):
    """The solution's pieces [a, b): the segment bounds split at the stick ends."""
    br = np.unique(np.concatenate([P.geometry.bounds, sol.stick_ends]))
    return [(a, b) for a, b in zip(br[:-1], br[1:]) if b > a]


def _left(fun, x, d=1e-7):
    """The left limit of fun at x by quadratic extrapolation from x - d, x - 2d, x - 3d
    (error of order (k d)^3 ~ 1e-13 for the decay rates k ~ 500 / m here)."""
    return 3 * fun(x - d) - 3 * fun(x - 2 * d) + fun(x - 3 * d)


def _quad(fun, a, b, points, epsabs=0.0):
    """The integral of fun over [a, b], split at the points inside (scipy quad)."""
    inner = [p for p in points if a < p < b]
    val, _ = quad(fun, a, b, points=inner or None, limit=2000, epsabs=epsabs, epsrel=1e-13)
    return val


# --------------------------------------------------------------------------------------
# the equations and conditions


@pytest.mark.parametrize("friction, inertia", CASES)
def test_fields_satisfy_the_steady_equations(friction, inertia):
    """B eps' + f = 0 and A theta'' - b2 theta + l f = 0 inside every piece, by central
    differences of the sampled fields (truncation (k h)^2 / 12 ~ 1e-7 relative at
    h = 1e-3 / k); v_rel = 0 in stick, f = +-mu p in slip."""
    P = _scene(friction, inertia).params
    sol = beam.solve_beam(P)
    B, A, alpha, beta, lever = _coefficients(P, sol)
    k = max(alpha, beta)
    h = 1e-3 / k
    xs = []
    for a, b in _pieces(P, sol):
        layer = a + np.array([3e-3, 1e-2, 0.1, 0.5, 1.0, 3.0]) / k
        xs.append(np.concatenate([np.linspace(a, b, 203)[1:-1], layer, a + b - layer]))
    x = np.concatenate(xs)
    x = x[np.all([(np.abs(x - e) > 3 * h) for e in np.concatenate(_pieces(P, sol))], axis=0)]
    f = sol.friction(x)
    deps = (sol.strain(x + h) - sol.strain(x - h)) / (2 * h)
    th = sol.theta(x)
    d2th = (sol.theta(x + h) - 2 * th + sol.theta(x - h)) / (h * h)
    f_scale = np.max(np.abs(f)) + B * np.max(np.abs(deps))
    assert np.max(np.abs(B * deps + f)) <= 1e-6 * f_scale
    if lever > 0:
        m_scale = np.max(np.abs(P.b2 * th))
        assert m_scale > 0
        assert np.max(np.abs(A * d2th - P.b2 * th + lever * f)) <= 1e-6 * m_scale
    g = P.geometry
    seg = g.segment_of(x)
    on_arc = seg % 2 == 0
    s1, s2 = sol.stick_ends
    stick = on_arc & (((seg == 0) & (x < s1)) | ((seg == 2) & (x < s2)))
    slip = on_arc & ~stick
    creep = sol.c * abs(sol.tight_tension - sol.slack_tension) / P.b1
    assert np.max(np.abs(sol.slip_velocity(x[stick]))) <= 1e-10 * creep
    if friction == "coulomb":
        assert np.any(slip)
        mup = P.mu * sol.pressure(x[slip])
        sign = np.where(seg[slip] == 0, 1.0, -1.0)
        np.testing.assert_allclose(f[slip], sign * mup, rtol=1e-12)
        # and Coulomb's law holds: |f| <= mu p in stick, sliding opposes f in slip
        assert np.all(np.abs(f[stick]) <= P.mu * sol.pressure(x[stick]))
        assert np.all(sign * sol.slip_velocity(x[slip]) <= 1e-10 * creep)
    else:
        assert not np.any(slip)
    # N is constant on the spans (f = 0 there) and equals the span means
    for k_seg, mean in ((1, sol.slack_tension), (3, sol.tight_tension)):
        np.testing.assert_allclose(sol.tension(x[seg == k_seg]), mean, rtol=1e-12)


@pytest.mark.parametrize("friction, inertia", CASES)
def test_continuity_and_jumps_at_every_interface(friction, inertia):
    """theta, A theta' and eps continuous at every interface; with perfect adhesion the
    exits carry [[B eps]] = -F_i and [[A theta']] = -l F_i."""
    P = _scene(friction, inertia).params
    sol = beam.solve_beam(P)
    B, _, _, _, lever = _coefficients(P, sol)
    e = P.geometry.bounds
    F = sol.concentrated
    th_scale = np.max(np.abs(sol.theta(sol.grid())))
    m_scale = np.max(np.abs(sol.moment(sol.grid())))
    eps_scale = abs(sol.tight_tension - sol.slack_tension) / P.b1
    exits = {e[1]: F[0], e[3]: F[1]}
    for x in np.unique(np.concatenate([e[:4], sol.stick_ends])):
        xl = x if x > 0 else P.geometry.loop_length
        jump = exits.get(x, 0.0) if friction == "stick" else 0.0
        assert abs(sol.theta(x) - _left(sol.theta, xl)) <= 1e-9 * th_scale + 1e-300
        assert abs(sol.moment(x) - _left(sol.moment, xl) + lever * jump) <= 1e-8 * (
            m_scale + abs(lever * jump)) + 1e-300
        assert abs(B * (sol.strain(x) - _left(sol.strain, xl)) + jump) <= 1e-9 * B * eps_scale
    if friction == "stick":
        assert F[0] > 0 > F[1]
    else:
        assert F == (0.0, 0.0)


@pytest.mark.parametrize("friction, inertia", CASES)
def test_length_balance_and_gauge_by_quadrature(friction, inertia):
    """The integral of eps over the loop vanishes, the driven pulley balances the load,
    the displacement has mean 0 and u' = eps (adaptive quadrature, tolerance 1e-13)."""
    P = _scene(friction, inertia).params
    sol = beam.solve_beam(P)
    g = P.geometry
    lam, e = g.loop_length, g.bounds
    pts = np.unique(np.concatenate([e, sol.stick_ends]))
    eps_scale = abs(sol.tight_tension - sol.slack_tension) / P.b1
    length = sum(_quad(lambda x: sol.strain(x), a, b, pts, 1e-13 * eps_scale * lam)
                 for a, b in zip(pts[:-1], pts[1:]))
    assert abs(length) <= 1e-10 * eps_scale * lam
    driven = _quad(lambda x: sol.friction(x), e[2], e[3], pts) + sol.concentrated[1]
    assert driven == pytest.approx(-P.M2 / g.R2, rel=1e-10)
    driver = _quad(lambda x: sol.friction(x), e[0], e[1], pts) + sol.concentrated[0]
    assert sol.driver_torque == pytest.approx(g.R1 * driver, rel=1e-10)
    u_scale = np.max(np.abs(sol.displacement(sol.grid())))
    mean = sum(_quad(lambda x: sol.displacement(x), a, b, pts, 1e-13 * u_scale * lam)
               for a, b in zip(pts[:-1], pts[1:])) / lam
    assert abs(mean) <= 1e-10 * u_scale
    x = np.linspace(0.01, lam - 0.01, 37)
    h = 1e-6
    du = (sol.displacement(x + h) - sol.displacement(x - h)) / (2 * h)
    np.testing.assert_allclose(du, sol.strain(x), atol=1e-6 * eps_scale)
    assert sol.displacement(0.0) == pytest.approx(sol.displacement(lam), abs=1e-12 * u_scale)


# --------------------------------------------------------------------------------------
# limits


@pytest.mark.parametrize("friction, inertia", CASES)
def test_string_model_is_the_closed_form_string(friction, inertia):
    """physics.model = "string" (lever 0) gives solve_string's solution to round-off."""
    P = _scene(friction, inertia, physics={"inertia": inertia, "model": "string"}).params
    assert P.lever == 0.0
    sol, ref = beam.solve_beam(P), analytic.solve_string(P)
    got, want = sol.summary(), ref.summary()
    assert set(got) == set(want)
    for key, value in want.items():
        if isinstance(value, list):  # spans and pulleys: their figures are compared below
            continue
        assert got[key] == pytest.approx(value, rel=1e-10, abs=1e-12), key
    for a, b in zip(got["pulleys"], want["pulleys"]):
        np.testing.assert_allclose(a["hub_load"], b["hub_load"], rtol=1e-10, atol=1e-9)
    x = np.linspace(0.0, P.geometry.loop_length, 1001)
    dT = ref.T1 - ref.T2
    np.testing.assert_allclose(sol.tension(x), ref.tension(x), rtol=0, atol=1e-10 * dT)
    np.testing.assert_allclose(sol.friction(x), ref.friction(x), rtol=0,
                               atol=1e-10 * np.max(np.abs(ref.friction(x)) + dT))
    np.testing.assert_allclose(sol.concentrated, ref.concentrated, rtol=1e-10, atol=1e-12)
    u = ref.displacement(x)
    np.testing.assert_allclose(sol.displacement(x), u, rtol=0, atol=1e-10 * np.max(np.abs(u)))
    assert np.all(sol.theta(x) == 0.0)


@pytest.mark.parametrize("inertia", [True, False])
def test_adhesion_spans_and_speeds_are_the_strings(inertia):
    """Perfect adhesion: theta's boundary layer at each exit has theta(e) = l F_i /
    (A (alpha + beta)), the same decay rates on both pulleys and F_2 = -F_1, so the
    length integrals' l theta terms cancel between the exits and the spans' tensions, c
    and omega2 are the string's (up to exp(-beta span), nil here), while the concentrated
    forces are smaller: part of the friction spreads over the stick zones' layers."""
    P = _scene("stick", inertia).params
    sol, ref = beam.solve_beam(P), analytic.solve_string(P)
    for key in ("tight_tension", "slack_tension", "belt_speed", "driven_speed"):
        assert sol.summary()[key] == pytest.approx(ref.summary()[key], rel=1e-12), key
    F, F_string = sol.concentrated, ref.concentrated
    assert F[0] == pytest.approx(-F[1], rel=1e-12)
    assert 0 < F[0] < 0.9 * F_string[0]
    B, A, alpha, beta, lever = _coefficients(P, sol)
    exit1 = P.geometry.bounds[1]
    assert sol.theta(exit1) == pytest.approx(lever * F[0] / (A * (alpha + beta)), rel=1e-9)


@pytest.mark.parametrize("inertia", [True, False])
def test_thin_belt_tends_to_the_string(inertia):
    """h scaled down at fixed b1, b2 and rho (a and I as h^2): the slip arcs approach the
    string's at first order in h and the tensions at second order."""
    P0 = _scene("coulomb", inertia).params
    errors = []
    for s in (1.0, 0.5, 0.25, 0.125):
        stiff = {"bending": P0.a * s * s, "tension": P0.b1, "shear": P0.b2}
        if inertia:
            stiff.update(mass=P0.rho, rotary_inertia=P0.I * s * s)
        P = _scene("coulomb", inertia, belt={"height": P0.h * s}, stiffness=stiff).params
        got, want = beam.solve_beam(P).summary(), analytic.solve_string(P).summary()
        errors.append([abs(got[k] / want[k] - 1.0) for k in
                       ("slip_arc_driver", "slip_arc_driven", "tight_tension",
                        "slack_tension")])
    errors = np.array(errors)
    rates = np.log2(errors[:-1] / errors[1:])
    np.testing.assert_allclose(rates[:, :2], 1.0, atol=0.05)
    np.testing.assert_allclose(rates[:, 2:], 2.0, atol=0.05)
    assert np.all(errors[-1] < [3e-3, 2e-3, 3e-7, 4e-7])


def test_slip_arcs_collapse_onto_perfect_adhesion():
    """As mu grows the slip arcs shrink as 1/mu and the Coulomb solution tends to perfect
    adhesion: theta everywhere, N outside the slip arcs and in the mean, all decreasing."""
    P = _scene().params
    mus = np.geomspace(1.0, 1e4, 9)  # through lam = beta (mu ~ 40 and ~ 80 here)
    r = beam.slip_collapse(P, mus)
    adh = r["adhesion"]
    for key in ("slip_arc_driver", "slip_arc_driven", "theta_diff", "tension_diff_l1"):
        assert np.all(np.diff(r[key]) < 0), key
    far = mus >= 10  # below, the slip arcs hide the adhesion's boundary layer at the exit
    assert np.all(np.diff(r["tension_diff"][far]) < 0)
    # first order in 1 / mu: each step of 10^0.5 shrinks them by 10^0.5
    for key in ("slip_arc_driver", "slip_arc_driven", "theta_diff", "tension_diff",
                "tension_diff_l1"):
        ratio = r[key][-2] / r[key][-1]
        assert ratio == pytest.approx(10**0.5, rel=0.02), key
    assert r["slip_arc_driver"][-1] < 5e-5 and r["theta_diff"][-1] < 5e-6
    dT = adh["tight_tension"] - adh["slack_tension"]
    assert r["tension_diff"][-1] < 5e-4 * dT
    for key in ("tight_tension", "slack_tension"):
        gap = np.abs(r[key] - adh[key])
        assert np.all(np.diff(gap) < 0) and gap[-1] < 1e-5 * dT


# --------------------------------------------------------------------------------------
# power, capacity, errors


@pytest.mark.parametrize("friction, inertia", CASES)
@pytest.mark.parametrize("load", [10.0, 50.0, 90.0])
def test_power_balance(friction, inertia, load):
    """M1 omega1 - M2 omega2 = slip power.

    Derivation: the motor's power is M1 omega1 = integral over the driver arc of f omega1
    R1 and the load takes M2 omega2 = -integral over the driven arc of f omega2 R2, so
    their difference is the integral of f times the rim speed. The fibre speed is
    v_b = c (1 + N0/b1 + eps + l theta'), and on the periodic loop integral f = 0,
    integral f eps = -B [eps^2 / 2] = 0 and integral l f theta' = [b2 theta^2/2 -
    A theta'^2/2] = 0, so integral f v_b = 0 and the difference is -integral f v_rel.
    Also checked: the slip power is that integral, by adaptive quadrature (Coulomb).
    """
    P = _scene(friction, inertia).params
    sol = beam.solve_beam(P, M2=load)
    s = sol.summary()
    loss = s["driver_torque"] * P.omega1 - load * s["driven_speed"]
    assert s["slip_power"] > 0
    assert loss == pytest.approx(s["slip_power"], rel=1e-9)
    if friction == "coulomb":
        e = P.geometry.bounds
        s1, s2 = sol.stick_ends
        direct = -sum(_quad(lambda x: sol.friction(x) * sol.slip_velocity(x), a, b, [])
                      for a, b in ((s1, e[1]), (s2, e[3])))
        assert direct == pytest.approx(s["slip_power"], rel=1e-10)
    # the friction on the whole loop vanishes (B eps' = -f, eps periodic): M1 = M2 R1 / R2
    # and the efficiency is the speed ratio
    R1, R2 = P.geometry.radii
    assert s["driver_torque"] == pytest.approx(load * R1 / R2, rel=1e-12)
    assert s["efficiency"] == pytest.approx(s["speed_ratio"], rel=1e-12)
    assert s["efficiency"] == pytest.approx(
        1.0 - s["slip_power"] / (s["driver_torque"] * P.omega1), rel=1e-9)


@pytest.mark.parametrize("inertia, swap", [(True, False), (False, False), (True, True)])
def test_gross_slip_above_the_beam_capacity(inertia, swap):
    """The beam's capacity is solved in its own model (the slip arc of the smaller wrap
    spans it: the driver's, or the driven pulley's when the pulleys swap); it lies within
    1e-4 of the string's here. Above it: GrossSlipError carrying it."""
    drive = {"driver_radius": 0.16, "driven_radius": 0.08, "driver_speed": 75.0} \
        if swap else {}
    P = _scene("coulomb", inertia, drive=drive).params
    cap, cap_string = beam.capacity(P), analytic.capacity(P)
    assert cap == pytest.approx(cap_string, rel=1e-4)
    with pytest.raises(analytic.GrossSlipError) as info:
        beam.solve_beam(P, M2=1.001 * cap_string)
    assert info.value.capacity == pytest.approx(cap, rel=1e-12)
    assert "\n" not in str(info.value) and "drive.load_torque" in str(info.value)
    with pytest.raises(analytic.GrossSlipError):
        beam.solve_beam(P, M2=cap * (1 + 1e-7))
    sol = beam.solve_beam(P, M2=cap * (1 - 1e-7))
    wraps, arcs = P.geometry.wraps, sol.slip_arcs
    small = 1 if swap else 0
    assert wraps[small] - 1e-3 < arcs[small] <= wraps[small]
    assert arcs[1 - small] < wraps[1 - small]
    # the loads between the two capacities: the beam's verdict, not the string's
    mid = 0.5 * (cap + cap_string)
    if cap > cap_string:
        assert beam.solve_beam(P, M2=mid).slip_arcs[small] < wraps[small]
    else:
        with pytest.raises(analytic.GrossSlipError):
            beam.solve_beam(P, M2=mid)
    assert beam.capacity(dataclasses.replace(P, mu=None, friction="stick")) == math.inf


def test_lift_off_and_bad_arguments():
    """A pretension too low for the load leaves an arc without pressure (LiftOffError);
    with a large mu the slip arcs stay short until the slack side's pressure vanishes, and
    that is lift-off too; a belt whose rotary inertia outweighs its bending stiffness at
    the belt speed has no steady state; nonsense arguments are refused in one line."""
    P = _scene("stick").params
    with pytest.raises(analytic.LiftOffError, match="drive.installation_tension"):
        beam.solve_beam(dataclasses.replace(P, N0=100.0))
    assert beam.solve_beam(dataclasses.replace(P, N0=300.0)).slip_arcs == (0.0, 0.0)
    sticky = dataclasses.replace(_scene().params, mu=50.0)
    assert beam.solve_beam(sticky, M2=200.0).slack_tension > 0
    with pytest.raises(analytic.LiftOffError, match="drive.installation_tension"):
        beam.solve_beam(sticky, M2=240.0)
    with pytest.raises(analytic.LiftOffError, match="lifts off even unloaded"):
        beam.solve_beam(dataclasses.replace(sticky, N0=30.0))  # rho c^2 = 41 N
    with pytest.raises(NoSolutionError, match=r"drive.driver_speed: .*\(a - I c\^2 <= 0\)"):
        beam.solve_beam(_scene().params, omega1=600.0)
    with pytest.raises(ValueError, match="omega1: must be > 0"):
        beam.solve_beam(P, omega1=0.0)
    with pytest.raises(ValueError, match="M2: must be >= 0"):
        beam.solve_beam(P, M2=-1.0)


def test_unloaded_drive_is_uniform():
    """M2 = 0: no friction, no slip, eps = 0 and theta = 0, omega2 R2 = omega1 R1."""
    P = _scene().params
    sol = beam.solve_beam(P, M2=0.0)
    x = sol.grid()
    assert sol.slip_arcs == (0.0, 0.0)
    assert np.max(np.abs(sol.tension(x) - P.N0)) <= 1e-12 * P.N0
    assert np.max(np.abs(sol.friction(x))) <= 1e-9
    assert sol.speed_ratio == pytest.approx(1.0, abs=1e-14)
    assert sol.efficiency == 1.0
