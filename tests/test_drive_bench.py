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
