"""beltsim against generic scipy peers and against a numpy port of its default scheme.

``python -m benchmarks.bench [SCENE] [--elements N]`` from the repository root prints a
log and, last, one line of JSON. The peers (:mod:`benchmarks.peers`) are what a skilled
user would write instead, on the same grid and the same semi-discretisation (the
vectorised reference of the model): scipy's Radau and BDF from rest to the steady test of
a run, each at its loosest tolerance that reaches beltsim's steady state, and a sparse
Newton iteration on the steady equations. The port (:mod:`benchmarks.port`) takes the
default scheme's own steps with numpy and scipy.sparse; its wall time over beltsim's is
what the compiled kernels buy. Every wall time is the shortest of ``repeat`` runs and
excludes numba compilation.
"""

from __future__ import annotations

import sys

from beltsim.api import load_scene
from beltsim.cli import OneLineParser
from beltsim.errors import BeltsimError
from beltsim.problem.scene import Scene
from beltsim.simulation.controller import Simulation
from beltsim.simulation.result import reference_of
from beltsim.simulation.solution import relative_error
from beltsim.studies.bench import bench_json, best_of, explicit_node_steps_per_s, run_ours

from . import peers, port

#: The transient peers, by key: (scipy class, description)
TRANSIENT_PEERS = {"radau": ("Radau", "solve_ivp Radau, analytic sparse Jacobian"),
                   "bdf": ("BDF", "solve_ivp BDF, analytic sparse Jacobian")}
STEADY_PEER = "newton"
DEFAULT_PEER_CAP = 600.0  # s of wall time per transient peer run


def _peer_entry(res: peers.PeerResult, description: str, exact: float,
                reference: float) -> dict:
    """A peer's row of the ``peers`` dict: converged means steady by the run's test (or,
    for the steady peer, Newton's) and on beltsim's steady state within SAME_STATE."""
    same = abs(res.total_friction - reference) <= peers.SAME_STATE * abs(reference)
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
    first (:func:`benchmarks.peers.loosest_tolerance`) instead of the defaults.
    A transient run that does not converge is not repeated.
    """
    out = {}
    for key, (method, description) in TRANSIENT_PEERS.items():
        if not scene.params.inertia:
            out[key] = {"method": description, "wall_time": None, "error": None,
                        "converged": False, "reason": "not applicable: no inertia",
                        "tolerance": None}
            continue
        rtol = peers.DEFAULT_RTOL[method]
        if search:
            log(f"{method}: searching the loosest rtol that reaches the steady state")
            found, _ = peers.loosest_tolerance(lambda: Simulation(scene), method, reference,
                                                 max_wall=peer_cap, log=log)
            rtol = found if found is not None else rtol
            log(f"{method}: rtol {rtol:g}" + ("" if found else " (none of the list did)"))
        runs = []
        for _ in range(repeat):
            runs.append(peers.run_transient_peer(Simulation(scene), method, rtol, peer_cap))
            if not runs[-1].converged:
                break
        res = best_of(runs) if all(r.converged for r in runs) else runs[-1]
        out[key] = entry = _peer_entry(res, description, exact, reference)
        log(f"peer {key:6s} ({description}, rtol {rtol:g}): {res.steps} steps, "
            f"{res.rhs_evaluations} rhs, {res.factorisations} LU, t = "
            f"{res.simulated_time:.4g} s, wall {res.wall_time:.3f} s, error "
            f"{entry['error']:.2e}, {'steady' if entry['converged'] else entry['reason']}")
    res = best_of([peers.run_steady_peer(Simulation(scene)) for _ in range(repeat)])
    description = "Newton, scipy.sparse, line search, continuation in v_reg"
    out[STEADY_PEER] = entry = _peer_entry(res, description, exact, reference)
    log(f"peer {STEADY_PEER:6s} ({description}): {res.steps} iterations, wall "
        f"{res.wall_time:.4f} s, error {entry['error']:.2e}, "
        f"{'converged' if entry['converged'] else entry['reason']}")
    return out


def run_port_entry(scene: Scene, ours, exact: float, repeat: int = 3, log=print) -> dict:
    """The port of the default scheme (:mod:`benchmarks.port`) on ``scene``, against
    ``ours`` (beltsim's RunResult of the same scene): the ``port`` dict of :func:`bench`.

    Converged: steady by the run's test on beltsim's steady state (SAME_STATE); the
    port takes the same steps, so its step count and total friction are reported beside
    ours (``total_friction_vs_ours``: relative difference).
    """
    description = "beltsim's BDF2 scheme ported to numpy and scipy.sparse (splu)"
    try:
        res = port.run_port(scene, repeat)
    except ValueError as exc:  # another scheme, law or loads: no port
        return {"method": description, "wall_time": None, "error": None, "converged": False,
                "reason": f"not applicable: {exc}"}
    total, ref = res.solution.total_friction, ours.solution.total_friction
    diff = abs(total - ref) / abs(ref) if ref != 0.0 else abs(total)
    same = diff <= peers.SAME_STATE
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


def bench(scene: Scene, peer=True, port_run=True, repeat=3, peer_cap=DEFAULT_PEER_CAP,
          search=False, log=print) -> dict:
    """Ours against the generic peers and the port on one grid.

    Keys: those of :func:`beltsim.studies.bench.run_ours`, ``peers`` (see
    :func:`run_peers`), ``peer_*`` and ``speedup`` (the fastest converged transient peer,
    its wall time over ours; None when none converged), ``steady_speedup`` (the steady
    peer's wall time over the steady scheme's), ``port`` and ``kernel_speedup`` (the
    port's wall time over ours), ``explicit_node_steps_per_s``.
    """
    exact = reference_of(scene).total_friction
    out, res, steady = run_ours(scene, repeat, log)
    reference = steady.solution.total_friction
    out.update(peer=None, peer_wall_time=None, peer_error=None, peer_converged=False,
               speedup=None, steady_speedup=None, kernel_speedup=None, peers=None,
               port=None)
    if port_run:
        # the port is of BDF2 ("implicit"): compared with our BDF2 run, same steps
        bdf2, same = scene, res
        if res.numerics.integrator != "implicit":
            bdf2 = scene.with_overrides([("numerics.integrator", "implicit")])
            same = run_ours(bdf2, repeat, log)[1]
        out["port"] = entry = run_port_entry(bdf2, same, exact, repeat, log)
        if entry["converged"]:
            out["kernel_speedup"] = entry["wall_time"] / same.wall_time
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
    return out


def _ratio(x):
    return "n/a" if x is None else f"{x:.3g}x"


def main(argv=None) -> int:
    parser = OneLineParser(prog="python -m benchmarks.bench", description=__doc__
                                     .split("\n\n")[0])
    parser.add_argument("scene", nargs="?", default="paper_slip",
                        help="scene file or shipped scene name (default paper_slip)")
    parser.add_argument("--set", dest="overrides", action="append", default=[],
                        metavar="SECTION.KEY=VALUE", help="override a scene key (repeatable)")
    parser.add_argument("--elements", type=int, default=None, help="numerics.elements")
    parser.add_argument("--repeat", type=int, default=3,
                        help="time each run this many times and keep the shortest")
    parser.add_argument("--peer-cap", type=float, default=DEFAULT_PEER_CAP,
                        help="wall-time cap of one transient peer run, s")
    parser.add_argument("--search-rtol", action="store_true",
                        help="first find each transient peer's loosest rtol on this grid")
    parser.add_argument("--no-peer", action="store_true", help="skip the peers")
    parser.add_argument("--no-port", action="store_true", help="skip the port")
    args = parser.parse_args(argv)
    if args.repeat < 1:
        parser.error(f"--repeat: must be at least 1, got {args.repeat}")
    if not args.peer_cap > 0:
        parser.error(f"--peer-cap: must be positive, got {args.peer_cap}")
    overrides = list(args.overrides)
    if args.elements is not None:
        overrides.append(f"numerics.elements={args.elements}")
    try:
        scene = load_scene(args.scene, overrides)
        result = bench(scene, peer=not args.no_peer, port_run=not args.no_port,
                       repeat=args.repeat, peer_cap=args.peer_cap, search=args.search_rtol)
    except BeltsimError as exc:
        print(f"benchmarks.bench: error: {exc}", file=sys.stderr)
        return 2
    print(bench_json(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
