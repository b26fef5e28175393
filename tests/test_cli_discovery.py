"""What a new user types first: `beltsim --version` and `beltsim scenes`."""

import pytest

import beltsim
from beltsim import cli as cli_module


@pytest.mark.cli
def test_version_prints_the_package_version():
    from helpers import cli

    proc = cli("--version", timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == f"beltsim {beltsim.__version__}"


@pytest.mark.cli
def test_scenes_lists_every_shipped_scene_with_its_kind_and_title():
    from helpers import cli

    proc = cli("scenes", timeout=120)
    assert proc.returncode == 0, proc.stderr
    lines = {line.split()[0]: line for line in proc.stdout.splitlines()}
    assert tuple(sorted(lines)) == beltsim.scene_names()
    for name in ("paper_slip", "drive_flat"):
        assert beltsim.shipped_scene(name).title in lines[name]
    assert "straight belt, stick and slip" in lines["paper_slip"]
    assert "straight belt, perfect adhesion" in lines["paper_quasistatic"]
    assert "closed drive" in lines["drive_flat"]


@pytest.mark.unit
def test_scenes_without_shipped_scenes_is_a_one_line_error(monkeypatch, capsys):
    monkeypatch.setattr("beltsim.problem.shipped.scenes_dir", lambda: None)
    assert cli_module.main(["scenes"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "no scenes ship" in err


@pytest.mark.cli
def test_analytic_writes_a_folder_of_its_own_scene_and_clears_what_it_did_not_write(tmp_path):
    from helpers import cli

    proc = cli("analytic", "paper_slip", cwd=tmp_path, timeout=300)
    assert proc.returncode == 0, proc.stderr
    own = tmp_path / "runs" / "out" / "analytic_paper_slip"
    assert {p.name for p in own.iterdir()} == {"summary.json", "fields.csv"}
    # a drive's analytic solution has no fields.csv: the straight belt's one goes
    proc = cli("analytic", "drive_flat", "--set", "physics.model=string", "--out", own,
               cwd=tmp_path, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert {p.name for p in own.iterdir()} == {"summary.json"}
    assert "slip_arc_driver" in (own / "summary.json").read_text()


@pytest.mark.cli
def test_run_clears_an_earlier_runs_snapshots_and_figures(tmp_path):
    """A run without snapshots leaves none of an earlier run's in its folder (`beltsim
    animate --from DIR` would draw them as this run's), nor the figures drawn from it;
    a file of the user's own stays."""
    from helpers import cli

    small = ("run", "paper_quasistatic", "--set", "numerics.elements=60", "--quiet",
             "--out", tmp_path)
    proc = cli(*small, "--snapshots", "0.05", timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "snapshots.npz").is_file()
    proc = cli("plot", tmp_path, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "fields.png").is_file() and (tmp_path / "history.png").is_file()
    (tmp_path / "transient.gif").write_bytes(b"an earlier run's animation")
    (tmp_path / "notes.txt").write_text("mine")
    proc = cli(*small, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert {p.name for p in tmp_path.iterdir()} == {
        "summary.json", "fields.csv", "history.csv", "scene.toml", "notes.txt"}


@pytest.mark.unit
def test_animate_of_a_scene_clears_an_earlier_runs_figures(tmp_path, monkeypatch):
    """`beltsim animate SCENE` runs the scene again: the figures of the folder's earlier
    run go, the other format's animation among them (the encoder is stubbed here)."""
    from beltsim.plots import animate as animate_module

    def encode(snapshots, path, fmt, fps):
        path.write_bytes(b"frames")
        return path
    monkeypatch.setattr(animate_module, "animate", encode)
    for name in ("transient.mp4", "fields.png", "notes.txt"):
        (tmp_path / name).write_bytes(b"earlier")
    assert cli_module.main(["animate", "paper_quasistatic", "--set", "numerics.elements=60",
                            "--format", "gif", "--quiet", "--out", str(tmp_path)]) == 0
    names = {p.name for p in tmp_path.iterdir()}
    assert {"transient.gif", "snapshots.npz", "notes.txt"} <= names
    assert not names & {"transient.mp4", "fields.png"}
