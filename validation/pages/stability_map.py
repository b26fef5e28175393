"""Page: a stability map of the paper's inertial steady states, the least stable exact root
over the damping d, the friction limit f* and the belt speed c, and the damping a stable
steady state needs; and of the closed drives, by their discrete estimate over d and the
friction coefficient (:mod:`beltsim.studies.stability_map`).

A page of its own rather than a section of the spectrum page: it depends on the map's
study module, which the spectrum page does not, and it is rewritten in minutes where the
spectrum page's paths take most of an hour.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
import time

from beltsim.api import shipped_scene
from beltsim.errors import NoSolutionError
from beltsim.problem import analytic
from beltsim.simulation.stability import BAND_HZ
from beltsim.studies import stability_map as study

from .kit import Page, decorate, fmt, num

TITLE = "A stability map of the paper's steady states and of the drives"
SCENES = ("paper_slip", "paper_inertia")
#: the closed drives mapped, each on its own grid (the quick page: a coarse one)
DRIVES = ("drive_flat", "serpentine_accessory")
CFG = {False: {"scenes": SCENES, "dampings": study.DEFAULT_VALUES["damping"],
               "frictions": study.DEFAULT_VALUES["max_friction"],
               "speeds": study.DEFAULT_VALUES["belt_speed"], "tol": study.TOLERANCE,
               "drives": DRIVES, "drive_elements": None,
               "drive_dampings": study.DRIVE_DEFAULT_VALUES["damping"],
               "drive_mus": study.DRIVE_DEFAULT_VALUES["friction_coefficient"]},
       True: {"scenes": ("paper_slip",), "dampings": (39.0, 200.0), "frictions": (1e4,),
              "speeds": (100.0,), "tol": 40.0, "drives": ("drive_flat",),
              "drive_elements": 60, "drive_dampings": (0.0, 80.0), "drive_mus": (0.4,)}}


@contextlib.contextmanager
def fresh_cache():
    """Every root computed by this run, so that the page's wall times are the searches'
    (the user's cache would serve the roots an earlier run computed)."""
    old = os.environ.get("BELTSIM_CACHE_DIR")
    with tempfile.TemporaryDirectory(prefix="beltsim_map_") as folder:
        os.environ["BELTSIM_CACHE_DIR"] = folder
        try:
            yield
        finally:
            if old is None:
                os.environ.pop("BELTSIM_CACHE_DIR", None)
            else:
                os.environ["BELTSIM_CACHE_DIR"] = old


def cells(page: Page, row: dict) -> list:
    """(rate, frequency, growing) of a point; its status where it has no root (a search
    that finds none is a failure of the page)."""
    if row["rate"] is None:
        if row["status"] == study.NO_ROOT:
            return [page.fail(f"{row['param']} = {row['value']:g}: {row['reason']}"), "", ""]
        return [row["status"], "", ""]
    return [f"{row['rate']:+.3f}", f"{row['frequency']:.1f}", str(row["growing"])]


def computed(rows) -> str:
    n = sum(not r["cached"] for r in rows)
    wall = sum(r["wall_time"] for r in rows)
    return f"{n} root {'search' if n == 1 else 'searches'}, {wall:.0f} s"


def damping_section(page: Page, cfg: dict) -> dict:
    page.heading("The damping d")
    page.para(
        "The least stable exact root up to "
        f"{BAND_HZ:g} Hz of each scene at each damping d (1/s, `physics.damping`; the "
        "steady state does not depend on d, only its spectrum does); growing: how many "
        "roots in the band grow. `beltsim stability-map SCENE --param damping --values "
        + ",".join(f"{d:g}" for d in cfg["dampings"]) + "` gives each column.")
    sweeps = {name: study.sweep(shipped_scene(name), "damping", cfg["dampings"])
              for name in cfg["scenes"]}
    header = ["d [1/s]"]
    for name in cfg["scenes"]:
        header += [f"{name} rate [1/s]", "at [Hz]", "growing"]
    rows = []
    for i, d in enumerate(cfg["dampings"]):
        line = [fmt(d, "g")]
        for name in cfg["scenes"]:
            line += cells(page, sweeps[name][i])
        rows.append(line)
    page.table(header, rows)
    page.para("Cost: " + "; ".join(f"{name} {computed(r)}" for name, r in sweeps.items())
              + ". " + monotone_note(sweeps))
    return sweeps


def monotone_note(sweeps: dict) -> str:
    """Whether the rate falls with d at every step of each sweep (what bisection on d
    relies on to find the smallest stable d)."""
    parts = []
    for name, rows in sweeps.items():
        rates = [r["rate"] for r in rows]
        if len(rates) < 2 or None in rates:
            continue
        falls = all(b < a for a, b in zip(rates, rates[1:]))
        drop = (rates[0] - rates[-1]) / (rows[-1]["value"] - rows[0]["value"])
        parts.append(f"{name}: the rate {'falls' if falls else 'does not fall'} with d at "
                     f"every step, by {drop:.3g} 1/s per 1/s of d on average")
    return ("; ".join(parts) + ".") if parts else ""


def critical_section(page: Page, cfg: dict) -> dict:
    page.heading("The damping a stable steady state needs")
    page.para(
        "The smallest d at which no root in the band grows "
        "(`beltsim.studies.stability_map.critical_damping`): from the scene's d = 39 1/s, "
        "d doubled until the least stable rate is <= 0, then the bracket halved until it "
        f"is {cfg['tol']:g} 1/s wide. The table gives the bracket's ends, the rates there "
        "and the searches it took. Command: `beltsim stability-map SCENE "
        f"--critical-damping --tol {cfg['tol']:g}`.")
    rows, out = [], {}
    for name in cfg["scenes"]:
        start = time.perf_counter()
        crit = study.critical_damping(shipped_scene(name), tol=cfg["tol"])
        out[name] = crit
        at = {r["value"]: r for r in crit.evaluations}
        if crit.damping is None:
            rows.append([name, crit.reason, "", "", "", str(len(crit.evaluations)),
                         fmt(time.perf_counter() - start, ".3g")])
            continue
        above = at[crit.damping]
        below = at.get(crit.lower) if crit.lower is not None else None
        rows.append([name, f"{crit.damping:.2f}",
                     "" if crit.lower is None else f"{crit.lower:.2f}",
                     "" if below is None else f"{below['rate']:+.3f} at "
                                              f"{below['frequency']:.1f} Hz",
                     f"{above['rate']:+.3f} at {above['frequency']:.1f} Hz",
                     str(len(crit.evaluations)), fmt(time.perf_counter() - start, ".3g")])
    page.table(["scene", "critical d [1/s]", "rate > 0 at d [1/s]", "rate there",
                "rate at the critical d", "root searches", "wall [s]"], rows)
    found = {n: c for n, c in out.items() if c.damping is not None}
    if found:
        page.para(
            "Answer: " + "; ".join(
                f"{n} needs d = {c.damping:.1f} 1/s ({c.damping / 39.0:.2g} times the "
                f"scene's 39 1/s, about {2 * c.damping / 39.0:.2g}% of critical in the "
                "lowest free-span mode by the scenes' own estimate)"
                for n, c in found.items())
            + ". Below it the steady state flutters in the model. The damping acts on "
            "u_t and theta_t, which the growing modes, mostly the stick zone's carried "
            "displacement, barely move (docs/theory/stability.md).")
    return out


def friction_section(page: Page, cfg: dict) -> list:
    page.heading("The friction limit f*")
    page.para(
        "paper_slip (d = 39 1/s) at each f* (N/m, `contact.max_friction`); the exact "
        "steady state's slip start x* and its stick zone [x1, x*] (x1 = L/3; full slip, no "
        "stick zone, where x* = x1). Perfect adhesion (paper_inertia) has no f*. Command: "
        "`beltsim stability-map paper_slip --param max_friction --values "
        + ",".join(num(f) for f in cfg["frictions"]) + "`.")
    scene = shipped_scene("paper_slip")
    swept = study.sweep(scene, "max_friction", cfg["frictions"])
    rows = []
    for row in swept:
        try:
            sol = analytic.solve(scene.with_overrides(study.overrides(
                scene, "max_friction", row["value"])))
            xs = f"{sol.x_star:.4f}"
            stick = f"{sol.x_star - scene.params.x1:.4f}"
        except NoSolutionError:
            xs = stick = ""
        rows.append([num(row["value"]), xs, stick, *cells(page, row)])
        row["stick"] = None if not stick else float(stick)
    page.table(["f* [N/m]", "slip start x* [m]", "stick zone [m]", "rate [1/s]",
                "at [Hz]", "growing"], rows)
    stable = [num(r["value"]) for r in swept if r["status"] == study.STABLE]
    stuck = [r for r in swept if r["stick"]]
    page.para(f"Cost: {computed(swept)}. No root grows at f* = "
              f"{', '.join(stable) or 'none of these'}; with a stick zone the state is "
              f"unstable at {sum(r['status'] == study.UNSTABLE for r in stuck)} of "
              f"{len(stuck)} values.")
    return swept


def speed_section(page: Page, cfg: dict) -> dict:
    page.heading("The belt speed c")
    ratio = {n: shipped_scene(n).to_dict()["motion"] for n in cfg["scenes"]}
    ratio = {n: m["surface_speed"] / m["belt_speed"] for n, m in ratio.items()}
    page.para(
        "Each scene (d = 39 1/s, f* as in the scene) at each belt speed c (m/s), with the "
        "surface speed v moved with it to keep the scenes' slip ratio v/c = "
        + ", ".join(f"{r:.4g}" for r in sorted(set(ratio.values())))
        + "; the damping stays 39 1/s (a rate, not a fraction of a mode's critical "
        "damping). c stays below the critical speed sqrt(a/I) = 129.1 m/s, at and above "
        "which the scene is refused. Command: `beltsim stability-map SCENE --param "
        "belt_speed --values " + ",".join(f"{c:g}" for c in cfg["speeds"]) + "`.")
    sweeps = {name: study.sweep(shipped_scene(name), "belt_speed", cfg["speeds"])
              for name in cfg["scenes"]}
    header = ["c [m/s]"]
    for name in cfg["scenes"]:
        header += [f"{name} rate [1/s]", "at [Hz]", "growing"]
    rows = []
    for i, c in enumerate(cfg["speeds"]):
        line = [fmt(c, "g")]
        for name in cfg["scenes"]:
            line += cells(page, sweeps[name][i])
        rows.append(line)
    page.table(header, rows)
    page.para("Cost: " + "; ".join(f"{name} {computed(r)}" for name, r in sweeps.items())
              + ". No root grows at " + "; ".join(
                  f"{name}: " + stable_speeds(rows) for name, rows in sweeps.items()) + ".")
    return sweeps


def stable_speeds(rows) -> str:
    speeds = [f"{r['value']:g}" for r in rows if r["status"] == study.STABLE]
    return f"c = {', '.join(speeds)} m/s" if speeds else "none of these speeds"


def _drive(name: str, cfg: dict):
    scene = shipped_scene(name)
    n = cfg["drive_elements"]
    return scene if n is None else scene.with_overrides({"numerics.elements": n})


def drive_cells(row: dict) -> list:
    """(status, rate +- error, frequency) of a drive's point."""
    if row["rate"] is None:
        return [row["status"], "", ""]
    return [row["status"], f"{row['rate']:+.2f} ± {row['error']:.2g}",
            f"{row['frequency']:.0f}"]


def drive_section(page: Page, cfg: dict) -> None:
    n = cfg["drive_elements"]
    grid = "" if n is None else f" --set numerics.elements={n}"
    page.heading("The closed drives")
    page.para(
        "A closed drive has no exact spectrum. Its point is what its runs report: the "
        "rightmost eigenvalue of the discrete model with the central gyroscopic form on "
        "the scene's grid, for frequencies up to 1.5 times the grid's highest axial "
        "frequency (`beltsim.simulation.stability_check.discrete_least_stable`), with its "
        "error, the difference from the same on half the grid; a rate within its error "
        "either way is undecided. Above that band the central form has grid-scale "
        "eigenvalues, some growing, whose frequency doubles with the grid: they are left "
        "out (the tests check the sweep against every eigenvalue of the band by the QZ "
        "algorithm). Commands: `beltsim stability-map SCENE" + grid + " --param damping "
        "--values " + ",".join(f"{d:g}" for d in cfg["drive_dampings"]) + "` and `--param "
        "friction_coefficient --values " + ",".join(f"{m:g}" for m in cfg["drive_mus"])
        + "` (the default coefficient of every pulley).")
    for param, values, unit in (("damping", cfg["drive_dampings"], "d [1/s]"),
                                ("friction_coefficient", cfg["drive_mus"], "mu")):
        sweeps = {name: study.sweep(_drive(name, cfg), param, values)
                  for name in cfg["drives"]}
        header = [unit]
        for name in cfg["drives"]:
            header += [f"{name}", "rate [1/s]", "at [Hz]"]
        rows = []
        for i, v in enumerate(values):
            line = [fmt(v, "g")]
            for name in cfg["drives"]:
                line += drive_cells(sweeps[name][i])
            rows.append(line)
        page.table(header, rows)
        page.para("Cost: " + "; ".join(f"{name} {computed(r)}"
                                       for name, r in sweeps.items()) + ".")
    rows = []
    for name in cfg["drives"]:
        start = time.perf_counter()
        crit = study.critical_damping(_drive(name, cfg), tol=cfg["tol"])
        at = {r["value"]: r for r in crit.evaluations}
        cell = crit.describe() if crit.damping is None or crit.lower is None else (
            f"{crit.damping:.2f} (rate {at[crit.damping]['rate']:+.2f} ± "
            f"{at[crit.damping]['error']:.2g}; at {crit.lower:.2f}: "
            f"{at[crit.lower]['rate']:+.2f} ± {at[crit.lower]['error']:.2g})")
        rows.append([name, cell, str(len(crit.evaluations)),
                     fmt(time.perf_counter() - start, ".3g")])
    page.table(["drive", "critical d [1/s]", "root searches", "wall [s]"], rows)
    page.para(
        "The critical damping of a drive is that of its discrete estimate: where the "
        "estimate's error exceeds the rate near the crossing, the crossing itself is "
        "known only to within the d that moves the rate by that error. Command: "
        f"`beltsim stability-map SCENE{grid} --critical-damping --tol {cfg['tol']:g}`.")


def figure(page: Page, sweeps: dict, crit: dict) -> None:
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4), constrained_layout=True)
    for name in sweeps:
        pts = {r["value"]: r["rate"] for r in sweeps[name] if r["rate"] is not None}
        pts.update({r["value"]: r["rate"] for r in crit[name].evaluations
                    if r["rate"] is not None})
        d = sorted(pts)
        line, = ax.plot(d, [pts[v] for v in d], "o-", ms=3, label=name)
        c = crit[name].damping
        if c is not None:
            ax.axvline(c, color=line.get_color(), ls="--", lw=0.8,
                       label=f"{name}: critical d = {c:.1f} 1/s")
    ax.axhline(0.0, color="k", lw=0.8)
    decorate(ax, "damping d [1/s]", "least stable rate [1/s]",
             f"Least stable exact root up to {BAND_HZ:g} Hz against the damping")
    page.figure(fig, "rate_vs_damping", "The least stable exact rate against the damping "
                "d (the sweep's points and the bisection's), and the critical damping of "
                "each scene (dashed): above zero the steady state flutters in the model")


def build(page: Page, quick: bool) -> None:
    cfg = CFG[quick]
    page.para(
        "How far the paper's inertial steady states are from stable in the model: the "
        "least stable root of the continuous model linearised about the exact steady "
        f"state, up to {BAND_HZ:g} Hz (`beltsim.simulation.stability.exact_least_stable`, "
        "no grid), over the damping d, the friction limit f* and the belt speed c, and "
        "the damping at which the steady state turns stable. Every root is computed by "
        "this run (an empty cache). Theory: docs/theory/stability.md; the spectra "
        "themselves: the spectrum page. A value with no exact steady state is shown as "
        "such, not as a number.")
    with fresh_cache():
        start = time.perf_counter()
        sweeps = damping_section(page, cfg)
        crit = critical_section(page, cfg)
        friction_section(page, cfg)
        speed_section(page, cfg)
        figure(page, sweeps, crit)
        drive_section(page, cfg)
        page.para(f"Wall time of the whole map: {time.perf_counter() - start:.0f} s.")
