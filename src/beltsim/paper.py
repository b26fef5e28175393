"""The paper's Table 1 and Figures 2-7, analytic curves with simulated markers.

Cases: "quasistatic" (no inertia, perfect adhesion), "inertia" (inertia, perfect
adhesion) and "slip" (inertia, stick and slip, f* = 1e5 N/m), the scenes
runs/paper_*.toml. Figures 2-6 have the paper's two panels: inertia against no
inertia (both perfect adhesion), and slip against no slip (both with inertia).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from . import analytic
from .results import prepare_outdir, write_csv
from .scene import paper_scene

CASES = {"quasistatic": "No inertia, no slip", "inertia": "With inertia, no slip",
         "slip": "With inertia, with slip"}
FIG7_FSTAR = (0.5e5, 1e5, 2e5)
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


def solutions() -> dict:
    """Analytic solutions of the three cases and of Fig. 7's friction limits."""
    out = {name: analytic.solve(paper_scene(name)) for name in CASES}
    for fs in FIG7_FSTAR:
        out[f"slip_{fs:.0e}"] = analytic.solve(
            paper_scene("slip", [f"contact.max_friction={fs}"]))
    return out


def table1(sols=None) -> list[dict]:
    """Concentrated (or slipping) part, distributed (or sticking) part and total, in N."""
    sols = sols or solutions()
    rows = []
    for name, label in CASES.items():
        s = sols[name]
        if s.model == "stick":
            first, second = s.concentrated_force, s.distributed_friction
        else:
            first, second = s.slip_friction, s.stick_friction
        rows.append({"case": label, "concentrated_or_slipping": first,
                     "distributed_or_sticking": second, "total": s.total_friction})
    return rows


def format_table1(rows) -> str:
    head = (f"{'Table 1. Total friction traction, N':<26s}\n"
            f"{'':<26s}{'Concentrated part':>20s}{'Distributed part':>20s}{'Total':>10s}\n"
            f"{'':<26s}{'or slipping part':>20s}{'or sticking part':>20s}{'':>10s}")
    lines = [head]
    for r in rows:
        lines.append(f"{r['case']:<26s}{r['concentrated_or_slipping']:>20.0f}"
                     f"{r['distributed_or_sticking']:>20.0f}{r['total']:>10.0f}")
    return "\n".join(lines)


def simulate(progress=None) -> dict:
    """Simulated steady states of the cases (transient runs from rest, default numerics)."""
    from .runner import run

    out = {}
    scenes = {name: paper_scene(name) for name in CASES}
    scenes.update({f"slip_{fs:.0e}": paper_scene("slip", [f"contact.max_friction={fs}"])
                   for fs in FIG7_FSTAR})
    for key, sc in scenes.items():
        res = run(sc)
        sol = res.solution
        fields = sol.fields()
        # the discrete force layer at x2 (last three contact nodes) is the concentrated
        # force, not a distributed traction: leave it out of the friction markers
        layer = np.zeros(len(sol.x), dtype=bool)
        layer[sol.grid.j2 - 2:sol.grid.j2 + 1] = sol.model == "stick"
        fields["friction"] = np.where(layer, np.nan, fields["friction"])
        out[key] = {"x": sol.x, **fields, "summary": sol.summary(),
                    "converged": res.converged}
        if progress:
            progress(key, res)
    return out


def _pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _markers(ax, sim, field, color):
    if sim is None:
        return
    x, y = sim["x"], sim[field]
    step = max(1, len(x) // 70)
    ax.plot(x[::step], y[::step], "o", ms=3.5, mfc="none", color=color)


def _shade_contact(ax, P):
    ax.axvspan(P.x1, P.x2, color="0.92", zorder=0)


def _two_panel(field, number, ylabel, title, sols, sims, path):
    plt = _pyplot()
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
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def _fig7(sols, sims, path):
    plt = _pyplot()
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
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def reproduce(out_dir, simulated: dict | None = None) -> dict:
    """Write table1.csv and fig2.png ... fig7.png; returns the rows and the paths."""
    out = prepare_outdir(out_dir)
    sols = solutions()
    sims = simulated or {}
    rows = table1(sols)
    paths = [write_csv(out / "table1.csv",
                       ("case", "concentrated_or_slipping", "distributed_or_sticking", "total"),
                       [[r[k] for r in rows] for k in ("case", "concentrated_or_slipping",
                                                       "distributed_or_sticking", "total")],
                       text_columns={"case"})]
    for field, number, ylabel, title in FIGURES:
        paths.append(_two_panel(field, number, ylabel, title, sols, sims,
                                Path(out) / f"fig{number}.png"))
    paths.append(_fig7(sols, sims, Path(out) / "fig7.png"))
    return {"table": rows, "paths": paths}
