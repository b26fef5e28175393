"""Cross-check against Exudyn: the four-pulley tensioner drive of Exudyn's example
``main/pythonDev/Examples/beltDrivesComparison.py`` (J. Gerstmayr, 2022), its fourth
layout, run by Exudyn (ANCF cable, penalty contact with regularised Coulomb friction,
time integration from rest) and by beltsim (the creep theory and the steady solve of
the string, ``validation/scenes/exudyn_four_pulley.toml``).

The Exudyn model is the example's, adapted so that both codes solve the same problem:

* the tensioner arm is held at its drawn angle: the two idlers turn on fixed axes (the
  example lets the arm swing about the driven pulley's axis);
* a constant load torque on the driven pulley, raised with the driver's speed (the
  example hangs a 1 kg pendulum lever of 0.5 m on it, whose torque follows its angle);
* no gravity on the belt (the example's ``massProportionalLoad``);
* the driver is brought to ``--omega`` (default 2 pi rad/s, the example's intended
  speed) with the C^2 smoothstep over ``--ramp`` seconds, through the velocity
  constraint's ``offsetUserFunction_t``. (The published example sets
  ``offsetUserFunction``, which a velocity-level constraint does not read, so there the
  driver steps to 1 rad/s at t = 0.) The load torque rises with the same smoothstep.

Everything else is the example's: 100 ANCF elements laid on the reeving curve with the
reference axial strain -0.005, axial damping 1e-2 EA, two contact segments per element
and pulley (contact stiffness 4e4, friction stiffness 8e3, velocity penalty 0.8),
mu = 0.2, 1 kg / 0.01 kg m^2 pulleys, generalised-alpha with spectral radius 0.5 and
steps of 0.25 ms, a static solve without friction and with the pulleys locked first.
It runs 8 s (``--t-end``) and reports means over the last 2 s (``--window``); the
results and what they mean are on docs/verification/exudyn.md.

Run it from the repository root with beltsim's interpreter; Exudyn may live elsewhere::

    .venv/bin/python -m validation.exudyn_drive --exudyn-python /work/exuvenv/bin/python

The Exudyn half runs in that interpreter (this file, ``exudyn`` sub-command; it needs no
beltsim) and writes its JSON; ``--exudyn-json FILE`` reuses such a file instead. The
beltsim half then solves the scene, prints the comparison table and writes everything to
``--out`` (default ``validation/out/exudyn_drive.json``).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "validation" / "scenes" / "exudyn_four_pulley.toml"
DEFAULT_OUT = ROOT / "validation" / "out" / "exudyn_drive.json"

# --- the example's data ------------------------------------------------------------------
E_MOD = 1e9            # Pa
RHO = 1000.0           # kg/m^3
B = H = 0.002          # m, the cable's cross-section
AREA = B * H
EA = E_MOD * AREA      # 4000 N
EI = E_MOD * B * H**3 / 12
MASS_PER_LENGTH = RHO * AREA
PRE_STRETCH = -0.005   # the cable's reference axial strain
N_ANCF_NODES = 100
CONTACT_STIFFNESS = 4e5 * 0.1
CONTACT_DAMPING = 1e-2 * CONTACT_STIFFNESS * 0.1
FRICTION_STIFFNESS = CONTACT_STIFFNESS * 0.2
FRICTION_VELOCITY_PENALTY = 1e-4 * FRICTION_STIFFNESS
MU = 0.2
N_SEGMENTS = 2
AXIAL_DAMPING = 1e-2 * EA
WHEEL_MASS = 1.0
WHEEL_INERTIA = 0.01
STEP = 0.25e-3

R_WHEEL = 0.25
D_WHEELS = 0.6
TENSIONER_Y = R_WHEEL * 0.7
#: (name, centre, radius, side in Exudyn's reeving curve), in the example's order
PULLEYS = (("driver", (0.0, 0.0), R_WHEEL * 0.5, "L"),
           ("idler_top", (D_WHEELS * 0.4, TENSIONER_Y), R_WHEEL * 0.2, "R"),
           ("driven", (D_WHEELS, 0.0), R_WHEEL, "L"),
           ("idler_bottom", (D_WHEELS * 0.4, -TENSIONER_Y), R_WHEEL * 0.2, "R"))


def smoothstep(s: float) -> float:
    """The C^2 smoothstep 6 s^5 - 15 s^4 + 10 s^3 on [0, 1], 1 beyond."""
    s = min(max(s, 0.0), 1.0)
    return s * s * s * (10.0 + s * (-15.0 + 6.0 * s))


def smoothstep_rate(s: float) -> float:
    """d smoothstep / ds."""
    if s <= 0.0 or s >= 1.0:
        return 0.0
    return 30.0 * s * s * (1.0 - s) ** 2


def span_lines(curve):
    """The free spans of Exudyn's reeving curve: [(from, to, p0, p1)] in the example's
    order, each pulley named by the nearest centre to the span's ends."""
    import numpy as np

    def nearest(p):
        d = [abs(math.dist(p, c) - r) for _, c, r, _ in PULLEYS]
        return PULLEYS[int(np.argmin(d))][0]

    spans, seen = [], set()
    for item in curve:
        if item["type"] != "LINE":
            continue
        p0, p1 = (tuple(float(v) for v in item[k][:2]) for k in ("point0", "point1"))
        key = (nearest(p0), nearest(p1))
        if key in seen:
            continue
        seen.add(key)
        spans.append((key[0], key[1], p0, p1))
    return spans


def run_exudyn(t_end: float, omega: float, ramp: float, load_torque: float,
               window: float, sample_dt: float, trace_dt: float = 0.1,
               friction_stiffness: float = FRICTION_STIFFNESS) -> dict:
    """Build and run the Exudyn model; means over the last ``window`` seconds.
    ``friction_stiffness``: the tangential penalty of sticking (the example's by
    default), its velocity penalty kept in the example's ratio 1e-4 s."""
    import copy

    import exudyn as exu
    import numpy as np
    from exudyn.beams import CreateReevingCurve, PointsAndSlopes2ANCFCable2D
    from exudyn.itemInterface import (
        Cable2D,
        CoordinateConstraint,
        MarkerBodyCable2DShape,
        MarkerBodyRigid,
        MarkerNodeCoordinate,
        MarkerNodeRigid,
        NodeGenericData,
        NodePointGround,
        NodeRigidBody2D,
        ObjectContactFrictionCircleCable2D,
        ObjectGround,
        ObjectRigidBody2D,
        RevoluteJoint2D,
        Torque,
    )

    SC = exu.SystemContainer()
    mbs = SC.AddSystem()

    circles = [[list(c), r, side] for _, c, r, side in PULLEYS]
    circles = copy.deepcopy(circles + circles[:2])   # closed as in the example
    reeving = CreateReevingCurve(circles, drawingLinesPerCircle=64, removeLastLine=True,
                                 numberOfANCFnodes=N_ANCF_NODES, graphicsNodeSize=0.01)
    loop_length = float(reeving["totalLength"])
    spans = span_lines(reeving["circleData"])

    oGround = mbs.AddObject(ObjectGround(referencePosition=[0, 0, 0]))
    template = Cable2D(physicsMassPerLength=MASS_PER_LENGTH, physicsBendingStiffness=EI,
                       physicsAxialStiffness=EA, physicsBendingDamping=0.0,
                       physicsAxialDamping=AXIAL_DAMPING,
                       physicsReferenceAxialStrain=PRE_STRETCH,
                       useReducedOrderIntegration=2)
    ancf = PointsAndSlopes2ANCFCable2D(mbs, reeving["ancfPointsSlopes"],
                                       reeving["elementLengths"], template,
                                       massProportionalLoad=[0, 0, 0],   # no gravity
                                       firstNodeIsLastNode=True)
    cables = ancf[1]
    element_lengths = [float(v) for v in reeving["elementLengths"]]

    nGround = mbs.AddNode(NodePointGround())
    mCoordGround = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=nGround, coordinate=0))

    def ramp_factor(t):
        return smoothstep(t / ramp) if ramp > 0 else 1.0

    def drive_speed_t(mbs, t, itemNumber, offset):     # noqa: ARG001  Exudyn's signature
        return offset * ramp_factor(t)

    def drive_angle(mbs, t, itemNumber, offset):       # noqa: ARG001  (not read here)
        return 0.0

    def load(mbs, t, load):                            # noqa: ARG001
        return [0.0, 0.0, -load_torque * ramp_factor(t)]

    wheels, joints, contacts, locks = {}, {}, {}, []
    driver_constraint = None
    for name, (x, y), r, _ in PULLEYS:
        nWheel = mbs.AddNode(NodeRigidBody2D(referenceCoordinates=[x, y, 0.0],
                                             initialVelocities=[0.0, 0.0, 0.0]))
        mbs.AddObject(ObjectRigidBody2D(physicsMass=WHEEL_MASS,
                                        physicsInertia=WHEEL_INERTIA, nodeNumber=nWheel))
        mWheel = mbs.AddMarker(MarkerNodeRigid(nodeNumber=nWheel))
        mAxis = mbs.AddMarker(MarkerBodyRigid(bodyNumber=oGround, localPosition=[x, y, 0]))
        # every axis fixed in space: the idlers' arm held at its drawn angle
        joints[name] = mbs.AddObject(RevoluteJoint2D(markerNumbers=[mAxis, mWheel]))
        mRot = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=nWheel, coordinate=2))
        locks.append(mbs.AddObject(CoordinateConstraint(markerNumbers=[mCoordGround, mRot])))
        if name == "driver":
            driver_constraint = mbs.AddObject(CoordinateConstraint(
                markerNumbers=[mCoordGround, mRot], velocityLevel=True, offset=omega,
                offsetUserFunction=drive_angle, offsetUserFunction_t=drive_speed_t))
        elif name == "driven":
            mbs.AddLoad(Torque(markerNumber=mWheel, loadVector=[0, 0, -load_torque],
                               loadVectorUserFunction=load))
        wheels[name] = nWheel
        contacts[name] = []
        for k, cable in enumerate(cables):
            gaps = [0.1] * N_SEGMENTS + [-2] * N_SEGMENTS + [0] * N_SEGMENTS
            mCable = mbs.AddMarker(MarkerBodyCable2DShape(bodyNumber=cable,
                                                          numberOfSegments=N_SEGMENTS,
                                                          verticalOffset=-H / 2))
            nData = mbs.AddNode(NodeGenericData(initialCoordinates=gaps,
                                                numberOfDataCoordinates=3 * N_SEGMENTS))
            co = mbs.AddObject(ObjectContactFrictionCircleCable2D(
                markerNumbers=[mWheel, mCable], nodeNumber=nData,
                numberOfContactSegments=N_SEGMENTS, contactStiffness=CONTACT_STIFFNESS,
                contactDamping=CONTACT_DAMPING,
                frictionVelocityPenalty=FRICTION_VELOCITY_PENALTY
                * friction_stiffness / FRICTION_STIFFNESS,
                frictionStiffness=friction_stiffness, frictionCoefficient=MU,
                circleRadius=r))
            contacts[name].append((co, nData, element_lengths[k] / N_SEGMENTS))

    # --- sampling: every sample_dt in the last window ------------------------------------
    OV = exu.OutputVariableType
    samples, trace = [], []
    next_sample = [t_end - window]
    next_trace = [0.0]

    def span_forces():
        """Axial force at the middle of each span: the element nearest the span's middle."""
        mids = []
        for k, cable in enumerate(cables):
            p = mbs.GetObjectOutputBody(cable, OV.Position,
                                        localPosition=[element_lengths[k] / 2, 0, 0])
            mids.append(np.asarray(p)[:2])
        mids = np.asarray(mids)
        out = {}
        for a, b, p0, p1 in spans:
            m = 0.5 * (np.asarray(p0) + np.asarray(p1))
            k = int(np.argmin(np.linalg.norm(mids - m, axis=1)))
            f = mbs.GetObjectOutputBody(cables[k], OV.ForceLocal,
                                        localPosition=[element_lengths[k] / 2, 0, 0])
            out[f"{a}-{b}"] = float(np.atleast_1d(f)[0])
        return out

    def contact_state():
        """Per pulley: the contact arc, the slip arc (segments in contact whose friction
        state is slip), the largest slip speed and the mean penetration."""
        out = {}
        radius = {name: r for name, _, r, _ in PULLEYS}
        for name, items in contacts.items():
            arc = slip = 0.0
            vmax, pen, npen = 0.0, 0.0, 0
            for co, nData, seg in items:
                data = np.asarray(mbs.GetNodeOutput(nData, OV.Coordinates))
                gap, state = data[:N_SEGMENTS], data[N_SEGMENTS:2 * N_SEGMENTS]
                if not np.any(gap < 0):
                    continue
                vel = np.asarray(mbs.GetObjectOutput(co, OV.Coordinates_t))
                for i in range(N_SEGMENTS):
                    if gap[i] < 0:
                        arc += seg / radius[name]
                        pen += -gap[i]
                        npen += 1
                        if state[i] != 0:
                            slip += seg / radius[name]
                            vmax = max(vmax, abs(float(vel[2 * i])))
            out[name] = {"contact_arc": arc, "slip_arc": slip, "max_slip_speed": vmax,
                         "penetration": pen / max(npen, 1)}
        return out

    def sample(t):
        row = {"t": t,
               "speed": {n: float(mbs.GetNodeOutput(w, OV.AngularVelocity)[2])
                         for n, w in wheels.items()},
               "hub": {n: float(np.linalg.norm(np.asarray(
                   mbs.GetObjectOutput(j, OV.Force))[:2])) for n, j in joints.items()},
               "tension": span_forces(),
               "contact": contact_state()}
        samples.append(row)

    def pre_step(mbs, t):
        if t >= next_trace[0] - 0.5 * STEP:     # the whole run, coarse: is it steady?
            if len(trace) % 10 == 0:
                print(f"exudyn: t = {t:.2f} s after {time.perf_counter() - wall1:.0f} s",
                      file=sys.stderr, flush=True)
            trace.append({"t": t, "tension": span_forces(),
                          "speed": {n: float(mbs.GetNodeOutput(w, OV.AngularVelocity)[2])
                                    for n, w in wheels.items()}})
            next_trace[0] += trace_dt
        if t >= next_sample[0] - 0.5 * STEP:
            sample(t)
            next_sample[0] += sample_dt
        return True

    mbs.Assemble()
    ss = exu.SimulationSettings()
    ss.linearSolverType = exu.LinearSolverType.EigenSparse
    ss.solutionSettings.writeSolutionToFile = False
    ss.solutionSettings.sensorsWritePeriod = 1.0
    ss.parallel.numberOfThreads = 1
    ss.timeIntegration.endTime = t_end
    ss.timeIntegration.numberOfSteps = int(round(t_end / STEP))
    ss.timeIntegration.verboseMode = 0
    ss.timeIntegration.newton.useModifiedNewton = True
    ss.timeIntegration.newton.numericalDifferentiation.minimumCoordinateSize = 1
    ss.timeIntegration.discontinuous.maxIterations = 5 + 2
    ss.timeIntegration.generalizedAlpha.spectralRadius = 0.5
    ss.staticSolver.adaptiveStep = False
    ss.staticSolver.loadStepGeometric = True
    ss.staticSolver.loadStepGeometricRange = 1e3
    ss.staticSolver.numberOfLoadSteps = 10
    ss.staticSolver.stabilizerODE2term = 1e5 * 10
    ss.staticSolver.newton.relativeTolerance = 1e-6
    ss.staticSolver.newton.absoluteTolerance = 1e-6
    ss.staticSolver.newton.numericalDifferentiation.minimumCoordinateSize = 1
    ss.staticSolver.newton.numericalDifferentiation.relativeEpsilon = 1e-5

    # the static state as in the example: no friction, the pulleys locked, no drive
    wall0 = time.perf_counter()
    mbs.SetObjectParameter(driver_constraint, "activeConnector", False)
    for items in contacts.values():
        for co, _, _ in items:
            mbs.SetObjectParameter(co, "frictionCoefficient", 0.0)
            mbs.SetObjectParameter(co, "frictionStiffness", 1.0)
    mbs.SolveStatic(ss, updateInitialValues=True)
    static = {"tension": span_forces(), "contact": contact_state()}
    for items in contacts.values():
        for co, _, _ in items:
            mbs.SetObjectParameter(co, "frictionCoefficient", MU)
            mbs.SetObjectParameter(co, "frictionStiffness", friction_stiffness)
    mbs.SetObjectParameter(driver_constraint, "activeConnector", True)
    for c in locks:
        mbs.SetObjectParameter(c, "activeConnector", False)
    wall_static = time.perf_counter() - wall0

    mbs.SetPreStepUserFunction(pre_step)
    wall1 = time.perf_counter()
    mbs.SolveDynamic(ss)
    wall_dynamic = time.perf_counter() - wall1
    sample(t_end)

    def mean(get):
        vals = [get(s) for s in samples]
        return float(np.mean(vals)), float(np.std(vals))

    result = {
        "exudyn_version": exu.__version__,
        "t_end": t_end, "step": STEP, "steps": ss.timeIntegration.numberOfSteps,
        "omega": omega, "ramp": ramp, "ramp_kind": "C2 smoothstep, offsetUserFunction_t",
        "load_torque": load_torque, "window": window, "samples": len(samples),
        "friction_stiffness": friction_stiffness, "contact_stiffness": CONTACT_STIFFNESS,
        "reference_length": loop_length, "pre_stretch": PRE_STRETCH,
        "wall_static": wall_static, "wall_dynamic": wall_dynamic,
        "static": static,
        "speed": {}, "speed_std": {}, "hub_load": {}, "hub_load_std": {},
        "tension": {}, "tension_std": {}, "contact": {},
        "history": samples, "trace": trace,
    }
    for n in wheels:
        result["speed"][n], result["speed_std"][n] = mean(lambda s, n=n: s["speed"][n])
        result["hub_load"][n], result["hub_load_std"][n] = mean(lambda s, n=n: s["hub"][n])
        result["contact"][n] = {k: mean(lambda s, n=n, k=k: s["contact"][n][k])[0]
                                for k in samples[0]["contact"][n]}
    for key in samples[0]["tension"]:
        result["tension"][key], result["tension_std"][key] = mean(
            lambda s, key=key: s["tension"][key])
    return result


def exudyn_main(argv) -> int:
    p = argparse.ArgumentParser(prog="exudyn_drive.py exudyn")
    p.add_argument("--t-end", type=float, default=8.0)
    p.add_argument("--omega", type=float, default=2 * math.pi)
    p.add_argument("--ramp", type=float, default=1.0)
    p.add_argument("--load-torque", type=float, default=1.5)
    p.add_argument("--window", type=float, default=2.0)
    p.add_argument("--sample-dt", type=float, default=0.05)
    p.add_argument("--friction-stiffness", type=float, default=FRICTION_STIFFNESS,
                   help="the tangential penalty of sticking (N/m per segment)")
    p.add_argument("--json", type=Path, required=True)
    a = p.parse_args(argv)
    res = run_exudyn(a.t_end, a.omega, a.ramp, a.load_torque, a.window, a.sample_dt,
                     friction_stiffness=a.friction_stiffness)
    a.json.parent.mkdir(parents=True, exist_ok=True)
    a.json.write_text(json.dumps(res, indent=1))
    print(f"exudyn: {a.t_end} s simulated in {res['wall_dynamic']:.1f} s of wall time "
          f"(static {res['wall_static']:.1f} s); wrote {a.json}")
    return 0


# --- the beltsim half ---------------------------------------------------------------------
#: the rims' radii in the example, for the theory on the rims (see the scene's [drive])
RIMS = {"driver": 0.125, "idler_bottom": 0.05, "driven": 0.25, "idler_top": 0.05}


def installation_tension(loop_length: float, reference_length: float) -> float:
    """N0 = EA (Lambda - L0) / Lambda of a loop Lambda long, L0 the example's unstretched
    length: its reference length (the reeving curve's) times 1 + its reference strain."""
    L0 = reference_length * (1.0 + PRE_STRETCH)
    return EA * (loop_length - L0) / loop_length


def _table(summary: dict) -> dict:
    """The figures compared, from a beltsim summary (the theory's or a run's)."""
    pulleys = {p["name"]: p for p in summary["pulleys"]}
    return {"tension": {f"{s['from']}-{s['to']}": s["tension"] for s in summary["spans"]},
            "speed": {n: p["speed"] for n, p in pulleys.items()},
            "slip_arc": {n: p["slip_arc"] for n, p in pulleys.items()},
            "wrap": {n: p["wrap"] for n, p in pulleys.items()},
            "hub_load": {n: math.hypot(*p["hub_load"]) for n, p in pulleys.items()}}


def run_beltsim(reference_length: float, startup: bool, omega: float, ramp: float,
                load_torque: float, static_tension: float) -> dict:
    """beltsim's creep theory and steady solve of the scene (and, with ``startup``, a
    start-up from rest by esdirk3 with Exudyn's ramp); the theory on the rims too, and
    with the belt installed at ``static_tension`` (Exudyn's, from its static solve)."""
    import beltsim
    from beltsim.beltdrive import string_state

    base = [f"pulley.driver.speed={omega!r}", f"pulley.driven.load_torque={load_torque!r}"]
    scene = beltsim.load_scene(SCENE, overrides=base)
    lam = scene.params.layout.loop_length
    n0 = installation_tension(lam, reference_length)
    if abs(n0 - scene.params.N0) > 1e-3:
        raise SystemExit(f"{SCENE.name}: drive.installation_tension = {scene.params.N0} N, "
                         f"but the example's belt on this loop has {n0:.4f} N")
    out = {"loop_length": lam, "installation_tension": n0}

    t0 = time.perf_counter()
    out["theory"] = _table(string_state(scene.params).summary())
    out["theory"]["wall"] = time.perf_counter() - t0

    rims = [f"pulley.{n}.radius={r!r}" for n, r in RIMS.items()]
    rim_scene = beltsim.load_scene(SCENE, overrides=base + rims)
    n0_rims = installation_tension(rim_scene.params.layout.loop_length, reference_length)
    rim_scene = beltsim.load_scene(
        SCENE, overrides=base + rims + [f"drive.installation_tension={n0_rims!r}"])
    out["theory_rims"] = _table(string_state(rim_scene.params).summary())
    out["theory_rims"]["installation_tension"] = n0_rims

    at_static = beltsim.load_scene(
        SCENE, overrides=base + [f"drive.installation_tension={static_tension!r}"])
    out["theory_static"] = _table(string_state(at_static.params).summary())
    out["theory_static"]["installation_tension"] = static_tension

    t0 = time.perf_counter()
    steady = beltsim.run(scene)
    out["steady"] = _table(steady.summary())
    out["steady"].update(wall=time.perf_counter() - t0, wall_time=float(steady.wall_time),
                         compile_time=float(steady.compile_time), status=str(steady.status),
                         errors={k: float(v) for k, v in steady.errors().items()})
    if startup:
        t0 = time.perf_counter()
        run = beltsim.run(scene, overrides=["numerics.integrator=esdirk3",
                                            f"numerics.ramp_time={ramp!r}"])
        out["startup"] = _table(run.summary())
        out["startup"].update(wall=time.perf_counter() - t0, wall_time=float(run.wall_time),
                              compile_time=float(run.compile_time), status=str(run.status),
                              simulated_time=float(run.simulated_time),
                              steps=int(run.statistics.get("steps", 0)),
                              errors={k: float(v) for k, v in run.errors().items()})
    return out


# --- the table ----------------------------------------------------------------------------
#: Exudyn's spans in beltsim's names (the belt runs driver -> idler_bottom -> driven ->
#: idler_top: the driver turns counterclockwise and its upper span is the tight one)
SPANS = (("driver-idler_bottom", "idler_bottom-driver"),
         ("idler_bottom-driven", "driven-idler_bottom"),
         ("driven-idler_top", "idler_top-driven"),
         ("idler_top-driver", "driver-idler_top"))
ORDER = ("driver", "idler_bottom", "driven", "idler_top")


def exudyn_table(exu: dict) -> dict:
    """Exudyn's figures in beltsim's names and senses."""
    c = exu["contact"]
    return {"tension": {b: exu["tension"][e] for b, e in SPANS},
            "tension_std": {b: exu["tension_std"][e] for b, e in SPANS},
            # speeds in each pulley's running sense, as beltsim gives them
            "speed": {n: abs(exu["speed"][n]) for n in ORDER},
            "slip_arc": {n: c[n]["slip_arc"] for n in ORDER},
            "wrap": {n: c[n]["contact_arc"] for n in ORDER},
            "hub_load": {n: exu["hub_load"][n] for n in ORDER}}


def comparison_rows(bs: dict, ex: dict):
    """(quantity, unit, {column: value}) rows of the comparison."""
    n0_rims = bs["theory_rims"]["installation_tension"]
    n0_static = bs["theory_static"]["installation_tension"]
    cols = {f"theory on the rims, N0 = {n0_rims:.1f} N": bs["theory_rims"],
            "beltsim theory": bs["theory"], "beltsim steady": bs["steady"],
            f"theory, N0 = Exudyn's static {n0_static:.2f} N": bs["theory_static"]}
    if "startup" in bs:
        cols["beltsim start-up"] = bs["startup"]
    cols["Exudyn"] = ex
    rows = []
    for span, _ in SPANS:
        rows.append((f"tension {span}", "N", {k: v["tension"][span] for k, v in cols.items()}))
    rows.append(("speed ratio driven/driver", "",
                 {k: v["speed"]["driven"] / v["speed"]["driver"] for k, v in cols.items()}))
    for n in ("idler_bottom", "idler_top"):
        rows.append((f"speed {n}", "rad/s", {k: v["speed"][n] for k, v in cols.items()}))
    for n in ORDER:
        rows.append((f"wrap {n}", "rad", {k: v["wrap"][n] for k, v in cols.items()}))
    for n in ORDER:
        rows.append((f"slip arc {n}", "rad", {k: v["slip_arc"][n] for k, v in cols.items()}))
    for n in ORDER:
        rows.append((f"hub load {n}", "N", {k: v["hub_load"][n] for k, v in cols.items()}))
    return rows


def markdown_table(rows) -> str:
    cols = list(rows[0][2])
    lines = ["| quantity | unit | " + " | ".join(cols) + " |",
             "|---|---|" + "---:|" * len(cols)]
    for name, unit, vals in rows:
        cells = []
        for c in cols:
            v = vals[c]
            cells.append(f"{v:.5f}" if "ratio" in name else f"{v:.4g}")
        lines.append(f"| {name} | {unit} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def steadiness(exu: dict) -> str:
    """How steady Exudyn's window is: each figure's standard deviation over the window and
    the change of its mean from the window's first half to its second."""
    hist = exu["history"]
    half = len(hist) // 2

    def drift(get):
        a = sum(get(h) for h in hist[:half]) / half
        b = sum(get(h) for h in hist[half:]) / (len(hist) - half)
        return b - a

    lines = [f"Exudyn over its last {exu['window']:g} s: standard deviation, drift "
             "(second half's mean less the first half's)"]
    for b, e in SPANS:
        lines.append(f"  tension {b}: {exu['tension_std'][e]:.3g} N, "
                     f"{drift(lambda h, e=e: h['tension'][e]):+.3g} N")
    ratio = [h["speed"]["driven"] / h["speed"]["driver"] for h in hist]
    mean = sum(ratio) / len(ratio)
    std = (sum((r - mean) ** 2 for r in ratio) / len(ratio)) ** 0.5
    lines.append(f"  speed ratio: {std:.2g}, "
                 f"{drift(lambda h: h['speed']['driven'] / h['speed']['driver']):+.2g}")
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m validation.exudyn_drive",
                                description="Cross-check beltsim against Exudyn on the "
                                            "four-pulley drive of beltDrivesComparison.py.")
    p.add_argument("--exudyn-python", default=os.environ.get("EXUDYN_PYTHON"),
                   help="an interpreter with exudyn (default: $EXUDYN_PYTHON, else this one)")
    p.add_argument("--exudyn-json", type=Path, default=None,
                   help="reuse this Exudyn result instead of running Exudyn")
    p.add_argument("--t-end", type=float, default=8.0, help="Exudyn's simulated time (s)")
    p.add_argument("--window", type=float, default=2.0,
                   help="Exudyn's means over the last WINDOW seconds")
    p.add_argument("--omega", type=float, default=2 * math.pi, help="driver speed (rad/s)")
    p.add_argument("--ramp", type=float, default=1.0, help="smoothstep ramp time (s)")
    p.add_argument("--load-torque", type=float, default=1.5, help="driven load (N m)")
    p.add_argument("--friction-stiffness", type=float, default=FRICTION_STIFFNESS,
                   help="Exudyn's tangential penalty of sticking (N/m per segment; "
                        "the example's 8000 by default)")
    p.add_argument("--no-startup", action="store_true", help="skip beltsim's start-up run")
    p.add_argument("--out", type=Path, default=DEFAULT_OUT)
    a = p.parse_args(argv)

    if a.exudyn_json is None:
        a.out.parent.mkdir(parents=True, exist_ok=True)
        a.exudyn_json = a.out.with_name(a.out.stem + "_exudyn.json")
        cmd = [a.exudyn_python or sys.executable, str(Path(__file__).resolve()), "exudyn",
               "--t-end", repr(a.t_end), "--window", repr(a.window), "--omega", repr(a.omega),
               "--ramp", repr(a.ramp), "--load-torque", repr(a.load_torque),
               "--friction-stiffness", repr(a.friction_stiffness),
               "--json", str(a.exudyn_json)]
        print("running Exudyn:", " ".join(cmd), flush=True)
        subprocess.run(cmd, check=True)
    exu = json.loads(a.exudyn_json.read_text())
    for key, mine in (("omega", a.omega), ("load_torque", a.load_torque), ("ramp", a.ramp)):
        if abs(exu[key] - mine) > 1e-12:
            raise SystemExit(f"{a.exudyn_json}: Exudyn ran with {key} = {exu[key]}, not {mine}")

    static = exu["static"]["tension"]
    bs = run_beltsim(exu["reference_length"], not a.no_startup, a.omega, a.ramp,
                     a.load_torque, sum(static.values()) / len(static))
    ex = exudyn_table(exu)
    rows = comparison_rows(bs, ex)
    print(f"Exudyn {exu['exudyn_version']}: {exu['t_end']:g} s simulated in "
          f"{exu['steps']} steps of {exu['step'] * 1e3:g} ms, means over the last "
          f"{exu['window']:g} s ({exu['samples']} samples); friction stiffness "
          f"{exu.get('friction_stiffness', FRICTION_STIFFNESS):g} N/m per segment")
    print(f"installation tension: beltsim {bs['installation_tension']:.3f} N on the middle "
          f"line's loop ({bs['loop_length']:.5f} m); Exudyn's static solve "
          f"{min(exu['static']['tension'].values()):.3f} .. "
          f"{max(exu['static']['tension'].values()):.3f} N")
    print(markdown_table(rows))
    print(steadiness(exu))
    # beltsim's runs: the run's own stepping time (result.wall_time), without compiling
    # or loading the numba kernels (compile_time, printed below)
    walls = {"beltsim theory": bs["theory"]["wall"],
             "beltsim steady": bs["steady"]["wall_time"]}
    if "startup" in bs:
        walls["beltsim start-up"] = bs["startup"]["wall_time"]
    walls["Exudyn static"] = exu["wall_static"]
    walls["Exudyn dynamic"] = exu["wall_dynamic"]
    print("wall time (s): " + ", ".join(f"{k} {v:.3g}" for k, v in walls.items()))
    print("beltsim kernels compiled or loaded (s): "
          + ", ".join(f"{k} {bs[k]['compile_time']:.3g}" for k in ("steady", "startup")
                      if k in bs))
    if "startup" in bs:
        print(f"beltsim start-up: {bs['startup']['status']}, "
              f"{bs['startup']['simulated_time']:.3g} s simulated in "
              f"{bs['startup']['steps']} steps")
    print(f"beltsim steady: {bs['steady']['status']}, errors against the theory "
          + ", ".join(f"{k} {v:.2g}" for k, v in bs["steady"]["errors"].items()))
    a.out.parent.mkdir(parents=True, exist_ok=True)
    a.out.write_text(json.dumps({"beltsim": bs, "exudyn": {k: v for k, v in exu.items()
                                                           if k not in ("history", "trace")},
                                 "exudyn_json": str(a.exudyn_json), "wall": walls,
                                 "rows": rows}, indent=1))
    print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "exudyn":
        sys.exit(exudyn_main(sys.argv[2:]))
    sys.exit(main())
