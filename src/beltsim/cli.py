"""Command-line interface: a thin layer over the Python API.

Exit status: 0 success, 2 bad input (scene, --set, output directory), 3 a run
that stopped on a numerical failure, 130 interrupted.
"""

from __future__ import annotations

import argparse
import sys

from .api import is_drive_scene
from .cli_text import cell as _cell
from .cli_text import format_run, format_summary
from .cli_text import int_list as _int_list
from .errors import BeltsimError, NumericalError, UsageError


class OneLineParser(argparse.ArgumentParser):
    """An argument parser whose errors are one line on stderr and exit status 2."""

    def error(self, message):  # one line, exit 2, as for a bad scene
        self.exit(2, f"{self.prog}: error: {message}\n")


def _add_scene_args(p, **scene_kw):
    p.add_argument("scene", **({"help": "scene file (TOML) or the name of a shipped scene "
                                          "(paper_slip, ...)"} | scene_kw))
    p.add_argument("--set", dest="overrides", action="append", default=[],
                   metavar="SECTION.KEY=VALUE", help="override a scene key (repeatable)")


def _scene(args):
    from .api import load_scene
    return load_scene(args.scene, args.overrides)


def _drive_analytic(args, scene):
    from .api import solve
    from .beltdrive.io import format_drive
    from .io.files import write_json

    out = _analytic_outdir(args)
    # the creep theory, and the beam's own exact state where the scene is a beam
    summaries = {"string": solve(scene, "string").summary()}
    if scene.params.model == "beam":
        summaries["beam"] = solve(scene).summary()
    write_json(out / "summary.json", summaries)
    _clear_stale(out, ANALYTIC_FILES, written=("summary.json",))
    for name, summary in summaries.items():
        print(format_drive(summary, title=f"{scene.title or args.scene} ({name})"))
    print(f"wrote {out / 'summary.json'}")
    return 0


def _progress(args) -> bool:
    """A progress bar unless --quiet, and only on a terminal: not in a captured log."""
    return not args.quiet and sys.stderr.isatty()


# ---------------------------------------------------------------------------
# commands


#: What 'beltsim analytic' writes: both for a straight belt, the summary for a drive
ANALYTIC_FILES = ("summary.json", "fields.csv")
#: What 'beltsim plot DIR' and 'beltsim animate --from DIR' draw from a run into its folder:
#: a new run there removes them (they are the earlier run's)
RUN_FIGURES = ("fields.png", "history.png", "drive.png", "transient.gif", "transient.mp4")
#: The figures of 'beltsim sweep', each for one key: a sweep removes the one it does not draw
SWEEP_FIGURES = ("creep_collapse.png", "characteristic.png")


def _analytic_outdir(args):
    from pathlib import Path

    from .io.files import prepare_outdir

    return prepare_outdir(args.out or Path("runs/out") / f"analytic_{Path(args.scene).stem}")


def _clear_stale(out, names, written):
    """Remove the files of ``names`` that this command did not write: an earlier scene's
    would read as this one's."""
    for name in set(names) - set(written):
        (out / name).unlink(missing_ok=True)


def cmd_analytic(args):
    from .io.files import write_json
    from .io.results import write_fields
    from .problem import analytic

    scene = _scene(args)
    if is_drive_scene(scene):
        return _drive_analytic(args, scene)
    sol = analytic.solve(scene)
    out = _analytic_outdir(args)
    x, fields = sol.sample()
    summary = sol.summary()
    write_json(out / "summary.json", summary)
    write_fields(out / "fields.csv", x, fields)
    print(format_summary(summary, title=scene.title or args.scene))
    print(f"wrote {out / 'summary.json'} and {out / 'fields.csv'}")
    return 0


def cmd_run(args):
    from pathlib import Path

    from .io.files import prepare_outdir
    from .io.results import CHECKPOINT, SNAPSHOTS, save_run
    from .simulation import stability_check
    from .simulation.controller import Simulation

    if args.snapshots is not None and not args.snapshots > 0:
        raise UsageError(f"--snapshots: must be > 0 s, got {args.snapshots}")
    if args.resume:
        if args.scene or args.overrides:
            raise UsageError("--resume DIR continues a run as it was: give no SCENE or --set")
        out = prepare_outdir(args.out or args.resume)
        sim = Simulation.resume(Path(args.resume) / CHECKPOINT)
        title = sim.scene.title or args.resume
    else:
        if not args.scene:
            raise UsageError("run: give a SCENE file, or --resume DIR")
        scene = _scene(args)
        sim = Simulation(scene, snapshot_interval=args.snapshots)
        out = prepare_outdir(args.out or Path("runs/out") / Path(args.scene).stem)
        title = scene.title or args.scene
    # a summary.json present means the latest run in this directory finished
    (out / "summary.json").unlink(missing_ok=True)
    result = sim.run(progress=_progress(args), raise_on_failure=False, handle_signals=True,
                     checkpoint=out / CHECKPOINT)
    if result.interrupted:
        save_run(result, out, complete=False)
        print(f"beltsim: {result.reason}; state so far and checkpoint written, continue with "
              f"'beltsim run --resume {out}'", file=sys.stderr)
        return 130
    result.reference = sim.readout.reference()
    stability_check.attach(result, notice=_progress(args))
    written = save_run(result, out)
    # an earlier run's snapshots would animate as this run's, its figures show as this one's
    _clear_stale(out, (SNAPSHOTS, *RUN_FIGURES), written=[p.name for p in written])
    summary = result.summary()
    print(format_summary(summary, title=title))
    print(format_run(summary))
    print(f"wrote {out}/summary.json, fields.csv, history.csv")
    stability_check.warn(result)
    if result.failed:
        print(f"beltsim: numerical failure: {result.reason}", file=sys.stderr)
        return 3
    if not result.converged:
        print(f"beltsim: warning: {result.reason}", file=sys.stderr)
        return 1
    return 0


def cmd_convergence(args):
    from pathlib import Path

    from . import solvers
    from .io.files import prepare_outdir, write_csv
    from .plots.common import save_figure
    from .plots.studies import ERROR_VS_RUNTIME_DPI, error_vs_runtime
    from .studies import convergence as studies

    scene = _scene(args)
    ladder = _int_list(args.ladder, "--ladder")
    schemes = args.schemes.split(",") if args.schemes else None
    known = (*solvers.names(), *(() if is_drive_scene(scene) else (studies.RICHARDSON,)))
    for s in schemes or ():
        if s not in known:
            raise UsageError(f"--schemes: unknown scheme {s!r} ({', '.join(known)})")
    out = prepare_outdir(args.out or Path("runs/out") / f"convergence_{Path(args.scene).stem}")
    keys = studies.error_keys(scene)
    cols = ("scheme", "elements", "h_min", "dt", "steps", "wall_time", "compile_time",
            "converged") + tuple(f"error_{k}" for k in keys)
    print("  ".join(f"{c:>12s}" for c in cols))

    def show(row):
        print("  ".join(_cell(row[c]) for c in cols)
              + (f"  refused: {row['reason']}" if row["reason"] else ""), flush=True)
    rows = studies.convergence(scene, ladder, schemes, progress=show)
    write_csv(out / "convergence.csv", (*cols, "reason"),
              [[r[c] for r in rows] for c in (*cols, "reason")],
              text_columns={"scheme", "reason"})
    save_figure(error_vs_runtime, out / "error_vs_runtime.png", rows,
                title=f"{scene.title or args.scene}", dpi=ERROR_VS_RUNTIME_DPI)
    print("observed order in the grid size (successive grids; least-squares fit):")
    for key in keys:
        for scheme, o in studies.observed_orders(rows, key).items():
            pairs = ", ".join(f"{p:.2f}" for p in o["pairs"])
            print(f"  {key:<20s} {scheme:<9s} {pairs}  (fit {o['fit']:.2f})")
    print(f"wrote {out / 'convergence.csv'} and {out / 'error_vs_runtime.png'}")
    return 0


def cmd_bench(args):
    if args.repeat < 1:
        raise UsageError(f"--repeat: must be at least 1, got {args.repeat}")
    from .api import load_scene
    from .studies import bench as studies

    grid = [("numerics.elements", args.elements)] if args.elements is not None else []
    scene = load_scene(args.scene, [*args.overrides, *grid])
    result = studies.bench(scene, cold=not args.no_cold, repeat=args.repeat)
    print(studies.bench_json(result))
    return 0


def cmd_stability(args):
    from pathlib import Path

    from .io.files import prepare_outdir, write_atomic, write_csv
    from .studies import stability as studies

    out = prepare_outdir(args.out or Path("runs/out/stability"))
    extra = [("numerics.elements", args.elements)] if args.elements else []
    cases = studies.STABILITY_CASES
    if args.elements:  # a coarse matrix: a case about the grid is the others coarsened
        cases = tuple(c for c in cases if not c.sets_grid)

    def show(row):
        print(f"{row['case']:<40s} {row['scheme']:<9s} {row['status'].value:<15s} "
              f"wall {row['wall_time']:.3g} s  {row['reason'][:90]}", flush=True)
    # a coarse grid's own error would hide whether a scheme reached its grid's steady state
    rows = studies.stability_matrix(cases, extra=extra, progress=show,
                                    discrete=bool(args.elements))
    # the errors of both layouts' cells, each empty (nan) where a cell has none
    cols = ("case", "scheme", "status", "dt", "steps", "wall_time",
            *studies.error_columns(rows), "reason")
    write_csv(out / "stability.csv", cols,
              [[r[c].value if c == "status" else r.get(c, float("nan")) for r in rows]
               for c in cols],
              text_columns={"case", "scheme", "status", "reason"})
    write_atomic(out / "stability.md", studies.stability_markdown(rows))
    bad = [r for r in rows if r["status"] not in studies.ACCEPTED]
    print(f"wrote {out / 'stability.csv'} and {out / 'stability.md'}; "
          f"{len(rows) - len(bad)} of {len(rows)} cells converged, refused or not applicable")
    return 1 if bad else 0


def cmd_sweep(args):
    from pathlib import Path

    import numpy as np

    from .io.files import prepare_outdir, write_csv
    from .plots.common import save_figure
    from .plots.studies import CREEP_COLLAPSE_DPI, creep_collapse
    from .studies import sweep

    scene = _scene(args)
    key, values = sweep.parse_vary(args.vary, scene)
    if args.workers is not None and args.workers < 1:
        raise UsageError(f"--workers: must be >= 1, got {args.workers}")
    if is_drive_scene(scene):
        return _drive_sweep(args, scene, key, values)
    out = prepare_outdir(args.out or Path("runs/out") / f"sweep_{Path(args.scene).stem}")
    collapse = key == "contact.max_friction"
    executor = sweep.make_executor(args.workers, args.scheduler)

    def show(row):
        print(f"  {key} = {row['value']!r:<12} total friction {row['total_friction']:.6g} N "
              f"(analytic {row['total_friction_analytic']:.6g}), wall {row['wall_time']:.3g} s"
              f"{'' if row['converged'] else ', NOT converged: ' + str(row['reason'])}",
              flush=True)
    rows = sweep.sweep(scene, key, values, executor, keep_theta=collapse, progress=show)
    cols = [key] + list(sweep.KEYS) + [f"{k}_analytic" for k in sweep.KEYS] + [
        "converged", "wall_time"]
    data = [[r["value"] for r in rows]] + [[r[c] for r in rows] for c in cols[1:]]
    data = [[np.nan if v is None else v for v in col] for col in data]
    write_csv(out / "sweep.csv", cols, data)
    print(f"wrote {out / 'sweep.csv'}")
    _clear_stale(out, SWEEP_FIGURES, written=("creep_collapse.png",) if collapse else ())
    if collapse:
        save_figure(creep_collapse, out / "creep_collapse.png", rows, title=scene.title,
                    dpi=CREEP_COLLAPSE_DPI)
        print(f"wrote {out / 'creep_collapse.png'}")
    return 0 if all(r["converged"] for r in rows) else 1


def _drive_sweep(args, scene, key, values):
    from pathlib import Path

    import numpy as np

    from .beltdrive.characteristic import plot_characteristic
    from .io.files import prepare_outdir, write_csv
    from .plots.common import save_figure
    from .simulation.loop_solution import SUMMARY_KEYS
    from .studies import sweep

    out = prepare_outdir(args.out or Path("runs/out") / f"sweep_{Path(args.scene).stem}")

    def show(row):
        print(f"  {key} = {row['value']!r:<10} {row['status']:<14} speed ratio "
              f"{row['speed_ratio']:.6f}, tight {row['tight_tension']:.5g} N, slack "
              f"{row['slack_tension']:.5g} N, wall {row['wall_time']:.3g} s", flush=True)
    rows = sweep.sweep(scene, key, values, sweep.make_executor(args.workers, args.scheduler),
                       progress=show)
    cols = [key, "status", *SUMMARY_KEYS, *(f"{k}_analytic" for k in SUMMARY_KEYS),
            "wall_time"]
    data = [[r["value"] for r in rows], [r["status"] for r in rows]] + [
        [np.nan if r[c] is None else r[c] for r in rows] for c in cols[2:]]
    write_csv(out / "sweep.csv", cols, data, text_columns=("status",))
    print(f"wrote {out / 'sweep.csv'}")
    characteristic = key == "drive.load_torque"
    _clear_stale(out, SWEEP_FIGURES, written=("characteristic.png",) if characteristic else ())
    if characteristic:
        ok = [r for r in rows if r["converged"]]
        fig = save_figure(
            plot_characteristic, out / "characteristic.png",
            [r["value"] for r in ok], [1.0 - r["speed_ratio"] for r in ok],
            [r["efficiency"] for r in ok], capacity=rows[0]["capacity"],
            analytic={"speed_loss": [1.0 - r["speed_ratio_analytic"] for r in ok],
                      "efficiency": [r["efficiency_analytic"] for r in ok]})
        print(f"wrote {fig}")
    # one rule for every command (outputs.md#exit-statuses): a point without a steady
    # state, gross slip included (as 'beltsim run' says), makes the exit status 1
    return 0 if all(r["status"] == "converged" for r in rows) else 1


def cmd_paper(args):
    from pathlib import Path

    from .plots.paper import figures
    from .studies import paper

    sims = None
    if not args.no_sim:
        def show(key, res):
            print(f"  simulated {key}: {'steady' if res.converged else 'NOT steady'} after "
                  f"{res.steps} steps, wall {res.wall_time:.3g} s", flush=True)
        sims = paper.simulate(progress=show)
    out = args.out or Path("runs/out/paper")
    sols = paper.solutions()
    rows, table = paper.write_table1(out, sols)
    paths = [table, *figures(out, sols, sims)]
    print(paper.format_table1(rows))
    print("wrote " + ", ".join(str(p) for p in paths))
    return 0


def _stored_drive(run_dir) -> bool:
    """Whether a run directory holds a closed drive's run (its scene.toml has [drive])."""
    import tomllib

    from .problem.kinds import is_drive_data

    try:
        return is_drive_data(tomllib.loads((run_dir / "scene.toml").read_text(encoding="utf-8")))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
        return False  # the straight belt's reader says what is wrong


def _drive_animate(args, out, src):
    from .beltdrive.io import animate_drive_run

    path = animate_drive_run(src, out / f"transient.{args.format}", args.fps)
    print(f"wrote {path}")
    return 0


def cmd_animate(args):
    from pathlib import Path

    from .io.files import prepare_outdir
    from .io.results import SNAPSHOTS, save_run
    from .plots.animate import animate
    from .simulation import stability_check
    from .simulation.controller import run

    if args.fps < 1:
        raise UsageError(f"--fps: must be >= 1, got {args.fps}")
    if args.format is None:
        from .plots.frames import default_format

        args.format, note = default_format()
        if note:
            print(note, file=sys.stderr)
    if args.from_dir:
        if args.scene or args.overrides:
            raise UsageError("--from DIR animates a stored run: give no SCENE or --set")
        src = Path(args.from_dir)
        out = prepare_outdir(args.out or src)
        if _stored_drive(src):
            return _drive_animate(args, out, src)
    else:
        if not args.scene:
            raise UsageError("animate: give a SCENE file, or --from DIR")
        scene = _scene(args)
        from .solvers import discretise

        window = discretise(scene).window
        interval = args.interval or scene.numerics.get("snapshot_interval") or window / (
            8 if is_drive_scene(scene) else 4)
        if not interval > 0:
            raise UsageError(f"--interval: must be > 0 s, got {interval}")
        out = prepare_outdir(args.out or Path("runs/out") / f"animate_{Path(args.scene).stem}")
        result = run(scene, progress=_progress(args), raise_on_failure=False,
                     snapshot_interval=interval)
        stability_check.attach(result, notice=_progress(args))
        save_run(result, out)
        # a new run: the figures of an earlier one, the other format's animation among
        # them, go
        _clear_stale(out, RUN_FIGURES, written=(f"transient.{args.format}",))
        print(f"ran {args.scene}: {'steady' if result.converged else result.reason} at "
              f"t = {result.simulated_time:.4g} s, {len(result.snapshots['t'])} snapshots")
        stability_check.warn(result)
        src = out
        if is_drive_scene(scene):
            return _drive_animate(args, out, src)
    if not (src / SNAPSHOTS).is_file():
        raise UsageError(f"--from {src}: no {SNAPSHOTS} there (run with --snapshots INTERVAL)")
    path = animate(src / SNAPSHOTS, out / f"transient.{args.format}", args.format, args.fps)
    print(f"wrote {path}")
    return 0


def cmd_plot(args):
    from pathlib import Path

    from .beltdrive.io import plot_drive_run
    from .plots.run import plot_run

    paths = (plot_drive_run if _stored_drive(Path(args.dir)) else plot_run)(
        args.dir, args.out)
    print("wrote " + ", ".join(str(p) for p in paths))
    return 0


def cmd_modes(args):
    from pathlib import Path

    from .api import modes
    from .cli_map import removing_damping
    from .io.files import prepare_outdir, write_json

    scene = _scene(args)
    found = modes(scene, count=args.count, f_max=args.f_max, elements=args.elements)
    out = prepare_outdir(args.out or Path("runs/out") / f"modes_{Path(args.scene).stem}")
    write_json(out / "modes.json", found.to_list())
    print(found.table())
    if found.least_stable.real > 0.0:
        print(removing_damping(scene, found.elements), flush=True)
    print(f"wrote {out / 'modes.json'}")
    return 0


def cmd_scenes(args):
    from .api import scene_names, shipped_scene
    from .cli_text import scene_kind
    from .errors import MissingInputError

    names = scene_names()
    if not names:
        raise MissingInputError("no scenes ship with this installation of beltsim")
    rows = [(name, *scene_kind(shipped_scene(name))) for name in names]
    width = max(len(name) for name, *_ in rows)
    kind_width = max(len(kind) for _, kind, _ in rows)
    for name, kind, title in rows:
        print(f"{name:<{width}}  {kind:<{kind_width}}  {title}")
    return 0


def build_parser():
    parser = OneLineParser(prog="beltsim", description="Belt-drive contact mechanics: analytic "
                     "steady solutions and transient Eulerian simulation.")
    from . import __version__

    parser.add_argument("--version", action="version", version=f"beltsim {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=OneLineParser)
    p = sub.add_parser("scenes", help="the shipped scenes: name, kind and title (run one "
                       "with 'beltsim run NAME')")
    p.set_defaults(func=cmd_scenes)

    p = sub.add_parser("analytic", help="analytic steady solution of a scene")
    _add_scene_args(p)
    p.add_argument("--out", default=None,
                   help="output directory (default runs/out/analytic_SCENE)")
    p.set_defaults(func=cmd_analytic)

    p = sub.add_parser("run", help="transient simulation from rest to steady state")
    _add_scene_args(p, nargs="?")
    p.add_argument("--out", default=None, help="output directory (default runs/out/SCENE)")
    p.add_argument("--resume", metavar="DIR", default=None,
                   help="continue an interrupted run from DIR/checkpoint.npz")
    p.add_argument("--snapshots", metavar="INTERVAL", type=float, default=None,
                   help="store the state every INTERVAL seconds of simulated time in "
                        "DIR/snapshots.npz (for 'beltsim animate --from DIR')")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_run)

    p = sub.add_parser("convergence", help="errors and run times of each scheme on a ladder "
                       "of grids")
    _add_scene_args(p)
    p.add_argument("--out", default=None, help="output directory")
    p.add_argument("--ladder", default="125,250,500,1000,2000",
                   help="element counts (comma-separated)")
    p.add_argument("--schemes", default=None,
                   help="comma-separated subset of the registered schemes and richardson")
    p.set_defaults(func=cmd_convergence)

    p = sub.add_parser("paper", help="the paper's Table 1 and Figures 2-7 (analytic, with "
                       "simulated markers)")
    p.add_argument("--out", default=None, help="output directory (default runs/out/paper)")
    p.add_argument("--no-sim", action="store_true",
                   help="analytic curves only, no simulated markers")
    p.set_defaults(func=cmd_paper)

    p = sub.add_parser("animate", help="animated transient (GIF or MP4) of a scene or a "
                       "stored run")
    _add_scene_args(p, nargs="?", help="scene file (TOML) to run")
    p.add_argument("--from", dest="from_dir", metavar="DIR", default=None,
                   help="animate DIR/snapshots.npz of a stored run, without running")
    p.add_argument("--out", default=None, help="output directory")
    p.add_argument("--format", choices=("gif", "mp4"), default=None,
                   help="mp4 where ffmpeg is at hand (imageio-ffmpeg ships one), else gif")
    p.add_argument("--fps", type=int, default=15, help="frames per second")
    p.add_argument("--interval", type=float, default=None,
                   help="simulated seconds between snapshots (default L / (4 c))")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_animate)

    p = sub.add_parser("plot", help="draw a stored run (fields and history, against the "
                       "analytic steady state) as PNG files")
    p.add_argument("dir", metavar="DIR", help="output directory of 'beltsim run'")
    p.add_argument("--out", default=None, metavar="OUTDIR",
                   help="where to write fields.png and history.png (default DIR)")
    p.set_defaults(func=cmd_plot)

    p = sub.add_parser("sweep", help="run a scene for several values of one key, in "
                       "parallel")
    _add_scene_args(p)
    p.add_argument("--vary", required=True, metavar="SECTION.KEY=V1,V2,...",
                   help="the key and its values")
    p.add_argument("--out", default=None, help="output directory")
    p.add_argument("--workers", type=int, default=None,
                   help="worker processes (default: one per core)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="run on a Dask distributed cluster (pip install 'beltsim[dask]')")
    p.set_defaults(func=cmd_sweep)

    p = sub.add_parser("stability", help="stiff and extreme scenes by integrator: converged, "
                       "refused or not applicable, never NaN")
    p.add_argument("--out", default=None, help="output directory")
    p.add_argument("--elements", type=int, default=None,
                   help="run every case on this many elements (a quick, coarse matrix)")
    p.set_defaults(func=cmd_stability)

    p = sub.add_parser("modes", help="a drive's lowest modes about its steady state: "
                       "frequencies, growth rates, pulley and belt shapes (modes.json)")
    _add_scene_args(p)
    p.add_argument("--out", default=None, help="output directory (default runs/out/modes_SCENE)")
    p.add_argument("--count", type=int, default=None, help="at most this many modes, the "
                   "lowest (default 10 without --f-max)")
    p.add_argument("--f-max", type=float, default=None, help="only modes up to this (Hz)")
    p.add_argument("--elements", type=int, default=None,
                   help="the grid (default the scene's numerics.elements, else 200)")
    p.set_defaults(func=cmd_modes)

    p = sub.add_parser("bench", help="wall times of the default and steady runs, the explicit "
                       "kernel's speed, import beltsim, a warm run end to end and a cold start "
                       "(peers: benchmarks/ of the repository)")
    _add_scene_args(p, nargs="?", default="paper_slip",
                    help="scene file or shipped scene name (default paper_slip)")
    p.add_argument("--elements", type=int, default=None,
                   help="number of elements (numerics.elements; default the scene's)")
    p.add_argument("--repeat", type=int, default=3,
                   help="time each run this many times and keep the shortest (default 3)")
    p.add_argument("--no-cold", action="store_true", help="skip the cold-start run")
    p.set_defaults(func=cmd_bench)
    from .cli_map import add_parser as add_stability_map  # beltsim stability-map
    add_stability_map(sub, _add_scene_args)
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except NumericalError as exc:
        print(f"beltsim: numerical failure: {exc}", file=sys.stderr)
        return 3
    except BeltsimError as exc:
        print(f"beltsim: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("beltsim: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
