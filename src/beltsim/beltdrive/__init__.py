"""The closed belt drive: a belt loop on a driver and a driven pulley.

The belt is the paper's axially moving extensible, shear-deformable beam (or the
extensible string) on a periodic Eulerian coordinate along the loop; the belt speed c(t)
and the driven pulley's speed omega2(t) are unknowns of the loop. A few lines::

    import beltsim
    from beltsim import beltdrive
    scene = beltsim.load_scene("drive_flat")          # a DriveScene
    print(beltdrive.solve_string(scene.params).summary())   # the creep theory
    result = beltsim.run(scene)                       # from rest, by the one engine
    print(result.status, result.summary()["speed_ratio"], result.errors())

This package holds the drive's problem: its scene, geometry and exact steady states
(the creep theory, the beam's), and its drawings. It is solved as a closed layout of
the one discrete model (:mod:`beltsim.physics.layout`, :mod:`beltsim.solvers`).
"""

from .analytic import GrossSlipError, LiftOffError, StringSolution, capacity, solve_string
from .creep import SerpentineData, SerpentineSolution, solve_serpentine
from .exact import exact_state, string_state
from .geometry import Geometry
from .pulleys import Pulley, PulleyLayout
from .scene import DriveParams, DriveScene
from .tensioner import Tensioner

__all__ = ["DriveParams", "DriveScene", "Geometry", "GrossSlipError", "LiftOffError",
           "Pulley", "PulleyLayout", "SerpentineData", "SerpentineSolution",
           "StringSolution", "Tensioner", "capacity", "exact_state", "solve_serpentine",
           "solve_string", "string_state"]
