"""Manufactured solutions: the order in time of the time-accurate schemes.

A smooth nodal history u_j(t) = X_j phi(t), theta_j(t) = Y_j phi(t) is made the exact
solution of the semi-discrete model by the distributed loads it leaves unbalanced,
q = (M u_tt - forces(u, u_t, t)) / hbar, computed with the numpy twin of the model
(physics.model.forces_numpy) and tabulated densely in time (cubic Hermite, error
O(dt_table^4), far below the schemes' errors). The space discretisation then makes no
error at all, so what remains is the time integrator's: its order is measured at
fixed steps dt, dt/2, dt/4. phi(t) = (1 - cos w t)^2 starts at rest with zero
acceleration, like a run. The friction law is smooth at this scale (tanh with a large
v_reg) and acts throughout the contact.
"""

import numpy as np
import pytest

import beltsim
from beltsim.physics.model import Loads, forces_numpy
from helpers import scene_path

OMEGA = 400.0  # rad/s: a few periods over the span, resolved by the steps below
SPAN = 0.02  # s
TABLE = 4001  # table times over the span


def _phi(t):
    c = np.cos(OMEGA * t)
    s = np.sin(OMEGA * t)
    return ((1 - c) ** 2, 2 * OMEGA * (1 - c) * s,
            2 * OMEGA**2 * (s * s + (1 - c) * c))


def _scene(scheme, step, *extra):
    # checks every `step` and time_tol far above any estimate: one step per check,
    # a fixed step for the implicit scheme
    return beltsim.load_scene(scene_path("paper_slip"), [
        "numerics.elements=40", "numerics.grading=1", "numerics.regularisation=0.5",
        "numerics.ramp_time=0", f"numerics.t_end={SPAN}", f"numerics.integrator={scheme}",
        f"numerics.snapshot_interval={step}", "numerics.time_tol=10", "numerics.steady_tol=1e-30",
        *extra])


def _manufactured(sim):
    d = sim.disc
    x = d.grid.x
    L = d.params.L
    shape_u = 1e-3 * np.sin(np.pi * x / L) * (1 + x / L)
    shape_t = 1e-2 * np.sin(2 * np.pi * x / L)
    times = np.linspace(0.0, SPAN, TABLE)

    def loads_at(t):
        p, dp, ddp = _phi(t)
        u, th = shape_u * p, shape_t * p
        ud, td = shape_u * dp, shape_t * dp
        fu, ft, _ = forces_numpy(u, th, ud, td, t, d.mesh, d.model, d.drive)
        hb = d.mesh.hb[1:-1]
        qu, qt = np.zeros_like(x), np.zeros_like(x)
        qu[1:-1] = (d.params.rho * hb * shape_u[1:-1] * ddp - fu) / hb
        qt[1:-1] = (d.params.I * hb * shape_t[1:-1] * ddp - ft) / hb
        return qu, qt

    q = [loads_at(t) for t in times]
    eps = 1e-7 * SPAN  # central differences for the slopes: O(eps^2) error
    dq = [[(a - b) / (2 * eps) for a, b in zip(loads_at(t + eps), loads_at(t - eps))]
          for t in times]
    loads = Loads(times, np.array([a for a, _ in q]), np.array([b for _, b in q]),
                  np.array([a for a, _ in dq]), np.array([b for _, b in dq]))
    exact = _phi(SPAN)[0]
    return loads, shape_u * exact, shape_t * exact


@pytest.mark.parametrize("scheme", ["implicit"])
def test_order_in_time_on_a_manufactured_solution(scheme):
    errors = []
    for step in (SPAN / 100, SPAN / 200, SPAN / 400):
        sim = beltsim.Simulation(_scene(scheme, step))
        loads, u_exact, th_exact = _manufactured(sim)
        sim.disc.loads = loads
        res = sim.run()
        assert res.simulated_time == pytest.approx(SPAN, rel=1e-12)
        err = max(np.abs(res.solution.u - u_exact).max() / np.abs(u_exact).max(),
                  np.abs(res.solution.theta - th_exact).max() / np.abs(th_exact).max())
        errors.append(err)
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    # second order: each halving of the step divides the error by ~4
    assert orders.min() >= 1.9, (errors, orders)
