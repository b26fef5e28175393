"""What a notebook shows: each figure once, and a text progress bar without ipywidgets.

The tutorial itself runs as a notebook in CI (.ci/tutorial-notebook); these are the two
switches it relies on, without a kernel.
"""

import io
import warnings

import pytest

import beltsim
from beltsim.plots import common
from beltsim.simulation import trackers

pytestmark = pytest.mark.unit


@pytest.fixture(scope="module")
def exact():
    return beltsim.solve(beltsim.paper_scene("slip"))


@pytest.mark.parametrize("inline", [True, False])
def test_a_new_figure_leaves_pyplot_only_under_the_inline_backend(monkeypatch, exact, inline,
                                                                 tmp_path):
    import matplotlib.pyplot as plt

    monkeypatch.setattr(common, "_inline_backend", lambda: inline)
    fig = beltsim.plot_fields(exact)
    try:
        # under the inline backend pyplot would show it again at the cell's end
        assert (fig.number in plt.get_fignums()) is not inline
        fig.savefig(tmp_path / "fields.png")  # closed or not, it draws and saves
        assert (tmp_path / "fields.png").stat().st_size > 0
    finally:
        plt.close(fig)


def test_the_inline_backend_is_recognised_by_its_names(monkeypatch):
    import matplotlib

    for name, inline in (("module://matplotlib_inline.backend_inline", True),
                         ("inline", True), ("agg", False), ("module://ipympl.backend_nbagg",
                                                           False)):
        monkeypatch.setattr(matplotlib, "get_backend", lambda name=name: name)
        assert common._inline_backend() is inline, name


@pytest.mark.parametrize("kernel, widgets, kind", [
    (True, False, "std"), (True, True, "notebook"), (False, False, "std"),
    (False, True, "std")])
def test_the_progress_bar_is_a_widget_only_in_a_kernel_with_ipywidgets(monkeypatch, kernel,
                                                                       widgets, kind):
    monkeypatch.setattr(trackers, "_in_kernel", lambda: kernel)
    monkeypatch.setattr(trackers, "_has_widgets", lambda: widgets)
    if kind == "notebook":
        pytest.importorskip("ipywidgets")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # tqdm.auto's "IProgress not found" would raise
        bar = trackers.progress_bar(total=1.0, leave=False, file=io.StringIO(),
                                    disable=kind == "notebook")
    try:
        assert type(bar).__module__ == f"tqdm.{kind}"
        if kind == "std":  # in a kernel it stays, so a saved notebook shows the end
            assert bar.leave is kernel
    finally:
        bar.close()
