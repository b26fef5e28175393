"""The drive drawn to scale, on any layout: its pulleys (back-side idlers on the belt's
outer face), the belt coloured by its tension, the slip arcs, the hub loads and the
pulleys' names, a tensioner's arm (animated over a run's snapshots by
:mod:`beltsim.beltdrive.animation`).

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

import numpy as np

from ..plots.common import panel_axes
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


def carried(base, layout, xs) -> np.ndarray:
    """Loop coordinates xs on ``base`` carried over to ``layout`` (the same pulleys, one
    of them moved: a tensioner's arm turned), segment by segment: a point a fraction of
    the way along an arc or a span of ``base`` goes as far along that of ``layout``. The
    loop model takes the arm's change of the loop length up as a stretch of the grid on
    the spans (:mod:`beltsim.physics.arm`); the drawing spreads it over each segment."""
    xs = np.asarray(xs, dtype=float)
    if layout is base:
        return xs
    lam = base.loop_length
    turns = np.floor(xs / lam)
    r = xs - lam * turns
    k = base.segment_of(r)
    lengths = np.diff(base.bounds)
    to = np.diff(layout.bounds)
    return (layout.bounds[k] + (r - base.bounds[k]) * to[k] / lengths[k]
            + layout.loop_length * turns)


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
    hub_loads : ndarray, optional
        (n, 2) (N): the labels are placed clear of these hub loads' arrows.
    arm : (int, pivot, drawn), optional
        A tensioner's arm: its pulley's index, its pivot and where the scene draws the
        pulley's centre (m): the arm as a bar to the pulley, the drawn one dashed.

    ``x`` lives on ``layout``; :meth:`show` may draw a state on another layout of the same
    pulleys (the tensioner's arm turned), the nodes :func:`carried` over to it, the
    labels where they were placed on ``layout``.
    """

    def __init__(self, ax, layout, x, norm, *, roles=None, rim_speeds=None, hub_max=None,
                 hub_loads=None, arm=None):
        from matplotlib.collections import LineCollection

        self.layout, self.base, self.x = layout, layout, x
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
        self.xf = np.union1d(x, np.linspace(x[0], x[0] + lam, PATH_SAMPLES + 1))
        self.mid = 0.5 * (self.xf[:-1] + self.xf[1:])
        self.belt = LineCollection(self._belt_pieces(), cmap=TENSION_CMAP,
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
        self.pulleys = [self._pulley(ax, i, None if rim_speeds is None else rim_speeds[i])
                        for i in range(n)]
        self.hubs = [] if self.hub_scale is None else [self._hub(ax, i) for i in range(n)]
        self.arm = None if arm is None else self._arm(ax, *arm)

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
        disc = ax.add_patch(Circle((cx, cy), r, facecolor=BACK_FACE if back else INNER_FACE,
                                   edgecolor="0.35", lw=1.2, zorder=1, gid=f"pulley {name}"))
        (hub,) = ax.plot([cx], [cy], "+", color="0.25", ms=7, mew=1.0, zorder=2)
        spin = int(g.spin[i])
        arrow = ax.add_patch(FancyArrowPatch(
            *self._spin_ends(i), connectionstyle=f"arc3,rad={0.5 * spin}",
            arrowstyle="-|>", mutation_scale=8, color="0.35", lw=1.0, zorder=2, gid="spin"))
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
        label = ax.text(at[0], at[1], text, fontsize=PULLEY_FONT, fontweight="bold",
                        color="0.2", zorder=6, ha=ha, va=va, gid="pulley name")
        return disc, hub, arrow, label

    def _spin_ends(self, i):
        """The ends of the curved arrow inside pulley i in its running sense (a back-side
        idler turns against the inner pulleys), over its top either way."""
        g = self.layout
        (cx, cy), r = g.centres[i], g.radii[i]
        a1, a2 = math.radians(35.0), math.radians(145.0)
        if g.spin[i] < 0:
            a1, a2 = a2, a1
        return ((cx + 0.62 * r * math.cos(a1), cy + 0.62 * r * math.sin(a1)),
                (cx + 0.62 * r * math.cos(a2), cy + 0.62 * r * math.sin(a2)))

    def _belt_pieces(self) -> np.ndarray:
        """The belt's fine pieces (pieces, 2, 2) on the layout drawn."""
        X, Y = self.layout.path(carried(self.base, self.layout, self.xf))
        pts = np.column_stack([X, Y])
        return np.stack([pts[:-1], pts[1:]], axis=1)

    def _span_arrow(self, j):
        """The ends of the arrow beside span j's middle in the belt's direction, and the
        span's outward normal there."""
        g = self.layout
        xm = 0.5 * (g.bounds[2 * j + 1] + g.bounds[2 * j + 2])
        half = 0.1 * g.spans[j]
        (xa, xb), (ya, yb) = g.path(np.array([xm - half, xm + half]))
        nx, ny = outward(g, np.array([xm]))[:, 0]
        shift = 3.0 * self.offset
        return ((xa + shift * nx, ya + shift * ny), (xb + shift * nx, yb + shift * ny),
                (nx, ny))

    def _arm(self, ax, k, pivot, drawn):
        """A tensioner's arm from its pivot to pulley k's centre, and dashed where the
        scene draws it (its travel between the two)."""
        pivot = np.asarray(pivot, dtype=float)
        ax.plot(*np.column_stack([pivot, drawn]), color="0.55", lw=1.5, ls="--", zorder=5,
                gid="arm drawn")
        (bar,) = ax.plot(*np.column_stack([pivot, self.layout.centres[k]]), color="0.25",
                         lw=4.0, zorder=5, solid_capstyle="round", gid="arm",
                         label="tensioner arm (drawn: dashed)")
        ax.plot(*pivot, marker="o", ms=7, mfc="white", mec="0.25", zorder=6)
        return k, pivot, bar

    def place(self, layout):
        """Move the drawing onto ``layout``, the same pulleys as the one it was made on
        with one moved (a tensioner's arm turned): the belt's path, the pulleys, the
        spans' arrows and the arm (the labels stay where they were placed)."""
        if layout is self.layout:
            return
        self.layout = layout
        self.belt.set_segments(self._belt_pieces())
        for i, (disc, hub, arrow, _) in enumerate(self.pulleys):
            c = layout.centres[i]
            disc.set_center(tuple(c))
            hub.set_data([c[0]], [c[1]])
            arrow.set_positions(*self._spin_ends(i))
        for _, _, _, arrow, j in self.spans:
            arrow.set_positions(*self._span_arrow(j)[:2])
        if self.arm is not None:
            k, pivot, bar = self.arm
            bar.set_data(*np.column_stack([pivot, layout.centres[k]]))

    def moving(self, layout=False) -> list:
        """The artists :meth:`show` changes, in the order they are drawn: with
        ``layout``, those :meth:`place` moves too (and the pulleys' names, drawn over
        them)."""
        out = [self.belt, self.slip, *(a for _, _, label, _, _ in self.spans
                                        for a in [label])]
        out += [a for pair in self.hubs for a in pair]
        if layout:
            out += [a for p in self.pulleys for a in p]
            out += [arrow for _, _, _, arrow, _ in self.spans]
            if self.arm is not None:
                out.append(self.arm[2])
        return sorted(out, key=lambda a: a.get_zorder())

    def _span(self, ax, j, name):
        """The belt's motion on span j (an arrow beside it) and a label for its mean
        tension; returns (the nodes on the span, the label)."""
        from matplotlib.patches import FancyArrowPatch

        g = self.layout
        e, k = g.bounds, 2 * j + 1
        a, b, (nx, ny) = self._span_arrow(j)
        arrow = ax.add_patch(FancyArrowPatch(a, b, arrowstyle="-|>", mutation_scale=14,
                                             lw=1.4, color="0.2", zorder=5, gid="motion"))
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
        return g.segment_of(self.x) == k, name, label, arrow, j

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

    def show(self, tension, slip, hub_loads=None, layout=None):
        """Draw one state: the nodal tension (N), the slip mask (None: no slip drawn),
        the hub loads (n, 2) (N; None leaves the arrows as they are) and the layout
        (None: as it is; another, :meth:`place`)."""
        if layout is not None:
            self.place(layout)
        g = self.layout
        lam = self.base.loop_length
        self.belt.set_array(np.interp(self.mid, self.x, tension, period=lam))
        runs = [] if slip is None else slip_runs(self.x, slip, lam)
        px, py = [], []
        for a, b in runs:
            xs = carried(self.base, g, np.linspace(a, b, max(2, math.ceil((b - a) / self.ds)
                                                             + 1)))
            X, Y = g.path(xs)
            # away from the pulley the belt slips on: outwards on an inner pulley, into
            # the loop on a back-side idler
            seg = g.segment_of(xs)
            side = np.where(seg % 2 == 0, g.sides[seg // 2], 1)
            n = outward(g, xs) * side
            px += [X + self.offset * n[0], [np.nan]]
            py += [Y + self.offset * n[1], [np.nan]]
        self.slip.set_data(np.concatenate(px) if px else [], np.concatenate(py) if py else [])
        for on, name, label, _, _ in self.spans:
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
               tension_range=None, hub_loads=None, roles=None, arm=None, at=None):
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
        A tensioner's arm: its pivot, the pulley's centre in the layout drawn (``at``,
        else ``layout``) and where the scene draws it (m, (x, y) each): the arm as a
        bar, the drawn one dashed.
    at : PulleyLayout or DriveParams, optional
        The layout to draw the state on where it is not the one ``x`` lives on: the same
        pulleys with a tensioner's arm turned (a transient's grid is laid with the arm
        at its rest angle; its state has the arm elsewhere). The nodes are
        :func:`carried` over to it.

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
    moved = None if at is None else drive_layout(at, roles)[0]
    if moved is not None and (len(moved) != n or moved.names != layout.names):
        raise ValueError("at: must be the same pulleys as the layout, in its order")
    drawn = moved if moved is not None else layout
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
    if arm is not None:
        pivot, centre, where = (np.asarray(q, dtype=float) for q in arm)
        # the arm's pulley: the one at ``centre``
        k = int(np.argmin(np.hypot(*(drawn.centres - centre).T)))
        arm = (k, pivot, where)
    drawing = DriveDrawing(ax, layout, x, norm, roles=roles, rim_speeds=rims,
                           hub_max=hub_max, hub_loads=hubs, arm=arm)
    drawing.show(tension, slip, hubs, layout=moved)
    fig.colorbar(drawing.belt, ax=ax, label="belt tension N [N]", shrink=0.9)
    drawing.legend(ax, slip=slip is not None and bool(slip.any()))
    if title:
        # a scene's title may be long: wrapped to the drawing's width, not cut off
        ax.set_title(textwrap.fill(title, int(10.0 * fig.get_size_inches()[0])), fontsize=10)
    return fig


__all__ = ["DriveDrawing", "carried", "draw_drive", "slip_runs"]
