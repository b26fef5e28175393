"""Page: the power balance of the implicit runs."""

from __future__ import annotations

from beltsim.api import shipped_scene
from beltsim.simulation.controller import run

from .kit import Page, fmt, num

TITLE = "Balance laws"
SCENES = ("paper_quasistatic", "paper_inertia", "paper_slip")
QUICK_ELEMENTS = 150
#: time_tol values of the paper_slip ladder
TOLS = {False: (1e-4, 1e-5, 1e-6, 1e-7), True: (1e-4, 1e-5, 1e-6)}
#: a residual above this fraction of the largest term fails the cell: above the time error
#: of the default time_tol (largest in paper_quasistatic, 4.5e-6) and below the damping's
#: share (8e-5 in paper_slip); smaller terms show against the residual itself
LIMIT = 1e-5
TERMS = (("stored_energy_change", "E(t) - E(0)"), ("surface_work", "surface work"),
         ("transport_work", "transport work"), ("load_work", "load work"),
         ("slip_dissipation", "slip"), ("damping_dissipation", "damping"),
         ("gyroscopic_dissipation", "gyroscopic"), ("residual", "residual"))


def _row(page: Page, label: str, res) -> list[str]:
    pb = res.power_balance
    if pb is None or pb["relative_residual"] is None:
        return [label, page.fail(f"{label}: no power balance"), *[""] * (len(TERMS) + 2)]
    rel = pb["relative_residual"]
    flow = abs(pb["residual"]) / largest_term(pb)
    if not res.converged:
        status = page.fail(f"{label}: {res.reason}")
    elif not flow <= LIMIT:
        status = page.fail(f"{label}: residual {flow:.2e} of the largest term, above "
                           f"{LIMIT:g}")
    else:
        status = "converged"
    return [label, status, fmt(res.simulated_time, ".4g"), str(res.steps),
            *(fmt(pb[k], ".5g") for k, _ in TERMS), f"{rel:.2e}", f"{flow:.2e}"]


def largest_term(pb: dict) -> float:
    """The largest power term's energy (J), the scale the residual is judged against."""
    return max(abs(pb[k]) for k, _ in TERMS if k != "residual")


HEADER = ["run", "status", "simulated time [s]", "steps", *(f"{t} [J]" for _, t in TERMS),
          "residual / dissipated", "residual / largest term"]


def build(page: Page, quick: bool) -> None:
    grid = [("numerics.elements", QUICK_ELEMENTS)] if quick else []
    where = f"{QUICK_ELEMENTS} elements" if quick else "each scene's default grid"
    page.para(
        "The implicit scheme integrates the power terms of the semi-discrete model along "
        "with the state, so every run can close its energy balance "
        "(`RunResult.power_balance`): the change of the stored energy E(t) - E(0) (strain "
        "and kinetic) equals the work of the moving surface through friction, the work of "
        "the material transported through the boundaries and of any loads, less what slip, "
        "viscous damping and the upwind gyroscopic term dissipate. The residual of that "
        "balance is the time integration's error: it falls with `numerics.time_tol`. "
        "`power_balance` states it relative to the dissipated energy; under perfect "
        "adhesion almost nothing dissipates (the adhesion layer's slip is tiny) and the "
        "power flows through, from the surface's work to the work transported out, so the "
        "residual is also given relative to the largest term. A cell fails when its run "
        "does not reach the steady state or its residual exceeds "
        f"{LIMIT:g} of the largest term. The works and dissipations grow with the simulated "
        f"time, as the steady state keeps dissipating, so runs that stop at different times "
        f"differ in them.")
    page.heading("The paper scenes")
    page.para(f"Implicit runs from rest to steady state on {where} (`beltsim run "
              f"paper_slip`, whose `summary.json` holds the same balance).")
    rows = []
    for name in SCENES:
        rows.append(_row(page, name, run(shipped_scene(name, grid), raise_on_failure=False)))
    page.table(HEADER, rows)
    page.heading("paper_slip as time_tol shrinks")
    rows, rel = [], []
    for tol in TOLS[quick]:
        res = run(shipped_scene("paper_slip", [*grid, ("numerics.time_tol", tol)]),
                  raise_on_failure=False)
        rows.append(_row(page, f"time_tol {num(tol)}", res))
        if res.power_balance and res.power_balance["relative_residual"] is not None:
            rel.append((tol, res.power_balance["relative_residual"]))
    page.table(HEADER, rows)
    if rel:
        page.para(
            "Relative residuals "
            + ", ".join(f"{r:.2g} at {num(t)}" for t, r in rel)
            + ". The residual is a sum of time errors of either sign, so it need not fall "
              "monotonically once it is small; it stays orders of magnitude below the "
              "smallest dissipation term.")
