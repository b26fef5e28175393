"""Compile every applicable scheme's kernels for the shipped scenes named on the command
line, into numba's cache, so that the test workers load them instead of each compiling
the same kernels at once (CI: .ci/run warms the straight belt and the drive side by side).
"""

import sys
import time

import beltsim
from beltsim.problem.kinds import is_drive_scene
from beltsim.simulation.controller import Simulation
from beltsim.solvers import registry

for name in sys.argv[1:]:
    scene = beltsim.load_scene(name)
    for scheme in registry.names():
        if registry.applicable(scheme, scene.params.inertia, is_drive_scene(scene)):
            continue
        start = time.perf_counter()
        Simulation(scene.with_overrides([("numerics.integrator", scheme)])).warm_up()
        print(f"warm kernels: {name} {scheme} {time.perf_counter() - start:.1f} s", flush=True)
