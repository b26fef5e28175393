"""The ESDIRK3(2)4L[2]SA scheme (``numerics.integrator = "esdirk3"``): its tableau, its
third order in time on a manufactured solution, and the steady states it reaches with
every friction law, drive profile and inertia setting the implicit scheme takes."""

import numpy as np
import pytest
from test_mms import SPAN, _manufactured
from test_mms import _scene as mms_scene

import beltsim
from beltsim import solvers
from beltsim.errors import FailureKind
from beltsim.simulation.controller import Simulation
from beltsim.solvers import esdirk
from beltsim.studies.stability import DISCRETE_BOUNDS, Case, CellStatus, stability_cell
from helpers import scene_path

# The tableau's entries are the published rationals, which approximate irrational
# numbers: the order conditions hold to about 1e-12, not to round-off.
TABLEAU_TOL = 1e-11


@pytest.mark.unit
def test_tableau_is_third_order_with_a_second_order_embedding():
    A, b, bh, c = esdirk.TABLEAU_A, esdirk.TABLEAU_B, esdirk.TABLEAU_B_HAT, esdirk.TABLEAU_C
    tol = TABLEAU_TOL
    assert np.allclose(A.sum(axis=1), c, rtol=0, atol=tol)  # stages at t_n + c_i h
    assert np.allclose(A[-1], b, rtol=0, atol=0)  # stiffly accurate: y_{n+1} = last stage
    assert A[0].tolist() == [0.0] * 4  # explicit first stage
    assert np.all(np.diag(A)[1:] == esdirk.GAMMA)  # one diagonal coefficient
    # order conditions up to 3 (b) and 2 (b^)
    assert abs(b.sum() - 1) < tol and abs(b @ c - 1 / 2) < tol
    assert abs(b @ c**2 - 1 / 3) < tol and abs(b @ A @ c - 1 / 6) < tol
    assert abs(bh.sum() - 1) < tol and abs(bh @ c - 1 / 2) < tol
    # the embedding is a different method (its error estimate is not zero): third order
    # fails for b^
    assert abs(bh @ c**2 - 1 / 3) > 1e-3 or abs(bh @ A @ c - 1 / 6) > 1e-3


def _stability_function(z):
    A, b = esdirk.TABLEAU_A, esdirk.TABLEAU_B
    return 1 + z * b @ np.linalg.solve(np.eye(4) - z * A, np.ones(4))


@pytest.mark.unit
def test_tableau_is_l_stable():
    """|R(z)| <= 1 on the imaginary axis (A-stability, with the method's poles at
    1/gamma > 0) and R(z) -> 0 as z -> -inf (L-stability: stiff components are damped),
    as 1/z: |R(z)| = 2.87 / |z| from z = -1e4 on (further out the rationals' inexactness
    shows)."""
    for y in np.concatenate([np.linspace(0, 10, 201), np.logspace(1, 8, 50)]):
        assert abs(_stability_function(1j * y)) <= 1 + 1e-12, y
    for z in (-1e4, -1e5, -1e6):
        assert abs(_stability_function(z)) < 3 / abs(z), z


@pytest.mark.unit
def test_registered_and_resolved_as_an_integrator():
    assert "esdirk3" in solvers.names() and solvers.get("esdirk3") is esdirk.EsdirkScheme
    assert esdirk.EsdirkScheme.time_accurate and not esdirk.EsdirkScheme.accelerated
    scene = beltsim.load_scene(scene_path("paper_quasistatic"),
                               ["numerics.integrator=esdirk3"])
    assert Simulation(scene).scheme.name == "esdirk3"  # quasistatic scenes too


# Measured errors (u, theta relative, steps SPAN / 50, / 100, / 200): 6.5e-4, 8.6e-5,
# 1.1e-5, orders 2.92, 2.96. The loads' table (cubic Hermite, step SPAN / 4000) errs by
# far less, so the orders are the scheme's.
@pytest.mark.verification
def test_third_order_in_time_on_a_manufactured_solution():
    errors = []
    for step in (SPAN / 50, SPAN / 100, SPAN / 200):
        # the first step dt = step, checks every step and time_tol far above any
        # estimate: fixed steps
        sim = beltsim.Simulation(mms_scene("esdirk3", step, f"numerics.dt={step}"))
        loads, u_exact, th_exact = _manufactured(sim)
        sim.disc.loads = loads
        res = sim.run()
        assert res.simulated_time == pytest.approx(SPAN, rel=1e-12)
        assert res.steps == round(SPAN / step) and res.statistics["rejected_steps"] == 0
        errors.append(max(np.abs(res.solution.u - u_exact).max() / np.abs(u_exact).max(),
                          np.abs(res.solution.theta - th_exact).max()
                          / np.abs(th_exact).max()))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    # third order: each halving of the step divides the error by ~8
    assert orders.min() >= 2.8, (errors, orders)


#: One case per friction law (the default grid's laws of a Coulomb and a stick scene,
#: the exact laws through the semi-smooth Newton), quasistatic, and the drive profiles.
LAW_CASES = (
    Case("tanh", "paper_slip"),
    Case("sqrt", "paper_slip", (("numerics.friction_law", "sqrt"),)),
    Case("ramp", "paper_slip", (("numerics.friction_law", "ramp"),)),
    Case("exact Coulomb", "paper_slip", (("numerics.friction_law", "exact"),)),
    Case("linear (adhesion layer)", "paper_inertia"),
    Case("exact adhesion", "paper_inertia", (("numerics.friction_law", "exact"),)),
    Case("quasistatic", "paper_quasistatic"),
    Case("quasistatic, exact Coulomb", "paper_slip",
         (("physics.inertia", False), ("numerics.friction_law", "exact"))),
    Case("speed profile", "speed_step"),
    Case("friction profile", "load_drop"),
)


@pytest.mark.verification
@pytest.mark.parametrize("case", LAW_CASES, ids=lambda c: c.name)
def test_reaches_the_steady_schemes_state(case):
    """From rest to the steady state of the grid, as the steady scheme solves it
    directly, within the stability matrix's DISCRETE_BOUNDS (ten times what the runs'
    own steady and Newton tolerances leave)."""
    cell = stability_cell(case, "esdirk3", extra=(("numerics.elements", 60),), discrete=True)
    assert cell["status"] == CellStatus.CONVERGED, cell


@pytest.mark.verification
@pytest.mark.parametrize("law", ["tanh", "ramp"])
def test_same_steady_state_as_bdf2(law):
    """paper_slip on 200 elements: the two time-accurate schemes end on one state, within
    DISCRETE_BOUNDS (the steady test stops each where the state changes by less than
    steady_tol per transit). The ramp law's kink defeats the steady scheme's Newton, so
    the steady-state case above judges it against the exact solution only."""
    scene = beltsim.load_scene(scene_path("paper_slip"), ["numerics.elements=200",
                                                          f"numerics.friction_law={law}"])
    ends = [Simulation(scene.with_overrides([("numerics.integrator", s)])).run()
            for s in ("implicit", "esdirk3")]
    assert all(r.converged for r in ends)
    bdf2, rk = (r.solution for r in ends)
    friction = [r.history["total_friction"][-1] for r in ends]
    assert abs(friction[1] - friction[0]) < DISCRETE_BOUNDS["total_friction"] * abs(friction[0])
    assert np.abs(rk.u - bdf2.u).max() < DISCRETE_BOUNDS["u"] * np.abs(bdf2.u).max()
    assert (np.abs(rk.theta - bdf2.theta).max()
            < DISCRETE_BOUNDS["theta"] * np.abs(bdf2.theta).max())



@pytest.mark.unit
def test_newton_failure_is_reported_with_time():
    """As the implicit scheme's: one Newton iteration cannot solve a stage, the step is
    cut back until it is too small, and the run stops naming the time."""
    scene = beltsim.load_scene(scene_path("paper_slip"), [
        "numerics.elements=200", "numerics.integrator=esdirk3",
        "numerics.newton_max_iterations=1"])
    res = Simulation(scene).run(raise_on_failure=False)
    assert res.failed and res.failure is FailureKind.NEWTON
    assert "Newton iteration failed at t = " in res.reason
    assert np.all(np.isfinite(res.solution.u))
