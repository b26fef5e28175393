"""A per-user cache of results that take seconds to compute and depend only on a scene's
data: the stability check's spectra (:mod:`beltsim.simulation.stability`).

Entries are JSON files named by a hash of what they depend on and of the package's
version and sources, under ``$BELTSIM_CACHE_DIR``, else ``$XDG_CACHE_HOME/beltsim``, else
``~/.cache/beltsim``. A cache that cannot be read or written is skipped: the value is
computed again, never taken from a damaged file.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

from .files import OutputError, _jsonable, write_atomic


def cache_dir() -> Path:
    """The cache's folder (not created here)."""
    env = os.environ.get("BELTSIM_CACHE_DIR")
    if env:
        return Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "beltsim"


_SOURCES: list[str] = []


def _version() -> str:
    """The package's version and a hash of its sources: an entry computed by other code
    (a source checkout between two edits, another install) is not served."""
    if not _SOURCES:
        from importlib.metadata import PackageNotFoundError, version

        try:
            ver = version("beltsim")
        except PackageNotFoundError:  # a source tree on sys.path, not installed
            ver = "source"
        digest = hashlib.sha256()
        for path in sorted(Path(__file__).resolve().parents[1].rglob("*.py")):
            digest.update(path.read_bytes())
        _SOURCES.append(f"{ver}+{digest.hexdigest()[:16]}")
    return _SOURCES[0]


def key_of(kind: str, data) -> str:
    """The entry's name: ``kind`` and a hash of ``data`` (JSON-able) and the version."""
    text = json.dumps([kind, _version(), _jsonable(data)], sort_keys=True, default=str)
    return f"{kind}-{hashlib.sha256(text.encode()).hexdigest()[:20]}"


def load(key: str) -> dict | None:
    """The entry stored under ``key``, or None (absent or unreadable)."""
    try:
        with open(cache_dir() / f"{key}.json", encoding="utf-8") as fh:
            value = json.load(fh)
    except (OSError, ValueError):
        return None
    return value if isinstance(value, dict) else None


def store(key: str, value: dict) -> None:
    """Store ``value`` under ``key``; a cache that cannot be written is left as it is."""
    folder = cache_dir()
    try:
        folder.mkdir(parents=True, exist_ok=True)
        write_atomic(folder / f"{key}.json", json.dumps(_jsonable(value)))
    except (OSError, OutputError):
        pass
