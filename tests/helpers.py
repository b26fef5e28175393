"""Paths and command runners shared by the tests, independent of the working directory."""

import subprocess
import sys
from importlib.resources import files
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def scene_path(name: str) -> str:
    """The file of a shipped scene, e.g. scene_path("paper_slip")."""
    return str(files("beltsim") / "scenes" / f"{name}.toml")


def cli(*args, timeout=600, **kw):
    """Run ``python -m beltsim.cli ARGS`` and capture its output."""
    return module("beltsim.cli", *args, timeout=timeout, **kw)


def module(name, *args, timeout=600, **kw):
    """Run ``python -m NAME ARGS`` from the repository root and capture its output."""
    kw.setdefault("cwd", ROOT)
    return subprocess.run([sys.executable, "-m", name, *map(str, args)],
                          capture_output=True, text=True, timeout=timeout, **kw)
