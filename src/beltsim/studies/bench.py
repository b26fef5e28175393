"""The benchmark: ours against generic scipy peers, the explicit kernel's speed, a cold start.

The peers (:mod:`beltsim.studies.peers`) are what a skilled user would write instead, on
the same grid and the same semi-discretisation (the numpy twin
:func:`beltsim.physics.model.forces_numpy` and its analytic sparse Jacobian): scipy's
Radau and BDF from rest to the steady test of a run (the run's own
:class:`~beltsim.simulation.trackers.SteadyStateTracker`), each at its loosest tolerance
that reaches beltsim's steady state, and a sparse Newton iteration on the steady
equations, converged to the tolerance of beltsim's Newton. Every wall time is the
shortest of ``repeat`` runs and excludes numba compilation, which is reported apart.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import tempfile
import time

from ..problem.scene import Scene, load_scene
from ..simulation.controller import Simulation
from ..simulation.result import reference_of
from ..simulation.solution import relative_error
from . import peers as peerlib
from .peers import PeerSystem  # noqa: F401  (the method-of-lines system; tests use it)

#: The transient peers, by key: (scipy class, description)
TRANSIENT_PEERS = {"radau": ("Radau", "solve_ivp Radau, analytic sparse Jacobian"),
                   "bdf": ("BDF", "solve_ivp BDF, analytic sparse Jacobian")}
STEADY_PEER = "newton"
DEFAULT_PEER_CAP = 600.0  # s of wall time per transient peer run


def explicit_node_steps_per_s(scene: Scene, settle=0.05, span=0.02) -> float:
    """Node-steps per second of the explicit kernel alone, in a settled state."""
    sim = Simulation(scene.with_overrides(["numerics.integrator=explicit"]))
    sim.warm_up()
    sim.advance(settle)
    steps0, start = sim.steps, time.perf_counter()
    sim.advance(sim.t + span)
    wall = time.perf_counter() - start
    return (sim.steps - steps0) * (sim.grid.n_elements - 1) / wall


def cold_start_time(scene_path, overrides=()) -> float:
    """Wall time of a fresh process with an empty numba cache, run to steady state."""
    with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as out:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        cmd = [sys.executable, "-m", "beltsim.cli", "run", str(scene_path), "--quiet",
               "--out", out]
        for o in overrides:
            cmd += ["--set", o]
        start = time.perf_counter()
        proc = subprocess.run(cmd, env=env, capture_output=True, text=True)
        wall = time.perf_counter() - start
        if proc.returncode != 0:
            raise RuntimeError(f"cold-start run failed: {proc.stderr.strip()}")
    return wall


def _best(runs):
    """The shortest of repeated runs (each returns an object with a wall_time)."""
    return min(runs, key=lambda r: r.wall_time)


def _ours(scene: Scene, repeat: int):
    """beltsim's run of ``scene``, the shortest of ``repeat`` (each from rest)."""
    results = []
    for _ in range(repeat):
        sim = Simulation(scene)
        results.append(sim.run())
    return _best(results)


def _peer_entry(res: peerlib.PeerResult, description: str, exact: float,
                reference: float) -> dict:
    """A peer's row of the ``peers`` dict: converged means steady by the run's test (or,
    for the steady peer, Newton's) and on beltsim's steady state within SAME_STATE."""
    same = abs(res.total_friction - reference) <= peerlib.SAME_STATE * abs(reference)
    reason = res.reason if same or not res.converged else "steady, but a different state"
    return {"method": description, "wall_time": res.wall_time,
            "error": relative_error(res.total_friction, exact),
            "converged": bool(res.converged and same), "reason": reason,
            "tolerance": res.tolerance, "total_friction": float(res.total_friction),
            "simulated_time": res.simulated_time, "rhs_evaluations": int(res.rhs_evaluations),
            "jacobian_evaluations": int(res.jacobian_evaluations),
            "factorisations": int(res.factorisations), "steps": int(res.steps)}


def run_peers(scene: Scene, exact: float, reference: float, repeat: int = 3,
              peer_cap: float = DEFAULT_PEER_CAP, search: bool = False, log=print) -> dict:
    """Every generic peer on ``scene``: the ``peers`` dict of :func:`bench`.

    ``reference``: beltsim's steady total friction on this grid (the steady state every
    peer must reach); ``search``: find each transient peer's loosest rtol on this grid
    first (:func:`beltsim.studies.peers.loosest_tolerance`) instead of the defaults.
    A transient run that does not converge is not repeated.
    """
    out = {}
    for key, (method, description) in TRANSIENT_PEERS.items():
        if not scene.params.inertia:
            out[key] = {"method": description, "wall_time": None, "error": None,
                        "converged": False, "reason": "not applicable: no inertia",
                        "tolerance": None}
            continue
        rtol = peerlib.DEFAULT_RTOL[method]
        if search:
            log(f"{method}: searching the loosest rtol that reaches the steady state")
            found, _ = peerlib.loosest_tolerance(lambda: Simulation(scene), method, reference,
                                                 max_wall=peer_cap, log=log)
            rtol = found if found is not None else rtol
            log(f"{method}: rtol {rtol:g}" + ("" if found else " (none of the list did)"))
        runs = []
        for _ in range(repeat):
            runs.append(peerlib.run_transient_peer(Simulation(scene), method, rtol, peer_cap))
            if not runs[-1].converged:
                break
        res = _best(runs) if all(r.converged for r in runs) else runs[-1]
        out[key] = entry = _peer_entry(res, description, exact, reference)
        log(f"peer {key:6s} ({description}, rtol {rtol:g}): {res.steps} steps, "
            f"{res.rhs_evaluations} rhs, {res.factorisations} LU, t = "
            f"{res.simulated_time:.4g} s, wall {res.wall_time:.3f} s, error "
            f"{entry['error']:.2e}, {'steady' if entry['converged'] else entry['reason']}")
    res = _best([peerlib.run_steady_peer(Simulation(scene)) for _ in range(repeat)])
    description = "Newton, scipy.sparse, line search, continuation in v_reg"
    out[STEADY_PEER] = entry = _peer_entry(res, description, exact, reference)
    log(f"peer {STEADY_PEER:6s} ({description}): {res.steps} iterations, wall "
        f"{res.wall_time:.4f} s, error {entry['error']:.2e}, "
        f"{'converged' if entry['converged'] else entry['reason']}")
    return out


def run_port_entry(scene: Scene, ours, exact: float, repeat: int = 3, log=print) -> dict:
    """The port of the default scheme (:mod:`beltsim.studies.port`) on ``scene``, against
    ``ours`` (beltsim's RunResult of the same scene): the ``port`` dict of :func:`bench`.

    Converged: steady by the run's test on beltsim's steady state (SAME_STATE); the
    port takes the same steps, so its step count and total friction are reported beside
    ours (``total_friction_vs_ours``: relative difference).
    """
    from . import port as portlib

    description = "beltsim's implicit scheme ported to numpy and scipy.sparse (splu)"
    try:
        res = portlib.run_port(scene, repeat)
    except ValueError as exc:  # another scheme, law or loads: no port
        return {"method": description, "wall_time": None, "error": None, "converged": False,
                "reason": f"not applicable: {exc}"}
    total, ref = res.solution.total_friction, ours.solution.total_friction
    diff = abs(total - ref) / abs(ref) if ref != 0.0 else abs(total)
    same = diff <= peerlib.SAME_STATE
    converged = bool(res.converged and same)
    entry = {"method": description, "wall_time": res.wall_time,
             "error": relative_error(total, exact), "converged": converged,
             "reason": ("steady" if converged else
                        res.reason or ("steady, but a different state" if res.converged
                                       else "not steady")),
             "total_friction": float(total), "total_friction_vs_ours": float(diff),
             "simulated_time": res.simulated_time, "ours_simulated_time": ours.simulated_time,
             "steps": int(res.steps), "ours_steps": int(ours.steps),
             "newton_iterations": int(res.statistics["newton_iterations"]),
             "ours_newton_iterations": int(ours.statistics.get("newton_iterations", 0)),
             "rejected_steps": int(res.statistics["rejected_steps"])}
    log(f"port   ({description}): {res.steps} steps (ours {ours.steps}), "
        f"{entry['newton_iterations']} Newton iterations, t = {res.simulated_time:.4g} s, "
        f"wall {res.wall_time:.4f} s, total friction {total:.10g} N ({diff:.1e} from ours), "
        f"{'steady' if converged else entry['reason']}")
    return entry


def bench(scene_path, overrides=(), peer=True, cold=True, elements=None, repeat=3,
          peer_cap=DEFAULT_PEER_CAP, search=False, port=True, log=print) -> dict:
    """Ours against the generic peers on one grid, the explicit kernel's speed, a cold start.

    ``elements`` overrides numerics.elements. Keys: ``ours_*`` (the scene's scheme, the
    default run), ``ours_steady_*`` (the steady scheme), ``peers`` (see
    :func:`run_peers`), ``peer_*`` and ``speedup`` (the fastest converged transient
    peer, its wall time over ours; None when none converged), ``steady_speedup`` (the
    steady peer's wall time over the steady scheme's), ``kernel_speedup`` (None: no port
    of the time scheme yet), ``explicit_node_steps_per_s``, ``cold_start_time``.
    """
    overrides = list(overrides)
    if elements is not None:
        overrides.append(f"numerics.elements={elements}")
    scene = load_scene(scene_path, overrides)
    exact = reference_of(scene).total_friction
    res = _ours(scene, repeat)
    total = res.solution.total_friction
    out = {"elements": res.solution.grid.n_elements, "ours_wall_time": res.wall_time,
           "ours_error": relative_error(total, exact), "ours_converged": res.converged}
    log(f"ours   ({res.numerics.integrator}, {out['elements']} elements): "
        f"{res.steps} steps, wall {res.wall_time:.4f} s, total "
        f"friction {total:.8g} N, error {out['ours_error']:.2e} (compile/cache load "
        f"{res.compile_time:.2f} s, not counted)")
    steady = _ours(scene.with_overrides(["numerics.integrator=steady"]), repeat)
    reference = steady.solution.total_friction
    out.update(ours_steady_wall_time=steady.wall_time,
               ours_steady_error=relative_error(reference, exact))
    log(f"ours   (steady): wall {steady.wall_time:.4f} s, total friction {reference:.8g} N, "
        f"error {out['ours_steady_error']:.2e}")
    out.update(peer=None, peer_wall_time=None, peer_error=None, peer_converged=False,
               speedup=None, steady_speedup=None, kernel_speedup=None, peers=None,
               port=None)
    if port:
        out["port"] = entry = run_port_entry(scene, res, exact, repeat, log)
        if entry["converged"]:
            out["kernel_speedup"] = entry["wall_time"] / res.wall_time
        log(f"kernel speedup: {_ratio(out['kernel_speedup'])} (the port's wall time over "
            f"ours, same scheme and steps)")
    if peer:
        table = run_peers(scene, exact, reference, repeat, peer_cap, search, log)
        out["peers"] = table
        done = [k for k in TRANSIENT_PEERS if table[k]["converged"]]
        if done:
            best = min(done, key=lambda k: table[k]["wall_time"])
            out.update(peer=best, peer_wall_time=table[best]["wall_time"],
                       peer_error=table[best]["error"], peer_converged=True,
                       speedup=table[best]["wall_time"] / res.wall_time)
        if table[STEADY_PEER]["converged"]:
            out["steady_speedup"] = table[STEADY_PEER]["wall_time"] / steady.wall_time
        log(f"speedup: {_ratio(out['speedup'])} (default run against the fastest converged "
            f"transient peer), {_ratio(out['steady_speedup'])} (steady scheme against the "
            f"steady peer)")
    out["explicit_node_steps_per_s"] = explicit_node_steps_per_s(scene)
    log(f"explicit kernel: {out['explicit_node_steps_per_s']:.3g} node-steps/s")
    out["cold_start_time"] = cold_start_time(scene_path, overrides) if cold else None
    if cold:
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
