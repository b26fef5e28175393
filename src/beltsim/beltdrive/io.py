"""Files of a drive's run or analytic solution: summary.json, fields.csv, history.csv."""

from __future__ import annotations

import numpy as np

from ..errors import NoSolutionError
from ..io.files import prepare_outdir, write_atomic, write_csv, write_json
from .run import DriveResult

#: the snapshots of a run (``beltsim run --snapshots``), for ``beltsim animate --from``
SNAPSHOTS = "snapshots.npz"
#: nodal fields written to fields.csv, after x
FIELD_KEYS = ("u", "theta", "tension", "friction", "pressure", "slip_velocity", "slip")


def power_balance(summary: dict) -> float:
    """driver - load - slip - damping - gyroscopic + transport power (W) of a summary:
    the rate of the stored energy (run.power_terms), zero at a steady state."""
    return float(summary["driver_power"] - summary["load_power"] - summary["slip_power"]
                 - summary["damping_power"] - summary["gyroscopic_power"]
                 + summary["transport_power"])


def result_summary(result: DriveResult) -> dict:
    """The summary.json of a run: status, figures, errors against the analytic state."""
    ana = result.analytic.summary() if result.analytic is not None else None
    return {
        "title": result.scene.title, "kind": "closed drive",
        "model": result.scene.params.model, "status": result.status.value,
        "converged": result.converged, "reason": result.reason,
        "integrator": result.numerics.integrator, "elements": result.numerics.elements,
        **{k: float(v) for k, v in result.summary.items()},
        # zero at a steady state to the grid's error (the stored energy's rate otherwise)
        "power_balance": power_balance(result.summary),
        "analytic": ana, "error": result.errors() or None,
        "wall_time": result.wall_time, **result.statistics,
    }


def save_drive_run(result: DriveResult, out) -> None:
    """Write summary.json, fields.csv, history.csv and scene.toml of a run into ``out``."""
    out = prepare_outdir(out)
    write_json(out / "summary.json", result_summary(result))
    cols = [result.x] + [np.asarray(result.fields[k], dtype=float) for k in FIELD_KEYS]
    write_csv(out / "fields.csv", ("x",) + FIELD_KEYS, cols)
    if result.history:
        keys = tuple(result.history)
        write_csv(out / "history.csv", keys, [result.history[k] for k in keys])
    write_atomic(out / "scene.toml", result.scene.to_toml())
    if result.snapshots and len(result.snapshots.get("t", ())):
        np.savez_compressed(out / SNAPSHOTS, x=result.x, **result.snapshots)


def format_drive(summary: dict, title: str = "") -> str:
    """A short table of a drive's figures."""
    units = {"tight_tension": "N", "slack_tension": "N", "belt_speed": "m/s",
             "driven_speed": "rad/s", "speed_ratio": "", "slip_arc_driver": "rad",
             "slip_arc_driven": "rad", "driver_torque": "N m", "efficiency": "",
             "slip_power": "W"}
    width = max(len(k) for k in units)
    lines = [title] if title else []
    for k, unit in units.items():
        if summary.get(k) is not None:
            lines.append(f"  {k:<{width}}  {summary[k]:.8g} {unit}".rstrip())
    return "\n".join(lines)


def read_drive_run(run_dir):
    """(scene, x, fields, history, summary) of a stored drive run."""
    import csv
    import json
    from pathlib import Path

    from .scene import DriveScene

    run_dir = Path(run_dir)
    scene = DriveScene.load(run_dir / "scene.toml")

    def columns(name):
        with open(run_dir / name, newline="") as fh:
            rows = list(csv.reader(fh))
        return {k: np.array([float(r[i]) for r in rows[1:]]) for i, k in enumerate(rows[0])}

    f = columns("fields.csv")
    hist = columns("history.csv") if (run_dir / "history.csv").is_file() else {}
    summary = json.loads((run_dir / "summary.json").read_text())
    return scene, f.pop("x"), f, hist, summary


def plot_drive_run(run_dir, out=None) -> list:
    """Draw a stored drive run: drive.png (to scale, coloured by tension, slip arcs),
    fields.png (tension and friction along the loop against the analytic state) and,
    where it has one, history.png. Returns the paths written."""
    from pathlib import Path

    from ..plots.common import save_figure
    from . import plots
    from .run import analytic_of

    scene, x, f, hist, summary = read_drive_run(run_dir)
    out = prepare_outdir(out or run_dir)
    g = scene.params.geometry
    try:
        ana = analytic_of(scene.params)
    except NoSolutionError:  # no steady state (gross slip): the run's own fields only
        ana = None
    paths = [save_figure(plots.draw_drive, out / "drive.png", g, x, f["tension"],
                         f["slip"] > 0.5, title=scene.title or Path(run_dir).name),
             save_figure(plots.plot_loop_fields, out / "fields.png", x,
                         {"tension": f["tension"], "friction": f["friction"]}, g,
                         analytic=ana)]
    if hist:
        paths.append(save_figure(plots.plot_drive_history, out / "history.png", hist["t"],
                                 hist))
    return paths


def animate_drive_run(run_dir, path, fps: int = 15):
    """Animate the snapshots of a stored drive run into ``path`` (.gif or .mp4)."""
    from pathlib import Path

    from ..errors import UsageError
    from . import plots
    from .scene import DriveScene

    run_dir = Path(run_dir)
    if not (run_dir / SNAPSHOTS).is_file():
        raise UsageError(f"{run_dir}: no {SNAPSHOTS} there (run with --snapshots INTERVAL)")
    scene = DriveScene.load(run_dir / "scene.toml")
    data = np.load(run_dir / SNAPSHOTS)
    frames = [{"tension": data["tension"][i], "slip": data["slip"][i],
               "belt_speed": float(data["belt_speed"][i]),
               "driven_speed": float(data["driven_speed"][i])} for i in range(len(data["t"]))]
    return plots.animate_drive(scene.params.geometry, data["x"], frames, times=data["t"],
                               path=path, fps=fps)
