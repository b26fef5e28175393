"""beltsim: contact mechanics of an axially moving shear-deformable belt.

A few lines do what the CLI does::

    import beltsim
    scene = beltsim.load_scene("paper_slip", ["contact.max_friction=2e5"])
    exact = beltsim.solve(scene)            # analytic steady state
    result = beltsim.run(scene)             # transient, from rest to steady state
    print(result.summary()["error"])        # errors against the analytic solution
    beltsim.save_run(result, "runs/out/slip")
"""

from .api import load_scene, paper_scene, run, scene_names, shipped_scene, solve
from .errors import (
    BeltsimError,
    MissingInputError,
    NoSolutionError,
    NumericalError,
    SceneError,
)
from .io.results import save_run
from .plots.run import plot_fields, plot_history
from .problem.analytic import AnalyticSolution
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
from .simulation.controller import Simulation
from .simulation.result import RunResult, RunStatus
from .simulation.trackers import Stop, Tracker

__version__ = "0.1.0"

__all__ = [
    "AnalyticSolution", "Beam", "BeltsimError", "Contact", "MissingInputError", "Motion",
    "NoSolutionError", "NumericalError", "NumericsSection", "Physics", "RunResult",
    "RunStatus", "Scene", "SceneError", "Simulation", "Sine", "Stiffness", "Stop", "Tracker",
    "load_scene", "paper_scene", "plot_fields", "plot_history", "run", "save_run",
    "scene_names", "shipped_scene", "solve",
]
