"""The closed drive's performance figures, against generic peers on the same discretisation.

``python -m benchmarks.drive [SCENE] [--elements N] [--repeat R]`` from the repository
root (SCENE defaults to the shipped ``drive_flat``) prints a log and, last, one line of
JSON (:func:`bench`'s dict). Ours:

* the kernels' compile time (empty numba cache) and load time (warm cache), each in a
  fresh process, apart from every other figure;
* the default run, :func:`beltsim.beltdrive.simulate` from rest to steady state: wall
  time, steps, Newton iterations;
* the steady scheme, :func:`beltsim.beltdrive.solve_steady`, on the grid and on grids
  ``--grids`` times finer (default 10 and 100: the cost's growth with the grid);
* one Newton iteration's pieces on each of those grids: the residual with its Jacobian
  (numba) and the bordered-band linear solve.

The peers (:mod:`benchmarks.drive_peers`) solve the same equations (the numpy/scipy.sparse
reference of the kernel) with generic tools: the steady state by the same Newton on
scipy.sparse (``spsolve``) and by ``scipy.optimize.root`` ("hybr", "krylov"); the start-up
by the same BDF2 steps on scipy.sparse (``splu``), and by ``solve_ivp``'s Radau and BDF
on the method-of-lines ODE, which exists for a regularised law only (tanh, the drive's
default v_reg) and is compared with our run of that law. A peer counts when it converged
and its summary is within SAME_STATE of our steady state (see :func:`bench`).

Two wall times: the whole call, and the solve, which is what the ratios compare: a run's
own ``wall_time`` (from its start to its last state: without the grid's setup and the
analytic solution every result carries, ~20 ms for the beam's), for ours and for the
peers that run our algorithms; the whole call for the scipy peers, whose setup is a few
array operations. Each is the shortest of ``--repeat`` runs with the kernels loaded (a
peer that needs more than PEER_REPEAT_LIMIT seconds runs once); ``--peer-cap`` stops a
peer.

Run as a script, the module keeps BLAS to one thread (``OPENBLAS_NUM_THREADS=1`` unless
set): on this 2-core machine, shared, OpenBLAS's threads made a dense LU of 400 unknowns
30 times slower than one thread did, which would flatter us.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import time

if __name__ == "__main__":  # before numpy loads (see the docstring)
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

DEFAULT_SCENE = "drive_flat"
#: finer grids for the steady scheme's growth, as factors of the default grid
GRID_FACTORS = (10, 100)
#: a peer whose first run takes longer than this (s) is not repeated
PEER_REPEAT_LIMIT = 10.0
DEFAULT_PEER_CAP = 600.0  # s of wall time per peer run
#: The solve_ivp peers' rtol: Radau reaches the steady state at 1e-3 (40, 100 and 800
#: elements); the steady test, not the tolerance, sets how close to it a run stops. BDF
#: crawls at any rtol tried (its orders 3-5 are not A-stable and the belt's waves are
#: barely damped): at 1e-3 on 800 elements it covered 0.25 s of the start-up in 600 s.
ODE_RTOL = {"Radau": 1e-3, "BDF": 1e-3}
#: every peer by key: what it solves
PEERS = {"newton": "steady", "hybr": "steady", "lm": "steady", "krylov": "steady",
         "bdf2": "start_up", "radau": "start_up", "bdf": "start_up"}
#: the peers that take our own algorithm on generic pieces (the others are generic
#: solvers): their ratio is what the compiled kernels and the bordered-band solve buy
PORTS = ("newton", "bdf2")
DEFAULT_PEERS = tuple(PEERS)


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


_KERNEL_LOAD = """
import json, sys, time
from beltsim.beltdrive import DriveScene, simulate, solve_steady
scene = DriveScene.loads(sys.stdin.read())
out = {}
for name, fn in (("steady", solve_steady), ("simulate", simulate)):
    t0 = time.perf_counter(); fn(scene); t1 = time.perf_counter(); fn(scene)
    out[name] = (t1 - t0) - (time.perf_counter() - t1)
print(json.dumps({"seconds": out["steady"] + out["simulate"]}))
"""


def kernel_time(scene, empty_cache: bool) -> float:
    """Seconds to compile (``empty_cache``) or load from numba's cache the drive's kernels,
    in a fresh process: each solver's first call less its second, on a coarse grid (40
    elements) so that the work itself is small."""
    env = dict(os.environ)
    import tempfile

    with tempfile.TemporaryDirectory() as cache:
        if empty_cache:
            env["NUMBA_CACHE_DIR"] = cache
        text = scene.with_overrides(["numerics.elements=40"]).to_toml()
        proc = subprocess.run([sys.executable, "-c", _KERNEL_LOAD], input=text, env=env,
                              capture_output=True, text=True, timeout=1200, check=False)
    if proc.returncode != 0:
        raise RuntimeError(f"kernel load in a fresh process failed: {proc.stderr.strip()}")
    return float(json.loads(proc.stdout.strip().splitlines()[-1])["seconds"])


def start_up(scene, repeat: int, elements=None, log=print) -> dict:
    """Our default run from rest, the shortest of ``repeat``."""
    from beltsim.beltdrive import simulate

    def once():
        t0 = time.perf_counter()
        res = simulate(scene, elements)
        return time.perf_counter() - t0, res

    runs = [once() for _ in range(repeat)]
    walls = [w for w, _ in runs]
    wall = min(walls)
    res = min((r for _, r in runs), key=lambda r: r.wall_time)
    st = res.statistics
    out = {"wall_time": wall, "walls": walls, "solve_wall_time": res.wall_time,
           "status": res.status.value, "reason": res.reason, "converged": res.converged,
           "steps": st["steps"], "newton_iterations": st["newton_iterations"],
           "rejected_steps": st["rejected_steps"],
           "simulated_time": float(res.history["t"][-1]) if len(res.history["t"]) else 0.0,
           "friction_law": res.numerics.friction_law, "elements": res.numerics.elements,
           "summary": dict(res.summary), "errors": res.errors()}
    log(f"ours, start-up ({out['friction_law']} law, {out['elements']} elements): "
        f"{res.status.value} at t = {out['simulated_time']:.4g} s, {out['steps']} steps, "
        f"{out['newton_iterations']} Newton iterations, wall {wall:.4g} s (shortest of "
        f"{repeat}: {', '.join(f'{w:.3g}' for w in walls)}), solve {res.wall_time:.4g} s")
    return out, res


def steady(scene, repeat: int, elements=None, log=print) -> tuple[dict, object]:
    """Our steady scheme, the shortest of ``repeat``; a failure is recorded (``failed``:
    its message; the result None), not raised."""
    from beltsim.beltdrive import solve_steady
    from beltsim.beltdrive.discrete import layout_of, loop_mesh
    from beltsim.errors import BeltsimError

    def once():
        t0 = time.perf_counter()
        res = solve_steady(scene, elements)
        return time.perf_counter() - t0, res

    num_elements = elements or drive_numerics(scene).elements
    n = layout_of(loop_mesh(scene.params.geometry, num_elements)).size
    t0 = time.perf_counter()
    try:
        runs = [once() for _ in range(repeat)]
    except BeltsimError as exc:
        wall = time.perf_counter() - t0
        log(f"ours, steady ({num_elements} elements, {n} unknowns): FAILED after {wall:.3g} "
            f"s: {exc}")
        return {"elements": num_elements, "unknowns": n, "failed": str(exc),
                "wall_time": None}, None
    wall = min(w for w, _ in runs)
    res = min((r for _, r in runs), key=lambda r: r.wall_time)
    its = res.statistics["newton_iterations"]
    out = {"elements": num_elements, "unknowns": n, "failed": None,
           "wall_time": wall, "solve_wall_time": res.wall_time, "newton_iterations": its,
           "microseconds_per_unknown_iteration": 1e6 * res.wall_time / (n * max(its, 1)),
           "summary": dict(res.summary), "errors": res.errors()}
    log(f"ours, steady ({num_elements} elements, {n} unknowns): wall {wall:.4g} s "
        f"(solve {res.wall_time:.4g} s), {its} Newton iterations, "
        f"{out['microseconds_per_unknown_iteration']:.3g} us per unknown and iteration")
    return out, res


def drive_numerics(scene, elements=None):
    """The scene's resolved numerics (:func:`beltsim.beltdrive.run.resolve`)."""
    from beltsim.beltdrive.run import resolve

    return resolve(scene, elements)


def iteration_cost(scene, elements=None, log=print) -> dict:
    """One Newton iteration's pieces at the string's state (the steady Newton's start):
    the residual alone, the residual with the Jacobian's triplets (numba), and the
    bordered-band solve (scatter, LAPACK gbsv, the border's Schur complement); and the
    start itself (the string's solution and its values on the grid). Each the shortest
    of enough calls to last about 0.2 s."""
    from beltsim.beltdrive.analytic import solve_string
    from beltsim.beltdrive.discrete import layout_of, loop_mesh, loop_params, string_guess
    from beltsim.beltdrive.model import assemble
    from beltsim.beltdrive.run import resolve
    from beltsim.beltdrive.solver import make_system, steady_rates

    num = resolve(scene, elements)
    P = scene.params
    mesh = loop_mesh(P.geometry, num.elements)
    lay = layout_of(mesh)
    prm = loop_params(P, num.friction_law, num.regularisation)
    S = make_system(mesh, prm, lay, P)
    y = string_guess(solve_string(P), mesh, lay)
    rates = steady_rates(lay.N)
    rim1 = P.omega1 * P.geometry.R1

    def timed(fn):
        fn()
        t0 = time.perf_counter()
        fn()
        once = time.perf_counter() - t0
        k = max(3, min(200, int(0.2 / max(once, 1e-6))))
        best = math.inf
        for _ in range(k):
            t0 = time.perf_counter()
            fn()
            best = min(best, time.perf_counter() - t0)
        return best

    def jac():
        return assemble(y, rates, rim1, P.M2, S.q, mesh, prm, S.R, S.rows, S.cols, S.vals,
                        True)

    n = jac()
    R = S.R.copy()
    out = {"elements": num.elements, "unknowns": lay.size,
           "residual_s": timed(lambda: assemble(y, rates, rim1, P.M2, S.q, mesh, prm, S.R, S.rows,
                                                S.cols, S.vals, False)),
           "residual_jacobian_s": timed(jac),
           "linear_solve_s": timed(lambda: S.band.solve(S, n, R)),
           "start_s": timed(lambda: string_guess(solve_string(P), mesh, lay))}
    out["linear_solve_us_per_unknown"] = 1e6 * out["linear_solve_s"] / lay.size
    log(f"ours, one Newton iteration ({num.elements} elements, {lay.size} unknowns): "
        f"residual {1e3 * out['residual_s']:.3g} ms, with Jacobian "
        f"{1e3 * out['residual_jacobian_s']:.3g} ms, linear solve "
        f"{1e3 * out['linear_solve_s']:.3g} ms "
        f"({out['linear_solve_us_per_unknown']:.3g} us per unknown); the steady Newton's "
        f"start (the string's state on the grid) {1e3 * out['start_s']:.3g} ms")
    return out


def _peer_entry(res, reference: dict, ours_wall: float, ours_label: str) -> dict:
    """A peer's row: ``ours_wall`` is our solve's wall time, compared with the peer's."""
    from .drive_peers import SAME_STATE, difference, speed_loss_difference

    diff = difference(res.summary, reference)
    same = diff is not None and diff <= SAME_STATE
    converged = bool(res.converged and same)
    reason = res.reason if same or not res.converged else \
        f"converged, but {diff:.2g} from the reference state"
    solve = res.solve_wall_time if res.solve_wall_time is not None else res.wall_time
    return {"method": res.name, "wall_time": res.wall_time, "solve_wall_time": solve,
            "converged": converged,
            "reason": reason, "difference": diff,
            "speed_loss_difference": speed_loss_difference(res.summary, reference),
            "statistics": res.statistics,
            "ours": ours_label, "ours_solve_wall_time": ours_wall,
            "ratio": solve / ours_wall if converged else None,
            "ratio_at_least": solve / ours_wall}


def _run_peer(fn, repeat: int):
    first = fn()
    if not first.converged or first.wall_time > PEER_REPEAT_LIMIT:
        return first
    return min([first] + [fn() for _ in range(repeat - 1)],
               key=lambda r: r.solve_wall_time or r.wall_time)


def run_peers(scene, which, repeat: int, peer_cap: float, ours: dict, elements=None,
              log=print) -> dict:
    """The generic peers ``which`` (keys of PEERS) on the scene's grid.

    ``ours``: {"steady": (figures, result), "start_up": (figures, result)} of the
    scene's own law. The steady peers and the BDF2 peer are compared with our steady
    state (the discrete solution they all solve for); the solve_ivp peers, on the tanh
    law, with our steady state of that law, and timed against our run of that law.
    """
    from beltsim.beltdrive import solve_steady

    from . import drive_peers as dp

    st_fig, st_res = ours["steady"]
    su_fig, _ = ours["start_up"]
    out = {}
    for key in which:
        if key == "newton":
            res = _run_peer(lambda: dp.run_generic_steady(scene, elements), repeat)
        elif key in ("hybr", "lm", "krylov"):
            res = _run_peer(lambda k=key: dp.run_root_peer(scene, k, elements,
                                                           max_wall=peer_cap), repeat)
        elif key == "bdf2":
            res = _run_peer(lambda: dp.run_generic_transient(scene, elements), repeat)
        else:
            continue
        base = st_fig if PEERS[key] == "steady" else su_fig
        label = "steady scheme" if PEERS[key] == "steady" else \
            f"default run ({su_fig['friction_law']} law)"
        out[key] = entry = _peer_entry(res, st_res.summary, base["solve_wall_time"], label)
        _log_peer(key, entry, log)
    odes = [k for k in which if k in ("radau", "bdf")]
    if odes:
        tanh = scene.with_overrides(["numerics.friction_law=tanh"])
        ref = solve_steady(tanh, elements).summary
        fig, _ = start_up(tanh, repeat, elements, log)
        fig["difference"] = dp.difference(fig["summary"], ref)
        fig["speed_loss_difference"] = dp.speed_loss_difference(fig["summary"], ref)
        out["ours_tanh"] = {k: fig[k] for k in ("wall_time", "solve_wall_time", "steps",
                                                  "newton_iterations",
                                                  "simulated_time", "converged",
                                                  "difference", "speed_loss_difference")}
        for key in odes:
            method = {"radau": "Radau", "bdf": "BDF"}[key]
            try:
                res = _run_peer(lambda m=method: dp.run_ode_peer(
                    tanh, m, ODE_RTOL[m], elements, max_wall=peer_cap), repeat)
            except ValueError as exc:  # no ODE form for this scene
                out[key] = {"method": f"solve_ivp {method}", "wall_time": None,
                            "converged": False, "reason": f"not applicable: {exc}",
                            "ratio": None, "ratio_at_least": None}
                continue
            out[key] = entry = _peer_entry(res, ref, fig["solve_wall_time"],
                                           "default run, tanh law")
            _log_peer(key, entry, log)
    return out


def _log_peer(key, e, log):
    diff = "n/a" if e["difference"] is None else f"{e['difference']:.2g}"
    ratio = (f"{e['ratio']:.3g}x" if e["ratio"] is not None else
             f"not converged (>= {e['ratio_at_least']:.3g}x)")
    log(f"peer {key:6s} ({e['method']}): wall {e['wall_time']:.4g} s (solve "
        f"{e['solve_wall_time']:.4g} s), {e['reason']}; {diff} from our steady state; its "
        f"solve's wall over ours ({e['ours']}): {ratio}")


def bench(scene, repeat: int = 3, elements=None, grids=GRID_FACTORS, peers=DEFAULT_PEERS,
          peer_cap: float = DEFAULT_PEER_CAP, kernels: bool = True, log=print) -> dict:
    """Ours on ``scene`` and, for ``peers``, the generic peers: the figures as a dict.

    Keys: ``kernels`` (compile_s, load_s), ``start_up``, ``steady`` (a list: the grid,
    then ``grids`` times finer), ``iteration`` (a list alike), ``peers`` (by key, see
    :func:`run_peers`); ``speedup``, ``kernel_speedup`` and ``solver_speedup``, each
    {"steady", "start_up"}: the smallest ratio among the converged peers of each kind
    (all of them; the PORTS; the generic solvers), None when none converged.
    """
    from .drive_peers import SAME_STATE, difference, speed_loss_difference

    out = {"scene": getattr(scene, "source", None), "repeat": repeat,
           "blas_threads": os.environ.get("OPENBLAS_NUM_THREADS"), "same_state": SAME_STATE,
           "cores": os.cpu_count(), "load_average_start": os.getloadavg()[0]}
    if kernels:
        out["kernels"] = {"compile_s": kernel_time(scene, True),
                          "load_s": kernel_time(scene, False)}
        log(f"kernels: compile {out['kernels']['compile_s']:.3g} s (empty cache), load "
            f"{out['kernels']['load_s']:.3g} s (warm cache), each in a fresh process")
    from beltsim.beltdrive import simulate, solve_steady

    solve_steady(scene, 40)  # the kernels loaded before any timing
    simulate(scene, 40)
    su, su_res = start_up(scene, repeat, elements, log)
    out["start_up"] = su
    base = su["elements"]
    out["steady"], out["iteration"] = [], []
    st0 = None
    for f in (1, *grids):
        fig, res = steady(scene, repeat, base * f, log)
        out["steady"].append(fig)
        if f == 1:
            if res is None:
                raise RuntimeError(f"the steady scheme failed on the scene's grid: "
                                   f"{fig['failed']}")
            st0 = (fig, res)
        out["iteration"].append(iteration_cost(scene, base * f, log))
    su["difference"] = difference(su["summary"], st0[1].summary)
    su["speed_loss_difference"] = speed_loss_difference(su["summary"], st0[1].summary)
    log(f"ours, start-up against our steady state: {su['difference']:.2g} (speed loss "
        f"{su['speed_loss_difference']:.2g})")
    out["peers"] = run_peers(scene, peers, repeat, peer_cap,
                             {"steady": st0, "start_up": (su, su_res)}, elements, log)
    groups = {"speedup": lambda k: True, "kernel_speedup": lambda k: k in PORTS,
              "solver_speedup": lambda k: k not in PORTS}
    for name, keep in groups.items():
        out[name] = {}
        for kind in ("steady", "start_up"):
            ratios = [e["ratio"] for k, e in out["peers"].items()
                      if PEERS.get(k) == kind and keep(k) and e.get("ratio") is not None]
            out[name][kind] = min(ratios) if ratios else None
        log(f"{name} (the fastest converged peer's solve wall over ours"
            f"{'' if name == 'speedup' else ', ' + name.split('_')[0] + ' peers'}): steady "
            f"{_ratio(out[name]['steady'])}, start-up {_ratio(out[name]['start_up'])}")
    out["load_average_end"] = os.getloadavg()[0]
    return _plain(out)


def _ratio(x):
    return "n/a" if x is None else f"{x:.3g}x"


def main(argv=None) -> int:
    from beltsim.cli import OneLineParser
    from beltsim.errors import BeltsimError

    parser = OneLineParser(prog="python -m benchmarks.drive",
                           description=__doc__.split("\n\n")[0])
    parser.add_argument("scene", nargs="?", default=DEFAULT_SCENE,
                        help=f"drive scene file or shipped name (default {DEFAULT_SCENE})")
    parser.add_argument("--set", dest="overrides", action="append", default=[],
                        metavar="SECTION.KEY=VALUE", help="override a scene key (repeatable)")
    parser.add_argument("--elements", type=int, default=None, help="numerics.elements")
    parser.add_argument("--repeat", type=int, default=3,
                        help="time each run this many times and keep the shortest")
    parser.add_argument("--grids", default=",".join(map(str, GRID_FACTORS)),
                        help="finer grids for the steady scheme, as factors (comma-separated; "
                             "empty for none)")
    parser.add_argument("--peers", default=",".join(DEFAULT_PEERS),
                        help=f"peers to run, comma-separated from {', '.join(PEERS)} "
                             f"(empty for none)")
    parser.add_argument("--peer-cap", type=float, default=DEFAULT_PEER_CAP,
                        help="wall-time cap of one peer run, s")
    parser.add_argument("--no-kernels", action="store_true",
                        help="skip the compile and load times (fresh processes)")
    parser.add_argument("--json", dest="json_path", default=None,
                        help="also write the JSON to this file")
    args = parser.parse_args(argv)
    if args.repeat < 1:
        parser.error(f"--repeat: must be at least 1, got {args.repeat}")
    if not args.peer_cap > 0:
        parser.error(f"--peer-cap: must be positive, got {args.peer_cap}")
    try:
        grids = tuple(int(g) for g in args.grids.split(",") if g.strip())
    except ValueError:
        parser.error(f"--grids: must be comma-separated integers, got {args.grids!r}")
    if any(g < 2 for g in grids):
        parser.error(f"--grids: factors must be at least 2, got {args.grids!r}")
    peers = tuple(p.strip() for p in args.peers.split(",") if p.strip())
    unknown = [p for p in peers if p not in PEERS]
    if unknown:
        parser.error(f"--peers: unknown {', '.join(unknown)}; one of {', '.join(PEERS)}")
    from beltsim.api import load_scene
    from beltsim.beltdrive import DriveScene

    overrides = list(args.overrides)
    if args.elements is not None:
        overrides.append(f"numerics.elements={args.elements}")
    try:
        scene = load_scene(args.scene, overrides)
        if not isinstance(scene, DriveScene):
            parser.error(f"scene: {args.scene} is not a closed drive (no [drive] section)")
        result = bench(scene, repeat=args.repeat, grids=grids, peers=peers,
                       peer_cap=args.peer_cap, kernels=not args.no_kernels)
    except BeltsimError as exc:
        print(f"benchmarks.drive: error: {exc}", file=sys.stderr)
        return 2
    text = json.dumps(result)
    if args.json_path:
        with open(args.json_path, "w", encoding="utf-8") as fh:
            fh.write(text + "\n")
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
