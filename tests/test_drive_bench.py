"""The closed drive's benchmark (benchmarks.drive) and its generic peers
(benchmarks.drive_peers), on small grids.

The peers must solve our equations, or their ratios mean nothing: the generic pieces drive
our Newton to our steady state and take our BDF2 steps; the ODE form has our steady state
as a fixed point, keeps the gauge, and its Jacobian is its derivative; solve_ivp's Radau
reaches our steady state from rest.
"""

import numpy as np
import pytest

from beltsim.beltdrive import simulate, solve_steady
from beltsim.beltdrive.scene import DriveScene
from benchmarks import drive, drive_peers
from helpers import module, scene_path

pytestmark = pytest.mark.lab


def _scene(*overrides):
    return DriveScene.load(scene_path("drive_flat")).with_overrides(list(overrides))


def test_generic_pieces_reach_our_steady_state():
    scene = _scene("numerics.elements=60")
    ours = solve_steady(scene)
    peer = drive_peers.run_generic_steady(scene)
    assert peer.converged
    assert peer.statistics["newton_iterations"] == ours.statistics["newton_iterations"]
    # both converge to newton_tol = 1e-10 in the scaled update: the same state to 1e-9
    assert drive_peers.difference(peer.summary, ours.summary) < 1e-9


def test_generic_pieces_take_our_bdf2_steps():
    scene = _scene("numerics.elements=40", "numerics.t_end=0.05")
    ours = simulate(scene)
    peer = drive_peers.run_generic_transient(scene)
    for key in ("steps", "newton_iterations", "rejected_steps"):
        assert peer.statistics[key] == ours.statistics[key], key
    # the same steps, each solved to newton_tol = 1e-10: agreement far below 1e-8
    assert drive_peers.difference(peer.summary, ours.summary) < 1e-8


def _ode_state(ode, res):
    """The ODE state of a steady result: its u, theta, c and omega2, rates zero."""
    z = np.zeros(ode.size)
    N = ode.N
    z[:N], z[N:2 * N] = res.fields["u"], res.fields["theta"]
    z[2 * N], z[2 * N + 1] = res.summary["belt_speed"], res.summary["driven_speed"]
    return z


def test_our_steady_state_is_a_fixed_point_of_the_ode_form():
    # ramps over by t = 1 s: the ODE's loads are the steady problem's
    scene = _scene("numerics.elements=60", "numerics.friction_law=tanh")
    ode = drive_peers.DriveODE(scene)
    z = _ode_state(ode, solve_steady(scene))
    f = ode.rhs(1.0, z)
    N, P = ode.N, ode.P
    # the accelerations are force residuals over masses, in units of N0 (torque N0 R2):
    # the steady Newton (update tolerance 1e-10) leaves 4e-14; leaving theta out or
    # changing omega2 by 1e-4 makes them 3e-4 and more
    scale = P.N0 / (P.rho * ode.mesh.hb)
    assert np.abs(f[2 * N + 2:3 * N + 2] / scale).max() < 1e-8
    assert abs(f[2 * N]) * ode.mesh.hb.sum() * P.rho / P.N0 < 1e-8
    assert abs(f[2 * N + 1]) * P.J2 / (P.N0 * P.geometry.R2) < 1e-8


def test_ode_form_keeps_the_gauge_and_its_jacobian_is_its_derivative():
    from scipy.optimize._numdiff import approx_derivative

    scene = _scene("numerics.elements=40", "numerics.friction_law=tanh")
    ode = drive_peers.DriveODE(scene)
    rng = np.random.default_rng(3)
    z = 0.3 * rng.standard_normal(ode.size) * ode.scale()
    N = ode.N
    z[2 * N], z[2 * N + 1] = 5.0, 30.0  # mid ramp: slip velocities of both signs
    f = ode.rhs(0.1, z)
    hb = ode.mesh.hb
    # the gauge twice differentiated: sum(hb u_tt) = 0 to round-off of the terms summed
    assert abs(hb @ f[2 * N + 2:3 * N + 2]) <= 1e-12 * (hb @ np.abs(f[2 * N + 2:3 * N + 2]))
    J = drive_peers.ode_jacobian(ode, 0.1, z)
    Jfd = approx_derivative(lambda zz: ode.rhs(0.1, zz), z, method="3-point")
    # central differences: truncation and round-off ~1e-10 of the largest entry (measured
    # 2e-10); a wrong term is O(1) of its own entries
    assert np.abs(J - Jfd).max() <= 1e-7 * np.abs(Jfd).max()


def test_radau_on_the_ode_form_reaches_our_steady_state():
    scene = _scene("numerics.elements=40", "numerics.friction_law=tanh")
    ref = solve_steady(scene)
    peer = drive_peers.run_ode_peer(scene, "Radau", drive.ODE_RTOL["Radau"], max_wall=120.0)
    assert peer.converged, peer.reason
    assert drive_peers.difference(peer.summary, ref.summary) < drive_peers.SAME_STATE


def test_difference_is_the_largest_relative_one():
    a = {k: 2.0 for k in drive_peers.COMPARED}
    b = dict(a, belt_speed=2.002, driver_torque=1.9)
    assert drive_peers.difference(a, a) == 0.0
    assert drive_peers.difference(b, a) == pytest.approx(0.05)
    assert drive_peers.difference(None, a) is None


def test_bench_on_a_small_grid_has_every_figure():
    scene = _scene("numerics.elements=40")
    out = drive.bench(scene, repeat=1, grids=(3,), peers=("newton", "lm", "bdf2"),
                      peer_cap=60.0, kernels=False, log=lambda *_: None)
    assert out["start_up"]["converged"] and out["start_up"]["steps"] > 0
    assert [s["elements"] for s in out["steady"]] == [40, 120]
    assert all(it["linear_solve_s"] > 0 for it in out["iteration"])
    for key in ("newton", "lm", "bdf2"):
        assert out["peers"][key]["converged"], (key, out["peers"][key]["reason"])
    assert out["speedup"]["steady"] is not None and out["kernel_speedup"]["start_up"]


def test_bad_options_are_one_line_errors():
    proc = module("benchmarks.drive", "--peers", "newton,bogus", timeout=120)
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines() == [
        "python -m benchmarks.drive: error: --peers: unknown bogus; one of "
        + ", ".join(drive.PEERS)]
    proc = module("benchmarks.drive", "paper_slip", "--peers", "", "--grids", "",
                  "--no-kernels", timeout=120)
    assert proc.returncode == 2
    assert "not a closed drive" in proc.stderr and len(proc.stderr.strip().splitlines()) == 1
