"""The closed drive's benchmark (benchmarks.drive) on small grids: every figure is there,
and the default run ends on the steady scheme's state."""

import pytest

from beltsim.beltdrive.scene import DriveScene
from benchmarks import drive
from helpers import module, scene_path

pytestmark = pytest.mark.lab


def test_bench_on_a_small_grid_has_every_figure():
    scene = DriveScene.load(scene_path("drive_flat"))
    out = drive.bench(scene, repeat=1, elements=40, grids=(3,), kernels=False)
    assert [s["elements"] for s in out["steady"]] == [40, 120]
    assert all(s["failed"] is None and s["newton_iterations"] > 0 for s in out["steady"])
    assert all(i["linear_solve_s"] > 0 for i in out["iteration"])
    su = out["start_up"]
    assert su["converged"], su["reason"]
    # the run from rest and the steady scheme solve the same discrete equations: they
    # agree to the steady test's tolerance (1e-7 of the rates), far below the grid's error
    assert su["difference"] < 1e-5


def test_bad_options_are_one_line_errors():
    res = module("benchmarks.drive", "--repeat", "0")
    assert res.returncode == 2 and "--repeat" in res.stderr
    res = module("benchmarks.drive", "--grids", "x")
    assert res.returncode == 2 and "--grids" in res.stderr


def test_peers_reach_our_state_on_the_serpentine_drive():
    """The generic peers (benchmarks.drive_peers) solve the same discrete equations: the
    sparse FD Newton and the BDF2 start-up end on our steady state (no timing asserted);
    the bench's start-up difference works on a drive of more than two pulleys."""
    scene = DriveScene.load(scene_path("serpentine_accessory"))
    out = drive.bench(scene, repeat=1, elements=60, grids=(), kernels=False,
                      peer_cap=300.0, which=("newton", "bdf2"))
    assert out["start_up"]["converged"] and out["start_up"]["difference"] < 1e-5
    rows = {r["peer"]: r for r in out["peers"]["rows"]}
    assert rows["newton"]["reached"] and rows["newton"]["difference"] < 1e-10
    assert rows["bdf2"]["reached"], rows["bdf2"]["reason"]


def test_the_peers_jacobian_is_the_residuals_derivative():
    """The grouped differences with the chain rule for the global rows and the exact
    law's generalised derivative give the whole residual's derivative (away from the
    projection's kink), and the peer's slip velocity is the kernel's."""
    import numpy as np
    from scipy.optimize._numdiff import approx_derivative

    from beltsim.solvers import LoopDiscretisation
    from beltsim.solvers.steady import creep_state
    from benchmarks import drive_peers

    scene = DriveScene.load(scene_path("serpentine_accessory")).with_overrides(
        {"numerics.elements": 60})
    d = LoopDiscretisation(scene)
    st = d.new_state()
    creep_state(d, st)
    assert drive_peers.check_slip_velocity(d, st) < 1e-12
    prob = drive_peers.LoopProblem(d)
    x, old, drive_ = prob.pack(st), d.new_state(), d.steady_drive()
    J = prob.jacobian(x, old, 0.0, 0.0, drive_).toarray()
    dense = approx_derivative(lambda y: prob.residual(y, old, 0.0, 0.0, drive_), x)
    # the differences of a sliding node near the kink (|lam + s| = 1.00006 here) cross it
    N, M = prob.N, prob.M
    s = prob.local(x, old, 0.0, 0.0, drive_)[0][2 * N:2 * N + M]
    near = np.abs(np.abs(x[2 * N:2 * N + M] + s) - 1.0) < 1e-2
    rows = np.ones(prob.size, bool)
    rows[2 * N + np.flatnonzero(near)] = False
    assert rows[2 * N:2 * N + M].sum() > M // 2
    unit = prob.scale()[None, :] / prob.row_scale()[rows, None]
    err = np.abs(J[rows] - dense[rows]) * unit
    assert err.max() < 1e-6 * (np.abs(dense[rows]) * unit).max()


def test_bad_peers_are_one_line_errors():
    res = module("benchmarks.drive", "--peers", "nope")
    assert res.returncode == 2 and "--peers" in res.stderr
