"""A closed drive's discrete state read as a solution: nodal fields along the loop, the
drive's figures (span tensions, speeds, slip arcs, torque, efficiency, powers) and the
errors against the exact steady state.

:class:`LoopSolution` is to a loop what
:class:`~beltsim.simulation.solution.DiscreteSolution` is to the open layout: the run
loop, the result, the writer and the plots read both through the same attributes
(``x``, ``fields()``, ``summary()``, ``errors()``, ``monitor``).
"""

from __future__ import annotations

import math

import numpy as np

from ..beltdrive.figures import figure_keys, layout_summary
from ..physics.arm import element_stretches, stencil_stretch
from ..physics.friction import EXACT, saturation
from ..physics.model import POWER_TERMS, power_terms, traction
from ..problem.drive import value, value_at
from ..problem.roots import RTOL, brentq

#: the drive's figures (the exact solutions give the same keys)
SUMMARY_KEYS = ("tight_tension", "slack_tension", "belt_speed", "driven_speed", "speed_ratio",
                "slip_arc_driver", "slip_arc_driven", "driver_torque", "efficiency",
                "slip_power")
#: the terms of the loop's power balance (W) and its stored energy (J)
POWER_KEYS = ("driver_power", "load_power", "damping_power", "gyroscopic_power",
              "transport_power", "energy")
#: nodal fields of fields.csv, after x
FIELD_KEYS = ("u", "theta", "tension", "friction", "pressure", "slip_velocity", "slip")
#: what a history records at every check (a two-pulley drive's)
HISTORY_KEYS = ("t", "omega1", "load_torque", *SUMMARY_KEYS, *POWER_KEYS)
#: the figures of every layout, scalars (each span's and each pulley's are in
#: ``spans`` and ``pulleys``, and under the names of :func:`~beltsim.beltdrive.figures.figure_keys`)
LOOP_KEYS = ("belt_speed", "driver_torque", "efficiency", "slip_power")
#: the errors of every layout against its exact steady state (:meth:`LoopSolution.errors`)
LOOP_ERROR_KEYS = ("span_tension", "speed_loss", "slip_arc", "hub_load", "belt_speed",
                   "driver_torque")


def stick_rate(alpha: float, h: float) -> float:
    """The growth rate (1/m) of the discrete stick mode on cells of length h: the grid's
    stick zone grows by r = exp(kappa h) from node to node, r + 1/r = 2 + (alpha h)^2
    (theta's central second difference), so kappa = (2 / h) asinh(alpha h / 2), alpha
    to O(alpha^3 h^2) and below alpha on cells wider than the layer 1/alpha."""
    return 2.0 / h * math.asinh(0.5 * alpha * h) if alpha > 0 else 0.0


def stick_mode(kappa: float, d, values) -> tuple[float, float, float]:
    """(kappa, P, Q): the stick zone's ratio P exp(kappa s) + Q exp(-kappa s) (s from the
    node in front) through ``values`` at the offsets ``d`` (two, upstream, < 0); a
    straight line through them where kappa is 0 (no lever: the string)."""
    (d1, d2), (v1, v2) = d, values
    if kappa == 0.0:
        slope = (v1 - v2) / (d1 - d2)
        return 0.0, v1 - slope * d1, slope
    M = np.array([[math.exp(kappa * d1), math.exp(-kappa * d1)],
                  [math.exp(kappa * d2), math.exp(-kappa * d2)]])
    P, Q = np.linalg.solve(M, [v1, v2])
    return kappa, float(P), float(Q)


def _stick_integral(stick, lo: float, s: float) -> float:
    """The integral of the stick mode (:func:`stick_mode`) over [lo, s]."""
    kappa, P, Q = stick
    if kappa == 0.0:
        return P * (s - lo) + 0.5 * Q * (s * s - lo * lo)
    return (P * (math.exp(kappa * s) - math.exp(kappa * lo))
            - Q * (math.exp(-kappa * s) - math.exp(-kappa * lo))) / kappa


def _value(stick, s: float) -> float:
    """The stick mode (:func:`stick_mode`) at s."""
    kappa, P, Q = stick
    if kappa == 0.0:
        return P + Q * s
    return P * math.exp(kappa * s) + Q * math.exp(-kappa * s)


def _bisect(fun, a: float, b: float) -> float:
    """The root of fun on [a, b] (fun(a), fun(b) of opposite signs), to round-off: by
    Brent's method, which needs some ten calls of fun where halving the interval to
    round-off takes sixty (a drive's history reads the slip arcs at every check)."""
    return brentq(fun, a, b, xtol=RTOL * max(abs(a), abs(b), 1e-300), maxiter=200)


def front_in_volume(stick, total: float, sign: float, lo: float, hi: float) -> float:
    """Where in the volume [lo, hi] (about its node) the slip arc starts: the s at which
    the stick ratio's integral over [lo, s] plus ``sign`` (hi - s) is ``total`` (the
    node's ratio times its volume), clamped to the volume.

    The stick ratio is the stick mode (:func:`stick_mode`) up to where it would reach
    the Coulomb bound ``sign``, which a sticking point cannot pass: on cells wider than
    the layer the grid's mode grows many times over a cell (a mode at the bound where
    the volume begins carries no stick share). Below the bound the residual falls
    monotonically, so bisection finds its one root.
    """
    cut = hi
    if sign * _value(stick, lo) >= 1.0:  # a mode at the bound already: no stick share
        stick = (0.0, 0.0, 0.0)
    elif sign * _value(stick, hi) > 1.0:  # the mode reaches the bound inside the volume
        cut = _bisect(lambda s: sign * _value(stick, s) - 1.0, lo, hi)

    def excess(s):
        s = min(s, cut)
        return _stick_integral(stick, lo, s) + sign * (hi - s) - total

    ea, eb = excess(lo), excess(cut)
    if ea * eb >= 0.0:  # no front inside (or at an end): the end nearer a root
        return lo if abs(ea) <= abs(eb) else cut
    return _bisect(excess, lo, cut)


def history_keys(P) -> tuple[str, ...]:
    """What a history records at every check: the two-pulley keys for a two-pulley
    drive, else the driver's speed, LOOP_KEYS,
    :func:`~beltsim.beltdrive.figures.figure_keys` and the powers."""
    if P.two_pulley:
        return HISTORY_KEYS
    arm = ("arm_angle", "arm_travel") if P.tensioner is not None else ()
    return ("t", "omega1", *LOOP_KEYS, *figure_keys(P.layout.names), *arm, *POWER_KEYS)


class MeshIndices:
    """What every reading of a loop's state on one mesh indexes with: the strain
    stencil's nodes, the contact nodes with their radii and each arc's nodes (a run reads
    its state at every check; these depend on the mesh alone)."""

    def __init__(self, mesh):
        N = len(mesh.seg)
        self.stencil = (np.arange(N)[:, None] + np.arange(-2, 1)[None, :]) % N
        self.on = mesh.seg >= 0
        self.radius = np.where(self.on, mesh.seg_radius[np.maximum(mesh.seg, 0)], 1.0)
        self.arcs = [np.flatnonzero(mesh.seg == a) for a in range(len(mesh.seg_radius))]


def indices_of(disc) -> MeshIndices:
    """The :class:`MeshIndices` of a discretisation's mesh, made at its first reading."""
    ix = disc.__dict__.get("_loop_indices")
    if ix is None or ix.mesh is not disc.mesh:
        ix = MeshIndices(disc.mesh)
        ix.mesh = disc.mesh
        disc._loop_indices = ix
    return ix


class LoopSolution:
    """A loop's state at time t read as the drive's solution.

    Parameters
    ----------
    disc : beltsim.solvers.base.LoopDiscretisation
        The drive on its grid.
    state : beltsim.physics.discrete.State
        The state (copied).
    t : float or None
        Its time, for the drive's profiles (None: a steady state, the final values).
    """

    model = "drive"

    def __init__(self, disc, state, t=None):
        self.params = disc.params
        self.disc = disc
        self.mesh = m = disc.mesh
        self.numerics = disc.numerics
        self.x = disc.grid.x.copy()
        self.wf = m.wf
        self.state = state.copy()
        drive = disc.steady_drive() if t is None else disc.drive
        self.rim1 = value(drive.speed, t or 0.0)
        #: each free pulley's load torque (N m) at this time, by its global
        self.loads = np.array([value_at(drive.load, k, t or 0.0)
                               for k in range(disc.n_globals)])
        self.load = self.loads[1]
        # the kernel's power terms of the rows: slip, damping, gyroscopic
        terms = np.zeros(len(POWER_TERMS))
        power_terms(state, t or 0.0, disc.mesh, disc.model, drive, disc.loads, terms)
        self._terms = dict(zip(POWER_TERMS, terms))
        self.c, self.omega2 = float(state.g[0]), float(state.g[1])
        self.cdot = float(state.gd[0])
        self.omega2_rate = float(state.gd[1])
        rd = self.params.pulleys[self.params.driver].radius
        #: each pulley's speed (rad/s): the driver's prescribed, the others' unknowns
        self.speeds = np.array([self.rim1 / rd if k < 0 else float(state.g[k])
                                for k in disc.speed_global])
        self._ix = indices_of(disc)
        self._torques = None
        self._fields = self._read(disc.model)

    def _read(self, prm) -> dict:
        P, m, s, ix = self.params, self.mesh, self.state, self._ix
        N = len(self.x)
        idx = ix.stencil
        lever = prm.half_height * m.face  # the face in contact's (per node)
        # axial force: the upwind three-point strain (the friction's) at every node
        stretch = stencil_stretch(m, s.g)  # a tensioner's spans' (physics.arm)
        eps = np.sum(m.sw * s.u[idx], axis=1) + stretch
        epsb = np.sum(m.sw * (s.u[idx] + lever[:, None] * s.theta[idx]), axis=1) + stretch
        tension = P.N0 + P.b1 * eps
        on, R = ix.on, ix.radius
        p = np.where(on, (tension - P.rho * self.c**2) / R, 0.0)
        f = traction(s.fnode, m.wf)
        rim = np.where(on, self.speeds[np.maximum(m.seg, 0)] * R, 0.0)
        vrel = np.where(on, self.c * (1.0 + P.N0 / P.b1 + epsb) + s.ud + lever * s.td - rim,
                        0.0)
        # sliding: the ratio at the bound (exact law) or saturated (a regularised law)
        level = 1.0 - 1e-9 if prm.law == EXACT else saturation(prm.law)
        slip = on & (np.abs(s.lam) >= level) if P.mu is not None else np.zeros(N, bool)
        return {"u": s.u.copy(), "theta": s.theta.copy(), "u_t": s.ud.copy(),
                "theta_t": s.td.copy(), "tension": tension, "friction": f, "pressure": p,
                "slip_velocity": vrel, "slip": slip, "ratio": s.lam.copy(),
                "bottom_strain": np.where(on, epsb, 0.0)}

    # fields ---------------------------------------------------------
    def fields(self) -> dict:
        """The nodal fields of fields.csv (FIELD_KEYS), one value a node."""
        return {k: self._fields[k] for k in FIELD_KEYS}

    @property
    def all_fields(self) -> dict:
        """Every nodal field: FIELD_KEYS and u_t, theta_t, the friction ratio and the
        bottom fibre's strain."""
        return dict(self._fields)

    # figures --------------------------------------------------------
    def span_tensions(self) -> np.ndarray:
        """Each span's mean axial force (N), in the belt's order (span i from pulley i to
        i + 1): N0 + b1 (u_end - u_start) / l, exact for the nodal values (the integral of
        the elements' strains)."""
        P, u, first = self.params, self.state.u, self.disc.grid.first
        n = len(u)
        spans = P.layout.spans
        stretch = np.concatenate([[0.0], np.cumsum(element_stretches(self.mesh, self.state.g)
                                                   * self.mesh.he)])
        return np.array([P.N0 + P.b1 * (u[first[2 * i + 2] % n] - u[first[2 * i + 1]]
                                        + stretch[first[2 * i + 2]]
                                        - stretch[first[2 * i + 1]]) / spans[i]
                         for i in range(len(spans))])

    def slip_arcs(self) -> tuple[float, ...]:
        """The slip arc of each pulley (rad): the sliding nodes' contact lengths plus the
        sliding share of the last sticking node in front of them.

        A node's friction is the integral of f over its volume. With the front x* inside
        the volume [a, b] of the last sticking node j, its ratio is lam_j (b - a) = (the
        integral of the stick zone's ratio over [a, x*]) + sign (b - x*), solved for x*
        (:func:`front_in_volume`). The stick zone's ratio is the beam's stick mode: the
        two exponentials of theta'' = alpha^2 theta (f = B l theta'' in stick) through
        the two sticking nodes upstream, at the grid's own rate (:func:`stick_rate`).
        The stick layer is about 1/alpha wide (3 mm on the shipped drives: a few cells
        or a fraction of one), and a straight line through those nodes would miss its
        growth across node j's volume by about (alpha h)^2 of the ratio (0.1 of a cell
        at alpha h = 0.36). The string's stick zones carry no friction.
        """
        m, f, P = self.mesh, self._fields, self.params
        lam, slide = f["ratio"], f["slip"]
        N = len(self.x)
        x, he = self.x, m.he
        lever = P.lever
        B, A = P.b1 - P.rho * self.c**2, P.a - P.I * self.c**2
        alpha = math.sqrt(P.b2 / (A + lever * lever * B)) if lever > 0 and A > 0 else 0.0
        out = []
        for a, js in enumerate(self._ix.arcs):
            length = float(np.sum(m.wf[js][slide[js]]))
            for j in (js[slide[js]] - 1) % N:
                if m.seg[j] != a or slide[j]:
                    continue  # not the sticking node in front of a sliding run
                sign = math.copysign(1.0, lam[(j + 1) % N])
                j1, j2 = (j - 1) % N, (j - 2) % N
                hi = 0.5 * he[j]
                lo = hi - m.wf[j]  # node j's volume about x_j
                if m.seg[j1] == a and m.seg[j2] == a and not (slide[j1] or slide[j2]):
                    d1 = -((x[j] - x[j1]) % m.loop_length)
                    d2 = d1 - (x[j1] - x[j2]) % m.loop_length
                    stick = stick_mode(stick_rate(alpha, he[j1]), (d1, d2),
                                       (lam[j1], lam[j2]))
                else:
                    stick = (0.0, 0.0, 0.0)
                start = front_in_volume(stick, lam[j] * (hi - lo), sign, lo, hi)
                length += hi - start
            out.append(length / m.seg_radius[a])
        return out

    def torques(self) -> np.ndarray:
        """The torque (N m) the driver puts into the belt and each other pulley takes out
        of it: r times the friction on its arc, signed so that both are positive in a
        driving drive."""
        if self._torques is None:
            F, m, arcs = self.state.fnode, self.mesh, self._ix.arcs
            self._torques = np.array([(1.0 if k < 0 else -1.0) * m.seg_radius[a]
                                      * float(np.sum(F[arcs[a]]))
                                      for a, k in enumerate(self.disc.speed_global)])
        return self._torques.copy()

    def driver_torque(self) -> float:
        """The driver's torque: r_d (the friction on its arc) (N m)."""
        return float(self.torques()[self.params.driver])

    @property
    def monitor(self) -> float:
        """The quantity whose change over a transit the steady test watches: the driver's
        torque (N m)."""
        return self.driver_torque()

    def power_terms(self) -> dict:
        """The semi-discrete power balance of the loop (W) and its stored energy E (J)::

            dE/dt = driver - load - slip - damping - gyroscopic + transport

        It follows from the rows of the axial equation times (c + u_t), the bending rows
        times theta_t and the driven pulley's times omega2, summed over the loop (the
        gauge makes every sum of hbar u_t vanish): E = rho Lambda c^2 / 2 + the belt's
        kinetic energy of u_t, theta_t + B(c), A(c), b2 strain energies + J2 omega2^2 /
        2; slip = -sum F v_rel; damping = d sum hbar (rho u_t^2 + I theta_t^2);
        gyroscopic: the gyroscopic term's work, the upwind form's numerical dissipation
        (>= 0); transport = -c sum F (N0 / b1 + eps_b) - c c_t (rho sum (du)^2 / h + I
        sum (dtheta)^2 / h), the linearised model's exchange through the transported
        strain and the speed-dependent stiffnesses (zero at a steady state, to the
        grid's error).
        """
        P, m, f = self.params, self.mesh, self._fields
        c = self.c
        F = self.state.fnode
        ud, td = f["u_t"], f["theta_t"]
        du = np.diff(np.append(f["u"], f["u"][0]))
        dth = np.diff(np.append(f["theta"], f["theta"][0]))
        he, hb = m.he, m.hb
        strain_u, strain_t = float(np.sum(du * du / he)), float(np.sum(dth * dth / he))
        B, A = P.b1 - P.rho * c * c, P.a - P.I * c * c
        g = self.state.g
        energy = (0.5 * P.rho * P.layout.loop_length * c * c
                  + 0.5 * float(np.sum(hb * (P.rho * ud * ud + P.I * td * td)))
                  + 0.5 * (B * strain_u + A * strain_t
                           + P.b2 * float(np.sum(hb * f["theta"] ** 2)))
                  + 0.5 * float(np.sum(m.inertia[1:] * g[1:] ** 2)))
        return {
            "driver_power": self.driver_torque() * self.speeds[P.driver],
            "load_power": float(np.sum(self.loads[1:] * g[1:])),
            "damping_power": float(self._terms["damping"]),
            "gyroscopic_power": float(self._terms["gyroscopic"]),
            "transport_power": float(-c * np.sum(F * (P.N0 / P.b1 + f["bottom_strain"])))
            - c * self.cdot * (P.rho * strain_u + P.I * strain_t),
            "energy": energy,
        }

    def arm_figures(self) -> dict:
        """A tensioner's ``arm_angle`` and ``arm_travel`` (rad): the layout's, turned by
        the arm's global angle in a transient."""
        P, m = self.params, self.mesh
        out = P.arm_figures()
        if m.arm_idx.shape[0]:
            beta = float(self.state.g[m.arm_idx[0]])
            out["arm_travel"] += beta
            out["arm_angle"] += P.tensioner.arm(P.layout)[2] * beta
        return out

    def summary(self, path: bool = False) -> dict:
        """The drive's figures: LOOP_KEYS, ``spans`` (a list in the belt's order of
        {from, to, tension}), ``pulleys`` (a list of {name, role, speed, slip_arc, wrap,
        torque, hub_load [Fx, Fy]}), each span's and pulley's figures under
        :func:`~beltsim.beltdrive.figures.figure_keys`' names, the power terms, a
        tensioner's ``arm_angle`` and ``arm_travel`` (and where its arm moves
        ``grid_arm_travel``, the travel of the layout x is laid on), a two-pulley drive's
        SUMMARY_KEYS
        and, with ``path``, the driver's speed and the load of this time."""
        P = self.params
        T = self.span_tensions()
        torques = self.torques()
        arcs = self.slip_arcs()
        speeds = self.speeds
        d = P.driver
        delivered = float(np.sum(self.loads[1:] * self.state.g[1:]))
        inp = torques[d] * speeds[d]
        eff = delivered / inp if inp > 0 and delivered > 0 else math.nan
        out = {"belt_speed": self.c, "driver_torque": float(torques[d]), "efficiency": eff,
               "slip_power": float(self._terms["slip"]),
               **layout_summary(P.layout, P.roles, P.rho, self.c, T, speeds, arcs,
                                torques),
               **self.arm_figures()}
        if self.mesh.arm_idx.shape[0]:  # the arm moves: the turn of the grid's layout
            out["grid_arm_travel"] = P.arm_turn
        if P.two_pulley:
            ratio = self.omega2 * P.geometry.R2 / self.rim1 if self.rim1 > 0 else math.nan
            out.update({"tight_tension": float(T[1]), "slack_tension": float(T[0]),
                        "driven_speed": self.omega2, "speed_ratio": ratio,
                        "slip_arc_driver": arcs[0], "slip_arc_driven": arcs[1]})
        out.update(self.power_terms())
        if path:
            out.update(omega1=float(speeds[d]), load_torque=self.load)
        return out

    def snapshot_arrays(self, snaps: dict) -> dict:
        """What snapshots.npz holds of a run's snapshots: u, theta, the traction, the
        axial force and the sliding nodes (times, nodes), the belt's and the driven
        pulley's speeds and the globals (times) and, where a tensioner's arm moves, its
        ``arm_travel`` (times; rad from the drawn angle) and ``grid_arm_travel`` (the
        turn of the layout the grid is laid on)."""
        from ..physics.discrete import State

        out = {k: [] for k in ("u", "theta", "friction", "tension", "slip", "belt_speed",
                               "driven_speed", "globals")}
        N = len(self.x)
        for i in range(len(snaps["t"])):
            st = State(snaps["u"][i], snaps["theta"][i], snaps["lam"][i], np.zeros(N),
                       np.zeros(N), snaps["fnode"][i], snaps["g"][i],
                       np.zeros(len(snaps["g"][i])))
            f = LoopSolution(self.disc, st, snaps["t"][i])._fields
            for k in ("u", "theta", "friction", "tension", "slip"):
                out[k].append(f[k])
            out["belt_speed"].append(st.g[0])
            out["driven_speed"].append(st.g[1])
            out["globals"].append(st.g)
        out = {k: np.array(v) for k, v in out.items()}
        if self.mesh.arm_idx.shape[0]:
            # the arm's travel from its drawn angle, and the grid's (the layout of x)
            out["arm_travel"] = self.params.arm_turn + out["globals"][:, self.mesh.arm_idx[0]]
            out["grid_arm_travel"] = np.array(self.params.arm_turn)
        return out

    # outcomes ---------------------------------------------------------
    def lift_off(self) -> str | None:
        """Why the state is outside the model (a contact pressure <= 0), or None."""
        on = self.mesh.seg >= 0
        p = self._fields["pressure"]
        bad = np.flatnonzero(on & (p <= 0.0))
        if bad.size == 0:
            return None
        return (f"the contact pressure fell to zero at x = {self.x[bad[0]]:.4g} m (the belt "
                f"lifts off; this model does not describe lift-off)")

    def sliding_arc(self) -> str | None:
        """The name of a pulley whose whole wrap slides, or None."""
        slide = self._fields["slip"]
        for a, p in enumerate(self.params.pulleys):
            if np.all(slide[self._ix.arcs[a]]):
                return p.name
        return None

    # errors -----------------------------------------------------------
    def errors(self, ref) -> dict:
        """Errors of the figures against the exact steady state ``ref``: LOOP_ERROR_KEYS
        (the largest over the spans or pulleys: tensions and hub loads relative to the
        largest span tension, speed losses 1 - omega r / (omega_d r_d) relative to the
        largest, slip arcs relative to the wrap) and, for a two-pulley drive, its figures
        one by one (relative; slip arcs over the wrap); with a tensioner, ``arm_travel``
        (rad, absolute)."""
        mine, ex = self.summary(), ref.summary()
        P = self.params
        scale = max(s["tension"] for s in ex["spans"])
        out = {"span_tension": max(abs(a["tension"] - b["tension"]) / scale
                                   for a, b in zip(mine["spans"], ex["spans"])),
               "hub_load": max(math.dist(a["hub_load"], b["hub_load"]) / scale
                               for a, b in zip(mine["pulleys"], ex["pulleys"]))}
        rim = P.driver_rim_speed
        loss = [1.0 - p["speed"] * q.radius / rim for p, q in zip(mine["pulleys"], P.pulleys)]
        loss_ex = [1.0 - p["speed"] * q.radius / rim for p, q in zip(ex["pulleys"], P.pulleys)]
        top = max(abs(v) for v in loss_ex)
        out["speed_loss"] = (max(abs(a - b) for a, b in zip(loss, loss_ex)) / top if top
                             else max(abs(v) for v in loss))
        out["slip_arc"] = max(abs(a["slip_arc"] - b["slip_arc"]) / a["wrap"]
                              for a, b in zip(mine["pulleys"], ex["pulleys"]))
        for key in ("belt_speed", "driver_torque"):
            out[key] = (mine[key] - ex[key]) / abs(ex[key]) if ex[key] else abs(mine[key])
        if P.tensioner is not None:  # rad, absolute: the drawn angle is the travel's 0
            out["arm_travel"] = mine["arm_travel"] - ex["arm_travel"]
        if not P.two_pulley:
            return out
        keys = ["tight_tension", "slack_tension", "driven_speed"]
        if self.params.mu is not None:
            # with perfect adhesion every node sticks: the exits' dissipation is not a
            # nodal slip power but the transport term's (power_terms)
            keys.append("slip_power")
        for key in keys:
            out[key] = ((mine[key] - ex[key]) / abs(ex[key]) if ex[key] else abs(mine[key]))
        loss, loss_ex = 1.0 - mine["speed_ratio"], 1.0 - ex["speed_ratio"]
        out["speed_loss"] = (loss - loss_ex) / abs(loss_ex) if loss_ex else abs(loss)
        wraps = self.params.geometry.wraps
        out["slip_arc_driver"] = (mine["slip_arc_driver"] - ex["slip_arc_driver"]) / wraps[0]
        out["slip_arc_driven"] = (mine["slip_arc_driven"] - ex["slip_arc_driven"]) / wraps[1]
        return out
