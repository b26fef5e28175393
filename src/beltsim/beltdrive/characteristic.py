"""Pictures of a closed drive's sweeps: its characteristic curve (speed loss and
efficiency against the load) and its slip arcs against the friction coefficient.

Like :mod:`beltsim.beltdrive.plots`, every function works on plain arrays (a sweep's runs
and the analytic steady states draw alike), takes an optional ``ax`` and returns the
Figure; bad input raises a one-line ValueError naming the argument and the rule.
"""

from __future__ import annotations

import math

import numpy as np

from ..plots.common import panel_axes
from ..plots.run import RUN_STYLE
from .plot_input import analytic_parts, curve, vector
from .plots import CURVE_SAMPLES


def plot_characteristic(loads, speed_loss, efficiency, *, capacity=None, analytic=None,
                        ax=None):
    """The drive's characteristic: speed loss and efficiency against the load torque.

    Parameters
    ----------
    loads : array_like
        Load torques M2 (N m).
    speed_loss : array_like
        1 - omega2 R2 / (omega1 R1) at each load (drawn in %).
    efficiency : array_like
        M2 omega2 / (M1 omega1) at each load (drawn in %).
    capacity : float, optional
        The largest load the drive carries (N m): a vertical line, gross slip beyond.
    analytic : mapping, optional
        ``"speed_loss"`` and/or ``"efficiency"``: callables of the load (sampled from 0 to
        the largest load, or to just short of a finite capacity) or arrays beside
        ``loads``; drawn as lines.
    ax : sequence of two Axes, optional
        Default a new figure.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ValueError
        Arrays of other lengths than ``loads``, an unknown analytic key, or ``ax`` with
        another number of Axes than two.
    """
    loads = vector("loads", loads, per="load")
    data = {"speed_loss": vector("speed_loss", speed_loss, len(loads), "load"),
            "efficiency": vector("efficiency", efficiency, len(loads), "load")}
    exact = analytic_parts("analytic", analytic, tuple(data))
    finite_cap = capacity is not None and math.isfinite(capacity)
    top = capacity if finite_cap else (loads.max() if len(loads) else 1.0)
    # no steady state at or beyond the capacity: the curves stop just short of it
    grid = np.linspace(0.0, top * (1 - 1e-6) if finite_cap else top, CURVE_SAMPLES)
    fig, axes, own = panel_axes(ax, 2, figsize=(8.0, 6.5), sharex=True)
    labels = {"speed_loss": "speed loss 1 − ω2R2 / ω1R1 [%]", "efficiency": "efficiency [%]"}
    right = 1.05 * max(loads.max() if len(loads) else 0.0, capacity if finite_cap else 0.0)
    for ax_, key in zip(axes, data):
        if key in exact:
            xs, ys = curve(f"analytic[{key!r}]", exact[key], loads, grid)
            ax_.plot(xs, 100 * ys, color="k", lw=1.2, label="analytic steady state")
        ax_.plot(loads, 100 * data[key], "o", color=RUN_STYLE["color"], ms=5,
                 label="simulation" if exact else None)
        if finite_cap:
            ax_.axvline(capacity, color="tab:red", ls="--", lw=1.2,
                        label=f"capacity {capacity:.4g} N m")
            ax_.axvspan(capacity, right, color="tab:red", alpha=0.08, lw=0,
                        label="gross slip (no steady state)")
        ax_.set_ylabel(labels[key], fontsize=9)
        ax_.grid(True, alpha=0.3)
    axes[0].legend(fontsize=8, loc="best")
    if right > 0:
        axes[-1].set_xlim(0.0, right)
    axes[-1].set_xlabel("load torque M2 [N m]")
    if own:
        fig.suptitle("drive characteristic: speed loss and efficiency against load",
                     fontsize=10)
    return fig


def plot_slip_collapse(mus, slip_arcs_driver, slip_arcs_driven, *, wraps=None,
                       analytic=None, ax=None):
    """The slip arcs on both pulleys against the friction coefficient mu (log scale).

    As mu grows the slip arcs shrink onto the arcs' exits and the drive tends to perfect
    adhesion; a slip arc reaching its wrap angle is gross slip.

    Parameters
    ----------
    mus : array_like
        Friction coefficients (> 0).
    slip_arcs_driver, slip_arcs_driven : array_like
        The slip arcs (rad) at each mu.
    wraps : (float, float), optional
        The wrap angles (rad) of the driver and the driven pulley, drawn as limits.
    analytic : mapping, optional
        ``"driver"`` and/or ``"driven"``: callables of mu (sampled over the range of
        ``mus``) or arrays beside ``mus``; drawn as lines.
    ax : Axes, optional
        Default a new figure.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ValueError
        Arrays of other lengths than ``mus``, a mu <= 0, or an unknown analytic key.
    """
    from matplotlib.ticker import FuncFormatter, LogLocator

    mus = vector("mus", mus, per="mu")
    if len(mus) == 0 or not np.all(mus > 0):
        raise ValueError("mus: needs at least one friction coefficient, each > 0")
    arcs = {"driver": vector("slip_arcs_driver", slip_arcs_driver, len(mus), "mu"),
            "driven": vector("slip_arcs_driven", slip_arcs_driven, len(mus), "mu")}
    exact = analytic_parts("analytic", analytic, tuple(arcs))
    wraps = None if wraps is None else vector("wraps", wraps, 2, "pulley")
    grid = np.geomspace(mus.min(), mus.max(), CURVE_SAMPLES)
    fig, (ax,), own = panel_axes(ax, 1, figsize=(7.5, 4.8))
    styles = {"driver": ("tab:blue", "o", 7), "driven": ("tab:orange", "s", 4)}
    for k, (name, values) in enumerate(arcs.items()):
        color, marker, size = styles[name]
        if name in exact:
            xs, ys = curve(f"analytic[{name!r}]", exact[name], mus, grid)
            ax.plot(xs, ys, color=color, lw=1.3, ls="-" if k == 0 else "--",
                    label=f"{name} pulley: analytic")
        ax.plot(mus, values, marker, color=color, ms=size, mfc="none" if k == 0 else color,
                mew=1.4, label=f"{name} pulley")
        if wraps is not None:
            ax.axhline(wraps[k], color=color, ls=":", lw=1.2,
                       label=f"{name} wrap {wraps[k]:.3g} rad (gross slip)")
    ax.set_xscale("log")
    # plain numbers (0.2, 0.5, 1, 2, ...) read better than powers of ten over a decade or two
    ax.xaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    ax.set_ylim(bottom=0.0)
    ax.set_xlabel("friction coefficient μ")
    ax.set_ylabel("slip arc [rad]")
    ax.secondary_yaxis("right", functions=(np.degrees, np.radians)).set_ylabel(
        "slip arc [°]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    if own:
        ax.set_title("slip arcs collapse onto the arcs' exits as μ grows", fontsize=10)
    return fig


__all__ = ["plot_characteristic", "plot_slip_collapse"]
