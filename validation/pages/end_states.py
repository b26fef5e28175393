"""Page: the end states of the shipped paper scenes by every applicable scheme, against
the exact steady solutions."""

from __future__ import annotations

import numpy as np

from beltsim import solvers
from beltsim.api import shipped_scene
from beltsim.simulation.controller import Simulation
from beltsim.simulation.result import reference_of
from beltsim.studies.convergence import ERROR_KEYS, RICHARDSON, richardson
from beltsim.studies.stability import BOUNDS

from .kit import Page, fmt

TITLE = "End states of the paper scenes"
SCENES = ("paper_quasistatic", "paper_inertia", "paper_slip")
QUICK_ELEMENTS = 150
#: every error key of :func:`beltsim.simulation.solution.compare`, with its column title
ERRORS = {"total_friction": "total friction", "u": "u", "theta": "theta",
          "slip_power": "slip power", "concentrated_force": "conc. force",
          "slip_start": "slip start [m]"}
STYLE = {"implicit": "tab:blue", "explicit": "tab:red", "pseudo": "tab:orange",
         "steady": "tab:green", RICHARDSON: "tab:purple"}


def _judge(page: Page, where: str, converged: bool, reason, err: dict) -> str:
    """The status cell: converged, or failed (not steady, or out of the bounds)."""
    if not converged:
        return page.fail(f"{where}: {reason or 'not converged'}")
    over = [f"{k} {err[k]:.3g} > {b:g}" for k, b in BOUNDS.items()
            if err.get(k) is not None and not err[k] <= b]
    if over:
        return page.fail(f"{where}: out of bounds ({'; '.join(over)})")
    return "converged"


def scene_rows(page: Page, name: str, quick: bool) -> list[dict]:
    """Every applicable scheme, and Richardson's extrapolation, on one scene."""
    scene = shipped_scene(name, [("numerics.elements", QUICK_ELEMENTS)] if quick else [])
    ref = reference_of(scene)
    rows = []
    for scheme in solvers.names():
        why_not = solvers.applicable(scheme, scene.params.inertia)
        if why_not:
            rows.append({"scheme": scheme, "status": "not applicable", "reason": why_not})
            continue
        sim = Simulation(scene.with_overrides([("numerics.integrator", scheme)]))
        res = sim.run(raise_on_failure=False)
        res.reference = ref
        err = res.errors() or {}
        rows.append({"scheme": scheme, "elements": sim.grid.n_elements,
                     "status": _judge(page, f"{name}, {scheme}", res.converged, res.reason,
                                      err),
                     "steps": res.steps, "newton": res.statistics.get("newton_iterations"),
                     "time": res.simulated_time if sim.scheme.transient else None,
                     "wall": res.wall_time, "compile": res.compile_time, "err": err})
    r1, r2, err, wall = richardson(scene, ref)
    ok = err is not None
    # what the extrapolation covers: the slip power is left as the coarse grid's
    err = {k: err[k] for k in ERROR_KEYS} if ok else None
    rows.append({"scheme": RICHARDSON, "elements": r1.solution.grid.n_elements,
                 "status": _judge(page, f"{name}, {RICHARDSON}", ok,
                                  r1.reason or r2.reason, err or {}),
                 "steps": r1.steps + r2.steps,
                 "newton": r1.newton_iterations + r2.newton_iterations, "time": None,
                 "wall": wall, "compile": r1.compile_time + r2.compile_time, "err": err or {}})
    return rows


def _table(page: Page, rows) -> None:
    body = []
    for r in rows:
        if r["status"] == "not applicable":
            body.append([r["scheme"], "not applicable", "", "", "", "", "",
                         *[""] * len(ERRORS), ])
            continue
        body.append([r["scheme"], r["status"], str(r["steps"]), fmt(r["newton"], "d"),
                     fmt(r["time"], ".4g"), fmt(r["wall"], ".3g"), fmt(r["compile"], ".2g"),
                     *(fmt(r["err"].get(k), ".2e") for k in ERRORS)])
    page.table(["scheme", "status", "steps", "Newton iterations", "simulated time [s]",
                "wall [s]", "compile or cache load [s]", *ERRORS.values()], body)
    skipped = [r for r in rows if r["status"] == "not applicable"]
    if skipped:
        page.bullets(f"{r['scheme']}: {r['reason']}" for r in skipped)


def _figure(page: Page, results: dict) -> None:
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(results), figsize=(5.2 * len(results), 4.2),
                             constrained_layout=True, sharey=True)
    for ax, (name, rows) in zip(np.atleast_1d(axes), results.items()):
        ran = [r for r in rows if "err" in r]
        keys = [k for k in ERRORS if any(r["err"].get(k) for r in ran)]
        width = 0.8 / max(len(ran), 1)
        for i, r in enumerate(ran):
            vals = [r["err"].get(k) or np.nan for k in keys]
            ax.bar(np.arange(len(keys)) + (i - (len(ran) - 1) / 2) * width, vals, width,
                   label=r["scheme"], color=STYLE.get(r["scheme"], "0.5"))
        ax.set_yscale("log")
        ax.set_xticks(np.arange(len(keys)), [ERRORS[k] for k in keys], rotation=30,
                      ha="right", fontsize=8)
        ax.set_title(f"{name} ({ran[0]['elements']} elements)" if ran else name, fontsize=10)
        ax.grid(True, axis="y", which="both", alpha=0.3)
    # one legend for all panels, from the panel with the most schemes
    widest = max(np.atleast_1d(axes), key=lambda a: len(a.get_legend_handles_labels()[1]))
    fig.legend(*widest.get_legend_handles_labels(), loc="outside right upper", fontsize=8)
    np.atleast_1d(axes)[0].set_ylabel("error against the exact steady state")
    page.figure(fig, "errors", "Errors of the end states against the exact steady "
                               "solutions, per scheme (relative; the slip start in metres)")


def build(page: Page, quick: bool) -> None:
    grid = f"{QUICK_ELEMENTS} elements" if quick else "each scene's default grid"
    page.para(
        f"Each shipped paper scene run from rest to its steady state by every registered "
        f"scheme that applies to it, on {grid}, and its end state compared with the exact "
        f"steady solution of the same scene (`beltsim.solve`). Errors are relative: the "
        f"total friction, the slip power (the steady energy balance's dissipation), the "
        f"concentrated force (perfect adhesion), and u and theta as the largest nodal "
        f"difference over the largest exact value; the slip start x* is an absolute error "
        f"in metres. *richardson* extrapolates the steady scheme's solutions on the grid "
        f"and its bisection (`beltsim convergence` runs it as a scheme). Wall times exclude "
        f"compiling or loading the numba kernels, in their own column. A cell fails when "
        f"its run is not steady by t_end or an error exceeds the transient simulator's "
        f"acceptance bounds (" + ", ".join(f"{k} {b:g}" for k, b in BOUNDS.items())
        + "); the commands are `beltsim run paper_slip --set numerics.integrator=steady` "
        "and so on.")
    results = {}
    for name in SCENES:
        results[name] = rows = scene_rows(page, name, quick)
        page.heading(f"{name}")
        _table(page, rows)
        ran = [r for r in rows if r.get("err")]
        if ran:
            tf = [r["err"]["total_friction"] for r in ran]
            page.para(f"The total friction's error spans {min(tf):.2e} to {max(tf):.2e} "
                      f"over the schemes.")
    page.heading("All scenes")
    _figure(page, results)
