"""Pictures of a closed belt drive: the drive to scale, its fields along the loop and its
history (its characteristic curve and its slip arcs against mu:
:mod:`beltsim.beltdrive.characteristic`).

Every function works on plain arrays, so that a simulation's results and the analytic
steady states (:func:`beltsim.beltdrive.analytic.solve_string`) draw alike: ``x`` holds
the loop coordinates of the nodes (periodic, increasing in [0, Lambda), no duplicate end
point) and each field one value per node. The figures follow
:mod:`beltsim.plots.common`: an optional ``ax``, the Figure returned, plain Figures
inside :func:`~beltsim.plots.common.offscreen` (save one with
:func:`~beltsim.plots.common.save_figure`).

Bad input (mismatched lengths, nodes outside the loop) raises a one-line ValueError
naming the argument and the rule.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from ..io.files import atomic_path
from ..plots.common import offscreen, panel_axes
from ..plots.run import EXACT_STYLE, RUN_STYLE
from .geometry import SEGMENTS

#: The belt's colours (tension, N) and the slip arcs' contrasting marking.
TENSION_CMAP = "viridis"
SLIP_COLOR = "tab:red"
#: Radial gap between the belt and the slip arcs' marking, as a fraction of the drive's
#: length C + R1 + R2 (the same fraction of the drawing whatever the drive's size).
SLIP_OFFSET = 0.016
#: Points along the loop the belt's path is drawn with (the nodes are added to them).
PATH_SAMPLES = 1200
#: Points the analytic curves are sampled at.
ANALYTIC_SAMPLES = 2001
SEGMENT_NAMES = {"driver": "driver arc", "slack": "slack span", "driven": "driven arc",
                 "tight": "tight span"}
# the contact arcs shaded in the colour of their pulley's label; the spans are left white
SEGMENT_SHADES = {"driver": "tab:blue", "driven": "tab:orange"}
LOOP_PANELS = (("tension", "tension N [N]"), ("friction", "friction f [N/m]"))
# history panels, top to bottom: (keys sharing the panel, axis label)
HISTORY_PANELS = ((("belt_speed",), "belt speed c [m/s]"),
                  (("driven_speed",), "driven speed ω2 [rad/s]"),
                  (("speed_ratio",), "speed ratio ω2R2 / ω1R1 [-]"),
                  (("tight_tension", "slack_tension"), "span tension [N]"),
                  (("driver_torque", "load_torque"), "torque [N m]"))
HISTORY_LINES = {"belt_speed": ("belt speed", "tab:red"),
                 "driven_speed": ("driven pulley", "tab:red"),
                 "speed_ratio": ("speed ratio", "tab:red"),
                 "tight_tension": ("tight span", "tab:red"),
                 "slack_tension": ("slack span", "tab:blue"),
                 "driver_torque": ("driver torque M1", "tab:red"),
                 "load_torque": ("load torque M2", "tab:blue")}
CURVE_SAMPLES = 201


# ---------------------------------------------------------------------------
# input checks


def vector(name, values, n=None, per="node") -> np.ndarray:
    """``values`` as a 1-D array of finite floats (``n`` of them, one per ``per``)."""
    try:
        a = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: must be an array of numbers") from None
    if a.ndim != 1:
        raise ValueError(f"{name}: must be one-dimensional, got shape {a.shape}")
    if n is not None and len(a) != n:
        raise ValueError(f"{name}: {len(a)} values for {n} {per}s (one per {per})")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: must be finite (holds NaN or inf)")
    return a


def _mask(name, values, n) -> np.ndarray:
    """A boolean mask of ``n`` nodes (booleans, or integers 0 and 1)."""
    m = np.asarray(values)
    if m.ndim != 1 or len(m) != n:
        raise ValueError(f"{name}: {m.size} values of shape {m.shape} for {n} nodes (one "
                         f"boolean per node)")
    if m.dtype != bool:
        if m.dtype.kind not in "iu" or not np.all((m == 0) | (m == 1)):
            raise ValueError(f"{name}: must be booleans (or 0 and 1), got dtype {m.dtype}")
        m = m.astype(bool)
    return m


def _nodes(geometry, x) -> np.ndarray:
    """The loop's node coordinates: increasing in [0, Lambda), at least three."""
    x = vector("x", x)
    lam = geometry.loop_length
    if len(x) < 3:
        raise ValueError(f"x: needs at least 3 nodes on the loop, got {len(x)}")
    if not np.all(np.diff(x) > 0):
        raise ValueError("x: the nodes must increase strictly along the loop")
    if x[0] < 0 or not x[-1] < lam:
        raise ValueError(f"x: nodes must lie in [0, {lam:.6g}) m, the loop without its "
                         f"end point, got [{x[0]:.6g}, {x[-1]:.6g}]")
    return x


def curve(name, spec, at, grid):
    """An analytic curve: a callable sampled on ``grid``, or an array beside ``at``."""
    if callable(spec):
        return grid, np.array([float(spec(v)) for v in grid])
    return at, vector(name, spec, len(at), "point")


def analytic_parts(name, analytic, keys) -> dict:
    """The analytic curves given (a mapping with some of ``keys``)."""
    if analytic is None:
        return {}
    if not isinstance(analytic, Mapping):
        raise ValueError(f"{name}: must be a mapping with keys {', '.join(keys)}, got "
                         f"{type(analytic).__name__}")
    unknown = [k for k in analytic if k not in keys]
    if unknown:
        raise ValueError(f"{name}: unknown key {unknown[0]!r} (known: {', '.join(keys)})")
    return dict(analytic)


# ---------------------------------------------------------------------------
# the drive to scale


def _outward(geometry, xs) -> np.ndarray:
    """Unit normals (2, n) pointing away from the loop's inside at loop coordinates xs.

    The belt runs counter-clockwise, so the outward normal is the tangent turned
    clockwise; the path is smooth (the spans are the pulleys' tangents), so a central
    difference gives the tangent everywhere.
    """
    d = 1e-7 * geometry.loop_length
    xa, ya = geometry.path(xs + d)
    xb, yb = geometry.path(xs - d)
    tx, ty = xa - xb, ya - yb
    norm = np.hypot(tx, ty)
    return np.array([ty / norm, -tx / norm])


def _slip_runs(x, slip, lam) -> list[tuple[float, float]]:
    """The loop intervals (a, b) of the slipping nodes' cells, b > a (b may pass Lambda).

    A node's cell reaches halfway to each neighbour, so a run of slipping nodes is drawn
    from halfway before its first node to halfway after its last: the stick/slip boundary
    lies somewhere between a sticking and a slipping node.
    """
    n = len(x)
    xe = np.concatenate([[x[-1] - lam], x, [x[0] + lam]])
    lo = 0.5 * (xe[:-2] + xe[1:-1])
    hi = 0.5 * (xe[1:-1] + xe[2:])
    if slip.all():
        return [(lo[0], lo[0] + lam)]
    if not slip.any():
        return []
    # start the scan at a sticking node so that no run wraps round the end of the arrays
    k = int(np.argmin(slip))
    order = np.roll(np.arange(n), -k)
    wrapped = lam * (order < k)
    lo, hi, on = lo[order] + wrapped, hi[order] + wrapped, slip[order].astype(int)
    edges = np.diff(np.concatenate([[0], on, [0]]))
    starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1
    return [(float(lo[a]), float(hi[b])) for a, b in zip(starts, ends)]


def _drawing_size(geometry) -> tuple[float, float]:
    """A figure size (in) that fits the drive's aspect with a colorbar beside it."""
    R1, R2, C = geometry.R1, geometry.R2, geometry.C
    pad = _pad(geometry)
    width = C + R1 + R2 + 2 * pad
    height = 2 * max(R1, R2) + 2 * pad
    return 10.0, float(np.clip(8.2 * height / width + 1.0, 3.5, 9.0))


def _pad(geometry) -> float:
    return 0.14 * (geometry.C + geometry.R1 + geometry.R2)


def _norm(lo, hi):
    """The colour scale from lo to hi (N); a uniform tension (a belt at rest) gets 1 N
    either side, as a scale of zero width has no colours."""
    from matplotlib.colors import Normalize

    return Normalize(lo, hi) if hi > lo else Normalize(lo - 1.0, hi + 1.0)


class _DriveDrawing:
    """The artists of one drawing of a drive, redrawn in place for each frame."""

    def __init__(self, ax, geometry, x, norm, rim_speeds=None):
        from matplotlib.collections import LineCollection
        from matplotlib.patches import Circle, FancyArrowPatch

        self.geometry, self.x = geometry, x
        R1, R2, C = geometry.R1, geometry.R2, geometry.C
        lam = geometry.loop_length
        scale = C + R1 + R2
        self.offset = SLIP_OFFSET * scale
        self.ds = lam / PATH_SAMPLES

        names = ("driver", "driven")
        speeds = (None, None) if rim_speeds is None else tuple(
            vector("rim_speeds", rim_speeds, 2, "pulley"))
        for (cx, R), name, v in zip(((0.0, R1), (C, R2)), names, speeds):
            ax.add_patch(Circle((cx, 0.0), R, facecolor="0.93", edgecolor="0.35", lw=1.2,
                                zorder=1, gid=f"pulley {name}"))
            ax.plot([cx], [0.0], "+", color="0.25", ms=9, mew=1.2, zorder=2)
            # a curved arrow inside the pulley: both turn counter-clockwise with the belt
            r, a1, a2 = 0.62 * R, math.radians(35.0), math.radians(145.0)
            ax.add_patch(FancyArrowPatch(
                (cx + r * math.cos(a1), r * math.sin(a1)),
                (cx + r * math.cos(a2), r * math.sin(a2)),
                connectionstyle="arc3,rad=0.5", arrowstyle="-|>", mutation_scale=11,
                color="0.35", lw=1.1, zorder=2))
            text = name if v is None else f"{name}\nrim {v:.4g} m/s"
            ax.text(cx, -0.3 * R, text, ha="center", va="top", fontsize=9.5,
                    fontweight="bold", color="0.2", zorder=6)

        # the belt: fine pieces of its path, each coloured by the tension at its middle
        # (linear between the nodes)
        xf = np.union1d(x, np.linspace(x[0], x[0] + lam, PATH_SAMPLES + 1))
        X, Y = geometry.path(xf)
        pts = np.column_stack([X, Y])
        self.mid = 0.5 * (xf[:-1] + xf[1:])
        self.belt = LineCollection(np.stack([pts[:-1], pts[1:]], axis=1), cmap=TENSION_CMAP,
                                   norm=norm, linewidths=6.0, capstyle="round", zorder=3,
                                   gid="belt")
        self.belt.set_array(np.zeros(len(self.mid)))
        ax.add_collection(self.belt)
        (self.slip,) = ax.plot([], [], color=SLIP_COLOR, lw=3.0, solid_capstyle="butt",
                               zorder=4, gid="slip",
                               label="slip arc (the belt slides on the rim)")

        # the belt's motion on each span, and the span's mean tension beside it
        self.spans = {}
        e = geometry.bounds
        for k, name in ((1, "slack"), (3, "tight")):
            xm = 0.5 * (e[k] + e[k + 1])
            half = 0.1 * geometry.span
            (xa, xb), (ya, yb) = geometry.path(np.array([xm - half, xm + half]))
            nx, ny = _outward(geometry, np.array([xm]))[:, 0]
            shift = 3.0 * self.offset
            ax.add_patch(FancyArrowPatch((xa + shift * nx, ya + shift * ny),
                                         (xb + shift * nx, yb + shift * ny),
                                         arrowstyle="-|>", mutation_scale=16, lw=1.6,
                                         color="0.2", zorder=5, gid="motion"))
            xt, yt = geometry.path(np.array([xm]))
            on = (geometry.segment_of(x) == k)
            label = ax.text(xt[0] + 5.5 * self.offset * nx, yt[0] + 5.5 * self.offset * ny,
                            "", ha="center", va="bottom" if ny > 0 else "top",
                            fontsize=9.5, zorder=6)
            self.spans[name] = (on, label)

        pad = _pad(geometry)
        ax.set_xlim(-R1 - pad, C + R2 + pad)
        ax.set_ylim(-max(R1, R2) - pad, max(R1, R2) + pad)
        ax.set_aspect("equal")
        ax.set_xlabel("[m]")
        ax.set_ylabel("[m]")
        ax.tick_params(labelsize=8)

    def show(self, tension, slip):
        """Draw one state: the nodal tension (N) and the slip mask (None: no slip drawn)."""
        lam = self.geometry.loop_length
        self.belt.set_array(np.interp(self.mid, self.x, tension, period=lam))
        runs = [] if slip is None else _slip_runs(self.x, slip, lam)
        px, py = [], []
        for a, b in runs:
            xs = np.linspace(a, b, max(2, math.ceil((b - a) / self.ds) + 1))
            X, Y = self.geometry.path(xs)
            n = _outward(self.geometry, xs)
            px += [X + self.offset * n[0], [np.nan]]
            py += [Y + self.offset * n[1], [np.nan]]
        self.slip.set_data(np.concatenate(px) if px else [], np.concatenate(py) if py else [])
        for name, (on, label) in self.spans.items():
            text = f"{name} side"
            if on.any():
                text += f", mean {np.mean(tension[on]):.4g} N"
            label.set_text(text)


def draw_drive(geometry, x, tension, slip=None, *, ax=None, title=None, rim_speeds=None,
               tension_range=None):
    """The drive to scale, its belt coloured by the tension, the slip arcs marked.

    The driver's centre is at the origin, the driven pulley's at (C, 0); the belt runs
    counter-clockwise (arrows), the tight span on top. A red line just outside the belt
    marks where it slips on the rims (the nodes of ``slip``); the rest of each arc sticks.

    Parameters
    ----------
    geometry : beltsim.beltdrive.geometry.Geometry
    x : array_like
        The nodes' loop coordinates (m): increasing in [0, Lambda), no duplicate end point.
    tension : array_like
        The belt's tension N (N) at the nodes (linear between them in the drawing).
    slip : array_like of bool, optional
        Which nodes slip on their pulley; default none marked.
    ax : Axes, optional
        Where to draw (a colorbar is added beside it); default a new figure.
    title : str, optional
        The axes' title.
    rim_speeds : (float, float), optional
        The rims' speeds omega1 R1 and omega2 R2 (m/s), written under the pulleys' names.
    tension_range : (float, float), optional
        The colour scale's limits (N); default the tension's range.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ValueError
        Nodes outside the loop or out of order, or arrays of other lengths than ``x``.
    """
    from matplotlib.colors import Normalize

    x = _nodes(geometry, x)
    tension = vector("tension", tension, len(x))
    slip = None if slip is None else _mask("slip", slip, len(x))
    if tension_range is None:
        norm = _norm(tension.min(), tension.max())
    else:
        lo, hi = vector("tension_range", tension_range, 2, "limit")
        if not hi > lo:
            raise ValueError(f"tension_range: must be (low, high) with low < high, got "
                             f"({lo:g}, {hi:g})")
        norm = Normalize(lo, hi)
    fig, (ax,), _ = panel_axes(ax, 1, figsize=_drawing_size(geometry))
    drawing = _DriveDrawing(ax, geometry, x, norm, rim_speeds)
    drawing.show(tension, slip)
    fig.colorbar(drawing.belt, ax=ax, label="belt tension N [N]", shrink=0.9)
    if slip is not None and slip.any():
        ax.legend(handles=[drawing.slip], loc="upper center", fontsize=8.5, frameon=False)
    if title:
        ax.set_title(title, fontsize=10)
    return fig


# ---------------------------------------------------------------------------
# along the loop


def _analytic_loop(analytic, geometry):
    """Loop coordinates to sample an analytic solution at: fine, with each breakpoint
    (segment ends, stick ends) and points just either side of it, as values may jump
    there (a jump is then drawn upright, to its full height)."""
    lam = geometry.loop_length
    breaks = np.concatenate([geometry.bounds, list(getattr(analytic, "stick_ends", ()))])
    inner = breaks[(breaks > 0) & (breaks < lam)]
    eps = 1e-9 * lam
    return np.union1d(np.linspace(0.0, lam, ANALYTIC_SAMPLES), np.concatenate(
        [inner - eps, inner, inner + eps]))


def plot_loop_fields(x, fields, geometry, *, analytic=None, ax=None):
    """Tension and friction along the loop coordinate, the loop's segments shaded.

    Parameters
    ----------
    x : array_like
        The nodes' loop coordinates (m): increasing in [0, Lambda), no duplicate end point.
    fields : mapping of str to array_like
        Nodal values: ``"tension"`` (N) and/or ``"friction"`` (N/m); other keys are left
        out. One panel each, in that order.
    geometry : beltsim.beltdrive.geometry.Geometry
    analytic : object, optional
        An analytic steady state with methods ``tension(x)`` and ``friction(x)`` (e.g.
        :class:`~beltsim.beltdrive.analytic.StringSolution`), drawn dashed; its
        ``stick_ends`` (where the slip arcs begin), if it has them, are marked.
    ax : Axes or sequence of Axes, optional
        One per panel; default a new figure with the panels stacked.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ValueError
        No tension or friction given, arrays of other lengths than ``x``, or ``ax`` with
        another number of Axes than panels.
    """
    from matplotlib.transforms import blended_transform_factory

    x = _nodes(geometry, x)
    if not isinstance(fields, Mapping):
        raise ValueError(f"fields: must be a mapping of field names to nodal arrays, got "
                         f"{type(fields).__name__}")
    panels = [(k, label) for k, label in LOOP_PANELS if k in fields]
    if not panels:
        raise ValueError("fields: needs 'tension' or 'friction' (nodal arrays)")
    values = {k: vector(f"fields[{k!r}]", fields[k], len(x)) for k, _ in panels}
    fig, axes, own = panel_axes(ax, len(panels), figsize=(9.0, 1.6 + 2.6 * len(panels)),
                                sharex=True)
    lam, e = geometry.loop_length, geometry.bounds
    xs = _analytic_loop(analytic, geometry) if analytic is not None else None
    ends = np.asarray(getattr(analytic, "stick_ends", ()), dtype=float)
    # the loop closes: the first node is drawn again at x0 + Lambda
    xc = np.append(x, x[0] + lam)
    marker = "o" if len(x) <= 200 else None
    for ax_, (key, label) in zip(axes, panels):
        for k, name in enumerate(SEGMENTS):
            if name in SEGMENT_SHADES:
                ax_.axvspan(e[k], e[k + 1], color=SEGMENT_SHADES[name], alpha=0.09, lw=0,
                            zorder=0)
        for b in e[1:-1]:
            ax_.axvline(b, color="0.6", lw=0.8, zorder=1)
        ax_.plot(xc, np.append(values[key], values[key][0]), marker=marker, ms=3.0,
                 label="simulation" if analytic is not None else "nodal values",
                 **(RUN_STYLE | {"lw": 1.2}))
        if analytic is not None:
            curve = getattr(analytic, key)
            ax_.plot(xs, curve(xs), label="analytic steady state", **EXACT_STYLE, zorder=4)
            if len(ends):
                ax_.plot(ends, curve(ends), "D", color="k", ms=5, zorder=5,
                         label="analytic start of the slip arcs")
        ax_.set_ylabel(label, fontsize=9)
        ax_.grid(True, alpha=0.3)
    top = axes[0]
    trans = blended_transform_factory(top.transData, top.transAxes)
    for k, name in enumerate(SEGMENTS):
        top.text(0.5 * (e[k] + e[k + 1]), 1.02, SEGMENT_NAMES[name], transform=trans,
                 ha="center", va="bottom", fontsize=9,
                 color=SEGMENT_SHADES.get(name, "0.3"), fontweight="bold")
    axes[-1].set_xlim(0.0, lam)
    axes[-1].set_xlabel("loop coordinate x [m] (in the belt's direction of motion, from "
                        "the driver arc's entry)")
    axes[-1].legend(fontsize=8, loc="best")
    if own:
        fig.suptitle("tension and friction along the belt loop", fontsize=10)
    return fig


# ---------------------------------------------------------------------------
# over time


def plot_drive_history(t, history, *, ax=None, steady=None):
    """The drive's quantities over time: belt speed, driven speed, speed ratio, span
    tensions and torques, one panel for each group the history holds.

    Parameters
    ----------
    t : array_like
        Times (s).
    history : mapping of str to array_like
        Arrays beside ``t`` under the keys ``belt_speed``, ``driven_speed``,
        ``speed_ratio``, ``tight_tension``, ``slack_tension``, ``driver_torque``,
        ``load_torque`` (those present are drawn; other keys are left out).
    ax : Axes or sequence of Axes, optional
        One per panel; default a new figure.
    steady : mapping of str to float, optional
        Steady values to mark dashed under the same keys (e.g. the analytic solution's
        :meth:`~beltsim.beltdrive.analytic.StringSolution.summary`).

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ValueError
        None of the keys above, arrays of other lengths than ``t``, or ``ax`` with another
        number of Axes than panels.
    """
    t = vector("t", t, per="time")
    if not isinstance(history, Mapping):
        raise ValueError(f"history: must be a mapping of names to arrays, got "
                         f"{type(history).__name__}")
    panels = [(tuple(k for k in keys if k in history), label)
              for keys, label in HISTORY_PANELS]
    panels = [(keys, label) for keys, label in panels if keys]
    if not panels:
        known = ", ".join(k for keys, _ in HISTORY_PANELS for k in keys)
        raise ValueError(f"history: holds none of {known}")
    steady = {} if steady is None else dict(steady)
    fig, axes, own = panel_axes(ax, len(panels), figsize=(9.0, 1.2 + 1.9 * len(panels)),
                                sharex=True)
    marker = "." if len(t) <= 40 else None
    for ax_, (keys, label) in zip(axes, panels):
        for key in keys:
            name, color = HISTORY_LINES[key]
            y = vector(f"history[{key!r}]", history[key], len(t), "time")
            # a panel of one line is named by its axis; its legend tells only the styles
            ax_.plot(t, y, color=color, lw=1.6, marker=marker,
                     label=name if len(keys) > 1 else "history")
            if steady.get(key) is not None:
                ax_.axhline(steady[key], color=color, ls="--", lw=1.0,
                            label=f"{name}: steady state" if len(keys) > 1 else
                            "steady state")
        ax_.set_ylabel(label, fontsize=9)
        ax_.grid(True, alpha=0.3)
        if len(keys) > 1 or any(steady.get(k) is not None for k in keys):
            ax_.legend(fontsize=8, loc="best")
    axes[-1].set_xlabel("t [s]")
    if len(t):
        axes[-1].set_xlim(t[0], t[-1] if t[-1] > t[0] else t[0] + 1.0)
    if own:
        fig.suptitle("drive history", fontsize=10)
    return fig


def animate_drive(geometry, x, frames, *, times, path, fps=20, dpi=80):
    """Animate :func:`draw_drive` over ``frames`` on one colour scale, to a GIF or an MP4.

    Parameters
    ----------
    geometry : beltsim.beltdrive.geometry.Geometry
    x : array_like
        The nodes' loop coordinates (m), as for :func:`draw_drive`.
    frames : sequence of mapping
        One per frame: ``"tension"`` (nodal, N), optionally ``"slip"`` (nodal booleans)
        and the scalars ``"belt_speed"`` (m/s) and ``"driven_speed"`` (rad/s), written in
        the frame's title.
    times : array_like
        The frames' times (s).
    path : str or Path
        The file to write (atomically): ``.gif`` (Pillow) or ``.mp4`` (ffmpeg, from
        imageio-ffmpeg).
    fps : int, optional
        Frames per second.
    dpi : float, optional

    Returns
    -------
    Path

    Raises
    ------
    ValueError
        Another suffix, no frames, or a frame whose arrays do not match ``x``.
    """
    import matplotlib
    from matplotlib import animation

    path = Path(path)
    fmt = path.suffix.lower()
    if fmt not in (".gif", ".mp4"):
        raise ValueError(f"path: must end in .gif or .mp4, got {path.name!r}")
    x = _nodes(geometry, x)
    frames = list(frames)
    if not frames:
        raise ValueError("frames: needs at least one frame")
    times = vector("times", times, len(frames), "frame")
    tensions, slips, titles = [], [], []
    for k, frame in enumerate(frames):
        if not isinstance(frame, Mapping) or "tension" not in frame:
            raise ValueError(f"frames[{k}]: must be a mapping with a 'tension' array")
        tensions.append(vector(f"frames[{k}]['tension']", frame["tension"], len(x)))
        slip = frame.get("slip")
        slips.append(None if slip is None else _mask(f"frames[{k}]['slip']", slip, len(x)))
        text = f"t = {times[k]:.4g} s"
        if frame.get("belt_speed") is not None:
            text += f"    belt speed c = {float(frame['belt_speed']):.4g} m/s"
        if frame.get("driven_speed") is not None:
            text += f"    driven speed ω2 = {float(frame['driven_speed']):.4g} rad/s"
        titles.append(text)
    lo = min(float(T.min()) for T in tensions)
    hi = max(float(T.max()) for T in tensions)

    with offscreen():  # a figure for a file: no window, no backend
        fig, (ax,), _ = panel_axes(None, 1, figsize=_drawing_size(geometry))
    drawing = _DriveDrawing(ax, geometry, x, _norm(lo, hi))
    fig.colorbar(drawing.belt, ax=ax, label="belt tension N [N]", shrink=0.9)
    ax.legend(handles=[drawing.slip], loc="upper center", fontsize=8.5, frameon=False)
    stamp = ax.set_title("", fontsize=10)

    def draw(k):
        drawing.show(tensions[k], slips[k])
        stamp.set_text(titles[k])

    with atomic_path(path, suffix=fmt) as tmp:
        anim = animation.FuncAnimation(fig, draw, frames=len(frames), blit=False)
        settings = {}
        if fmt == ".gif":
            writer = animation.PillowWriter(fps=fps)
        else:
            import imageio_ffmpeg
            # for this save only: the user's rcParams stay as they are
            settings["animation.ffmpeg_path"] = imageio_ffmpeg.get_ffmpeg_exe()
            # libx264 takes only even frame sizes: pad an odd one by a pixel
            writer = animation.FFMpegWriter(fps=fps, codec="libx264", extra_args=[
                "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-pix_fmt", "yuv420p"])
        with matplotlib.rc_context(settings):
            anim.save(tmp, writer=writer, dpi=dpi)
    return path


# ---------------------------------------------------------------------------
# sweeps


__all__ = ["animate_drive", "draw_drive", "plot_drive_history", "plot_loop_fields"]
