"""Page: the exact spectrum of the linearised steady state, the discrete spectra converging
to it, and the inertial paths of the two gyroscopic forms converging in the grid."""

from __future__ import annotations

import math
import time

import numpy as np

from beltsim.api import shipped_scene
from beltsim.physics import modes
from beltsim.simulation.controller import run
from beltsim.solvers.settings import DEFAULT_ADHESION_LAYER, resolve

from .kit import FAILED, Page, decorate, fmt

TITLE = "The converged spectrum and the inertial paths"
SCENES = ("paper_slip", "paper_inertia")
DAMPINGS = (39.0, 0.0)
#: f_max (Hz) of the exact spectrum; the grids of the discrete spectra; the path study's
#: grids, its reference grid, span (s), time_tol and history interval (s)
CFG = {False: {"scenes": SCENES, "dampings": DAMPINGS, "seed": modes.SEED_ELEMENTS,
               "f_max": 3000.0, "band": 900.0, "ladder": (600, 1200, 2400, 4800, 9600),
               "paths": (600, 1200, 2400, 4800), "path_ref": 9600, "t_end": 0.25,
               "tol": 1e-8, "every": 2.5e-4},
       True: {"scenes": ("paper_slip",), "dampings": (39.0,), "seed": 200,
              "f_max": 600.0, "band": 600.0, "ladder": (300, 600),
              "paths": (150, 300), "path_ref": 600, "t_end": 0.02, "tol": 1e-6,
              "every": 1e-3}}
#: the bands (Hz) of the chain above the least stable root's band, an octave each
CHAIN = {False: ((0.0, 3000.0), (3000.0, 6000.0), (6000.0, 12000.0), (12000.0, 24000.0)),
         True: ((0.0, 600.0), (600.0, 1200.0))}


def fixed_law(scene) -> list:
    """Overrides that hold the friction law's regularisation at the default grid's value,
    so every grid linearises the same law (it otherwise shrinks with the grid)."""
    P, num = scene.params, resolve(scene)
    if P.friction == "coulomb":
        return [("numerics.regularisation", num.regularisation)]
    return [("numerics.adhesion_layer", DEFAULT_ADHESION_LAYER * P.L)]


def hz(lam: complex) -> float:
    return lam.imag / (2.0 * math.pi)


def exact_section(page: Page, cfg: dict) -> dict:
    page.heading("Does the steady state flutter? The exact spectrum")
    page.para(
        "The continuous model linearised about its exact steady state, with the friction's "
        "linearisation held fixed (the stick zone's constraint that the bottom fibre moves "
        "with the surface, no friction slope where it slides), has a characteristic "
        "determinant of a small matrix whose entries are exponentials in x "
        "(`beltsim.physics.continuum`): its roots are the eigenvalues, exact to the root "
        "finder's 1e-12, with no grid. `beltsim.physics.modes.exact_spectrum` finds them "
        "by Newton's method from the eigenvalues of the discrete model on "
        f"{cfg['seed']} elements (central form) and from a scan of the band. "
        f"Below: the three least stable roots up to {cfg['f_max']:g} Hz.")
    rows, out = [], {}
    for name in cfg["scenes"]:
        for d in cfg["dampings"]:
            start = time.perf_counter()
            roots = modes.exact_spectrum(shipped_scene(name), cfg["f_max"], damping=d,
                                         seed_elements=cfg["seed"])
            out[(name, d)] = roots
            growing = int(np.sum(roots.real > 0.0))
            rows.append([name, fmt(d, "g"), str(len(roots)), str(growing)]
                        + [f"{z.real:+.3f} 1/s at {hz(z):.2f} Hz" for z in roots[:3]]
                        + [fmt(time.perf_counter() - start, ".3g")])
    page.table(["scene", "damping d [1/s]", "roots found", "growing", "least stable",
                "second", "third", "wall [s]"], rows)
    worst = {k: v[0] for k, v in out.items()}
    page.para(
        "Answer: yes. " + "; ".join(
            f"{n} at d = {d:g} 1/s: a mode at {hz(z):.1f} Hz grows at {z.real:.3g} 1/s"
            for (n, d), z in worst.items()) + ". The roots form chains that go on to high "
        "frequencies with growth rates that do not decay: the stick zone carries the "
        "bottom fibre's displacement with the flow from x1 to its end, where the "
        "concentrated friction force of the outflow feeds it back into the spans, a loop "
        "with a delay (the transit time of the stick zone) whose gain exceeds one. The "
        "scene's damping d lowers the rates by only a few 1/s: the growing modes are "
        "mostly the carried displacement, whose material derivative the damping of u_t "
        "barely sees.")
    return out


def chain_section(page: Page, cfg: dict, quick: bool) -> None:
    """The exact roots band by band above the runs' band: the chains' rates."""
    from beltsim.physics import continuum

    bands = CHAIN[quick]
    page.heading("Above the band: growing roots in every octave")
    page.para(
        "The same determinant's roots band by band up to "
        f"{bands[-1][1]:g} Hz (`beltsim.physics.continuum.characteristic(scene)"
        ".roots(f_max, f_min)`, Newton's method from a grid of starts over each band): how "
        "many, how many grow, and the largest rate with its frequency.")
    rows, points, quiet = [], {}, []
    for name in cfg["scenes"]:
        for d in cfg["dampings"]:
            ch = continuum.characteristic(
                shipped_scene(name).with_overrides({"physics.damping": d}))
            found = []
            for lo, hi in bands:
                start = time.perf_counter()
                roots = ch.roots(hi, f_min=lo)
                found.append(roots)
                if not np.any(roots.real > 0.0):
                    quiet.append(f"{name} at d = {d:g} 1/s, {lo:g}-{hi:g} Hz")
                top = roots[np.argmax(roots.real)] if roots.size else None
                rows.append([name, fmt(d, "g"), f"{lo:g}-{hi:g}", str(roots.size),
                             str(int(np.sum(roots.real > 0.0))),
                             f"{top.real:+.3f} 1/s at {hz(top):.1f} Hz" if top is not None
                             else "none found", fmt(time.perf_counter() - start, ".3g")])
            points[(name, d)] = np.concatenate(found)
    page.table(["scene", "damping d [1/s]", "band [Hz]", "roots found", "growing",
                "largest rate", "wall [s]"], rows)
    high = {k: v[np.abs(v.imag) / (2 * math.pi) > bands[0][1]] for k, v in points.items()}
    faster = [f"{n} at d = {d:g} 1/s: {v[np.argmax(v.real)].real:.3g} 1/s at "
              f"{hz(v[np.argmax(v.real)]):.0f} Hz" for (n, d), v in high.items() if v.size]
    if quiet:
        page.para("Read: some bands hold no growing root (" + "; ".join(quiet) + "): the "
                  "chains' rates fall somewhere.")
    else:
        page.para(
            f"Read: above the first band ({bands[0][1]:g} Hz) every band holds growing roots, "
            "at rates as large as the band's least stable one, and larger in places ("
            + "; ".join(faster) + "). No band holds the model's least stable mode: its "
            f"chains grow at about the same rates up to {bands[-1][1]:g} Hz, the highest "
            "band searched. Its only damping, d on u_t and "
            "theta_t, lowers every rate by about the same amount, and nothing in it damps "
            "short waves more than long ones. So a transient grows in whichever of these "
            "modes its grid resolves best, and a finer grid resolves new ones: the limit cycle "
            "of a physical transient is the grid's, and converges neither in the grid nor to "
            "the least stable root of a band ([flutter](flutter.md)). A run's stability entry "
            "names its band for this reason.")
    roots_figure(page, points, f"Exact eigenvalues up to {bands[-1][1]:g} Hz",
                 "exact_chain", "The exact roots band by band: growing roots in every "
                 "octave, at rates that do not decay", bottom=-40.0, size=2)


def roots_figure(page: Page, roots_by_scene: dict, title: str, name: str, caption: str,
                 bottom: float, size: float) -> None:
    """Exact roots as points in the (frequency, rate) plane, one series per (scene, d)."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4), constrained_layout=True)
    for (scene, d), roots in roots_by_scene.items():
        ax.plot(roots.imag / (2 * math.pi), roots.real, ".", ms=size,
                label=f"{scene}, d = {d:g} 1/s")
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_ylim(bottom, 25)
    decorate(ax, "frequency [Hz]", "rate Re(lambda) [1/s]", title)
    page.figure(fig, name, caption)


def convergence_section(page: Page, cfg: dict, exact: dict) -> dict:
    page.heading("The discrete spectra against the exact one")
    page.para(
        "The two least stable exact roots below "
        f"{cfg['band']:g} Hz of each scene (d = 39 1/s), and the discrete model's "
        "eigenvalue nearest to each (shift-invert), with the upwind (default) and the "
        "central (Galerkin, skew) gyroscopic forms. The friction law's regularisation is "
        "held at the default grid's value on every grid, so each grid linearises the same "
        "law. Error: |discrete - exact|; order: log2 of its ratio between grids.")
    rows, damping, last_orders = [], {}, {"central": [], "upwind": []}
    for name in cfg["scenes"]:
        scene = shipped_scene(name, fixed_law(shipped_scene(name)))
        roots = exact[(name, 39.0)]
        targets = roots[np.abs(roots.imag) < 2 * math.pi * cfg["band"]][:2]
        for k, z in enumerate(targets):
            prev = {}
            for N in cfg["ladder"]:
                cells = [name, f"{z.real:+.4f} at {hz(z):.3f} Hz", str(N)]
                for form in ("central", "upwind"):
                    lam = modes.nearest_eigenvalue(
                        scene.with_overrides([("numerics.gyroscopic", form)]), z, N)
                    err = abs(lam - z)
                    order = (fmt(math.log2(prev[form] / err), ".2f")
                             if form in prev and err > 0 else "")
                    prev[form] = err
                    cells += [f"{lam.real:+.3f} at {hz(lam):.3f} Hz", f"{err:.2e}", order]
                    if N == cfg["ladder"][-1] and order:
                        last_orders[form].append(float(order))
                    if form == "upwind" and k == 0:
                        damping.setdefault(name, {})[N] = z.real - lam.real
                rows.append(cells)
    page.table(["scene", "exact root [1/s]", "elements", "central", "error", "order",
                "upwind", "error", "order"], rows)
    def span(v):
        return f"{min(v):.2f} to {max(v):.2f}" if v else "n/a"

    page.para(
        "On coarse grids the nearest discrete eigenvalue may belong to a neighbouring mode "
        "(the modes are a few hertz apart); on the finest pair the central form's order "
        f"is {span(last_orders['central'])}, the upwind form's "
        f"{span(last_orders['upwind'])}. The central form keeps the growing modes, as the "
        "exact spectrum has them; the upwind form damps them numerically by " + "; ".join(
            f"{name}: " + ", ".join(f"{v:.3g} 1/s on {N}" for N, v in per.items())
            for name, per in damping.items())
        + " elements (the least stable root's rate minus the discrete one's).")
    return damping


def _history(name, form, N, cfg):
    scene = shipped_scene(name, [("numerics.elements", N), ("numerics.gyroscopic", form),
                                 ("numerics.time_tol", cfg["tol"]),
                                 ("numerics.t_end", cfg["t_end"]),
                                 ("numerics.snapshot_interval", cfg["every"])])
    res = run(scene, raise_on_failure=False)
    return res


def paths_section(page: Page, cfg: dict) -> dict:
    page.heading("The inertial paths converging in the grid")
    ref_n = cfg["path_ref"]
    page.para(
        f"paper_slip from rest to t = {cfg['t_end']:g} s by the default scheme (esdirk3) "
        f"at `numerics.time_tol = {cfg['tol']:g}` (its time error far below the "
        f"differences shown), total friction and slip start every "
        f"{cfg['every'] * 1e3:g} ms, against the central form on {ref_n} elements: max "
        "over the checks of |F - F_ref| / |F_steady| (all; the ramp t < 0.02 s; t >= 0.1 "
        "s) and of |x* - x*_ref| (m). Both forms converge to the same path. Order: log2 "
        "of the ratio between grids (the last one is lowered by the reference's own "
        "error).")
    ref = _history("paper_slip", "central", ref_n, cfg)
    if not np.all(np.isfinite(ref.history["total_friction"])):
        page.fail(f"the reference run failed: {ref.reason}")
        return {}
    tr, fr, sr = (ref.history[k] for k in ("t", "total_friction", "slip_start"))
    F = abs(fr[-1])
    rows, out = [], {}
    for form in ("central", "upwind"):
        prev = None
        for N in cfg["paths"]:
            res = _history("paper_slip", form, N, cfg)
            t, f, s = (res.history[k] for k in ("t", "total_friction", "slip_start"))
            n = min(len(t), len(tr))
            if n < 2 or not np.allclose(t[:n], tr[:n], rtol=0, atol=1e-9):
                rows.append([form, str(N), FAILED] + [""] * 10)
                page.fail(f"{form} on {N} elements: its checks are not the reference's")
                continue
            e = np.abs(f[:n] - fr[:n]) / F
            ramp, late = t[:n] < 0.02, t[:n] >= 0.1
            errs = [e.max(), e[ramp].max(), e[late].max() if late.any() else np.nan,
                    float(np.nanmax(np.abs(s[:n] - sr[:n])))]
            out[(form, N)] = errs
            cells = [form, str(N), str(res.steps), fmt(res.wall_time, ".3g")]
            for i, err in enumerate(errs):
                cells.append(f"{err:.2e}" if np.isfinite(err) else "")
                cells.append(fmt(math.log2(prev[i] / err), ".2f")
                             if prev is not None and np.isfinite(err) and err > 0 else "")
            prev = errs
            rows.append(cells)
    page.table(["form", "elements", "steps", "wall [s]", "friction path", "order", "ramp",
                "order", "t >= 0.1 s", "order", "slip start [m]", "order"], rows)
    def orders(form, i):
        errs = [out[(form, N)][i] for N in cfg["paths"] if (form, N) in out]
        return ", ".join(f"{math.log2(a / b):.2f}" for a, b in zip(errs, errs[1:])
                         if np.isfinite(a) and np.isfinite(b) and b > 0) or "n/a"

    page.para(
        f"Read: after the ramp (t >= 0.1 s) the central form's path converges at orders "
        f"{orders('central', 2)} and the upwind form's at {orders('upwind', 2)}; during "
        f"the ramp they are {orders('central', 1)} and {orders('upwind', 1)}, and the slip "
        f"start's path {orders('central', 3)} and {orders('upwind', 3)}. That first-order "
        "part does not depend on the gyroscopic form; its likely source, not isolated "
        "here, is the slip front moving through the grid during the ramp: the friction "
        "near a moving front is integrated over whole control volumes and read inside one "
        "cell, so its error changes at O(h) as the front crosses a node.")
    return out


def build(page: Page, quick: bool) -> None:
    cfg = CFG[quick]
    page.para(
        "Whether the paper's inertial steady states are stable, computed without a grid; "
        "how the discrete model's spectrum and its transient paths converge, with the "
        "default upwind gyroscopic term and with the second-order central one "
        "(`numerics.gyroscopic`). Theory: docs/theory/stability.md.")
    exact = exact_section(page, cfg)
    chain_section(page, cfg, quick)
    convergence_section(page, cfg, exact)
    paths_section(page, cfg)
    roots_figure(page, exact, "Exact eigenvalues of the linearised steady states",
                 "exact_spectrum", "The exact roots (physics.continuum) near the imaginary "
                 "axis: above zero they grow", bottom=-60.0, size=3)
