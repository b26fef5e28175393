"""Running a closed drive: numerical settings, the steady solve, time steps from rest,
and the result with its summary and its errors against the analytic steady state."""

from __future__ import annotations

import enum
import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import NoSolutionError, NumericalError, SceneError
from ..physics.friction import EXACT, saturation
from ..problem.drive import Profile, as_profile, value
from .analytic import solve_string
from .discrete import (
    DEFAULT_ELEMENTS,
    Layout,
    creep_speed,
    law_of,
    layout_of,
    loop_mesh,
    loop_params,
    string_guess,
)
from .model import LoopMesh, Rates
from .scene import DriveParams, DriveScene
from .solver import make_system, newton, steady_rates

#: the summary's figures (the analytic solution gives the same keys)
SUMMARY_KEYS = ("tight_tension", "slack_tension", "belt_speed", "driven_speed", "speed_ratio",
                "slip_arc_driver", "slip_arc_driven", "driver_torque", "efficiency",
                "slip_power")


#: the smallest step a Newton failure may halve to, relative to numerics.dt
MIN_STEP_FRACTION = 1e-4
#: BDF2's local error per step, relative to the unknowns' scales (discrete.scales)
DEFAULT_TIME_TOL = 1e-4
#: the explicit scheme checks its state every this fraction of a transit
CHECK_INTERVAL = 0.02
#: the first step, relative to numerics.dt (the largest step)
FIRST_STEP_FRACTION = 1e-3
#: steps in a row with a whole arc sliding and the driven pulley slowing: gross slip
GROSS_SLIP_STEPS = 3


class DriveStatus(enum.Enum):
    """How a drive's run ended."""

    CONVERGED = "converged"  # steady state reached
    REACHED_END = "reached t_end"  # t_end reached before a steady state
    GROSS_SLIP = "gross slip"  # a whole arc slides and the driven pulley slows: physics
    LIFT_OFF = "lift-off"  # the contact pressure fell to zero: outside this model
    FAILED = "failed"  # a numerical failure; the state is the last good one


@dataclass(frozen=True)
class DriveNumerics:
    """A drive scene's numerical settings, every default resolved (:func:`resolve`)."""

    integrator: str
    elements: int
    friction_law: str
    regularisation: float | None
    ramp_time: float
    dt: float
    t_end: float
    steady_tol: float
    time_tol: float
    newton_tol: float
    newton_max_iterations: int


def transit_time(P: DriveParams) -> float:
    """Lambda / (omega1 R1): how long the belt takes once round the loop (s)."""
    return P.geometry.loop_length / (P.omega1 * P.geometry.R1)


def resolve(scene: DriveScene, elements: int | None = None) -> DriveNumerics:
    """The scene's numerical settings with their defaults."""
    P, nm = scene.params, scene.numerics
    law = law_of(P, nm.get("friction_law"))
    reg = None
    if law in ("tanh", "sqrt"):
        # a tenth of the creep speed: sharper ones stall the Newton iteration (the exact law
        # is the default and has no regularisation error)
        reg = nm.get("regularisation", 0.1 * creep_speed(P))
    transit = transit_time(P)
    ramp_time = nm.get("ramp_time", 2.0 * transit)
    settle = max(ramp_time, _last_table_time(scene))
    # the largest step; the steps adapt below it to the local error's time_tol
    dt = nm.get("dt", transit / 4.0)
    t_end = nm.get("t_end", settle + 40.0 * transit)
    if dt > t_end:
        raise SceneError("numerics.dt", f"must be <= numerics.t_end = {t_end!r}, got {dt!r}")
    return DriveNumerics(
        integrator=nm.get("integrator", "implicit"),
        elements=elements or nm.get("elements", DEFAULT_ELEMENTS), friction_law=law,
        regularisation=reg, ramp_time=ramp_time, dt=dt, t_end=t_end,
        steady_tol=nm.get("steady_tol", 1e-7),
        time_tol=nm.get("time_tol", DEFAULT_TIME_TOL), newton_tol=nm.get("newton_tol", 1e-10),
        newton_max_iterations=nm.get("newton_max_iterations", 40))


def _last_table_time(scene: DriveScene) -> float:
    out = 0.0
    for key in ("driver_speed", "load_torque"):
        v = scene.drive[key]
        if isinstance(v, list):
            out = max(out, v[-1][0])
    return out


def profiles(scene: DriveScene, ramp_time: float) -> tuple[Profile, Profile]:
    """The driver's rim speed omega1(t) R1 and the load M2(t) as kernel profiles: numbers
    and sines ramp from 0 over ramp_time, tables are taken as they are."""
    d = scene.drive
    R1 = scene.params.geometry.R1
    return (as_profile(d["driver_speed"], 0.0, 1.0 / R1, ramp_time),
            as_profile(d["load_torque"], 0.0, 1.0, ramp_time))


def fields_of(y, lay: Layout, mesh: LoopMesh, P: DriveParams, prm, rim1: float,
              rates=None) -> dict:
    """Nodal fields of the unknowns y: u, theta, their rates u_t, theta_t (``rates``: the
    time step's (u_t, theta_t), None at a steady state), the axial force N, friction f
    (N/m), pressure p (N/m), slip velocity v_rel (m/s), slip (bool), the friction ratio
    lam, and the bottom fibre's strain eps_b of the slip velocity's stencil."""
    u, th = lay.u(y), lay.theta(y)
    c, w2 = y[lay.c], y[lay.omega2]
    N = len(mesh.x)
    ud, td = (np.zeros(N), np.zeros(N)) if rates is None else rates
    # axial force: the upwind three-point strain (as the friction's) at every node
    idx = (np.arange(N)[:, None] + np.arange(-2, 1)[None, :]) % N
    eps = np.sum(mesh.sw * u[idx], axis=1)
    epsb = np.sum(mesh.sw * (u + prm.lever * th)[idx], axis=1)
    tension = P.N0 + P.b1 * eps
    on = mesh.lidx >= 0
    lam = np.zeros(N)
    lam[on] = lay.lam(y)[mesh.lidx[on]]
    R = np.where(on, mesh.radius, 1.0)
    p = np.where(on, (tension - P.rho * c * c) / R, 0.0)
    S = p * P.mu if P.mu is not None else np.where(on, prm.p_ref, 0.0)
    f = -S * lam
    rim = np.where(mesh.arc == 1, w2 * P.geometry.R2, rim1)
    vrel = np.where(on, c * (1.0 + P.N0 / P.b1 + epsb) + ud + prm.lever * td - rim, 0.0)
    # sliding: the ratio at the bound (exact law) or saturated (a regularised law's 0.99)
    level = 1.0 - 1e-9 if prm.law == EXACT else saturation(prm.law)
    slip = on & (np.abs(lam) >= level) if P.mu is not None else np.zeros(N, bool)
    return {"u": u.copy(), "theta": th.copy(), "u_t": ud.copy(), "theta_t": td.copy(),
            "tension": tension, "friction": f, "pressure": p, "slip_velocity": vrel,
            "slip": slip, "ratio": lam, "bottom_strain": np.where(on, epsb, 0.0)}


#: the terms of the drive's power balance (W) and its stored energy (J), see power_terms
POWER_KEYS = ("driver_power", "load_power", "slip_power", "damping_power",
              "gyroscopic_power", "transport_power", "energy")


def power_terms(y, flds: dict, cdot: float, lay: Layout, mesh: LoopMesh, P: DriveParams,
                rim1: float, load: float) -> dict:
    """The semi-discrete power balance of the loop (W) and its stored energy E (J)::

        dE/dt = driver - load - slip - damping - gyroscopic + transport

    It follows from the rows of the axial equation times (c + u_t), the bending rows times
    theta_t and the driven pulley's times omega2, summed over the loop (the gauge makes
    every sum of hbar u_t vanish): E = rho Lambda c^2 / 2 + the belt's kinetic energy of
    u_t, theta_t + B(c), A(c), b2 strain energies + J2 omega2^2 / 2; slip = -sum F v_rel;
    damping = d sum hbar (rho u_t^2 + I theta_t^2); gyroscopic = 2 c sum (rho u_t,j
    (u_t,j - u_t,j-1) + I ...), the upwind term's numerical dissipation (>= 0); transport =
    -c sum F (N0 / b1 + eps_b) - c c_t (rho sum (du)^2 / h + I sum (dtheta)^2 / h), the
    linearised model's exchange through the transported strain and the speed-dependent
    stiffnesses (zero at a steady state, to the grid's error).
    """
    c, w2 = y[lay.c], y[lay.omega2]
    F = flds["friction"] * mesh.wf
    ud, td = flds["u_t"], flds["theta_t"]
    du, dth = np.diff(np.append(flds["u"], flds["u"][0])), np.diff(
        np.append(flds["theta"], flds["theta"][0]))
    he, hb = mesh.he, mesh.hb
    M1 = P.geometry.R1 * float(np.sum(F[mesh.arc == 0]))
    strain_u, strain_t = float(np.sum(du * du / he)), float(np.sum(dth * dth / he))
    B, A = P.b1 - P.rho * c * c, P.a - P.I * c * c
    gyro = 2.0 * c * float(np.sum(P.rho * ud * (ud - np.roll(ud, 1))
                                  + P.I * td * (td - np.roll(td, 1))))
    energy = (0.5 * P.rho * P.geometry.loop_length * c * c
              + 0.5 * float(np.sum(hb * (P.rho * ud * ud + P.I * td * td)))
              + 0.5 * (B * strain_u + A * strain_t
                       + P.b2 * float(np.sum(hb * flds["theta"] ** 2)))
              + 0.5 * P.J2 * w2 * w2)
    return {
        "driver_power": M1 * rim1 / P.geometry.R1, "load_power": load * w2,
        "slip_power": float(-np.sum(F * flds["slip_velocity"])),
        "damping_power": P.damping * float(np.sum(hb * (P.rho * ud * ud + P.I * td * td))),
        "gyroscopic_power": gyro,
        "transport_power": float(-c * np.sum(F * (P.N0 / P.b1 + flds["bottom_strain"])))
        - c * cdot * (P.rho * strain_u + P.I * strain_t),
        "energy": energy,
    }


def _segment_nodes(mesh: LoopMesh, P: DriveParams):
    """Node indices of each segment's start (entry nodes of the 4 segments)."""
    return [int(np.argmin(np.abs(mesh.x - b))) for b in P.geometry.bounds[:4]]


def span_tensions(u, mesh: LoopMesh, P: DriveParams) -> tuple[float, float]:
    """Mean axial force over the tight and the slack span: N0 + b1 (u_end - u_start) / l,
    exact for the nodal values (the integral of the elements' strains)."""
    k = _segment_nodes(mesh, P)
    ls = P.geometry.span
    slack = P.N0 + P.b1 * (u[k[2]] - u[k[1]]) / ls
    tight = P.N0 + P.b1 * (u[k[0]] - u[k[3]]) / ls
    return tight, slack


def slip_arcs(flds: dict, mesh: LoopMesh, P: DriveParams) -> tuple[float, float]:
    """The slip arc of each pulley (rad): the sliding nodes' contact lengths plus the
    sliding share of the last sticking node next to them.

    A node's friction is the integral of f over its volume. With the front inside the
    volume of the last sticking node j, a share phi of it slides (ratio +-1) and the rest
    sticks with the stick zone's ratio lam_s, so lam_j = (1 - phi) lam_s + phi sign:
    phi = (lam_j - lam_s) / (sign - lam_s), with lam_s extrapolated linearly from the two
    sticking nodes upstream (zero for the string, whose stick zones carry no friction).
    The front is then located within a cell, not at its nodes.
    """
    out = []
    lam = flds["ratio"]
    N = len(mesh.x)
    for a, R in ((0, P.geometry.R1), (1, P.geometry.R2)):
        js = np.flatnonzero(mesh.arc == a)
        slip = flds["slip"][js]
        length = float(np.sum(mesh.wf[js][slip]))
        for j in (js[slip] - 1) % N:
            if mesh.arc[j] != a or flds["slip"][j]:
                continue  # not the sticking node in front of a sliding run
            sign = math.copysign(1.0, lam[(j + 1) % N])
            j1, j2 = (j - 1) % N, (j - 2) % N
            lam_s = 0.0
            if mesh.arc[j1] == a and mesh.arc[j2] == a and not (flds["slip"][j1]
                                                                 or flds["slip"][j2]):
                lam_s = 2.0 * lam[j1] - lam[j2]
            if sign != lam_s:
                phi = min(1.0, max(0.0, (lam[j] - lam_s) / (sign - lam_s)))
                length += mesh.wf[j] * phi
        out.append(length / R)
    return out[0], out[1]


def summary_of(y, flds, lay, mesh, P, load, omega1, rim1) -> dict:
    """The summary figures of a state and its fields (see SUMMARY_KEYS)."""
    c, w2 = y[lay.c], y[lay.omega2]
    T1, T2 = span_tensions(flds["u"], mesh, P)
    F = flds["friction"] * mesh.wf
    M1 = P.geometry.R1 * float(np.sum(F[mesh.arc == 0]))
    s1, s2 = slip_arcs(flds, mesh, P)
    slip_power = float(-np.sum(F * flds["slip_velocity"]))
    ratio = w2 * P.geometry.R2 / rim1 if rim1 > 0 else math.nan
    eff = load * w2 / (M1 * omega1) if M1 * omega1 > 0 and load > 0 else math.nan
    return {"tight_tension": T1, "slack_tension": T2, "belt_speed": c, "driven_speed": w2,
            "speed_ratio": ratio, "slip_arc_driver": s1, "slip_arc_driven": s2,
            "driver_torque": M1, "efficiency": eff, "slip_power": slip_power,
            "driver_power": M1 * omega1, "load_power": load * w2}


@dataclass
class DriveResult:
    """A drive run's outcome: how it ended, its final state and its history."""

    scene: DriveScene
    numerics: DriveNumerics
    status: DriveStatus
    reason: str | None
    x: np.ndarray
    fields: dict
    summary: dict
    history: dict = field(default_factory=dict)
    wall_time: float = 0.0
    statistics: dict = field(default_factory=dict)
    snapshots: dict = field(default_factory=dict)
    _analytic: object = field(default=None, repr=False, compare=False)
    _analytic_done: bool = field(default=False, repr=False, compare=False)

    @property
    def analytic(self):
        """The analytic steady state the run compares with (:func:`analytic_of`; None where
        the drive has none, e.g. beyond its capacity). Solved on first use: the beam's takes
        about as long as the discrete steady solve."""
        if not self._analytic_done:
            try:
                self._analytic = analytic_of(self.scene.params)
            except NoSolutionError:
                self._analytic = None
            self._analytic_done = True
        return self._analytic

    @property
    def converged(self) -> bool:
        """Whether the run reached a steady state."""
        return self.status is DriveStatus.CONVERGED

    def errors(self) -> dict:
        """Relative errors of the summary against the analytic steady state (speed loss
        1 - speed_ratio compared as itself; slip arcs relative to the wrap)."""
        if self.analytic is None or not self.converged:
            return {}
        ex = self.analytic.summary()
        out = {}
        keys = ["tight_tension", "slack_tension", "belt_speed", "driven_speed",
                "driver_torque"]
        if self.scene.params.mu is not None:
            # with perfect adhesion every node sticks: the exits' dissipation is not a
            # nodal slip power but the transport term's (power_terms)
            keys.append("slip_power")
        for key in keys:
            out[key] = (self.summary[key] - ex[key]) / abs(ex[key]) if ex[key] else \
                abs(self.summary[key])
        loss, loss_ex = 1.0 - self.summary["speed_ratio"], 1.0 - ex["speed_ratio"]
        out["speed_loss"] = (loss - loss_ex) / abs(loss_ex) if loss_ex else abs(loss)
        wraps = self.scene.params.geometry.wraps
        out["slip_arc_driver"] = (self.summary["slip_arc_driver"] - ex["slip_arc_driver"]) \
            / wraps[0]
        out["slip_arc_driven"] = (self.summary["slip_arc_driven"] - ex["slip_arc_driven"]) \
            / wraps[1]
        return out


def analytic_of(P: DriveParams):
    """The analytic steady state the run compares with: the string's creep solution for
    the string model, the beam's exact solution for the beam (when available)."""
    if P.model == "beam":
        try:
            from .beam import solve_beam
        except ImportError:  # pragma: no cover - until the beam's solution lands
            return solve_string(P)
        return solve_beam(P)
    return solve_string(P)


def _setup(scene, num):
    P = scene.params
    mesh = loop_mesh(P.geometry, num.elements)
    lay = layout_of(mesh)
    prm = loop_params(P, num.friction_law, num.regularisation)
    return P, mesh, lay, prm, make_system(mesh, prm, lay, P)


#: the steady solve starts a grid finer than this many times the default from the steady
#: state of a grid COARSENING times coarser (recursively)
FINE_GRID_FACTOR = 4
COARSENING = 4


def _steady_y(scene: DriveScene, num: DriveNumerics, elements: int):
    """(y, mesh, lay, prm, Newton iterations) of the discrete steady state on ``elements``.

    The semi-smooth Newton moves a slip front by about one node an iteration, so on a
    fine grid the string's front (the beam's differs by millimetres) is many iterations
    away: there the start is the steady state of a grid four times coarser, interpolated.
    """
    P = scene.params
    mesh = loop_mesh(P.geometry, elements)
    lay = layout_of(mesh)
    prm = loop_params(P, num.friction_law, num.regularisation)
    S = make_system(mesh, prm, lay, P)
    rim1 = P.omega1 * P.geometry.R1
    its = 0
    if elements > FINE_GRID_FACTOR * DEFAULT_ELEMENTS:
        yc, meshc, layc, _, its = _steady_y(scene, num, elements // COARSENING)
        y = _interpolated(yc, meshc, layc, mesh, lay, P.geometry.loop_length)
    else:
        y = string_guess(solve_string(P), mesh, lay)
        if num.regularisation is not None:
            # a regularised law from the creep scale down to its own v_reg, ten by ten:
            # from the exact law's start a sharp regularisation's Newton does not converge
            v = creep_speed(P)
            while v > 10.0 * prm.v_scale:
                S.params = prm._replace(v_scale=v)
                its += newton(S, y, steady_rates(lay.N), rim1, P.M2, num.newton_tol,
                              num.newton_max_iterations)
                v /= 10.0
            S.params = prm
    its += newton(S, y, steady_rates(lay.N), rim1, P.M2, num.newton_tol,
                  num.newton_max_iterations)
    return y, mesh, lay, prm, its


def _interpolated(yc, meshc, layc, mesh, lay, loop_length):
    """A coarse grid's unknowns on a finer grid: fields and friction ratios linear in x
    (periodic), the ratios kept within [-1, 1]; c and omega2 as they are."""
    xc = np.append(meshc.x, loop_length)

    def onto(values):
        return np.interp(mesh.x, xc, np.append(values, values[0]))

    y = np.zeros(lay.size)
    y[0:2 * lay.N:2] = onto(layc.u(yc))
    y[1:2 * lay.N:2] = onto(layc.theta(yc))
    ratio = np.zeros(layc.N)
    on = meshc.lidx >= 0
    ratio[on] = layc.lam(yc)[meshc.lidx[on]]
    fine = mesh.lidx >= 0
    lay.lam(y)[mesh.lidx[fine]] = np.clip(onto(ratio)[fine], -1.0, 1.0)
    y[lay.c], y[lay.omega2] = yc[layc.c], yc[layc.omega2]
    return y


def solve_steady(scene: DriveScene, elements: int | None = None) -> DriveResult:
    """The discrete steady state, by Newton from the string's analytic state (on fine
    grids from a coarser grid's steady state).

    Raises
    ------
    GrossSlipError, LiftOffError
        The drive has no steady state (the load exceeds its capacity, or the slack side
        lifts off).
    """
    num = resolve(scene, elements)
    P = scene.params
    start = time.perf_counter()
    y, mesh, lay, prm, its = _steady_y(scene, num, num.elements)
    wall = time.perf_counter() - start
    rim1 = P.omega1 * P.geometry.R1
    flds = fields_of(y, lay, mesh, P, prm, rim1)
    final = summary_of(y, flds, lay, mesh, P, P.M2, P.omega1, rim1)
    final.update(power_terms(y, flds, 0.0, lay, mesh, P, rim1, P.M2))
    return DriveResult(scene, num, DriveStatus.CONVERGED, None, mesh.x.copy(), flds, final,
                       wall_time=wall, statistics={"newton_iterations": its})


#: what a snapshot holds: nodal tension, friction and slip, and the two speeds
SNAPSHOT_KEYS = ("t", "tension", "friction", "slip", "belt_speed", "driven_speed")


def _snapshot(snaps: dict, t: float, flds: dict, summary: dict) -> None:
    snaps["t"].append(t)
    for k in ("tension", "friction", "slip"):
        snaps[k].append(flds[k].copy())
    snaps["belt_speed"].append(summary["belt_speed"])
    snaps["driven_speed"].append(summary["driven_speed"])


def local_error(y, pred, yscale, lay: Layout) -> float:
    """BDF2's local error from the quadratic predictor's (Milne's device: the error
    constants -2/9 and 1 give 2/11 of the difference), relative to the unknowns' scales:
    the root mean square over the fields (a front crossing a node makes a kink at that
    node only) and the belt's and the driven pulley's speeds."""
    e = np.abs(y - pred) / yscale * (2.0 / 11.0)
    nu = 2 * lay.N
    return float(max(np.sqrt(np.mean(e[:nu] ** 2)), e[lay.c], e[lay.omega2]))


def predictor(past, t):
    """The quadratic through the last three accepted states, at t (None before three)."""
    if len(past) < 3:
        return None
    (t0, y0), (t1, y1), (t2, y2) = past
    l0 = (t - t1) * (t - t2) / ((t0 - t1) * (t0 - t2))
    l1 = (t - t0) * (t - t2) / ((t1 - t0) * (t1 - t2))
    l2 = (t - t0) * (t - t1) / ((t2 - t0) * (t2 - t1))
    return l0 * y0 + l1 * y1 + l2 * y2


def profile_stops(scene: DriveScene) -> list:
    """The times of the drive's table rows: steps land on them (a load step is a kink)."""
    out = set()
    for key in ("driver_speed", "load_torque"):
        v = scene.drive[key]
        if isinstance(v, list):
            out.update(float(row[0]) for row in v)
    return sorted(out)


def bdf_coefficients(h, h_prev):
    """(a0, a1, a2) of the variable-step BDF2 derivative y'_n = a0 y_n + a1 y_n-1 +
    a2 y_n-2; backward Euler (a2 = 0) when h_prev is None."""
    if h_prev is None:
        return 1.0 / h, -1.0 / h, 0.0
    r = h / h_prev
    return (1.0 + 2.0 * r) / ((1.0 + r) * h), -(1.0 + r) / h, r * r / ((1.0 + r) * h)


class _Monitor:
    """What every time-stepping scheme does after a step: the history, the snapshots, and
    the stops (lift-off, gross slip, steady state), and the result at the end."""

    def __init__(self, scene, num, mesh, lay, P, prm, speed, load, progress,
                 snapshot_interval):
        self.scene, self.num, self.mesh, self.lay, self.P, self.prm = (scene, num, mesh, lay,
                                                                        P, prm)
        self.speed, self.load = speed, load
        self.progress, self.snapshot_interval = progress, snapshot_interval
        self.settle = max(num.ramp_time, _last_table_time(scene))
        self.hist = {k: [] for k in ("t", "omega1", "load_torque", *SUMMARY_KEYS,
                                     *POWER_KEYS)}
        self.snaps = {k: [] for k in SNAPSHOT_KEYS}
        self.next_snap = 0.0
        self.full_slip_steps = 0
        self.start = time.perf_counter()

    def check(self, t, y, ud, td, cdot, w2dot):
        """Record the state after a step at t; (status, reason) when the run must stop."""
        mesh, lay, P, num = self.mesh, self.lay, self.P, self.num
        rim1, m2 = value(self.speed, t), value(self.load, t)
        flds = fields_of(y, lay, mesh, P, self.prm, rim1, (ud, td))
        on = mesh.lidx >= 0
        if np.any(flds["pressure"][on] <= 0.0):
            j = np.flatnonzero(on & (flds["pressure"] <= 0.0))[0]
            return DriveStatus.LIFT_OFF, (
                f"t = {t:.6g} s: the contact pressure fell to zero at x = {mesh.x[j]:.4g} m "
                f"(the belt lifts off; this model does not describe lift-off)")
        sm = summary_of(y, flds, lay, mesh, P, m2, rim1 / P.geometry.R1, rim1)
        sm.update(power_terms(y, flds, cdot, lay, mesh, P, rim1, m2))
        self.hist["t"].append(t)
        self.hist["omega1"].append(rim1 / P.geometry.R1)
        self.hist["load_torque"].append(m2)
        for k in self.hist:
            if k in sm:
                self.hist[k].append(sm[k])
        if self.progress is not None:
            self.progress(t, num.t_end)
        if self.snapshot_interval and t >= self.next_snap:
            _snapshot(self.snaps, t, flds, sm)
            self.next_snap = t + self.snapshot_interval
        # gross slip: a whole arc slides while the driven pulley slows down (the load wins)
        arcs_slide = [bool(np.all(flds["slip"][mesh.arc == a])) for a in (0, 1)]
        self.full_slip_steps = self.full_slip_steps + 1 if any(arcs_slide) and w2dot < 0 \
            else 0
        if self.full_slip_steps >= GROSS_SLIP_STEPS:
            which = "driver" if arcs_slide[0] else "driven pulley"
            return DriveStatus.GROSS_SLIP, (
                f"t = {t:.6g} s: the belt slides over the {which}'s whole wrap and the "
                f"driven pulley slows down ({y[lay.omega2]:.6g} rad/s)")
        if t < self.settle:
            return None
        rate = max(abs(cdot) / rim1, abs(w2dot) * P.geometry.R2 / rim1,
                   float(np.max(np.abs(ud))) / (rim1 * P.N0 / P.b1))
        if rate * transit_time(P) < num.steady_tol:
            return DriveStatus.CONVERGED, None
        return None

    def result(self, status, reason, t, y, ud, td, cdot, statistics) -> DriveResult:
        """The run's DriveResult from its last state."""
        mesh, lay, P = self.mesh, self.lay, self.P
        wall = time.perf_counter() - self.start
        rim1, m2 = value(self.speed, t), value(self.load, t)
        flds = fields_of(y, lay, mesh, P, self.prm, rim1, (ud, td))
        final = summary_of(y, flds, lay, mesh, P, m2, rim1 / P.geometry.R1, rim1)
        final.update(power_terms(y, flds, cdot, lay, mesh, P, rim1, m2))
        if self.snapshot_interval and (not self.snaps["t"] or self.snaps["t"][-1] < t):
            _snapshot(self.snaps, t, flds, final)
        return DriveResult(self.scene, self.num, status, reason, mesh.x.copy(), flds, final,
                           history={k: np.asarray(v) for k, v in self.hist.items()},
                           snapshots={k: np.asarray(v) for k, v in self.snaps.items()},
                           wall_time=wall, statistics=statistics)


def simulate(scene: DriveScene, elements: int | None = None, progress=None,
             snapshot_interval: float | None = None) -> DriveResult:
    """Run the drive from rest (c = omega = 0, uniform N0) until the steady state, gross
    slip, lift-off or t_end: adaptive BDF2 steps (numerics.integrator = "implicit", the
    default) or the explicit scheme ("explicit"); "steady" solves the steady state alone.

    Parameters
    ----------
    scene : DriveScene
    elements : int, optional
        Stands for numerics.elements.
    progress : callable, optional
        Called as progress(t, t_end) after every step.
    snapshot_interval : float, optional
        Store the nodal tension, friction and slip every this many seconds (and the last
        state) in ``result.snapshots``, for animations.
    """
    num = resolve(scene, elements)
    if num.integrator == "steady":
        return solve_steady(scene, elements)
    P, mesh, lay, prm, S = _setup(scene, num)
    speed, load = profiles(scene, num.ramp_time)
    mon = _Monitor(scene, num, mesh, lay, P, prm, speed, load, progress, snapshot_interval)
    if num.integrator == "explicit":
        return _run_explicit(mon, prm, speed, load)
    y = np.zeros(lay.size)
    nu = 2 * lay.N
    v = v_prev = np.zeros(nu)  # rates of (u, theta) at the previous steps
    y_prev, y_prev2, v_prev2 = y.copy(), None, None
    past = [(0.0, y.copy())]  # the last accepted states, for the predictor
    h_prev = None
    t = cdot = 0.0
    dt = num.dt * FIRST_STEP_FRACTION
    stops = sorted(tt for tt in profile_stops(scene) if 0.0 < tt < num.t_end) + [num.t_end]
    yscale = S.yscale
    err_mask = np.ones(lay.size, bool)
    err_mask[2 * lay.N:2 * lay.N + lay.M] = False  # the friction ratios: no predictor
    status, reason = DriveStatus.REACHED_END, None
    steps = its_total = rejected = 0
    just_rejected = False
    while t < num.t_end - 1e-12 * num.t_end:
        stop = next(tt for tt in stops if tt > t * (1 + 1e-12))
        h = min(dt, stop - t)
        if stop - t - h < 0.05 * h:  # no sliver of a step before a table's row
            h = stop - t
        a0, a1, a2 = bdf_coefficients(h, h_prev)
        hu = a1 * y_prev[:nu] + (a2 * y_prev2[:nu] if y_prev2 is not None else 0.0)
        hv = a1 * v_prev + (a2 * v_prev2 if v_prev2 is not None else 0.0)
        hc = a1 * y_prev[lay.c] + (a2 * y_prev2[lay.c] if y_prev2 is not None else 0.0)
        h2 = a1 * y_prev[lay.omega2] + (a2 * y_prev2[lay.omega2] if y_prev2 is not None
                                        else 0.0)
        rates = Rates(a0, np.ascontiguousarray(hu[0::2]), np.ascontiguousarray(hu[1::2]),
                      np.ascontiguousarray(hv[0::2]), np.ascontiguousarray(hv[1::2]), hc, h2)
        t_new = t + h
        rim1 = value(speed, t_new)
        m2 = value(load, t_new)
        pred = predictor(past, t_new)
        y_try = y.copy()
        if pred is not None:
            y_try[err_mask] = pred[err_mask]
        try:
            its = newton(S, y_try, rates, rim1, m2, num.newton_tol, num.newton_max_iterations)
        except NumericalError as exc:
            # a step the semi-smooth Newton cannot finish is retried at half the size
            if h > num.dt * MIN_STEP_FRACTION:
                dt = 0.5 * h
                rejected += 1
                continue
            status, reason = DriveStatus.FAILED, f"t = {t_new:.6g} s: {exc}"
            break
        if pred is not None:
            # BDF2's local error from the quadratic predictor's (Milne's device: the two
            # error constants -2/9 and 1 give 2/11 of their difference)
            err = local_error(y_try, pred, yscale, lay)
            factor = 0.9 * (num.time_tol / max(err, 1e-300)) ** (1.0 / 3.0)
            if err > num.time_tol and h > num.dt * MIN_STEP_FRACTION:
                dt = h * max(0.2, factor)
                rejected += 1
                just_rejected = True
                continue
            # no growth right after a rejection: the controller would oscillate
            grow = 1.0 if just_rejected else 2.0
            dt = min(num.dt, h * min(grow, max(0.5, factor)))
            just_rejected = False
        else:
            dt = min(num.dt, 2.0 * h)
        y[:] = y_try
        past = (past + [(t_new, y.copy())])[-3:]
        its_total += its
        steps += 1
        v = a0 * y[:nu] + hu
        y_prev2, v_prev2 = y_prev, v_prev
        y_prev, v_prev = y.copy(), v
        h_prev, t = h, t_new
        cdot = a0 * y[lay.c] + hc
        w2dot = a0 * y[lay.omega2] + h2
        stop = mon.check(t, y, v[0::2], v[1::2], cdot, w2dot)
        if stop is not None:
            status, reason = stop
            break
    return mon.result(status, reason, t, y, v[0::2], v[1::2], cdot,
                      {"steps": steps, "newton_iterations": its_total,
                       "rejected_steps": rejected})


def _run_explicit(mon: _Monitor, prm, speed, load) -> DriveResult:
    """The explicit scheme (beltdrive.explicit) from rest, checked every CHECK_INTERVAL of
    a transit."""
    from .explicit import advance, explicit_law_ok, stable_step

    num, mesh, lay, P = mon.num, mon.mesh, mon.lay, mon.P
    if not P.inertia:
        raise SceneError("numerics.integrator", '"explicit" needs physics.inertia = true '
                         "(a quasistatic belt has no waves to step)")
    if not explicit_law_ok(prm.law):
        raise SceneError("numerics.friction_law", '"explicit" takes the exact laws only '
                         '(leave numerics.friction_law out, or "exact")')
    N = lay.N
    u, th, vu, vt, lam, F = (np.zeros(N) for _ in range(6))
    state = np.zeros(3)  # c, omega2, c_t
    rim_max = max(value(speed, tt) for tt in np.linspace(0.0, num.t_end, 2001))
    dt = stable_step(mesh, P, rim_max)
    chunk = max(1, int(round(CHECK_INTERVAL * transit_time(P) / dt)))
    t = 0.0
    steps = 0
    status, reason = DriveStatus.REACHED_END, None
    y = np.zeros(lay.size)
    while t < num.t_end - 0.5 * dt:
        n = min(chunk, max(1, int(round((num.t_end - t) / dt))))
        w2_old = state[1]
        t = advance(u, th, vu, vt, lam, F, state, t, dt, n, speed, load, mesh, prm,
                    P.geometry.loop_length)
        steps += n
        if not np.all(np.isfinite(state)) or not np.all(np.isfinite(u)):
            status, reason = DriveStatus.FAILED, f"t = {t:.6g} s: non-finite state"
            break
        y[0:2 * N:2], y[1:2 * N:2] = u, th
        y[2 * N:2 * N + lay.M] = lam[mesh.lidx >= 0]
        y[lay.c], y[lay.omega2] = state[0], state[1]
        w2dot = (state[1] - w2_old) / (n * dt)
        stop = mon.check(t, y, vu, vt, state[2], w2dot)
        if stop is not None:
            status, reason = stop
            break
    return mon.result(status, reason, t, y, vu, vt, state[2],
                      {"steps": steps, "dt": dt})

