"""The closed drive's performance figures, on the one engine.

``python -m benchmarks.drive [SCENE] [--elements N] [--repeat R] [--grids F,...]`` from the
repository root (SCENE defaults to the shipped ``drive_flat``) prints a log and, last, one
line of JSON (:func:`bench`'s dict):

* the kernels' compile time (empty numba cache) and load time (warm cache), each in a
  fresh process, apart from every other figure (``--no-kernels`` skips them);
* the default run from rest to steady state (``beltsim.run``): wall time of the call and
  of the solve (the run's own ``wall_time``), steps, Newton iterations, and its largest
  relative difference from the steady scheme's state;
* the steady scheme on the grid and on grids ``--grids`` times finer (default 10 and 100:
  the cost's growth with the grid);
* one Newton iteration's pieces on each of those grids, at the creep theory's state (the
  steady Newton's start): the residual with its Jacobian (numba), the bordered block-band
  factorisation with its solve, and the start itself;
* with ``--peers [LIST]``, generic peers on the same grid (:mod:`benchmarks.drive_peers`,
  all on the numpy reference of the kernel's residual): Newton with a sparse
  finite-difference Jacobian and spsolve, scipy.optimize.root krylov and hybr (against
  our steady scheme), BDF2 steps with splu (against our start-up); with ``--peers all``
  also solve_ivp's Radau and BDF on the tanh law's ODE form (against our start-up of the
  tanh law, timed here). Each is stopped at ``--peer-cap`` seconds; a table of them
  against ours is printed last before the JSON.

Each wall time is the shortest of ``--repeat`` calls with the kernels loaded.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import tempfile
import time

GRID_FACTORS = (10, 100)
KEYS = ("tight_tension", "slack_tension", "belt_speed", "driven_speed", "speed_ratio",
        "slip_arc_driver", "slip_arc_driven")

_KERNEL_LOAD = """
import json, sys, time
import beltsim
from beltsim.beltdrive import DriveScene
scene = DriveScene.loads(sys.stdin.read())
out = 0.0
for over in ({"numerics.integrator": "steady"}, {}):
    s = scene.with_overrides(over)
    t0 = time.perf_counter(); beltsim.run(s, stability=False); t1 = time.perf_counter()
    beltsim.run(s, stability=False)
    out += (t1 - t0) - (time.perf_counter() - t1)
print(json.dumps({"seconds": out}))
"""


def log(text):
    print(text, flush=True)


def _plain(v):
    """JSON-ready: numpy scalars to Python, non-finite floats to None."""
    if isinstance(v, dict):
        return {str(k): _plain(x) for k, x in v.items()}
    if isinstance(v, list | tuple):
        return [_plain(x) for x in v]
    if hasattr(v, "item") and not hasattr(v, "__len__"):
        v = v.item()
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return v


def kernel_time(scene, empty_cache: bool) -> float:
    """Seconds to compile (``empty_cache``) or load from numba's cache the kernels a drive
    runs with, in a fresh process: each run's first call less its second, on a coarse grid
    (40 elements) so that the work itself is small."""
    env = dict(os.environ)
    with tempfile.TemporaryDirectory() as cache:
        if empty_cache:
            env["NUMBA_CACHE_DIR"] = cache
        text = scene.with_overrides({"numerics.elements": 40,
                                     "numerics.t_end": 0.05}).to_toml()
        proc = subprocess.run([sys.executable, "-c", _KERNEL_LOAD], input=text, env=env,
                              capture_output=True, text=True, timeout=1200, check=False)
    if proc.returncode != 0:
        raise RuntimeError(f"kernel load in a fresh process failed: {proc.stderr.strip()}")
    return float(json.loads(proc.stdout.strip().splitlines()[-1])["seconds"])


def _shortest(fn, repeat):
    runs = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        res = fn()
        runs.append((time.perf_counter() - t0, res))
    return min(w for w, _ in runs), min((r for _, r in runs), key=lambda r: r.wall_time)


def difference(summary: dict, reference: dict) -> float:
    """The largest relative difference of the KEYS (the speed ratio as the speed loss); a
    drive of more than two pulleys (no two-pulley KEYS): of the belt's speed, each span's
    tension and each pulley's speed."""
    out = 0.0
    if "tight_tension" not in reference:
        pairs = [(summary["belt_speed"], reference["belt_speed"])]
        pairs += [(a["tension"], b["tension"])
                  for a, b in zip(summary["spans"], reference["spans"])]
        pairs += [(a["speed"], b["speed"])
                  for a, b in zip(summary["pulleys"], reference["pulleys"])]
        return max(abs(a - b) / max(abs(b), 1e-300) for a, b in pairs)
    for k in KEYS:
        a, b = summary[k], reference[k]
        if k == "speed_ratio":
            a, b = 1.0 - a, 1.0 - b
        out = max(out, abs(a - b) / max(abs(b), 1e-300))
    return out


def steady(scene, repeat: int, elements=None) -> tuple[dict, object]:
    """Our steady scheme, the shortest of ``repeat``; a failure is recorded, not raised."""
    import beltsim
    from beltsim.errors import BeltsimError

    over = {"numerics.integrator": "steady"}
    if elements:
        over["numerics.elements"] = elements
    s = scene.with_overrides(over)
    t0 = time.perf_counter()
    try:
        wall, res = _shortest(lambda: beltsim.run(s, stability=False), repeat)
    except BeltsimError as exc:
        log(f"ours, steady ({elements} elements): FAILED after "
            f"{time.perf_counter() - t0:.3g} s: {exc}")
        return {"elements": elements, "failed": str(exc), "wall_time": None}, None
    # the loop's grid may round the elements asked for (799 of 800 on the serpentine
    # drive's 14 segments): the unknowns are its nodes' u and theta and the globals
    st = res.solution.state
    n = 2 * len(st.u) + len(st.g)
    its = res.newton_iterations
    out = {"elements": res.numerics.elements, "unknowns": n, "failed": None,
           "wall_time": wall, "solve_wall_time": res.wall_time, "newton_iterations": its,
           "grid_iterations": res.statistics.get("grid_iterations"),
           "microseconds_per_unknown_iteration": 1e6 * res.wall_time / (n * max(its, 1)),
           "summary": res.solution.summary(), "errors": res.errors()}
    log(f"ours, steady ({out['elements']} elements, {n} unknowns): wall {wall:.4g} s "
        f"(solve {res.wall_time:.4g} s), {its} Newton iterations "
        f"({out['grid_iterations']} by grid)")
    return out, res


def start_up(scene, repeat: int, reference: dict, elements=None) -> dict:
    """Our default run from rest, the shortest of ``repeat``."""
    import beltsim

    s = scene.with_overrides({"numerics.elements": elements} if elements else {})
    wall, res = _shortest(lambda: beltsim.run(s, raise_on_failure=False, stability=False),
                           repeat)
    summary = res.solution.summary()
    out = {"wall_time": wall, "solve_wall_time": res.wall_time, "status": res.status.value,
           "reason": res.reason, "converged": res.converged, "steps": res.steps,
           "newton_iterations": res.newton_iterations,
           "rejected_steps": res.statistics.get("rejected_steps", 0),
           "simulated_time": res.simulated_time, "integrator": res.numerics.integrator,
           "friction_law": res.numerics.friction_law, "elements": res.numerics.elements,
           "difference": difference(summary, reference) if res.converged else None}
    log(f"ours, start-up ({out['integrator']}, {out['friction_law']} law, "
        f"{out['elements']} elements): {out['status']} at t = {out['simulated_time']:.4g} "
        f"s, {out['steps']} steps, {out['newton_iterations']} Newton iterations, wall "
        f"{wall:.4g} s, solve {res.wall_time:.4g} s")
    return out


def iteration_cost(scene, elements=None) -> dict:
    """One Newton iteration's pieces at the creep theory's state, each the shortest of
    enough calls to last about 0.2 s."""
    import numpy as np

    from beltsim.physics.friction import TANH
    from beltsim.physics.model import assemble
    from beltsim.solvers import LoopDiscretisation
    from beltsim.solvers.newton import Workspace, factorise, linear_solve
    from beltsim.solvers.steady import creep_state

    d = LoopDiscretisation(scene.with_overrides({"numerics.elements": elements}
                                                if elements else {}))
    # the regularised twin's condensed 2x2 system: what the steady scheme solves first
    model = d.model._replace(law=TANH, dual=1)
    N = len(d.mesh.hb)
    st = d.new_state()
    creep_state(d, st)
    w = Workspace.allocate(N, False, True, d.n_globals)
    f = np.zeros(N)
    drive = d.steady_drive()

    def jac():
        assemble(st.u, st.theta, st.lam, st.g, f, st, 0.0, 0.0, d.mesh, model, drive,
                 d.loads, w, True)

    def solve():
        factorise(w, d.mesh)
        linear_solve(w, d.mesh, w.R, w.Rg, w.dx, w.dg)

    def start():
        creep_state(d, d.new_state())

    def timed(fn):
        fn()
        t0 = time.perf_counter()
        fn()
        once = time.perf_counter() - t0
        best = math.inf
        for _ in range(max(3, min(200, int(0.2 / max(once, 1e-6))))):
            t0 = time.perf_counter()
            fn()
            best = min(best, time.perf_counter() - t0)
        return best

    jac()
    out = {"elements": N, "unknowns": 2 * N + d.n_globals,
           "residual_jacobian_s": timed(jac), "linear_solve_s": timed(solve),
           "start_s": timed(start)}
    log(f"ours, one Newton iteration ({N} elements): residual with Jacobian "
        f"{1e3 * out['residual_jacobian_s']:.3g} ms, bordered factorisation and solve "
        f"{1e3 * out['linear_solve_s']:.3g} ms; the start (the creep theory's state) "
        f"{1e3 * out['start_s']:.3g} ms")
    return out


#: the generic peers of ``--peers`` (benchmarks.drive_peers), by key: radau and bdf run
#: the tanh law (a method-of-lines right-hand side needs a single-valued law)
PEERS = ("newton", "krylov", "hybr", "bdf2", "radau", "bdf")
#: those of ``--peers`` without a choice (``--peers all``: every one)
DEFAULT_PEERS = PEERS[:4]
#: the ODE peers' rtol
ODE_RTOL = 1e-3


def peers(scene, steady_out: dict, ours, start_out: dict, cap: float,
          which=PEERS, repeat: int = 1) -> dict:
    """The generic peers of :mod:`benchmarks.drive_peers` on our steady run's grid, each
    capped at ``cap`` s, against our steady scheme (``steady_out``, its result ``ours``)
    or our start-up (``start_out``); the ODE peers (tanh law) against our run of the tanh
    law (its start-up, timed here, and its steady state). Prints their table."""
    import beltsim
    from beltsim.simulation.controller import Simulation
    from beltsim.solvers import LoopDiscretisation

    from . import drive_peers as dp

    elements = steady_out["elements"]
    base = scene.with_overrides({"numerics.elements": elements})
    d = LoopDiscretisation(base.with_overrides({"numerics.integrator": "steady"}))
    state = ours.solution.state
    tanh = base.with_overrides({"numerics.friction_law": "tanh"})
    tanh_out = tanh_state = None
    if {"radau", "bdf"} & set(which):
        tanh_steady = beltsim.run(tanh.with_overrides({"numerics.integrator": "steady"}))
        tanh_state = tanh_steady.solution.state
        # at least twice: the first run of the tanh law in a process loads its kernels
        tanh_out = start_up(tanh, max(2, repeat), tanh_steady.solution.summary())
    rows = []
    for key in which:
        log(f"peer {key} ({elements} elements, cap {cap:g} s) ...")
        ref, against, same = state, "steady scheme", dp.SAME_STEADY
        base_solve = steady_out["solve_wall_time"]
        if key == "newton":
            res = dp.run_newton_peer(d, cap=cap)
        elif key in ("krylov", "hybr"):
            res = dp.run_root_peer(d, key, cap=cap)
        elif key == "bdf2":
            res = dp.run_bdf2_peer(Simulation(base), cap=cap)
            against, same = "start-up (default run)", dp.SAME_RUN
            base_solve = start_out["solve_wall_time"]
        elif key in ("radau", "bdf"):
            res = dp.run_ode_peer(Simulation(tanh), "Radau" if key == "radau" else "BDF",
                                  ODE_RTOL, cap=cap)
            ref, against, same = tanh_state, "start-up, tanh law", dp.SAME_RUN
            base_solve = tanh_out["solve_wall_time"]
        else:
            raise ValueError(f"unknown peer {key!r}")
        diff = dp.difference(d, res.state, ref)
        reached = res.converged and diff <= same
        rows.append({"peer": key, "name": res.name, "against": against,
                     "wall_time": res.wall_time, "converged": res.converged,
                     "reason": res.reason, "reached": reached, "difference": diff,
                     "tolerance": same, "ours_solve": base_solve,
                     "ratio": res.wall_time / base_solve,
                     "simulated_time": res.simulated_time, "statistics": res.statistics})
        log(f"  {res.name}: {res.reason}, wall {res.wall_time:.4g} s, difference "
            f"{diff:.2e}, its wall over our solve {res.wall_time / base_solve:.3g}"
            f"{'' if reached else ' (did NOT reach our state)'}")
    table(steady_out, start_out, rows, tanh_out)
    return {"elements": elements, "cap": cap, "rows": rows, "start_up_tanh": tanh_out}


def table(steady_out: dict, start_out: dict, rows, tanh_out=None) -> None:
    """The peers' table, ours first (plain text)."""
    head = ("method", "against", "call [s]", "solve [s]", "its solve over ours",
            "reached our state", "largest difference")
    lines = [("ours: steady scheme", "", f"{steady_out['wall_time']:.4g}",
              f"{steady_out['solve_wall_time']:.4g}", "1", "yes", ""),
             (f"ours: start-up ({start_out['integrator']})", "",
              f"{start_out['wall_time']:.4g}", f"{start_out['solve_wall_time']:.4g}", "1",
              "yes" if start_out["converged"] else "no",
              f"{start_out['difference']:.2e}" if start_out["difference"] is not None
              else "")]
    if tanh_out is not None:
        lines.append((f"ours: start-up ({tanh_out['integrator']}), tanh law", "",
                      f"{tanh_out['wall_time']:.4g}", f"{tanh_out['solve_wall_time']:.4g}",
                      "1", "yes" if tanh_out["converged"] else "no",
                      f"{tanh_out['difference']:.2e}" if tanh_out["difference"] is not None
                      else ""))
    for r in rows:
        ratio = f"{r['ratio']:.3g}" if r["reached"] else f">= {r['ratio']:.3g}"
        why = "yes" if r["reached"] else (
            f"no: {r['reason']}" if not r["converged"]
            else f"no: {r['difference']:.1e} > {r['tolerance']:g}")
        lines.append((r["name"], r["against"], f"{r['wall_time']:.4g}",
                      f"{r['wall_time']:.4g}", ratio, why, f"{r['difference']:.2e}"))
    widths = [max(len(x[i]) for x in (head, *lines)) for i in range(len(head))]
    for line in (head, tuple("-" * w for w in widths), *lines):
        log(" | ".join(x.ljust(w) for x, w in zip(line, widths)))


def bench(scene, repeat: int = 3, elements=None, grids=GRID_FACTORS, kernels=True,
          peer_cap=None, which=PEERS) -> dict:
    """Every figure of the module's docstring, as a dict; with ``peer_cap`` (s), the
    peers too."""
    out = {"kernels": None}
    if kernels:
        out["kernels"] = {"compile_s": kernel_time(scene, True),
                          "load_s": kernel_time(scene, False)}
        log(f"kernels: compile {out['kernels']['compile_s']:.3g} s, load "
            f"{out['kernels']['load_s']:.3g} s")
    base = elements
    first, ref = steady(scene, repeat, base)
    if ref is None:
        raise RuntimeError(f"the steady scheme failed: {first['failed']}")
    n0 = first["elements"]
    out["steady"] = [first] + [steady(scene, max(1, repeat if f <= 10 else 1), n0 * f)[0]
                               for f in grids]
    out["iteration"] = [iteration_cost(scene, e["elements"]) for e in out["steady"]
                        if e.get("elements")]
    out["start_up"] = start_up(scene, repeat, ref.solution.summary(), base)
    if peer_cap is not None:
        out["peers"] = peers(scene, first, ref, out["start_up"], peer_cap, which, repeat)
    return _plain(out)


def main(argv=None) -> int:
    import argparse

    from beltsim.api import load_scene

    p = argparse.ArgumentParser(prog="python -m benchmarks.drive")
    p.add_argument("scene", nargs="?", default="drive_flat")
    p.add_argument("--elements", type=int, default=None)
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--grids", default=",".join(map(str, GRID_FACTORS)),
                   help="comma-separated factors of finer grids for the steady scheme")
    p.add_argument("--no-kernels", action="store_true", help="skip compile and load times")
    p.add_argument("--peers", nargs="?", const=",".join(DEFAULT_PEERS), default=None,
                   help="run generic peers (benchmarks.drive_peers) on the grid: "
                        f"{', '.join(DEFAULT_PEERS)} without a value, 'all', or a "
                        f"comma-separated choice of {', '.join(PEERS)}")
    p.add_argument("--peer-cap", type=float, default=300.0,
                   help="each peer's wall-time cap in s (default 300)")
    p.add_argument("--json", default=None, help="also write the dict to this file")
    args = p.parse_args(argv)
    if args.repeat < 1:
        p.error(f"--repeat: must be at least 1, got {args.repeat}")
    try:
        grids = tuple(int(g) for g in args.grids.split(",") if g)
    except ValueError:
        p.error(f"--grids: expected comma-separated whole numbers, got {args.grids!r}")
    which = PEERS
    if args.peers is not None:
        which = PEERS if args.peers == "all" else tuple(k for k in args.peers.split(",")
                                                        if k)
        bad = [k for k in which if k not in PEERS]
        if bad:
            p.error(f"--peers: unknown {', '.join(bad)} (choose from {', '.join(PEERS)})")
    out = bench(load_scene(args.scene), args.repeat, args.elements, grids,
                kernels=not args.no_kernels,
                peer_cap=args.peer_cap if args.peers is not None else None, which=which)
    emit(out, args.json)
    return 0


def emit(out: dict, path=None) -> None:
    """Print ``out`` as one line of JSON, last; with ``path``, write it there too."""
    text = json.dumps(_plain(out))
    if path:
        with open(path, "w", encoding="utf-8") as fh:
            fh.write(text)
    print(text)


if __name__ == "__main__":
    sys.exit(main())
