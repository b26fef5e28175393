"""``beltsim stability-map``: the command line over :mod:`beltsim.studies.stability_map`.

Its own module so that :mod:`beltsim.cli` stays within the package's module length;
:func:`beltsim.cli.build_parser` registers it with :func:`add_parser`.
"""

from __future__ import annotations

import sys

from .errors import SceneError, UsageError


def cmd_stability_map(args):
    """Sweep one parameter of a scene: least stable exact root per value, a CSV and a
    table; with ``--critical-damping``, the damping a stable steady state needs too."""
    import json
    from pathlib import Path

    from .api import load_scene
    from .cli_text import float_list, map_header, map_row
    from .io.files import prepare_outdir, write_atomic, write_csv
    from .problem.kinds import is_drive_scene
    from .studies import stability_map as study

    if not (args.tol > 0):
        raise UsageError(f"--tol: must be > 0 1/s, got {args.tol}")
    scene = load_scene(args.scene, args.overrides)
    study.check_scene(scene, args.param)
    values = (float_list(args.values, "--values") if args.values is not None
              else study.default_values(scene, args.param))
    try:
        values = study.check_values(scene, args.param, values)
    except SceneError as exc:
        raise UsageError(f"--values: {exc}") from None
    out = prepare_outdir(args.out or Path("runs/out") / f"stability_map_{Path(args.scene).stem}"
                         f"_{args.param}")
    how = ("rightmost eigenvalue of the discrete model (central form) with its error"
           if is_drive_scene(scene) else f"least stable exact root up to {_band():g} Hz")
    print(f"{how}, by {args.param} ({study.params_of(scene)[args.param]})", flush=True)
    print(map_header(args.param, study.UNITS[args.param]), flush=True)
    rows = study.sweep(scene, args.param, values,
                       progress=lambda row: print(map_row(row), flush=True))
    write_csv(out / "stability_map.csv", study.COLUMNS, study.csv_columns(rows),
              text_columns=study.TEXT_COLUMNS)
    written = [out / "stability_map.csv"]
    (out / "critical_damping.json").unlink(missing_ok=True)  # an earlier call's
    if args.critical_damping:
        print("critical damping (bisection on d):", flush=True)
        crit = study.critical_damping(scene, tol=args.tol,
                                      progress=lambda row: print(map_row(row), flush=True))
        print(crit.describe())
        write_atomic(out / "critical_damping.json", json.dumps(
            {"damping": crit.damping, "lower": crit.lower, "tolerance": crit.tolerance,
             "reason": crit.reason, "evaluations": crit.evaluations}, indent=1))
        written.append(out / "critical_damping.json")
    print("wrote " + " and ".join(str(p) for p in written))
    missing = [r for r in rows if r["rate"] is None]
    for r in missing:
        print(f"beltsim: warning: {args.param} = {r['value']:g}: {r['status']}",
              file=sys.stderr)
    # as 'beltsim sweep': a point without a steady state (or without a root) exits 1
    return 1 if missing else 0


def removing_damping(scene, elements: int) -> str:
    """What ``beltsim modes`` says when the least stable mode grows: the damping d at
    which the drive's least stable mode decays (the stability map's critical damping of
    the central form's estimate on the modes' grid), or why there is none."""
    from .studies import stability_map as study

    on_grid = scene.with_overrides({"numerics.elements": elements})
    crit = study.critical_damping(on_grid)
    if crit.damping is None or crit.lower is None:
        return f"a mode grows; the damping that removes it: {crit.describe()}"
    at = {r["value"]: r for r in crit.evaluations}[crit.damping]
    return (f"a mode grows; physics.damping = {crit.damping:.4g} 1/s removes it (the "
            f"least stable rate of the central form's estimate there: {at['rate']:+.3g} "
            f"+- {at['error']:.2g} 1/s; at {crit.lower:.4g} 1/s it still grows; "
            "beltsim stability-map SCENE --critical-damping)")


def _band() -> float:
    from .simulation.stability import BAND_HZ

    return BAND_HZ


def add_parser(sub, add_scene_args) -> None:
    """Register ``stability-map`` on the subparsers ``sub`` of :func:`beltsim.cli.build_parser`.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The command line's subcommands.
    add_scene_args : callable
        ``add_scene_args(parser)`` adds SCENE and ``--set`` as every scene command has them.
    """
    from .studies.stability_map import (
        DEFAULT_VALUES,
        DRIVE_DEFAULT_VALUES,
        DRIVE_PARAMS,
        PARAMS,
        TOLERANCE,
    )

    def defaults(table):
        return "; ".join(f"{k} " + ",".join(f"{v:g}" for v in vals)
                         for k, vals in table.items())

    p = sub.add_parser("stability-map", help="the least stable root of a scene's steady "
                       "state over one parameter (stability_map.csv), and the damping a "
                       "stable state needs: exact roots for a straight belt, the discrete "
                       "estimate with its error for a closed drive")
    add_scene_args(p)
    p.add_argument("--param", choices=tuple(dict.fromkeys([*PARAMS, *DRIVE_PARAMS])),
                   default="damping",
                   help="the parameter swept; a straight belt's: physics.damping, "
                        "contact.max_friction, or motion.belt_speed with the surface speed "
                        "at the scene's v/c; a closed drive's: physics.damping, "
                        "contact.friction_coefficient, or the driver's speed "
                        "(default damping)")
    p.add_argument("--values", default=None, metavar="V1,V2,...",
                   help="its values, comma-separated (default, straight belt: "
                        + defaults(DEFAULT_VALUES) + "; closed drive: "
                        + defaults(DRIVE_DEFAULT_VALUES) + ")")
    p.add_argument("--critical-damping", action="store_true",
                   help="also find the smallest damping with no growing root in the band "
                        "(bisection on d; critical_damping.json)")
    p.add_argument("--tol", type=float, default=TOLERANCE,
                   help=f"the critical damping's bracket width, 1/s (default {TOLERANCE:g})")
    p.add_argument("--out", default=None,
                   help="output directory (default runs/out/stability_map_SCENE_PARAM)")
    p.set_defaults(func=cmd_stability_map)
