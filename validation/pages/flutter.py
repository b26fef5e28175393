"""Page: the flutter of the paper's unstable steady states, followed by physical transients
(``numerics.transient = "physical"``, :mod:`beltsim.studies.flutter`): the linear phase
against the linearisation of the model and scheme, and the limit cycle on a ladder of
grids and steps, or its absence under perfect adhesion."""

from __future__ import annotations

import math

import numpy as np

from beltsim.api import shipped_scene
from beltsim.physics import modes
from beltsim.simulation import stability as st
from beltsim.studies.flutter import flutter_run, observed_order

from .kit import Page, decorate, fmt
from .spectrum import fixed_law

TITLE = "Flutter: the linear phase and the limit cycle"
#: the linear phase's grid, span (s), fit window (s) and perturbation; the limit cycle's
#: grids, the step ladder's grid, span (s), and the adhesion run's grid
#: (the quick mode checks the page's making, not the rate: its grid has no clean linear
#: phase in its span)
CFG = {False: {"linear": 150, "linear_t": 1.0, "fit": (0.4, 1.0), "kick": 1e-6,
               "grids": (300, 600, 1200), "half": 600, "t_end": 2.5, "adhesion": 600,
               "dampings": (39.0, 0.0), "check": True},
       True: {"linear": 60, "linear_t": 0.15, "fit": (0.05, 0.15), "kick": 1e-6,
              "grids": (40, 80), "half": 40, "t_end": 0.05, "adhesion": 40,
              "dampings": (39.0, 0.0), "check": False}}


def linear_section(page: Page, cfg: dict) -> None:
    n = cfg["linear"]
    page.heading("The linear phase against the linearised model and scheme")
    scene = shipped_scene("paper_slip")
    central = scene.with_overrides([("numerics.gyroscopic", "central"),
                                    ("numerics.elements", n)])
    found = st.exact_least_stable(central)
    h = st.physical_step(found, "esdirk3")
    eigs = modes.spectrum(*modes.steady_discretisation(central))
    rates = [(z.real - st.step_damping("esdirk3", z, h), z) for z in eigs if abs(z) > 1e-3]
    predicted, lam = max(rates, key=lambda r: r[0])
    run = flutter_run(scene, cfg["linear_t"], elements=n, from_steady=cfg["kick"])
    measured = run.growth(*cfg["fit"])
    err = (measured - predicted) / predicted
    page.para(
        f"paper_slip (d = 39 1/s) on {n} elements, from the grid's steady state with u "
        f"perturbed by {cfg['kick']:g} of its largest value, by esdirk3 at the physical "
        f"step limit h = {h:.3g} s. Its linearisation predicts growth at the largest Re "
        f"lambda - D(lambda, h) over the discrete eigenvalues (D the scheme's damping over "
        f"steps h, from its amplification factor): that is the grid's mode, not yet the "
        f"exact one, which the central form reaches at second order on far finer grids "
        f"(the [spectrum](spectrum.md) page). The measured rate is the slope of the "
        f"logarithm of the friction's envelope over {cfg['fit'][0]:g}-{cfg['fit'][1]:g} s.")
    ok = abs(err) <= 0.05 or not cfg["check"]
    page.table(["elements", "predicted [1/s]", "at [Hz]", "measured [1/s]", "difference",
                "exact least stable root", "wall [s]"],
               [[n, f"{predicted:+.3f}", f"{abs(lam.imag) / (2 * math.pi):.1f}",
                 f"{measured:+.3f}", f"{err:+.1%}" if ok else page.fail(
                     f"linear phase on {n} elements: {measured:.3f} against {predicted:.3f}"),
                 f"{found.rate:+.3f} 1/s at {found.frequency:.1f} Hz",
                 fmt(run.wall_time)]])


def _scene(name: str, damping: float):
    """The shipped scene at damping d, its friction law's regularisation held at the
    default grid's value."""
    scene = shipped_scene(name).with_overrides({"physics.damping": damping})
    return scene.with_overrides(fixed_law(scene))


def cycle_rows(page: Page, cfg: dict, damping: float) -> tuple[list, dict]:
    scene = _scene("paper_slip", damping)
    runs = {}
    for n in cfg["grids"]:
        runs[(n, 1.0)] = flutter_run(scene, cfg["t_end"], elements=n)
    runs[(cfg["half"], 0.5)] = flutter_run(scene, cfg["t_end"], elements=cfg["half"],
                                           step_factor=0.5)
    rows = []
    for (n, _factor), run in runs.items():
        lc = run.limit_cycle()
        late = run.envelope()[1]
        rising = late[-1] / late[max(0, len(late) - 25)] if len(late) > 1 else math.nan
        rows.append([n, f"{run.step:.3g}", run.steps, fmt(run.wall_time),
                     f"{lc['friction']:.2%}", f"{lc['friction_mean']:+.2%}",
                     f"{lc['front_range'][0]:.4f}-{lc['front_range'][1]:.4f}",
                     f"{lc['u']:.3g}", f"{lc['frequencies'][0]:.0f}" if lc["frequencies"]
                     else "", f"{rising:.2f}"])
    return rows, runs


def cycle_section(page: Page, cfg: dict, damping: float) -> dict:
    page.heading(f"From rest to the limit cycle (paper_slip, d = {damping:g} 1/s)")
    rows, runs = cycle_rows(page, cfg, damping)
    page.para(
        f"paper_slip at d = {damping:g} 1/s from rest to t = {cfg['t_end']:g} s, physical "
        f"transients (central "
        f"form, esdirk3 at the step limit that resolves every growing exact root up to "
        f"{st.BAND_HZ:g} Hz), the friction law's regularisation held at the default grid's "
        f"value on every grid. Over the last 0.2 s: half the peak-to-peak of the total "
        f"friction (relative to the grid's steady value), its mean shift, the slip front's "
        f"range, half the peak-to-peak of u in the middle of the outflow span, the "
        f"friction's leading frequency, and the envelope's growth over the last 0.5 s "
        f"(1.00: settled).")
    page.table(["elements", "step [s]", "steps", "wall [s]", "friction amplitude",
                "mean shift", "slip front [m]", "u amplitude [m]", "frequency [Hz]",
                "envelope growth"], rows)
    lcs = {key: run.limit_cycle() for key, run in runs.items()}
    amps = [lcs[(n, 1.0)]["friction"] for n in cfg["grids"]]
    freqs = [lcs[(n, 1.0)]["frequencies"][:1] for n in cfg["grids"]]
    halved = lcs[(cfg["half"], 0.5)]["friction"] - lcs[(cfg["half"], 1.0)]["friction"]
    same_mode = len({round(f[0], -1) for f in freqs if f}) == 1
    if len(amps) < 3:
        order = "fewer than three grids: no observed order"
    elif same_mode:
        order = (f"observed order of the friction amplitude over the last three grids: "
                 f"{observed_order(*amps[-3:]):.2f}")
    else:
        order = ("no order over the grids: their cycles are different modes (leading "
                 "frequencies " + ", ".join(f"{f[0]:.0f}" for f in freqs if f) + " Hz), "
                 "and a cycle still growing (envelope growth above 1) is not yet the limit")
    page.para(f"With the step halved on {cfg['half']} elements the amplitude moves by "
              f"{halved:+.2%} of the steady friction; {order}.")
    return runs


def adhesion_section(page: Page, cfg: dict, damping: float) -> None:
    page.heading(f"Perfect adhesion (paper_inertia, d = {damping:g} 1/s)")
    run = flutter_run(_scene("paper_inertia", damping), cfg["t_end"],
                      elements=cfg["adhesion"])
    c, p = run.envelope()
    # the growth where the deviation rises through (1e-3, 0.3), past the start-up's
    rising = np.flatnonzero((c > 0.2 * c[-1]) & (p > 1e-3) & (p < 0.3))
    if rising.size >= 3:
        t0, t1 = c[rising[0]], c[rising[-1]]
        growth = (f"Its envelope grows at {run.growth(t0, t1):.3g} 1/s from "
                  f"{t0:.3g} to {t1:.3g} s (deviation 1e-3 to 0.3).")
    else:
        growth = "Its envelope does not rise through 1e-3 to 0.3 in this span."
    page.para(
        f"paper_inertia at d = {damping:g} 1/s from rest, {cfg['adhesion']} elements, to "
        f"t = {cfg['t_end']:g} s. "
        f"Perfect adhesion has no friction bound: the run ends with: {run.reason}. "
        + growth)


def build(page: Page, quick: bool) -> None:
    cfg = CFG[quick]
    page.para(
        "Physical transients of the paper's unstable steady states "
        "(`numerics.transient = \"physical\"`; theory: docs/theory/stability.md, the delay "
        "loop and what saturates it), recorded by `beltsim.studies.flutter`.")
    linear_section(page, cfg)
    runs = {}
    for d in cfg["dampings"]:
        runs[d] = cycle_section(page, cfg, d)
        adhesion_section(page, cfg, d)
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(runs), figsize=(11, 4), sharey=True,
                             constrained_layout=True)
    for ax, (d, ladder) in zip(np.atleast_1d(axes), runs.items()):
        for (n, factor), run in ladder.items():
            c, p = run.envelope()
            ax.semilogy(c, p, label=f"{n} elements" + ("" if factor == 1.0 else ", step / 2"))
        decorate(ax, "t [s]", "max |F - F_s| / F_s per window",
                 f"paper_slip, d = {d:g} 1/s: the friction's envelope")
    page.figure(fig, "envelope", "The total friction's deviation from the grid's steady "
                                 "value, largest per 20 ms window, on each grid")
