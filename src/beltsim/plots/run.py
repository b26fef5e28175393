"""A stored run drawn as figures: its final fields and its history, against the exact steady state.

:func:`plot_run` reads nothing but the files a run wrote (:func:`beltsim.io.results.save_run`),
so a run can be drawn long after it ended, on another machine, without running it again.
"""

from __future__ import annotations

import json
import textwrap
from pathlib import Path

import numpy as np

from ..errors import BeltsimError
from ..io.files import prepare_outdir, read_csv
from ..io.results import CHECKPOINT, FIELDS_HEADER
from ..problem.drive import profile_times
from ..problem.scene import load_scene
from ..simulation.result import reference_of
from .animate import PANELS
from .common import pyplot, save

RUN_FILES = ("scene.toml", "fields.csv", "history.csv", "summary.json")
# the run a little wider than the dashed analytic curve, so it still shows where they agree
RUN_STYLE = {"color": "tab:red", "lw": 2.0}
EXACT_STYLE = {"color": "k", "ls": "--", "lw": 1.0}
PROFILE_STYLE = {"color": "tab:purple", "ls": ":", "lw": 1.0}
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


class RunDirectoryError(BeltsimError, ValueError):
    """A directory does not hold a complete run that can be drawn."""


def plot_run(run_dir, out=None) -> list[Path]:
    """Draw the run stored in ``run_dir`` as ``fields.png`` and ``history.png`` in ``out``.

    Reads only what ``beltsim run`` (or :func:`beltsim.io.results.save_run`) wrote in
    ``run_dir``: scene.toml, fields.csv (the final state), history.csv (the checks) and
    summary.json (status, simulated time, integrator). The analytic steady state of the
    same scene is computed afresh and overlaid where the scene has one.

    Writes into ``out`` (default ``run_dir``), each file atomically:

    * ``fields.png``: friction, tension, moment, rotation and displacement against x;
    * ``history.png``: the total friction (and its stick and slip parts), the slip start
      or the concentrated force, the slip power and the largest rate against t, with
      the profile tables' row times and the analytic values marked.

    A run that stopped before steady state (t_end, numerical failure, a signal) is
    drawn as it stopped (an interrupted run wrote no summary.json, only a checkpoint
    beside its state so far); a directory without the files raises
    :class:`RunDirectoryError`.
    Returns the paths written.
    """
    run_dir = Path(run_dir)
    run = read_run(run_dir)
    out = prepare_outdir(run_dir if out is None else out)
    reference = reference_of(run["scene"])
    return [fields_figure(run, reference, out / "fields.png"),
            history_figure(run, reference, out / "history.png")]


# ---------------------------------------------------------------------------
# reading


def read_run(run_dir) -> dict:
    """The files of a run: scene (Scene), fields and history (dicts of arrays), summary.

    Raises :class:`RunDirectoryError` naming the problem for anything else.
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
    scene = load_scene(run_dir / "scene.toml")
    fields = _read_table(run_dir / "fields.csv", FIELDS_HEADER)
    if not len(fields["x"]):
        raise RunDirectoryError(f"{run_dir / 'fields.csv'}: no rows")
    history = _read_table(run_dir / "history.csv", ("t", "total_friction"))
    if interrupted:
        t = float(history["t"][-1]) if len(history["t"]) else 0.0
        return {"dir": run_dir, "scene": scene, "fields": fields, "history": history,
                "summary": {"interrupted": True, "simulated_time": t, "reason": (
                    f"interrupted at t = {t:.4g} s; continue with "
                    f"'beltsim run --resume {run_dir}'")}}
    try:
        summary = json.loads((run_dir / "summary.json").read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise RunDirectoryError(f"{run_dir / 'summary.json'}: unreadable ({exc})") from None
    if not isinstance(summary, dict):
        raise RunDirectoryError(f"{run_dir / 'summary.json'}: not a run summary")
    return {"dir": run_dir, "scene": scene, "fields": fields, "history": history,
            "summary": summary}


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


def _status(run: dict) -> str:
    s = run["summary"]
    where = f"{s.get('elements', '?')} elements, {s.get('steps', '?')} steps"
    if s.get("converged"):
        return f"steady at t = {s.get('simulated_time', float('nan')):.4g} s ({where})"
    if s.get("interrupted"):
        return s["reason"]
    return f"unfinished ({where}): {s.get('reason') or 'no reason recorded'}"


def _title(fig, run: dict, what: str, reference) -> None:
    scene = run["scene"]
    head = scene.title or str(run["dir"])
    lines = textwrap.wrap(f"{what}: {head}", 95) + textwrap.wrap(_status(run), 95)
    if reference is None:
        lines.append("no analytic steady state for this scene: the run only")
    fig.suptitle("\n".join(lines), fontsize=9.5)


def _run_label(run: dict) -> str:
    s = run["summary"]
    return (f"run (t = {s.get('simulated_time', float('nan')):.4g} s, "
            f"{s.get('integrator', '?')})")


def fields_figure(run: dict, reference, path) -> Path:
    """Friction, tension, moment, rotation and displacement over x, one panel each."""
    plt = pyplot()
    scene, f = run["scene"], run["fields"]
    P = scene.params
    exact = reference.sample(1201) if reference is not None else None
    fig, axes = plt.subplots(len(PANELS), 1, figsize=(8.5, 10.5), sharex=True,
                             layout="constrained")
    for ax, (key, label) in zip(axes, PANELS):
        ax.axvspan(P.x1, P.x2, color="0.92", zorder=0,
                   label=f"contact [{P.x1:.4g}, {P.x2:.4g}] m")
        ax.plot(f["x"], f[key], label=_run_label(run), **RUN_STYLE)
        if exact is not None and key in exact[1]:
            ax.plot(exact[0], exact[1][key], label="analytic steady state", **EXACT_STYLE)
        ax.set_ylabel(label, fontsize=9)
        ax.grid(True, alpha=0.3)
        if key == "friction":
            _clip_force_layer(ax, run, reference, exact)
    axes[-1].set_xlabel("x [m]")
    axes[-1].set_xlim(f["x"][0], f["x"][-1])
    fig.legend(*axes[0].get_legend_handles_labels(), loc="outside lower center", ncols=3,
               fontsize=8.5)
    _title(fig, run, "final fields", reference)
    return save(fig, path, dpi=110)


def _clip_force_layer(ax, run, reference, exact) -> None:
    """Perfect adhesion: keep the run's force layer at x2 from flattening the traction.

    The run carries the exact concentrated force as a traction over its last few contact
    elements, orders of magnitude above the distributed traction; the axis is cut at 1.5
    times the exact traction, the cut points are marked and both forces are written out.
    """
    if reference is None or reference.model != "stick":
        return
    x, f = run["fields"]["x"], run["fields"]["friction"]
    cap = 1.5 * np.max(np.abs(exact[1]["friction"]))
    off = np.abs(f) > cap
    if not cap > 0 or not np.any(off):
        return
    lo = -cap if np.min(f) < -0.1 * cap else -0.1 * cap
    ax.set_ylim(lo, cap)
    ax.plot(x[off], np.clip(f[off], lo, cap) * 0.97, "^", color=RUN_STYLE["color"], ms=5,
            label="run, off scale")
    force = run["summary"].get("concentrated_force")
    text = f"concentrated force at x2: exact {reference.concentrated_force:.4g} N"
    if force is not None:
        text += f", run {force:.4g} N"
    ax.text(0.01, 0.95, text, transform=ax.transAxes, fontsize=8, va="top",
            bbox={"facecolor": "white", "edgecolor": "none", "alpha": 0.8})


def history_figure(run: dict, reference, path) -> Path:
    """The history's columns against t, one panel per quantity, whichever the run recorded."""
    plt = pyplot()
    scene, h = run["scene"], run["history"]
    t = h["t"]
    known = {k for k, _ in HISTORY_PANELS} | {k for k, *_ in FRICTION_PARTS} | {"t"}
    # columns this module has never heard of still get a panel, named after the column
    panels = [(k, label) for k, label in HISTORY_PANELS if k in h]
    panels += [(k, k.replace("_", " ")) for k in h if k not in known]
    exact = reference.summary() if reference is not None else {}
    times = profile_times(scene)
    fig, axes = plt.subplots(len(panels), 1, figsize=(8.5, 1.2 + 2.0 * len(panels)),
                             sharex=True, squeeze=False, layout="constrained")
    axes = axes[:, 0]
    marker = "." if len(t) <= 40 else None  # a short history is a few points, not a line
    for ax, (key, label) in zip(axes, panels):
        if key == "total_friction":
            for part, name, color, width in FRICTION_PARTS:
                if part not in h:
                    continue
                ax.plot(t, h[part], color=color, lw=width, marker=marker, label=f"run: {name}")
                if exact.get(part) is not None:
                    ax.axhline(exact[part], color=color, ls="--", lw=1.0,
                               label=f"analytic: {name}")
        elif key == "rate":
            y = np.where(h[key] > 0, h[key], np.nan)
            ax.semilogy(t, y, marker=marker, label="run", **RUN_STYLE)
            # a periodic drive is judged on its period's repeat, not on the rate falling
            tol = _steady_tol(scene) if run["summary"].get("periodic") is None else None
            if tol is not None:
                ax.axhline(tol, color="0.4", ls="--", lw=1.0, label="steady tolerance")
        else:
            ax.plot(t, h[key], marker=marker, label="run", **RUN_STYLE)
            if exact.get(key) is not None:
                ax.axhline(exact[key], label="analytic steady state", **EXACT_STYLE)
        for k, tk in enumerate(times):
            ax.axvline(tk, label="profile row times" if k == 0 else None, **PROFILE_STYLE)
        ax.set_ylabel(label, fontsize=9)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7.5, loc="best", ncols=2 if key == "total_friction" else 1)
    axes[-1].set_xlabel("t [s]")
    if len(t):
        axes[-1].set_xlim(0.0, max(t[-1], *times) if times else t[-1])
    else:
        axes[0].text(0.5, 0.5, "no history recorded (the run made no check)",
                     transform=axes[0].transAxes, ha="center", va="center")
    _title(fig, run, "history", reference)
    return save(fig, path, dpi=110)


def _steady_tol(scene) -> float | None:
    from ..solvers.settings import resolve

    try:
        return resolve(scene).steady_tol
    except BeltsimError:  # a scene the numerics refuse still has a history to draw
        return None
