"""Sweeps, and the paper's central claim: the creep zone collapses onto x2 as f* grows."""

import csv
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from beltsim.api import paper_scene
from beltsim.errors import SceneError, UsageError
from beltsim.studies import sweep
from helpers import scene_path

F_STARS = (5e4, 7e4, 1e5, 2e5, 5e5, 1e6)


@pytest.fixture(scope="module")
def collapse():
    scene = paper_scene("slip")
    with ThreadPoolExecutor(max_workers=2) as ex:  # any Executor serves
        return sweep.sweep(scene, "contact.max_friction", [*F_STARS, 1e7], ex)


@pytest.mark.verification
def test_simulated_slip_zone_matches_the_analytic_one(collapse):
    """From f* = 5e4 to 1e6 on the default grid (600 elements, a node at the expected
    slip start; second order): the zone's length is off by 1.3e-5 ... 7.7e-5 of itself
    (measured; the largest at f* = 1e6); bound 3x the largest."""
    for r in collapse[:-1]:
        x2 = paper_scene("slip").params.x2
        sim, exact = x2 - r["slip_start"], x2 - r["slip_start_analytic"]
        assert r["converged"]
        assert abs(sim - exact) <= 3 * 7.7e-5 * exact, r["value"]


@pytest.mark.verification
def test_slip_zone_shrinks_monotonically(collapse):
    lengths = [r["slip_start"] for r in collapse]
    assert all(b >= a for a, b in zip(lengths, lengths[1:]))  # x* moves towards x2
    assert lengths[-1] > lengths[0]


@pytest.mark.verification
def test_large_friction_limit_is_perfect_adhesion(collapse):
    """At f* = 1e7 the total friction is within 0.3% of the perfect-adhesion value."""
    last = collapse[-1]
    assert last["value"] == 1e7
    rel = abs(last["total_friction"] - last["total_friction_adhesion"])
    assert rel / last["total_friction_adhesion"] < 3e-3


@pytest.mark.unit
def test_parse_vary_validates():
    assert sweep.parse_vary("contact.max_friction=1e5, 2e5") == (
        "contact.max_friction", [1e5, 2e5])
    with pytest.raises(UsageError):
        sweep.parse_vary("contact.max_friction")
    with pytest.raises(SceneError):
        sweep.parse_vary("contact.nonsense=1,2")
    with pytest.raises(SceneError):  # a bad value fails before any run starts
        sweep.sweep(paper_scene("slip"), "contact.max_friction", [1e5, -1.0])


@pytest.mark.cli
def test_sweep_command_writes_csv_and_figure(tmp_path):
    # a drive's load sweep drew this here before: it is not this sweep's, so it goes
    (tmp_path / "characteristic.png").write_bytes(b"an earlier sweep's figure")
    proc = subprocess.run(
        [sys.executable, "-m", "beltsim.cli", "sweep", scene_path("paper_slip"), "--vary",
         "contact.max_friction=5e4,1e5,1e6", "--set", "numerics.elements=300", "--workers",
         "2", "--out", str(tmp_path)], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    rows = list(csv.DictReader((tmp_path / "sweep.csv").open()))
    assert [float(r["contact.max_friction"]) for r in rows] == [5e4, 1e5, 1e6]
    for r in rows:
        assert float(r["converged"]) == 1.0  # booleans as numbers
        for k in ("total_friction", "stick_friction", "slip_friction", "slip_start"):
            assert np.isfinite(float(r[k])) and np.isfinite(float(r[f"{k}_analytic"]))
    assert (tmp_path / "creep_collapse.png").stat().st_size > 20_000
    assert not (tmp_path / "characteristic.png").exists()


@pytest.mark.unit
def test_scheduler_without_dask_is_a_clean_error(tmp_path, monkeypatch, capsys):
    """Dask missing (its import made to fail, whether or not it is installed): exit 2 with
    one line naming the extra to install."""
    from beltsim.cli import main

    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed -> ImportError
    code = main(["sweep", scene_path("paper_slip"), "--vary", "contact.max_friction=1e5",
                 "--scheduler", "tcp://127.0.0.1:1", "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2 and "beltsim[dask]" in err
    assert err.count("\n") == 1 and "Traceback" not in err
