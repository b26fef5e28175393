"""Files written atomically: JSON, CSV, any bytes, and files that a library writes.

Every file goes to a temporary name in the same directory and is renamed into
place, so an interrupted or killed run never leaves a half-written output; the
permissions follow the umask like those of any ordinary file.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import tempfile
from pathlib import Path

import numpy as np

from ..errors import BeltsimError


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


@contextlib.contextmanager
def atomic_path(path, suffix=".tmp"):
    """A temporary path beside ``path`` to write to; renamed into place on success.

    For writers that want a file name (matplotlib, imageio); ``suffix`` keeps the
    extension they infer the format from.
    """
    path = Path(path)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix, dir=path.parent)
    except OSError as exc:
        raise OutputError(f"{path}: cannot write ({exc.strerror})") from None
    os.close(fd)
    try:
        yield tmp
        os.chmod(tmp, 0o666 & ~_UMASK)  # mkstemp makes it private; outputs are ordinary files
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def write_atomic(path, data: bytes | str) -> Path:
    """Write ``data`` to ``path`` through a temporary file and a rename."""
    if isinstance(data, str):
        data = data.encode("utf-8")
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
    return Path(path)


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
    """Write ``obj`` as indented JSON, atomically; non-finite numbers become null."""
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


def read_csv(path) -> dict:
    """Read a CSV written by :func:`write_csv` into a dict of arrays."""
    with open(path) as fh:
        header = fh.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return {name: data[:, i] for i, name in enumerate(header)}
