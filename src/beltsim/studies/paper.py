"""The paper's Table 1 and Figures 2-7, analytic curves with simulated markers.

Cases: "quasistatic" (no inertia, perfect adhesion), "inertia" (inertia, perfect
adhesion) and "slip" (inertia, stick and slip, f* = 1e5 N/m), the scenes
runs/paper_*.toml. Figures 2-6 have the paper's two panels: inertia against no
inertia (both perfect adhesion), and slip against no slip (both with inertia).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..io.files import prepare_outdir, write_csv
from ..problem import analytic
from ..problem.scene import paper_scene

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
    from ..simulation.controller import run

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


def reproduce(out_dir, simulated: dict | None = None) -> dict:
    """Write table1.csv and fig2.png ... fig7.png; returns the rows and the paths."""
    from ..plots import paper as figures

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
        paths.append(figures.two_panel(field, number, ylabel, title, sols, sims,
                                       Path(out) / f"fig{number}.png"))
    paths.append(figures.fig7(sols, sims, Path(out) / "fig7.png"))
    return {"table": rows, "paths": paths}
