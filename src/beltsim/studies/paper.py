"""The paper's Table 1 and Figures 2-7, analytic curves with simulated markers.

Cases: "quasistatic" (no inertia, perfect adhesion), "inertia" (inertia, perfect
adhesion) and "slip" (inertia, stick and slip, f* = 1e5 N/m), the scenes
the shipped scenes paper_*.toml. The figures are drawn by :mod:`beltsim.plots.paper`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..api import paper_scene
from ..io.files import prepare_outdir, write_csv
from ..problem import analytic

CASES = {"quasistatic": "No inertia, no slip", "inertia": "With inertia, no slip",
         "slip": "With inertia, with slip"}
FIG7_FSTAR = (0.5e5, 1e5, 2e5)


def solutions() -> dict:
    """Analytic solutions of the three cases and of Fig. 7's friction limits."""
    out = {name: analytic.solve(paper_scene(name)) for name in CASES}
    for fs in FIG7_FSTAR:
        out[f"slip_{fs:.0e}"] = analytic.solve(
            paper_scene("slip", [("contact.max_friction", fs)]))
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
    """Table 1 as text, in the paper's layout."""
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
    scenes.update({f"slip_{fs:.0e}": paper_scene("slip", [("contact.max_friction", fs)])
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


def write_table1(out_dir, sols=None) -> tuple[list[dict], Path]:
    """Table 1 from the analytic solutions, written to table1.csv; returns rows and path."""
    out = prepare_outdir(out_dir)
    rows = table1(sols)
    keys = ("case", "concentrated_or_slipping", "distributed_or_sticking", "total")
    return rows, write_csv(out / "table1.csv", keys, [[r[k] for r in rows] for k in keys],
                           text_columns={"case"})
