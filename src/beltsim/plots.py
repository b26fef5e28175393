"""Plots of studies (figures of the paper live in paper.py, animation in animate.py)."""

from __future__ import annotations

import numpy as np

SCHEME_STYLE = {"explicit": ("tab:red", "s"), "implicit": ("tab:blue", "o"),
                "steady": ("tab:green", "^")}


def _pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def error_vs_runtime(rows, path, title=""):
    """Log-log error of the total friction against wall time, one line per scheme."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.6), constrained_layout=True)
    for scheme in dict.fromkeys(r["scheme"] for r in rows):
        rs = [r for r in rows if r["scheme"] == scheme and r["converged"]]
        t = np.array([r["wall_time"] for r in rs])
        e = np.array([r["error_total_friction"] for r in rs])
        color, marker = SCHEME_STYLE.get(scheme, ("k", "x"))
        ax.loglog(t, e, marker=marker, color=color, label=scheme)
        for r, ti, ei in zip(rs, t, e):
            ax.annotate(f"{r['elements']}", (ti, ei), textcoords="offset points",
                        xytext=(4, 4), fontsize=7, color=color)
    ax.set_xlabel("wall time to steady state [s] (numba compilation excluded)")
    ax.set_ylabel("relative error of the total friction")
    ax.set_title(title or "Error against run time (labels: elements)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.savefig(path, dpi=130)
    plt.close(fig)
    return path
