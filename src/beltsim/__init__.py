"""beltsim: contact mechanics of an axially moving shear-deformable belt.

A few lines do what the CLI does::

    import beltsim
    scene = beltsim.load_scene("paper_slip", ["contact.max_friction=2e5"])
    exact = beltsim.solve(scene)            # analytic steady state
    result = beltsim.run(scene)             # transient, from rest to steady state
    print(result.summary()["error"])        # errors against the analytic solution
    beltsim.save_run(result, "runs/out/slip")
"""

from .errors import (
    BeltsimError,
    MissingInputError,
    NoSolutionError,
    NumericalError,
    SceneError,
)
from .problem.builder import (
    Beam,
    Contact,
    Motion,
    NumericsSection,
    Physics,
    Sine,
    Stiffness,
)
from .problem.scene import Scene

__version__ = "0.1.0"

# Imported on first use: they bring numba, scipy.optimize and matplotlib, a second of
# `import beltsim` that listing scenes or building one does not need.
_LAZY = {
    "forced_response": "api", "load_scene": "api", "modes": "api", "paper_scene": "api",
    "run": "api", "scene_names": "api", "shipped_scene": "api", "solve": "api",
    "save_run": "io.results", "plot_fields": "plots.run", "plot_history": "plots.run",
    "AnalyticSolution": "problem.analytic",
    "Simulation": "simulation.controller",
    "RunResult": "simulation.result", "RunStatus": "simulation.result",
    "Stop": "simulation.trackers", "Tracker": "simulation.trackers",
}


_SUBPACKAGES = ("api", "beltdrive", "cli", "io", "physics", "plots", "problem",
                "simulation", "solvers", "studies")


def __getattr__(name):
    import importlib

    if name in _SUBPACKAGES:  # beltsim.solvers.settings... after a bare `import beltsim`
        return importlib.import_module(f".{name}", __name__)
    if name not in _LAZY:
        raise AttributeError(f"module 'beltsim' has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    globals()[name] = value  # once: later lookups skip this function
    return value


def __dir__():
    return sorted(set(globals()) | set(_LAZY))

__all__ = [
    "AnalyticSolution", "Beam", "BeltsimError", "Contact", "MissingInputError", "Motion",
    "NoSolutionError", "NumericalError", "NumericsSection", "Physics", "RunResult",
    "RunStatus", "Scene", "SceneError", "Simulation", "Sine", "Stiffness", "Stop", "Tracker",
    "forced_response", "load_scene", "modes", "paper_scene", "plot_fields", "plot_history",
    "run", "save_run", "scene_names", "shipped_scene", "solve",
]
