"""Pictures of a closed belt drive on any layout: its fields along the loop and its
history (the drive to scale and its animation: :mod:`beltsim.beltdrive.drawing`; its
characteristic curve and its slip arcs against mu: :mod:`beltsim.beltdrive.characteristic`).

Every function works on plain arrays, so that a simulation's results and the exact
steady states (:func:`beltsim.beltdrive.exact.string_state`) draw alike: ``x`` holds
the loop coordinates of the nodes (periodic, increasing in [0, Lambda), no duplicate end
point) and each field one value per node. The drive is a
:class:`~beltsim.beltdrive.pulleys.PulleyLayout` (or what
:func:`~beltsim.beltdrive.plot_input.drive_layout` reads as one: a drive's parameters, a
two-pulley Geometry), two pulleys or N. The figures follow :mod:`beltsim.plots.common`:
an optional ``ax``, the Figure returned, plain Figures inside
:func:`~beltsim.plots.common.offscreen` (save one with
:func:`~beltsim.plots.common.save_figure`).

Bad input (mismatched lengths, nodes outside the loop) raises a one-line ValueError
naming the argument and the rule.
"""

from __future__ import annotations

import re
from collections.abc import Mapping

import numpy as np

from ..plots.common import panel_axes
from ..plots.run import EXACT_STYLE, RUN_STYLE
from .animation import animate_drive
from .drawing import draw_drive
from .plot_input import drive_layout, nodes, span_names, vector

#: Points the analytic curves are sampled at.
ANALYTIC_SAMPLES = 2001
#: Samples of a characteristic's analytic curves (:mod:`beltsim.beltdrive.characteristic`).
CURVE_SAMPLES = 201
#: Pulley i's colour (its arc's shade, its lines in a history): matplotlib's cycle.
PULLEY_COLORS = tuple(f"C{i}" for i in range(10))
#: Above this many pulleys the segments' labels are turned, to fit over narrow arcs.
UPRIGHT_LABELS = 3
LOOP_PANELS = (("tension", "tension N [N]"), ("friction", "friction f [N/m]"))
# history panels, top to bottom: (a two-pulley drive's keys sharing the panel, the
# N-pulley family drawn instead when the history holds it, the axis label)
HISTORY_PANELS = ((("belt_speed",), None, "belt speed c [m/s]"),
                  (("driven_speed",), "speed", "pulley speed ω [rad/s]"),
                  (("speed_ratio",), None, "speed ratio ω2R2 / ω1R1 [-]"),
                  (("tight_tension", "slack_tension"), "tension", "span tension [N]"),
                  (("driver_torque", "load_torque"), "torque", "torque [N m]"),
                  (("arm_travel",), None, "tensioner arm travel β [rad]"))
HISTORY_LINES = {"belt_speed": ("belt speed", "tab:red"),
                 "driven_speed": ("driven pulley", "tab:red"),
                 "speed_ratio": ("speed ratio", "tab:red"),
                 "tight_tension": ("tight span", "tab:red"),
                 "slack_tension": ("slack span", "tab:blue"),
                 "driver_torque": ("driver torque M1", "tab:red"),
                 "load_torque": ("load torque M2", "tab:blue"),
                 "arm_travel": ("arm travel (into the belt, from the drawn angle)",
                                "tab:green")}
#: A panel of more lines than this has its legend beside it, not over the lines.
LEGEND_INSIDE = 3


# ---------------------------------------------------------------------------
# along the loop


def _analytic_loop(analytic, layout):
    """Loop coordinates to sample an analytic solution at: fine, with each breakpoint
    (segment ends, stick ends) and points just either side of it, as values may jump
    there (a jump is then drawn upright, to its full height)."""
    lam = layout.loop_length
    breaks = np.concatenate([layout.bounds, list(getattr(analytic, "stick_ends", ()))])
    inner = breaks[(breaks > 0) & (breaks < lam)]
    eps = 1e-9 * lam
    return np.union1d(np.linspace(0.0, lam, ANALYTIC_SAMPLES), np.concatenate(
        [inner - eps, inner, inner + eps]))


def _segment_labels(ax, layout, roles):
    """The pulleys' names over their arcs (and, on a few pulleys, the spans' names) in
    the pulleys' colours, above the axes."""
    from matplotlib.transforms import blended_transform_factory

    e, n = layout.bounds, len(layout)
    few = n <= UPRIGHT_LABELS
    trans = blended_transform_factory(ax.transData, ax.transAxes)
    turned = {} if few else {"rotation": 40.0, "rotation_mode": "anchor", "ha": "left"}
    for i, name in enumerate(layout.names):
        back = " (back side)" if layout.sides[i] < 0 else ""
        text = f"{name} arc{back}" if few else name + back
        ax.text(0.5 * (e[2 * i] + e[2 * i + 1]), 1.02, text, transform=trans,
                **({"ha": "center"} | turned), va="bottom", fontsize=9 if few else 8,
                color=PULLEY_COLORS[i % len(PULLEY_COLORS)], fontweight="bold")
    if few:
        for j, name in enumerate(span_names(layout, roles)):
            ax.text(0.5 * (e[2 * j + 1] + e[2 * j + 2]), 1.02, name or "span",
                    transform=trans, ha="center", va="bottom", fontsize=9, color="0.3",
                    fontweight="bold")


def plot_loop_fields(x, fields, layout, *, analytic=None, ax=None, roles=None):
    """Tension and friction along the loop coordinate, each pulley's arc shaded and
    named, the boundaries of the arcs and spans marked.

    Parameters
    ----------
    x : array_like
        The nodes' loop coordinates (m): increasing in [0, Lambda), no duplicate end point.
    fields : mapping of str to array_like
        Nodal values: ``"tension"`` (N) and/or ``"friction"`` (N/m); other keys are left
        out. One panel each, in that order.
    layout : PulleyLayout, DriveParams or Geometry
        The drive (:func:`~beltsim.beltdrive.plot_input.drive_layout`), two pulleys or N.
    analytic : object, optional
        An exact steady state with methods ``tension(x)`` and ``friction(x)`` (e.g.
        :class:`~beltsim.beltdrive.analytic.StringSolution`, or
        :class:`~beltsim.beltdrive.creep.SerpentineSolution` on N pulleys), drawn dashed;
        its ``stick_ends`` (where the slip arcs begin), if it has them, are marked.
    ax : Axes or sequence of Axes, optional
        One per panel; default a new figure with the panels stacked.
    roles : sequence of str, optional
        The pulleys' roles, to name the tight and the slack span on a few pulleys.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ValueError
        No tension or friction given, arrays of other lengths than ``x``, or ``ax`` with
        another number of Axes than panels.
    """
    layout, roles = drive_layout(layout, roles)
    x = nodes(layout, x)
    if not isinstance(fields, Mapping):
        raise ValueError(f"fields: must be a mapping of field names to nodal arrays, got "
                         f"{type(fields).__name__}")
    panels = [(k, label) for k, label in LOOP_PANELS if k in fields]
    if not panels:
        raise ValueError("fields: needs 'tension' or 'friction' (nodal arrays)")
    values = {k: vector(f"fields[{k!r}]", fields[k], len(x)) for k, _ in panels}
    fig, axes, own = panel_axes(ax, len(panels), figsize=(9.0, 1.6 + 2.6 * len(panels)),
                                sharex=True)
    lam, e = layout.loop_length, layout.bounds
    xs = _analytic_loop(analytic, layout) if analytic is not None else None
    ends = np.asarray(getattr(analytic, "stick_ends", ()), dtype=float)
    # the loop closes: the first node is drawn again at x0 + Lambda
    xc = np.append(x, x[0] + lam)
    marker = "o" if len(x) <= 200 else None
    for ax_, (key, label) in zip(axes, panels):
        for i in range(len(layout)):
            ax_.axvspan(e[2 * i], e[2 * i + 1], color=PULLEY_COLORS[i % len(PULLEY_COLORS)],
                        alpha=0.09, lw=0, zorder=0)
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
    _segment_labels(axes[0], layout, roles)
    axes[-1].set_xlim(0.0, lam)
    axes[-1].set_xlabel(f"loop coordinate x [m] (in the belt's direction of motion, from "
                        f"the entry of {layout.names[0]}'s arc)")
    axes[-1].legend(fontsize=8, loc="best")
    if own:
        fig.suptitle("tension and friction along the belt loop", fontsize=10)
    return fig


# ---------------------------------------------------------------------------
# over time


def _family(history, family) -> list[tuple[str, str]]:
    """The keys ``family[NAME]`` of a history in its order, with their NAMEs."""
    if family is None:
        return []
    pattern = re.compile(rf"{re.escape(family)}\[(.+)\]")
    return [(k, m.group(1)) for k in history if (m := pattern.fullmatch(k))]


def _history_panels(history):
    """(lines, label) per panel drawn: lines of (key, name, colour)."""
    panels = []
    for keys, family, label in HISTORY_PANELS:
        members = _family(history, family)
        if members:
            lines = [(k, name, PULLEY_COLORS[i % len(PULLEY_COLORS)])
                     for i, (k, name) in enumerate(members)]
        else:
            lines = [(k, *HISTORY_LINES[k]) for k in keys if k in history]
        if lines:
            panels.append((lines, label))
    return panels


def plot_drive_history(t, history, *, ax=None, steady=None):
    """The drive's quantities over time, one panel for each group the history holds:
    the belt speed, the pulleys' speeds, the speed ratio, the span tensions, the
    torques and a tensioner's arm travel.

    Parameters
    ----------
    t : array_like
        Times (s).
    history : mapping of str to array_like
        Arrays beside ``t``: a two-pulley drive's ``belt_speed``, ``driven_speed``,
        ``speed_ratio``, ``tight_tension``, ``slack_tension``, ``driver_torque``,
        ``load_torque``, or a drive's on N pulleys
        (:func:`~beltsim.beltdrive.figures.figure_keys`): ``speed[A]`` of every pulley,
        ``tension[A-B]`` of every span and ``torque[A]``, which take the place of the
        two-pulley keys of their panel; and a tensioner's ``arm_travel`` (rad). Those
        present are drawn; other keys are left out.
    ax : Axes or sequence of Axes, optional
        One per panel; default a new figure.
    steady : mapping of str to float, optional
        Steady values to mark dashed under the same keys (e.g. the exact steady state's
        ``summary()``).

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
    panels = _history_panels(history)
    if not panels:
        known = [k for keys, _, _ in HISTORY_PANELS for k in keys]
        known += [f"{f}[...]" for _, f, _ in HISTORY_PANELS if f]
        raise ValueError(f"history: holds none of {', '.join(dict.fromkeys(known))}")
    steady = {} if steady is None else dict(steady)
    fig, axes, own = panel_axes(ax, len(panels), figsize=(9.0, 1.2 + 1.9 * len(panels)),
                                sharex=True)
    marker = "." if len(t) <= 40 else None
    for ax_, (lines, label) in zip(axes, panels):
        many = len(lines) > 1
        for key, name, color in lines:
            y = vector(f"history[{key!r}]", history[key], len(t), "time")
            # a panel of one line is named by its axis; its legend tells only the styles
            ax_.plot(t, y, color=color, lw=1.6, marker=marker,
                     label=name if many else "history")
            if steady.get(key) is not None:
                ax_.axhline(steady[key], color=color, ls="--", lw=1.0,
                            label=f"{name}: steady state" if many else "steady state")
        ax_.set_ylabel(label, fontsize=9)
        ax_.grid(True, alpha=0.3)
        if len(lines) > LEGEND_INSIDE:
            # many lines: the legend beside the panel, the steady values' dashes named
            # once
            handles = [h for h in ax_.get_lines() if not h.get_label().endswith(
                ": steady state")]
            ax_.legend(handles=handles, fontsize=7, loc="center left",
                       bbox_to_anchor=(1.01, 0.5), frameon=False)
        elif many or any(steady.get(k) is not None for k, _, _ in lines):
            ax_.legend(fontsize=8, loc="best")
    axes[-1].set_xlabel("t [s]")
    if len(t):
        axes[-1].set_xlim(t[0], t[-1] if t[-1] > t[0] else t[0] + 1.0)
    if own:
        fig.suptitle("drive history" + (" (dashed: the exact steady state)" if steady
                                        else ""), fontsize=10)
    return fig


__all__ = ["animate_drive", "draw_drive", "plot_drive_history", "plot_loop_fields"]
