"""Paths and a CLI runner shared by the tests, independent of the working directory."""

import subprocess
import sys
from pathlib import Path

RUNS = Path(__file__).resolve().parents[1] / "runs"


def scene_path(name: str) -> str:
    """The path of a shipped scene, e.g. scene_path("paper_slip")."""
    return str(RUNS / f"{name}.toml")


def cli(*args, timeout=600, **kw):
    """Run ``python -m beltsim.cli ARGS`` and capture its output."""
    return subprocess.run([sys.executable, "-m", "beltsim.cli", *map(str, args)],
                          capture_output=True, text=True, timeout=timeout, **kw)
