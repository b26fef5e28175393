"""Serpentine drives: the geometry of a belt on N pulleys and the string's creep theory on
it, against closed forms, the two-pulley theory and balances computed here from the
returned tension field by quadrature (never from the solution's own formulas)."""

import math
from dataclasses import replace

import numpy as np
import pytest

from beltsim.beltdrive.analytic import GrossSlipError, LiftOffError, capacity, solve_string
from beltsim.beltdrive.creep import SerpentineData, Tensioner, solve_serpentine
from beltsim.beltdrive.figures import figure_keys
from beltsim.beltdrive.geometry import Geometry, GeometryError
from beltsim.beltdrive.pulleys import Pulley, PulleyLayout
from beltsim.beltdrive.scene import DriveScene
from beltsim.errors import NoSolutionError
from helpers import scene_path

pytestmark = pytest.mark.unit

GX, GW = np.polynomial.legendre.leggauss(40)


def gauss(fun, breaks):
    """Integral of fun over [breaks[0], breaks[-1]], Gauss-Legendre on each piece (fun's
    last axis runs over the nodes)."""
    total = 0.0
    for a, b in zip(breaks[:-1], breaks[1:]):
        if b > a:
            x = 0.5 * (b - a) * GX + 0.5 * (a + b)
            total = total + 0.5 * (b - a) * np.sum(GW * fun(x), axis=-1)
    return total


def two(R1, R2, C, names=("driver", "driven")):
    return [Pulley(names[0], (0.0, 0.0), R1, 1), Pulley(names[1], (C, 0.0), R2, 1)]


def mirrored(pulleys):
    return [replace(p, centre=(p.centre[0], -p.centre[1])) for p in pulleys]


# a five-pulley serpentine: crank (driver), pump, alternator, a back-side idler pressing
# into the alternator -> air-conditioning span, air conditioning; listed counterclockwise
FIVE = [Pulley("crank", (0.0, 0.0), 0.09, 1), Pulley("pump", (0.30, -0.05), 0.06, 1),
        Pulley("alt", (0.35, 0.28), 0.03, 1), Pulley("idler", (0.10, 0.33), 0.03, -1),
        Pulley("ac", (-0.15, 0.30), 0.05, 1)]
LOADS = (0.0, 5.0, 2.0, 0.0, 2.0)
B1, RHO, N0, OMEGA = 1.2e5, 0.288, 600.0, 100.0


def five(mu=0.5, rho=RHO, loads=LOADS, n0=N0, tensioner=None, pulleys=FIVE):
    return SerpentineData(PulleyLayout(pulleys), B1, rho, mu, n0, 0, OMEGA, loads, tensioner)


# geometry -------------------------------------------------------------------------

@pytest.mark.parametrize("r1, r2, c", [(0.08, 0.16, 0.6), (0.2, 0.05, 0.5), (0.1, 0.1, 0.3)])
def test_two_pulleys_are_the_open_drive(r1, r2, c):
    g, lay = Geometry(r1, r2, c), PulleyLayout(two(r1, r2, c))
    assert lay.sense == 1
    np.testing.assert_allclose(lay.wraps, g.wraps, rtol=1e-14)
    np.testing.assert_allclose(lay.spans, g.span, rtol=1e-14)
    np.testing.assert_allclose(lay.lengths, g.lengths, rtol=1e-14)
    np.testing.assert_allclose(lay.bounds, g.bounds, rtol=1e-14, atol=1e-15)
    x = np.linspace(-0.3, 2.0 * g.loop_length, 20001)  # the same origin, modulo the loop
    for a, b in zip(lay.path(x), g.path(x)):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-14)
    np.testing.assert_array_equal(lay.segment_of(x), g.segment_of(x))


def test_equilateral_triangle():
    side, r = 0.7, 0.12
    tri = [Pulley("a", (0.0, 0.0), r, 1), Pulley("b", (side, 0.0), r, 1),
           Pulley("c", (0.5 * side, 0.5 * math.sqrt(3) * side), r, 1)]
    for pulleys, sense in ((tri, 1), (tri[::-1], -1), (mirrored(tri), -1)):
        lay = PulleyLayout(pulleys)
        assert lay.sense == sense
        np.testing.assert_allclose(lay.wraps, 2 * math.pi / 3, rtol=1e-14)
        np.testing.assert_allclose(lay.spans, side, rtol=1e-14)
        assert lay.loop_length == pytest.approx(3 * side + 2 * math.pi * r, rel=1e-14)


def idler_drive(R, C, r, depth, names=("A", "idler", "B")):
    """Two equal inner pulleys and a back-side idler under the bottom span's middle,
    pushing it up by ``depth`` (negative: clear of it)."""
    return [Pulley(names[0], (0.0, 0.0), R, 1),
            Pulley(names[1], (0.5 * C, -R - r + depth), r, -1),
            Pulley(names[2], (C, 0.0), R, 1)]


@pytest.mark.parametrize("R, C, r, depth", [(0.1, 0.8, 0.04, 0.03), (0.05, 0.5, 0.08, 0.1)])
def test_back_side_idler_by_hand(R, C, r, depth):
    lay = PulleyLayout(idler_drive(R, C, r, depth))
    # The span from A to the idler is their cross tangent: it passes through the internal
    # homothety centre H, which divides the centre line in the ratio R : r. From H the
    # tangent to A's circle makes asin(R / |AH|) with the line AH; the belt rises by
    # theta = (angle of AH) + asin(R / |AH|) above the horizontal.
    P = np.array([0.5 * C, -R - r + depth])
    H = P * R / (R + r)
    AH = math.hypot(*H)
    theta = math.atan2(H[1], H[0]) + math.asin(R / AH)
    span = math.sqrt(AH**2 - R**2) + math.sqrt((AH * r / R) ** 2 - r**2)
    # A's wrap grows from pi by theta (the belt leaves it theta later), B's likewise by
    # symmetry, and the idler turns the belt by 2 theta
    np.testing.assert_allclose(lay.wraps, [math.pi + theta, 2 * theta, math.pi + theta],
                               rtol=1e-13)
    np.testing.assert_allclose(lay.spans, [span, span, C], rtol=1e-13)
    assert lay.wraps[0] + lay.wraps[2] - lay.wraps[1] == pytest.approx(2 * math.pi, rel=1e-14)
    # the belt touches each circle: its points on the spans keep at least the radius
    x = np.linspace(0.0, lay.loop_length, 200001)
    X, Y = lay.path(x)
    for p in lay.pulleys:
        gap = np.hypot(X - p.centre[0], Y - p.centre[1]) - p.radius
        assert gap.min() > -1e-12 and np.abs(gap).min() < 1e-12


def random_layout(rng):
    """Inner pulleys round a circle and back-side idlers pushed into some of their spans."""
    n_in = int(rng.integers(2, 6))
    ang = np.sort(rng.uniform(0, 2 * math.pi, n_in))
    out = []
    for k in range(n_in):
        r = rng.uniform(0.05, 0.25)
        out.append(Pulley(f"p{k}", (math.cos(ang[k]), math.sin(ang[k])), r, 1))
    full = []
    for k, p in enumerate(out):
        full.append(p)
        if len(out) + len(full) - k - 1 < 7 and rng.random() < 0.5:
            q = out[(k + 1) % n_in]
            mid = 0.5 * (np.array(p.centre) + np.array(q.centre))
            normal = mid / np.hypot(*mid) if np.hypot(*mid) > 1e-9 else np.array([0.0, 1.0])
            rb = rng.uniform(0.03, 0.12)
            reach = 0.5 * (p.radius + q.radius) + rb - rng.uniform(0.0, 0.2)
            c = mid + normal * reach
            full.append(Pulley(f"b{k}", (c[0], c[1]), rb, -1))
    return full if rng.random() < 0.5 else full[::-1]


def test_random_layouts_close_and_turn_once():
    rng = np.random.default_rng(7)
    valid = 0
    for _ in range(400):
        pulleys = random_layout(rng)
        if not 3 <= len(pulleys) <= 7:
            continue
        try:
            lay = PulleyLayout(pulleys)
        except GeometryError:
            continue
        valid += 1
        sides = np.array([p.side for p in pulleys])
        assert np.all(lay.wraps > 0)
        assert np.sum(lay.wraps[sides > 0]) - np.sum(lay.wraps[sides < 0]) \
            == pytest.approx(2 * math.pi, abs=1e-12)
        x = np.linspace(0.0, lay.loop_length, 100001)
        X, Y = lay.path(x)
        steps = np.hypot(np.diff(X), np.diff(Y))
        # continuous, at unit speed in x, closed, and turning once in the listed sense
        assert np.max(np.abs(steps / np.diff(x) - 1.0)) < 1e-6
        assert math.hypot(X[-1] - X[0], Y[-1] - Y[0]) < 1e-12
        heading = np.unwrap(np.arctan2(np.diff(Y), np.diff(X)))
        turned = heading[-1] - heading[0]
        assert turned == pytest.approx(2 * math.pi * lay.sense, abs=1e-3)
        # the mirror image, read in the other sense, has the same lengths
        mir = PulleyLayout(mirrored(pulleys), sense=-lay.sense)
        np.testing.assert_allclose(mir.lengths, lay.lengths, rtol=1e-12)
        np.testing.assert_allclose(np.stack(mir.path(x)), np.stack([X, -Y]), atol=1e-13)
        # and read by itself it takes the other sense (the listing's sense flips)
        assert PulleyLayout(mirrored(pulleys)).sense == -lay.sense
    assert valid >= 40


# a pentagon's corners listed as a star: every turn is positive and below pi, but the
# belt would cross itself (and turn twice)
STAR = [Pulley(f"s{k}", (math.cos(0.4 * math.pi * (2 * k % 5)),
                         math.sin(0.4 * math.pi * (2 * k % 5))), 0.05, 1) for k in range(5)]


@pytest.mark.parametrize("pulleys, key, rule", [
    (two(0.1, -0.1, 0.5), "pulley 'driven'.radius", "> 0"),
    (two(0.1, 0.2, 0.25), "pulley 'driven'.centre", "overlaps"),
    ([Pulley("a", (0.0, 0.0), 0.25, 1), Pulley("b", (0.5, 0.0), 0.25, -1)],
     "pulley 'b'.centre", "no common tangent"),
    (STAR, ".centre", "crosses"),
    ([Pulley("a", (0, 0), 0.1, 1), Pulley("b", (1, 1), 0.1, 1), Pulley("c", (1, 0), 0.1, 1),
      Pulley("d", (0, 1), 0.1, 1)], "pulley 'b'.side", "spans cross"),
    (idler_drive(0.1, 0.8, 0.05, 0.0), "pulley 'idler'.centre", "wrap <= 0"),
    (idler_drive(0.1, 0.8, 0.05, -0.02), "pulley 'idler'.side", "bend against"),
    ([Pulley("a", (0.0, 0.0), 0.1, 1)], "pulleys", "at least 2"),
    (two(0.1, 0.1, 0.5, names=("a", "a")), "pulley 'a'.name", "share"),
    (two(0.1, 0.1, 0.5) + [Pulley("mid", (0.25, 0.0), 0.03, 1)],
     "pulley 'mid'.side", "bend against"),
    (two(0.1, 0.1, 2.0) + [Pulley("big", (1.0, 0.3), 0.5, 1)],
     "pulley 'big'.centre", "runs through"),
])
def test_bad_layouts_are_refused(pulleys, key, rule):
    with pytest.raises(GeometryError) as info:
        PulleyLayout(pulleys)
    msg = str(info.value)
    assert key in msg and rule in msg and "\n" not in msg


def test_moved_rebuilds():
    lay = PulleyLayout(FIVE)
    moved = lay.moved(3, (0.1, 0.32))
    direct = PulleyLayout([*FIVE[:3], replace(FIVE[3], centre=(0.1, 0.32)), FIVE[4]])
    np.testing.assert_array_equal(moved.lengths, direct.lengths)
    with pytest.raises(GeometryError, match="pulley 'idler'.side"):
        lay.moved(3, (0.1, 0.40))  # lifted clear of its span


# creep theory: two pulleys ----------------------------------------------------------

@pytest.mark.parametrize("friction, rho, M2", [
    ("coulomb", None, None), ("stick", None, None), ("coulomb", 0.0, 30.0),
    ("coulomb", None, 5.0), ("stick", 0.0, 80.0)])
def test_two_pulleys_are_the_string_solution(friction, rho, M2):
    P = DriveScene.load(scene_path("drive_flat")).params
    P = replace(P, mu=P.mu if friction == "coulomb" else None,
                rho=P.rho if rho is None else rho)
    M2 = P.M2 if M2 is None else M2
    ref = solve_string(P, M2=M2)
    g = P.geometry
    d = SerpentineData(PulleyLayout(two(g.R1, g.R2, g.C)), P.b1, P.rho, P.mu, P.N0, 0,
                       P.omega1, (0.0, M2))
    sol = solve_serpentine(d)
    rel = dict(rtol=1e-12, atol=0)
    np.testing.assert_allclose(sol.tensions, [ref.T2, ref.T1], **rel)  # slack span first
    np.testing.assert_allclose(sol.c, ref.c, **rel)
    np.testing.assert_allclose(sol.phi_s, ref.phi_s, rtol=1e-11, atol=1e-15)
    np.testing.assert_allclose(sol.driver_torque, ref.driver_torque, **rel)
    np.testing.assert_allclose(sol.efficiency, ref.efficiency, **rel)
    np.testing.assert_allclose(sol.speeds, [P.omega1, ref.omega2], **rel)
    np.testing.assert_allclose(sol.slip_power, ref.slip_power, **rel)
    x = np.linspace(0, g.loop_length, 5001)
    np.testing.assert_allclose(sol.tension(x), ref.tension(x), rtol=1e-11)
    if P.mu is not None:  # the driver's margin is the drive's capacity over its load
        assert sol.slip_margins[0] * M2 == pytest.approx(capacity(P), rel=1e-9)


# creep theory: five pulleys ---------------------------------------------------------

def arc_quadrature(sol, i, integrand):
    """Integral over pulley i's arc of integrand(x, N, n, tau): n the outward normal,
    tau the belt's direction, at Gauss nodes, with the slip arc's start as a break."""
    g = sol.layout
    a, b = g.bounds[2 * i], g.bounds[2 * i + 1]
    start = b - g.radii[i] * sol.phi_s[i]
    centre = g.centres[i]

    def fun(x):
        X, Y = g.path(x)
        n = np.stack([X - centre[0], Y - centre[1]]) / g.radii[i]
        # the belt turns in the sense spin_i: tau = spin J n
        tau = g.spin[i] * np.stack([-n[1], n[0]])
        return integrand(x, sol.tension(x), n, tau)

    return gauss(fun, [a, start, b])


@pytest.mark.parametrize("rho, loads", [(0.0, LOADS), (RHO, LOADS),
                                        (RHO, (0.0, 5.0, 2.0, 0.6, 2.0))])
def test_five_pulleys_balances(rho, loads):
    """The last case loads the back-side pulley too (a pump driven by the belt's back)."""
    d = five(rho=rho, loads=loads)
    sol = solve_serpentine(d)
    g, n = sol.layout, len(FIVE)
    c = sol.c
    rc, kappa = rho * c * c, 1 - rho * c * c / B1
    Tin, T = np.roll(sol.tensions, 1), sol.tensions
    mu = np.full(n, 0.5)
    # adhesion at each entry; the driver turns at the given speed
    np.testing.assert_allclose(sol.speeds * g.radii, c * (1 + Tin / B1), rtol=1e-14)
    assert sol.speeds[0] == pytest.approx(OMEGA, rel=1e-14)
    # each pulley's torque is its lever times the friction on its arc, by quadrature of
    # mu p over the slip arc with p = (N - rho c^2) / r
    for i in range(n):
        def fric(x, N, nrm, tau, i=i):
            slip = x > g.bounds[2 * i + 1] - g.radii[i] * sol.phi_s[i]
            return np.where(slip, mu[i] * (N - rc) / g.radii[i], 0.0)
        torque = g.radii[i] * arc_quadrature(sol, i, fric)
        assert torque == pytest.approx(sol.torques[i], rel=1e-10, abs=1e-12)
        if i > 0:
            assert torque == pytest.approx(loads[i], rel=1e-10, abs=1e-12)
    # power: the driver's = delivered + the friction's work on the slip velocity
    # c (1 + N / b1) - omega_i r_i, by quadrature
    slip = 0.0
    for i in range(n):
        def work(x, N, nrm, tau, i=i):
            on = x > g.bounds[2 * i + 1] - g.radii[i] * sol.phi_s[i]
            v_rel = c * (1 + N / B1) - sol.speeds[i] * g.radii[i]
            return np.where(on, mu[i] * (N - rc) / g.radii[i] * np.abs(v_rel), 0.0)
        slip += arc_quadrature(sol, i, work)
    p_in = sol.driver_torque * OMEGA
    p_out = float(np.dot(loads, sol.speeds))
    assert slip == pytest.approx(sol.slip_power, rel=1e-9)
    assert p_in - p_out == pytest.approx(slip, rel=1e-9)
    assert sol.efficiency == pytest.approx(p_out / p_in, rel=1e-14)
    # closure: the integral of N over the loop is b1 (Lambda - L0), L0 = Lambda (1 - N0/b1)
    breaks = np.unique(np.concatenate(
        [g.bounds, g.bounds[1::2] - g.radii * sol.phi_s]))
    integral = gauss(sol.tension, breaks)
    L0 = g.loop_length * (1 - N0 / B1)
    assert integral == pytest.approx(B1 * (g.loop_length - L0), rel=1e-11)
    # hub loads: the contact forces' resultant on each pulley, -(integral of p n + f tau),
    # with f = -kappa N' (the axial balance) on the slip arc
    for i in range(n):
        rate = np.sign(T[i] - Tin[i]) * mu[i] / (kappa * g.radii[i])

        def force(x, N, nrm, tau, i=i, rate=rate):
            on = x > g.bounds[2 * i + 1] - g.radii[i] * sol.phi_s[i]
            dN = np.where(on, rate * (N - rc), 0.0)
            return -((N - rc) / g.radii[i] * nrm - kappa * dN * tau)

        F = arc_quadrature(sol, i, force)
        # exact for rho = 0; with rho > 0 the pressure (N - rho c^2) / r leaves the
        # momentum flux rho c^2 N / b1 out of the resultant: the documented formula
        # differs by (rho c^2 / b1) times the integral of N' tau, below rc |dT| / b1
        bound = rc * abs(T[i] - Tin[i]) / B1 * 1.0001 + 1e-10 * np.hypot(*F)
        assert np.hypot(*(F - sol.hub_loads[i])) <= bound
    # the belt as a whole is in equilibrium: its momentum is rho c times the closed loop's
    # integral of tau, zero, so the hubs' forces on it sum to zero
    assert np.hypot(*sol.hub_loads.sum(axis=0)) < 1e-10 * np.abs(sol.hub_loads).max()


def test_listing_order_and_sense_do_not_matter():
    """The same drive listed from another pulley, or mirrored (listed clockwise), has the
    same span tensions; the mirror's hub loads are the mirror images."""
    ref = solve_serpentine(five())
    names = [p.name for p in FIVE]
    rolled = FIVE[2:] + FIVE[:2]
    d = SerpentineData(PulleyLayout(rolled), B1, RHO, 0.5, N0, 3, OMEGA,
                       LOADS[2:] + LOADS[:2])
    sol = solve_serpentine(d)
    by_name = dict(zip([p.name for p in rolled], sol.tensions))
    np.testing.assert_allclose([by_name[n] for n in names], ref.tensions, rtol=1e-12)
    mir = solve_serpentine(five(pulleys=mirrored(FIVE)))
    assert mir.layout.sense == -1
    np.testing.assert_allclose(mir.tensions, ref.tensions, rtol=1e-12)
    np.testing.assert_allclose(mir.hub_loads, ref.hub_loads * [1, -1], rtol=1e-12,
                               atol=1e-10)
    np.testing.assert_array_equal(mir.layout.spin, -ref.layout.spin)


@pytest.mark.parametrize("change, key", [
    (dict(b1=0.0), "serpentine.b1"), (dict(N0=-1.0), "serpentine.N0"),
    (dict(rho=-1.0), "serpentine.rho"), (dict(driver=7), "serpentine.driver"),
    (dict(loads=(0.0, -1.0, 0.0, 0.0, 0.0)), "serpentine.loads"),
    (dict(loads=(1.0, 1.0, 0.0, 0.0, 0.0)), "serpentine.loads"),
    (dict(mu=(0.5, 0.5)), "serpentine.mu"),
    (dict(tensioner=Tensioner(1, (0.0, 0.0), 1.0, 1.0)), "serpentine.tensioner.index")])
def test_bad_data_are_refused(change, key):
    base = dict(layout=PulleyLayout(FIVE), b1=B1, rho=RHO, mu=0.5, N0=N0, driver=0,
                omega=OMEGA, loads=LOADS)
    with pytest.raises(ValueError, match=key.replace(".", r"\.")):
        SerpentineData(**{**base, **change})


def test_hub_load_of_two_pulleys():
    R1, R2, C = 0.08, 0.16, 0.6
    d = SerpentineData(PulleyLayout(two(R1, R2, C)), B1, 0.0, 0.4, 600.0, 0, 150.0,
                       (0.0, 50.0))
    sol = solve_serpentine(d)
    b = math.asin((R2 - R1) / C)
    T2, T1 = sol.tensions
    # both spans pull the pulleys towards each other, at the angle 2 b between them
    mag = math.sqrt(T1**2 + T2**2 + 2 * T1 * T2 * math.cos(2 * b))
    np.testing.assert_allclose(np.hypot(*sol.hub_loads.T), mag, rtol=1e-14)
    assert sol.hub_loads[0, 0] > 0 and sol.hub_loads[1, 0] < 0


def test_perfect_adhesion_limit():
    stick = solve_serpentine(five(mu=None))
    assert np.all(stick.phi_s == 0) and np.all(np.isinf(stick.slip_margins))
    errors = []
    for mu in (1e3, 1e5):
        near = solve_serpentine(five(mu=mu))
        assert np.all(near.phi_s < 1.0 / mu)
        errors.append(np.max(np.abs(near.tensions / stick.tensions - 1)))
    # the slip arcs shrink like 1 / mu and the tensions converge at that rate
    assert errors[1] < 1e-6 and errors[0] / errors[1] == pytest.approx(100, rel=0.05)


def test_gross_slip_names_the_pulley():
    mu = (0.5, 0.15, 0.5, 0.5, 0.5)  # a slippery pump pulley slips first
    sol = solve_serpentine(five(mu=mu))
    m = sol.slip_margins
    assert np.isinf(m[3]) and m[1] == min(m) and m[1] > 1
    cap = m[1] * LOADS[1]
    with pytest.raises(GrossSlipError) as info:
        solve_serpentine(five(mu=mu, loads=(0.0, cap * (1 + 1e-6), 2.0, 0.0, 2.0)))
    assert "pulley 'pump'" in str(info.value)
    assert info.value.capacity == pytest.approx(cap, rel=1e-9)
    edge = solve_serpentine(five(mu=mu, loads=(0.0, cap * (1 - 1e-6), 2.0, 0.0, 2.0)))
    assert edge.phi_s[1] == pytest.approx(edge.layout.wraps[1], rel=1e-4)
    # the driver (it slips first with one coefficient): all loads scaled by its margin
    # bring its slip arc to its wrap
    sol = solve_serpentine(five())
    lam = sol.slip_margins[0]
    assert lam == min(sol.slip_margins)
    edge = solve_serpentine(five(loads=tuple(np.array(LOADS) * lam * (1 - 1e-7))))
    assert edge.phi_s[0] == pytest.approx(edge.layout.wraps[0], rel=1e-4)
    with pytest.raises(GrossSlipError, match="pulley 'crank'"):
        solve_serpentine(five(loads=tuple(np.array(LOADS) * lam * (1 + 1e-7))))


def test_lift_off_names_the_span():
    with pytest.raises(LiftOffError, match="span 'crank'->'pump'"):
        solve_serpentine(five(mu=None, n0=40.0, loads=(0.0, 10.0, 3.0, 0.0, 4.0)))


def test_summary_keys():
    s = solve_serpentine(five()).summary()
    assert set(s) == {"spans", "pulleys", "belt_speed", "driver_torque", "efficiency",
                      "slip_power", *figure_keys([p["name"] for p in s["pulleys"]])}
    assert [p["role"] for p in s["pulleys"]] == ["driver", "driven", "driven", "idler",
                                                 "driven"]
    assert set(s["pulleys"][0]) == {"name", "role", "speed", "slip_arc", "slip_margin",
                                    "hub_load", "torque", "slip_power", "wrap"}
    assert s["spans"][0] == {"from": "crank", "to": "pump",
                             "tension": pytest.approx(s["spans"][0]["tension"])}


# tensioner --------------------------------------------------------------------------

PIVOT = (0.18, 0.40)


@pytest.mark.parametrize("stiffness, preload", [(20.0, 16.0), (5.0, 12.0), (80.0, 25.0)])
def test_tensioner_equilibrium(stiffness, preload):
    ten = Tensioner(3, PIVOT, stiffness, preload)
    sol = solve_serpentine(five(tensioner=ten))
    O = np.array(PIVOT)
    arm0 = np.array(FIVE[3].centre) - O
    a, alpha0 = math.hypot(*arm0), math.atan2(arm0[1], arm0[0])

    def layout(alpha):
        P = O + a * np.array([math.cos(alpha), math.sin(alpha)])
        return PulleyLayout([*FIVE[:3], replace(FIVE[3], centre=tuple(P)), FIVE[4]])

    # the sense s that lengthens the loop, by a central difference
    h = 1e-6
    s = np.sign(layout(alpha0 + h).loop_length - layout(alpha0 - h).loop_length)
    assert sol.sense_tensioner == s
    lay = layout(sol.alpha)
    assert lay.loop_length == pytest.approx(sol.layout.loop_length, rel=1e-14)
    # the belt's force on the idler from the solution's tensions and this geometry
    c = sol.c
    T = sol.tensions
    t = lay.span_directions
    F = (T[3] - RHO * c * c) * t[3] - (T[2] - RHO * c * c) * t[2]
    arm = lay.centres[3] - O
    moment = arm[0] * F[1] - arm[1] * F[0]
    spring = s * preload - stiffness * (sol.alpha - alpha0)
    assert abs(spring + moment) < 1e-9 * abs(moment)
    # the belt's unstretched length is the drawn layout's
    L0 = PulleyLayout(FIVE).loop_length * (1 - N0 / B1)
    g = sol.layout
    breaks = np.unique(np.concatenate([g.bounds, g.bounds[1::2] - g.radii * sol.phi_s]))
    assert gauss(sol.tension, breaks) == pytest.approx(B1 * (lay.loop_length - L0),
                                                        rel=1e-11)


def test_tensioner_without_equilibrium():
    ten = Tensioner(3, PIVOT, 1.0, -40.0)  # a spring pulling the idler off the belt
    with pytest.raises(NoSolutionError, match="tensioner: no equilibrium"):
        solve_serpentine(five(tensioner=ten))
