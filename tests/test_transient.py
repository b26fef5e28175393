"""The simulated transient against the exact one of the thin quasistatic belt.

beltsim.problem.transient derives the total friction against time of the limit
inertia = false, h -> 0 with a, b1, b2 held fixed (an axially moving bar): closed forms
for perfect adhesion, a scalar root x*(t) for Coulomb friction. Here that solution is
checked against the bar's equations themselves (finite differences, not its formulas),
against its ODE by a separate integrator and against the exact steady solution, and
then the simulation is shown to converge to it in the grid and in time.

Scenes: the paper's (the shipped paper_slip, f* = 1e5 N/m, and
paper_quasistatic, perfect adhesion), quasistatic, h = 1e-6 m, and
[stiffness] a = E w h^3/12, b1 = E w h, b2 = k E w h/(2 (1 + nu)) of the paper's
h = 0.1 m. The history's checks are every 2^-11 s (about L/(17 c); the default L/(4c)
gives only 8 checks in the ramp): binary, so fixed steps 2^-k end on every check.
"""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import beltsim
from beltsim.problem.drive import ramp
from beltsim.problem.transient import (
    THIN_TOL,
    thin_belt,
    thin_belt_transient,
    thin_parameter,
)
from helpers import scene_path

SNAP = 2.0**-11  # check interval (s)
T_SHORT = 80 * SNAP  # 0.039 s: the ramp (T = 2 L / c = 0.0167 s) and most of the relaxation


def _paper_stiffness():
    P = beltsim.load_scene(scene_path("paper_slip")).params  # h = 0.1 m
    return [f"stiffness.bending={P.a!r}", f"stiffness.tension={P.b1!r}",
            f"stiffness.shear={P.b2!r}"]


THIN = ["physics.inertia=false", "beam.height=1e-6", *_paper_stiffness()]
SCENES = {"coulomb": "paper_slip", "stick": "paper_quasistatic"}


def thin_scene(kind, *overrides):
    return beltsim.load_scene(scene_path(SCENES[kind]), [*THIN, *overrides])


def _run(kind, elements, *overrides):
    scene = thin_scene(kind, "numerics.grading=1", f"numerics.elements={elements}",
                       f"numerics.snapshot_interval={SNAP!r}", *overrides)
    return scene, beltsim.Simulation(scene).run()


def history_error(scene, result):
    """max over the checks of |simulated - exact total friction| / |steady total friction|."""
    exact = thin_belt(scene)
    t = result.history["t"]
    ref = exact.history(t)["total_friction"]
    return float(np.max(np.abs(result.history["total_friction"] - ref))
                 / abs(exact.steady()["total_friction"]))


# ---------------------------------------------------------------------------
# the exact solution, independently of its derivation


@pytest.mark.unit
@pytest.mark.parametrize("ramp_time", [None, 1e-3, 0.0])
def test_inlet_strain_solves_its_ode(ramp_time):
    """x1 eps_in' = (v(t) - c) - c eps_in by DOP853 against the closed form (T = 2L/c,
    q = x1/(c T) = 1/6), the quadrature (T = 1e-3 s, q = 2.8) and the step (T = 0)."""
    extra = [] if ramp_time is None else [f"numerics.ramp_time={ramp_time}"]
    scene = thin_scene("coulomb", *extra)
    exact, P = thin_belt(scene), scene.params
    t = np.linspace(0.0, 0.05, 201)

    def rhs(s, y):
        return (exact.mismatch(s) - P.c * y) / P.x1

    # the ramp and the rest apart: the third derivative of v(t) jumps at T
    y = np.zeros_like(t)
    start, y0 = 0.0, [0.0]
    for stop in ([exact.T] if exact.T > 0 else []) + [0.05]:
        sol = solve_ivp(rhs, (start, stop), y0, method="DOP853", rtol=1e-13, atol=1e-18,
                        dense_output=True, max_step=(stop - start) / 50)
        inside = (t >= start) & (t <= stop)
        y[inside] = sol.sol(t[inside])[0]
        start, y0 = stop, sol.y[:, -1]
    # measured 8e-14 (the integrator's round-off)
    assert np.max(np.abs(y - exact.inlet_strain(t))) <= 1e-12 * abs(P.e0)


@pytest.mark.unit
def test_drive_and_ramp_time_are_the_simulations():
    scene = thin_scene("coulomb")
    exact, sim = thin_belt(scene), beltsim.Simulation(scene)
    assert exact.T == sim.numerics.ramp_time
    t = np.linspace(-0.01, 0.03, 57)
    P = scene.params
    drive = np.array([(P.v - P.c) * ramp(s, exact.T) for s in t])
    np.testing.assert_allclose(exact.mismatch(t), drive, rtol=1e-14, atol=1e-15)


CASES = [("coulomb", ()), ("coulomb", ("motion.surface_speed=118.8",)),
         ("coulomb", ("numerics.ramp_time=1e-3",)), ("stick", ()),
         ("stick", ("motion.surface_speed=118.8",))]


@pytest.mark.unit
@pytest.mark.parametrize("kind,extra", CASES)
def test_fields_satisfy_the_bar_equations(kind, extra):
    """Finite differences of the exact u(x, t): b1 u_xx + f = 0, v_rel = 0 in stick,
    sliding against f in slip, |f| <= f*, u(0) = u(L) = 0, u and u_x continuous (except
    u_x at x2 under perfect adhesion, where [[b1 u_x]] = -F), total = int f + F."""
    scene = thin_scene(kind, *extra)
    exact, P = thin_belt(scene), scene.params
    s, e0 = exact.s, abs(P.e0)
    dx, dt = 1e-4, 1e-7

    def u(x, t):
        return exact.fields(x, t)["u"]

    x_stars = []
    for t in [0.001, 0.004, 0.01, 0.017, 0.03, 0.06]:
        H = exact.history([t])
        xs = H["slip_start"][0] if kind == "coulomb" else P.x2
        x_stars.append(xs)
        zones = [(0.0, P.x1, "free"), (P.x1, xs, "stick"), (xs, P.x2, "slip"),
                 (P.x2, P.L, "free")]
        for lo, hi, zone in zones:
            if hi - lo < 3e-3:
                continue
            x = np.linspace(lo + 1e-3, hi - 1e-3, 40)
            fld = exact.fields(x, t)
            uxx = (u(x + dx, t) - 2 * u(x, t) + u(x - dx, t)) / dx**2
            ux = (u(x + dx, t) - u(x - dx, t)) / (2 * dx)
            ut = (u(x, t + dt) - u(x, t - dt)) / (2 * dt)
            vrel = ut + P.c * ux - exact.mismatch(t)
            # FD truncation and round-off: measured 1e-6 and 7e-8 at most
            assert np.max(np.abs(P.b1 * uxx + fld["friction"])) <= 1e-5 * P.b1 * e0 / P.L
            assert np.max(np.abs(ux - fld["strain"])) <= 1e-6 * e0
            if zone == "stick":
                assert np.max(np.abs(vrel)) <= 1e-6 * P.c * e0
                assert np.all(s * fld["friction"] >= 0.0)
                if kind == "coulomb":
                    assert np.max(np.abs(fld["friction"])) < P.fstar
            if zone == "slip":
                assert np.all(s * vrel < 0.0)  # the belt slides against its traction s f*
        assert np.max(np.abs(u(np.array([0.0, P.L]), t))) <= 1e-13 * e0 * P.L
        joints = [P.x1] + ([xs, P.x2] if kind == "coulomb" else [])
        for xj in joints:
            side = exact.fields(np.array([xj - 1e-9, xj + 1e-9]), t)
            assert abs(np.diff(side["u"])[0]) <= 1e-8 * e0 * P.L
            assert abs(np.diff(side["strain"])[0]) <= 1e-7 * e0
        F = H.get("concentrated_force", [0.0])[0]
        if kind == "stick":
            side = exact.fields(np.array([P.x2 - 1e-9, P.x2 + 1e-9]), t)
            assert P.b1 * np.diff(side["strain"])[0] == pytest.approx(-F, rel=1e-7)
        # Gauss-Legendre on pieces where f is smooth: f jumps at x*, and its derivatives
        # where the material entered at t = 0 and t = T
        cuts = [P.x1 + P.c * t, P.x1 + P.c * (t - exact.T)]
        ends = sorted({P.x1, xs, P.x2, *(x for x in cuts if P.x1 < x < xs)})
        xg, wg = np.polynomial.legendre.leggauss(40)
        integral = sum(0.5 * (hi - lo) * wg @ exact.fields(lo + 0.5 * (hi - lo) * (xg + 1), t)
                       ["friction"] for lo, hi in zip(ends, ends[1:]))
        assert integral + F == pytest.approx(H["total_friction"][0], rel=1e-9)
    if kind == "coulomb":
        assert np.all(np.diff(x_stars) <= 0.0)  # the slip zone grows (monotone loading)


@pytest.mark.unit
@pytest.mark.parametrize("kind", ["coulomb", "stick"])
def test_steady_limit_is_the_steady_solution(kind):
    """Late times tend to beltsim.solve of the same thin scene (derived independently);
    its deviation is O(eta) = 3e-10 relative (the scene's h = 1e-6 m), measured 2e-11."""
    scene = thin_scene(kind)
    exact, steady = thin_belt(scene), beltsim.solve(scene)
    late = thin_belt_transient(scene, [1.0])
    assert late["total_friction"][0] == pytest.approx(steady.total_friction, rel=1e-9)
    assert exact.steady()["total_friction"] == pytest.approx(steady.total_friction, rel=1e-9)
    if kind == "coulomb":
        assert late["slip_start"][0] == pytest.approx(steady.x_star, abs=1e-9)
    else:
        assert late["concentrated_force"][0] == pytest.approx(steady.concentrated_force,
                                                              rel=1e-9)


@pytest.mark.unit
@pytest.mark.parametrize("overrides,key", [
    (("physics.inertia=true",), "physics.inertia"),
    (("beam.height=0.1",), "beam.height"),  # the paper's h with [stiffness]: eta = 3
    (("contact.max_friction=2e4",), "contact.max_friction"),  # slides everywhere in the end
    (("contact.start=0.05", "contact.end=0.9", "numerics.ramp_time=0", "contact.max_friction=5e4"),
     "contact.max_friction"),  # stick traction b1 e0 / x1 = 1e5 N/m at once: above f*
    (("contact.max_friction=[[0.0, 1e6], [0.1, 5e5]]",), "contact.max_friction"),  # profile
])
def test_scenes_outside_the_limit_are_refused(overrides, key):
    scene = thin_scene("coulomb", *overrides)
    with pytest.raises(beltsim.SceneError) as info:
        thin_belt_transient(scene, [0.01])
    assert str(info.value).startswith(key + ":") and "\n" not in str(info.value)


@pytest.mark.unit
def test_thin_needs_the_stiffness_held_fixed():
    """Without [stiffness], a, b1, b2 follow h and b1/a = 12/h^2: eta = 3 whatever h."""
    scene = beltsim.load_scene(scene_path("paper_slip"),
                               ["physics.inertia=false", "beam.height=1e-6"])
    assert thin_parameter(scene.params) == pytest.approx(3.0, rel=1e-9)
    with pytest.raises(beltsim.SceneError, match="^beam.height:"):
        thin_belt(scene)
    assert thin_parameter(thin_scene("coulomb").params) <= THIN_TOL * 1e-3


# ---------------------------------------------------------------------------
# the simulation converges to it
#
# Grid and time step together (grading 1): h and dt halve together, and the error against
# the exact history (max over the checks of |simulated - exact total friction|, relative
# to the steady total friction) falls at the lower of the two orders.
#
# Implicit (BDF2 at a fixed step dt = 2^-13 s on 250 elements, halved with h: time_tol
# 10, so no step is rejected, and a check at every step, so none grows; to T_SHORT)
# with the exact law (numerics.friction_law = "exact": no regularisation floor),
# measured:
#
#   N          250        500        1000       2000
#   coulomb    9.267e-5   2.310e-5   5.964e-6   1.493e-6   orders 2.00 1.95 2.00
#   stick      6.386e-5   1.596e-5   3.989e-6   9.970e-7   orders 2.00 2.00 2.00
#
# the same to 4 digits when run to steady state. With the default tanh law, whose v_reg
# shrinks with the grid, measured with time_tol 1e-9: 3.5e-5, 1.2e-5, 3.0e-6, 8.0e-7
# (coulomb; a fixed v_reg = 1e-4 |v - c| stopped at 4.4e-6 from 1000 elements on).
# Adaptive steps with time_tol / 8 per rung (1e-4 on 250 elements; error ~
# time_tol^(2/3)) give 4.5e-4, 1.3e-4, 3.9e-5, 1.1e-5 (coulomb, exact law, orders 1.84,
# 1.68, 1.81): the time error dominates.
#
# Pseudo (backward Euler, first order in dt; dt = 2^-12 s on 250 elements, halved with
# h; default law), measured:
#
#   coulomb    5.088e-3   2.562e-3   1.286e-3   6.437e-4   orders 0.99 0.99 1.00
#   stick      5.860e-3   2.961e-3   1.492e-3   7.494e-4   orders 0.99 0.99 0.99
#
# The bounds: 25% above the measured errors; implicit orders within 0.2 of 2 (measured
# 1.95-2.00); pseudo, the first-order line through the coarsest error (25% above), a
# least-squares order within 0.1 of 1 and no halving below order 0.8.

LADDER = [250, 500, 1000, 2000]
SECOND_ORDER_LADDER = [250, 500, 1000]  # the 2000 rung of the table adds 10 s for nothing
MEASURED_SECOND_ORDER = {"coulomb": [9.267e-5, 2.310e-5, 5.964e-6],
                         "stick": [6.386e-5, 1.596e-5, 3.989e-6]}
MEASURED_PSEUDO_COARSEST = {"coulomb": 5.088e-3, "stick": 5.860e-3}


@pytest.mark.verification
@pytest.mark.parametrize("kind", ["coulomb", "stick"])
def test_implicit_history_converges_at_second_order_in_grid_and_step(kind):
    errors = []
    for i, n in enumerate(SECOND_ORDER_LADDER):
        step = 2.0 ** (-13 - i)
        scene, result = _run(kind, n, "numerics.integrator=implicit",
                             'numerics.friction_law="exact"', "numerics.time_tol=10.0",
                             f"numerics.dt={step!r}", f"numerics.snapshot_interval={step!r}",
                             f"numerics.t_end={T_SHORT!r}")
        assert result.steps == round(T_SHORT / step)  # fixed steps, none cut or rejected
        errors.append(history_error(scene, result))
    errors = np.array(errors)
    assert np.all(errors <= 1.25 * np.array(MEASURED_SECOND_ORDER[kind])), errors
    orders = np.log2(errors[:-1] / errors[1:])
    assert np.all(np.abs(orders - 2.0) <= 0.2), (errors, orders)


@pytest.mark.verification
@pytest.mark.parametrize("kind", ["coulomb", "stick"])
def test_pseudo_history_converges_at_first_order(kind):
    errors = []
    for i, n in enumerate(LADDER):
        scene, result = _run(kind, n, "numerics.integrator=pseudo",
                             f"numerics.dt={2.0 ** (-12 - i)!r}")
        assert result.converged, result.reason
        t = result.history["t"]
        assert t[0] == pytest.approx(SNAP) and t[-1] > 3 * thin_belt(scene).T
        errors.append(history_error(scene, result))
    errors = np.array(errors)
    bound = 1.25 * MEASURED_PSEUDO_COARSEST[kind] * LADDER[0] / np.array(LADDER)
    assert np.all(errors <= bound), (errors, bound)
    orders = np.log2(errors[:-1] / errors[1:])
    fitted = -np.polyfit(np.log2(LADDER), np.log2(errors), 1)[0]
    assert abs(fitted - 1.0) <= 0.1, (fitted, orders)
    assert np.all(orders >= 0.8), orders


# Time alone, on one grid (250 elements): successive differences of runs whose steps
# halve, compared at their common checks (multiples of the coarsest step), up to
# T_SHORT. Their ratio gives the order without a reference run. The implicit scheme
# runs with time_tol = 10, far above any step's estimated error, so every step is one
# check interval (numerics.dt, the first step, set to it as well): BDF2 at a fixed step.
# Measured differences, relative to the steady total friction:
#   BDF2, steps 2^-10 ... 2^-13:        coulomb 2.498e-3 6.439e-4 1.644e-4 (orders 1.96 1.97)
#                                       stick   2.796e-3 7.217e-4 1.808e-4 (orders 1.95 2.00)
#   backward Euler, dt 2^-11 ... 2^-14: coulomb 5.063e-3 2.588e-3 1.309e-3 (orders 0.97 0.98)
#                                       stick   4.597e-3 2.349e-3 1.188e-3 (orders 0.97 0.98)
# The bounds: orders within 0.15 of 2 and of 1.


def _time_ladder(kind, scheme):
    histories = []
    for p in range(10, 14) if scheme == "implicit" else range(11, 15):
        step = 2.0**-p
        if scheme == "implicit":
            over = ["numerics.time_tol=10.0", f"numerics.snapshot_interval={step!r}",
                    f"numerics.dt={step!r}"]
        else:
            over = [f"numerics.dt={step!r}"]
        scene, result = _run(kind, 250, f"numerics.integrator={scheme}",
                             f"numerics.t_end={T_SHORT!r}", *over)
        assert result.steps == round(T_SHORT / step)  # fixed steps, none cut or rejected
        histories.append((result.history["t"], result.history["total_friction"]))
    common = histories[0][0]  # the coarsest run's checks, also checks of the finer ones
    vals = []
    for t, f in histories:
        idx = np.searchsorted(t, common - 1e-12)
        np.testing.assert_allclose(t[idx], common, rtol=0, atol=1e-12)
        vals.append(f[idx])
    scale = abs(thin_belt(scene).steady()["total_friction"])
    diffs = np.array([np.max(np.abs(a - b)) for a, b in zip(vals, vals[1:])]) / scale
    return diffs, np.log2(diffs[:-1] / diffs[1:])


@pytest.mark.verification
@pytest.mark.parametrize("kind", ["coulomb", "stick"])
def test_implicit_is_second_order_in_time(kind):
    diffs, orders = _time_ladder(kind, "implicit")
    assert np.all(np.abs(orders - 2.0) <= 0.15), (diffs, orders)
    assert diffs[-1] <= 2.3e-4  # measured 1.64e-4 and 1.81e-4; 25% above the larger


@pytest.mark.verification
@pytest.mark.parametrize("kind", ["coulomb", "stick"])
def test_pseudo_is_first_order_in_time(kind):
    diffs, orders = _time_ladder(kind, "pseudo")
    assert np.all(np.abs(orders - 1.0) <= 0.15), (diffs, orders)
    assert diffs[-1] <= 1.65e-3  # measured 1.31e-3 and 1.19e-3; 25% above the larger
