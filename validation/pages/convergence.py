"""Page: grid convergence of the paper scenes, errors and observed orders."""

from __future__ import annotations

import numpy as np

from beltsim.api import shipped_scene
from beltsim.plots.common import save_figure
from beltsim.plots.studies import SCHEME_STYLE, error_vs_runtime
from beltsim.studies.convergence import (
    ERROR_KEYS,
    LADDER,
    RICHARDSON,
    convergence,
    observed_orders,
    schemes_for,
)

from .kit import Page, fmt

TITLE = "Grid convergence"
SCENES = ("paper_quasistatic", "paper_inertia", "paper_slip")
#: (ladder, schemes) per mode; None: every scheme that applies (beltsim convergence's)
LADDERS = {False: (LADDER, None), True: ((60, 120, 240), ("steady", "implicit", RICHARDSON))}
#: the exact (set-valued) friction law on paper_slip
EXACT_LADDERS = {False: ((250, 500, 1000, 2000, 4000), ("steady", "implicit", RICHARDSON)),
                 True: ((60, 120, 240), ("steady", "implicit", RICHARDSON))}
EXACT_LAW = ("numerics.friction_law", "exact")
TITLES = {"total_friction": "total friction", "u": "u", "theta": "theta",
          "concentrated_force": "conc. force", "slip_start": "slip start [m]"}


def _keys(rows) -> list[str]:
    """The error keys the scene has (a stick scene no slip start, a slip scene no force)."""
    return [k for k in ERROR_KEYS if any(np.isfinite(r[f"error_{k}"]) for r in rows)]


def _status(page: Page, where: str, r: dict) -> str:
    if r["converged"]:
        return "converged"
    if r["reason"]:  # refused before running (a SceneError), e.g. the explicit max_work
        return "refused: " + r["reason"]
    return page.fail(f"{where}, {r['scheme']}, {r['elements']} elements: not converged")


def ladder_section(page: Page, label: str, scene, ladder, schemes, stem: str) -> dict:
    """Run one ladder and write its tables and figures; returns the observed orders."""
    rows = convergence(scene, ladder, schemes)
    keys = _keys(rows)
    body = [[r["scheme"], str(r["elements"]), f"{r['h_min'] * 1e3:.4g}",
             _status(page, label, r), str(r["steps"]), fmt(r["wall_time"], ".3g"),
             *(fmt(r[f"error_{k}"], ".3e") for k in keys)] for r in rows]
    page.table(["scheme", "elements", "smallest element [mm]", "status", "steps", "wall [s]",
                *(TITLES[k] for k in keys)], body)
    orders = {k: observed_orders(rows, k) for k in keys}
    body = []
    for k in keys:
        for scheme, o in orders[k].items():
            body.append([TITLES[k], scheme, ", ".join(f"{p:.2f}" for p in o["pairs"]),
                         f"{o['fit']:.2f}"])
    page.para("Observed orders in the smallest element size, log(e1 / e2) / log(h1 / h2) "
              "for each successive pair of grids, and the least-squares slope over the "
              "ladder:")
    page.table(["error", "scheme", "successive pairs", "fitted"], body)
    _figure(page, rows, keys, label, stem)
    return orders


def _figure(page: Page, rows, keys, label, stem) -> None:
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter

    fig, axes = plt.subplots(1, len(keys), figsize=(3.6 * len(keys), 3.6),
                             constrained_layout=True)
    for ax, k in zip(np.atleast_1d(axes), keys):
        for i, scheme in enumerate(dict.fromkeys(r["scheme"] for r in rows)):
            rs = [r for r in rows if r["scheme"] == scheme and r["converged"]
                  and np.isfinite(r[f"error_{k}"]) and r[f"error_{k}"] > 0]
            if not rs:
                continue
            color, marker = SCHEME_STYLE.get(scheme, ("tab:orange", "v"))
            ax.loglog([r["h_min"] for r in rs], [r[f"error_{k}"] for r in rs],
                      marker=marker, color=color, label=scheme, ms=7 - 1.5 * i,
                      mfc="none", ls=("-", "--", "-.", ":")[i % 4])
        h = np.array([r["h_min"] for r in rows if r["converged"]])
        e = np.array([r[f"error_{k}"] for r in rows if r["converged"]])
        ok = np.isfinite(e) & (e > 0)
        if ok.any():  # a second-order line through the coarsest grid's largest error
            h0 = h[ok].max()
            e0 = e[ok][h[ok] == h0].max()
            hh = np.array([h[ok].min(), h0])
            ax.loglog(hh, e0 * (hh / h0) ** 2, ":", color="k", label="order 2")
        ax.xaxis.set_minor_formatter(NullFormatter())  # minor labels collide on short ladders
        ax.set_xlabel("smallest element [m]")
        ax.set_title(TITLES[k], fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
    np.atleast_1d(axes)[0].set_ylabel("error against the exact steady state")
    np.atleast_1d(axes)[0].legend(fontsize=7)
    fig.suptitle(label, fontsize=10)
    page.figure(fig, stem, f"{label}: errors against the smallest element size")
    if any(r["converged"] for r in rows):
        path = save_figure(error_vs_runtime, page.figure_path(f"{stem}_cost"), rows,
                           title=label)
        page.image(path, f"{label}: error of the total friction against wall time")


def _headline(orders: dict, key: str = "total_friction") -> str:
    parts = [f"{scheme} {o['fit']:.2f}" for scheme, o in orders.get(key, {}).items()]
    return ", ".join(parts)


def build(page: Page, quick: bool) -> None:
    ladder, schemes = LADDERS[quick]
    page.para(
        "Each paper scene solved on a ladder of grids (each twice as fine as the last, the "
        "grading kept), by each scheme, and every error against the exact steady solution "
        "of the same scene. The default friction law's regularisation shrinks with the "
        "grid (as (N0 / N)^2, N0 the scene's default), so its error falls with the grid's. "
        "The second-order discretisation (three-point upwind transport in the slip "
        "velocity, trapezoidal friction, the grid's node at the analytic slip start) "
        "should show order 2 in every error. *richardson* extrapolates the steady scheme "
        "on each grid and its bisection: it removes the grid's leading error but not the "
        "regularisation's, which is the same on both grids of a pair (v_reg follows the "
        "coarse one) and stays at its largest value, 1e-4 |v - c|, up to the scene's "
        "default grid; so with the default law its error levels off there and its orders "
        "scatter, while with the exact law below it falls faster than second order. "
        "Wall times exclude "
        "compilation. A rung refused before running (the explicit scheme's "
        "numerics.max_work) is shown as refused; a rung that does not reach its steady "
        "state fails.")
    summary = []
    for name in SCENES:
        scene = shipped_scene(name)
        page.heading(name)
        chosen = schemes or schemes_for(scene)
        page.para(f"`beltsim convergence {name} --ladder {','.join(map(str, ladder))} "
                  f"--schemes {','.join(chosen)}`")
        orders = ladder_section(page, name, scene, ladder, chosen, name)
        summary.append(f"{name}: {_headline(orders)}")
    ladder, schemes = EXACT_LADDERS[quick]
    page.heading("paper_slip with the exact friction law")
    page.para(
        "The set-valued Coulomb law without regularisation (`numerics.friction_law = "
        "\"exact\"`, solved by a semi-smooth Newton iteration): no regularisation error, "
        "so the errors are the grid's alone. "
        f"`beltsim convergence paper_slip --set 'numerics.friction_law=\"exact\"' --ladder "
        f"{','.join(map(str, ladder))} --schemes {','.join(schemes)}`")
    orders = ladder_section(page, "paper_slip, exact law",
                            shipped_scene("paper_slip", [EXACT_LAW]), ladder, schemes,
                            "paper_slip_exact")
    summary.append(f"paper_slip with the exact law: {_headline(orders)}")
    for key in ("theta", "slip_start"):
        summary.append(f"paper_slip with the exact law, {TITLES[key]}: "
                       f"{_headline(orders, key)}")
    page.heading("Summary")
    page.para("Fitted orders of the total friction's error (and, for the exact law, of "
              "theta and the slip start), per scheme:")
    page.bullets(summary)
