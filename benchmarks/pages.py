"""The performance page of the documentation, from fresh runs.

``python -m benchmarks.pages [--quick] [--out DIR]`` times beltsim on the paper slip
scene and writes ``timings.md`` with its figure and ``index.md`` into DIR (default
``docs/performance``): the default run and the steady scheme, the explicit kernel's
node-steps per second and a cold start (:func:`beltsim.studies.bench.bench`); the
generic scipy peers and the numpy port of the default scheme (:func:`benchmarks.bench.bench`);
the compile time and the cache load time of the kernels, each in a fresh process; the
default run across grids; and the closed drive against its generic peers
(:mod:`benchmarks.drive`, in a fresh process). Every wall time is the shortest of
``--repeat`` runs with the kernels loaded, compilation apart. ``--quick`` does the same
on a tiny grid, once.

Exit status: 0 when every beltsim run reached its steady state; 1 when one did not or a
measurement failed (the page says which); 2 on a missing input or a bad option.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from validation.pages import stamps
from validation.pages.kit import (
    ROOT,
    Page,
    command_line,
    commit,
    describe_machine,
    fmt,
    log,
    machine_facts,
    num,
    write_index,
)

DEFAULT_OUT = ROOT / "docs" / "performance"
SCENE = "paper_slip"
#: (grid or None for the default, repeats, transient peers' wall cap in s, grid ladder)
MODES = {False: (None, 3, 600.0, (250, 600, 1000, 2000)), True: (40, 1, 60.0, (20, 40, 60))}
#: the steady scheme's grids: the cost of a solve against the grid
STEADY_LADDER = {False: (1000, 10000, 100000), True: (1000, 4000)}
#: the closed drive's bench (benchmarks.drive), by mode: its options
DRIVE_ARGS = {False: [],
              True: ["--elements", "40", "--repeat", "1", "--grids", "3"]}
#: the serpentine drive against its generic peers (benchmarks.drive --peers), by mode
SERPENTINE_ARGS = {
    False: ["serpentine_accessory", "--grids", "", "--no-kernels", "--peers",
            "--peer-cap", "300"],
    True: ["serpentine_accessory", "--elements", "60", "--repeat", "1", "--grids", "",
           "--no-kernels", "--peers", "newton,hybr,bdf2", "--peer-cap", "30"]}
#: the crankshaft's fluctuation (benchmarks.fluctuation), by mode: simulated seconds after
#: the start-up ramp, the laws, and overrides
FLUCTUATION = {False: {"seconds": 1.0, "laws": ("tanh", "exact"), "sets": ()},
               True: {"seconds": 0.02, "laws": ("tanh",),
                      "sets": (("numerics.elements", 120),)}}
#: the modes' benchmark (benchmarks.modes), by mode: repeats; and the issue's target (s)
MODES_REPEAT = {False: 5, True: 1}
MODES_TARGET = 1.0
TITLE = "Timings"
INDEX_INTRO = (
    "How fast beltsim runs, measured by `python -m benchmarks.pages` on the machine its "
    "page names: the default run of the paper slip scene, the steady scheme, the explicit "
    "kernel, compilation and a cold start, against generic scipy peers and a numpy port "
    "of the default scheme; and the closed belt drive's start-up and steady scheme, run by "
    "the same engine as a closed layout, and a second of a crankshaft's speed "
    "fluctuation and the modes of the accessory drive. `python -m benchmarks.pages "
    "--quick` does the same on tiny grids (CI runs it).")

_KERNEL_LOAD = """
import json, sys, time
from beltsim.problem.scene import Scene
from beltsim.simulation.controller import Simulation
sim = Simulation(Scene.loads(sys.stdin.read()))
print(json.dumps({"seconds": sim.warm_up()}))
"""


def kernel_load_time(scene, empty_cache: bool) -> float:
    """Seconds to compile (``empty_cache``) or to load from numba's cache the scene's
    scheme kernels, in a fresh process (the interpreter's start and imports left out)."""
    env = dict(os.environ)
    with tempfile.TemporaryDirectory() as cache:
        if empty_cache:
            env["NUMBA_CACHE_DIR"] = cache
        proc = subprocess.run([sys.executable, "-c", _KERNEL_LOAD], input=scene.to_toml(),
                              env=env, capture_output=True, text=True, timeout=1200,
                              check=False)
    if proc.returncode != 0:
        raise RuntimeError(f"kernel load in a fresh process failed: {proc.stderr.strip()}")
    return float(json.loads(proc.stdout.strip().splitlines()[-1])["seconds"])


def _ours_table(page: Page, res: dict, compile_s: float, load_s: float) -> None:
    page.table(["quantity", "value"], [
        ["elements", str(res["elements"])],
        [f"default run ({res['ours_integrator']}), wall to steady state [s]",
         fmt(res["ours_wall_time"], ".4g")],
        ["default run: steps", str(res["ours_steps"])],
        ["default run: error of the total friction", fmt(res["ours_error"], ".2e")],
        ["steady scheme, wall [s]", fmt(res["ours_steady_wall_time"], ".4g")],
        ["steady scheme: error of the total friction", fmt(res["ours_steady_error"], ".2e")],
        ["explicit kernel [node-steps/s]", fmt(res["explicit_node_steps_per_s"], ".3g")],
        ["compile the default scheme's kernels, empty cache [s]",
         fmt(compile_s, ".3g") if compile_s is not None else "not measured"],
        ["load them from numba's cache [s]", fmt(load_s, ".3g")],
        ["`import beltsim` in a fresh interpreter [s]", fmt(res["import_time"], ".3g")],
        [("warm run: `beltsim run` in a fresh process with the kernels cached, to steady "
          "state, end to end [s]"), fmt(res["warm_run_time"], ".3g")],
        [("cold start: `beltsim run` in a fresh process with an empty cache, to steady "
          "state [s]"), fmt(res["cold_start_time"], ".3g") if res["cold_start_time"] is not None
         else "not measured"]])


def _peers_table(page: Page, lab: dict) -> None:
    rows = [[f"beltsim, {lab['ours_integrator']} (default)", fmt(lab["ours_wall_time"], ".4g"),
             fmt(lab["ours_error"], ".2e"), str(lab["ours_steps"]), "", "yes", ""],
            ["beltsim, steady scheme", fmt(lab["ours_steady_wall_time"], ".4g"),
             fmt(lab["ours_steady_error"], ".2e"), "", "", "yes", ""]]
    port = lab.get("port")
    if port:
        if not port["converged"] and not str(port["reason"]).startswith("not applicable"):
            page.fail(f"numpy port: {port['reason']}")
        rows.append([port["method"], fmt(port["wall_time"], ".4g"), fmt(port["error"], ".2e"),
                     str(port.get("steps", "")), "", "yes" if port["converged"] else "no",
                     fmt(lab.get("kernel_speedup"), ".3g")])
    for key, p in (lab.get("peers") or {}).items():
        speed = None
        if p["converged"] and p["wall_time"]:
            base = lab["ours_steady_wall_time"] if key == "newton" else lab["ours_wall_time"]
            speed = p["wall_time"] / base
        rows.append([p["method"], fmt(p["wall_time"], ".4g"), fmt(p["error"], ".2e"),
                     str(p.get("steps", "")),
                     num(p["tolerance"]) if p.get("tolerance") is not None else "",
                     "yes" if p["converged"] else f"no: {p['reason']}", fmt(speed, ".3g")])
    page.table(["method", "wall [s]", "error of the total friction", "steps",
                "rtol (Newton: tol)", "reached beltsim's steady state",
                "its wall over beltsim's"], rows)


def _grid_section(page: Page, ladder, repeat: int) -> list[dict]:
    from beltsim.api import shipped_scene
    from beltsim.studies.bench import run_ours

    rows = []
    for n in ladder:
        out, res, steady = run_ours(shipped_scene(SCENE, [f"numerics.elements={n}"]),
                                    repeat, log=lambda *_: None)
        if not (res.converged and steady.converged):
            page.fail(f"{n} elements: {res.reason or steady.reason}")
        rows.append({"elements": n, "wall": out["ours_wall_time"], "steps": out["ours_steps"],
                     "newton": res.newton_iterations, "error": out["ours_error"],
                     "steady": out["ours_steady_wall_time"],
                     "steady_error": out["ours_steady_error"]})
    page.table(["elements", "default run, wall [s]", "steps", "Newton iterations",
                "error", "steady scheme, wall [s]", "error"],
               [[str(r["elements"]), fmt(r["wall"], ".4g"), str(r["steps"]), str(r["newton"]),
                 fmt(r["error"], ".2e"), fmt(r["steady"], ".3g"), fmt(r["steady_error"], ".2e")]
                for r in rows])
    return rows


def _figure(page: Page, rows) -> None:
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.2), constrained_layout=True)
    for key, label, style in (("wall", "default run (implicit)", "o-"),
                              ("steady", "steady scheme", "^-")):
        ax.loglog([r[key] for r in rows], [r["error" if key == "wall" else "steady_error"]
                                           for r in rows], style, label=label)
        for r in rows:
            ax.annotate(str(r["elements"]), (r[key], r["error" if key == "wall"
                                                      else "steady_error"]),
                        textcoords="offset points", xytext=(4, 4), fontsize=7)
    ax.set_xlabel("wall time [s] (shortest of the repeats, compilation excluded)")
    ax.set_ylabel("relative error of the total friction")
    ax.set_title(f"{SCENE}: error against wall time (labels: elements)", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    page.figure(fig, "grids", f"{SCENE}: error of the total friction against wall time, "
                              f"default run and steady scheme, across grids")


def build(page: Page, quick: bool, cold: bool = True) -> None:
    from beltsim.api import shipped_scene
    from beltsim.studies import bench as ours_bench

    from . import bench as lab_bench

    elements, repeat, cap, ladder = MODES[quick]
    scene = shipped_scene(SCENE, [f"numerics.elements={elements}"] if elements else [])
    grid = f"{elements} elements" if elements else "the default grid"
    page.para(
        f"beltsim on the paper slip scene (`{SCENE}`, {grid}). Wall times are the shortest "
        f"of {repeat} {'run' if repeat == 1 else 'runs'} in one process with the numba "
        f"kernels loaded; compiling and loading the kernels are measured apart, each in a "
        f"fresh process. The machine is shared (its load at the start is given above), so "
        f"the shortest of the repeats is the figure to read.")
    page.heading("beltsim")
    el = f" --elements {elements}" if elements else ""
    page.para(f"`beltsim bench{el} --repeat {repeat}{'' if cold else ' --no-cold'}`: the "
              f"default run from rest to steady state, the steady scheme, the explicit "
              f"kernel alone in a settled state, the import, a warm run end to end and a "
              f"cold start.")
    compile_s = kernel_load_time(scene, empty_cache=True) if cold else None
    load_s = kernel_load_time(scene, empty_cache=False)
    res = ours_bench.bench(scene, cold=cold, repeat=repeat, log=log)
    if not cold:
        page.para("Run with `--no-cold`: the compile time and the cold start were not "
                  "measured.")
    if not res["ours_converged"]:
        page.fail("the default run did not reach its steady state")
    _ours_table(page, res, compile_s, load_s)
    page.heading("Against generic peers and a numpy port")
    page.para(
        f"`python -m benchmarks.bench {SCENE}{el} --repeat {repeat} --peer-cap {cap:g}`: "
        f"what a skilled scipy user would write instead, on the same grid and the same "
        f"semi-discretisation: `solve_ivp`'s Radau and BDF with the analytic sparse "
        f"Jacobian from rest to the run's steady test (a run is capped at {cap:g} s), and a "
        f"sparse Newton iteration on the steady equations; and beltsim's BDF2 scheme "
        f"(`implicit`) ported to numpy and scipy.sparse, taking the same steps as beltsim's "
        f"BDF2 run, whose wall time over that run's is what the compiled kernels buy. A "
        f"peer counts only if it reaches beltsim's steady state (total friction within "
        f"1e-5).")
    lab = lab_bench.bench(scene, peer=True, port_run=True, repeat=repeat, peer_cap=cap, log=log)
    _peers_table(page, lab)
    page.heading("Across grids")
    page.para(f"The default run and the steady scheme on {', '.join(map(str, ladder))} "
              f"elements (`beltsim bench --elements N --repeat {repeat}`), each the "
              f"shortest of {repeat}.")
    rows = _grid_section(page, ladder, repeat)
    _figure(page, rows)
    same = [res["ours_wall_time"], lab["ours_wall_time"]] + [
        r["wall"] for r in rows if r["elements"] == res["elements"]]
    if len(same) > 1:
        page.para(f"The default run on {res['elements']} elements is timed {len(same)} times "
                  f"on this page, once by each command: {min(same):.3g} to {max(same):.3g} "
                  f"s. Their spread is the machine's, not beltsim's.")
    _steady_section(page, quick, repeat)
    _drive_section(page, quick, cold)
    _serpentine_section(page, quick)
    _fluctuation_section(page, quick)
    _modes_section(page, quick)
    page.para(f"Load average at the end of the run: {os.getloadavg()[0]:.2f} (at the start: "
              f"see the top of the page); on this machine {os.cpu_count()} cores.")


def _steady_section(page: Page, quick: bool, repeat: int) -> None:
    from beltsim.api import shipped_scene
    from beltsim.simulation.controller import run
    from beltsim.simulation.result import reference_of
    from beltsim.simulation.solution import relative_error

    ladder = STEADY_LADDER[quick]
    page.heading("The steady scheme against the grid")
    page.para(
        f"`beltsim run {SCENE} --set numerics.integrator=steady --set numerics.elements=N"
        f" [--set numerics.friction_law=exact]`, the shortest of {repeat}: grids finer than "
        "four times the default start from the steady state of a grid four times coarser "
        "(grid sequencing), so the continuation stages stay at the coarsest grid's and "
        "Newton takes a few iterations on each finer one (per grid, coarsest first). "
        "Error: the total friction against the exact solution.")
    rows = []
    for law in ("tanh", "exact"):
        for n in ladder:
            over = [("numerics.integrator", "steady"), ("numerics.elements", n)]
            if law == "exact":
                over.append(("numerics.friction_law", "exact"))
            scene = shipped_scene(SCENE, over)
            res = min((run(scene, raise_on_failure=False) for _ in range(repeat)),
                      key=lambda r: r.wall_time)
            if not res.converged:
                page.fail(f"steady, {law}, {n} elements: {res.reason}")
                rows.append([law, str(n), "**failed**", "", "", ""])
                continue
            err = relative_error(res.solution.total_friction,
                                 reference_of(scene).total_friction)
            its = res.statistics.get("grid_iterations", [])
            rows.append([law, str(n), fmt(res.wall_time, ".3g"), str(res.steps),
                         " + ".join(map(str, its)), f"{err:.2e}"])
    page.table(["friction law", "elements", "wall [s]", "continuation stages",
                "Newton iterations per grid", "total friction error"], rows)


def run_drive_bench(args) -> dict:
    """``python -m benchmarks.drive ARGS`` in a fresh process with one BLAS thread (as the
    script runs itself, see its docstring): its dict."""
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "drive.json"
        proc = subprocess.run([sys.executable, "-m", "benchmarks.drive", *args, "--json",
                               str(out)], cwd=ROOT, env=env, capture_output=True, text=True,
                              timeout=7200, check=False)
        if proc.returncode != 0:
            raise RuntimeError(f"benchmarks.drive failed: {proc.stderr.strip()[-500:]}")
        for line in proc.stdout.splitlines()[:-1]:
            log(line)
        return json.loads(out.read_text(encoding="utf-8"))


def _drive_section(page: Page, quick: bool, cold: bool) -> None:
    args = DRIVE_ARGS[quick] + ([] if cold else ["--no-kernels"])
    page.heading("The closed belt drive")
    page.para(
        f"`python -m benchmarks.drive {' '.join(args)}`".replace(" `", "`") + ": the shipped "
        "`drive_flat` scene, a closed layout of the one engine, from rest to steady state "
        "(`beltsim.run`, the default scheme esdirk3, exact Coulomb friction) and its steady "
        "scheme, on the scene's grid and on finer ones. Wall times are the shortest of the "
        "repeats: of the whole call, and of the solve (a run's own wall time). Compiling "
        "and loading the kernels are timed apart in fresh processes. The start-up follows "
        "the drive's rotational mode (about 88 Hz, lightly damped) to the time tolerance, "
        "which is what its steps pay for.")
    d = run_drive_bench(args)
    su = d["start_up"]
    if not su["converged"]:
        page.fail(f"the drive's default run: {su['status']} ({su['reason']})")
    k = d.get("kernels") or {}
    rows = [["compile the kernels, empty cache [s]",
             fmt(k.get("compile_s"), ".3g") or "not measured"],
            ["load them from numba's cache [s]", fmt(k.get("load_s"), ".3g") or "not measured"],
            [f"start-up, {su['elements']} elements: wall to steady state, call [s]",
             fmt(su["wall_time"], ".4g")],
            ["start-up: wall of the solve [s]", fmt(su["solve_wall_time"], ".4g")],
            ["start-up: steps, Newton iterations", f"{su['steps']}, {su['newton_iterations']}"],
            ["start-up: simulated time [s]", fmt(su["simulated_time"], ".4g")],
            ["start-up: largest relative difference from the steady scheme's state",
             fmt(su.get("difference"), ".2e")]]
    page.table(["quantity", "value"], rows)
    steady_rows = []
    for st, it in zip(d["steady"], d["iteration"]):
        if st.get("failed"):
            page.fail(f"steady scheme, {st['elements']} elements: {st['failed']}")
        steady_rows.append([
            str(st["elements"]), str(st["unknowns"]), fmt(st["wall_time"], ".4g"),
            fmt(st.get("solve_wall_time"), ".4g"), str(st.get("newton_iterations", "")),
            " + ".join(map(str, st.get("grid_iterations") or [])),
            fmt(1e3 * it["residual_jacobian_s"], ".3g"), fmt(1e3 * it["linear_solve_s"], ".3g"),
            fmt(1e3 * it["start_s"], ".3g")])
    page.table(["elements", "unknowns", "steady scheme, call [s]", "solve [s]",
                "Newton iterations", "by grid", "residual + Jacobian [ms]",
                "bordered factorisation and solve [ms]", "the creep theory's start [ms]"],
               steady_rows)


def _serpentine_section(page: Page, quick: bool) -> None:
    args = SERPENTINE_ARGS[quick]
    page.heading("The serpentine drive against generic peers")
    page.para(
        f"`python -m benchmarks.drive {' '.join(a or repr(a) for a in args)}`: the shipped "
        "seven-pulley `serpentine_accessory` drive (exact Coulomb friction), our steady "
        "scheme and our default run from rest against generic peers that solve the same "
        "discrete equations, the numpy reference of the kernel's residual "
        "(`physics.reference.loop_residual`), on the same grid (`benchmarks.drive_peers`): "
        "Newton with a finite-difference Jacobian on the stencil's sparsity (columns "
        "grouped) and spsolve, and scipy.optimize.root, from our steady scheme's start "
        "(the creep theory's state); variable-step BDF2 from rest with the same Jacobian, "
        "splu and our run's steady test. The exact law's ratios take the usual projection "
        "function lam - proj(lam + v_rel / v_aug) as their equations. A peer counts only "
        "if it reaches our state (span tensions and speeds within 1e-8 of our steady "
        "state's, the start-up's within 1e-6); each is stopped at its cap. Ratios: the "
        "peer's wall over our solve's.")
    d = run_drive_bench(args)
    pe = d["peers"]
    st, su = d["steady"][0], d["start_up"]
    if not su["converged"]:
        page.fail(f"the serpentine drive's default run: {su['status']} ({su['reason']})")
    rows = [["ours: steady scheme", "", fmt(st["wall_time"], ".4g"),
             fmt(st["solve_wall_time"], ".4g"), "yes", "", "1"],
            [f"ours: start-up ({su['integrator']}, {su['steps']} steps)", "",
             fmt(su["wall_time"], ".4g"), fmt(su["solve_wall_time"], ".4g"),
             "yes" if su["converged"] else "no", fmt(su.get("difference"), ".2e"), "1"]]
    for r in pe["rows"]:
        why = "yes" if r["reached"] else (
            f"no: {r['reason']}" if not r["converged"]
            else f"no: {fmt(r['difference'], '.1e')} > {r['tolerance']:g}")
        rows.append([r["name"], r["against"], fmt(r["wall_time"], ".4g"), "", why,
                     fmt(r["difference"], ".2e"),
                     ("" if r["reached"] else ">= ") + fmt(r["ratio"], ".3g")])
    page.table(["method", "against", "call [s]", "solve [s]", "reached our state",
                "largest relative difference", "its wall over our solve"], rows)
    reached = [r for r in pe["rows"] if r["reached"]]
    for label, key in (("steady", "steady scheme"), ("start-up", "start-up (default run)")):
        best = min((r["ratio"] for r in reached if r["against"] == key), default=None)
        page.para(f"{pe['elements']} elements; {label}: the fastest peer that reached our "
                  f"state took {fmt(best, '.3g') + ' times' if best else 'none reached it:'}"
                  f" our solve's wall.")


def _fluctuation_section(page: Page, quick: bool) -> None:
    from beltsim.api import shipped_scene

    from . import fluctuation

    cfg = FLUCTUATION[quick]
    page.heading("A fluctuating crankshaft")
    page.para(
        f"`python -m benchmarks.fluctuation serpentine_accessory --seconds "
        f"{cfg['seconds']:g}` (its functions, called here): the shipped accessory drive "
        f"from rest with the crankshaft's speed a sine (its speed +- "
        f"{fluctuation.AMPLITUDE:g} rad/s at {fluctuation.FREQUENCY:g} Hz) through its "
        f"start-up ramp and {cfg['seconds']:g} simulated second(s) more, by the default "
        f"scheme (esdirk3) under each friction law; the wall time, steps and Newton "
        f"iterations of the time after the ramp, and the periodic tracker's amplitude of "
        f"the first span's tension over the last period.")
    out = fluctuation.bench(shipped_scene("serpentine_accessory"), laws=cfg["laws"],
                            seconds=cfg["seconds"], sets=cfg["sets"])
    rows = []
    for r in out["runs"]:
        span = next((k for k in r["amplitudes"] if k.startswith("tension[")), None)
        rows.append([r["law"], r["elements"], fmt(r["wall_time"], ".3g"),
                     fmt(r["wall_per_second"], ".3g"), r["steps"], r["rejected_steps"],
                     fmt(r["newton_per_step"], ".3g"),
                     f"{span}: {r['amplitudes'][span]:.6g} N" if span else ""])
    page.table(["law", "elements", "wall [s]", "wall per simulated second [s]", "steps",
                "rejected", "Newton iterations a step", "tension amplitude"], rows)


def _modes_section(page: Page, quick: bool) -> None:
    from . import modes

    repeat = MODES_REPEAT[quick]
    page.heading("A drive's modes")
    page.para(
        f"`python -m benchmarks.modes serpentine_accessory --repeat {repeat}` (its "
        "functions, called here): the accessory drive's rotational modes, numba's cache "
        "warm, each the shortest of its repeats: the call `beltsim.modes(scene)` with the "
        "kernels loaded (the steady solve, the linearisation, the shift-invert sweep of "
        "the band for the least stable eigenvalue and the listing of the lowest modes); "
        "`beltsim modes serpentine_accessory --out DIR` end to end in a fresh process, "
        "which adds the interpreter, the imports and the kernels' load from the cache; "
        "and those imports alone (beltsim's CLI, numpy, scipy.sparse.linalg, numba). "
        f"The target: {MODES_TARGET:g} s.")
    out = modes.bench("serpentine_accessory", repeat)
    page.table(["quantity", "value"], [
        ["grid: elements, method, eigenvalues found, modes listed",
         f"{out['elements']}, {out['method']}, {out['eigenvalues']}, {out['modes']}"],
        ["call, kernels loaded [s]", fmt(out["call"], ".3g")],
        ["command in a fresh process [s]", fmt(out["command"], ".3g")],
        ["its imports [s]", fmt(out["imports"], ".3g")]])
    for what in ("call", "command"):
        verdict = "met" if out[what] <= MODES_TARGET else "not met on this machine"
        page.para(f"The {what}: {out[what]:.3g} s against {MODES_TARGET:g} s, {verdict}.")


def main(argv=None) -> int:
    from beltsim.cli import OneLineParser
    from beltsim.errors import MissingInputError

    argv = list(sys.argv[1:] if argv is None else argv)
    parser = OneLineParser(prog="python -m benchmarks.pages",
                           description="Write the performance page from fresh runs.")
    parser.add_argument("--quick", action="store_true", help="a tiny grid, once (for CI)")
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT,
                        help="output directory (default docs/performance)")
    parser.add_argument("--no-cold", action="store_true",
                        help="skip the measurements with an empty numba cache (compile "
                             "time, cold start)")
    args = parser.parse_args(argv)

    import matplotlib
    matplotlib.use("Agg")  # a script's figures go to files: no display

    command = command_line("benchmarks.pages", argv)
    sha = commit()
    page = Page("timings", TITLE, command, sha, args.out, describe_machine(machine_facts()),
                source_hash=stamps.page_hash("performance/timings.md"))
    start = time.perf_counter()
    status = 0
    try:
        build(page, args.quick, cold=not args.no_cold)
    except MissingInputError as exc:
        page.abort(f"missing input: {exc}", missing_input=True)
    except Exception as exc:  # noqa: BLE001  a failed measurement is reported, not hidden
        page.abort(f"{type(exc).__name__}: {exc}")
    path = page.write()
    if page.aborted is not None:
        log(f"timings: FAILED ({page.aborted})")
        status = 2 if page.missing_input else 1
    elif page.failures:
        for f in page.failures:
            log(f"  failed: {f}")
        status = 1
    index = write_index(args.out, "Performance", INDEX_INTRO, ["timings"], command, sha)
    log(f"wrote {path} and {index} in {time.perf_counter() - start:.0f} s, exit status "
        f"{status}")
    return status


if __name__ == "__main__":
    sys.exit(main())
