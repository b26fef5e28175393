"""Figures of studies: error against run time, creep-zone collapse.

Each takes the rows its study returned, an optional ``ax`` (or ``axes``) to draw on, and
returns the Figure; :func:`beltsim.plots.common.save_figure` writes one to a file.
"""

from __future__ import annotations

import textwrap

import numpy as np

from .common import panel_axes

#: the resolutions the CLI saves the two figures at
ERROR_VS_RUNTIME_DPI, CREEP_COLLAPSE_DPI = 130, 110
SCHEME_STYLE = {"explicit": ("tab:red", "s"), "implicit": ("tab:blue", "o"),
                "esdirk3": ("tab:orange", "v"),
                "steady": ("tab:green", "^"), "richardson": ("tab:purple", "D")}


def error_vs_runtime(rows, title="", ax=None):
    """Log-log error against wall time, one line per scheme: the total friction's of a
    straight belt, the tight span tension's of a drive (the rows' first error).

    Parameters
    ----------
    rows : list of dict
        The rows of :func:`beltsim.studies.convergence.convergence` (scheme, elements,
        wall_time, converged and the errors); rows that did not converge are left out.
    title : str, optional
        The axes' title (the scene's, typically).
    ax : Axes, optional
        Where to draw; default a new figure.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, (ax,), _ = panel_axes(ax, 1, figsize=(6.4, 4.6))
    key = next((k for k in rows[0] if k.startswith("error_")), "error_total_friction") \
        if rows else "error_total_friction"
    for scheme in dict.fromkeys(r["scheme"] for r in rows):
        rs = [r for r in rows if r["scheme"] == scheme and r["converged"]]
        t = np.array([r["wall_time"] for r in rs])
        e = np.array([abs(r[key]) for r in rs])
        color, marker = SCHEME_STYLE.get(scheme, ("k", "x"))
        ax.loglog(t, e, marker=marker, color=color, label=scheme)
        for r, ti, ei in zip(rs, t, e):
            ax.annotate(f"{r['elements']}", (ti, ei), textcoords="offset points",
                        xytext=(4, 4), fontsize=7, color=color)
    ax.set_xlabel("wall time to steady state [s] (numba compilation excluded)")
    ax.set_ylabel(f"relative error of the {key[6:].replace('_', ' ')}")
    ax.set_title(textwrap.fill(f"{title} (labels: elements)" if title else
                               "Error against run time (labels: elements)", 70), fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return fig


def creep_collapse(rows, title="", axes=None):
    """Three panels for a sweep over f*: slip-zone length, theta(x), total friction.

    Parameters
    ----------
    rows : list of dict
        The rows of :func:`beltsim.studies.sweep.sweep` over ``contact.max_friction``
        with ``keep_theta``.
    title : str, optional
        The figure's title (a new figure only).
    axes : sequence of three Axes, optional
        Where to draw; default a new figure.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fs = np.array([r["value"] for r in rows], dtype=float)
    x2 = rows[0]["x2"]
    sim_len = np.array([x2 - r["slip_start"] for r in rows])
    ex_len = np.array([x2 - r["slip_start_analytic"] for r in rows])
    fig, axes, own = panel_axes(axes, 1, 3, figsize=(15, 4.4))
    ax = axes[0]
    ax.loglog(fs, ex_len, "-", color="k", label="analytic")
    pos = sim_len > 0
    ax.loglog(fs[pos], sim_len[pos], "o", color="tab:red", label="simulation")
    hmin = np.array([r["h_min"] for r in rows])
    ax.loglog(fs, hmin, ":", color="0.5", label="smallest element")
    ax.set_xlabel("f* [N/m]")
    ax.set_ylabel("slip-zone length x2 - x* [m]")
    ax.set_title("Creep zone collapses onto x2")
    ax.legend()
    ax.grid(True, which="both", alpha=0.3)

    ax = axes[1]
    picks = [rows[i] for i in sorted({0, len(rows) // 2, len(rows) - 1}) if "theta" in rows[i]]
    colors = ["tab:blue", "tab:orange", "tab:green", "tab:purple"]
    for r, col in zip(picks, colors):
        ax.plot(r["x_exact"], r["theta_exact"], "-", color=col, lw=1.2)
        step = max(1, len(r["x"]) // 60)
        ax.plot(r["x"][::step], r["theta"][::step], "o", ms=3, color=col,
                label=f"f* = {r['value']:.3g} N/m")
    if picks:
        ax.plot(picks[0]["x_exact"], picks[0]["theta_adhesion"], "--", color="k",
                label="perfect adhesion")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("theta [rad]")
    ax.set_title("Rotation: simulation (markers), analytic (lines)")
    ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)

    ax = axes[2]
    tot = np.array([r["total_friction"] for r in rows])
    ax.semilogx(fs, tot, "o", color="tab:red", label="simulation")
    ax.semilogx(fs, [r["total_friction_analytic"] for r in rows], "-", color="k",
                label="analytic (stick and slip)")
    ax.axhline(rows[0]["total_friction_adhesion"], ls="--", color="tab:blue",
               label="perfect adhesion")
    ax.set_xlabel("f* [N/m]")
    ax.set_ylabel("total friction [N]")
    ax.set_title("Total friction tends to the adhesion value")
    ax.legend()
    ax.grid(True, which="both", alpha=0.3)
    if title and own:
        fig.suptitle(title)
    return fig
