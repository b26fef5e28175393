"""Page: the analytic solutions against the paper (Table 1, Figures 2-7) and the
creep-zone collapse as the friction limit grows."""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

from beltsim.api import paper_scene
from beltsim.plots.common import save_figure
from beltsim.plots.paper import figures
from beltsim.plots.studies import creep_collapse
from beltsim.studies import paper
from beltsim.studies.sweep import run_point

from .kit import Page, fmt, num

TITLE = "Analytic solutions against the paper"

#: Table 1 of Oborin & Vetyukov (2019), as printed (whole newtons): (concentrated or
#: slipping part, distributed or sticking part, total)
PUBLISHED = {"No inertia, no slip": (6482, 6237, 12719),
             "With inertia, no slip": (2024, 5375, 7398),
             "With inertia, with slip": (3253, 3870, 7124)}
#: f* of the creep-zone sweep (N/m): from a slip zone of a third of the contact to one
#: shorter than the smallest element
FSTAR = {False: (5e4, 7e4, 1e5, 2e5, 5e5, 1e6, 1e7), True: (5e4, 2e5, 1e7)}
QUICK_ELEMENTS = 150  # the sweep's grid in --quick (else each scene's default)
KEY = "contact.max_friction"


def _simulated_parts(summary: dict) -> tuple:
    if summary["model"] == "stick":
        return (summary["concentrated_force"], summary["distributed_friction"],
                summary["total_friction"])
    return summary["slip_friction"], summary["stick_friction"], summary["total_friction"]


def table1(page: Page, sols: dict, sims: dict) -> None:
    page.heading("Table 1: total friction traction")
    page.para(
        "The paper's Table 1 splits the total friction on the belt into its concentrated "
        "part (at x2, perfect adhesion) or slipping part and its distributed or sticking "
        "part. *Analytic* is beltsim's exact steady solution of the shipped scene "
        "(`beltsim analytic paper_quasistatic` and so on); *printed* is the paper's "
        "number, rounded there to whole newtons, so the analytic value must round to it. "
        "*Simulated* is the default run's steady state (implicit scheme, default grid, "
        "from rest: `beltsim run paper_slip` and so on), its relative difference from the "
        "analytic value beside it.")
    rows = []
    names = {label: name for name, label in paper.CASES.items()}
    parts = ("concentrated or slipping", "distributed or sticking", "total")
    worst = 0.0
    for r in paper.table1(sols):
        case = r["case"]
        ours = (r["concentrated_or_slipping"], r["distributed_or_sticking"], r["total"])
        sim = _simulated_parts(sims[names[case]]["summary"])
        for part, value, printed, s in zip(parts, ours, PUBLISHED[case], sim):
            match = "yes" if round(value) == printed else page.fail(
                f"Table 1, {case}, {part}: analytic {value:.2f} N does not round to the "
                f"printed {printed} N")
            rel = (s - value) / abs(value)
            worst = max(worst, abs(rel))
            rows.append([case, part, str(printed), f"{value:.2f}", f"{value - printed:+.2f}",
                         match, f"{s:.2f}", f"{rel:+.1e}"])
    page.table(["case", "part", "printed [N]", "analytic [N]", "analytic - printed [N]",
                "rounds to printed", "simulated [N]", "simulated / analytic - 1"], rows)
    conv = [k for k, v in sims.items() if not v["converged"]]
    for k in conv:
        page.fail(f"paper run {k}: not steady by t_end")
    page.para(
        f"Every simulated part is within {worst:.1e} of the analytic one (relative), "
        f"which is the default grid's discretisation error (see [grid convergence]"
        f"(convergence.md)).")


def paper_figures(page: Page, sols: dict, sims: dict) -> None:
    page.heading("Figures 2-7 of the paper")
    page.para(
        "The paper's Figures 2-7 redrawn from the analytic solutions (lines), with the "
        "simulated steady states of the same scenes as markers (every few nodes of the "
        "default grid). Figures 2-6 compare inertia against no inertia (both perfect "
        "adhesion) and slip against no slip (both with inertia); Figure 7 shows the "
        "rotation for the friction limits f* = 0.5e5, 1e5 and 2e5 N/m against perfect "
        "adhesion. `beltsim paper` draws the same figures.")
    with tempfile.TemporaryDirectory() as tmp:
        for path in figures(Path(tmp), sols, sims):
            target = page.figure_path(path.stem)
            shutil.copyfile(path, target)
            number = path.stem[3:]
            page.image(target, f"Figure {number} of the paper: analytic (lines) and "
                               f"simulated (markers)")


def creep(page: Page, quick: bool) -> None:
    page.heading("Creep-zone collapse as f* grows")
    overrides = [f"numerics.elements={QUICK_ELEMENTS}"] if quick else []
    scene = paper_scene("slip", overrides)
    grid = f"{QUICK_ELEMENTS} elements" if quick else "the default grid"
    page.para(
        f"The paper slip scene with the friction limit f* raised from {num(FSTAR[quick][0])} "
        f"N/m (a slip zone over a third of the contact) to {num(FSTAR[quick][-1])} N/m: the "
        f"slip zone x2 - x* shrinks onto x2 and the solution tends to perfect adhesion "
        f"with its concentrated force. Each point is a transient run from rest to steady "
        f"state on {grid} (`beltsim sweep paper_slip --vary "
        f"{KEY}={','.join(num(v) for v in FSTAR[quick])}` runs the same points in "
        f"parallel), compared with the analytic solution of the same f* and with the "
        f"perfect-adhesion solution.")
    rows = [run_point(scene.to_dict(), KEY, v, keep_theta=True) for v in FSTAR[quick]]
    table = []
    for r in rows:
        ok = r["converged"] or page.fail(f"creep sweep, f* = {num(r['value'])} N/m: "
                                         f"{r['reason']}")
        sim_len = r["x2"] - r["slip_start"]
        ex_len = r["x2"] - r["slip_start_analytic"]
        table.append([num(r['value']), f"{ex_len * 1e3:.4g}", f"{sim_len * 1e3:.4g}",
                      f"{(sim_len - ex_len) / ex_len:+.1e}", f"{r['h_min'] * 1e3:.3g}",
                      f"{r['total_friction_analytic']:.2f}", f"{r['total_friction']:.2f}",
                      f"{r['total_friction_adhesion']:.2f}",
                      f"{_relative(r['total_friction'], r['total_friction_adhesion']):+.1e}",
                      "yes" if ok is True else ok, fmt(r["wall_time"])])
    page.table(["f* [N/m]", "slip zone, analytic [mm]", "simulated [mm]", "relative diff.",
                "smallest element [mm]", "total friction, analytic [N]", "simulated [N]",
                "perfect adhesion [N]", "simulated / adhesion - 1", "steady", "wall [s]"],
               table)
    resolved = [(r, r["x2"] - r["slip_start_analytic"]) for r in rows]
    rel = [abs((r["x2"] - r["slip_start"]) - ex) / ex for r, ex in resolved
           if ex > r["h_min"] and r["converged"]]
    last = rows[-1]
    text = ""
    if rel:
        text += (f"Where the analytic slip zone is longer than the smallest element, the "
                 f"simulated one is within {100 * min(rel):.2g}% to {100 * max(rel):.2g}% "
                 f"of it. ")
    text += (f"At f* = {num(last['value'])} N/m the analytic slip zone is "
             f"{(last['x2'] - last['slip_start_analytic']) * 1e3:.3g} mm against a smallest "
             f"element of {last['h_min'] * 1e3:.3g} mm, and the simulated total friction, "
             f"{last['total_friction']:.2f} N, is within "
             f"{100 * abs(last['total_friction'] / last['total_friction_adhesion'] - 1):.2g}% "
             f"of the perfect-adhesion value, {last['total_friction_adhesion']:.2f} N.")
    page.para(text)
    path = save_figure(creep_collapse, page.figure_path("creep_collapse"), rows,
                       title=f"{scene.title}, {grid}")
    page.image(path, "Creep-zone collapse: slip-zone length, rotation and total friction "
                     "against f* (simulation markers, analytic lines)")


def build(page: Page, quick: bool) -> None:
    page.para(
        "Two checks of beltsim's exact steady solutions (`beltsim.solve`) against "
        "the paper they follow, E. Oborin and Y. Vetyukov, *Steady state motion of a shear "
        "deformable beam in contact with a traveling surface*, Acta Mechanica (2019), and "
        "of the simulation against them: the paper's Table 1 and Figures 2-7 for its "
        "three scenes (shipped as `paper_quasistatic`, `paper_inertia` and `paper_slip`), "
        "and the collapse of the slip (creep) zone into the concentrated force of perfect "
        "adhesion as the friction limit grows.")
    sols = paper.solutions()
    sims = paper.simulate()
    table1(page, sols, sims)
    paper_figures(page, sols, sims)
    creep(page, quick)


def _relative(value, reference):
    """(value - reference) / |reference|."""
    return (value - reference) / abs(reference)
