"""A drive's stored run read back (summary.json, fields.csv, history.csv, snapshots.npz,
as :func:`beltsim.io.results.save_run` writes them), drawn and animated; its figures as
text."""

from __future__ import annotations

import numpy as np

from ..errors import NoSolutionError
from ..io.files import prepare_outdir

#: the snapshots of a run (``beltsim run --snapshots``), for ``beltsim animate --from``
SNAPSHOTS = "snapshots.npz"
#: The most frames an animation of a run draws (its snapshots evenly thinned to these)
MAX_FRAMES = 150


def format_drive(summary: dict, title: str = "") -> str:
    """A short table of a drive's figures: a two-pulley drive's by name, and on more
    pulleys each span's tension and each pulley's speed, slip arc, torque and hub load
    (and a tensioner's arm angle and travel)."""
    units = {"tight_tension": "N", "slack_tension": "N", "belt_speed": "m/s",
             "driven_speed": "rad/s", "speed_ratio": "", "slip_arc_driver": "rad",
             "slip_arc_driven": "rad", "driver_torque": "N m", "efficiency": "",
             "slip_power": "W", "arm_angle": "rad", "arm_travel": "rad"}
    width = max(len(k) for k in units)
    lines = [title] if title else []
    for k, unit in units.items():
        if summary.get(k) is not None:
            lines.append(f"  {k:<{width}}  {summary[k]:.8g} {unit}".rstrip())
    if "tight_tension" in summary or "spans" not in summary:
        return "\n".join(lines)
    lines.append("  span                          tension (N)")
    for sp in summary["spans"]:
        lines.append(f"  {sp['from'] + ' -> ' + sp['to']:<28}  {sp['tension']:12.6g}")
    lines.append("  pulley        role       speed (rad/s)  slip arc (rad)  torque (N m)"
                 "  hub load (N)" + ("  slip margin" if "slip_margin" in
                                     summary["pulleys"][0] else ""))
    for p in summary["pulleys"]:
        hub = (p["hub_load"][0] ** 2 + p["hub_load"][1] ** 2) ** 0.5
        row = (f"  {p['name']:<12}  {p['role']:<9}  {p['speed']:13.6g}  "
               f"{p['slip_arc']:14.4g}  {p['torque']:12.5g}  {hub:12.5g}")
        if "slip_margin" in p:
            row += f"  {p['slip_margin']:11.4g}"
        lines.append(row)
    return "\n".join(lines)


def read_drive_run(run_dir):
    """(scene, x, fields, history, summary) of a stored drive run."""
    import csv
    import json
    from pathlib import Path

    from .scene import DriveScene

    run_dir = Path(run_dir)
    scene = DriveScene.load(run_dir / "scene.toml")

    def columns(name):
        with open(run_dir / name, newline="") as fh:
            rows = list(csv.reader(fh))
        return {k: np.array([float(r[i]) for r in rows[1:]]) for i, k in enumerate(rows[0])}

    f = columns("fields.csv")
    hist = columns("history.csv") if (run_dir / "history.csv").is_file() else {}
    summary = json.loads((run_dir / "summary.json").read_text())
    return scene, f.pop("x"), f, hist, summary


def plot_drive_run(run_dir, out=None) -> list:
    """Draw a stored drive run, on any layout: drive.png (to scale, coloured by tension,
    slip arcs, hub loads), fields.png (tension and friction along the loop against the
    exact steady state) and, where it has one, history.png. Returns the paths written."""
    from pathlib import Path

    from ..plots.common import save_figure
    from . import drawing, plots
    from .exact import exact_state

    scene, x, f, hist, summary = read_drive_run(run_dir)
    out = prepare_outdir(out or run_dir)
    P, grid, arm = scene.params, scene.params, None
    if P.tensioner is not None:
        # the state's layout: the arm where the run ends; the grid's (x's), that one
        # after a steady search, the layout at the rest angle where the arm moved
        k = P.tensioner.index
        drawn = P.layout.centres[k]
        travel = summary.get("arm_travel") or 0.0
        P = P.at_arm(travel)
        grid = scene.params.at_arm(summary.get("grid_arm_travel", travel))
        arm = (P.tensioner.pivot, P.layout.centres[k], drawn)
    try:
        ana = exact_state(P)
    except NoSolutionError:  # no steady state (gross slip): the run's own fields only
        ana = None
    hubs = [p["hub_load"] for p in summary["pulleys"]] if "pulleys" in summary else None
    paths = [save_figure(drawing.draw_drive, out / "drive.png", grid, x, f["tension"],
                         f["slip"] > 0.5, title=scene.title or Path(run_dir).name,
                         hub_loads=hubs, arm=arm, at=P),
             save_figure(plots.plot_loop_fields, out / "fields.png", x,
                         {"tension": f["tension"], "friction": f["friction"]}, grid,
                         analytic=ana)]
    if hist:
        # the steady values only where the run reached them: a periodic drive's or a
        # failed run's history is not compared with a state it never approaches
        steady = ana.summary() if ana is not None and summary.get("converged") else None
        paths.append(save_figure(plots.plot_drive_history, out / "history.png", hist["t"],
                                 hist, steady=steady))
    return paths


def snapshot_frames(P, data) -> list[dict]:
    """The frames of :func:`~beltsim.beltdrive.animation.animate_drive` from a run's
    snapshots (snapshots.npz read as a mapping; ``P`` the DriveParams of its grid's
    layout): each one's tension, slip, belt speed, hub loads (from the tension at each
    span's middle, as the run's summary has them from its span tensions, on the layout
    of the frame), a moving tensioner's arm travel and, on two pulleys, the driven
    pulley's speed."""
    from .figures import hub_loads

    g = P.layout
    x = data["x"]
    middles = 0.5 * (g.bounds[1:-1:2] + g.bounds[2::2])
    travels = data["arm_travel"] if "arm_travel" in data else None
    frames = []
    for i in range(len(data["t"])):
        T = data["tension"][i]
        c = float(data["belt_speed"][i])
        spans = np.interp(middles, x, T, period=g.loop_length)
        frame = {"tension": T, "slip": data["slip"][i], "belt_speed": c}
        gi = g
        if travels is not None:
            frame["arm_travel"] = float(travels[i])
            gi = P.tensioner.turned(g, float(travels[i]) - P.arm_turn)
        frame["hub_loads"] = hub_loads(gi, P.rho, c, spans)
        if P.two_pulley:
            frame["driven_speed"] = float(data["driven_speed"][i])
        frames.append(frame)
    return frames


def animate_drive_run(run_dir, path, fps: int = 15):
    """Animate the snapshots of a stored drive run, on any layout, into ``path`` (.gif
    or .mp4); a tensioner's arm at each snapshot's angle where it moves."""
    from pathlib import Path

    from ..errors import UsageError
    from .animation import animate_drive
    from .scene import DriveScene

    run_dir = Path(run_dir)
    if not (run_dir / SNAPSHOTS).is_file():
        raise UsageError(f"{run_dir}: no {SNAPSHOTS} there (run with --snapshots INTERVAL)")
    P = DriveScene.load(run_dir / "scene.toml").params
    with np.load(run_dir / SNAPSHOTS) as z:
        data = {k: z[k] for k in z.files}
    # at most MAX_FRAMES, evenly over the run, the last among them
    n = len(data["t"])
    keep = np.unique(np.linspace(0, n - 1, min(n, MAX_FRAMES)).round().astype(int))
    data = {k: v[keep] if np.ndim(v) and len(v) == n and k != "x" else v
            for k, v in data.items()}
    if "grid_arm_travel" in data:  # the grid is laid with the arm turned
        P = P.at_arm(float(data["grid_arm_travel"]))
    return animate_drive(P, data["x"], snapshot_frames(P, data), times=data["t"],
                         path=path, fps=fps)
