"""Paths and command runners shared by the tests, independent of the working directory;
error bounds; and the one discrete model's two layouts as the kernel tests build them."""

import subprocess
import sys
from importlib.resources import files
from pathlib import Path
from typing import NamedTuple

import numpy as np

from beltsim.beltdrive.scene import DriveScene
from beltsim.physics import reference
from beltsim.physics.discrete import GYROSCOPIC_FORMS, Loads, Mesh, ModelParams, State
from beltsim.physics.friction import ADHESION, EXACT, LINEAR, RAMP, SQRT, TANH, is_exact
from beltsim.physics.model import JACOBIAN, assemble
from beltsim.problem.drive import Drive, Profile, Profiles
from beltsim.problem.scene import Scene
from beltsim.solvers import Discretisation, LoopDiscretisation
from beltsim.solvers.linearise import jacobian_matrix
from beltsim.solvers.newton import Workspace

ROOT = Path(__file__).resolve().parents[1]


def scene_path(name: str) -> str:
    """The file of a shipped scene, e.g. scene_path("paper_slip")."""
    return str(files("beltsim.scenes") / f"{name}.toml")


def cli(*args, timeout=600, **kw):
    """Run ``python -m beltsim.cli ARGS`` and capture its output."""
    return module("beltsim.cli", *args, timeout=timeout, **kw)


def module(name, *args, timeout=600, **kw):
    """Run ``python -m NAME ARGS`` from the repository root and capture its output."""
    kw.setdefault("cwd", ROOT)
    return subprocess.run([sys.executable, "-m", name, *map(str, args)],
                          capture_output=True, text=True, timeout=timeout, **kw)


#: End-to-end error bounds are this factor above the error measured on the test's own
#: grid (the discretisation error), so that a loss of accuracy fails long before the
#: issue's acceptance bounds (0.5% total friction, 2% u and theta) would notice it.
ERROR_FACTOR = 3.0

#: Errors of the paper scenes on 500 elements against their exact solutions (relative;
#: slip start in m), measured; second order in the element size. The transient and the
#: steady schemes land on the same discrete steady state, so they share these.
PAPER_ERRORS_500 = {
    "quasistatic": {"total_friction": 1.7e-5, "u": 1.5e-5, "theta": 3.4e-5,
                    "concentrated_force": 1.5e-5, "slip_power": 1.8e-5},
    "inertia": {"total_friction": 2.7e-5, "u": 3.0e-5, "theta": 1.0e-4,
                "concentrated_force": 2.0e-4, "slip_power": 3.8e-5},
    "slip": {"total_friction": 1.5e-5, "u": 1.3e-5, "theta": 5.2e-5, "slip_power": 1.4e-5,
             "slip_start": 7.3e-8},
}


def assert_errors_near(result, measured: dict, factor: float = ERROR_FACTOR):
    """A converged run whose every error is within ``factor`` of its measurement
    (``measured`` names every error the run has)."""
    assert result.converged, result.reason
    errors = {k: v for k, v in result.errors().items() if v is not None}
    assert set(errors) == set(measured), (sorted(errors), sorted(measured))
    for key, value in errors.items():
        assert value <= factor * measured[key], (key, value, measured[key])


# -- the one discrete model on either layout, as the kernel tests build it -------------
# A layout's mesh, coefficients, drive and loads, and a random trial state with a
# previous step's: what the tests hand to physics.model.assemble and to physics.reference
# (reference.residual on the straight belt, reference.loop_residual on the loop).

#: The layouts of the one model: the paper's open belt and the closed two-pulley drive.
LAYOUTS = ("straight", "loop", "serpentine", "tensioner")

#: A four-pulley drive of inner pulleys (the beam takes it): drive_flat's belt on a
#: motor, a mill, a fan and an idler, listed counterclockwise.
SERPENTINE_PULLEYS = [
    {"name": "motor", "centre": [0.0, 0.0], "radius": 0.08, "speed": 150.0},
    {"name": "mill", "centre": [0.55, 0.05], "radius": 0.12, "inertia": 0.02,
     "load_torque": 20.0},
    {"name": "fan", "centre": [0.38, 0.36], "radius": 0.06, "inertia": 0.005,
     "load_torque": 5.0},
    {"name": "idler", "centre": [0.05, 0.3], "radius": 0.04, "inertia": 1e-4},
]


#: A three-pulley machine drive with a back-side idler on its tight span (as the shipped
#: serpentine_machine's layout).
BACK_IDLER = [
    {"name": "motor", "centre": [0.0, 0.0], "radius": 0.08, "speed": 150.0},
    {"name": "mill", "centre": [0.6, 0.0], "radius": 0.12, "inertia": 0.02,
     "load_torque": 30.0},
    {"name": "idler", "centre": [0.16, 0.075], "radius": 0.035, "side": "back",
     "inertia": 1e-4},
]
#: SERPENTINE_PULLEYS with a back-side idler pressing on the motor-mill span from outside
#: the loop: the kernels' N-pulley layout (the friction on the belt's outer face there).
SERPENTINE_BACK = [SERPENTINE_PULLEYS[0],
                   {"name": "press", "centre": [0.3, -0.05], "radius": 0.03, "side": "back",
                    "inertia": 1e-4},
                   *SERPENTINE_PULLEYS[1:]]


def serpentine_scene(pulleys=None, model="beam", **over) -> DriveScene:
    """drive_flat's belt, contact and physics on a layout of ``pulleys`` (tables of
    [[pulley]]; SERPENTINE_PULLEYS by default), with ``over`` (SECTION.KEY: value)."""
    data = DriveScene.load(scene_path("drive_flat")).to_dict()
    data["drive"] = {"installation_tension": data["drive"]["installation_tension"]}
    data["pulley"] = [dict(p) for p in (pulleys or SERPENTINE_PULLEYS)]
    data["physics"]["model"] = model
    scene = DriveScene.from_dict(data)
    return scene.with_overrides(over) if over else scene

#: The straight belt's friction laws by name (the loop's scene takes tanh, sqrt and
#: exact, and adhesion as a "stick" contact).
LAWS = {"linear": LINEAR, "tanh": TANH, "sqrt": SQRT, "ramp": RAMP, "exact": EXACT,
        "adhesion": ADHESION}

#: a backward-Euler step's 1 / dt, or 0 (the steady problem), on each layout: the loop's
#: dt = 2e-4 s is about a thousandth of its belt's transit time
INV_DT = {"straight": 3e3, "loop": 1.0 / 2e-4, "serpentine": 1.0 / 2e-4,
          "tensioner": 1.0 / 2e-4}

#: The loop's drive: rim speed, friction factor and load torque.
LOOP_DRIVE = Drive(Profile.constant(12.1), Profile.constant(0.9),
                   Profiles.constants((0.0, 40.0)))


class KernelCase(NamedTuple):
    """A layout at time t with a random trial state (u, theta, lam: all the nodes; g: a
    loop's global unknowns) and a previous step's ``old``; ``m``: the magnitudes of the
    unknowns, in the order of :func:`unknowns`."""

    layout: str
    mesh: Mesh
    p: ModelParams
    drive: Drive
    loads: Loads
    t: float
    u: np.ndarray
    th: np.ndarray
    lam: np.ndarray
    g: np.ndarray
    old: State
    inv_dt: float
    m: np.ndarray
    disc: object  # the Discretisation or LoopDiscretisation it was built from


def random_loads(n_nodes, seed):
    """Random distributed loads on ``n_nodes`` nodes, tabulated at three times."""
    rng = np.random.default_rng(seed)
    return Loads(np.array([0.0, 0.004, 0.01]),
                 *(1e3 * rng.standard_normal((3, n_nodes)) for _ in range(4)))


def straight_state(n_nodes, seed, amp):
    """(u, theta, old): a random trial state of the straight belt and a previous step's
    (values and local velocities), of size ``amp`` and zero at both ends."""
    rng = np.random.default_rng(seed)
    arrs = [amp * rng.standard_normal(n_nodes) for _ in range(6)]
    for a in arrs:
        a[0] = a[-1] = 0.0
    u, th, uo, tho, udo, tdo = arrs
    zero = np.zeros(n_nodes)
    return u, th, State(uo, tho, zero.copy(), udo, tdo, zero.copy())


def kernel_case(layout, law, step, seed, gyro="upwind", inertia=True, loads=False,
                model="beam", grid=None) -> KernelCase:
    """``layout`` with friction ``law`` (a name), a step (``step``; else the steady
    problem), the gyroscopic form, inertia, random loads and the string or beam model,
    and a random state drawn from ``seed``; ``grid``: a loop's own grid."""
    if layout == "straight":
        return _straight_case(law, INV_DT[layout] if step else 0.0, seed, gyro, inertia,
                              loads, model, grid)
    return _loop_case(layout, law, INV_DT[layout] if step else 0.0, seed, gyro, inertia,
                      loads, model, grid)


def _straight_case(law, inv_dt, seed, gyro, inertia, loads, model, grid):
    """The paper's belt on 40 elements; laws at v_reg 5 m/s (v_aug for the exact ones), so
    that the random slip velocities (~5 m/s) fall on the steep part of the saturating laws
    and the exact law's stick test goes both ways."""
    assert model == "beam" and grid is None, "the straight belt is a beam on its own grid"
    scene = Scene.load(scene_path("paper_slip")).with_overrides(
        ["numerics.elements=40", f"physics.inertia={str(inertia).lower()}"])
    d = Discretisation(scene)
    p = d.model._replace(dual=0, law=LAWS[law], regularisation=5.0,
                         gyro=GYROSCOPIC_FORMS[gyro])
    n, amp = len(d.grid.x), 1e-4
    u, th, old = straight_state(n, seed, amp)
    # the exact laws' multipliers, stick and slip
    lam = 1.5 * np.random.default_rng(seed + 100).uniform(-1.0, 1.0, n)
    ld = random_loads(n, seed + 7) if loads else Loads.none(n)
    return KernelCase("straight", d.mesh, p, d.drive, ld, 0.005, u, th, lam, np.zeros(0),
                      old, inv_dt, np.full(2 * (n - 2), amp), d)


def _loop_case(layout, law, inv_dt, seed, gyro, inertia, loads, model, grid):
    """drive_flat ("loop"), its belt on SERPENTINE_BACK ("serpentine") or the shipped
    accessory drive with its tensioner's arm (a transient's: "tensioner") on 60
    elements (about 60 nodes, 26 of them in contact on drive_flat); the regularised
    laws at half the creep speed, so that the random slip velocities reach their saturated
    part. The state's sizes are a time step's: u a strain of half N0 / b1 over an element
    (the pressure stays positive), theta N0 / b1, the speeds within 1e-3 and 1e-2 of the
    creep theory's."""
    scene = (DriveScene.load(scene_path("drive_flat")) if layout == "loop"
             else DriveScene.load(scene_path("serpentine_tensioner")) if layout == "tensioner"
             else serpentine_scene(SERPENTINE_BACK))
    if law == "adhesion":
        data = scene.to_dict()
        data["contact"] = {"friction": "stick"}
        scene = DriveScene.from_dict(data)
    over = {"physics.model": model, "physics.inertia": inertia, "numerics.elements": 60,
            "numerics.gyroscopic": gyro, "numerics.integrator": "esdirk3"}
    if law in ("tanh", "sqrt"):
        over.update({"numerics.friction_law": law, "numerics.regularisation": 0.03})
    d = LoopDiscretisation(scene.with_overrides(over), grid)
    # the primal form: the kernel's Jacobian is then the residual's whole derivative
    d.model = d.model._replace(dual=0)
    rng = np.random.default_rng(seed)
    P, mesh = d.params, d.mesh
    N = len(mesh.hb)
    strain = P.N0 / P.b1
    rim = P.driver_rim_speed
    mu_, mt = 0.25 * strain * float(np.min(mesh.he)), strain
    ng = d.n_globals
    mg = np.concatenate([[rim], rim / mesh.seg_radius[d.speed_global >= 0]])
    if d.arm is not None:  # a tensioner's arm: its angle about rest, and its rate
        mg = np.append(mg, [0.05, 50.0])
    u, th = mu_ * rng.uniform(-1, 1, N), mt * rng.uniform(-1, 1, N)
    g = np.concatenate([[rim / (1.0 + strain) * (1.0 + 1e-3 * rng.uniform(-1, 1))],
                        mg[1:] * (1.0 + 1e-2 * rng.uniform(-1, 1, ng - 1))])
    if d.arm is not None:
        g[-2:] = [d.arm_rest + 0.05 * rng.uniform(-1, 1), 50.0 * rng.uniform(-1, 1)]
    lam = np.where(mesh.seg >= 0, 2.0 * rng.uniform(-1, 1, N), 0.0)
    step = INV_DT["loop"]
    old = State(u - mu_ * rng.uniform(-1, 1, N), th - mt * rng.uniform(-1, 1, N),
                np.zeros(N), step * mu_ * rng.uniform(-1, 1, N),
                step * mt * rng.uniform(-1, 1, N), np.zeros(N),
                g * (1.0 - 1e-3 * rng.uniform(-1, 1, ng)), np.zeros(ng))
    ld = random_loads(N, seed + 7) if loads else Loads.none(N)
    drive = LOOP_DRIVE if layout == "loop" else LOOP_DRIVE._replace(
        load=Profiles.constants([0.0] + [10.0 * k for k in range(1, ng)]))
    return KernelCase(layout, mesh, d.model, drive, ld, 0.3, u, th, lam, g, old,
                      inv_dt, np.concatenate([np.tile([mu_, mt], N), mg]), d)


def unknowns(case: KernelCase) -> np.ndarray:
    """The unknowns of the rows, (u, theta) interleaved, then the globals: the straight
    belt's interior nodes', all the loop's nodes'."""
    sl = slice(1, -1) if case.layout == "straight" else slice(None)
    return np.concatenate([np.column_stack([case.u[sl], case.th[sl]]).ravel(), case.g])


def with_unknowns(case: KernelCase, x) -> KernelCase:
    """The case with the unknowns x (:func:`unknowns`) in place of its own."""
    u, th = case.u.copy(), case.th.copy()
    sl = slice(1, -1) if case.layout == "straight" else slice(None)
    n = len(u[sl])
    u[sl], th[sl] = x[0:2 * n:2], x[1:2 * n:2]
    return case._replace(u=u, th=th, g=np.array(x[2 * n:]))


def kernel_residual(case: KernelCase):
    """(w, r, F): physics.model.assemble's workspace with the Jacobian, its residual (the
    rows', then the globals') and the nodal friction forces."""
    N = len(case.mesh.he)
    closed = case.layout != "straight"
    w = Workspace.allocate(N, False, closed, len(case.g))
    F = np.zeros(len(case.u))
    assemble(case.u.copy(), case.th.copy(), case.lam.copy(), case.g.copy(), F, case.old,
             case.inv_dt, case.t, case.mesh, case.p, case.drive, case.loads, w, JACOBIAN)
    return w, np.concatenate([w.R.ravel(), w.Rg]), F


def reference_residual(case: KernelCase):
    """(r, F): physics.reference's residual (the rows', then the globals') and nodal
    friction forces; an exact law's ratios are the case's lam."""
    if case.layout != "straight":
        R, Rg, F = reference.loop_residual(case.u, case.th, case.lam, case.g, case.old,
                                           case.inv_dt, case.t, case.mesh, case.p,
                                           case.drive, case.loads)
        return np.concatenate([R.ravel(), Rg]), F
    ratios = case.lam if is_exact(case.p.law) else None
    R, F = reference.residual(case.u, case.th, case.old, case.inv_dt, case.t, case.mesh,
                              case.p, case.drive, case.loads, ratios)
    return R.ravel(), F


def reference_derivative(case: KernelCase, step=1e-7):
    """Central differences of the reference's residual in the unknowns, each stepped by
    ``step`` times its magnitude (truncation and round-off ~1e-7 of a row's terms)."""
    x0 = unknowns(case)
    J = np.zeros((len(x0), len(x0)))
    for k in range(len(x0)):
        h = step * case.m[k]
        xp, xm = x0.copy(), x0.copy()
        xp[k] += h
        xm[k] -= h
        J[:, k] = (reference_residual(with_unknowns(case, xp))[0]
                   - reference_residual(with_unknowns(case, xm))[0]) / (2 * h)
    return J


def dense_jacobian(w, closed=False):
    """The whole Jacobian of a workspace (or the exact laws' saddle blocks) as a dense
    array: :func:`beltsim.solvers.linearise.jacobian_matrix`."""
    return jacobian_matrix(w, closed).toarray()


def row_terms(case: KernelCase, J, r):
    """Each row's term scale: the largest change of the row for a typical change of one
    unknown (max_k |J_ik| m_k, m_k the state's magnitude of unknown k) or the row's value,
    whichever is larger. The random old states are of a time step's size, so it is the
    size of the row's largest term, and round-off is ~1e-16 of it."""
    return np.maximum(np.max(np.abs(J) * case.m, axis=1), np.abs(r))
