"""Animated transients from a run's snapshot file."""


import numpy as np
import pytest
from PIL import Image

from beltsim.io.results import read_snapshots
from beltsim.plots.animate import frame_fields
from helpers import cli, scene_path

pytestmark = pytest.mark.cli


@pytest.mark.long  # 11 s: an encode of each format (CI's budget; the other tests animate)
def test_animate_runs_and_stores_an_mp4_then_a_gif_from_the_stored_run(tmp_path):
    run_dir = tmp_path / "run"
    proc = cli("animate", scene_path("paper_slip"), "--set", "numerics.elements=150",
                "--interval", "0.05", "--fps", "5", "--out", str(run_dir), "--quiet")
    assert proc.returncode == 0, proc.stderr
    # MP4 by default: imageio-ffmpeg, a dependency, ships ffmpeg
    data = (run_dir / "transient.mp4").read_bytes()
    assert len(data) > 10_000 and data[4:8] == b"ftyp"
    stamp = (run_dir / "summary.json").stat().st_mtime_ns
    out = tmp_path / "gif"
    proc = cli("animate", "--from", str(run_dir), "--format", "gif", "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    gif = Image.open(out / "transient.gif")
    assert gif.n_frames > 5
    # every frame has the time stamp above the top panel (drawn over a fixed background)
    gif.seek(gif.n_frames - 1)
    # rows 18-34 of the 640 x 760 frame: below the figure's title, above the top panel
    band = np.asarray(gif.convert("L"))[18:34]
    assert (band < 128).sum() > 200  # measured about 670 dark pixels of text
    assert (run_dir / "summary.json").stat().st_mtime_ns == stamp  # no new run


def test_snapshots_settle_on_the_stored_final_state(tmp_path):
    proc = cli("run", scene_path("paper_inertia"), "--set", "numerics.elements=150",
                "--snapshots", "0.005", "--out", str(tmp_path), "--quiet")
    assert proc.returncode == 0, proc.stderr
    snaps = read_snapshots(tmp_path / "snapshots.npz")
    assert snaps["t"][0] == 0.0 and np.all(np.diff(snaps["t"]) > 0)
    fields = frame_fields(snaps)
    assert np.all(fields["u"][0] == 0)  # from rest
    final = np.loadtxt(tmp_path / "fields.csv", delimiter=",", skiprows=1)
    # the last snapshot is the final state, in single precision
    np.testing.assert_allclose(fields["u"][-1], final[:, 1], rtol=1e-6,
                               atol=1e-7 * np.abs(final[:, 1]).max())
    np.testing.assert_allclose(fields["tension"][-1], final[:, 4], rtol=1e-5,
                               atol=1e-5 * np.abs(final[:, 4]).max())


def test_missing_snapshots_is_a_clean_error(tmp_path):
    proc = cli("animate", "--from", str(tmp_path))
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1
    assert "snapshots.npz" in proc.stderr and "Traceback" not in proc.stderr


def test_every_frame_names_the_scheme_and_the_damping():
    from beltsim.api import load_scene
    from beltsim.plots.animate import scheme_label
    default = scheme_label(load_scene(scene_path("paper_slip")))
    assert default == "esdirk3 (time-accurate), damping 39 1/s"
    pseudo = scheme_label(load_scene(scene_path("paper_slip"), ["numerics.integrator=pseudo"]))
    assert pseudo.startswith("pseudo (pseudo-transient path)") and "acceleration" in pseudo


def test_animating_leaves_the_users_matplotlib_as_it_was(tmp_path):
    """No backend switch, no pyplot figure left open, no rcParams changed (the ffmpeg path
    is set for the save only)."""
    import matplotlib
    import matplotlib.pyplot as plt

    import beltsim
    from beltsim.io.results import save_run
    from beltsim.plots.animate import animate

    result = beltsim.run(beltsim.load_scene(scene_path("paper_slip"),
                                            ["numerics.elements=60"]), snapshot_interval=0.02)
    save_run(result, tmp_path)
    before = (matplotlib.get_backend(), plt.get_fignums(),
              matplotlib.rcParams["animation.ffmpeg_path"])
    path = animate(tmp_path / "snapshots.npz", tmp_path / "transient.mp4", "mp4", fps=5)
    assert path.read_bytes()[4:8] == b"ftyp"
    assert (matplotlib.get_backend(), plt.get_fignums(),
            matplotlib.rcParams["animation.ffmpeg_path"]) == before


@pytest.mark.unit
def test_mp4_is_the_default_where_ffmpeg_is_at_hand_else_a_gif_said_so(monkeypatch):
    from beltsim.plots import frames

    monkeypatch.setattr(frames, "ffmpeg_available", lambda: True)
    assert frames.default_format() == ("mp4", None)
    monkeypatch.setattr(frames, "ffmpeg_available", lambda: False)
    fmt, note = frames.default_format()
    assert fmt == "gif" and "ffmpeg" in note and "\n" not in note
