"""A run drawn as figures: its final fields and its history, against the exact steady state.

:func:`~beltsim.plot_fields` and :func:`~beltsim.plot_history` draw a run in memory (a
:class:`~beltsim.RunResult`, or a stored run that :func:`read_run` read back) or an
:class:`~beltsim.AnalyticSolution`, on the caller's axes or a new figure, and return the
Figure. :func:`plot_run` draws a stored run directory to files (``beltsim plot DIR``)
through the same two functions: it reads nothing but the files the run wrote
(:func:`beltsim.save_run`), so a run can be drawn long after it ended, on another
machine, without running it again.
"""

from __future__ import annotations

import json
import textwrap
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import BeltsimError
from ..io.files import prepare_outdir, read_csv
from ..io.results import CHECKPOINT, FIELDS_HEADER
from ..problem.analytic import AnalyticSolution
from ..problem.drive import profile_times
from ..problem.scene import Scene
from ..simulation.result import RunResult, reference_of
from .animate import PANELS
from .common import panel_axes, save_figure

RUN_FILES = ("scene.toml", "fields.csv", "history.csv", "summary.json")
# the run a little wider than the dashed analytic curve, so it still shows where they agree
RUN_STYLE = {"color": "tab:red", "lw": 2.0}
EXACT_STYLE = {"color": "k", "ls": "--", "lw": 1.0}
PROFILE_STYLE = {"color": "tab:purple", "ls": ":", "lw": 1.0}
#: axis labels of the fields by key; the default panels (animate's) top to bottom
FIELD_LABELS = dict(PANELS) | {"strain": "strain [-]"}
# history columns with a panel of their own, in panel order: (key, axis label); the stick
# and slip parts of the friction share the total's panel, t is the abscissa
HISTORY_PANELS = (("total_friction", "friction [N]"),
                  ("slip_start", "slip start x* [m]"),
                  ("concentrated_force", "concentrated force F [N]"),
                  ("slip_power", "slip power [W]"),
                  ("rate", "largest rate / (c |e0|) [-]"))
# (column, name, colour, width): the total widest, as a part may lie on it (no slip yet)
FRICTION_PARTS = (("total_friction", "total", "tab:red", 2.4),
                  ("stick_friction", "stick part", "tab:blue", 1.3),
                  ("slip_friction", "slip part", "tab:green", 1.3))
DPI = 110
EXACT_SAMPLES = 1201


class RunDirectoryError(BeltsimError, ValueError):
    """A directory does not hold a complete run that can be drawn."""


@dataclass(frozen=True)
class RunRecord:
    """A run as its figures draw it: the same whether in memory or read from its files.

    Attributes
    ----------
    scene : Scene
        The scene that ran.
    fields : dict of str to numpy.ndarray
        The final state: ``x`` and the nodal fields (the columns of fields.csv).
    history : dict of str to numpy.ndarray
        The checks: ``t`` and the recorded quantities (the columns of history.csv).
    summary : dict
        As summary.json (status, simulated time, integrator, totals); an interrupted
        run's has ``interrupted`` true.
    source : Path or None
        The run directory it was read from (None for a run in memory).
    """

    scene: Scene
    fields: dict
    history: dict
    summary: dict
    source: Path | None = None

    @classmethod
    def of(cls, result: RunResult) -> RunRecord:
        """The record of a run in memory.

        Parameters
        ----------
        result : RunResult

        Returns
        -------
        RunRecord
        """
        summary = result.summary()
        if result.interrupted:
            summary["interrupted"] = True
        return cls(result.scene, result.fields, result.history, summary)


def as_record(run) -> RunRecord:
    """A :class:`RunRecord` of a RunResult (or the record itself).

    Parameters
    ----------
    run : RunResult or RunRecord

    Returns
    -------
    RunRecord

    Raises
    ------
    TypeError
        Anything else.
    """
    if isinstance(run, RunRecord):
        return run
    if isinstance(run, RunResult):
        return RunRecord.of(run)
    raise TypeError(f"expected a RunResult or a stored run (read_run), got "
                    f"{type(run).__name__}")


def plot_run(run_dir, out=None) -> list[Path]:
    """Draw the run stored in ``run_dir`` as ``fields.png`` and ``history.png`` in ``out``.

    Reads only what ``beltsim run`` (or :func:`beltsim.save_run`) wrote in ``run_dir``
    (:func:`read_run`); the analytic steady state of the same scene is computed afresh and
    overlaid where the scene has one. The figures are those of :func:`~beltsim.plot_fields`
    (friction, tension, moment, rotation and displacement against x) and
    :func:`~beltsim.plot_history` (the total friction and its stick and slip parts, the
    slip start or the concentrated force, the slip power and the largest rate against t,
    with the profile tables' row times and the analytic values marked), each written
    atomically.

    A run that stopped before steady state (t_end, numerical failure, a signal) is
    drawn as it stopped (an interrupted run wrote no summary.json, only a checkpoint
    beside its state so far).

    Parameters
    ----------
    run_dir : str or Path
        The output directory of a run.
    out : str or Path, optional
        Where to write the figures (default ``run_dir``).

    Returns
    -------
    list of Path
        fields.png and history.png.

    Raises
    ------
    RunDirectoryError
        A directory without the run's files, or with unreadable ones.
    """
    run_dir = Path(run_dir)
    run = read_run(run_dir)
    out = prepare_outdir(run_dir if out is None else out)
    reference = reference_of(run.scene)
    return [save_figure(plot_fields, out / "fields.png", run, exact=reference, dpi=DPI),
            save_figure(plot_history, out / "history.png", run, exact=reference, dpi=DPI)]


# ---------------------------------------------------------------------------
# reading


def read_run(run_dir) -> RunRecord:
    """The files of a stored run, as the record its figures draw.

    Parameters
    ----------
    run_dir : str or Path
        The output directory of ``beltsim run`` (or :func:`beltsim.save_run`).

    Returns
    -------
    RunRecord
        Its scene (scene.toml), fields (fields.csv), history (history.csv) and summary
        (summary.json; for an interrupted run, which wrote a checkpoint instead, one
        that says so).

    Raises
    ------
    RunDirectoryError
        Naming the problem: no directory, a missing file, an unreadable one.
    """
    run_dir = Path(run_dir)
    if not run_dir.exists():
        raise RunDirectoryError(f"{run_dir}: no such directory")
    if not run_dir.is_dir():
        raise RunDirectoryError(f"{run_dir}: not a directory")
    missing = [name for name in RUN_FILES if not (run_dir / name).is_file()]
    # an interrupted run writes its state so far and a checkpoint, but no summary
    interrupted = missing == ["summary.json"] and (run_dir / CHECKPOINT).is_file()
    if missing and not interrupted:
        raise RunDirectoryError(f"{run_dir}: not a beltsim run directory (missing "
                                f"{', '.join(missing)})")
    scene = Scene.load(run_dir / "scene.toml")
    fields = _read_table(run_dir / "fields.csv", FIELDS_HEADER)
    if not len(fields["x"]):
        raise RunDirectoryError(f"{run_dir / 'fields.csv'}: no rows")
    history = _read_table(run_dir / "history.csv", ("t", "total_friction"))
    if interrupted:
        t = float(history["t"][-1]) if len(history["t"]) else 0.0
        summary = {"interrupted": True, "simulated_time": t, "reason": (
            f"interrupted at t = {t:.4g} s; continue with 'beltsim run --resume {run_dir}'")}
        return RunRecord(scene, fields, history, summary, run_dir)
    try:
        summary = json.loads((run_dir / "summary.json").read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise RunDirectoryError(f"{run_dir / 'summary.json'}: unreadable ({exc})") from None
    if not isinstance(summary, dict):
        raise RunDirectoryError(f"{run_dir / 'summary.json'}: not a run summary")
    return RunRecord(scene, fields, history, summary, run_dir)


def _read_table(path: Path, required) -> dict:
    """A CSV of the run as a dict of arrays; empty arrays for a header without rows."""
    try:
        with open(path) as fh:
            header = fh.readline().strip().split(",")
            has_rows = any(line.strip() for line in fh)
    except (OSError, UnicodeDecodeError) as exc:
        raise RunDirectoryError(f"{path}: unreadable ({exc})") from None
    absent = [k for k in required if k not in header]
    if absent:
        raise RunDirectoryError(f"{path}: no column {', '.join(absent)} (header: "
                                f"{','.join(header)})")
    # a run stopped before its first check (or a steady solve) has no history rows,
    # which read_csv cannot take
    if not has_rows:
        return {k: np.zeros(0) for k in header}
    try:
        return read_csv(path)
    except (ValueError, IndexError) as exc:
        raise RunDirectoryError(f"{path}: unreadable ({exc})") from None


# ---------------------------------------------------------------------------
# figures


def _reference(run, record: RunRecord | None, exact):
    """The analytic solution a figure overlays: ``exact`` itself, none (False or None),
    or (True) the one a result carries, else the scene's."""
    if exact is None or exact is False:
        return None
    if isinstance(exact, AnalyticSolution):
        return exact
    if exact is not True:
        raise TypeError(f"exact: must be True, False or an AnalyticSolution, got {exact!r}")
    if isinstance(run, RunResult) and run.reference is not None:
        return run.reference
    return reference_of(record.scene)


def _status(run: RunRecord) -> str:
    s = run.summary
    where = f"{s.get('elements', '?')} elements, {s.get('steps', '?')} steps"
    if s.get("converged"):
        return f"steady at t = {s.get('simulated_time', float('nan')):.4g} s ({where})"
    if s.get("interrupted"):
        return s["reason"]
    return f"unfinished ({where}): {s.get('reason') or 'no reason recorded'}"


def _title(fig, run: RunRecord | None, what: str, reference) -> None:
    if run is None:
        fig.suptitle(f"{what}: analytic steady state ({reference.model} model)", fontsize=9.5)
        return
    scene = run.scene
    head = scene.title or str(run.source or scene.source or "untitled scene")
    lines = textwrap.wrap(f"{what}: {head}", 95) + textwrap.wrap(_status(run), 95)
    if reference is None:
        lines.append("no analytic steady state for this scene: the run only")
    fig.suptitle("\n".join(lines), fontsize=9.5)


def _run_label(run: RunRecord) -> str:
    s = run.summary
    return (f"run (t = {s.get('simulated_time', float('nan')):.4g} s, "
            f"{s.get('integrator', '?')})")


def _choose(keys, known, what):
    """The panels asked for, in the order given; an unknown one is a ValueError."""
    keys = (keys,) if isinstance(keys, str) else tuple(keys)
    if not keys:
        raise ValueError("keys: give at least one panel (or None for all)")
    for k in keys:
        if k not in known:
            raise ValueError(f"keys: {what} has no {k!r} (it has {', '.join(known)})")
    return keys


def plot_fields(result, keys=None, ax=None, exact=True):
    """The final fields over x, one panel each, with the exact steady state dashed.

    Parameters
    ----------
    result : RunResult, RunRecord or AnalyticSolution
        A run (in memory, or a stored one from :func:`~beltsim.plots.run.read_run`), or an analytic
        solution alone.
    keys : str or sequence of str, optional
        The fields, one panel each: ``"friction"``, ``"tension"``, ``"moment"``,
        ``"theta"``, ``"u"`` (the default, top to bottom) and ``"strain"``.
    ax : Axes or sequence of Axes, optional
        Where to draw: one Axes per key. Default a new figure (with a title and a
        legend below the panels).
    exact : bool or AnalyticSolution, optional
        The analytic steady state to overlay: True (default) the one the result
        carries or, without it, the scene's (none where the scene has none); False
        for none; or a solution of your own.

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn on (the one ``ax`` belongs to, when given).

    Raises
    ------
    ValueError
        An unknown key, or ``ax`` holding another number of Axes than keys.

    Examples
    --------
    >>> fig = plot_fields(result)                                  # doctest: +SKIP
    >>> fig, ax = plt.subplots()                                   # doctest: +SKIP
    >>> plot_fields(result, keys="theta", ax=ax)                   # doctest: +SKIP
    """
    if isinstance(result, AnalyticSolution):
        run, reference, P = None, result, result.params
    else:
        run = as_record(result)
        reference, P = _reference(result, run, exact), run.scene.params
    keys = _choose(tuple(k for k, _ in PANELS) if keys is None else keys,
                   tuple(FIELD_LABELS), "the fields")
    fig, axes, own = panel_axes(ax, len(keys), figsize=(8.5, 1.5 + 1.8 * len(keys)),
                                sharex=True)
    sample = reference.sample(EXACT_SAMPLES) if reference is not None else None
    for ax_, key in zip(axes, keys):
        ax_.axvspan(P.x1, P.x2, color="0.92", zorder=0,
                    label=f"contact [{P.x1:.4g}, {P.x2:.4g}] m")
        if run is not None:
            ax_.plot(run.fields["x"], run.fields[key], label=_run_label(run), **RUN_STYLE)
        if sample is not None:
            ax_.plot(sample[0], sample[1][key], label="analytic steady state", **EXACT_STYLE)
        ax_.set_ylabel(FIELD_LABELS[key], fontsize=9)
        ax_.grid(True, alpha=0.3)
        if key == "friction" and run is not None:
            _clip_force_layer(ax_, run, reference, sample)
    axes[-1].set_xlabel("x [m]")
    axes[-1].set_xlim(0.0, P.L)
    if own:
        fig.legend(*axes[0].get_legend_handles_labels(), loc="outside lower center",
                   ncols=3, fontsize=8.5)
        _title(fig, run, "final fields", reference)
    else:
        axes[0].legend(fontsize=8)
    return fig


def _clip_force_layer(ax, run: RunRecord, reference, sample) -> None:
    """Perfect adhesion: keep the run's force layer at x2 from flattening the traction.

    The run carries the exact concentrated force as a traction over its last few contact
    elements, orders of magnitude above the distributed traction; the axis is cut at 1.5
    times the exact traction, the cut points are marked and both forces are written out.
    """
    if reference is None or reference.model != "stick":
        return
    x, f = run.fields["x"], run.fields["friction"]
    cap = 1.5 * np.max(np.abs(sample[1]["friction"]))
    off = np.abs(f) > cap
    if not cap > 0 or not np.any(off):
        return
    lo = -cap if np.min(f) < -0.1 * cap else -0.1 * cap
    ax.set_ylim(lo, cap)
    ax.plot(x[off], np.clip(f[off], lo, cap) * 0.97, "^", color=RUN_STYLE["color"], ms=5,
            label="run, off scale")
    force = run.summary.get("concentrated_force")
    text = f"concentrated force at x2: exact {reference.concentrated_force:.4g} N"
    if force is not None:
        text += f", run {force:.4g} N"
    ax.text(0.01, 0.95, text, transform=ax.transAxes, fontsize=8, va="top",
            bbox={"facecolor": "white", "edgecolor": "none", "alpha": 0.8})


def plot_history(result, keys=None, ax=None, exact=True):
    """The history's quantities against t, one panel each, with the exact values dashed.

    The stick and slip parts of the friction share the total's panel; the rate's panel
    is logarithmic and marks the steady tolerance; dotted lines mark the times of the
    drive profiles' table rows. Columns this function does not know get a panel too.

    Parameters
    ----------
    result : RunResult or RunRecord
        A run in memory, or a stored one from :func:`~beltsim.plots.run.read_run`.
    keys : str or sequence of str, optional
        The panels: ``"total_friction"``, ``"slip_start"`` or ``"concentrated_force"``,
        ``"slip_power"``, ``"rate"`` and any other column, of those the run recorded
        (default all of them).
    ax : Axes or sequence of Axes, optional
        Where to draw: one Axes per panel. Default a new figure (with a title).
    exact : bool or AnalyticSolution, optional
        Whose steady values to mark: True (default) the result's reference or the
        scene's, False none, or a solution of your own.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ValueError
        A key the run did not record, or ``ax`` holding another number of Axes.
    TypeError
        An analytic solution (it has no history).

    Examples
    --------
    >>> plot_history(result, keys=("total_friction", "rate"))      # doctest: +SKIP
    """
    run = as_record(result)
    reference = _reference(result, run, exact)
    scene, h = run.scene, run.history
    t = h["t"]
    known = {k for k, _ in HISTORY_PANELS} | {k for k, *_ in FRICTION_PARTS} | {"t"}
    # columns this module has never heard of still get a panel, named after the column
    panels = [(k, label) for k, label in HISTORY_PANELS if k in h]
    panels += [(k, k.replace("_", " ")) for k in h if k not in known]
    if keys is not None:
        labels = dict(panels)
        panels = [(k, labels[k]) for k in _choose(keys, tuple(labels), "this history")]
    values = reference.summary() if reference is not None else {}
    times = profile_times(scene)
    fig, axes, own = panel_axes(ax, len(panels), figsize=(8.5, 1.2 + 2.0 * len(panels)),
                                sharex=True)
    marker = "." if len(t) <= 40 else None  # a short history is a few points, not a line
    for ax_, (key, label) in zip(axes, panels):
        if key == "total_friction":
            for part, name, color, width in FRICTION_PARTS:
                if part not in h:
                    continue
                ax_.plot(t, h[part], color=color, lw=width, marker=marker, label=f"run: {name}")
                if values.get(part) is not None:
                    ax_.axhline(values[part], color=color, ls="--", lw=1.0,
                                label=f"analytic: {name}")
        elif key == "rate":
            y = np.where(h[key] > 0, h[key], np.nan)
            ax_.semilogy(t, y, marker=marker, label="run", **RUN_STYLE)
            # a periodic drive is judged on its period's repeat, not on the rate falling
            tol = _steady_tol(scene) if run.summary.get("periodic") is None else None
            if tol is not None:
                ax_.axhline(tol, color="0.4", ls="--", lw=1.0, label="steady tolerance")
        else:
            ax_.plot(t, h[key], marker=marker, label="run", **RUN_STYLE)
            if values.get(key) is not None:
                ax_.axhline(values[key], label="analytic steady state", **EXACT_STYLE)
        for k, tk in enumerate(times):
            ax_.axvline(tk, label="profile row times" if k == 0 else None, **PROFILE_STYLE)
        ax_.set_ylabel(label, fontsize=9)
        ax_.grid(True, alpha=0.3)
        ax_.legend(fontsize=7.5, loc="best", ncols=2 if key == "total_friction" else 1)
    axes[-1].set_xlabel("t [s]")
    if len(t):
        axes[-1].set_xlim(0.0, max(t[-1], *times) if times else t[-1])
    else:
        axes[0].text(0.5, 0.5, "no history recorded (the run made no check)",
                     transform=axes[0].transAxes, ha="center", va="center")
    if own:
        _title(fig, run, "history", reference)
    return fig


def _steady_tol(scene) -> float | None:
    from ..solvers.settings import resolve

    try:
        return resolve(scene).steady_tol
    except BeltsimError:  # a scene the numerics refuse still has a history to draw
        return None
