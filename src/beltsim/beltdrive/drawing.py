"""The drive drawn to scale, on any layout: its pulleys (back-side idlers on the belt's
outer face), the belt coloured by its tension, the slip arcs, the hub loads and the
pulleys' names; and that drawing animated over a run's snapshots.

One code path draws every drive from its :class:`~beltsim.beltdrive.pulleys.PulleyLayout`
(the two-pulley drive is the layout of two inner pulleys:
:func:`~beltsim.beltdrive.plot_input.drive_layout`). Every function works on plain arrays
(``x`` holds the loop coordinates of the nodes, periodic and increasing in
[0, Lambda), no duplicate end point; each field one value per node) and follows
:mod:`beltsim.plots.common`: an optional ``ax``, the Figure returned, plain Figures
inside :func:`~beltsim.plots.common.offscreen`.
"""

from __future__ import annotations

import math
import textwrap
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from ..io.files import atomic_path
from ..plots.common import offscreen, panel_axes
from .plot_input import drive_layout, loads, mask, nodes, span_names, vector

#: The belt's colours (tension, N) and the slip arcs' contrasting marking.
TENSION_CMAP = "viridis"
SLIP_COLOR = "tab:red"
HUB_COLOR = "tab:purple"
#: Gap between the belt and the slip arcs' marking, as a fraction of the layout's size
#: (the larger side of its bounding box): the same fraction of any drawing.
SLIP_OFFSET = 0.016
#: The largest hub load's arrow, as a fraction of the layout's size.
HUB_ARROW = 0.16
#: Points along the loop the belt's path is drawn with (the nodes are added to them).
PATH_SAMPLES = 1200
#: The drawing's room (in) beside the colorbar, and the figure's limits.
DRAWING_WIDTH, DRAWING_HEIGHT = 8.2, 8.0
INNER_FACE, BACK_FACE = "0.93", "0.82"
#: A span shorter than this fraction of the layout's size gets no arrow and no label (a
#: back-side idler's short spans would crowd it).
SHORT_SPAN = 0.2
#: The directions a pulley's name is tried in, round its centre.
LABEL_DIRECTIONS = 16
PULLEY_FONT, SPAN_FONT, HUB_FONT = 9.0, 8.5, 8.0
#: A label this many slip-marking gaps clear of everything else is placed there.
LABEL_CLEARANCE = 1.5


def outward(layout, xs) -> np.ndarray:
    """Unit normals (2, n) pointing away from the loop's inside at loop coordinates xs.

    The path is smooth (the spans are the pulleys' tangents), so a central difference
    gives the tangent t everywhere; the inside lies on the left of a belt running
    counterclockwise (``layout.sense`` +1) and on its right otherwise.
    """
    d = 1e-7 * layout.loop_length
    xa, ya = layout.path(xs + d)
    xb, yb = layout.path(xs - d)
    tx, ty = xa - xb, ya - yb
    norm = np.hypot(tx, ty) / layout.sense
    return np.array([ty / norm, -tx / norm])


def slip_runs(x, slip, lam) -> list[tuple[float, float]]:
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


def extent(layout) -> tuple[np.ndarray, np.ndarray, float]:
    """The layout's bounding box (low corner, high corner, m) and its size (its larger
    side), which every length of the drawing is a fraction of."""
    r = layout.radii[:, None]
    lo = np.min(layout.centres - r, axis=0)
    hi = np.max(layout.centres + r, axis=0)
    return lo, hi, float(np.max(hi - lo))


def drawing_size(layout) -> tuple[float, float]:
    """A figure size (in) that fits the layout's bounding box, padded, at its aspect,
    with a colorbar beside it and the legend below."""
    lo, hi, size = extent(layout)
    w, h = hi - lo + 2.0 * pad(layout)
    s = min(DRAWING_WIDTH / w, DRAWING_HEIGHT / h)
    return float(max(s * w + 1.8, 5.0)), float(np.clip(s * h + 1.0, 3.5, 9.5))


def pad(layout) -> float:
    """The margin round the layout's bounding box (m): room for the labels."""
    return 0.18 * extent(layout)[2]


def tension_norm(lo, hi):
    """The colour scale from lo to hi (N); a uniform tension (a belt at rest) gets 1 N
    either side, as a scale of zero width has no colours."""
    from matplotlib.colors import Normalize

    return Normalize(lo, hi) if hi > lo else Normalize(lo - 1.0, hi + 1.0)


def _text_box(at, u, lines, m_per_pt, fontsize) -> np.ndarray:
    """Points (9, 2) on the box of a text of ``lines`` anchored at ``at`` and aligned
    away from it along u (as :func:`_align` aligns it): its corners, edges' middles and
    centre, roughly (a glyph taken 0.6 of the font size wide)."""
    w = max(len(t) for t in lines) * 0.6 * fontsize * m_per_pt
    h = len(lines) * 1.25 * fontsize * m_per_pt
    ha, va = _align(u)
    x0 = at[0] - {"left": 0.0, "center": 0.5, "right": 1.0}[ha] * w
    y0 = at[1] - {"bottom": 0.0, "center": 0.5, "top": 1.0}[va] * h
    fx, fy = np.meshgrid([0.0, 0.5, 1.0], [0.0, 0.5, 1.0])
    return np.column_stack([x0 + w * fx.ravel(), y0 + h * fy.ravel()])


def _align(u) -> tuple[str, str]:
    """The alignment that puts a text on the side u of its anchor."""
    return ("left" if u[0] > 0.35 else "right" if u[0] < -0.35 else "center",
            "bottom" if u[1] > 0.35 else "top" if u[1] < -0.35 else "center")


class _Clearance:
    """How far points are from what is drawn already: the belt, the pulleys, the hub
    loads' arrows and the texts placed (m; negative inside a pulley)."""

    def __init__(self, layout, belt_width, limits):
        X, Y = layout.path(np.linspace(0.0, layout.loop_length, 400, endpoint=False))
        self.points = [np.column_stack([X, Y])]
        self.belt_width = belt_width
        self.layout = layout
        self.limits = limits

    def add(self, points):
        self.points.append(np.asarray(points, dtype=float).reshape(-1, 2))

    def of(self, q) -> float:
        g = self.layout
        to_rims = np.hypot(*(q[:, None, :] - g.centres[None]).transpose(2, 0, 1)) - g.radii
        known = np.concatenate(self.points)
        near = np.hypot(*(q[:, None, :] - known[None]).transpose(2, 0, 1))
        lo, hi = self.limits
        inside = np.min(np.concatenate([q - lo, hi - q], axis=1))  # < 0: cut off
        return float(min(to_rims.min(), near.min() - self.belt_width, 3.0 * inside))


class DriveDrawing:
    """The artists of one drawing of a drive, redrawn in place for each frame.

    Parameters
    ----------
    ax : Axes
    layout : PulleyLayout
    x : ndarray
        The nodes' loop coordinates (checked).
    norm : Normalize
        The tension's colour scale.
    roles : tuple of str, optional
        Name the tight and the slack span.
    rim_speeds : ndarray, optional
        One per pulley (m/s), written under its name.
    hub_max : float, optional
        The hub load (N) drawn HUB_ARROW of the layout's size long; None: no hub loads.
    """

    def __init__(self, ax, layout, x, norm, *, roles=None, rim_speeds=None, hub_max=None,
                 hub_loads=None):
        from matplotlib.collections import LineCollection

        self.layout, self.x = layout, x
        lam = layout.loop_length
        lo, hi, size = extent(layout)
        self.offset = SLIP_OFFSET * size
        self.ds = lam / PATH_SAMPLES
        n = len(layout)
        w, h = hi - lo + 2.0 * pad(layout)
        # metres per point of the drawing at its figure size (drawing_size)
        self.m_per_pt = max(w / DRAWING_WIDTH, h / DRAWING_HEIGHT) / 72.0
        p = pad(layout)
        self.limits = (lo - p, hi + p)
        self.clear = _Clearance(layout, 2.0 * self.offset, self.limits)
        self.hub_scale = None if not hub_max else HUB_ARROW * size / hub_max
        if self.hub_scale is not None and hub_loads is not None:
            for c, F in zip(layout.centres, hub_loads):
                tip = c + self.hub_scale * F
                self.clear.add(c + np.outer(np.linspace(0.2, 1.0, 6), tip - c))
                u, at = self._hub_text_at(c, F)
                self.clear.add(_text_box(at, u, ["0000 N"], self.m_per_pt, HUB_FONT))

        # the belt: fine pieces of its path, each coloured by the tension at its middle
        # (linear between the nodes)
        xf = np.union1d(x, np.linspace(x[0], x[0] + lam, PATH_SAMPLES + 1))
        X, Y = layout.path(xf)
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
        self.spans = [self._span(ax, j, name)
                      for j, name in enumerate(span_names(layout, roles))
                      if layout.spans[j] >= SHORT_SPAN * size]
        # the pulleys' names last: each where it is clearest of all the rest
        for i in range(n):
            self._pulley(ax, i, None if rim_speeds is None else rim_speeds[i])
        self.hubs = [] if self.hub_scale is None else [self._hub(ax, i) for i in range(n)]

        ax.set_xlim(self.limits[0][0], self.limits[1][0])
        ax.set_ylim(self.limits[0][1], self.limits[1][1])
        ax.set_aspect("equal")
        ax.set_xlabel("[m]")
        ax.set_ylabel("[m]")
        ax.tick_params(labelsize=8)

    def _pulley(self, ax, i, rim):
        """Pulley i, its running sense and its name, placed where it is clearest."""
        from matplotlib.patches import Circle, FancyArrowPatch

        g = self.layout
        (cx, cy), r, name = g.centres[i], g.radii[i], g.names[i]
        back = g.sides[i] < 0
        ax.add_patch(Circle((cx, cy), r, facecolor=BACK_FACE if back else INNER_FACE,
                            edgecolor="0.35", lw=1.2, zorder=1, gid=f"pulley {name}"))
        ax.plot([cx], [cy], "+", color="0.25", ms=7, mew=1.0, zorder=2)
        # a curved arrow inside the pulley in its running sense (a back-side idler turns
        # against the inner pulleys), over its top either way
        a1, a2 = math.radians(35.0), math.radians(145.0)
        spin = int(g.spin[i])
        if spin < 0:
            a1, a2 = a2, a1
        ax.add_patch(FancyArrowPatch(
            (cx + 0.62 * r * math.cos(a1), cy + 0.62 * r * math.sin(a1)),
            (cx + 0.62 * r * math.cos(a2), cy + 0.62 * r * math.sin(a2)),
            connectionstyle=f"arc3,rad={0.5 * spin}", arrowstyle="-|>", mutation_scale=8,
            color="0.35", lw=1.0, zorder=2, gid="spin"))
        text = name + ("\n(back side)" if back else "")
        if rim is not None:
            text += f"\nrim {rim:.4g} m/s"
        lines = text.split("\n")
        # beside the wrap's middle, beyond the belt, unless something else is there: the
        # directions tried from that side round, the first clear enough taken
        mid = g.bounds[2 * i] + 0.5 * g.arcs[i]
        wx, wy = (np.concatenate(g.path(np.array([mid]))) - (cx, cy)) / r
        turns = np.linspace(0.0, 2.0 * math.pi, LABEL_DIRECTIONS, endpoint=False)
        turns = turns[np.argsort(np.abs(np.angle(np.exp(1j * turns))))]
        candidates = []
        for a in math.atan2(wy, wx) + turns:
            u = np.array([math.cos(a), math.sin(a)])
            candidates.append((np.array([cx, cy]) + (r + 4.0 * self.offset) * u, u))
        at, u, box = self._clearest(candidates, lines, PULLEY_FONT)
        self.clear.add(box)
        ha, va = _align(u)
        ax.text(at[0], at[1], text, fontsize=PULLEY_FONT, fontweight="bold", color="0.2",
                zorder=6, ha=ha, va=va, gid="pulley name")

    def _span(self, ax, j, name):
        """The belt's motion on span j (an arrow beside it) and a label for its mean
        tension; returns (the nodes on the span, the label)."""
        from matplotlib.patches import FancyArrowPatch

        g = self.layout
        e, k = g.bounds, 2 * j + 1
        xm = 0.5 * (e[k] + e[k + 1])
        half = 0.1 * g.spans[j]
        (xa, xb), (ya, yb) = g.path(np.array([xm - half, xm + half]))
        nx, ny = outward(g, np.array([xm]))[:, 0]
        shift = 3.0 * self.offset
        ax.add_patch(FancyArrowPatch((xa + shift * nx, ya + shift * ny),
                                     (xb + shift * nx, yb + shift * ny),
                                     arrowstyle="-|>", mutation_scale=14, lw=1.4,
                                     color="0.2", zorder=5, gid="motion"))
        lines = [name, "mean 00000 N"] if name else ["00000 N"]
        # outside the loop at the span's middle, or further along it, or inside, where
        # the outside is crowded or cut off
        candidates = []
        for sign in (1.0, -1.0):
            for frac in (0.5, 0.3, 0.7):
                xt, yt = g.path(np.array([e[k] + frac * g.spans[j]]))
                u = sign * np.array([nx, ny])
                candidates.append((np.array([xt[0], yt[0]]) + 5.5 * self.offset * u, u))
        at, u, box = self._clearest(candidates, lines, SPAN_FONT)
        ha, va = _align(u)
        label = ax.text(at[0], at[1], "", ha=ha, va=va, fontsize=SPAN_FONT, zorder=6,
                        gid="span tension")
        return g.segment_of(self.x) == k, name, label

    def _clearest(self, candidates, lines, fontsize):
        """The first of ``candidates`` (anchor, direction) whose text box is clear by
        LABEL_CLEARANCE of the belt's gap, else the clearest; (anchor, direction, box),
        the box then taken."""
        enough = LABEL_CLEARANCE * self.offset
        best = None
        for at, u in candidates:
            box = _text_box(at, u, lines, self.m_per_pt, fontsize)
            score = min(self.clear.of(box), enough)
            if best is None or score > best[0]:
                best = (score, at, u, box)
            if score >= enough:
                break
        _, at, u, box = best
        self.clear.add(box)
        return at, u, box

    def _hub(self, ax, i):
        from matplotlib.patches import FancyArrowPatch

        c = tuple(self.layout.centres[i])
        arrow = FancyArrowPatch(c, c, arrowstyle="-|>", mutation_scale=14, lw=2.0,
                                color=HUB_COLOR, zorder=5, gid="hub load")
        ax.add_patch(arrow)
        text = ax.text(*c, "", fontsize=HUB_FONT, color=HUB_COLOR, zorder=6,
                       gid="hub load value")
        return arrow, text

    def _hub_text_at(self, c, F):
        """The direction of a hub load and where its magnitude is written: past its
        arrow's tip."""
        u = F / max(np.hypot(*F), 1e-300)
        return u, c + self.hub_scale * F + 1.5 * self.offset * u

    def show(self, tension, slip, hub_loads=None):
        """Draw one state: the nodal tension (N), the slip mask (None: no slip drawn) and
        the hub loads (n, 2) (N; None leaves the arrows as they are)."""
        g = self.layout
        lam = g.loop_length
        self.belt.set_array(np.interp(self.mid, self.x, tension, period=lam))
        runs = [] if slip is None else slip_runs(self.x, slip, lam)
        px, py = [], []
        for a, b in runs:
            xs = np.linspace(a, b, max(2, math.ceil((b - a) / self.ds) + 1))
            X, Y = g.path(xs)
            # away from the pulley the belt slips on: outwards on an inner pulley, into
            # the loop on a back-side idler
            seg = g.segment_of(xs)
            side = np.where(seg % 2 == 0, g.sides[seg // 2], 1)
            n = outward(g, xs) * side
            px += [X + self.offset * n[0], [np.nan]]
            py += [Y + self.offset * n[1], [np.nan]]
        self.slip.set_data(np.concatenate(px) if px else [], np.concatenate(py) if py else [])
        for on, name, label in self.spans:
            text = f"{name}\nmean " if name else ""
            if on.any():
                text += f"{np.mean(tension[on]):.4g} N"
            label.set_text(text.removesuffix("\nmean "))
        if hub_loads is not None and self.hubs:
            for (arrow, text), c, F in zip(self.hubs, g.centres, hub_loads):
                arrow.set_positions(tuple(c), tuple(c + self.hub_scale * F))
                u, at = self._hub_text_at(c, F)
                text.set_position(at)
                ha, va = _align(u)
                text.set_ha(ha)
                text.set_va(va)
                text.set_text(f"{np.hypot(*F):.4g} N")

    def legend(self, ax, slip=True):
        """A legend below the axes of the slip arcs' marking and the hub loads'
        arrows, those drawn."""
        from matplotlib.lines import Line2D

        handles = [self.slip] if slip else []
        if self.hubs:
            handles.append(Line2D([], [], color=HUB_COLOR, lw=2.0, marker=">",
                                  label="hub load (the belt's force on the bearing)"))
        if handles:
            ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.09),
                      ncol=len(handles), fontsize=8.5, frameon=False)


def draw_drive(layout, x, tension, slip=None, *, ax=None, title=None, rim_speeds=None,
               tension_range=None, hub_loads=None, roles=None, arm=None):
    """The drive to scale, its belt coloured by the tension, the slip arcs marked.

    The pulleys are drawn where the layout puts them, each named beside its wrap (the
    back-side idlers shaded darker, on the belt's outer face); an arrow inside each shows
    its running sense and one beside each span the belt's motion, with the span's mean
    tension. A red line just outside the belt marks where it slips on the rims (the
    nodes of ``slip``); the rest of each arc sticks.

    Parameters
    ----------
    layout : PulleyLayout, DriveParams or Geometry
        The drive (:func:`~beltsim.beltdrive.plot_input.drive_layout`: a two-pulley
        Geometry is drawn as its layout, the driver's centre at the origin).
    x : array_like
        The nodes' loop coordinates (m): increasing in [0, Lambda), no duplicate end point.
    tension : array_like
        The belt's tension N (N) at the nodes (linear between them in the drawing).
    slip : array_like of bool, optional
        Which nodes slip on their pulley; default none marked.
    ax : Axes, optional
        Where to draw (a colorbar is added beside it); default a new figure sized from
        the layout's bounding box.
    title : str, optional
        The axes' title.
    rim_speeds : array_like, optional
        Each pulley's rim speed omega r (m/s), written under its name.
    tension_range : (float, float), optional
        The colour scale's limits (N); default the tension's range.
    hub_loads : array_like, optional
        Each pulley's hub load (Fx, Fy) (N), the belt's force on its bearing (a run's
        ``summary()["pulleys"][i]["hub_load"]``): an arrow from the centre, the largest
        HUB_ARROW of the layout's size long, its magnitude at its tip.
    roles : sequence of str, optional
        The pulleys' roles, to name the tight and the slack span (known already from a
        DriveParams or a Geometry).
    arm : (pivot, centre, drawn), optional
        A tensioner's arm: its pivot, the pulley's centre in this layout and where the
        scene draws it (m, (x, y) each): the arm as a bar, the drawn one dashed.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ValueError
        Nodes outside the loop or out of order, or arrays of other lengths than ``x`` or
        than the pulleys.
    """
    from matplotlib.colors import Normalize

    layout, roles = drive_layout(layout, roles)
    n = len(layout)
    x = nodes(layout, x)
    tension = vector("tension", tension, len(x))
    slip = None if slip is None else mask("slip", slip, len(x))
    rims = None if rim_speeds is None else vector("rim_speeds", rim_speeds, n, "pulley")
    hubs = None if hub_loads is None else loads("hub_loads", hub_loads, n)
    if tension_range is None:
        norm = tension_norm(tension.min(), tension.max())
    else:
        lo, hi = vector("tension_range", tension_range, 2, "limit")
        if not hi > lo:
            raise ValueError(f"tension_range: must be (low, high) with low < high, got "
                             f"({lo:g}, {hi:g})")
        norm = Normalize(lo, hi)
    fig, (ax,), _ = panel_axes(ax, 1, figsize=drawing_size(layout))
    hub_max = None if hubs is None else float(np.max(np.hypot(hubs[:, 0], hubs[:, 1])))
    drawing = DriveDrawing(ax, layout, x, norm, roles=roles, rim_speeds=rims,
                           hub_max=hub_max, hub_loads=hubs)
    drawing.show(tension, slip, hubs)
    if arm is not None:
        _draw_arm(ax, *(np.asarray(q, dtype=float) for q in arm))
    fig.colorbar(drawing.belt, ax=ax, label="belt tension N [N]", shrink=0.9)
    drawing.legend(ax, slip=slip is not None and bool(slip.any()))
    if title:
        # a scene's title may be long: wrapped to the drawing's width, not cut off
        ax.set_title(textwrap.fill(title, int(10.0 * fig.get_size_inches()[0])), fontsize=10)
    return fig


def _draw_arm(ax, pivot, centre, drawn):
    """A tensioner's arm from its pivot to the pulley's centre, and dashed where the
    scene draws it (its travel between the two)."""
    ax.plot(*np.column_stack([pivot, drawn]), color="0.55", lw=1.5, ls="--", zorder=5)
    ax.plot(*np.column_stack([pivot, centre]), color="0.25", lw=4.0, zorder=5,
            solid_capstyle="round", gid="arm", label="tensioner arm (drawn: dashed)")
    ax.plot(*pivot, marker="o", ms=7, mfc="white", mec="0.25", zorder=6)


def animate_drive(layout, x, frames, *, times, path, fps=20, dpi=80, roles=None):
    """Animate :func:`draw_drive` over ``frames`` on one colour scale, to a GIF or an MP4.

    Parameters
    ----------
    layout : PulleyLayout, DriveParams or Geometry
        The drive, as for :func:`draw_drive`.
    x : array_like
        The nodes' loop coordinates (m), as for :func:`draw_drive`.
    frames : sequence of mapping
        One per frame: ``"tension"`` (nodal, N), optionally ``"slip"`` (nodal booleans),
        ``"hub_loads"`` ((n, 2), N; on one scale over the frames, given in every frame
        or in none) and the scalars ``"belt_speed"`` (m/s) and ``"driven_speed"``
        (rad/s, a two-pulley drive's), written in the frame's title.
    times : array_like
        The frames' times (s).
    path : str or Path
        The file to write (atomically): ``.gif`` (Pillow) or ``.mp4`` (ffmpeg, from
        imageio-ffmpeg).
    fps : int, optional
        Frames per second.
    dpi : float, optional
    roles : sequence of str, optional
        As for :func:`draw_drive`.

    Returns
    -------
    Path

    Raises
    ------
    ValueError
        Another suffix, no frames, or a frame whose arrays do not match ``x`` or the
        pulleys.
    """
    import matplotlib
    from matplotlib import animation

    path = Path(path)
    fmt = path.suffix.lower()
    if fmt not in (".gif", ".mp4"):
        raise ValueError(f"path: must end in .gif or .mp4, got {path.name!r}")
    layout, roles = drive_layout(layout, roles)
    x = nodes(layout, x)
    frames = list(frames)
    if not frames:
        raise ValueError("frames: needs at least one frame")
    times = vector("times", times, len(frames), "frame")
    tensions, slips, hubs, titles = [], [], [], []
    for k, frame in enumerate(frames):
        if not isinstance(frame, Mapping) or "tension" not in frame:
            raise ValueError(f"frames[{k}]: must be a mapping with a 'tension' array")
        tensions.append(vector(f"frames[{k}]['tension']", frame["tension"], len(x)))
        slip = frame.get("slip")
        slips.append(None if slip is None else mask(f"frames[{k}]['slip']", slip, len(x)))
        if (frame.get("hub_loads") is None) != (frames[0].get("hub_loads") is None):
            raise ValueError(f"frames[{k}]: 'hub_loads' in every frame or in none")
        hubs.append(None if frame.get("hub_loads") is None else
                    loads(f"frames[{k}]['hub_loads']", frame["hub_loads"], len(layout)))
        text = f"t = {times[k]:.4g} s"
        if frame.get("belt_speed") is not None:
            text += f"    belt speed c = {float(frame['belt_speed']):.4g} m/s"
        if frame.get("driven_speed") is not None:
            text += f"    driven speed ω2 = {float(frame['driven_speed']):.4g} rad/s"
        titles.append(text)
    lo = min(float(T.min()) for T in tensions)
    hi = max(float(T.max()) for T in tensions)
    hub_max = None if hubs[0] is None else max(
        float(np.max(np.hypot(F[:, 0], F[:, 1]))) for F in hubs)

    with offscreen():  # a figure for a file: no window, no backend
        fig, (ax,), _ = panel_axes(None, 1, figsize=drawing_size(layout))
    # the labels keep clear of the last frame's hub loads (the state the run ends in)
    drawing = DriveDrawing(ax, layout, x, tension_norm(lo, hi), roles=roles,
                           hub_max=hub_max, hub_loads=hubs[-1])
    fig.colorbar(drawing.belt, ax=ax, label="belt tension N [N]", shrink=0.9)
    drawing.legend(ax)
    stamp = ax.set_title("", fontsize=10)

    def draw(k):
        drawing.show(tensions[k], slips[k], hubs[k])
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


__all__ = ["DriveDrawing", "animate_drive", "draw_drive", "slip_runs"]
