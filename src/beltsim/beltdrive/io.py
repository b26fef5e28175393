"""Files of a drive's run or analytic solution: summary.json, fields.csv, history.csv."""

from __future__ import annotations

import numpy as np

from ..io.files import prepare_outdir, write_atomic, write_csv, write_json
from .run import DriveResult

#: nodal fields written to fields.csv, after x
FIELD_KEYS = ("u", "theta", "tension", "friction", "pressure", "slip_velocity", "slip")


def result_summary(result: DriveResult) -> dict:
    """The summary.json of a run: status, figures, errors against the analytic state."""
    ana = result.analytic.summary() if result.analytic is not None else None
    return {
        "title": result.scene.title, "kind": "closed drive",
        "model": result.scene.params.model, "status": result.status.value,
        "converged": result.converged, "reason": result.reason,
        "integrator": result.numerics.integrator, "elements": result.numerics.elements,
        **{k: float(v) for k, v in result.summary.items()},
        "power_balance": float(result.summary["driver_power"] - result.summary["load_power"]
                               - result.summary["slip_power"]),
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
