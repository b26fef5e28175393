"""Page: the closed belt drive against the string's creep theory: steady convergence, the
default grid, a start-up from rest, the gross-slip threshold and the power balance."""

from __future__ import annotations

import time

import numpy as np

import beltsim
from beltsim.api import shipped_scene
from beltsim.beltdrive import DriveScene, GrossSlipError, capacity, solve_string
from beltsim.physics.layout import LoopGrid
from beltsim.simulation.controller import Simulation
from beltsim.simulation.result import RunStatus
from beltsim.solvers.settings import LOOP_ELEMENTS as DEFAULT_ELEMENTS
from beltsim.solvers.settings import LOOP_TIME_TOLS

from ..slip_fronts import OCTAVE, slip_arc_envelope
from .kit import Page, fmt, num, observed_orders

TITLE = "The closed belt drive"
SCENE = "drive_flat"
STRING = ("physics.model", "string")
LADDERS = {False: (100, 200, 400, 800, 1600, 3200), True: (100, 200, 400)}
#: the beam's ladder reaches far below the stick zones' boundary layer next to the slip
#: fronts (4.2 mm): on coarser grids the slip arcs' errors scatter
BEAM_LADDERS = {False: (200, 400, 800, 1600, 3200, 6400, 12800, 25600),
                True: (200, 400, 800)}
#: the errors of the ladder, with their column titles; the orders of the first five are
#: held to the issue's target
ERRORS = {"tight_tension": "tight tension", "slack_tension": "slack tension",
          "speed_loss": "speed loss", "slip_arc_driver": "slip arc, driver",
          "slip_arc_driven": "slip arc, driven", "slip_power": "slip power",
          "belt_speed": "belt speed", "driver_torque": "driver torque"}
#: errors that are round-off on every grid (no order to observe)
EXACT_KEYS = ("driver_torque",)
ORDER_KEYS = ("tight_tension", "slack_tension", "speed_loss", "slip_arc_driver",
              "slip_arc_driven")
BEAM_ORDER_KEYS = ("tight_tension", "slack_tension", "speed_loss")
#: the beam's slip arcs: the octaves' first grids of their error envelope
#: (validation.slip_fronts), the octave from which its order is held to MIN_ORDER, and
#: its bound there in cells (the front node's friction is off the exact volume integral
#: by up to 0.02 of the bound, which moves the front by a few hundredths of a cell;
#: tests/test_slip_front.py)
ENVELOPE_OCTAVES = {False: (400, 800, 1600, 3200, 6400, 12800), True: (400, 800)}
ENVELOPE_FROM = 1600
ENVELOPE_CELLS = 0.05
#: the issue's targets: the fitted order of those errors, the default grid's errors
MIN_ORDER = 1.8
TENSION_TOL = 1e-4
SPEED_LOSS_TOL = 1e-3
#: wall-time targets (s) of a default start-up and a steady solve, reported, not failed
#: (timings depend on the machine's load)
STARTUP_WALL = 2.0
STEADY_WALL = 0.02
#: repetitions of the steady solve for its wall time (the best counts)
STEADY_REPEATS = 5
#: loads of the gross-slip runs, as fractions of the string's capacity
THRESHOLDS = {False: (0.95, 0.99, 1.01, 1.05), True: (0.95, 1.05)}
QUICK_ELEMENTS = 200


def _cmd(*sets: str) -> str:
    return "`beltsim run " + SCENE + "".join(f" --set {s}" for s in sets) + "`"


def _string(overrides=()) -> DriveScene:
    return shipped_scene(SCENE, [STRING, *overrides])


def _h(scene: DriveScene, elements: int) -> float:
    """The grid's largest element (m)."""
    return float(LoopGrid.build(scene.params.geometry.lengths, elements).he.max())


def solve_steady(scene: DriveScene, elements: int | None = None):
    """The steady scheme's state of a drive (``numerics.integrator = "steady"``)."""
    sets = [("numerics.integrator", "steady")]
    if elements is not None:
        sets.append(("numerics.elements", elements))
    return beltsim.run(scene.with_overrides(sets))


def simulate(scene: DriveScene):
    """A run from rest by the scene's scheme, its failures returned as results."""
    return beltsim.run(scene, raise_on_failure=False)


def _balance(summary: dict) -> tuple[float, float]:
    """driver power - load power - slip power (W), and that relative to the driver power."""
    res = summary["driver_power"] - summary["load_power"] - summary["slip_power"]
    return res, res / summary["driver_power"]


def ladder(page: Page, quick: bool, beam: bool = False) -> list[dict]:
    rungs = (BEAM_LADDERS if beam else LADDERS)[quick]
    scene = shipped_scene(SCENE) if beam else _string()
    order_keys = BEAM_ORDER_KEYS if beam else ORDER_KEYS
    if beam:
        page.para(
            "The same ladder for the beam model (the shipped scene as it is) against the "
            "beam's exact steady state (`beltsim.beltdrive.exact.exact_state`: piecewise "
            "exponentials, the slip arcs' starts as unknowns), on a ladder reaching 128 "
            "times finer. On coarse grids the slip arcs' errors scatter: the stick zones' "
            "boundary layer next to the slip front, sqrt((A + B h^2 / 4) / b2) = 4.2 mm for "
            "this belt, is about two elements of the default grid. On this nested ladder a "
            "front's place within its cell doubles from grid to grid, so the slip arcs' "
            "errors jump and change sign and an order fitted to them measures that "
            "scatter: this ladder holds the tensions and the speed loss to the order, and "
            "the next section holds the slip arcs by their envelope. Fine grids start from "
            "the steady state of a grid four times coarser. Commands: "
            + _cmd("numerics.integrator=steady", "numerics.elements=N")
            + f" for N in {', '.join(map(str, rungs))}.")
    else:
        page.para(
            "The steady discrete state (`solve_steady`: Newton's method on the loop's "
            "equations with the time derivatives zero, from the analytic state) of the "
            f"string model of `{SCENE}` on a ladder of grids, each twice as fine as the "
            "last, against the string's analytic steady state (`solve_string`). Errors are "
            "relative; the speed loss 1 - speed ratio is compared as itself, the slip arcs "
            "relative to their pulley's wrap. Commands: "
            + _cmd("physics.model=string", "numerics.integrator=steady",
                   "numerics.elements=N") + f" for N in {', '.join(map(str, rungs))}.")
    rows = []
    for n in rungs:
        r = solve_steady(scene, n)
        rows.append({"elements": n, "h": _h(scene, n), "result": r, "errors": r.errors(),
                     "balance": _balance(r.summary())})
    body = [[str(r["elements"]), f"{r['h'] * 1e3:.4g}",
             str(r["result"].statistics["newton_iterations"]),
             fmt(r["result"].wall_time * 1e3, ".3g"),
             *(fmt(r["errors"][k], ".3e") for k in ERRORS)] for r in rows]
    page.table(["elements", "largest element [mm]", "Newton iterations", "wall [ms]",
                *ERRORS.values()], body)
    page.para("Observed orders in the element size, log(e1 / e2) / log(h1 / h2) for each "
              "successive pair of grids, and the least-squares slope of log |e| against "
              f"log h over the ladder. A fitted order below {MIN_ORDER:g} fails its cell "
              "for the tensions, the speed loss"
              + (" (the accuracy target; the slip arcs' by their envelope below)" if beam
                 else " and the slip arcs (the accuracy target)")
              + "; the others are shown as measured. The driver's torque is exact to "
              "round-off on every grid: at steady state the pulley's row and the loop's "
              "momentum balance (the sum of the axial rows) give M1 = (R1 / R2) M2, as the "
              "analytic state does.")
    h = np.array([r["h"] for r in rows])
    body = []
    for key, title in ERRORS.items():
        if key in EXACT_KEYS:
            continue
        e = np.abs([r["errors"][key] for r in rows])
        pairs, fit = observed_orders(h, e)
        if fit is None:
            body.append([title, "", "too few nonzero errors"])
            continue
        cell = f"{fit:.2f}"
        if key in order_keys and not fit >= MIN_ORDER:
            cell = page.fail(f"steady ladder, {title}: fitted order {fit:.2f} < {MIN_ORDER:g}")
        signs = "" if (np.all(np.array([r["errors"][key] for r in rows]) > 0)
                       or np.all(np.array([r["errors"][key] for r in rows]) < 0)) \
            else " (the error changes sign)"
        body.append([title, ", ".join(f"{p:.2f}" for p in pairs), cell + signs])
    page.table(["error", "successive pairs", "fitted"], body)
    if not beam:
        _figure(page, rows)
    return rows


def slip_envelope(page: Page, quick: bool) -> None:
    octaves = ENVELOPE_OCTAVES[quick]
    page.para(
        "The beam's slip arcs by their error envelope: for each octave's first grid n, "
        f"the largest error over the {OCTAVE} grids n, n + n/64, ..., n + {OCTAVE - 1}n/64, "
        "whose fronts lie at places that cover their cells "
        "(`validation.slip_fronts.slip_arc_envelope`), in cells (the arc length's error "
        "over the largest element) and in mm. The target: from "
        f"{ENVELOPE_FROM} elements on, within {ENVELOPE_CELLS:g} of a cell, and a fitted "
        f"order of the envelope in mm of at least {MIN_ORDER:g}. Coarser grids are "
        "shown as measured: there the front node's friction is off the exact volume "
        "integral by an error that does not yet fall at second order "
        "(tests/test_slip_front.py). Commands: "
        + _cmd("numerics.integrator=steady", "numerics.elements=N")
        + f" for N in n, ..., n + {OCTAVE - 1}n/64, n in {', '.join(map(str, octaves))}.")
    scene = shipped_scene(SCENE, [("numerics.integrator", "steady")])
    rows = [(n, *slip_arc_envelope(scene, n)) for n in octaves]
    names = list(rows[0][1])
    body = []
    for n, worst, h in rows:
        cells = []
        for name in names:
            cell = f"{worst[name]:.4f}"
            if n >= ENVELOPE_FROM and not worst[name] < ENVELOPE_CELLS:
                cell = page.fail(f"slip-arc envelope, {name}, {n} elements: "
                                 f"{worst[name]:.4f} cells >= {ENVELOPE_CELLS:g}")
            cells.append(cell)
        body.append([str(n), f"{h * 1e3:.4g}", *cells,
                     *(f"{worst[name] * h * 1e3:.3e}" for name in names)])
    page.table(["first grid n", "largest element [mm]",
                *(f"{name} [cells]" for name in names),
                *(f"{name} [mm]" for name in names)], body)
    fine = [(h, worst) for n, worst, h in rows if n >= ENVELOPE_FROM]
    if len(fine) < 2:
        page.para(f"(The quick page's octaves stop below {ENVELOPE_FROM} elements: no "
                  "order is held.)")
        return
    h = np.array([f[0] for f in fine])
    body = []
    for name in names:
        pairs, fit = observed_orders(h, np.array([w[name] * hh for hh, w in fine]))
        cell = f"{fit:.2f}"
        if not fit >= MIN_ORDER:
            cell = page.fail(f"slip-arc envelope, {name}: fitted order {fit:.2f} < "
                             f"{MIN_ORDER:g}")
        body.append([f"slip arc, {name}", ", ".join(f"{p:.2f}" for p in pairs), cell])
    page.para(f"Observed orders of the envelope (mm) from {ENVELOPE_FROM} elements on:")
    page.table(["error", "successive pairs", "fitted"], body)


def _figure(page: Page, rows) -> None:
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 4.8), constrained_layout=True)
    h = np.array([r["h"] for r in rows])
    markers = "osD^v<>p"
    # the belt speed's error lies on the speed loss's (both follow the tight tension)
    shown = [(k, t) for k, t in ERRORS.items() if k not in EXACT_KEYS + ("belt_speed",)]
    for (key, title), m in zip(shown, markers):
        e = np.abs([r["errors"][key] for r in rows])
        ok = e > 0
        ax.loglog(h[ok], e[ok], marker=m, mfc="none", label=title)
    top = max(abs(rows[0]["errors"][k]) for k in ORDER_KEYS)
    ax.loglog(h, top * (h / h[0]) ** 2, "k:", label="order 2")
    ax.set_xlabel("largest element [m]")
    ax.set_ylabel("|error| against the string's analytic state")
    ax.set_title(f"{SCENE}, string model: steady errors against the element size",
                 fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    page.figure(fig, "convergence", f"{SCENE}, string model: relative errors of the steady "
                "state against the largest element, with a second-order line")


def default_grid(page: Page) -> None:
    page.para(
        f"The default grid has {DEFAULT_ELEMENTS} elements. The targets there: the "
        f"tensions within {num(TENSION_TOL)} and the speed loss within "
        f"{num(SPEED_LOSS_TOL)} (relative) of the analytic state, and a steady solve in "
        f"at most {STEADY_WALL * 1e3:g} ms (best of {STEADY_REPEATS}, compilation "
        f"excluded). Command: " + _cmd("physics.model=string",
                                       "numerics.integrator=steady") + ".")
    scene = _string()
    best, r = np.inf, None
    for _ in range(STEADY_REPEATS):
        t0 = time.perf_counter()
        r = solve_steady(scene)
        best = min(best, time.perf_counter() - t0)
    e = r.errors()
    body = []
    for key, tol in (("tight_tension", TENSION_TOL), ("slack_tension", TENSION_TOL),
                     ("speed_loss", SPEED_LOSS_TOL)):
        ok = abs(e[key]) <= tol
        cell = "met" if ok else page.fail(f"default grid, {key}: {e[key]:.3e} beyond "
                                          f"{num(tol)}")
        body.append([ERRORS[key], f"{e[key]:.3e}", num(tol), cell])
    body.append(["steady solve, wall [ms]", f"{best * 1e3:.3g}", f"{STEADY_WALL * 1e3:g}",
                 "met" if best <= STEADY_WALL else "not met on this machine"])
    page.table(["quantity", "measured", "target", ""], body)


def startup(page: Page, quick: bool) -> None:
    grid = [("numerics.elements", QUICK_ELEMENTS)] if quick else []
    where = f"{QUICK_ELEMENTS} elements" if quick else "the default grid"
    page.para(
        f"Time-accurate runs from rest (c = omega2 = 0, uniform tension N0) on {where}: "
        "the driver's speed and the load ramp up smoothly over two transits of the loop, "
        "and the run stops when the drive is steady (`numerics.steady_tol`). Errors of "
        "the end state against the analytic steady state the run compares with "
        "(`RunResult.reference`: the string's for the string model; for the beam, the "
        "beam's exact solution where beltsim has it, else the string's, which the beam "
        "differs from by its shear and bending). The target: a default start-up in "
        f"at most {STARTUP_WALL:g} s wall for the default scheme (esdirk3). Commands: "
        "`beltsim run "
        f"{SCENE} --set physics.model=string`, `beltsim run {SCENE}` (the beam) and "
        f"`beltsim run {SCENE} --set numerics.integrator=implicit`"
        + (f", with `--set numerics.elements={QUICK_ELEMENTS}`" if quick else "") + ".")
    keys = ("tight_tension", "slack_tension", "speed_loss", "slip_arc_driver",
            "slip_arc_driven", "slip_power")
    body = []
    bdf2 = ("numerics.integrator", "implicit")
    for label, scene in (("string", _string(grid)), ("beam", shipped_scene(SCENE, grid)),
                         ("beam, BDF2", shipped_scene(SCENE, [*grid, bdf2]))):
        r = simulate(scene)
        if r.converged:
            status = "converged"
        else:
            status = page.fail(f"start-up, {label}: {r.status.value} ({r.reason})")
        e = r.errors()
        target = "met" if r.wall_time <= STARTUP_WALL else "not met on this machine"
        body.append([label, type(r.reference).__name__, status,
                     fmt(r.simulated_time, ".4g"), str(r.statistics["steps"]),
                     str(r.statistics.get("newton_iterations", "")),
                     str(r.statistics.get("rejected_steps", "")),
                     f"{r.wall_time:.3g} ({target})",
                     *(fmt(e.get(k), ".3e") for k in keys)])
    page.table(["model", "compared with", "status", "end time [s]", "steps",
                "Newton iterations", "rejected steps", "wall [s]",
                *(ERRORS[k] for k in keys)], body)
    if any(row[0] == "beam" and row[1] == "StringSolution" for row in body):
        page.para("The beam's row is compared with the string's solution: its differences "
                  "are the beam's own physics (the friction's moment about the middle line "
                  "and the shear), mostly in the slip arcs, not the discretisation's error, "
                  "which the string's row shows.")


def threshold(page: Page, quick: bool) -> None:
    grid = [("numerics.elements", QUICK_ELEMENTS)] if quick else []
    scene = _string(grid)
    cap = capacity(scene.params)
    page.para(
        f"The string's capacity at the driver's final speed is {cap:.6g} N m "
        "(`capacity`: the load at which the slip arcs cover the smaller wrap). Runs from "
        "rest of the string model at loads about it: below it the run must reach its "
        "steady state, above it end in gross slip, and the steady solver must refuse the "
        "load. Command: `beltsim run " + SCENE + " --set physics.model=string --set "
        "drive.load_torque=M2" + (f" --set numerics.elements={QUICK_ELEMENTS}" if quick
                                  else "") + "`.")
    body = []
    for frac in THRESHOLDS[quick]:
        load = frac * cap
        s = scene.with_overrides([("drive.load_torque", load)])
        r = simulate(s)
        expect = RunStatus.CONVERGED if frac < 1 else RunStatus.GROSS_SLIP
        status = r.status.value if r.status is expect else page.fail(
            f"threshold, {frac:g} x capacity: {r.status.value}, expected {expect.value}")
        try:
            exact = solve_string(s.params)
            arc = f"{r.summary()['slip_arc_driver']:.4f} / {exact.phi_s:.4f}"
            steady = "solved"
        except GrossSlipError as exc:
            arc = f"{r.summary()['slip_arc_driver']:.4f} / (none)"
            steady = "refused: " + str(exc)
        if frac > 1:
            try:
                solve_steady(s)
                steady = page.fail(f"threshold, {frac:g} x capacity: the steady solver "
                                   "did not refuse the load")
            except GrossSlipError as exc:
                steady = "refused: " + str(exc)
        body.append([f"{frac:g}", f"{load:.5g}", status, r.reason or "",
                     f"{r.simulated_time:.4g}", arc, steady])
    page.table(["load / capacity", "load [N m]", "status", "reason", "end time [s]",
                "driver's slip arc, run / analytic [rad]", "steady solver"], body)


def balance(page: Page, rows: list[dict], quick: bool) -> None:
    page.para(
        "At steady state the driver's power M1 omega1 equals the load's M2 omega2 plus "
        "the slip power, the friction's dissipation -sum F_j v_rel,j over the contact "
        "nodes (damping and the stored energies' rates vanish). The residual driver power "
        "- load power - slip power of the steady states above falls with the grid. The "
        "driver's torque is exact and the speeds' errors are tiny, so the residual is the "
        "error of the slip power, the discrete friction's work, and falls at its order.")
    body = [[str(r["elements"]), f"{r['result'].summary()['driver_power']:.6g}",
             f"{r['result'].summary()['load_power']:.6g}",
             f"{r['result'].summary()['slip_power']:.6g}", f"{r['balance'][0]:.3e}",
             f"{r['balance'][1]:.3e}",
             f"{r['balance'][0] / r['result'].summary()['slip_power']:.3e}"] for r in rows]
    page.table(["elements", "driver power [W]", "load power [W]", "slip power [W]",
                "residual [W]", "residual / driver power", "residual / slip power"], body)
    data = _string().to_dict()
    data["contact"] = {"friction": "stick"}
    stick = DriveScene(data)
    r = solve_steady(stick, QUICK_ELEMENTS if quick else None)
    sm = r.summary()
    lost = sm["driver_power"] - sm["load_power"]
    exact = r.reference
    page.para(
        "Perfect adhesion (`contact.friction = \"stick\"`, the string model, "
        f"{r.numerics.elements} elements): every node sticks, so the nodal slip power is "
        f"{sm['slip_power']:.3g} W, yet the driver supplies "
        f"{sm['driver_power']:.6g} W and the load takes "
        f"{sm['load_power']:.6g} W. The difference, {lost:.6g} W, is the analytic "
        f"creep loss kappa c dT^2 / b1 = {exact.slip_power:.6g} W (relative difference "
        f"{(lost - exact.slip_power) / exact.slip_power:.2e}): it is dissipated by the "
        "concentrated friction forces at the arcs' exits, where the belt's speed jumps, "
        "and no nodal slip power records it.")


#: the default scheme's time tolerance (esdirk3)
DEFAULT_TIME_TOL = LOOP_TIME_TOLS["esdirk3"]
#: time tolerances of the path study and its reference (numerics.time_tol)
TIME_TOLS = {False: (1e-1, DEFAULT_TIME_TOL, 1e-3, 1e-4), True: (1e-1, DEFAULT_TIME_TOL)}
TIME_REFERENCE = {False: 1e-6, True: 1e-4}
PATH_KEYS = ("tight_tension", "slack_tension", "belt_speed", "driven_speed")
#: the paths held to PATH_TOL at the default tolerance (the tensions are reported: see the
#: page's note on the spans' oscillation)
PATH_HELD = ("belt_speed", "driven_speed")
#: the path's target: within this of a run refined in time (relative to the steady value)
PATH_TOL = 1e-3
#: the checks' interval of the path study (s): the history then resolves the 88 Hz ringing
CHECK_INTERVAL = 2e-4


def _energy_mismatch(r) -> float:
    """max over t of the stored energy minus the integrated power balance (trapezoidal
    from rest), relative to the driver's work."""
    H = r.history
    t = np.concatenate([[0.0], H["t"]])
    net = np.concatenate([[0.0], H["driver_power"] - H["load_power"] - H["slip_power"]
                          - H["damping_power"] - H["gyroscopic_power"]
                          + H["transport_power"]])
    drive = np.concatenate([[0.0], H["driver_power"]])
    integral = np.cumsum(0.5 * (net[1:] + net[:-1]) * np.diff(t))
    work = float(np.sum(0.5 * (drive[1:] + drive[:-1]) * np.diff(t)))
    return float(np.max(np.abs(H["energy"] - integral)) / work)


def time_path(page: Page, quick: bool) -> None:
    grid = [("numerics.elements", QUICK_ELEMENTS)] if quick else []
    t_end = 0.3 if quick else 0.5
    common = [*grid, ("numerics.t_end", t_end), ("numerics.steady_tol", 1e-30)]
    ref_tol = TIME_REFERENCE[quick]
    page.para(
        "The start-up's path in time: the beam model of the shipped scene from rest to "
        f"t = {t_end:g} s with the default scheme's adaptive steps (esdirk3) at several "
        f"local-error tolerances `numerics.time_tol`, against a run at {ref_tol:g}. Path "
        f"error: the largest difference over t in [0.01, {t_end:g}] s, relative to the "
        f"steady value. The default tolerance is {DEFAULT_TIME_TOL:g}; the target is a "
        f"path within {PATH_TOL:g}. The last column is "
        "the semi-discrete power balance over the run: the stored energy minus the "
        "integral of the driver's power less the load, slip, damping and gyroscopic "
        "powers plus the transport power, "
        "relative to the driver's work, by the trapezoidal rule over the history's checks "
        f"(`RunResult.history`, a check every {CHECK_INTERVAL * 1e3:g} ms, the snapshot "
        "interval, which resolves the drive's rotational oscillation). Command: "
        f"`beltsim run {SCENE} --set numerics.time_tol=TOL --set numerics.t_end={t_end:g}`.")
    runs = {}
    for tol in (*TIME_TOLS[quick], ref_tol):
        start = time.perf_counter()
        r = beltsim.run(shipped_scene(SCENE, [*common, ("numerics.time_tol", tol)]),
                        raise_on_failure=False, snapshot_interval=CHECK_INTERVAL)
        runs[tol] = (r, time.perf_counter() - start)
    ref = runs[ref_tol][0]
    tt = np.linspace(0.01, t_end, 400)
    body = []
    for tol in TIME_TOLS[quick]:
        r, wall = runs[tol]
        errs = []
        for k in PATH_KEYS:
            a = np.interp(tt, r.history["t"], r.history[k])
            b = np.interp(tt, ref.history["t"], ref.history[k])
            errs.append(float(np.max(np.abs(a - b)) / abs(ref.summary()[k])))
        worst = max(errs[PATH_KEYS.index(k)] for k in PATH_HELD)
        if tol == DEFAULT_TIME_TOL and worst > PATH_TOL:
            page.fail(f"the default time_tol's speed path error {worst:.2e} exceeds "
                      f"{PATH_TOL:g}")
        body.append([f"{tol:g}", str(r.statistics["steps"]), str(r.statistics["rejected_steps"]),
                     f"{wall:.3g}", *(f"{e:.2e}" for e in errs),
                     f"{_energy_mismatch(r):.2e}"])
    r, wall = runs[ref_tol]
    body.append([f"{ref_tol:g} (reference)", str(r.statistics["steps"]),
                 str(r.statistics["rejected_steps"]), f"{wall:.3g}", *("" for _ in PATH_KEYS),
                 f"{_energy_mismatch(r):.2e}"])
    page.table(["time_tol", "steps", "rejected", "wall [s]",
                *(f"path error, {k.replace('_', ' ')}" for k in PATH_KEYS),
                "power balance"], body)
    page.para(
        "The speeds' paths are held to the target at the default tolerance. The span "
        "tensions' paths converge more slowly: their largest differences sit in the ramp, "
        "where the slip fronts sweep across the arcs' nodes and every jump of a node "
        "between stick and slip excites the spans' axial oscillation (about 2 ms period) "
        "a little differently. The end states agree to the grid's error whatever the "
        "tolerance.")


#: the free-step path study's sample interval (s): few enough landings that the steps are
#: the error control's own
SAMPLE_INTERVAL = 0.02


def _sampled_path(scene, t_end):
    """(values at every SAMPLE_INTERVAL up to t_end (samples, PATH_KEYS), steps, wall)."""
    sim = Simulation(scene)
    sim.warm_up()
    start = time.perf_counter()
    rows = []
    for t in np.arange(SAMPLE_INTERVAL, t_end + 1e-12, SAMPLE_INTERVAL):
        sim.advance(t)
        summary = sim.solution().summary()
        rows.append([summary[k] for k in PATH_KEYS])
    return np.array(rows), sim.steps, time.perf_counter() - start


def free_path(page: Page, quick: bool) -> None:
    grid = [("numerics.elements", QUICK_ELEMENTS)] if quick else []
    t_end = 0.3 if quick else 0.6
    ref_tol = TIME_REFERENCE[quick]
    page.para(
        "The same start-up with the steps the error control chooses: the study above lands "
        f"a step on every check ({CHECK_INTERVAL * 1e3:g} ms), which caps them. Here the "
        f"run is sampled every {SAMPLE_INTERVAL:g} s up to t = {t_end:g} s, against a run "
        f"at {ref_tol:g}; path error as above (largest difference over the samples, "
        "relative to the steady value). This is the study that sets the default "
        f"tolerance, {DEFAULT_TIME_TOL:g}: it must keep the speeds' and the tensions' paths "
        f"within {PATH_TOL:g} (the page fails otherwise), with room left for drives that "
        "ring longer than this one.")
    runs = {tol: _sampled_path(shipped_scene(SCENE, [*grid, ("numerics.time_tol", tol),
                                                     ("numerics.t_end", t_end),
                                                     ("numerics.steady_tol", 1e-30)]), t_end)
            for tol in (*TIME_TOLS[quick], ref_tol)}
    ref = runs[ref_tol][0]
    body = []
    for tol in TIME_TOLS[quick]:
        values, steps, wall = runs[tol]
        errs = np.max(np.abs(values - ref), axis=0) / np.abs(ref[-1])
        if tol == DEFAULT_TIME_TOL and np.max(errs) > PATH_TOL:
            page.fail(f"the default time_tol's free-step path error {np.max(errs):.2e} "
                      f"exceeds {PATH_TOL:g}")
        body.append([f"{tol:g}", str(steps), f"{wall:.3g}", *(f"{e:.2e}" for e in errs)])
    _, steps, wall = runs[ref_tol]
    body.append([f"{ref_tol:g} (reference)", str(steps), f"{wall:.3g}",
                 *("" for _ in PATH_KEYS)])
    page.table(["time_tol", "steps", "wall [s]",
                *(f"path error, {k.replace('_', ' ')}" for k in PATH_KEYS)], body)


def build(page: Page, quick: bool) -> None:
    page.para(
        f"The shipped `{SCENE}` scene (a flat belt on pulleys of radius R = 80 / 160 mm, "
        "150 rad/s, 50 N m, mu = 0.4) against the string's creep theory, the analytic steady state "
        "derived on the [theory page](../theory/drive.md). Every table is computed "
        "through beltsim's API; the commands give the same runs from the command line. "
        "Wall times exclude compilation.")
    page.heading("Steady convergence of the string model")
    rows = ladder(page, quick)
    page.heading("Steady convergence of the beam model")
    ladder(page, quick, beam=True)
    slip_envelope(page, quick)
    page.heading("The default grid")
    default_grid(page)
    page.heading("A start-up from rest")
    startup(page, quick)
    page.heading("The path in time")
    time_path(page, quick)
    free_path(page, quick)
    page.heading("The gross-slip threshold")
    threshold(page, quick)
    page.heading("The power balance at steady state")
    balance(page, rows, quick)
