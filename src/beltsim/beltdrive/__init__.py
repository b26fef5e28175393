"""The closed belt drive: a belt loop on a driver and a driven pulley.

The belt is the paper's axially moving extensible, shear-deformable beam (or the
extensible string) on a periodic Eulerian coordinate along the loop; the belt speed c(t)
and the driven pulley's speed omega2(t) are unknowns of the loop. A few lines::

    import beltsim
    from beltsim import beltdrive
    scene = beltsim.load_scene("drive_flat")          # a DriveScene
    print(beltdrive.solve_string(scene.params).summary())   # the creep theory
    result = beltdrive.simulate(scene)                # from rest to steady state
    print(result.status, result.summary["speed_ratio"], result.errors())
"""

from .analytic import GrossSlipError, LiftOffError, StringSolution, capacity, solve_string
from .geometry import Geometry
from .run import DriveResult, DriveStatus, simulate, solve_steady
from .scene import DriveParams, DriveScene

__all__ = ["DriveParams", "DriveResult", "DriveScene", "DriveStatus", "Geometry",
           "GrossSlipError", "LiftOffError", "StringSolution", "capacity", "simulate",
           "solve_steady", "solve_string"]
