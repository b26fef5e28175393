"""The beam's steady state of a closed drive as a solution: its fields along the loop,
its summary, and the checks that it is one (contact pressure, slip arcs in their wraps).

Solved by :func:`beltsim.beltdrive.beam.solve_beam`.
"""

from __future__ import annotations

import numpy as np

from ..errors import NoSolutionError
from .analytic import LiftOffError
from .beam_loop import _frame, _graded, _Loop, _Seg
from .figures import hub_loads, layout_summary
from .params import DriveParams


class BeamSolution:
    """The beam's steady state of a drive on N pulleys (SI units; arcs in rad); the
    interface of :class:`~beltsim.beltdrive.creep.SerpentineSolution` (and for two
    pulleys of :class:`~beltsim.beltdrive.analytic.StringSolution`) where it applies.

    ``loads`` are the pulleys' load torques M_i (N m, the driver's entry ignored).
    Fields take loop coordinates x (taken modulo Lambda) and give the value downstream at
    a jump.
    """

    def __init__(self, P: DriveParams, omega1: float, loads, loop: _Loop, z):
        self.P, self.omega1 = P, omega1
        self.loads = np.asarray(loads, dtype=float)
        self._loop = loop
        self._zz = np.append(z, 1.0)
        self._starts = np.array([seg.p for seg in loop.segs])
        # u at each piece's start: the integral of eps from 0
        ends = [float(loop.int_eps(i, seg.length)[0] @ self._zz)
                for i, seg in enumerate(loop.segs)]
        self._u0 = np.concatenate([[0.0], np.cumsum(ends)[:-1]])
        xq, wq = self._quadrature()
        self._u_mean = float(np.sum(wq * self._field(xq, "u"))) / self._loop.loop_length

    # scalars -----------------------------------------------------------------------
    @property
    def c(self) -> float:
        """The belt speed c (m/s)."""
        return self._loop.c

    @property
    def M2(self) -> float:
        """The driven pulley's load (two-pulley drives, N m)."""
        return float(self.loads[1])

    @property
    def lever(self) -> float:
        """The friction's lever l (m) the solution was computed with (on the belt's
        inner face; -l on a back-side pulley's arc)."""
        return self._loop.l

    @property
    def layout(self):
        """The layout solved (with a tensioner's arm at the drive's angle)."""
        return self.P.layout

    @property
    def arm_travel(self) -> float | None:
        """The tensioner arm's turn into the belt from its drawn angle (rad), None
        without a tensioner (the creep solution's property of the same name)."""
        return None if self.P.tensioner is None else self.P.arm_turn

    @property
    def strain_constants(self) -> tuple[float, ...]:
        """Each arc's e_i: its stick zone's eps + l_i theta'."""
        return tuple(float(self._zz[i]) for i in self._loop.ie)

    @property
    def speeds(self) -> np.ndarray:
        """Each pulley's speed (rad/s), its rim moving with the stuck belt's contact
        fibre c (1 + N0/b1 + e_i); the driver's is omega1."""
        P = self.P
        out = self.c * (1.0 + P.N0 / P.b1 + np.array(self.strain_constants)) / self._loop.radii
        out[P.driver] = self.omega1
        return out

    @property
    def omega2(self) -> float:
        """The driven pulley's speed (two-pulley drives, rad/s)."""
        return float(self.speeds[1])

    @property
    def speed_ratio(self) -> float:
        """omega2 R2 / (omega1 R1) (two-pulley drives)."""
        R1, R2 = self._loop.radii
        return self.omega2 * R2 / (self.omega1 * R1)

    @property
    def stick_ends(self) -> tuple[float, ...]:
        """Loop coordinates where each arc's slip arc begins (its exit for perfect
        adhesion)."""
        return tuple(seg.q for seg in self._loop.segs if seg.kind == "stick")

    @property
    def slip_arcs(self) -> tuple[float, ...]:
        """Each pulley's slip arc (rad), its length whichever way it slips."""
        loop = self._loop
        exits = loop.bounds[1::2]
        return tuple(float((exits[i] - s) / loop.radii[i])
                     for i, s in enumerate(self.stick_ends))

    @property
    def slip_signs(self) -> tuple[float, ...]:
        """The sign of each arc's friction on its slip arc (+1 along the motion, as on
        the driver; 0 for perfect adhesion)."""
        return tuple(seg.sign for seg in self._loop.segs if seg.kind == "slip") \
            if self._loop.coulomb else (0.0,) * len(self.P.layout)

    @property
    def concentrated(self) -> tuple[float, ...]:
        """Concentrated friction forces (N) at each arc's exit: nonzero for perfect
        adhesion only."""
        if self._loop.coulomb:
            return (0.0,) * len(self.P.layout)
        return tuple(float(self._zz[i]) for i in self._loop.iF)

    def _arc_force(self, arc) -> float:
        """The friction force (N) on ``arc``, distributed and concentrated."""
        return float(self._loop.arc_force(arc) @ self._zz)

    @property
    def arc_torques(self) -> np.ndarray:
        """R_i times the friction's resultant on each arc (N m): what each pulley puts
        into the belt (the driver's > 0, a loaded pulley's -M_i, an idler's 0)."""
        return np.array([self._arc_force(i) for i in range(len(self.P.layout))]) \
            * self._loop.radii

    @property
    def torques(self) -> np.ndarray:
        """Each pulley's torque (N m) as the creep theory reports them: the driver's
        supplied, each other one's consumed (its load; 0 at idlers)."""
        out = -self.arc_torques
        out[self.P.driver] *= -1.0
        return out

    @property
    def driver_torque(self) -> float:
        """M_d = R_d times the friction force on the driver's arc (N m)."""
        return float(self.arc_torques[self.P.driver])

    @property
    def efficiency(self) -> float:
        """sum_i M_i omega_i / (M_d omega_d) (1 when unloaded)."""
        rest = np.arange(len(self.loads)) != self.P.driver
        out = float(np.dot(self.loads[rest], self.speeds[rest]))
        return out / (self.driver_torque * self.omega1) if out > 0 else 1.0

    @property
    def slip_powers(self) -> np.ndarray:
        """The friction's dissipation on each arc (W): minus the integral of f v_rel
        over its slip arc, and for perfect adhesion its exit's concentrated force times
        minus the mean of the sliding speeds on the two sides of the exit (the module
        docstring of :mod:`beltsim.beltdrive.beam`)."""
        loop = self._loop
        out = np.zeros(len(self.P.layout))
        for i, seg in enumerate(loop.segs):
            if loop.coulomb and seg.kind == "slip" and seg.length > 0:
                t, w = _graded(seg)
                f = loop.friction(i, t) @ self._zz
                v = loop.fibre_speed(i, t) @ self._zz - self._rim(seg.arc)
                out[seg.arc] -= float(np.sum(w * f * v))
            elif not loop.coulomb and seg.kind == "stick":
                rim = self._rim(seg.arc)
                before = float(loop.fibre_speed(i, seg.length)[0] @ self._zz) - rim
                after = float(loop.fibre_speed(i + 1, 0.0, seg.lever)[0] @ self._zz) - rim
                out[seg.arc] -= self.concentrated[seg.arc] * 0.5 * (before + after)
        return out

    @property
    def slip_power(self) -> float:
        """The friction's total dissipation (W)."""
        return float(self.slip_powers.sum())

    def _rim(self, arc) -> float:
        return float(self.speeds[arc] * self._loop.radii[arc])

    def _span_mean(self, i) -> float:
        seg = self._loop.segs[i]
        mean_eps = float(self._loop.int_eps(i, seg.length)[0] @ self._zz) / seg.length
        return self.P.N0 + self.P.b1 * mean_eps

    @property
    def tensions(self) -> np.ndarray:
        """Each span's axial force N (N), span j from pulley j to j + 1: its mean,
        constant there (no friction acts on a span, so B eps' = 0; theta's boundary
        layers at its ends leave N alone)."""
        return np.array([self._span_mean(i) for i, seg in enumerate(self._loop.segs)
                         if seg.kind == "span"])

    @property
    def tight_tension(self) -> float:
        """The tight span's N (two-pulley drives: the span into the driver)."""
        return self._span_mean(len(self._loop.segs) - 1)

    @property
    def slack_tension(self) -> float:
        """The slack span's N (two-pulley drives: the span out of the driver)."""
        return self._span_mean(2 if self._loop.coulomb else 1)

    @property
    def hub_loads(self) -> np.ndarray:
        """The belt's force on each pulley's bearing (N, rows (Fx, Fy)), from the span
        tensions as the creep theory and a run's summary take it
        (:func:`~beltsim.beltdrive.figures.hub_loads`)."""
        return hub_loads(self.P.layout, self.P.rho, self.c, self.tensions)

    def summary(self) -> dict:
        """The drive's figures, under the run summary's names: the spans' and pulleys'
        (:func:`~beltsim.beltdrive.figures.layout_summary`), the totals, a tensioner's
        arm and, on two pulleys, the two-pulley drive's own figures."""
        P = self.P
        out = {"belt_speed": self.c, "driver_torque": self.driver_torque,
               "efficiency": self.efficiency, "slip_power": self.slip_power}
        arcs = self.slip_arcs
        if P.two_pulley:
            out |= {"tight_tension": self.tight_tension,
                    "slack_tension": self.slack_tension, "driven_speed": self.omega2,
                    "speed_ratio": self.speed_ratio, "slip_arc_driver": arcs[0],
                    "slip_arc_driven": arcs[1]}
        out = {k: float(v) for k, v in out.items()}
        out |= layout_summary(P.layout, P.roles, P.rho, self.c, self.tensions,
                              self.speeds, arcs, self.torques,
                              **({} if P.two_pulley else {"slip_power": self.slip_powers}))
        return out | P.arm_figures()

    # fields ------------------------------------------------------------------------
    def _field(self, x, name):
        loop = self._loop
        x = np.asarray(x, dtype=float)
        xs = np.mod(x.ravel(), self._loop.loop_length)
        idx = np.clip(np.searchsorted(self._starts, xs, side="right") - 1, 0,
                      len(loop.segs) - 1)
        out = np.zeros_like(xs)
        for i, seg in enumerate(loop.segs):
            on = idx == i
            if not np.any(on):
                continue
            t = xs[on] - seg.p
            if name == "u":
                out[on] = self._u0[i] + loop.int_eps(i, t) @ self._zz
            elif name == "theta":
                out[on] = loop.theta(i, t) @ self._zz
            elif name == "dtheta":
                out[on] = loop.theta(i, t, 1) @ self._zz
            elif name == "eps":
                out[on] = loop.eps(i, t) @ self._zz
            elif name == "friction":
                out[on] = loop.friction(i, t) @ self._zz
            elif name == "v_rel":
                out[on] = (loop.fibre_speed(i, t) @ self._zz - self._rim(seg.arc)
                           if seg.arc >= 0 else 0.0)
        return out.reshape(x.shape)

    def strain(self, x) -> np.ndarray:
        """eps = u_x at x."""
        return self._field(x, "eps")

    def tension(self, x) -> np.ndarray:
        """The axial force N = N0 + b1 eps (N) at x."""
        return self.P.N0 + self.P.b1 * self._field(x, "eps")

    def friction(self, x) -> np.ndarray:
        """Distributed friction f (N/m) on the belt at x (the concentrated forces of
        perfect adhesion excluded: see :attr:`concentrated`)."""
        return self._field(x, "friction")

    def pressure(self, x) -> np.ndarray:
        """Contact pressure (N - rho c^2) / R_i (N/m) on the arcs, 0 on the spans."""
        seg = _frame(self.P).segment_of(x)
        R = self._loop.radii[seg // 2]
        return np.where(seg % 2 == 0, (self.tension(x) - self._loop.rc) / R, 0.0)

    def theta(self, x) -> np.ndarray:
        """The cross-section's rotation theta (rad) at x."""
        return self._field(x, "theta")

    def moment(self, x) -> np.ndarray:
        """A theta' = (a - I c^2) theta' (N m) at x: the moment flux that is continuous
        across the Coulomb solution's interfaces (a theta' is the elastic moment)."""
        return self._loop.A * self._field(x, "dtheta")

    def slip_velocity(self, x) -> np.ndarray:
        """v_rel = c (1 + N0/b1 + eps + l theta') - omega_i R_i (m/s) on the arcs, 0 on
        the spans (no rim there)."""
        return self._field(x, "v_rel")

    def displacement(self, x) -> np.ndarray:
        """u (m) at x: the integral of eps from 0, less its mean over the loop (the gauge)."""
        return self._field(x, "u") - self._u_mean

    def grid(self, n: int = 400) -> np.ndarray:
        """Sorted loop coordinates that resolve every boundary layer: n even points and
        the graded quadrature's nodes."""
        lam = self._loop.loop_length
        return np.unique(np.concatenate([np.linspace(0.0, lam, n, endpoint=False),
                                         self._quadrature()[0]]))

    def _quadrature(self):
        """Nodes and weights over the loop, graded towards every piece's ends."""
        xs, ws = [], []
        for seg in self._loop.segs:
            if seg.length > 0:
                t, w = _graded(seg)
                xs.append(seg.p + t)
                ws.append(w)
        return np.concatenate(xs), np.concatenate(ws)

    # admissibility -----------------------------------------------------------------
    def _check(self):
        """Raise where the solution breaks its model: no contact pressure, a slip arc
        outside its wrap, friction above mu p in a stick zone or sliding along f."""
        loop, P, lay = self._loop, self.P, self.P.layout
        names = [f"{r} pulley {n!r}" for r, n in zip(P.roles, lay.names)]
        # the creep's scale, and the round-off of v_rel as a difference of speeds
        tol = self.c * (1e-9 * float(np.ptp(self.strain_constants)) + 1e-13)
        for i, seg in enumerate(loop.segs):
            arc = seg.arc
            if arc < 0:
                continue
            t = np.concatenate([[0.0, seg.length], _graded(seg)[0]])
            p = loop.pressure(i, t) @ self._zz
            if not np.min(p) > 0:
                raise LiftOffError(
                    f"drive.installation_tension: {P.N0:g} N leaves the {names[arc]}'s arc "
                    f"without contact pressure (min {np.min(p):.4g} N/m) at this load and "
                    f"speed: the belt would lift off, which this model does not describe")
            if not loop.coulomb:
                continue
            f = loop.friction(i, t) @ self._zz
            if seg.kind == "stick":
                ratio = np.max(np.abs(f) / (P.mus[arc] * p))
                if ratio > 1.0 + 1e-9:
                    raise NoSolutionError(
                        f"beam drive: the {names[arc]}'s stick zone needs friction "
                        f"{ratio:.6g} times mu p: the stick-then-slip layout does not hold")
            else:
                v = loop.fibre_speed(i, t) @ self._zz - self._rim(arc)
                if np.max(seg.sign * v) > tol:
                    raise NoSolutionError(
                        f"beam drive: the belt slides along its friction on the "
                        f"{names[arc]}'s slip arc (v_rel {np.max(seg.sign * v):.3g} m/s "
                        f"the wrong way): the stick-then-slip layout does not hold")
        if loop.coulomb:
            slack = 1e-12 * lay.loop_length
            for arc, d in enumerate(self.slip_arcs):
                if not -slack <= d * loop.radii[arc] <= loop.arcs[arc] + slack:
                    raise NoSolutionError(f"beam drive: the {names[arc]}'s slip arc "
                                          f"{d:.6g} rad lies outside its wrap")


def _loop_quadrature(*sols):
    """Graded Gauss nodes over the loop, split at every piece end of the solutions."""
    breaks = np.unique(np.concatenate([[seg.p for seg in s._loop.segs] + [
        s._loop.loop_length] for s in sols]))
    k = max(s._loop.alpha for s in sols) + max(s._loop.beta for s in sols)
    xs, ws = [], []
    for a, b in zip(breaks[:-1], breaks[1:]):
        if b > a:
            t, w = _graded(_Seg(a, b, "span", -1, k))
            xs.append(a + t)
            ws.append(w)
    return np.concatenate(xs), np.concatenate(ws)
