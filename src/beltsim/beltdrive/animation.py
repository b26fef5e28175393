"""The drive's drawing (:mod:`beltsim.beltdrive.drawing`) animated over a run's states:
the belt's tension and slip, the hub loads and, with a tensioner whose arm moves, the
arm, its pulley and the belt's path at each state's angle.

The frames are blitted (:mod:`beltsim.plots.frames`): the figure is drawn once without
what changes, and each frame draws only that on it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from ..plots.common import offscreen, panel_axes
from ..plots.frames import blit_frames, write_frames
from .drawing import DriveDrawing, drawing_size, tension_norm
from .plot_input import drive_layout, loads, mask, nodes, vector


def _arm_layouts(params, travels):
    """With a tensioner's arm travel per frame (rad, from the drawn angle): each frame's
    layout (the arm turned from ``params``' own turn) and the arm (index, pivot, drawn
    centre); without one, (None per frame, None)."""
    if travels is None:
        return None, None
    ten = getattr(params, "tensioner", None)
    if ten is None:
        raise ValueError("frames: 'arm_travel' needs a layout with a tensioner (the "
                         "DriveParams of the run's grid)")
    turn = params.arm_turn
    k = ten.index
    drawn = ten.turned(params.layout, -turn).centres[k]
    layouts = [params.layout if t == turn else ten.turned(params.layout, t - turn)
               for t in travels]
    return layouts, (k, ten.pivot, drawn)


def animate_drive(layout, x, frames, *, times, path, fps=20, dpi=80, roles=None):
    """Animate :func:`~beltsim.beltdrive.drawing.draw_drive` over ``frames`` on one
    colour scale, to a GIF or an MP4.

    Parameters
    ----------
    layout : PulleyLayout, DriveParams or Geometry
        The drive, as for :func:`~beltsim.beltdrive.drawing.draw_drive`: the layout ``x``
        lives on (a run's grid's).
    x : array_like
        The nodes' loop coordinates (m), as for ``draw_drive``.
    frames : sequence of mapping
        One per frame: ``"tension"`` (nodal, N), optionally ``"slip"`` (nodal booleans),
        ``"hub_loads"`` ((n, 2), N; on one scale over the frames, given in every frame
        or in none), ``"arm_travel"`` (rad: a tensioner's arm turned into the belt from
        its drawn angle; in every frame or in none, ``layout`` then the DriveParams with
        the tensioner and its ``arm_turn``; each frame drawn on the layout of its angle,
        the arm as a bar, the drawn one dashed) and the scalars ``"belt_speed"`` (m/s)
        and ``"driven_speed"`` (rad/s, a two-pulley drive's), written in the frame's
        title with the arm's travel.
    times : array_like
        The frames' times (s).
    path : str or Path
        The file to write (atomically): ``.gif`` (Pillow, one palette) or ``.mp4``
        (ffmpeg, from imageio-ffmpeg).
    fps : int, optional
        Frames per second.
    dpi : float, optional
    roles : sequence of str, optional
        As for ``draw_drive``.

    Returns
    -------
    Path

    Raises
    ------
    ValueError
        Another suffix, no frames, a frame whose arrays do not match ``x`` or the
        pulleys, or an arm's travel without a tensioner.
    """
    from pathlib import Path

    path = Path(path)
    if path.suffix.lower() not in (".gif", ".mp4"):
        raise ValueError(f"path: must end in .gif or .mp4, got {path.name!r}")
    params = layout
    layout, roles = drive_layout(layout, roles)
    x = nodes(layout, x)
    frames = list(frames)
    if not frames:
        raise ValueError("frames: needs at least one frame")
    times = vector("times", times, len(frames), "frame")
    tensions, slips, hubs, titles, travels = [], [], [], [], []
    for k, frame in enumerate(frames):
        if not isinstance(frame, Mapping) or "tension" not in frame:
            raise ValueError(f"frames[{k}]: must be a mapping with a 'tension' array")
        tensions.append(vector(f"frames[{k}]['tension']", frame["tension"], len(x)))
        slip = frame.get("slip")
        slips.append(None if slip is None else mask(f"frames[{k}]['slip']", slip, len(x)))
        for key in ("hub_loads", "arm_travel"):
            if (frame.get(key) is None) != (frames[0].get(key) is None):
                raise ValueError(f"frames[{k}]: {key!r} in every frame or in none")
        hubs.append(None if frame.get("hub_loads") is None else
                    loads(f"frames[{k}]['hub_loads']", frame["hub_loads"], len(layout)))
        text = f"t = {times[k]:.4g} s"
        if frame.get("belt_speed") is not None:
            text += f"    belt speed c = {float(frame['belt_speed']):.4g} m/s"
        if frame.get("driven_speed") is not None:
            text += f"    driven speed ω2 = {float(frame['driven_speed']):.4g} rad/s"
        if frame.get("arm_travel") is not None:
            beta = float(frame["arm_travel"])
            travels.append(beta)
            text += (f"\narm travel β = {beta:.4g} rad ({math.degrees(beta):.3g}°) from "
                     f"the drawn arm (dashed)")
        titles.append(text)
    layouts, arm = _arm_layouts(params, travels or None)
    lo = min(float(T.min()) for T in tensions)
    hi = max(float(T.max()) for T in tensions)
    hub_max = None if hubs[0] is None else max(
        float(np.max(np.hypot(F[:, 0], F[:, 1]))) for F in hubs)

    with offscreen():  # a figure for a file: no window, no backend
        fig, (ax,), _ = panel_axes(None, 1, figsize=drawing_size(layout))
    # the labels keep clear of the last frame's hub loads (the state the run ends in)
    drawing = DriveDrawing(ax, layout, x, tension_norm(lo, hi), roles=roles,
                           hub_max=hub_max, hub_loads=hubs[-1], arm=arm)
    fig.colorbar(drawing.belt, ax=ax, label="belt tension N [N]", shrink=0.9)
    drawing.legend(ax)
    stamp = ax.set_title("\n" if layouts else "", fontsize=10)

    def draw(k):
        drawing.show(tensions[k], slips[k], hubs[k],
                     layout=None if layouts is None else layouts[k])
        stamp.set_text(titles[k])

    moving = [*drawing.moving(layout=layouts is not None), stamp]
    return write_frames(path, blit_frames(fig, draw, range(len(frames)), moving, dpi=dpi),
                        fps)


__all__ = ["animate_drive"]
