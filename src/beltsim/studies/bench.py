"""The benchmark of a scene: the default and steady runs' wall times, the explicit kernel's
speed, and what a user waits for: ``import beltsim``, a run end to end in a fresh process
with the kernels cached, and a cold start.

Every wall time is the shortest of ``repeat`` runs and excludes numba compilation, which
is reported apart. The comparison with generic scipy peers and with a numpy port of the
default scheme is lab work: ``python -m benchmarks.bench`` in a source checkout.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import tempfile
import time

from ..api import is_drive_scene
from ..problem.scene import Scene
from ..simulation.controller import Simulation
from ..simulation.readout import readout_class
from ..simulation.solution import relative_error
from .convergence import error_keys


def explicit_node_steps_per_s(scene: Scene, settle=0.05, span=0.02) -> float:
    """Node-steps per second of the explicit kernel alone, in a settled state."""
    sim = Simulation(scene.with_overrides([("numerics.integrator", "explicit")]))
    sim.warm_up()
    sim.advance(settle)
    steps0, start = sim.steps, time.perf_counter()
    sim.advance(sim.t + span)
    wall = time.perf_counter() - start
    return (sim.steps - steps0) * (sim.grid.n_elements - 1) / wall


def _cli_run_time(scene: Scene, env: dict, what: str) -> float:
    """Wall time of ``beltsim run`` of ``scene`` in a fresh process, from start to steady
    state (the scene written to a file first)."""
    with tempfile.TemporaryDirectory() as out:
        path = os.path.join(out, "scene.toml")
        with open(path, "w", encoding="utf-8") as fh:
            fh.write(scene.to_toml())
        cmd = [sys.executable, "-m", "beltsim.cli", "run", path, "--quiet", "--out",
               os.path.join(out, "run")]
        start = time.perf_counter()
        proc = subprocess.run(cmd, env=env, capture_output=True, text=True)
        wall = time.perf_counter() - start
        if proc.returncode != 0:
            raise RuntimeError(f"{what} run failed: {proc.stderr.strip()}")
    return wall


def user_env(**extra) -> dict:
    """The environment of a user's process: this one's, with Python's bytecode cache on
    (its default; a sandbox's PYTHONDONTWRITEBYTECODE would recompile every module of
    the package in every run, about 0.1 s that no installed package pays)."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env.update(extra)
    return env


def cold_start_time(scene: Scene) -> float:
    """Wall time of ``beltsim run`` in a fresh process with an empty numba cache, from
    start to steady state (the scene written to a file first)."""
    with tempfile.TemporaryDirectory() as cache:
        return _cli_run_time(scene, user_env(NUMBA_CACHE_DIR=cache), "cold-start")


def warm_run_time(scene: Scene, repeat=3) -> float:
    """Wall time of ``beltsim run`` end to end in a fresh process whose kernels are in
    numba's cache and whose modules are in Python's bytecode cache (a first run puts
    both there, and is not counted), the shortest of ``repeat``."""
    _cli_run_time(scene, user_env(), "warm")
    return min(_cli_run_time(scene, user_env(), "warm") for _ in range(repeat))


def import_time(repeat=3) -> float:
    """Seconds of ``import beltsim`` in a fresh interpreter, the shortest of ``repeat``."""
    code = ("import time; start = time.perf_counter(); import beltsim; "
            "print(time.perf_counter() - start)")
    times = []
    for _ in range(repeat):
        proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                              env=user_env())
        if proc.returncode != 0:
            raise RuntimeError(f"import beltsim failed: {proc.stderr.strip()}")
        times.append(float(proc.stdout))
    return min(times)


def best_of(runs):
    """The shortest of repeated runs (each returns an object with a wall_time)."""
    return min(runs, key=lambda r: r.wall_time)


def _ours(scene: Scene, repeat: int):
    """beltsim's run of ``scene``, the shortest of ``repeat`` (each from rest)."""
    results = []
    for _ in range(repeat):
        sim = Simulation(scene)
        results.append(sim.run())
    return best_of(results)


def run_ours(scene: Scene, repeat=3, log=print) -> tuple[dict, object, object]:
    """The scene's default run and its steady scheme, each the shortest of ``repeat``.

    Returns the ``ours_*`` entries of :func:`bench` and the two RunResults.
    """
    key = error_keys(scene)[0]  # the total friction; a drive's tight span tension
    exact = readout_class(is_drive_scene(scene)).exact(scene).summary()[key]
    res = _ours(scene, repeat)
    value = res.summary()[key]
    out = {"elements": res.numerics.elements, "ours_integrator": res.numerics.integrator,
           "figure": key, "ours_wall_time": res.wall_time,
           "ours_error": relative_error(value, exact), "ours_converged": res.converged,
           "ours_steps": res.steps, f"ours_{key}": value}
    name = key.replace("_", " ")
    log(f"ours   ({res.numerics.integrator}, {out['elements']} elements): "
        f"{res.steps} steps, wall {res.wall_time:.4f} s, {name} {value:.8g} N, error "
        f"{out['ours_error']:.2e} (compile/cache load {res.compile_time:.2f} s, not counted)")
    steady = _ours(scene.with_overrides([("numerics.integrator", "steady")]), repeat)
    value = steady.summary()[key]
    out.update({"ours_steady_wall_time": steady.wall_time, f"ours_steady_{key}": value,
                "ours_steady_error": relative_error(value, exact)})
    log(f"ours   (steady): wall {steady.wall_time:.4f} s, {name} {value:.8g} N, error "
        f"{out['ours_steady_error']:.2e}")
    return out, res, steady


def bench(scene: Scene, cold=True, repeat=3, log=print) -> dict:
    """The default run, the steady scheme, the explicit kernel's speed, the import, a
    warm run end to end and a cold start, of a straight belt or a drive.

    Keys: ``elements``, ``figure`` (what the errors are of: the total friction, a drive's
    tight span tension), ``ours_*`` (the scene's scheme, the default run), ``ours_steady_*``
    (the steady scheme), ``explicit_node_steps_per_s``, ``import_time`` (``import
    beltsim`` in a fresh interpreter), ``warm_run_time`` (``beltsim run`` in a fresh
    process with the kernels cached, start to steady state, files included) and
    ``cold_start_time`` (the same with an empty numba cache; None when ``cold`` is false).
    The last three are each the shortest of ``repeat``, but the cold start: one.
    """
    out, _, _ = run_ours(scene, repeat, log)
    out["explicit_node_steps_per_s"] = (explicit_node_steps_per_s(scene)
                                        if scene.params.inertia else None)
    if out["explicit_node_steps_per_s"] is not None:
        log(f"explicit kernel: {out['explicit_node_steps_per_s']:.3g} node-steps/s")
    out["import_time"] = import_time(repeat)
    log(f"import beltsim (fresh interpreter): {out['import_time']:.3f} s")
    out["warm_run_time"] = warm_run_time(scene, repeat)
    log(f"warm run (fresh process, kernels cached, to steady state, end to end): "
        f"{out['warm_run_time']:.2f} s")
    out["cold_start_time"] = None
    if cold:
        out["cold_start_time"] = cold_start_time(scene)
        log(f"cold start (fresh process, empty numba cache, to steady state): "
            f"{out['cold_start_time']:.2f} s")
    return out


def _ratio(x):
    return "n/a" if x is None else f"{x:.3g}x"


def _clean(v):
    if isinstance(v, dict):
        return {k: _clean(x) for k, x in v.items()}
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return v


def bench_json(result: dict) -> str:
    """One line of JSON; non-finite numbers become null."""
    return json.dumps(_clean(result))
