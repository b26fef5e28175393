"""Random scenes across the whole parameter space, each by every applicable scheme.

`python -m validation.random_scenes N --seed S` draws N valid scenes and runs each with every
registered scheme at its default grid. A cell is judged exactly as in the stability
matrix (:func:`beltsim.studies.stability.stability_cell`, its statuses, ACCEPTED and
BOUNDS): each drawn scene is the base of a :class:`~beltsim.studies.stability.Case`, so
nothing of the matrix's logic is copied. Only the slip start's bound, in metres, is
scaled to the scene's grid (:func:`scene_bounds`).

Scene i of seed S is drawn from its own generator ``default_rng([S, i])``: the same seed
draws the same scenes whatever N, and a failure is reproduced from (S, i) alone.

What is drawn (log-uniform unless said otherwise):

* geometry: length 0.1 .. 50 m, slenderness L / h 3 .. 300, width / h 0.2 .. 10, and
  the inlet, contact and outlet spans as weights 0.02 .. 1 (so each is at least 1% of L);
* materials: E 1e5 .. 1e11 Pa, density 300 .. 8000 kg/m^3, poisson_ratio uniform over
  (-1, 0.5), shear_factor 0.4 .. 1.5;
* speed: c = r c_low with c_low the lower critical speed of the beam (with inertia; a
  quasistatic scene has none, and its c only scales time) and r 1e-3 .. 0.95 for half
  the scenes, uniform 0.5 .. 0.95 for the other half (the near-critical band, where the
  effective bending stiffness a - I c^2 is small);
* mismatch: v = c (1 + s e), s = +-1, e 1e-6 .. 0.05;
* friction: stick or coulomb (half each); f* = R B |e0| / (x2 - x1), R 0.1 .. 1e4: the
  contact can carry about B |e0| in stick, so R below about 1 makes it slide whole;
* inertia on for half the scenes; physics.damping 0 for half of the inertial ones, else
  2 zeta omega with zeta 0.5% .. 5% of critical in the axial mode of a free span
  omega = 3 pi B / (L sqrt(rho b1)) (as the shipped scenes state it).

The default grid follows the scene (settings.default_elements), so slender belts and
poisson_ratio near -1 (a stiff shear, a thin boundary layer) get fine grids: the explicit
scheme is then refused above numerics.max_work, which is an accepted outcome.
"""

from __future__ import annotations

import math
import time
from collections import Counter

import numpy as np

from beltsim import solvers
from beltsim.api import is_drive_scene
from beltsim.errors import BeltsimError
from beltsim.problem.scene import Scene
from beltsim.simulation.result import RunStatus
from beltsim.studies.convergence import error_keys
from beltsim.studies.stability import (
    ACCEPTED,
    BOUNDS,
    DRIVE_BOUNDS,
    Case,
    CellStatus,
    error_columns,
    stability_cell,
)
from validation.random_drives import draw_drive

SKIPPED = "skipped"  # not started: the run's --max-wall was spent
CRASHED = "crashed"  # an exception that is not one of beltsim's own errors (a bug)
#: The slip start's bound in mean element lengths L / N (:func:`scene_bounds`)
SLIP_START_ELEMENTS = 5.0
#: Columns of random.csv before the errors (the layout's) and the reason.
COLUMNS = ("index", "scheme", "status", "reason_key", "friction", "inertia", "damping",
           "mismatch", "speed_ratio", "elements", "dt", "steps", "wall_time", "elapsed")
TEXT_COLUMNS = {"index", "scheme", "status", "reason_key", "friction", "inertia", "elements",
                "steps", "reason"}
INTERRUPTED = "interrupted (SIGINT)"  # the reason of cells skipped after a Ctrl-C


def _log_uniform(rng, lo, hi):
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


def _sig(x, digits=4):
    """A readable scene file: inputs rounded to a few digits (they are drawn, not measured)."""
    return float(f"{x:.{digits - 1}e}")


def draw_scene(seed: int, index: int) -> Scene:
    """Scene `index` of `seed`: valid by construction (Scene validates it)."""
    rng = np.random.default_rng([seed, index])
    L = _sig(_log_uniform(rng, 0.1, 50.0))
    h = _sig(L / _log_uniform(rng, 3.0, 300.0))
    w = _sig(h * _log_uniform(rng, 0.2, 10.0))
    spans = np.array([_log_uniform(rng, 0.02, 1.0) for _ in range(3)])
    x1, x2 = L * np.cumsum(spans / spans.sum())[:2]
    x1, x2 = _sig(x1, 6), _sig(x2, 6)
    E = _sig(_log_uniform(rng, 1e5, 1e11))
    nu = 0.0
    while True:  # the open interval (-1, 0.5): uniform() may return its lower end
        nu = _sig(rng.uniform(-1.0, 0.5))
        if -1.0 < nu < 0.5:
            break
    density = _sig(_log_uniform(rng, 300.0, 8000.0))
    k = _sig(_log_uniform(rng, 0.4, 1.5))
    inertia = bool(rng.random() < 0.5)
    b1, a = E * w * h, E * w * h**3 / 12.0
    rho, rot = density * h * w, density * h * w * (h * h + w * w) / 12.0
    c_low = min(math.sqrt(b1 / rho), math.sqrt(a / rot))
    r = (_log_uniform(rng, 1e-3, 0.95) if rng.random() < 0.5 else rng.uniform(0.5, 0.95))
    c = _sig(r * c_low, 6)
    e = _log_uniform(rng, 1e-6, 0.05) * (1.0 if rng.random() < 0.5 else -1.0)
    v = c * (1.0 + e)  # full precision: |e| reaches 1e-6
    B = b1 - (rho * c * c if inertia else 0.0)
    friction = "stick" if rng.random() < 0.5 else "coulomb"
    ratio = _log_uniform(rng, 0.1, 1e4)
    damped = inertia and rng.random() < 0.5
    zeta = _log_uniform(rng, 0.005, 0.05)
    omega = 3.0 * math.pi * B / (L * math.sqrt(rho * b1))
    data = {
        "title": f"random scene {index} (seed {seed})",
        "beam": {"length": L, "height": h, "width": w, "youngs_modulus": E,
                 "poisson_ratio": nu, "density": density, "shear_factor": k},
        "motion": {"belt_speed": c, "surface_speed": v},
        "contact": {"start": x1, "end": x2, "friction": friction},
        "physics": {"inertia": inertia,
                    "damping": _sig(2.0 * zeta * omega) if damped else 0.0},
    }
    if friction == "coulomb":
        data["contact"]["max_friction"] = _sig(ratio * B * abs(v / c - 1.0) / (x2 - x1))
    return Scene.from_dict(data)


def draw_scenes(n: int, seed: int, drives: bool = False) -> list:
    """Scenes (or, ``drives``, closed drives: :func:`validation.random_drives.draw_drive`)
    0 .. n - 1 of ``seed``."""
    draw = draw_drive if drives else draw_scene
    return [draw(seed, i) for i in range(n)]


def _no_errors(scene) -> dict:
    """The error columns of the scene's layout, all nan (a cell that did not run)."""
    return {f"error_{k}": math.nan for k in error_keys(scene)}


def scene_case(scene: Scene) -> Case:
    """The drawn scene as a stability case, named by its title."""
    return Case(scene.title, scene)


def failed(row) -> bool:
    return row["status"] not in ACCEPTED and row["status"] != SKIPPED


#: An undamped inertial scene runs a time-accurate scheme for the drive's settle time plus
#: this many transits L / c, not the default 400: only friction dissipates, and the long
#: runs that cost most of a random study (up to 1000 s a cell) end ringing anyway. A run
#: still ringing there is judged by the eigenvalues of its steady state (stability_cell):
#: bounded if stable, "unstable steady state" if a mode grows.
RINGING_TRANSITS = 50


def ringing_span(scene: Scene, scheme: str, extra=()) -> list[tuple[str, float]]:
    """The overrides that shorten an undamped scene's time-accurate run (RINGING_TRANSITS),
    with the explicit scheme's max_work scaled alike, so that it refuses the cells it
    would refuse over the default span."""
    from beltsim.solvers.settings import DEFAULT_MAX_WORK, resolve

    P = scene.params
    if (is_drive_scene(scene) or not (P.inertia and P.damping == 0.0
                                      and solvers.get(scheme).time_accurate)):
        return []
    try:
        num = resolve(scene.with_overrides(list(extra)))
    except BeltsimError:  # stability_cell refuses the scene with this error
        return []
    t_end = num.settle_time + RINGING_TRANSITS * P.L / P.c
    if not t_end < num.t_end:
        return []
    out = [("numerics.t_end", t_end)]
    if scheme == "explicit":
        # max_work is the explicit scheme's key: the scene takes it with that scheme set
        out += [("numerics.integrator", scheme),
                ("numerics.max_work", DEFAULT_MAX_WORK * t_end / num.t_end)]
    return out


def random_cell(scene: Scene, index: int, scheme: str, extra=()) -> dict:
    """One scene by one scheme, judged by the stability matrix's rules, on the bounds of
    its grid (:func:`scene_bounds`)."""
    start = time.perf_counter()
    info = describe(scene, extra)
    try:
        cell = stability_cell(scene_case(scene), scheme,
                              extra=[*extra, *ringing_span(scene, scheme, extra)],
                              bounds=scene_bounds(scene, info["elements"]))
    except Exception as exc:  # noqa: BLE001  a crash is a finding, the rest must still run
        cell = {"scheme": scheme, "status": CRASHED,
                "reason": f"{type(exc).__name__}: {exc}".replace("\n", " "),
                "reason_key": type(exc).__name__, "dt": math.nan, "steps": 0,
                "wall_time": math.nan, **_no_errors(scene)}
    P = scene.params
    if (cell["status"] is CellStatus.NOT_CONVERGED and P.inertia and P.damping == 0.0
            and cell["reason_key"] == RunStatus.REACHED_END.value):
        # undamped, only friction dissipates: ringing on at t_end is the physics (a
        # time-accurate run says so), judged like the matrix's span cases: it stayed
        # finite and bounded throughout (the divergence guard would have stopped it)
        cell.update(status=CellStatus.BOUNDED, reason_key="",
                    reason="undamped, still ringing: " + cell["reason"])
    status = getattr(cell["status"], "value", cell["status"])
    return {"index": index, **cell, "status": status, **info,
            "elapsed": time.perf_counter() - start}


def scene_bounds(scene: Scene, elements: int) -> dict:
    """stability.BOUNDS with the slip start's (in metres) scaled to the grid (a drive:
    stability.DRIVE_BOUNDS).

    The paper's 5 mm on 1000 elements over 1 m are SLIP_START_ELEMENTS mean element
    lengths: the slip start's error is a fraction of an element, so on a long belt a
    bound in metres fails however well the grid resolves the scene. The relative bounds
    stay: they hold on the default grid, which resolves each scene's shortest decay
    length as it does the paper's.
    """
    if is_drive_scene(scene):
        return dict(DRIVE_BOUNDS)
    out = dict(BOUNDS)
    out["slip_start"] = SLIP_START_ELEMENTS * scene.params.L / elements
    return out


def describe(scene: Scene, extra=()) -> dict:
    """What a failure is usually about: friction, inertia, damping, v/c - 1, c / c_low
    (0 without inertia) and the grid; a drive's speed ratio is rho c^2 / N0 (its
    mismatch nan)."""
    P = scene.params
    if is_drive_scene(scene):
        from beltsim.solvers.settings import LOOP_ELEMENTS

        rim = P.omega1 * P.geometry.R1
        return {"friction": P.friction, "inertia": int(P.inertia), "damping": P.damping,
                "mismatch": math.nan, "speed_ratio": P.rho * rim * rim / P.N0,
                "elements": dict(extra).get("numerics.elements", scene.numerics.get(
                    "elements", LOOP_ELEMENTS))}
    return {"friction": P.friction, "inertia": int(P.inertia), "damping": P.damping,
            "mismatch": P.e0, "speed_ratio": P.c / min(P.critical_speeds),
            "elements": _elements(scene, extra)}


def _elements(scene, extra) -> int:
    from beltsim.solvers.settings import default_elements
    return dict(extra).get("numerics.elements",
                           scene.numerics.get("elements", default_elements(scene.params)))


#: Schemes that run in a second pass, on the scenes the first reached: a fixed step costs
#: up to numerics.max_work node-steps (minutes) a cell, and run first they would spend a
#: --max-wall on a few scenes and leave the rest untried by every scheme. The first pass
#: stops at FIRST_PASS_SHARE of --max-wall, so the second has a share too.
DEFERRED = ("explicit",)
FIRST_PASS_SHARE = 0.5


def random_study(n: int, seed: int, schemes=None, extra=(), max_wall=None, progress=None,
                 on_failure=None, jobs: int = 1, drives: bool = False) -> list[dict]:
    """Every drawn scene by every registered scheme, one row per cell in scene order.

    The schemes of DEFERRED run in a second pass over the scenes the first pass reached.
    Cells not started within max_wall seconds are `skipped`, and so are the cell under way
    and the rest after a Ctrl-C (reason INTERRUPTED), so that what ran is still reported.
    on_failure(scene, rows) is called at each failed cell with the scene's rows so far.
    With jobs > 1 the cells run in a pool of that many processes (:func:`_parallel_study`):
    the same cells, rows and callbacks in the same order, only the wall times differ.
    ``drives``: closed drives (:func:`validation.random_drives.draw_drive`) instead of
    straight belts.
    """
    if jobs > 1:
        return _parallel_study(n, seed, schemes, extra, max_wall, progress, on_failure, jobs,
                               drives)
    start, stop = time.perf_counter(), ""
    schemes = tuple(schemes or solvers.names())
    scenes = draw_scenes(n, seed, drives)
    done: dict[tuple[int, str], dict] = {}
    first = [s for s in schemes if s not in DEFERRED]
    second = [s for s in schemes if s in DEFERRED]
    reached = n
    for group, share in ((first, FIRST_PASS_SHARE if second else 1.0), (second, 1.0)):
        if stop != INTERRUPTED:
            stop = ""
        for i, scene in enumerate(scenes):
            for scheme in group:
                stop, reached = _wall_stop(stop, reached, start, max_wall, share, group,
                                           first, i, scheme)
                if not stop:
                    try:
                        row = random_cell(scene, i, scheme, extra)
                    except KeyboardInterrupt:
                        stop = INTERRUPTED
                if stop:
                    row = _skipped(scene, i, scheme, stop, extra)
                done[i, scheme] = row
                if progress:
                    progress(row)
                if on_failure and failed(row):
                    on_failure(scene, [done[i, s] for s in schemes if (i, s) in done])
    return [done[i, s] for i in range(n) for s in schemes]


def _wall_stop(stop, reached, start, max_wall, share, group, first, i, scheme):
    """(stop, reached) before cell (i, scheme) of a pass: the pass's share of max_wall
    spent, or the scene not reached by the first pass (the second runs on the scenes
    the first began)."""
    spent = time.perf_counter() - start
    if max_wall is not None and spent > share * max_wall and not stop:
        stop = f"--max-wall {max_wall:g} s: {share * max_wall:g} s spent"
        if group is first:
            reached = i if scheme == group[0] else i + 1
    if i >= reached and not stop:
        stop = f"--max-wall {max_wall:g} s: scene not reached by {first[0]} ..."
    return stop, reached


def _skipped(scene, i, scheme, reason, extra) -> dict:
    return {"index": i, "scheme": scheme, "status": SKIPPED, "reason": reason,
            "reason_key": "", **describe(scene, extra), "dt": math.nan, "steps": 0,
            "wall_time": math.nan, "elapsed": 0.0, **_no_errors(scene)}


def _cell_task(seed, i, scheme, extra, drives):
    """One cell in a worker process (the scene is drawn there: only numbers travel)."""
    return random_cell((draw_drive if drives else draw_scene)(seed, i), i, scheme, extra)


def _parallel_study(n, seed, schemes, extra, max_wall, progress, on_failure, jobs, drives):
    """random_study on a pool of `jobs` processes, with its rules: cells are started in
    scene order, at most `jobs` at a time, and none after the pass's share of max_wall
    (the second pass runs on the scenes whose first cell the first pass started); rows,
    progress and on_failure come in scene order, as each cell and all before it are done."""
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

    start = time.perf_counter()
    schemes = tuple(schemes or solvers.names())
    scenes = draw_scenes(n, seed, drives)
    first = [s for s in schemes if s not in DEFERRED]
    second = [s for s in schemes if s in DEFERRED]
    done: dict[tuple[int, str], dict] = {}
    reached, interrupted = n, False
    pool = ProcessPoolExecutor(max_workers=jobs)
    try:
        for group, share in ((first, FIRST_PASS_SHARE if second else 1.0), (second, 1.0)):
            tasks = [(i, s) for i in range(n) for s in group]
            running: dict = {}  # future -> task
            results: dict[tuple[int, str], dict] = {}
            k_next = k_emit = 0
            stop = INTERRUPTED if interrupted else ""
            while k_emit < len(tasks):
                while k_next < len(tasks) and len(running) < jobs:
                    i, scheme = tasks[k_next]
                    stop, reached = _wall_stop(stop, reached, start, max_wall, share, group,
                                               first, i, scheme)
                    if stop:
                        results[i, scheme] = _skipped(scenes[i], i, scheme, stop, extra)
                    else:
                        fut = pool.submit(_cell_task, seed, i, scheme, tuple(extra), drives)
                        running[fut] = (i, scheme)
                    k_next += 1
                if running and tasks[k_emit] not in results:
                    try:
                        finished, _ = wait(running, return_when=FIRST_COMPLETED)
                    except KeyboardInterrupt:
                        interrupted, stop = True, INTERRUPTED
                        finished = list(running)
                    for fut in finished:
                        i, scheme = running.pop(fut)
                        try:
                            if interrupted:
                                raise KeyboardInterrupt
                            results[i, scheme] = fut.result()
                        except BaseException:  # noqa: BLE001  a worker stopped by the Ctrl-C
                            interrupted, stop = True, INTERRUPTED
                            results[i, scheme] = _skipped(scenes[i], i, scheme, INTERRUPTED,
                                                          extra)
                while k_emit < len(tasks) and tasks[k_emit] in results:
                    i, scheme = tasks[k_emit]
                    row = done[i, scheme] = results[i, scheme]
                    k_emit += 1
                    if progress:
                        progress(row)
                    if on_failure and failed(row):
                        on_failure(scenes[i], [done[i, s] for s in schemes if (i, s) in done])
    finally:
        pool.shutdown(wait=not interrupted, cancel_futures=True)
    return [done[i, s] for i in range(n) for s in schemes]


def failure_scene(scene: Scene, rows, extra=()) -> Scene:
    """The scene to rerun with `beltsim run FILE`: the grid as run, the failures named."""
    bad = "; ".join(f"{r['scheme']}: {r['status']}" for r in rows if failed(r))
    return scene.with_overrides([*extra, ("title", f"{scene.title}; failed: {bad}")])


def counts(rows) -> dict:
    """Cells by status, and by status and reason key for refusals and failures."""
    by_status = Counter(r["status"] for r in rows)
    by_reason = Counter((r["status"], r["reason_key"]) for r in rows
                        if r["status"] == CellStatus.REFUSED.value or failed(r))
    return {"status": dict(by_status), "reason": dict(by_reason)}


def random_markdown(rows, seed: int, n: int, wall: float, extra=(), drives=False) -> str:
    """Counts per status and per scheme, refusals and failures by key, the failed cells
    (``drives``: of random closed drives)."""
    c = counts(rows)
    schemes = list(dict.fromkeys(r["scheme"] for r in rows))
    statuses = [s.value for s in CellStatus] + [CRASHED, SKIPPED]
    statuses = [s for s in statuses if s in c["status"]]
    grid = ", ".join(f"{k} = {v}" for k, v in extra) if extra else "the default grid"
    if drives:
        bounds = ", ".join(f"{k} {b:g}" for k, b in DRIVE_BOUNDS.items()) + " (relative)"
    else:
        bounds = (", ".join(f"{k} {b:g}" for k, b in BOUNDS.items() if k != "slip_start")
                  + f" (relative), slip start {SLIP_START_ELEMENTS:g} L / N (N elements)")
    lines = [f"# Random {'drives' if drives else 'scenes'}: {n} drawn with seed {seed}, on "
             f"{grid}", "",
             (f"{len(rows)} cells in {wall:.0f} s wall; {sum(failed(r) for r in rows)} "
              f"failed. Bounds: {bounds}."), "",
             "| scheme | " + " | ".join(statuses) + " |", "|---|" + "---|" * len(statuses)]
    for scheme in schemes + ["all"]:
        mine = Counter(r["status"] for r in rows if scheme in ("all", r["scheme"]))
        lines.append(f"| {scheme} | " + " | ".join(str(mine.get(s, 0)) for s in statuses)
                     + " |")
    lines += ["", "| status | reason key | cells |", "|---|---|---|"]
    for (status, key), k in sorted(c["reason"].items(), key=lambda kv: (-kv[1], kv[0])):
        lines.append(f"| {status} | {key.replace('|', '/')} | {k} |")
    bad = [r for r in rows if failed(r)]
    if bad:
        lines += ["", "Failed cells (scene files in failures/):", "",
                  "| scene | scheme | status | elements | wall [s] | reason |",
                  "|---|---|---|---|---|---|"]
        for r in bad:
            lines.append(f"| {r['index']} | {r['scheme']} | {r['status']} | {r['elements']} "
                         f"| {r['elapsed']:.3g} | {r['reason'].replace('|', '/')} |")
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    """``python -m validation.random_scenes N [--seed S] [--elements E] [--max-wall SECONDS]
    [--jobs J] [--out DIR]``: N random scenes, each by every applicable scheme.

    Exit status 0 when every cell passed, 1 when a cell failed (its scene is written to
    ``failures/``), 2 on bad options, 130 interrupted.
    """
    import sys
    from pathlib import Path

    from beltsim.cli import OneLineParser
    from beltsim.io.files import prepare_outdir, write_atomic, write_csv

    parser = OneLineParser(
        prog="python -m validation.random_scenes",
        description="Random valid scenes, each by every applicable scheme (random.csv, "
                    "random.md, failures/scene_<i>.toml).")
    parser.add_argument("n", type=int, metavar="N", help="number of scenes (>= 1)")
    parser.add_argument("--seed", type=int, default=0, metavar="S",
                        help="the draw (default 0); scene i of seed S is always the same")
    parser.add_argument("--elements", type=int, default=None,
                        help="run every scene on this many elements")
    parser.add_argument("--max-wall", type=float, default=None, metavar="SECONDS",
                        help="start no cell after this many seconds (the rest are skipped)")
    parser.add_argument("--jobs", type=int, default=1, metavar="J",
                        help="run the cells in J processes (default 1); the rows and counts "
                             "are the same, only the wall times differ")
    parser.add_argument("--drives", action="store_true",
                        help="random closed drives (validation.random_drives) instead of "
                             "straight belts")
    parser.add_argument("--out", default=None,
                        help="output directory (default runs/out/stability_random, "
                             "runs/out/stability_random_drives with --drives)")
    args = parser.parse_args(argv)
    if args.n < 1:
        parser.error(f"N: must be >= 1 scene, got {args.n}")
    if args.max_wall is not None and not args.max_wall > 0:
        parser.error(f"--max-wall: must be > 0 s, got {args.max_wall}")
    if args.jobs < 1:
        parser.error(f"--jobs: must be >= 1, got {args.jobs}")
    out = prepare_outdir(Path(args.out or "runs/out/stability_random"
                              + ("_drives" if args.drives else "")))
    failures = out / "failures"
    for old in failures.glob("scene_*.toml"):  # a previous draw's: they would pass as ours
        old.unlink()
    extra = [("numerics.elements", args.elements)] if args.elements else []

    def show(row):
        print(f"scene {row['index']:<5d} {row['scheme']:<9s} {row['status']:<15s} "
              f"{row['elements']:>7d} el {row['elapsed']:8.3g} s  {row['reason'][:80]}",
              flush=True)

    def keep(scene, rows):  # at each failed cell: a killed run still leaves the scenes
        prepare_outdir(failures)
        write_atomic(failures / f"scene_{rows[0]['index']}.toml",
                     failure_scene(scene, rows, extra).to_toml())
    start = time.perf_counter()
    rows = random_study(args.n, args.seed, extra=extra, max_wall=args.max_wall,
                        progress=show, on_failure=keep, jobs=args.jobs, drives=args.drives)
    wall = time.perf_counter() - start
    cols = (*COLUMNS, *error_columns(rows), "reason")
    write_csv(out / "random.csv", cols, [[r[c] for r in rows] for c in cols],
              text_columns=TEXT_COLUMNS)
    write_atomic(out / "random.md", random_markdown(rows, args.seed, args.n, wall, extra,
                                                    args.drives))
    tally = counts(rows)
    print(f"{args.n} scenes (seed {args.seed}), {len(rows)} cells in {wall:.0f} s: "
          + ", ".join(f"{k} {n}" for k, n in sorted(tally["status"].items())))
    for (status, key), n in sorted(tally["reason"].items(), key=lambda kv: -kv[1]):
        print(f"  {status:<15s} {n:5d}  {key}")
    bad = [r for r in rows if failed(r)]
    print(f"wrote {out / 'random.csv'} and {out / 'random.md'}"
          + (f"; {len(bad)} failed cells, their scenes in {failures}" if bad else ""))
    if any(r["reason"] == INTERRUPTED for r in rows):
        print("interrupted (the cells not run are reported as skipped)", file=sys.stderr)
        return 130
    return 1 if bad else 0


if __name__ == "__main__":
    raise SystemExit(main())
