"""Page: transient paths, not only end states. The thin belt's exact transient converging
in the grid and the time step together, and the default time tolerance's path error on
the paper slip scene."""

from __future__ import annotations

import numpy as np

from beltsim.api import shipped_scene
from beltsim.problem.transient import thin_belt
from beltsim.simulation.controller import Simulation, run
from beltsim.solvers.settings import DEFAULT_INTEGRATOR, DEFAULT_TIME_TOL

from .kit import FAILED, Page, decorate, fmt, num

TITLE = "Transient paths"
SNAP = 2.0**-11  # s: the thin belt's check interval (binary, so fixed steps land on it)
T_SHORT = 80 * SNAP  # s: the ramp (2 L / c = 0.0167 s) and most of the relaxation
THIN_SCENES = {"coulomb": "paper_slip", "stick": "paper_quasistatic"}
#: grids of the thin-belt ladders and the first (coarsest) step of each scheme
THIN = {False: {"ladder": (250, 500, 1000, 2000), "implicit": 2.0**-13, "pseudo": 2.0**-12},
        True: {"ladder": (125, 250, 500), "implicit": 2.0**-12, "pseudo": 2.0**-11}}
#: time_tol values against a reference run, on the default grid (or a coarse one)
TOLS = {False: {"elements": None, "tols": (1e-4, 1e-5, DEFAULT_TIME_TOL, 1e-6),
                "reference": 1e-8},
        True: {"elements": 150, "tols": (1e-4, 1e-5, DEFAULT_TIME_TOL), "reference": 1e-7}}
EXPECTED = {"implicit": 2, "pseudo": 1}
#: the path error of a scheme of order p under local error control goes as time_tol^(p/3)
#: (steps from a local error of order h^3 in both schemes, a global error of order h^p)
TOL_EXPONENT = {"esdirk3": 1.0, "implicit": 2.0 / 3.0}


def pow2(step: float) -> str:
    """A binary step as 2^-k."""
    return f"2^{round(np.log2(step))}"


def thin_overrides() -> list[str]:
    """The thin-belt limit of the paper's data: quasistatic, h = 1e-6 m, and the
    stiffnesses a, b1, b2 of the paper's h = 0.1 m held fixed."""
    P = shipped_scene("paper_slip").params
    return [("physics.inertia", False), ("beam.height", 1e-6), ("stiffness.bending", P.a),
            ("stiffness.tension", P.b1), ("stiffness.shear", P.b2)]


def _thin_run(kind: str, scheme: str, elements: int, step: float):
    """One run of the thin scene on a uniform grid; returns (scene, result)."""
    common = [*thin_overrides(), ("numerics.grading", 1), ("numerics.elements", elements),
              ("numerics.integrator", scheme)]
    if scheme == "implicit":  # BDF2 at a fixed step: time_tol far above any estimate
        extra = [("numerics.friction_law", "exact"), ("numerics.time_tol", 10.0),
                 ("numerics.dt", step), ("numerics.snapshot_interval", step),
                 ("numerics.t_end", T_SHORT)]
    else:  # backward Euler at the nominal step, to steady state
        extra = [("numerics.dt", step), ("numerics.snapshot_interval", SNAP)]
    scene = shipped_scene(THIN_SCENES[kind], [*common, *extra])
    return scene, Simulation(scene).run(raise_on_failure=False)


def _history_error(scene, result) -> float:
    """max over the checks of |simulated - exact total friction| / |steady total friction|."""
    exact = thin_belt(scene)
    t = result.history["t"]
    ref = exact.history(t)["total_friction"]
    return float(np.max(np.abs(result.history["total_friction"] - ref))
                 / abs(exact.steady()["total_friction"]))


def thin_section(page: Page, quick: bool) -> None:
    cfg = THIN[quick]
    ladder = cfg["ladder"]
    page.heading("The thin belt's exact transient: grid and step together")
    page.para(
        "In the limit of a thin quasistatic belt (h -> 0 with the stiffnesses a, b1, b2 "
        "held) the belt is an axially moving bar in frictional contact, and its start-up "
        "from rest under the smooth ramp of the surface speed has an exact solution "
        "(`beltsim.problem.transient`): closed forms for perfect adhesion "
        "(`paper_quasistatic`), a scalar root x*(t) for Coulomb friction (`paper_slip`). "
        "The scenes here are those two with `physics.inertia=false`, `beam.height=1e-6` "
        "and the paper's a, b1, b2 in `[stiffness]`, on uniform grids. The error is the "
        "largest difference of the total friction from the exact one over the checks "
        "(relative to the steady total friction). The element size and the step halve "
        "together, so the error falls at the lower of the two orders:")
    page.bullets([
        (f"implicit: BDF2 at a fixed step (first step {pow2(cfg['implicit'])} s on "
        f"{ladder[0]} elements, `numerics.time_tol=10` so that no step is rejected, a "
        f"check at every step) with the exact friction law, to t = {T_SHORT:.4g} s "
        f"(the ramp and most of the relaxation); second order expected;"),
        (f"pseudo: backward Euler at the nominal step (first {pow2(cfg['pseudo'])} s), "
        f"default law, to the steady state; first order expected.")])
    rows, errors, shown = [], {}, {}
    for kind in THIN_SCENES:
        for scheme in ("implicit", "pseudo"):
            errs = []
            for i, n in enumerate(ladder):
                step = cfg[scheme] / 2**i
                scene, res = _thin_run(kind, scheme, n, step)
                ok = res.converged or (scheme == "implicit" and not res.failed
                                       and res.simulated_time >= T_SHORT * (1 - 1e-9))
                e = _history_error(scene, res) if not res.failed else float("nan")
                if not ok:
                    e = float("nan")
                errs.append(e)
                order = (np.log2(errs[-2] / e) if i and np.isfinite(errs[-2]) and np.isfinite(e)
                         else None)
                status = "ran" if ok else page.fail(
                    f"thin belt, {kind}, {scheme}, {n} elements: {res.reason}")
                rows.append([kind, scheme, str(n), pow2(step), str(res.steps), status,
                             fmt(e, ".3e"), fmt(order, ".2f"), fmt(res.wall_time, ".3g")])
                if scheme == "implicit":
                    shown[kind] = (scene, res)
            errors[kind, scheme] = np.array(errs)
    page.table(["scene", "scheme", "elements", "step [s]", "steps", "status",
                "history error", "order", "wall [s]"], rows)
    fits = []
    for (kind, scheme), e in errors.items():
        ok = np.isfinite(e) & (e > 0)
        if ok.sum() >= 2:
            fit = -np.polyfit(np.log2(np.array(ladder)[ok]), np.log2(e[ok]), 1)[0]
            fits.append(f"{kind}, {scheme}: {fit:.2f} (expected {EXPECTED[scheme]})")
    page.para("Fitted orders (least squares over the ladder):")
    page.bullets(fits)
    _thin_figures(page, ladder, errors, shown)


def _thin_figures(page: Page, ladder, errors, shown) -> None:
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter

    fig, axes = plt.subplots(1, 3, figsize=(14, 4), constrained_layout=True)
    scene, res = shown["coulomb"]
    exact = thin_belt(scene)
    t = np.linspace(0.0, T_SHORT, 400)
    h = exact.history(t)
    step = max(1, len(res.history["t"]) // 40)
    ax = axes[0]
    ax.plot(t * 1e3, h["total_friction"], "-", color="k", label="exact")
    ax.plot(res.history["t"][::step] * 1e3, res.history["total_friction"][::step], "o",
            ms=3.5, mfc="none", color="tab:blue",
            label=f"implicit, {res.solution.grid.n_elements} elements")
    stick_scene, stick = shown["stick"]
    ax.plot(t * 1e3, thin_belt(stick_scene).history(t)["total_friction"], "--", color="0.3",
            label="exact (adhesion)")
    ax.plot(stick.history["t"][::step] * 1e3, stick.history["total_friction"][::step], "s",
            ms=3, mfc="none", color="tab:green", label="implicit (adhesion)")
    decorate(ax, "t [ms]", "total friction [N]", "Start-up of the thin belt")
    ax = axes[1]
    ax.plot(t * 1e3, h["slip_start"], "-", color="k", label="exact x*(t)")
    ax.plot(res.history["t"][::step] * 1e3, res.history["slip_start"][::step], "o", ms=3.5,
            mfc="none", color="tab:blue", label="implicit")
    decorate(ax, "t [ms]", "slip start x* [m]", "The slip front opens from x2 (Coulomb)")
    ax = axes[2]
    styles = {"implicit": ("o", "-"), "pseudo": ("s", "--")}
    colors = {"coulomb": "tab:blue", "stick": "tab:green"}
    n = np.array(ladder, dtype=float)
    for (kind, scheme), e in errors.items():
        marker, ls = styles[scheme]
        ax.loglog(n, e, marker=marker, ls=ls, color=colors[kind], label=f"{kind}, {scheme}")
        if np.isfinite(e[0]):
            ax.loglog(n, e[0] * (n[0] / n) ** EXPECTED[scheme], ":", color="0.5", lw=1)
    ax.set_xticks(n, [str(int(v)) for v in n])
    ax.xaxis.set_minor_formatter(NullFormatter())
    decorate(ax, "elements (the step halves with the element)", "history error (relative)",
             "Errors; dotted: orders 1 and 2")
    page.figure(fig, "thin_belt", "The thin belt's start-up: exact histories (lines) and "
                                  "simulated (markers), and the history error as the grid "
                                  "and the step shrink together")


def _common(ref, res, page: Page, label: str):
    """Both histories at the checks they share (the same times: steps land on checks)."""
    n = min(len(ref.history["t"]), len(res.history["t"]))
    t_ref, t = ref.history["t"][:n], res.history["t"][:n]
    if not np.allclose(t, t_ref, rtol=0, atol=1e-9 * t_ref[-1]):
        page.fail(f"{label}: its checks are not the reference run's")
    return t_ref, ref.history["total_friction"][:n], res.history["total_friction"][:n]


def tolerance_section(page: Page, quick: bool) -> None:
    cfg = TOLS[quick]
    grid = [("numerics.elements", cfg['elements'])] if cfg["elements"] else []
    where = f"{cfg['elements']} elements" if cfg["elements"] else "the default grid"
    expo = TOL_EXPONENT[DEFAULT_INTEGRATOR]
    page.heading("The default time tolerance's path error on paper_slip")
    page.para(
        f"The default scheme's ({DEFAULT_INTEGRATOR}) step is set by `numerics.time_tol`, "
        f"the local error per step; its default, {num(DEFAULT_TIME_TOL)}, is chosen so that "
        f"the total-friction history of the paper slip scene stays within 1e-3 of a "
        f"converged one in time (max over the checks, relative to the steady total "
        f"friction; the grid's share is on the spectrum page). Here the scene runs from "
        f"rest to steady state on {where} at several tolerances and is compared with a "
        f"run at `numerics.time_tol={num(cfg['reference'])}`, check by check (the "
        f"adaptive steps land on every check). Under local error control the path error "
        f"should go about as time_tol^{expo:.2g}. The "
        f"explicit scheme (its fixed step, 0.9 of the stability limit) is a second, "
        f"independent second-order path on the same semi-discretisation; its checks fall "
        f"within a step of the default scheme's, so its history is moved onto them with its "
        f"own slope.")
    scene = shipped_scene("paper_slip", grid)
    ref = run(scene.with_overrides([("numerics.time_tol", cfg['reference'])]),
              raise_on_failure=False)
    if not ref.converged:
        page.fail(f"time_tol {num(cfg['reference'])} reference: {ref.reason}")
    F = abs(ref.reference.total_friction)
    rows = [[num(cfg["reference"]) + " (reference)", str(ref.steps),
             str(ref.statistics.get("rejected_steps", 0)), fmt(ref.wall_time, ".3g"), "", "",
             "converged" if ref.converged else FAILED]]
    diffs, curves = [], {}
    for tol in cfg["tols"]:
        res = run(scene.with_overrides([("numerics.time_tol", tol)]), raise_on_failure=False)
        t, f_ref, f = _common(ref, res, page, f"time_tol {num(tol)}")
        d = float(np.max(np.abs(f - f_ref)) / F)
        diffs.append((tol, d))
        curves[f"{DEFAULT_INTEGRATOR}, time_tol {num(tol)}"] = (t, np.abs(f - f_ref) / F)
        status = "converged" if res.converged else page.fail(
            f"time_tol {num(tol)}: {res.reason}")
        label = num(tol) + (" (default)" if tol == DEFAULT_TIME_TOL else "")
        rows.append([label, str(res.steps), str(res.statistics.get("rejected_steps", 0)),
                     fmt(res.wall_time, ".3g"), f"{d:.2e}",
                     f"{d / tol ** expo:.3g}",
                     status])
        if tol == DEFAULT_TIME_TOL:
            default = d
    exp = run(scene.with_overrides([("numerics.integrator", "explicit")]), raise_on_failure=False)
    t_ref, f_ref = ref.history["t"], ref.history["total_friction"]
    t, f = exp.history["t"], exp.history["total_friction"]
    n = min(len(t), len(t_ref))
    moved = f[:n] + np.gradient(f, t)[:n] * (t_ref[:n] - t[:n])
    d_exp = float(np.max(np.abs(moved - f_ref[:n])) / F)
    curves["explicit"] = (t_ref[:n], np.abs(moved - f_ref[:n]) / F)
    rows.append(["explicit (fixed step)", str(exp.steps), "", fmt(exp.wall_time, ".3g"),
                 f"{d_exp:.2e}", "", "converged" if exp.converged else page.fail(
                     f"explicit: {exp.reason}")])
    page.table(["time_tol", "steps", "rejected steps", "wall [s]",
                "path difference from the reference", f"difference / time_tol^{expo:.2g}",
                "status"], rows)
    verdict = "within" if default <= 1e-3 else "NOT within"
    if default > 1e-3:
        page.fail(f"the default time_tol's path difference {default:.2e} exceeds 1e-3")
    tols, ds = np.array(diffs).T
    slope = float(np.polyfit(np.log(tols), np.log(ds), 1)[0]) if len(diffs) > 1 else None
    page.para(
        f"At the default time_tol the path is {default:.2e} from the reference: {verdict} "
        f"1e-3. The reference run's own error, about "
        f"({num(cfg['reference'])} / {num(DEFAULT_TIME_TOL)})^{expo:.2g} = "
        f"{(cfg['reference'] / DEFAULT_TIME_TOL) ** expo:.2g} of the default's, is "
        f"inside that margin. The explicit path is {d_exp:.2e} from the reference."
        + (f" The path difference goes as time_tol^{slope:.2f} (least squares; "
           f"{expo:.2g} expected)." if slope is not None else ""))
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4), constrained_layout=True)
    for label, (t, d) in curves.items():
        ax.semilogy(t, np.maximum(d, 1e-12), label=label, lw=1)
    ax.axhline(1e-3, ls="--", color="k", lw=0.8, label="1e-3")
    decorate(ax, "t [s]", "|F - F_ref| / |F_steady|", f"paper_slip, {where}: total "
             f"friction against the time_tol {num(cfg['reference'])} run")
    page.figure(fig, "time_tol", "Path difference of the total friction from the reference "
                                 "run, check by check")



def build(page: Page, quick: bool) -> None:
    page.para(
        "The end-state pages check where a run arrives; this one checks the way there. A "
        "time-accurate scheme (implicit, explicit) follows the scene's own transient to a "
        "controlled error, and that error is measured here against an exact transient "
        "and against converged runs.")
    thin_section(page, quick)
    tolerance_section(page, quick)
