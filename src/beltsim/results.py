"""Results and I/O: summary.json, fields.csv, history.csv, all written atomically.

Every file goes to a temporary name in the same directory and is renamed into
place, so an interrupted or killed run never leaves a half-written output.
"""

from __future__ import annotations

import json
import math
import os
import tempfile
from pathlib import Path

import numpy as np

from .errors import BeltsimError

FIELDS_HEADER = ("x", "u", "theta", "strain", "tension", "moment", "friction")


class OutputError(BeltsimError, ValueError):
    """The output directory cannot be created or written."""


def prepare_outdir(path) -> Path:
    """Create the output directory (and parents), or fail with a one-line reason."""
    path = Path(path)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise OutputError(f"--out {path}: exists and is not a directory") from None
    except OSError as exc:
        raise OutputError(f"--out {path}: cannot create directory ({exc.strerror})") from None
    if not os.access(path, os.W_OK | os.X_OK):
        raise OutputError(f"--out {path}: directory is not writable")
    return path


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


_UMASK = _umask()


def write_atomic(path, data: bytes | str) -> Path:
    """Write ``data`` to ``path`` through a temporary file and a rename."""
    path = Path(path)
    if isinstance(data, str):
        data = data.encode("utf-8")
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    except OSError as exc:
        raise OutputError(f"{path}: cannot write ({exc.strerror})") from None
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o666 & ~_UMASK)  # mkstemp makes it private; outputs are ordinary files
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise
    return path


def _jsonable(value):
    if isinstance(value, dict):
        return {k: _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, (np.bool_, bool)):
        return bool(value)
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        value = float(value)
        # JSON has no NaN; a missing number is null, never a fake value
        return value if math.isfinite(value) else None
    return value


def write_json(path, obj) -> Path:
    return write_atomic(path, json.dumps(_jsonable(obj), indent=2) + "\n")


def write_csv(path, header, columns, text_columns=()) -> Path:
    """Columns of equal length under a header, full double precision.

    Columns named in ``text_columns`` are written as text (quoted where needed);
    numbers as repr() (round-trips exactly), NaN as "nan".
    """
    import csv
    import io

    cols = [list(c) if name in text_columns else [repr(float(v)) for v in np.asarray(c, float)]
            for name, c in zip(header, columns)]
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(header)
    writer.writerows(zip(*cols))
    return write_atomic(path, buf.getvalue())


def write_fields(path, x, fields: dict) -> Path:
    return write_csv(path, FIELDS_HEADER, [x] + [fields[k] for k in FIELDS_HEADER[1:]])


def read_csv(path) -> dict:
    """Read a CSV written by :func:`write_csv` into a dict of arrays."""
    with open(path) as fh:
        header = fh.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return {name: data[:, i] for i, name in enumerate(header)}


def save_run(result, out) -> list[Path]:
    """Write a run's summary.json, fields.csv, history.csv and scene.toml into ``out``.

    A failed run writes its summary (converged = false, the reason) and the
    fields of the last good state, which hold no NaN by construction.
    """
    out = prepare_outdir(out)
    sol = result.solution
    paths = [
        write_fields(out / "fields.csv", sol.x, sol.fields()),
        write_csv(out / "history.csv", ("t", "total_friction", "rate"),
                  [result.history["t"], result.history["total_friction"],
                   result.history["rate"]]),
        write_atomic(out / "scene.toml", result.scene.to_toml()),
    ]
    if result.snapshots:
        paths.append(write_snapshots(out / SNAPSHOTS, result))
    # the summary last: its presence means the other files are complete
    paths.append(write_json(out / "summary.json", result.summary()))
    return paths


SNAPSHOTS = "snapshots.npz"


def write_snapshots(path, result) -> Path:
    """States at every snapshot interval, compressed, in single precision.

    Arrays: ``x`` (nodes), ``t`` (times), ``u``, ``theta``, ``friction`` (element
    traction in N/m at the downstream node, as in fields.csv), each (times, nodes);
    ``scene`` (the scene as TOML text). Single precision keeps a long run's file small
    and is far finer than a plot.
    """
    import io

    sol = result.solution
    snaps = result.snapshots
    he = sol.grid.he
    traction = np.zeros_like(snaps["fnode"])
    traction[:, 1:] = snaps["fnode"][:, 1:] / he
    buf = io.BytesIO()
    np.savez_compressed(buf, x=sol.x, t=snaps["t"], u=snaps["u"].astype(np.float32),
                        theta=snaps["theta"].astype(np.float32),
                        friction=traction.astype(np.float32),
                        scene=np.array(result.scene.to_toml()))
    return write_atomic(path, buf.getvalue())


def read_snapshots(path) -> dict:
    """The arrays of :func:`write_snapshots`, with ``scene`` as a Scene."""
    import tomllib

    from .scene import Scene
    try:
        with np.load(path) as z:
            data = {k: z[k] for k in ("x", "t", "u", "theta", "friction")}
            data["scene"] = Scene(tomllib.loads(str(z["scene"])))
    except (OSError, KeyError, ValueError) as exc:
        raise OutputError(f"{path}: not a beltsim snapshots file ({exc})") from None
    return data
