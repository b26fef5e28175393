"""Analytic solutions checked against the steady equations, independently of their formulas.

Equations (the paper's, as in beltsim.problem.analytic), B = b1 - rho c^2, A = a - I c^2:
  B eps' + f = 0,  A theta'' - b2 theta + (h/2) f = 0,  eps + (h/2) theta' = e0 in stick,
  theta = 0 at 0 and L, integral of eps = 0, [[B eps]] = -F and [[A theta']] = -(h/2) F at x2.
Derivatives here are finite differences (or Chebyshev interpolants) of the returned u, theta
and strain, never the solution's own derivative formulas.
"""

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

from beltsim.api import paper_scene
from beltsim.errors import NoSolutionError
from beltsim.problem import analytic
from beltsim.problem.scene import Scene

pytestmark = pytest.mark.unit


def _scene(L, x1f, x2f, h, w, E, nu, k, dens, cfrac, e0, fstar, inertia, friction):
    data = {
        "beam": {"length": L, "height": h, "width": w, "youngs_modulus": E,
                 "poisson_ratio": nu, "density": dens, "shear_factor": k},
        "motion": {"belt_speed": 1.0, "surface_speed": 1.0},
        "contact": {"start": x1f * L, "end": x2f * L, "friction": friction},
        "physics": {"inertia": inertia},
    }
    if friction == "coulomb":
        data["contact"]["max_friction"] = fstar
    # speed as a fraction of the lower critical speed, so every scene stays subcritical
    b1, a = E * w * h, E * w * h**3 / 12
    rho, I = dens * h * w, dens * h * w * (h * h + w * w) / 12
    c = cfrac * min(math.sqrt(b1 / rho), math.sqrt(a / I))
    data["motion"] = {"belt_speed": c, "surface_speed": c * (1 + e0)}
    return Scene(data)


scenes = st.builds(
    _scene,
    L=st.floats(0.5, 3.0), x1f=st.floats(0.1, 0.45), x2f=st.floats(0.55, 0.9),
    h=st.floats(0.02, 0.2), w=st.floats(0.05, 0.3), E=st.floats(1e7, 1e9),
    nu=st.floats(0.0, 0.49), k=st.floats(0.8, 1.2), dens=st.floats(500, 3000),
    cfrac=st.floats(0.05, 0.9),
    e0=st.floats(0.001, 0.03).flatmap(lambda m: st.sampled_from([m, -m])),
    fstar=st.floats(4.0, 7.0).map(lambda p: 10.0**p),
    inertia=st.booleans(), friction=st.sampled_from(["stick", "coulomb"]))


def _solve(scene):
    try:
        return analytic.solve(scene)
    except NoSolutionError:
        assume(False)


def _d(fn, x, dx):
    return (fn(x + dx) - fn(x - dx)) / (2 * dx)


def _d2(fn, x, dx):
    return (fn(x + dx) - 2 * fn(x) + fn(x - dx)) / dx**2


def _field(sol, name, side="right"):
    return lambda x: sol.fields(np.atleast_1d(x), side=side)[name]


def _segments(sol):
    P = sol.params
    pts = sorted({0.0, P.x1, P.x2, P.L} | ({sol.x_star} if sol.model == "slip" else set()))
    return [(a, b) for a, b in zip(pts, pts[1:]) if b - a > 1e-9 * P.L]


def _check_balance(sol):
    P = sol.params
    kmax = max(s.k for s in sol.segments)
    dx = 1e-3 / kmax  # FD truncation O((k dx)^2) = 1e-6 of each term
    th, eps, f = _field(sol, "theta"), _field(sol, "strain"), _field(sol, "friction")
    for a, b in _segments(sol):
        if b - a < 10 * dx:
            continue
        xs = np.linspace(a + 3 * dx, b - 3 * dx, 7)
        r1 = P.B * _d(eps, xs, dx) + f(xs)
        scale1 = np.abs(P.B * _d(eps, xs, dx)).max() + np.abs(f(xs)).max() + 1e-12
        assert np.abs(r1).max() <= 1e-4 * scale1 + 1e-9 * P.B * abs(P.e0)
        t2 = P.A * _d2(th, xs, dx)
        t0 = P.b2 * th(xs)
        r2 = t2 - t0 + 0.5 * P.h * f(xs)
        scale2 = np.abs(t2).max() + np.abs(t0).max() + 1e-12
        assert np.abs(r2).max() <= 1e-4 * scale2
        mid = 0.5 * (a + b)
        in_stick = P.x1 < mid < (sol.x_star if sol.model == "slip" else P.x2)
        if in_stick:
            stick = eps(xs) + 0.5 * P.h * _d(th, xs, dx) - P.e0
            assert np.abs(stick).max() <= 1e-5 * abs(P.e0)
            if P.fstar is not None:  # Coulomb: |f| <= f* while sticking
                assert np.abs(f(xs)).max() <= P.fstar * (1 + 1e-9)
        elif sol.model == "slip" and P.x1 < mid < P.x2:
            np.testing.assert_allclose(f(xs), math.copysign(P.fstar, P.e0))
    return dx


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(scenes)
def test_solution_satisfies_the_steady_equations(scene):
    sol = _solve(scene)
    P = sol.params
    dx = _check_balance(sol)
    th, eps = _field(sol, "theta"), _field(sol, "strain")
    th_l, eps_l = _field(sol, "theta", "left"), _field(sol, "strain", "left")
    tscale = np.abs(sol.fields(np.linspace(0, P.L, 2001))["theta"]).max() + 1e-15
    # boundary conditions
    assert abs(th(0.0)[0]) <= 1e-10 * tscale and abs(th_l(P.L)[0]) <= 1e-10 * tscale
    # continuity of theta everywhere, of eps and theta' where no force is concentrated
    joints = [P.x1, P.x2] + ([sol.x_star] if sol.model == "slip" else [])
    for x in joints:
        assert abs(th(x)[0] - th_l(x)[0]) <= 1e-9 * tscale
    smooth = [P.x1] + ([sol.x_star, P.x2] if sol.model == "slip" else [])
    ends = sorted({0.0, P.L, *joints})
    for x in smooth:
        assert abs(eps(x)[0] - eps_l(x)[0]) <= 1e-9 * abs(P.e0)
        # one-sided second-order differences of theta on each side, each stencil inside
        # its own segment: across the next joint theta'' jumps (by h f* / (2 A) at x2),
        # and a short slip zone (large f*) is narrower than 2 dx
        i = ends.index(x)
        dr = min(dx, (ends[i + 1] - x) / 3)
        dl = min(dx, (x - ends[i - 1]) / 3)
        right = (-3 * th(x) + 4 * th(x + dr) - th(x + 2 * dr)) / (2 * dr)
        left = (3 * th_l(x) - 4 * th_l(x - dl) + th_l(x - 2 * dl)) / (2 * dl)
        assert abs(right[0] - left[0]) <= 1e-4 * (abs(right[0]) + tscale / P.L)
    if sol.model == "stick":
        F, x2 = sol.concentrated_force, P.x2
        assert eps(x2)[0] - eps_l(x2)[0] == pytest.approx(-F / P.B, rel=1e-7, abs=1e-12)
        right = (-3 * th(x2) + 4 * th(x2 + dx) - th(x2 + 2 * dx)) / (2 * dx)
        left = (3 * th_l(x2) - 4 * th_l(x2 - dx) + th_l(x2 - 2 * dx)) / (2 * dx)
        jump = right[0] - left[0]
        assert jump == pytest.approx(-0.5 * P.h * F / P.A, rel=1e-4,
                                     abs=1e-6 * tscale / P.L)
    # material length: the integral of the strain vanishes
    segs = _segments(sol)
    integral = sum(quad(lambda x: eps(x)[0], a, b, epsabs=0, epsrel=1e-11, limit=200)[0]
                   for a, b in segs)
    assert abs(integral) <= 1e-8 * abs(P.e0) * P.L
    # friction totals: the integral of f plus F, and the global balance
    f_int = sum(quad(lambda x: _field(sol, "friction")(x)[0], a, b, epsrel=1e-10,
                     limit=200)[0] for a, b in segs)
    assert sol.total_friction == pytest.approx(f_int + sol.concentrated_force, rel=1e-7,
                                               abs=1e-9 * P.B * abs(P.e0))
    balance = P.B * (eps(0.0)[0] - eps_l(P.L)[0])
    assert balance == pytest.approx(sol.total_friction, rel=1e-8, abs=1e-12 * P.B)
    # the friction pushes the belt towards the surface's speed
    assert math.copysign(1, sol.total_friction) == math.copysign(1, P.e0)


def test_table1_values():
    """The paper's Table 1, to its rounding (N)."""
    qs, inert = analytic.solve(paper_scene("quasistatic")), analytic.solve(paper_scene("inertia"))
    slip = analytic.solve(paper_scene("slip"))
    assert (round(qs.concentrated_force), round(qs.distributed_friction),
            round(qs.total_friction)) == (6482, 6237, 12719)
    assert (round(inert.concentrated_force), round(inert.distributed_friction),
            round(inert.total_friction)) == (2024, 5375, 7398)
    assert (round(slip.slip_friction), round(slip.stick_friction),
            round(slip.total_friction)) == (3253, 3870, 7124)


def test_slip_tends_to_stick_as_friction_limit_grows():
    stick = analytic.solve(paper_scene("slip"), model="stick")
    x2 = stick.params.x2
    prev_len, prev_gap = math.inf, math.inf
    for fs in (1e5, 1e6, 1e7, 1e8, 1e9):
        s = analytic.solve(paper_scene("slip", [f"contact.max_friction={fs}"]))
        length, gap = x2 - s.x_star, stick.total_friction - s.total_friction
        assert 0 < length < prev_len and 0 < gap < prev_gap
        # the slip zone carries what the concentrated force carried: f* (x2 - x*) -> F
        assert s.slip_friction == pytest.approx(fs * length)
        prev_len, prev_gap = length, gap
    # the gap shrinks like 1/f*: at 1e9 it is ~1e-4 of its value at 1e5
    assert gap < 1e-5 * stick.total_friction
    assert s.slip_friction == pytest.approx(stick.concentrated_force, rel=1e-3)


def test_equal_speeds_give_the_zero_state_and_reversal_mirrors():
    for model in ("stick", "slip"):
        zero = analytic.solve(paper_scene("slip", ["motion.surface_speed=120"]), model=model)
        f = zero.fields(np.linspace(0, 1, 101))
        assert all(np.all(v == 0) for v in f.values()) and zero.total_friction == 0
        fwd = analytic.solve(paper_scene("slip", ["motion.surface_speed=121.2"]), model=model)
        back = analytic.solve(paper_scene("slip", ["motion.surface_speed=118.8"]), model=model)
        x = np.linspace(0, 1, 301)
        for name in ("u", "theta", "strain", "friction"):
            np.testing.assert_allclose(back.fields(x)[name], -fwd.fields(x)[name],
                                       atol=1e-12 * np.abs(fwd.fields(x)[name]).max())
        if model == "slip":
            assert back.x_star == pytest.approx(fwd.x_star, abs=1e-12)


def test_full_slip_when_the_limit_is_low():
    s = analytic.solve(paper_scene("slip", ["contact.max_friction=1e4"]))
    assert s.full_slip and s.x_star == s.params.x1
    assert s.total_friction == pytest.approx(1e4 * (s.params.x2 - s.params.x1))


# Slip power ------------------------------------------------------------------------------
# theta' comes from the Chebyshev interpolant of the sampled theta on one smooth segment
# (theta is a sum of exponentials there, so the interpolant converges spectrally), never
# from the solution's own derivative formulas.


def _theta_prime(sol, a, b, n=64):
    nodes = np.polynomial.chebyshev.chebpts2(n)
    x = a + 0.5 * (b - a) * (nodes + 1.0)
    # theta is continuous at the joints, so the segment's end values need no side
    fit = np.polynomial.Chebyshev.fit(x, sol.fields(x)["theta"], n - 1, domain=[a, b])
    return fit.deriv()


def _sliding_integral(sol, a, b, epsabs=0.0):
    """The integral over [a, b] of |f| |eps_b - e0|, eps_b = strain + (h/2) theta'."""
    P = sol.params
    dth = _theta_prime(sol, a, b)

    def integrand(x):
        fl = sol.fields(np.atleast_1d(x))
        return abs(fl["friction"][0]) * abs(fl["strain"][0] + 0.5 * P.h * dth(x) - P.e0)

    return quad(integrand, a, b, epsabs=epsabs, epsrel=1e-13, limit=500)[0]


def _balance_power(sol):
    """c e0 F_tot + (c/2) [B eps^2 + A theta'^2] from 0 to L, F_tot = B (eps(0) - eps(L))."""
    P = sol.params
    eps0 = sol.fields(np.array([0.0]))["strain"][0]
    epsL = sol.fields(np.array([P.L]), side="left")["strain"][0]
    dth0 = _theta_prime(sol, 0.0, P.x1)(0.0)
    dthL = _theta_prime(sol, P.x2, P.L)(P.L)
    return P.c * (P.e0 * P.B * (eps0 - epsL)
                  + 0.5 * (P.B * (epsL**2 - eps0**2) + P.A * (dthL**2 - dth0**2)))


def _stick_power(sol):
    P = sol.params
    return 0.5 * P.c * sol.concentrated_force**2 * (1 / P.B + P.h**2 / (4 * P.A))


SLIP_SCENES = {
    "paper": [],
    "reversed": ["motion.surface_speed=119.9"],  # belt at 120 m/s: e0 < 0, short slip zone
    "full_slip": ["contact.max_friction=1e4"],
}


@pytest.mark.parametrize("name", SLIP_SCENES)
def test_slip_power_is_the_integral_of_the_sliding_power(name):
    sol = analytic.solve(paper_scene("slip", SLIP_SCENES[name]))
    P = sol.params
    assert sol.full_slip == (name == "full_slip")
    assert (P.e0 < 0) == (name == "reversed")
    power = P.c * _sliding_integral(sol, sol.x_star, P.x2)
    assert sol.slip_power > 0
    assert sol.slip_power == pytest.approx(power, rel=1e-8)
    assert sol.summary()["slip_power"] == sol.slip_power
    # the global balance of the steady equations accounts for all of it
    assert sol.slip_power == pytest.approx(_balance_power(sol), rel=1e-8)


@pytest.mark.parametrize("name", ["quasistatic", "inertia", "slip"])
def test_adhesion_dissipates_only_at_the_concentrated_force(name):
    sol = analytic.solve(paper_scene(name), model="stick")
    P = sol.params
    assert sol.slip_power == pytest.approx(_stick_power(sol), rel=1e-12)
    assert sol.summary()["slip_power"] == sol.slip_power > 0
    # no sliding where the distributed traction acts (the integrand is round-off)
    tol = 1e-9 * sol.slip_power
    assert P.c * _sliding_integral(sol, P.x1, P.x2, epsabs=0.1 * tol / P.c) <= tol
    # the jump at x2 dissipates what the global balance says is missing
    assert sol.slip_power == pytest.approx(_balance_power(sol), rel=1e-8)


def test_slip_power_tends_to_the_adhesion_value_as_the_limit_grows():
    stick = analytic.solve(paper_scene("slip"), model="stick").slip_power
    prev = math.inf
    gaps = {}
    for fs in (1e5, 1e6, 1e7, 1e8, 1e9):
        sol = analytic.solve(paper_scene("slip", [f"contact.max_friction={fs}"]))
        gaps[fs] = stick - sol.slip_power
        assert 0 < gaps[fs] < prev
        prev = gaps[fs]
    # the gap shrinks like 1/f*, as the slip zone's width F/f*
    assert gaps[1e9] * 1e9 == pytest.approx(gaps[1e8] * 1e8, rel=1e-2)
    assert gaps[1e9] < 1e-5 * stick


def test_slip_power_of_the_zero_state_and_under_reversal():
    for model in ("stick", "slip"):
        zero = analytic.solve(paper_scene("slip", ["motion.surface_speed=120"]), model=model)
        assert zero.slip_power == 0.0
        fwd = analytic.solve(paper_scene("slip", ["motion.surface_speed=121.2"]), model=model)
        back = analytic.solve(paper_scene("slip", ["motion.surface_speed=118.8"]), model=model)
        assert back.slip_power == pytest.approx(fwd.slip_power, rel=1e-12)
