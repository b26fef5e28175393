"""What a run reads off its state, layout by layout: the solution, the rate and the
quantity the steady test watches, the history's keys, a periodic drive's comparisons,
the snapshots' arrays, the physical outcomes and the exact steady state.

The run loop (:mod:`beltsim.simulation.controller`) and its trackers read every layout
through a :class:`Readout`; :func:`readout_of` picks the layout's.
"""

from __future__ import annotations

import numpy as np

from ..errors import NoSolutionError
from ..problem.drive import mismatch as mismatch_at
from ..problem.drive import period_of
from .loop_solution import LoopSolution, figure_keys, history_keys
from .result import RunStatus, reference_of
from .solution import DiscreteReference, DiscreteSolution

#: checks in a row with a whole wrap sliding and the driven pulley slowing: gross slip
GROSS_SLIP_CHECKS = 3


class Readout:
    """The open layout's (the paper's belt): total friction, slip start or concentrated
    force, against the exact steady solution of the paper."""

    #: what snapshots store of the state (arrays over the nodes)
    snapshot_keys = ("u", "theta", "fnode")
    #: the errors a study reports, of :meth:`beltsim.RunResult.errors`
    #: (relative; slip start in m)
    error_keys = ("total_friction", "u", "theta", "concentrated_force", "slip_start")

    def __init__(self, disc):
        self.disc = disc
        P = disc.params
        self.model = "stick" if P.friction == "stick" else "slip"
        split = {"slip": ("slip_start", "stick_friction", "slip_friction", "slip_power"),
                 "stick": ("concentrated_force",)}
        self.history_keys = ("t", "total_friction", "rate", *split[self.model])
        #: the monitor's scale: its changes are measured against at least this
        self.monitor_scale = P.B * disc.scales.theta * 1e-3
        second = "slip_start" if self.model == "slip" else "concentrated_force"
        #: a periodic drive's quantities: the first two compared between periods, the
        #: second relative to ``second_scale`` (None: the first's scale)
        self.periodic_keys = ("total_friction", second) + (
            ("slip_power",) if self.model == "slip" else ())
        self.second_scale = P.L if self.model == "slip" else None

    def solution(self, state, t: float, transient: bool):
        """The state read as a solution (a steady solve's: the final drive's)."""
        d, n = self.disc, self.disc.numerics
        mismatch = mismatch_at(d.drive, t) if transient else None
        return DiscreteSolution(d.params, d.grid, state.u, state.theta, state.fnode,
                                n.law_code, n.friction_scale, state.ud, state.td, mismatch,
                                (d.mesh.c0, d.mesh.wf, d.mesh.sw))

    def monitor(self, state) -> float:
        """The total friction (N): what the steady test watches."""
        return float(state.fnode.sum())

    def rate(self, state) -> float:
        """Largest local rate, relative to c abs(e0) (per unit length for theta)."""
        P, s = self.disc.params, self.disc.scales
        v = P.c * s.theta
        return float(max(np.max(np.abs(state.ud)), P.L * np.max(np.abs(state.td))) / v)

    def outcome(self, sim):
        """A physical outcome that ends the run, as (status, reason), or None."""
        return None

    def reference(self):
        """The exact steady solution of the scene, or None."""
        return self.exact(self.disc.scene)

    @staticmethod
    def exact(scene):
        """The exact steady solution of a scene of this layout, or None."""
        return reference_of(scene)

    @staticmethod
    def discrete_reference(solution):
        """A discrete steady state of this layout as the reference of another state on the
        same grid."""
        return DiscreteReference(solution)


class LoopReadout(Readout):
    """A closed drive's: the driver's torque, the span tensions, the speeds and slip arcs,
    against the creep theory (string) or the beam's exact steady state; lift-off and
    gross slip end a run as outcomes."""

    snapshot_keys = ("u", "theta", "fnode", "lam", "g")
    error_keys = ("tight_tension", "slack_tension", "speed_loss", "slip_arc_driver",
                  "slip_arc_driven")

    def __init__(self, disc):
        self.disc = disc
        P = disc.params
        self.model = "drive"
        keys = history_keys(P)
        self.history_keys = keys[:1] + ("rate",) + keys[1:]
        rd = P.pulleys[P.driver].radius
        self.monitor_scale = 1e-3 * P.N0 * rd
        if P.two_pulley:
            self.periodic_keys = ("driver_torque", "driven_speed", "tight_tension",
                                  "slack_tension", "belt_speed")
            self.second_scale = P.omega1 * rd / P.geometry.R2
        else:
            # the first free pulley's speed second, over the driver's speed ratio
            first = next(p for p in P.pulleys if p.role != "driver")
            # the first free pulley's speed is compared between periods; every span's
            # tension and every pulley's speed is reported over the last one
            keys = figure_keys(P.layout.names)
            speeds = [f"speed[{p.name}]" for p in P.pulleys if p.role != "driver"]
            self.periodic_keys = ("driver_torque", *speeds, "belt_speed",
                                  *(k for k in keys if k.startswith("tension[")))
            self.second_scale = P.driver_rim_speed / first.radius
        #: each global's speed scale: the rim speed, and its radius for a pulley's
        radii = np.array([1.0] + [p.radius for p in P.pulleys if p.role != "driver"])
        if disc.arm is not None:
            # the arm's pulley moves at a beta' (over the creep speed, as u's rate) and
            # accelerates at a beta'' (over the rim speed, as the pulleys')
            a = P.tensioner.arm(P.layout)[0]
            radii = np.append(radii, [a * P.b1 / P.N0, a])
            self.periodic_keys = (*self.periodic_keys, "arm_travel")
        self._radii = radii
        self._sliding = 0

    def solution(self, state, t: float, transient: bool):
        """The state read as the drive's solution (with the profiles' values at t in a
        transient)."""
        return LoopSolution(self.disc, state, t if transient else None)

    def monitor(self, state) -> float:
        """The driver's torque (N m)."""
        m, P = self.disc.mesh, self.disc.params
        d = P.driver
        return P.pulleys[d].radius * float(np.sum(state.fnode[m.seg == d]))

    def rate(self, state) -> float:
        """The largest rate of the belt's and the pulleys' speeds and of u, each over its
        scale (the rim speed, the creep speed) times the transit time."""
        P = self.disc.params
        rim = P.driver_rim_speed
        creep = rim * P.N0 / P.b1
        return float(max(np.max(np.abs(state.gd) * self._radii) / rim,
                         np.max(np.abs(state.ud)) / creep) * self.disc.window)

    def outcome(self, sim):
        """Lift-off, or gross slip: a whole wrap slides while a pulley slows,
        GROSS_SLIP_CHECKS checks in a row; under a periodic drive, after its ramp, a whole
        wrap that slides at every check of two whole periods (a wrap that slides for part
        of each period is the periodic state's, not an end)."""
        sol = sim.solution()
        why = sol.lift_off()
        if why is not None:
            return RunStatus.LIFT_OFF, f"t = {sim.t:.6g} s: {why}"
        which = sol.sliding_arc()
        samples = getattr(sim.steady, "samples", None)
        if samples is None:
            slowing = np.any(sim.state.gd[1:] < 0)
            self._sliding = self._sliding + 1 if which and slowing else 0
            if self._sliding >= GROSS_SLIP_CHECKS:
                return RunStatus.GROSS_SLIP, (
                    f"t = {sim.t:.6g} s: gross slip at {which}: the belt slides over its "
                    f"whole wrap and a pulley slows down")
            return None
        # a periodic drive's speeds rise and fall each period, and its start-up may slide
        # for a while: after the ramp, a whole wrap sliding through two whole periods
        on = which is not None and sim.t >= sim.steady.t_min
        self._sliding = self._sliding + 1 if on else 0
        if self._sliding >= 2 * samples:
            return RunStatus.GROSS_SLIP, (
                f"t = {sim.t:.6g} s: gross slip at {which}: the belt slides over its "
                f"whole wrap through two whole periods of the drive")
        return None

    @staticmethod
    def exact(scene):
        """The drive's exact steady state (the string's or the beam's, as the scene's
        model), or None: a periodic drive, or a load beyond the capacity."""
        from ..beltdrive.exact import exact_state

        if period_of(scene) is not None:
            return None  # a periodic drive never settles
        P = scene.params
        try:
            return exact_state(P)
        except NoSolutionError:
            return None


    @staticmethod
    def discrete_reference(solution):
        """A drive's discrete steady state: its own summary is what another's errors
        compare with (:meth:`~beltsim.simulation.loop_solution.LoopSolution.errors`)."""
        return solution


def readout_class(closed: bool) -> type[Readout]:
    """The readout of the open layout or of a loop (``closed``)."""
    return LoopReadout if closed else Readout


def readout_of(disc) -> Readout:
    """The readout of a discretisation's layout."""
    return readout_class(disc.closed)(disc)
