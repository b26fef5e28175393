"""Figures of a stored run: 'beltsim plot DIR' reads only the files the run wrote."""

import shutil

import pytest
from PIL import Image

import beltsim
from beltsim.cli import main
from beltsim.io.results import save_run
from beltsim.plots.common import save_figure
from beltsim.plots.run import RunDirectoryError, plot_history, plot_run, read_run
from helpers import scene_path

pytestmark = pytest.mark.unit

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def stick_run(tmp_path_factory):
    """A converged perfect-adhesion run on a coarse grid (well under a second)."""
    out = tmp_path_factory.mktemp("stick")
    result = beltsim.run(beltsim.load_scene(scene_path("paper_quasistatic"),
                                            ["numerics.elements=60"]))
    assert result.converged
    save_run(result, out)
    return out


@pytest.fixture
def run_copy(stick_run, tmp_path):
    """A copy of the stored run that a test may break."""
    return shutil.copytree(stick_run, tmp_path / "run")


def assert_png(path):
    data = path.read_bytes()
    assert data[:8] == PNG_MAGIC and len(data) > 20_000, path
    with Image.open(path) as im:
        im.verify()


def test_an_unfinished_coulomb_run_plots_through_the_api(tmp_path):
    scene = beltsim.load_scene(scene_path("paper_slip"),
                               ["numerics.elements=60", "numerics.t_end=0.01"])
    result = beltsim.run(scene, raise_on_failure=False)
    assert not result.converged
    save_run(result, tmp_path / "run")
    paths = plot_run(tmp_path / "run", tmp_path / "figs")
    assert [p.name for p in paths] == ["fields.png", "history.png"]
    for p in paths:
        assert p.parent == tmp_path / "figs"
        assert_png(p)


def test_cli_plot_writes_into_the_run_directory(run_copy, capsys):
    # main() in this process, as a subprocess would spend seconds importing numba again
    code = main(["plot", str(run_copy)])
    out = capsys.readouterr().out
    assert code == 0
    for name in ("fields.png", "history.png"):
        assert str(run_copy / name) in out
        assert_png(run_copy / name)


def test_cli_plot_without_fields_is_a_one_line_error(run_copy, capsys):
    (run_copy / "fields.csv").unlink()
    code = main(["plot", str(run_copy)])
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and "Traceback" not in err
    assert str(run_copy) in err and "missing fields.csv" in err
    assert not (run_copy / "fields.png").exists()


def test_history_columns_are_read_not_assumed(run_copy, tmp_path):
    # a column the plot has never heard of gets a panel; a header without rows is a run
    # that stopped before its first check
    lines = (run_copy / "history.csv").read_text().splitlines()
    extra = [lines[0] + ",slip_power,new_column"] + [r + ",1.0,2.0" for r in lines[1:]]
    (run_copy / "history.csv").write_text("\n".join(extra) + "\n")
    run = read_run(run_copy)
    assert {"slip_power", "new_column"} <= set(run.history)
    fig = plot_history(run, exact=False)
    assert fig.axes[-1].get_ylabel() == "new column"
    assert_png(save_figure(plot_history, tmp_path / "extra.png", run, exact=False))
    (run_copy / "history.csv").write_text(lines[0] + "\n")
    run = read_run(run_copy)
    assert len(run.history["t"]) == 0
    assert_png(save_figure(plot_history, tmp_path / "empty.png", run, exact=False))


def test_an_interrupted_run_is_drawn_as_it_stopped(tmp_path):
    """A run stopped by a callback (as by a signal) writes its state so far and a
    checkpoint but no summary: plot draws it and says it was interrupted."""
    from beltsim.io.results import CHECKPOINT
    from beltsim.simulation.controller import Simulation

    sim = Simulation(beltsim.load_scene(scene_path("paper_slip"), ["numerics.elements=60"]))
    result = sim.run(callback=lambda s: s.t > 0.01, checkpoint=tmp_path / CHECKPOINT)
    assert result.interrupted
    save_run(result, tmp_path, complete=False)
    assert not (tmp_path / "summary.json").exists() and (tmp_path / CHECKPOINT).exists()
    run = read_run(tmp_path)
    assert "interrupted at t = " in run.summary["reason"]
    for path in plot_run(tmp_path):
        assert_png(path)
    (tmp_path / CHECKPOINT).unlink()  # no checkpoint and no summary: not a run
    with pytest.raises(RunDirectoryError, match="missing summary.json"):
        plot_run(tmp_path)
