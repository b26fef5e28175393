"""Animated transients: friction, tension, moment, rotation and displacement over x.

Reads the compact snapshot file of a run (``snapshots.npz``, see
:func:`beltsim.io.results.write_snapshots`), so a long run can be animated later
without running it again. Each frame shows the simulated fields, the contact zone,
the analytic steady state (dashed) and the simulated time. Tension and moment come
from the snapshots' u and theta as b1 du/dx and a dtheta/dx, with the nodal slopes
of the run's own fields.csv (:func:`beltsim.simulation.solution.stress_resultants`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..io.files import OutputError
from ..io.results import read_snapshots
from ..problem import analytic
from ..problem.drive import drive_of, friction_factor, has_profiles, mismatch
from ..simulation.solution import stress_resultants
from ..solvers.settings import resolve
from .common import offscreen, panel_axes
from .frames import blit_frames, ffmpeg_available, write_frames

__all__ = ["animate", "ffmpeg_available", "frame_fields", "scheme_label"]

MAX_FRAMES = 150
# (key, axis label) of the panels, top to bottom
PANELS = (("friction", "friction f [N/m]"), ("tension", "tension T [N]"),
          ("moment", "moment M [N m]"), ("theta", "angle theta [rad]"),
          ("u", "displacement u [m]"))


def frame_fields(snaps: dict) -> dict:
    """The five panel fields for every snapshot.

    Parameters
    ----------
    snaps : dict
        :func:`beltsim.io.results.read_snapshots` of a run.

    Returns
    -------
    dict of str to numpy.ndarray
        ``friction``, ``tension``, ``moment``, ``theta``, ``u``, each (frames, nodes).
    """
    P = snaps["scene"].params
    he = np.diff(snaps["x"])
    u = snaps["u"].astype(float)
    th = snaps["theta"].astype(float)
    return {"friction": snaps["friction"].astype(float), **stress_resultants(P, u, th, he),
            "theta": th, "u": u}


def scheme_label(scene) -> str:
    """The scheme and the damping a transient was computed with, for every frame.

    Parameters
    ----------
    scene : Scene

    Returns
    -------
    str
        E.g. ``"esdirk3 (time-accurate), damping 39 1/s"``.
    """
    from .. import solvers
    from ..solvers.settings import resolve

    name = resolve(scene).integrator
    kind = "time-accurate" if solvers.get(name).time_accurate else "pseudo-transient path"
    damping = scene.params.damping
    text = f"{name} ({kind}), damping {damping:g} 1/s" if scene.params.inertia else (
        f"{name} ({kind}), quasistatic")
    acceleration = resolve(scene).acceleration
    if acceleration:
        text += f" + numerical acceleration {acceleration:.3g} 1/s"
    return text


def _limits(values, exact):
    lo = min(np.nanmin(values), np.nanmin(exact))
    hi = max(np.nanmax(values), np.nanmax(exact))
    pad = 0.06 * (hi - lo or abs(hi) or 1.0)
    return lo - pad, hi + pad


def animate(snapshots_path, out_path, fmt: str = "gif", fps: int = 15) -> Path:
    """Render the transient stored in ``snapshots_path`` to ``out_path`` (GIF or MP4).

    Parameters
    ----------
    snapshots_path : str or Path
        A run's ``snapshots.npz``.
    out_path : str or Path
        The file to write (atomically).
    fmt : {"gif", "mp4"}, optional
    fps : int, optional
        Frames per second.

    Returns
    -------
    Path

    Raises
    ------
    OutputError
        An unknown format, or a file that is not a snapshots file.
    """
    if fmt not in ("gif", "mp4"):
        raise OutputError(f"--format: must be gif or mp4, got {fmt!r}")
    snaps = read_snapshots(snapshots_path)
    scene = snaps["scene"]
    P = scene.params
    fields = frame_fields(snaps)
    x, times = snaps["x"], snaps["t"]
    frames = np.unique(np.linspace(0, len(times) - 1, min(len(times), MAX_FRAMES)).astype(int))
    try:
        exact = analytic.solve(scene)
        xe, fe = exact.sample(801)
    except analytic.NoSolutionError:
        exact, xe, fe = None, None, None

    # the discrete force layer at x2 (perfect adhesion) is off any sensible scale: clip
    # the friction axis at 1.5 x the exact distributed traction (or f*) and mark it
    f_cap = 1.5 * (np.max(np.abs(fe["friction"])) if fe is not None else
                   np.nanmax(np.abs(fields["friction"])))
    if P.fstar is not None:
        f_cap = max(f_cap, 1.2 * P.fstar)

    with offscreen():  # a figure for a file: no window, no backend
        fig, axes, _ = panel_axes(None, len(PANELS), figsize=(8, 9.5), sharex=True)
    lines, marks = {}, None
    for ax, (key, label) in zip(axes, PANELS):
        ax.axvspan(P.x1, P.x2, color="0.92", zorder=0)
        ref = fe[key] if fe is not None else np.zeros(1)
        if key == "friction":
            ax.set_ylim(-f_cap, f_cap) if np.min(fields[key]) < 0 or P.e0 < 0 else \
                ax.set_ylim(-0.1 * f_cap, f_cap)
        else:
            ax.set_ylim(*_limits(fields[key], ref))
        if fe is not None:
            ax.plot(xe, fe[key], "--", color="k", lw=1.0, label="analytic steady state")
        (lines[key],) = ax.plot(x, fields[key][0], color="tab:red", lw=1.4, label="simulation")
        ax.set_ylabel(label, fontsize=9)
        ax.grid(True, alpha=0.3)
        if key == "friction":
            (marks,) = ax.plot([], [], "^", color="tab:red", ms=6, label="off scale")
            if exact is not None and exact.model == "stick":
                ax.text(0.01, 0.9, f"concentrated force at x2 (exact): "
                        f"{exact.concentrated_force:.0f} N", transform=ax.transAxes,
                        fontsize=8)
            ax.legend(loc="upper left", fontsize=8, bbox_to_anchor=(0.0, 0.82))
    axes[-1].set_xlabel("x [m]")
    stamp = axes[0].set_title("", fontsize=10)
    how = scheme_label(scene)
    fig.suptitle(scene.title or "beltsim transient", fontsize=11)

    # a drive that changes after its start-up names its values on each frame
    drive = drive_of(scene, resolve(scene).ramp_time)
    P = scene.params
    varies = has_profiles(scene)

    def drive_text(t):
        if not varies:
            return ""
        text = f"   v = {P.c + mismatch(drive, t):.4g} m/s"
        if P.fstar is not None:
            text += f", f* = {P.fstar * friction_factor(drive, t):.3g} N/m"
        return text

    def draw(k):
        for key, line in lines.items():
            line.set_ydata(fields[key][k])
        f = fields["friction"][k]
        off = np.abs(f) > f_cap
        marks.set_data(x[off], np.sign(f[off]) * f_cap * 0.97)
        stamp.set_text(f"t = {1e3 * times[k]:.2f} ms{drive_text(times[k])}   {how}")
        return [*lines.values(), marks, stamp]

    return write_frames(out_path, blit_frames(fig, draw, frames,
                                              moving=[*lines.values(), marks, stamp]), fps)
