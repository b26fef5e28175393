"""Studies that measure the schemes: convergence ladders and the benchmark.

Timing lives here and in the CLI commands built on it, never in tests. Every
wall time excludes numba compilation, which is reported in its own column
(kernels are compiled or loaded from the cache by ``Simulation.warm_up``).
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

from .model import forces_numpy
from .runner import Simulation
from .scene import Scene
from .steady import SteadyDetector

LADDER = (125, 250, 500, 1000, 2000)
ERROR_KEYS = ("total_friction", "u", "theta", "concentrated_force", "slip_start")


def schemes_for(scene: Scene):
    """The schemes that apply: the explicit one needs inertia."""
    base = ("implicit", "steady", "richardson")
    return ("explicit",) + base if scene.params.inertia else base


def richardson(scene: Scene):
    """Steady solutions on a grid and on its bisection, extrapolated to zero element size.

    The errors are first order and regular in the element size, so 2 q(h/2) - q(h)
    cancels their leading term for the total friction, the concentrated force, u and
    theta (at the coarse nodes, which the bisected grid shares). The slip start is
    not smooth in h (it sits on element boundaries): the fine grid's is kept.
    Returns (coarse result, fine result, extrapolated errors, wall time of both).
    """
    from .grid import bisect
    from .solution import compare

    steady = scene.with_overrides(["numerics.integrator=steady"])
    coarse = Simulation(steady)
    r1 = coarse.run(raise_on_failure=False)
    r2 = Simulation(steady, grid=bisect(coarse.grid)).run(raise_on_failure=False)
    ref = r1.reference
    if ref is None or not (r1.converged and r2.converged):
        return r1, r2, None, r1.wall_time + r2.wall_time
    s1, s2 = r1.solution, r2.solution
    ext = type(s1)(s1.params, s1.grid, 2 * s2.u[::2] - s1.u, 2 * s2.theta[::2] - s1.theta,
                   s1.fnode, s1._law, s1._fs)
    err = compare(ext, ref)

    def rel(x, y):
        return abs(x - y) / abs(y) if y else abs(x - y)
    err["total_friction"] = rel(2 * s2.total_friction - s1.total_friction, ref.total_friction)
    if ref.model == "stick":
        err["concentrated_force"] = rel(2 * s2.concentrated_force - s1.concentrated_force,
                                        ref.concentrated_force)
    else:
        err["slip_start"] = abs(s2.slip_start - ref.x_star)
    return r1, r2, err, r1.wall_time + r2.wall_time


def convergence(scene: Scene, ladder=LADDER, schemes=None, progress=None) -> list[dict]:
    """Run each scheme on each grid of the ladder; one row per run."""
    rows = []
    for scheme in schemes or schemes_for(scene):
        for n in ladder:
            if scheme == "richardson":
                sc = scene.with_overrides([f"numerics.elements={n}"])
                r1, r2, err, wall = richardson(sc)
                h_min = r1.solution.grid.h_min
                rows.append({
                    "scheme": scheme, "elements": n, "h_min": h_min, "dt": float("nan"),
                    "steps": r1.steps + r2.steps,
                    "newton_iterations": r1.newton_iterations + r2.newton_iterations,
                    "wall_time": wall, "compile_time": r1.compile_time + r2.compile_time,
                    "converged": err is not None,
                    **{f"error_{k}": ((err or {}).get(k) if (err or {}).get(k) is not None
                                      else float("nan")) for k in ERROR_KEYS},
                })
                if progress:
                    progress(rows[-1])
                continue
            sc = scene.with_overrides([f"numerics.elements={n}", f"numerics.integrator={scheme}"])
            sim = Simulation(sc)
            res = sim.run(raise_on_failure=False)
            err = res.errors() or {}
            rows.append({
                "scheme": scheme, "elements": n, "h_min": sim.grid.h_min,
                "dt": sim.numerics.dt if scheme != "steady" else float("nan"),
                "steps": res.steps, "newton_iterations": res.newton_iterations,
                "wall_time": res.wall_time, "compile_time": res.compile_time,
                "converged": res.converged,
                **{f"error_{k}": (err.get(k) if err.get(k) is not None else float("nan"))
                   for k in ERROR_KEYS},
            })
            if progress:
                progress(rows[-1])
    return rows


def observed_orders(rows, key) -> dict:
    """Per scheme: orders between successive grids and the least-squares slope."""
    out = {}
    for scheme in dict.fromkeys(r["scheme"] for r in rows):
        rs = [r for r in rows if r["scheme"] == scheme and r["converged"]]
        h = np.array([r["h_min"] for r in rs])
        e = np.array([r[f"error_{key}"] for r in rs])
        ok = np.isfinite(e) & (e > 0)
        h, e = h[ok], e[ok]
        if len(e) < 2:
            continue
        pair = np.log(e[:-1] / e[1:]) / np.log(h[:-1] / h[1:])
        fit = float(np.polyfit(np.log(h), np.log(e), 1)[0])
        out[scheme] = {"pairs": [float(p) for p in pair], "fit": fit}
    return out


# ---------------------------------------------------------------------------
# The peer: scipy's BDF on the method-of-lines system of the same discretisation


class PeerSystem:
    """y' = f(t, y) with y = (u, theta, u_t, theta_t) at the interior nodes."""

    def __init__(self, sim: Simulation):
        if not sim.params.inertia:
            raise ValueError("the method-of-lines peer needs an inertial scene")
        self.sim = sim
        N = sim.grid.n_elements
        self.n = N - 1
        self.m = sim.params.rho * sim.hb[1:-1]
        self.mi = sim.params.I * sim.hb[1:-1]
        self._full = [np.zeros(N + 1) for _ in range(4)]

    def unpack(self, y):
        n = self.n
        for k, arr in enumerate(self._full):
            arr[1:-1] = y[k * n:(k + 1) * n]
        return self._full

    def rhs(self, t, y):
        s = self.sim
        u, th, ud, td = self.unpack(y)
        fu, ft, _ = forces_numpy(u, th, ud, td, t, s.he, s.hb, s.prm, s.iprm)
        return np.concatenate([ud[1:-1], td[1:-1], fu / self.m, ft / self.mi])

    def friction(self, t, y):
        s = self.sim
        u, th, ud, td = self.unpack(y)
        return forces_numpy(u, th, ud, td, t, s.he, s.hb, s.prm, s.iprm)[2].sum()

    def sparsity(self):
        from scipy.sparse import bmat, diags, identity
        n = self.n
        tri = diags([np.ones(n - 1), np.ones(n), np.ones(n - 1)], [-1, 0, 1])
        eye = identity(n)
        return bmat([[None, None, eye, None], [None, None, None, eye],
                     [tri, tri, tri, tri], [tri, tri, tri, tri]]).tocsc()


def run_peer(sim: Simulation, rtol=1e-5, atol_scale=1e-7, max_wall=1800.0):
    """solve_ivp's BDF from rest to the steady tolerance of a run (same detector).

    Tolerances: rtol 1e-5; atol 1e-7 of the displacement and rotation scales and 1e-9
    of the velocity scale c |e0|. BDF of orders 3-5 is not A-stable, so the undamped
    high-frequency gyroscopic modes of the central scheme are held at the error
    tolerance only: with a velocity atol of 1e-7 they kept rates ~1.5e-5, above the
    steady tolerance (1e-6), and the run never settled. Looser or tighter rtol ran no
    faster: the step stays near 1.6e-5 s. Stops after ``max_wall`` seconds.
    Returns (total friction, wall time, simulated time, rhs evaluations, converged).
    """
    from scipy.integrate import BDF

    P, num = sim.params, sim.numerics
    sysm = PeerSystem(sim)
    n = sysm.n
    sc = sim.scales
    vel = P.c * sc[3]
    atol = np.concatenate([np.full(n, sc[2]), np.full(n, sc[3]), np.full(n, 1e-2 * vel),
                           np.full(n, 1e-2 * vel / P.L)]) * atol_scale
    window = P.L / P.c
    check = window / 4.0
    detector = SteadyDetector(num.steady_tol, window, t_min=num.ramp_time)
    fscale = P.B * sc[3] * 1e-3
    start = time.perf_counter()
    solver = BDF(sysm.rhs, 0.0, np.zeros(4 * n), num.t_end, rtol=rtol, atol=atol,
                 jac_sparsity=sysm.sparsity())
    next_check, converged, total = check, False, 0.0
    while solver.status == "running" and time.perf_counter() - start < max_wall:
        solver.step()
        if solver.status == "failed":
            break
        if solver.t >= next_check:
            y = solver.y
            total = sysm.friction(solver.t, y)
            rate = max(np.abs(y[2 * n:3 * n]).max(), P.L * np.abs(y[3 * n:]).max()) / vel
            next_check = solver.t + check
            if detector.update(solver.t, rate, total, fscale):
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
    from .scene import load_scene

    scene = load_scene(scene_path, overrides)
    sim = Simulation(scene)
    compile_time = sim.warm_up()
    res = sim.run()
    exact = res.reference.total_friction

    def rel(x):
        return abs(x - exact) / abs(exact)

    out = {"ours_wall_time": res.wall_time, "ours_error": rel(res.solution.total_friction)}
    log(f"ours   ({sim.numerics.integrator}, {sim.grid.n_elements} elements): "
        f"{res.steps} steps, wall {res.wall_time:.4f} s, total friction "
        f"{res.solution.total_friction:.6g} N, error {out['ours_error']:.2e} "
        f"(compile/cache load {compile_time:.2f} s, not counted)")
    if peer:
        total, wall, t, nfev, conv = run_peer(Simulation(scene))
        out.update(peer_wall_time=wall, peer_error=rel(total))
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


# ---------------------------------------------------------------------------
# Stability matrix

#: The acceptance bounds of the transient simulator (relative errors; slip start in m).
BOUNDS = {"total_friction": 5e-3, "u": 2e-2, "theta": 2e-2, "concentrated_force": 5e-2,
          "slip_start": 5e-3}

_THIN = ("beam.height=0.01",)
#: (name, base scene, overrides): each derived from the paper's data.
STABILITY_CASES = (
    ("paper quasistatic", "paper_quasistatic", ()),
    ("paper inertia", "paper_inertia", ()),
    ("paper slip", "paper_slip", ()),
    ("stiff friction (v_reg 1e-5, f* 1e8)", "paper_slip",
     ("contact.max_friction=1e8", "numerics.regularisation=1e-5")),
    ("stiff belt (E x 100)", "paper_slip", ("beam.youngs_modulus=5e9",)),
    ("thin belt (h = 0.01 m)", "paper_slip", _THIN),
    ("thin belt, quasistatic", "paper_slip", _THIN + ("physics.inertia=false",)),
    ("near-critical (c = 0.97 sqrt(a/I))", "paper_slip",
     ("motion.belt_speed=125.2265", "motion.surface_speed=126.4787")),
    ("large mismatch (v/c - 1 = 0.05)", "paper_slip", ("motion.surface_speed=126",)),
    ("v = c (zero state)", "paper_slip", ("motion.surface_speed=120",)),
    ("v < c (reversed forces)", "paper_slip", ("motion.surface_speed=118.8",)),
    ("short contact (x2 - x1 = 0.02 L)", "paper_slip", ("contact.start=0.49",
                                                          "contact.end=0.51")),
    ("contact ends 0.02 L from the outlet", "paper_slip", ("contact.start=0.6466666666666666",
                                                            "contact.end=0.98")),
    ("very fine grid (20,000 elements)", "paper_slip", ("numerics.elements=20000",)),
)


def stability_cell(base, overrides, scheme, extra=()):
    """One cell: status, reason, dt, steps, wall time and errors of one scheme on one case."""
    from .errors import BeltsimError
    from .scene import load_scene, runs_dir

    cell = {"scheme": scheme, "status": "", "reason": "", "dt": float("nan"), "steps": 0,
            "wall_time": float("nan"), **{f"error_{k}": float("nan") for k in ERROR_KEYS}}
    try:
        scene = load_scene(runs_dir() / f"{base}.toml",
                           [*overrides, *extra, f"numerics.integrator={scheme}"])
        sim = Simulation(scene)
    except BeltsimError as exc:
        msg = str(exc)
        not_applicable = "needs physics.inertia = true" in msg
        cell.update(status="not applicable" if not_applicable else "refused", reason=msg)
        return cell
    res = sim.run(raise_on_failure=False)
    err = res.errors() or {}
    cell.update(dt=sim.numerics.dt if scheme != "steady" else float("nan"), steps=res.steps,
                wall_time=res.wall_time,
                **{f"error_{k}": err[k] for k in ERROR_KEYS if err.get(k) is not None})
    if res.failed:
        cell.update(status="diverged", reason=res.reason)
    elif not res.converged:
        cell.update(status="not converged", reason=res.reason)
    else:
        over = [f"{k} {err[k]:.3g} > {b:g}" for k, b in BOUNDS.items()
                if err.get(k) is not None and not err[k] <= b]
        cell.update(status="out of bounds" if over else "converged", reason="; ".join(over))
    return cell


def stability_matrix(cases=STABILITY_CASES, schemes=("explicit", "implicit", "steady"),
                     extra=(), progress=None) -> list[dict]:
    rows = []
    for name, base, overrides in cases:
        for scheme in schemes:
            row = {"case": name, **stability_cell(base, overrides, scheme, extra=extra)}
            rows.append(row)
            if progress:
                progress(row)
    return rows


def stability_markdown(rows) -> str:
    """A table per case and scheme: status, dt, steps, wall time, errors, reason."""
    head = ("| case | scheme | status | dt [s] | steps | wall [s] | total friction | u | theta "
            "| conc. force | slip start [m] | reason |")
    lines = [head, "|" + "---|" * 12]

    def num(v, fmt):
        return "" if v is None or (isinstance(v, float) and not math.isfinite(v)) else fmt % v
    for r in rows:
        lines.append("| " + " | ".join([
            r["case"], r["scheme"], r["status"], num(r["dt"], "%.2e"), str(r["steps"]),
            num(r["wall_time"], "%.3g"),
            *(num(r[f"error_{k}"], "%.1e") for k in ERROR_KEYS),
            r["reason"].replace("|", "/")]) + " |")
    return "\n".join(lines) + "\n"
