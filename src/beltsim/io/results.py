"""A run's outputs: summary.json, fields.csv, history.csv, scene.toml, snapshots, checkpoints.

All written atomically (:mod:`beltsim.io.files`); ``summary.json`` last, so its
presence means the run's outputs are complete.
"""

from __future__ import annotations

import io
import tomllib
from pathlib import Path

import numpy as np

from ..errors import SceneError
from ..problem.kinds import scene_from_tables
from ..problem.scene import Scene
from .files import OutputError, prepare_outdir, write_atomic, write_csv, write_json

FIELDS_HEADER = ("x", "u", "theta", "strain", "tension", "moment", "friction")
SNAPSHOTS = "snapshots.npz"
CHECKPOINT = "checkpoint.npz"


def write_fields(path, x, fields: dict, keys=FIELDS_HEADER[1:]) -> Path:
    """Write fields.csv: x and the fields ``keys`` (default FIELDS_HEADER's, the paper's
    belt; a drive's run writes its own)."""
    return write_csv(path, ("x", *keys), [x] + [np.asarray(fields[k], dtype=float)
                                                 for k in keys])


def save_run(result, out, complete: bool = True) -> list[Path]:
    """Write a run's summary.json, fields.csv, history.csv and scene.toml into ``out``.

    A failed run writes its summary (converged = false, the reason) and the
    fields of the last good state, which hold no NaN by construction. An interrupted
    run (``complete`` false) writes all but the summary: its state so far can be
    looked at, and the missing summary says it is not finished.
    """
    out = prepare_outdir(out)
    sol = result.solution
    keys = tuple(result.history)
    paths = [
        write_fields(out / "fields.csv", sol.x, sol.fields(), tuple(sol.fields())),
        write_csv(out / "history.csv", keys, [result.history[k] for k in keys]),
        write_atomic(out / "scene.toml", result.scene.to_toml()),
    ]
    if result.snapshots:
        paths.append(write_snapshots(out / SNAPSHOTS, result))
    # the summary last: its presence means the other files are complete
    if complete:
        paths.append(write_json(out / "summary.json", result.summary()))
    return paths


def write_snapshots(path, result) -> Path:
    """States at every snapshot interval, compressed, in single precision.

    Arrays: ``x`` (nodes), ``t`` (times) and the layout's fields, each (times, nodes)
    (``result.solution.snapshot_arrays``): ``u``, ``theta``, ``friction`` (the traction in
    N/m at the friction nodes, as in fields.csv) and, for a drive, ``tension``, ``slip``
    and the speeds ``belt_speed``, ``driven_speed`` (times), with a moving tensioner's arm
    ``arm_travel`` (times) and ``grid_arm_travel`` (the grid's layout's, double
    precision); ``scene`` (the scene as TOML text). Single precision keeps a long run's
    file small and is far finer than a plot.
    """
    sol, snaps = result.solution, result.snapshots
    # the fields in single precision; a scalar (the grid's arm turn) as it is
    arrays = {k: np.asarray(v).astype(np.float32)
              if np.asarray(v).dtype.kind == "f" and np.ndim(v) else v
              for k, v in sol.snapshot_arrays(snaps).items()}
    buf = io.BytesIO()
    np.savez_compressed(buf, x=sol.x, t=snaps["t"], **arrays,
                        scene=np.array(result.scene.to_toml()))
    return write_atomic(path, buf.getvalue())


def read_snapshots(path) -> dict:
    """The arrays of :func:`write_snapshots`, with ``scene`` as a Scene."""
    try:
        with np.load(path) as z:
            data = {k: z[k] for k in ("x", "t", "u", "theta", "friction")}
            data["scene"] = Scene(tomllib.loads(str(z["scene"])))
    except (OSError, KeyError, ValueError) as exc:
        raise OutputError(f"{path}: not a beltsim snapshots file ({exc})") from None
    return data


def write_checkpoint(path, sim) -> Path:
    """Everything a resumed run needs to continue exactly as this one would.

    The state, the time, the scheme's own state (step size, counters) and the state
    of every tracker that carries one, each under a prefix of its own.
    """
    data = {f"state.{k}": a for k, a in zip(sim.state._fields, sim.state)}
    data.update({f"scheme.{k}": v for k, v in sim.scheme.checkpoint().items()})
    for name, items in sim.tracker_states().items():
        data.update({f"tracker.{name}.{k}": v for k, v in items.items()})
    data["t"], data["wall_time"] = np.array(sim.t), np.array(sim.wall_time)
    data["scene"] = np.array(sim.scene.to_toml())
    buf = io.BytesIO()
    np.savez(buf, **data)
    return write_atomic(path, buf.getvalue())


def read_checkpoint(path) -> dict:
    """The parts of :func:`write_checkpoint`: scene (of either kind), t, wall_time, state,
    scheme, trackers."""
    try:
        with np.load(path) as z:
            scene = scene_from_tables(tomllib.loads(str(z["scene"])))
            out = {"scene": scene, "t": float(z["t"]), "wall_time": float(z["wall_time"]),
                   "state": {}, "scheme": {}, "trackers": {}}
            for key in z.files:
                part, _, rest = key.partition(".")
                if part in ("state", "scheme"):
                    out[part][rest] = z[key]
                elif part == "tracker":
                    name, _, k = rest.partition(".")
                    out["trackers"].setdefault(name, {})[k] = z[key]
    except (OSError, ValueError, KeyError, tomllib.TOMLDecodeError) as exc:
        raise SceneError(f"--resume: cannot read checkpoint {path} ({exc})") from None
    return out
