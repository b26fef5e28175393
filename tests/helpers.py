"""Paths and command runners shared by the tests, independent of the working directory."""

import subprocess
import sys
from importlib.resources import files
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def scene_path(name: str) -> str:
    """The file of a shipped scene, e.g. scene_path("paper_slip")."""
    return str(files("beltsim.scenes") / f"{name}.toml")


def cli(*args, timeout=600, **kw):
    """Run ``python -m beltsim.cli ARGS`` and capture its output."""
    return module("beltsim.cli", *args, timeout=timeout, **kw)


def module(name, *args, timeout=600, **kw):
    """Run ``python -m NAME ARGS`` from the repository root and capture its output."""
    kw.setdefault("cwd", ROOT)
    return subprocess.run([sys.executable, "-m", name, *map(str, args)],
                          capture_output=True, text=True, timeout=timeout, **kw)


#: End-to-end error bounds are this factor above the error measured on the test's own
#: grid (the discretisation error), so that a loss of accuracy fails long before the
#: issue's acceptance bounds (0.5% total friction, 2% u and theta) would notice it.
ERROR_FACTOR = 3.0

#: Errors of the paper scenes on 500 elements against their exact solutions (relative;
#: slip start in m), measured; second order in the element size. The transient and the
#: steady schemes land on the same discrete steady state, so they share these.
PAPER_ERRORS_500 = {
    "quasistatic": {"total_friction": 1.7e-5, "u": 1.5e-5, "theta": 3.4e-5,
                    "concentrated_force": 1.5e-5, "slip_power": 1.8e-5},
    "inertia": {"total_friction": 2.7e-5, "u": 3.0e-5, "theta": 1.0e-4,
                "concentrated_force": 2.0e-4, "slip_power": 3.8e-5},
    "slip": {"total_friction": 1.5e-5, "u": 1.3e-5, "theta": 5.2e-5, "slip_power": 1.4e-5,
             "slip_start": 7.3e-8},
}


def assert_errors_near(result, measured: dict, factor: float = ERROR_FACTOR):
    """A converged run whose every error is within ``factor`` of its measurement
    (``measured`` names every error the run has)."""
    assert result.converged, result.reason
    errors = {k: v for k, v in result.errors().items() if v is not None}
    assert set(errors) == set(measured), (sorted(errors), sorted(measured))
    for key, value in errors.items():
        assert value <= factor * measured[key], (key, value, measured[key])
