"""The benchmark: ours against a solve_ivp peer, the explicit kernel's speed, a cold start.

The peer integrates the method-of-lines system of the same discretisation (the
numpy twin :func:`beltsim.physics.model.forces_numpy`) and stops on the same
steady-state test as a run (:class:`~beltsim.simulation.trackers.SteadyStateTracker`
of a :class:`~beltsim.simulation.controller.Simulation`, with its window and tolerance).
Every wall time excludes numba compilation, which is reported apart.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

from ..physics.model import forces_numpy
from ..problem.scene import Scene, load_scene
from ..simulation.controller import Simulation
from ..simulation.result import reference_of
from ..simulation.solution import relative_error


class PeerSystem:
    """y' = f(t, y) with y = (u, theta, u_t, theta_t) at the interior nodes."""

    def __init__(self, sim: Simulation):
        if not sim.params.inertia:
            raise ValueError("the method-of-lines peer needs an inertial scene")
        self.disc = d = sim.disc
        N = d.grid.n_elements
        self.n = N - 1
        self.m = d.params.rho * d.mesh.hb[1:-1]
        self.mi = d.params.I * d.mesh.hb[1:-1]
        self._full = [np.zeros(N + 1) for _ in range(4)]

    def unpack(self, y):
        n = self.n
        for k, arr in enumerate(self._full):
            arr[1:-1] = y[k * n:(k + 1) * n]
        return self._full

    def forces(self, t, y):
        d = self.disc
        u, th, ud, td = self.unpack(y)
        return forces_numpy(u, th, ud, td, t, d.mesh, d.model, d.drive)

    def rhs(self, t, y):
        fu, ft, _ = self.forces(t, y)
        n = self.n
        return np.concatenate([y[2 * n:3 * n], y[3 * n:], fu / self.m, ft / self.mi])

    def friction(self, t, y):
        return self.forces(t, y)[2].sum()

    def sparsity(self):
        from scipy.sparse import bmat, diags, identity
        n = self.n
        tri = diags([np.ones(n - 1), np.ones(n), np.ones(n - 1)], [-1, 0, 1])
        eye = identity(n)
        return bmat([[None, None, eye, None], [None, None, None, eye],
                     [tri, tri, tri, tri], [tri, tri, tri, tri]]).tocsc()


def run_peer(sim: Simulation, rtol=1e-5, atol_scale=1e-7, max_wall=1800.0):
    """solve_ivp's BDF from rest to the steady tolerance of a run (same steady test).

    Tolerances: rtol 1e-5; atol 1e-7 of the displacement and rotation scales and 1e-9
    of the velocity scale c |e0|. BDF of orders 3-5 is not A-stable, so the undamped
    high-frequency gyroscopic modes of the central scheme are held at the error
    tolerance only: with a velocity atol of 1e-7 they kept rates ~1.5e-5, above the
    steady tolerance (1e-6), and the run never settled. Looser or tighter rtol ran no
    faster: the step stays near 1.6e-5 s. Stops after ``max_wall`` seconds.
    Returns (total friction, wall time, simulated time, rhs evaluations, converged).
    """
    from scipy.integrate import BDF

    P, num, sc = sim.params, sim.numerics, sim.disc.scales
    sysm = PeerSystem(sim)
    n = sysm.n
    vel = P.c * sc.theta
    atol = np.concatenate([np.full(n, sc.u), np.full(n, sc.theta), np.full(n, 1e-2 * vel),
                           np.full(n, 1e-2 * vel / P.L)]) * atol_scale
    steady = sim.steady
    start = time.perf_counter()
    solver = BDF(sysm.rhs, 0.0, np.zeros(4 * n), num.t_end, rtol=rtol, atol=atol,
                 jac_sparsity=sysm.sparsity())
    next_check, converged, total = sim.check, False, 0.0
    while solver.status == "running" and time.perf_counter() - start < max_wall:
        solver.step()
        if solver.status == "failed":
            break
        if solver.t >= next_check:
            y = solver.y
            total = sysm.friction(solver.t, y)
            rate = max(np.abs(y[2 * n:3 * n]).max(), P.L * np.abs(y[3 * n:]).max()) / vel
            next_check = solver.t + sim.check
            if steady.update(solver.t, rate, total):
                converged = True
                break
    wall = time.perf_counter() - start
    return total, wall, solver.t, solver.nfev, converged


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


def bench(scene_path, overrides=(), peer=True, cold=True, log=print) -> dict:
    """The paper slip scene: ours against the solve_ivp peer, kernel speed, cold start."""
    scene = load_scene(scene_path, overrides)
    exact = reference_of(scene).total_friction
    sim = Simulation(scene)
    res = sim.run()
    total = res.solution.total_friction
    out = {"ours_wall_time": res.wall_time, "ours_error": relative_error(total, exact)}
    log(f"ours   ({sim.numerics.integrator}, {sim.grid.n_elements} elements): "
        f"{res.steps} steps, wall {res.wall_time:.4f} s, total friction {total:.6g} N, "
        f"error {out['ours_error']:.2e} (compile/cache load {res.compile_time:.2f} s, "
        f"not counted)")
    if peer:
        total, wall, t, nfev, conv = run_peer(Simulation(scene))
        out.update(peer_wall_time=wall, peer_error=relative_error(total, exact))
        log(f"peer   (solve_ivp BDF, sparse Jacobian, same grid): {nfev} rhs evaluations, "
            f"t = {t:.4g} s, wall {wall:.3f} s, error {out['peer_error']:.2e}, "
            f"{'steady' if conv else 'NOT steady by t_end or the wall-time cap'}")
        out["peer_converged"] = conv
        out["speedup"] = wall / res.wall_time
    else:
        out.update(peer_wall_time=None, peer_error=None, speedup=None)
    out["explicit_node_steps_per_s"] = explicit_node_steps_per_s(scene)
    log(f"explicit kernel: {out['explicit_node_steps_per_s']:.3g} node-steps/s")
    out["cold_start_time"] = cold_start_time(scene_path, overrides) if cold else None
    if cold:
        log(f"cold start (fresh process, empty numba cache, to steady state): "
            f"{out['cold_start_time']:.2f} s")
    return out


def bench_json(result: dict) -> str:
    return json.dumps({k: (None if isinstance(v, float) and not math.isfinite(v) else v)
                       for k, v in result.items()})
