"""Page: serpentine drives (N pulleys, back-side idlers, a tensioner's arm) against the
N-pulley creep theory: steady ladders and their orders, the default grid's errors and
the steady solve's time, a start-up from rest with its power balance, gross slip at a
named pulley, the forced response, and the tensioner's arm in motion."""

from __future__ import annotations

import time

import numpy as np

import beltsim
from beltsim.api import shipped_scene
from beltsim.beltdrive import GrossSlipError, string_state
from beltsim.physics.layout import LoopGrid
from beltsim.solvers.settings import LOOP_ELEMENTS as DEFAULT_ELEMENTS

from ..slip_fronts import OCTAVE, slip_arc_envelope
from .kit import Page, fmt, num, observed_orders

TITLE = "Serpentine drives"
#: the shipped scenes: seven pulleys with two back-side idlers; three with one; the
#: seven with the tensioner's arm at rest
SCENES = ("serpentine_accessory", "serpentine_machine", "serpentine_tensioner")
STEADY = ("numerics.integrator", "steady")
LADDERS = {False: (100, 200, 400, 800, 1600, 3200), True: (200, 400, 800)}
#: the run's errors against the creep theory (LoopSolution.errors), with their titles
ERRORS = {"span_tension": "span tensions", "hub_load": "hub loads",
          "speed_loss": "speed losses", "slip_arc": "slip arcs", "belt_speed": "belt speed",
          "arm_travel": "arm travel [rad]"}
#: the issue's targets: the fitted order of these errors over the full ladder ...
ORDER_KEYS = ("span_tension", "hub_load", "speed_loss", "slip_arc", "arm_travel")
MIN_ORDER = 1.8
#: ... and, on the quick page's three grids, where the slip fronts' jumps between nodes
#: scatter successive pairs by +-0.5 about the order, a floor that still catches a
#: first-order or broken discretisation
QUICK_MIN_ORDER = 1.0
TENSION_TOL = 1e-4
#: wall-time targets (s): a steady solve, a start-up from rest; reported, not failed
STEADY_WALL = 0.02
STARTUP_WALL = 2.0
STEADY_REPEATS = 5
QUICK_ELEMENTS = 200
#: the beam's slip arcs by their error envelope (validation.slip_fronts): the octaves'
#: first grids, and its bound in cells on them (the front node's friction is off the
#: exact volume integral by up to 0.02 of the bound; tests/test_slip_front.py measured
#: 0.033-0.037 of a cell on 1600 elements); its order over them is held to MIN_ORDER
ENVELOPE_OCTAVES = {False: (1600, 3200, 6400), True: ()}
ENVELOPE_CELLS = 0.05
#: the gross-slip case: the alternator's friction coefficient worn to 0.12 and its load
#: raised to 4 N m, beyond its capacity
WORN = {"pulley.alternator.friction_coefficient": 0.12, "pulley.alternator.load_torque": 4.0}


def _cmd(scene: str, *sets: str) -> str:
    return "`beltsim run " + scene + "".join(f" --set {s}" for s in sets) + "`"


def _h(scene, elements: int) -> float:
    """The grid's largest element (m)."""
    return float(LoopGrid.build(scene.params.layout.lengths, elements).he.max())


def _orders(page: Page, name: str, rows, quick: bool,
            held=ORDER_KEYS) -> list[list[str]]:
    h = np.array([r["h"] for r in rows])
    floor = QUICK_MIN_ORDER if quick else MIN_ORDER
    body = []
    for key, title in ERRORS.items():
        if rows[0]["errors"].get(key) is None:
            continue
        pairs, fit = observed_orders(h, [r["errors"][key] for r in rows])
        if fit is None:
            body.append([name, title, "", "too few nonzero errors"])
            continue
        cell = f"{fit:.2f}"
        if key in held and not fit >= floor:
            cell = page.fail(f"{name}, {title}: fitted order {fit:.2f} < {floor:g}")
        body.append([name, title, ", ".join(f"{p:.2f}" for p in pairs), cell])
    return body


def ladders(page: Page, quick: bool, model: str = "string") -> None:
    rungs = LADDERS[quick]
    if model == "beam":
        beam_ladders(page, rungs, quick)
        return
    page.para(
        "The steady discrete state (Newton's method on the loop's equations with the time "
        "derivatives zero, from the creep theory's state; with a tensioner, a root search "
        "on the arm's torque over such states) of each shipped serpentine scene on a "
        "ladder of grids, each twice as fine as the last, against the string's creep "
        "theory on N pulleys (`beltsim.beltdrive.string_state`). Errors as "
        "`RunResult.errors()` gives them: span tensions and hub loads, the largest "
        "difference over the spans (pulleys) over the largest span tension; speed losses "
        "1 - omega_i r_i / (omega_d r_d), the largest difference over the largest loss; "
        "slip arcs over their pulley's wrap; the arm's travel in rad. Commands: "
        + ", ".join(_cmd(s, "numerics.integrator=steady", "numerics.elements=N")
                    for s in SCENES) + f" for N in {', '.join(map(str, rungs))}.")
    orders = []
    for name in SCENES:
        scene = shipped_scene(name, [STEADY])
        rows = _ladder_rows(scene, rungs)
        keys = [k for k in ERRORS if rows[0]["errors"].get(k) is not None]
        page.heading(f"`{name}`: {len(scene.params.pulleys)} pulleys", 3)
        page.table(["elements", "largest element [mm]", "wall [ms]",
                    *(ERRORS[k] for k in keys)],
                   [[str(r["elements"]), f"{r['h'] * 1e3:.4g}",
                     fmt(r["result"].wall_time * 1e3, ".3g"),
                     *(fmt(r["errors"][k], ".3e") for k in keys)] for r in rows])
        orders += _orders(page, name, rows, quick)
    floor = QUICK_MIN_ORDER if quick else MIN_ORDER
    page.para(
        "Observed orders in the element size: log(e1 / e2) / log(h1 / h2) for each "
        "successive pair, and the least-squares slope of log |e| against log h over the "
        f"ladder. A fitted order below {floor:g} fails its cell for the tensions, hub "
        "loads, speed losses, slip arcs and the arm's travel"
        + (" (the quick page's floor: on three grids the slip fronts' jumps between "
           f"nodes scatter the pairs; the full page holds {MIN_ORDER:g})" if quick else "")
        + ". The pairs scatter about the fit because a slip front's position jumps when "
        "it crosses a node.")
    page.table(["scene", "error", "successive pairs", "fitted"], orders)


def _ladder_rows(scene, rungs) -> list[dict]:
    rows = []
    for n in rungs:
        r = beltsim.run(scene.with_overrides([("numerics.elements", n)]))
        rows.append({"elements": n, "h": _h(scene, n), "result": r, "errors": r.errors()})
    return rows


def beam_ladders(page: Page, rungs, quick: bool) -> None:
    """The beam's ladders against its exact steady state on N pulleys."""
    page.para(
        "The same ladders with the beam (`physics.model = \"beam\"`, bending and shear; "
        "on a back-side idler the friction acts on the belt's other face) against the "
        "beam's exact steady state on N pulleys (`beltsim.beltdrive.exact_state`: "
        "piecewise exponentials on each span, stick and slip zone; theory page, \"The "
        "beam's exact steady state on N pulleys\"). The tensions, hub loads, speed losses"
        " and the arm's travel are held to the order floor; the slip arcs are reported: "
        "the run reads a slip front from the stick zone's friction ratio at two nodes "
        "upstream, carried across the front's node by the grid's stick mode, and the "
        "beam's ratio changes within a layer of width 1/alpha (about 3 mm here), which "
        "the ladder's coarser cells do not resolve: the front's node's own friction is "
        "then off by up to a tenth of a cell, an error that falls at second order only "
        "from about 1600 elements (tests/test_slip_front.py; the two-pulley beam shows "
        "the same). Commands: "
        + ", ".join(_cmd(s, "physics.model=beam", "numerics.integrator=steady",
                         "numerics.elements=N") for s in SCENES)
        + f" for N in {', '.join(map(str, rungs))}. The slip arcs are held by their "
        "error envelope below.")
    orders, rows_all = [], []
    for name in SCENES:
        scene = shipped_scene(name, [STEADY, ("physics.model", "beam")])
        rows = _ladder_rows(scene, rungs)
        rows_all += [[name, str(r["elements"]), fmt(r["result"].wall_time * 1e3, ".3g"),
                      *(fmt(r["errors"].get(k), ".3e") for k in ERRORS)] for r in rows]
        orders += _orders(page, name, rows, quick,
                          held=tuple(k for k in ORDER_KEYS if k != "slip_arc"))
    page.table(["scene", "elements", "wall [ms]", *ERRORS.values()], rows_all)
    page.table(["scene", "error", "successive pairs", "fitted"], orders)
    slip_envelopes(page, quick)


def slip_envelopes(page: Page, quick: bool) -> None:
    """The beam's slip arcs by their error envelope over each octave."""
    octaves = ENVELOPE_OCTAVES[quick]
    if not octaves:
        page.para("(The quick page leaves out the beam's slip-arc envelope: its grids "
                  f"start at {ENVELOPE_OCTAVES[False][0]} elements.)")
        return
    page.para(
        "The beam's slip arcs by their error envelope: on a nested ladder a slip front's "
        "place within its cell doubles from grid to grid, so single errors jump and an "
        "order fitted to them measures that. For each octave's first grid n, the largest "
        f"error over the {OCTAVE} grids n, n + n/64, ..., n + {OCTAVE - 1}n/64 and over the "
        "pulleys (`validation.slip_fronts.slip_arc_envelope`), in cells (the arc length's "
        "error over the largest element) and in mm, and the pulley where it is largest. "
        f"The target: within {ENVELOPE_CELLS:g} of a cell, and a fitted order of the "
        f"envelope in mm of at least {MIN_ORDER:g}. Commands: the beam's above, for N in "
        f"n, ..., n + {OCTAVE - 1}n/64, n in {', '.join(map(str, octaves))}.")
    body, orders = [], []
    for name in SCENES:
        scene = shipped_scene(name, [STEADY, ("physics.model", "beam")])
        hs, mm = [], []
        for n in octaves:
            worst, h = slip_arc_envelope(scene, n)
            at = max(worst, key=worst.get)
            cell = f"{worst[at]:.4f}"
            if not worst[at] < ENVELOPE_CELLS:
                cell = page.fail(f"{name}, slip-arc envelope on {n} elements: "
                                 f"{worst[at]:.4f} cells >= {ENVELOPE_CELLS:g}")
            body.append([name, str(n), f"{h * 1e3:.4g}", at, cell,
                         f"{worst[at] * h * 1e3:.3e}"])
            hs.append(h)
            mm.append(worst[at] * h)
        pairs, fit = observed_orders(np.array(hs), np.array(mm))
        cell = f"{fit:.2f}"
        if not fit >= MIN_ORDER:
            cell = page.fail(f"{name}, slip-arc envelope: fitted order {fit:.2f} < "
                             f"{MIN_ORDER:g}")
        orders.append([name, ", ".join(f"{p:.2f}" for p in pairs), cell])
    page.table(["scene", "first grid n", "largest element [mm]", "pulley",
                "envelope [cells]", "envelope [mm]"], body)
    page.table(["scene", "successive pairs", "fitted"], orders)


def default_grid(page: Page) -> None:
    page.para(
        f"The default grid has {DEFAULT_ELEMENTS} elements. The targets there: the span "
        f"tensions within {num(TENSION_TOL)} of the creep theory, and a steady solve of "
        f"the accessory drive in at most {STEADY_WALL * 1e3:g} ms (best of "
        f"{STEADY_REPEATS}, the kernels loaded, the scene's validation apart). Command: "
        + _cmd(SCENES[0], "numerics.integrator=steady") + ".")
    body = []
    for name in SCENES:
        scene = shipped_scene(name, [STEADY])
        best, r = np.inf, None
        for _ in range(STEADY_REPEATS):
            t0 = time.perf_counter()
            r = beltsim.run(scene)
            best = min(best, time.perf_counter() - t0)
        e = r.errors()["span_tension"]
        cell = "met" if abs(e) <= TENSION_TOL else page.fail(
            f"default grid, {name}: span tensions {e:.3e} beyond {num(TENSION_TOL)}")
        wall = f"{best * 1e3:.3g}"
        if name == SCENES[0]:
            wall += " (met)" if best <= STEADY_WALL else " (not met on this machine)"
        solves = r.statistics.get("arm_solves")
        body.append([name, f"{e:.3e}", cell, wall,
                     f"{solves} steady solves" if solves else "one steady solve"])
    page.table(["scene", "span tensions", f"within {num(TENSION_TOL)}", "wall [ms]", ""],
               body)


def startup(page: Page, quick: bool) -> None:
    grid = [("numerics.elements", QUICK_ELEMENTS)] if quick else []
    name = SCENES[0]
    page.para(
        f"`{name}` from rest (the belt and the free pulleys still, uniform tension N0) by "
        "the default scheme (esdirk3, adaptive steps) "
        + (f"on {QUICK_ELEMENTS} elements" if quick else "on the default grid")
        + ": the crankshaft's speed and the loads rise together over the default ramp "
        "(within half the crankshaft's torque reserve, the pulleys' inertia reflected to "
        "it), and the run stops when the drive is steady. The power balance: the driver's "
        "power less the loads', the slip power, the damping's and the gyroscopic term's, "
        "plus the transport term, against the rate of the stored energy (zero at steady "
        f"state). Target: at most {STARTUP_WALL:g} s wall. Command: "
        + _cmd(name, *(f"numerics.elements={QUICK_ELEMENTS}",) if quick else ()) + ".")
    r = beltsim.run(shipped_scene(name, grid), raise_on_failure=False)
    status = r.status.value if r.converged else page.fail(
        f"start-up: {r.status.value} ({r.reason})")
    s, e = r.summary(), r.errors() or {}
    residual = (s["driver_power"] - s["load_power"] - s["slip_power"] - s["damping_power"]
                - s["gyroscopic_power"] + s["transport_power"])
    exact = string_state(r.scene.params).slip_power
    page.table(["quantity", "value"], [
        ["status", status], ["end time [s]", f"{r.simulated_time:.4g}"],
        ["steps (rejected)", f"{r.statistics['steps']} ({r.statistics.get('rejected_steps')})"],
        ["wall [s]", f"{r.wall_time:.3g} ("
         + ("met" if r.wall_time <= STARTUP_WALL else "not met on this machine") + ")"],
        *([ERRORS[k], fmt(e.get(k), ".3e")] for k in ("span_tension", "hub_load",
                                                       "speed_loss", "slip_arc")),
        ["power balance residual / driver power", f"{residual / s['driver_power']:.2e}"],
        ["(slip - transport power) / creep theory's slip power - 1",
         f"{(s['slip_power'] - s['transport_power']) / exact - 1:.2e}"]])


def gross_slip(page: Page, quick: bool) -> None:
    name = SCENES[0]
    sets = dict(WORN)
    if quick:
        sets["numerics.elements"] = QUICK_ELEMENTS
    scene = shipped_scene(name, list(sets.items()))
    try:
        string_state(scene.params)
        refused = page.fail("gross slip: the creep theory did not refuse the load")
    except GrossSlipError as exc:
        refused = str(exc)
    r = beltsim.run(scene, raise_on_failure=False)
    named = r.status.name == "GROSS_SLIP" and "alternator" in (r.reason or "")
    outcome = f"{r.status.value}: {r.reason}" if named else page.fail(
        f"gross slip: the run ended {r.status.value} ({r.reason}), not gross slip at the "
        "alternator")
    page.para(
        "The alternator's friction coefficient worn to 0.12 and its load raised to 4 N m: "
        "beyond its capacity. The creep theory (and so `beltsim analytic` and the steady "
        "solver) refuses it naming the pulley; a run from rest ends in the physical "
        "outcome, gross slip at that pulley (exit status 1). Command: "
        + _cmd(name, *(f"{k}={v}" for k, v in sets.items())) + ".")
    page.table(["", ""], [["creep theory", refused], ["run from rest", outcome]])


#: the forced-response study: the crankshaft's speed fluctuation (rad/s) and its
#: frequencies (Hz) for the periodic runs, through the first mode (48 Hz)
FLUCTUATION = 0.5
FORCED = {False: (10.0, 20.0, 30.0, 45.0, 60.0, 80.0, 100.0, 130.0, 170.0),
          True: (20.0, 80.0)}
#: the linear and the periodic amplitudes agree to this away from the resonance (the
#: slip arcs move with the fluctuation there, which the linearisation holds still)
FORCED_TOL = 0.02
RESONANCE = (40.0, 55.0)
SPANS = ("tension[crankshaft-compressor]", "tension[pump-crankshaft]")


def forced(page: Page, quick: bool) -> None:
    import matplotlib.pyplot as plt

    elements = QUICK_ELEMENTS if quick else DEFAULT_ELEMENTS
    sets = {"numerics.friction_law": "tanh", "numerics.elements": elements}
    page.para(
        f"The crankshaft's speed fluctuating by {FLUCTUATION:g} rad/s about its 150 rad/s: "
        "each span's tension amplitude against the fluctuation's frequency, from periodic "
        "runs from rest (half of max - min over the last period, "
        "`RunResult.periodic`) and from the drive linearised about its steady state "
        "(`beltsim.forced_response`: (-w^2 M + i w C + K) z = f, f the driver's forcing, "
        f"the same grid of {elements} elements). Both take the tanh law (a smooth "
        "linearisation; the exact law's stuck nodes enter the linearisation with a penalty "
        f"slope). Away from the first resonance ({RESONANCE[0]:g} to {RESONANCE[1]:g} Hz) "
        f"the two must agree to {FORCED_TOL:.0%}; near it the slip arcs move with the "
        "fluctuation, which the linearisation holds still. Commands: "
        + _cmd(SCENES[0], "numerics.friction_law=tanh", f"numerics.elements={elements}",
               "'pulley.crankshaft.speed={mean = 150.0, amplitude = 0.5, period = T}'")
        + " with T = 1/F s for F in " + ", ".join(f"{f:g}" for f in FORCED[quick]) + " Hz.")
    scene = shipped_scene(SCENES[0], list(sets.items()))
    dense = np.geomspace(5.0, 200.0, 240)
    lin = beltsim.forced_response(scene, dense).amplitudes(FLUCTUATION)
    at = beltsim.forced_response(scene, FORCED[quick]).amplitudes(FLUCTUATION)
    rows, runs = [], {k: [] for k in SPANS}
    for m, f in enumerate(FORCED[quick]):
        sine = {"mean": 150.0, "amplitude": FLUCTUATION, "period": 1.0 / f}
        r = beltsim.run(scene.with_overrides([("pulley.crankshaft.speed", sine)]),
                        raise_on_failure=False)
        if not r.converged or not r.periodic:
            rows.append([f"{f:g}", page.fail(f"forced response, {f:g} Hz: {r.status.value} "
                                             f"({r.reason})"), "", "", "", ""])
            continue
        cells = [f"{f:g}", f"{r.wall_time:.3g}", str(r.statistics["steps"])]
        for key in SPANS:
            amp = 0.5 * (r.periodic[key]["max"] - r.periodic[key]["min"])
            runs[key].append((f, amp))
            rel = amp / at[key][m] - 1
            near = RESONANCE[0] <= f <= RESONANCE[1]
            cell = f"{amp:.4g} / {at[key][m]:.4g} ({rel:+.1%})"
            if not near and abs(rel) > FORCED_TOL:
                cell = page.fail(f"forced response, {f:g} Hz, {key}: {rel:+.1%}")
            cells.append(cell)
        rows.append(cells)
    page.table(["frequency [Hz]", "run wall [s]", "steps",
                *(f"{k}: run / linear [N]" for k in SPANS)], rows)
    fig, ax = plt.subplots(figsize=(7.5, 4.5), constrained_layout=True)
    for key, colour in zip(SPANS, ("C0", "C3")):
        ax.semilogy(dense, lin[key], color=colour, label=f"{key}, linearised")
        if runs[key]:
            f_run, a_run = zip(*runs[key])
            ax.semilogy(f_run, a_run, "o", mfc="none", color=colour,
                        label=f"{key}, periodic runs")
    ax.set_xlabel("crankshaft speed fluctuation frequency [Hz]")
    ax.set_ylabel(f"span tension amplitude [N] at {FLUCTUATION:g} rad/s")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    page.figure(fig, "forced_response", f"{SCENES[0]}: span tension amplitudes against "
                "the crankshaft's fluctuation frequency, linearised (lines) and from "
                "periodic runs (circles)")


#: the arm's forced response: frequencies (Hz) of the periodic runs with the moving arm,
#: away from the arm's mode at 132 Hz (at 130 Hz the arm's amplitude differs by 2.5 %:
#: the slip arcs move there, as at the accessory drive's first resonance), and the
#: figures compared with the linearisation (the arm's two spans and its angle)
ARM_FORCED = {False: (20.0, 50.0, 80.0, 110.0), True: (20.0, 80.0)}
ARM_KEYS = ("tension[steering-tensioner]", "tension[tensioner-pump]", "arm_travel")


def arm_motion(page: Page, quick: bool) -> None:
    """The tensioner's arm in transients: a start-up, the forced response with the arm
    against the linearisation, and its rotational modes against the discrete model."""
    import matplotlib.pyplot as plt

    from beltsim.beltdrive.rotational import adhesion_limit, rotational_model
    from beltsim.physics.loop_modes import drive_modes

    name = SCENES[2]
    elements = QUICK_ELEMENTS if quick else DEFAULT_ELEMENTS
    sets = [("numerics.integrator", "esdirk3"), ("numerics.elements", elements)]
    page.para(
        f"`{name}` from rest by esdirk3 on {elements} elements: the drive at rest with the "
        "arm settled under the installation tension, then the crankshaft and the loads "
        "ramped up; the arm's angle and rate are two unknowns of the loop (theory: "
        "\"The arm in a transient\"). The end state against the creep theory, as the "
        "steady solve's (its search for the rest angle). Commands: "
        + _cmd(name, "numerics.integrator=esdirk3", f"numerics.elements={elements}")
        + " and the same with `numerics.integrator=steady`.")
    r = beltsim.run(shipped_scene(name, sets), raise_on_failure=False)
    st = beltsim.run(shipped_scene(name, [STEADY, ("numerics.elements", elements)]),
                     raise_on_failure=False)
    e, es = r.errors() or {}, st.errors() or {}
    status = r.status.value if r.converged else page.fail(
        f"arm start-up: {r.status.value} ({r.reason})")
    page.table(["quantity", "start-up", "steady solve"], [
        ["status", status, st.status.value],
        ["end time [s]", f"{r.simulated_time:.4g}", ""],
        ["steps (rejected)", f"{r.statistics['steps']} ({r.statistics.get('rejected_steps')})",
         f"{st.statistics.get('arm_solves')} steady solves"],
        ["wall [s]", f"{r.wall_time:.3g}", f"{st.wall_time:.3g}"],
        *([ERRORS[k], fmt(e.get(k), ".3e"), fmt(es.get(k), ".3e")]
          for k in ("span_tension", "hub_load", "slip_arc", "arm_travel"))])
    h = r.history
    fig, ax = plt.subplots(figsize=(7.5, 3.5), constrained_layout=True)
    ax.plot(h["t"], h["arm_travel"], label="start-up (esdirk3)")
    ax.axhline(string_state(r.scene.params).arm_travel, ls="--", color="k",
               label="creep theory's rest angle")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("arm travel [rad]")
    ax.legend(fontsize=8)
    page.figure(fig, "arm_startup", f"{name}: the arm's travel into the belt from its drawn "
                "angle through the start-up")

    tanh = [("numerics.friction_law", "tanh"), *sets]
    scene = shipped_scene(name, tanh)
    freqs = ARM_FORCED[quick]
    page.para(
        f"The crankshaft's speed fluctuating by {FLUCTUATION:g} rad/s with the arm free: "
        "periodic runs with the moving arm against the drive linearised about its steady "
        "state with the arm's angle among its unknowns (`beltsim.forced_response`, "
        "`ForcedResponse.arm`), for the arm's two spans and its angle, the tanh law. "
        f"Agreement required: {FORCED_TOL:.0%}, away from the arm's mode at 132 Hz (at "
        "130 Hz the arm's amplitude differs by 2.5 %: the slip arcs move with it). "
        "Commands: "
        + _cmd(name, "numerics.friction_law=tanh", "numerics.integrator=esdirk3",
               f"numerics.elements={elements}",
               "'pulley.crankshaft.speed={mean = 150.0, amplitude = 0.5, period = T}'")
        + " with T = 1/F s for F in " + ", ".join(f"{f:g}" for f in freqs) + " Hz.")
    lin = beltsim.forced_response(scene, freqs).amplitudes(FLUCTUATION)
    rows = []
    for m, f in enumerate(freqs):
        sine = {"mean": 150.0, "amplitude": FLUCTUATION, "period": 1.0 / f}
        run = beltsim.run(scene.with_overrides([("pulley.crankshaft.speed", sine)]),
                          raise_on_failure=False)
        if not run.converged or not run.periodic:
            rows.append([f"{f:g}", page.fail(f"arm forced response, {f:g} Hz: "
                                             f"{run.status.value} ({run.reason})"), "",
                         *([""] * len(ARM_KEYS))])
            continue
        cells = [f"{f:g}", f"{run.wall_time:.3g}", str(run.statistics["steps"])]
        for key in ARM_KEYS:
            amp = 0.5 * (run.periodic[key]["max"] - run.periodic[key]["min"])
            rel = amp / lin[key][m] - 1
            cell = f"{amp:.4g} / {lin[key][m]:.4g} ({rel:+.2%})"
            if abs(rel) > FORCED_TOL:
                cell = page.fail(f"arm forced response, {f:g} Hz, {key}: {rel:+.2%}")
            cells.append(cell)
        rows.append(cells)
    page.table(["frequency [Hz]", "run wall [s]", "steps",
                *(f"{k}: run / linear" for k in ARM_KEYS)], rows)

    page.para(
        "The arm in the rotational model's limit (perfect adhesion, no loads, a belt 1e-4 as "
        "dense, no damping, the arm's neither, `beltdrive.rotational.adhesion_limit`): the "
        "lowest rotational frequencies of the linearised belt model with the arm free "
        "against the discrete model with the arm's angle as a degree of freedom "
        "(`rotational_model`, about the creep theory's rest angle). Command: "
        f"`beltsim modes {name}` on that scene.")
    lim = adhesion_limit(shipped_scene(name), elements=100)
    P = lim.params
    sol = string_state(P)
    rest = P.at_arm(sol.arm_travel - P.arm_turn)
    ref = rotational_model(rest, tension=rest.N0 - rest.rho * sol.c ** 2)
    found = drive_modes(lim, count=60, method="dense")  # the limit's spread spectrum
    light = [m.frequency_hz for m in found.modes if m.damping_ratio < 0.01][:len(ref.names)]
    page.table(["mode", "belt model [Hz]", "discrete model [Hz]", "relative"],
               [[str(k + 1), f"{a:.6g}", f"{b:.6g}", f"{a / b - 1:+.2e}"]
                for k, (a, b) in enumerate(zip(light, ref.frequencies))])


def build(page: Page, quick: bool) -> None:
    page.heading("Steady ladders")
    ladders(page, quick)
    page.heading("The beam's steady ladders")
    ladders(page, quick, "beam")
    page.heading("The default grid")
    default_grid(page)
    page.heading("A start-up from rest")
    startup(page, quick)
    page.heading("Gross slip at a named pulley")
    gross_slip(page, quick)
    page.heading("Forced response to the crankshaft's speed fluctuation")
    forced(page, quick)
    page.heading("The tensioner's arm in motion")
    arm_motion(page, quick)
