"""`python -m validation.random_scenes`: the draw is valid and reproducible, the CLI
counts add up."""

import csv
import math
import tomllib

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from beltsim import solvers
from beltsim.api import shipped_scene
from beltsim.errors import FailureKind
from beltsim.problem import analytic
from beltsim.problem.scene import Scene
from beltsim.simulation import trackers
from beltsim.solvers.settings import resolve
from beltsim.studies import stability
from beltsim.studies.stability import ACCEPTED, CellStatus, stability_cell
from helpers import module
from validation import random_scenes as rs

pytestmark = pytest.mark.lab


@settings(max_examples=300, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), index=st.integers(0, 10**6))
def test_every_drawn_scene_is_valid_and_runs_as_drawn(seed, index):
    scene = rs.draw_scene(seed, index)
    P = scene.params
    # the file written for a failure reads back as the same scene
    again = Scene.from_dict(tomllib.loads(scene.to_toml()))
    assert again.to_dict() == scene.to_dict()
    # the stability case built from it runs it as drawn
    assert rs.scene_case(scene).scene().to_dict() == scene.to_dict()
    assert 0.0 < P.x1 < P.x2 < P.L and -1.0 < scene.to_dict()["beam"]["poisson_ratio"] < 0.5
    assert 1e-6 * (1 - 1e-6) <= abs(P.e0) <= 0.05 * (1 + 1e-6)
    if P.inertia:
        assert P.c <= 0.95 * min(P.critical_speeds) * (1 + 1e-5)
    # the numerics resolve (mismatch, regularisation, memory) for every applicable scheme
    for scheme in solvers.names():
        if not solvers.applicable(scheme, P.inertia):
            resolve(scene.with_overrides([("numerics.integrator", scheme)]))


def test_the_draw_covers_the_space():
    """Both frictions, inertia on and off, damped and undamped, both signs of v - c over
    the decades, whole-contact sliding, poisson_ratio near both ends, near-critical."""
    scenes = rs.draw_scenes(200, seed=11)
    P = [s.params for s in scenes]
    e = np.array([p.e0 for p in P])
    assert (e > 0).any() and (e < 0).any()
    assert np.abs(e).min() < 1e-5 and np.abs(e).max() > 1e-2
    assert {p.friction for p in P} == {"stick", "coulomb"}
    assert {p.inertia for p in P} == {True, False}
    inertial = [p for p in P if p.inertia]
    assert any(p.damping == 0 for p in inertial) and any(p.damping > 0 for p in inertial)
    assert max(p.c / min(p.critical_speeds) for p in inertial) > 0.9
    assert min(p.c / min(p.critical_speeds) for p in inertial) < 0.01
    nu = [s.to_dict()["beam"]["poisson_ratio"] for s in scenes]
    assert min(nu) < -0.9 and max(nu) > 0.45
    slip = [analytic.solve(p) for p in P if p.friction == "coulomb"]
    whole = [s for s in slip if s.x_star == s.params.x1]
    assert 0 < len(whole) < len(slip)
    fstar = [p.fstar for p in P if p.friction == "coulomb"]
    assert max(fstar) / min(fstar) > 1e4


def test_the_same_seed_draws_the_same_scenes():
    a = [s.to_toml() for s in rs.draw_scenes(6, seed=5)]
    assert a == [s.to_toml() for s in rs.draw_scenes(6, seed=5)]
    # scene i does not depend on how many are drawn
    assert rs.draw_scene(5, 4).to_toml() == a[4]
    assert a != [s.to_toml() for s in rs.draw_scenes(6, seed=6)]


def test_reasons_are_grouped_by_what_they_are_about(monkeypatch):
    """A refusal counts by the key its SceneError names, a cell out of bounds by the
    errors beyond their bounds, a failed run by its FailureKind: read from the objects."""
    scene = shipped_scene("paper_slip", [("numerics.elements", 60)])
    work = rs.random_cell(scene, 0, "explicit", extra=[("numerics.max_work", 1e3)])
    assert (work["status"], work["reason_key"]) == ("refused", "numerics.max_work")
    outside = rs.random_cell(scene, 0, "steady", extra=[("contact.end", 2.0)])
    assert (outside["status"], outside["reason_key"]) == ("refused", "contact.start/end")
    tight = stability_cell(rs.scene_case(scene), "steady",
                           bounds={"total_friction": 0.0, "u": 1.0, "theta": 0.0})
    assert tight["status"] is CellStatus.OUT_OF_BOUNDS
    assert tight["reason_key"] == "total_friction, theta"
    monkeypatch.setattr(trackers, "GROWTH_LIMIT", 1e-12)  # any growth is divergence
    monkeypatch.setattr(stability, "_VERDICTS", {})
    grew = rs.random_cell(scene, 0, "implicit")
    assert (grew["status"], grew["reason_key"]) == ("diverged", FailureKind.GREW.value)


@pytest.mark.cli
def test_a_few_random_scenes_through_the_cli(tmp_path):
    """A coarse grid (60 elements): out of bounds is expected there; the files and the
    counts must agree with each other and with the exit status."""
    n, out = 4, tmp_path / "r"
    (out / "failures").mkdir(parents=True)
    (out / "failures" / "scene_99.toml").write_text("stale")  # a previous draw's
    proc = module("validation.random_scenes", n, "--seed", 3, "--elements", 60, "--out", out,
               timeout=900)
    rows = list(csv.DictReader((out / "random.csv").open()))
    assert len(rows) == n * len(solvers.names())
    assert {(int(r["index"]), r["scheme"]) for r in rows} == {
        (i, s) for i in range(n) for s in solvers.names()}
    known = {s.value for s in CellStatus} | {rs.CRASHED}
    assert {r["status"] for r in rows} <= known
    for r in rows:
        assert int(r["elements"]) == 60
        if r["status"] != "converged":
            assert r["reason"], r
        if r["status"] in ("converged", "out of bounds"):
            assert math.isfinite(float(r["error_total_friction"]))
    failed = {int(r["index"]) for r in rows if r["status"] not in {s.value for s in ACCEPTED}}
    files = sorted(p.name for p in (out / "failures").glob("*.toml"))
    assert files == sorted(f"scene_{i}.toml" for i in failed)
    for i in failed:  # each reruns as drawn, on the grid it ran on
        scene = Scene.load(out / "failures" / f"scene_{i}.toml")
        assert scene.to_dict()["numerics"] == {"elements": 60}
        drawn = rs.draw_scene(3, i).to_dict()
        got = scene.to_dict()
        assert got.pop("title").startswith(drawn.pop("title") + "; failed: ")
        got.pop("numerics")
        assert got == drawn
    md = (out / "random.md").read_text()
    total = next(line for line in md.splitlines() if line.startswith("| all |"))
    counts = {s: sum(r["status"] == s for r in rows) for s in known}
    header = next(line for line in md.splitlines() if line.startswith("| scheme |"))
    cols = [c.strip() for c in header.strip("|").split("|")][1:]
    assert dict(zip(cols, map(int, total.strip("|").split("|")[1:]))) == {
        c: counts[c] for c in cols}
    assert sum(counts.values()) == len(rows)
    assert f"{len(rows)} cells" in proc.stdout
    assert proc.returncode == (1 if failed else 0), proc.stderr


@pytest.mark.cli
def test_max_wall_skips_the_cells_not_started(tmp_path):
    proc = module("validation.random_scenes", 3, "--seed", 3, "--elements", 60, "--max-wall",
               1e-9, "--out", tmp_path)
    rows = list(csv.DictReader((tmp_path / "random.csv").open()))
    assert proc.returncode == 0, proc.stderr
    assert {r["status"] for r in rows} == {rs.SKIPPED}
    assert len(rows) == 3 * len(solvers.names()) and f"skipped {len(rows)}" in proc.stdout


@pytest.mark.cli
def test_bad_random_options_are_one_line_errors(tmp_path):
    for args in ([0], ["--seed", 3], [2, "--max-wall", -1]):
        proc = module("validation.random_scenes", *args, "--out", tmp_path)
        assert proc.returncode == 2 and proc.stderr.count("\n") == 1, proc.stderr


def test_the_slip_start_bound_scales_with_the_grid():
    from beltsim.api import paper_scene
    from beltsim.studies.stability import BOUNDS
    assert rs.scene_bounds(paper_scene("slip"), 1000) == BOUNDS  # what BOUNDS were set on
    long = paper_scene("slip", ["beam.length=40", "contact.start=10", "contact.end=30"])
    # five mean element lengths: 40 m over 2000 elements
    assert rs.scene_bounds(long, 2000)["slip_start"] == pytest.approx(5 * 40 / 2000)
    assert rs.scene_bounds(long, 2000)["theta"] == BOUNDS["theta"]


def test_the_deferred_schemes_get_their_share_of_max_wall(monkeypatch):
    """The adaptive schemes stop at FIRST_PASS_SHARE of --max-wall; the deferred ones run
    on the scenes the first pass reached, then are skipped too."""
    import time

    def fake(scene, i, scheme, extra):
        time.sleep(0.2 if scheme in rs.DEFERRED else 0.05)
        return {"index": i, "scheme": scheme, "status": "converged", "reason": "",
                "reason_key": "", **rs.describe(scene), "elapsed": 0.0}
    monkeypatch.setattr(rs, "random_cell", fake)
    rows = rs.random_study(40, 1, max_wall=2.0)
    assert [(r["index"], r["scheme"]) for r in rows] == [
        (i, s) for i in range(40) for s in solvers.names()]
    ran = {(r["index"], r["scheme"]) for r in rows if r["status"] != rs.SKIPPED}
    first = {i for i, s in ran if s not in rs.DEFERRED}
    deferred = {i for i, s in ran if s in rs.DEFERRED}
    assert first and deferred and max(deferred) <= max(first) < 39
    assert all(r["reason"].startswith("--max-wall 2 s") for r in rows
               if r["status"] == rs.SKIPPED)


def test_an_undamped_scene_still_ringing_at_t_end_counts_as_bounded():
    """Undamped, only friction dissipates and a time-accurate run may ring past t_end: it
    says so (not steady) and the study counts it like the matrix's span cases. The damped
    scene cut as short is judged by its slowest mode instead (decaying at ~10 1/s it needs
    ~1.3 s, not the 0.003 s left after the ramp): bounded, stable but slow; a damped cell
    that could have settled stays a failure (tests/test_modes.py)."""
    scene = shipped_scene("paper_slip", [("numerics.elements", 120)])
    short = (("numerics.t_end", 0.02),)
    undamped = rs.random_cell(scene.with_overrides([("physics.damping", 0.0)]), 0,
                              "implicit", extra=short)
    assert undamped["status"] == CellStatus.BOUNDED.value, undamped
    assert undamped["reason"].startswith("undamped, still ringing: not steady by t_end")
    damped = rs.random_cell(scene, 1, "implicit", extra=short)
    assert damped["status"] == CellStatus.BOUNDED.value and not rs.failed(damped), damped
    assert damped["reason"].startswith("stable but slow")


def test_jobs_give_the_same_rows_in_the_same_order(monkeypatch):
    """A pool of processes (--jobs) runs the same cells: rows, progress and on_failure in
    scene order, whatever order the cells finish in; max_wall skips alike."""
    import time

    def fake(scene, i, scheme, extra):
        time.sleep(0.02 * ((7 * i + len(scheme)) % 5))  # finish out of order
        bad = i % 4 == 1 and scheme == "implicit"
        return {"index": i, "scheme": scheme, "status": "diverged" if bad else "converged",
                "reason": "x" if bad else "", "reason_key": "", **rs.describe(scene),
                "elapsed": 0.0}
    monkeypatch.setattr(rs, "random_cell", fake)
    runs = {}
    for jobs in (1, 3):
        shown, failures = [], []

        def failed(scene, rows, failures=failures):
            failures.append((scene.title, [x["scheme"] for x in rows]))
        rows = rs.random_study(12, 5, jobs=jobs, progress=shown.append, on_failure=failed)
        runs[jobs] = (rows, shown, failures)
    assert runs[1] == runs[3]
    assert [(r["index"], r["scheme"]) for r in runs[3][1]] == [
        (i, s) for i in range(12) for s in solvers.names() if s not in rs.DEFERRED] + [
        (i, s) for i in range(12) for s in rs.DEFERRED]
    assert len(runs[3][2]) == 3
    skipped = rs.random_study(3, 5, jobs=2, max_wall=1e-9)
    assert {r["status"] for r in skipped} == {rs.SKIPPED}


# closed drives ---------------------------------------------------------------------

def test_every_drawn_drive_is_valid_and_loads_within_its_capacity():
    from beltsim.beltdrive.analytic import capacity
    from beltsim.beltdrive.scene import DriveScene
    drives = rs.draw_scenes(60, seed=3, drives=True)
    for d in drives:
        P = d.params
        # the file written for a failure reads back as the same drive
        assert DriveScene(tomllib.loads(d.to_toml())).to_dict() == d.to_dict()
        # the load was drawn as 0.1 .. 0.9 of the capacity (rounded to 4 digits)
        assert 0.1 * 0.999 <= P.M2 / capacity(P) <= 0.9 * 1.001
        if P.inertia:
            rim = P.omega1 * P.geometry.R1
            assert P.rho * rim * rim <= 0.5 * P.N0 * 1.001
    assert {d.params.model for d in drives} == {"beam", "string"}
    assert {d.params.inertia for d in drives} == {True, False}
    # drive i of a seed does not depend on how many are drawn, and not on the straight
    # scenes of that seed
    assert rs.draw_scenes(4, seed=3, drives=True)[3].to_toml() == drives[3].to_toml()


def test_a_random_drive_runs_by_every_applicable_scheme_and_passes():
    """The campaign's cells on drives: each applicable scheme from rest to the exact
    state within stability.DRIVE_BOUNDS (a coarse grid: 200 elements)."""
    rows = rs.random_study(1, 1, extra=[("numerics.elements", 200)], drives=True)
    assert {r["scheme"] for r in rows} == set(solvers.names())
    assert not [r for r in rows if rs.failed(r)], rows
    ran = [r for r in rows if r["status"] == CellStatus.CONVERGED.value]
    assert ran and all(math.isfinite(r["error_tight_tension"]) for r in ran)
