"""beltsim: contact mechanics of an axially moving shear-deformable belt.

A few lines do what the CLI does::

    import beltsim
    scene = beltsim.load_scene("runs/paper_slip.toml", ["contact.max_friction=2e5"])
    exact = beltsim.solve(scene)            # analytic steady state
    result = beltsim.run(scene)             # transient, from rest to steady state
    print(result.summary()["error"])        # errors against the analytic solution
    beltsim.save_run(result, "runs/out/slip")
"""

from .analytic import AnalyticSolution, solve
from .errors import BeltsimError, NoSolutionError, NumericalError, SceneError
from .results import save_run
from .runner import RunResult, Simulation, run
from .scene import Scene, load_scene

__version__ = "0.1.0"

__all__ = [
    "AnalyticSolution", "BeltsimError", "NoSolutionError", "NumericalError", "RunResult",
    "Scene", "SceneError", "Simulation", "load_scene", "run", "save_run", "solve",
]
