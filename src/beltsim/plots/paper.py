"""The paper's Figures 2-7: analytic curves, with simulated steady states as markers.

Figures 2-6 have the paper's two panels: inertia against no inertia (both perfect
adhesion), and slip against no slip (both with inertia); Figure 7 the rotation for
three friction limits against perfect adhesion.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..studies.paper import FIG7_FSTAR
from .common import pyplot, save

STYLE = {"quasistatic": ("tab:gray", "no inertia, no slip"),
         "inertia": ("tab:blue", "inertia, no slip"),
         "slip": ("tab:red", "inertia, slip (f* = 1e5 N/m)")}
# (field, figure number, y label, title) of the two-panel figures
FIGURES = (("friction", 2, "distributed friction f [N/m]", "Distributed friction force"),
           ("tension", 3, "tension T [N]", "Tension"),
           ("moment", 4, "moment M [N m]", "Moment"),
           ("theta", 5, "angle theta [rad]", "Angle"),
           ("u", 6, "displacement u [m]", "Displacement"))
PANELS = (("quasistatic", "inertia"), ("inertia", "slip"))
PANEL_TITLES = ("inertia versus no inertia", "slip versus no slip")


def _markers(ax, sim, field, color):
    if sim is None:
        return
    x, y = sim["x"], sim[field]
    step = max(1, len(x) // 70)
    ax.plot(x[::step], y[::step], "o", ms=3.5, mfc="none", color=color)


def _shade_contact(ax, P):
    ax.axvspan(P.x1, P.x2, color="0.92", zorder=0)


def two_panel(field, number, ylabel, title, sols, sims, path):
    """One of Figures 2-6: a field, inertia against none and slip against none."""
    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.3), constrained_layout=True)
    for ax, cases, sub in zip(axes, PANELS, PANEL_TITLES):
        _shade_contact(ax, sols["inertia"].params)
        for case in cases:
            color, label = STYLE[case]
            s = sols[case]
            x, f = s.sample(1201)
            ax.plot(x, f[field], color=color, lw=1.6, label=label)
            _markers(ax, sims.get(case), field, color)
            if field == "friction" and s.model == "stick":
                # a delta cannot be drawn as a curve: a stem with its value
                top = 1.08 * max(np.max(np.abs(sols[c].sample(401)[1]["friction"]))
                                 for c in cases)
                ax.annotate(f"concentrated force\nF = {s.concentrated_force:.0f} N at x2",
                            xy=(s.params.x2, top * 0.97),
                            xytext=(s.params.x2 + 0.06, top * (0.8 if case == "inertia"
                                                                else 0.5)),
                            color=color, fontsize=9,
                            arrowprops=dict(arrowstyle="->", color=color))
        ax.set_xlabel("x [m]")
        ax.set_ylabel(ylabel)
        ax.set_title(sub)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8, loc="upper left")
    note = " (lines: analytic; markers: simulated from rest)" if sims else ""
    fig.suptitle(f"Fig. {number}. {title} over the spatial coordinate{note}", fontsize=11)
    return save(fig, path, dpi=120)


def fig7(sols, sims, path):
    """Figure 7: the rotation for three friction limits against perfect adhesion."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 4.6), constrained_layout=True)
    _shade_contact(ax, sols["inertia"].params)
    colors = ("tab:orange", "tab:red", "tab:purple")
    for fs, color in zip(FIG7_FSTAR, colors):
        key = f"slip_{fs:.0e}"
        x, f = sols[key].sample(1201)
        ax.plot(x, f["theta"], color=color, lw=1.4, label=f"slip, f* = {fs:.1e} N/m")
        _markers(ax, sims.get(key), "theta", color)
    x, f = sols["inertia"].sample(1201)
    ax.plot(x, f["theta"], "k--", lw=1.6, label="perfect adhesion")
    _markers(ax, sims.get("inertia"), "theta", "k")
    ax.set_xlim(0.4, 0.8)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("angle theta [rad]")
    ax.set_title("Fig. 7. Rotation angle: slip models converge to the stick model as f* "
                 "grows", fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=9)
    return save(fig, path, dpi=120)


def figures(out_dir, sols: dict, sims: dict | None = None) -> list[Path]:
    """fig2.png ... fig7.png in ``out_dir`` (analytic solutions, optional simulated markers)."""
    sims = sims or {}
    paths = [two_panel(field, number, ylabel, title, sols, sims,
                       Path(out_dir) / f"fig{number}.png")
             for field, number, ylabel, title in FIGURES]
    paths.append(fig7(sols, sims, Path(out_dir) / "fig7.png"))
    return paths
