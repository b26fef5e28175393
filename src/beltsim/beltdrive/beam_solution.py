"""The beam's steady state of a closed drive as a solution: its fields along the loop,
its summary, and the checks that it is one (contact pressure, slip arcs in their wraps).

Solved by :func:`beltsim.beltdrive.beam.solve_beam`.
"""

from __future__ import annotations

import numpy as np

from ..errors import NoSolutionError
from .analytic import LiftOffError
from .beam_loop import _graded, _Loop, _Seg
from .figures import layout_summary
from .params import DriveParams


class BeamSolution:
    """The beam's steady state of a drive (SI units; arcs in rad); the interface of
    :class:`~beltsim.beltdrive.analytic.StringSolution` where it applies.

    Fields take loop coordinates x (taken modulo Lambda) and give the value downstream at
    a jump.
    """

    def __init__(self, P: DriveParams, omega1: float, M2: float, loop: _Loop, z):
        self.P, self.omega1, self.M2 = P, omega1, M2
        self._loop = loop
        self._zz = np.append(z, 1.0)
        self._starts = np.array([seg.p for seg in loop.segs])
        # u at each piece's start: the integral of eps from 0
        ends = [float(loop.int_eps(i, seg.length)[0] @ self._zz)
                for i, seg in enumerate(loop.segs)]
        self._u0 = np.concatenate([[0.0], np.cumsum(ends)[:-1]])
        xq, wq = self._quadrature()
        self._u_mean = float(np.sum(wq * self._field(xq, "u"))) / P.geometry.loop_length

    # scalars -----------------------------------------------------------------------
    @property
    def c(self) -> float:
        """The belt speed c (m/s)."""
        return self._loop.c

    @property
    def lever(self) -> float:
        """The friction's lever l (m) the solution was computed with."""
        return self._loop.l

    @property
    def strain_constants(self) -> tuple[float, float]:
        """(e_1, e_2): the stick zones' eps + l theta' on the driver and the driven arc."""
        return tuple(float(self._zz[i]) for i in self._loop.ie)

    @property
    def omega2(self) -> float:
        """The driven pulley's speed (rad/s): its rim moves with the stuck belt's fibre."""
        P = self.P
        return self.c * (1.0 + P.N0 / P.b1 + self.strain_constants[1]) / P.geometry.R2

    @property
    def speed_ratio(self) -> float:
        """omega2 R2 / (omega1 R1)."""
        R1, R2 = self.P.geometry.radii
        return self.omega2 * R2 / (self.omega1 * R1)

    @property
    def stick_ends(self) -> tuple[float, float]:
        """Loop coordinates where the driver's and the driven arc's slip arcs begin (the
        arcs' exits for perfect adhesion)."""
        segs = self._loop.segs
        return segs[0].q, segs[3 if self._loop.coulomb else 2].q

    @property
    def slip_arcs(self) -> tuple[float, float]:
        """The slip arcs (rad) of the driver and the driven pulley."""
        g = self.P.geometry
        e = g.bounds
        s1, s2 = self.stick_ends
        return (e[1] - s1) / g.R1, (e[3] - s2) / g.R2

    @property
    def concentrated(self) -> tuple[float, float]:
        """Concentrated friction forces (N) at the driver's and the driven arc's exits:
        nonzero for perfect adhesion only."""
        if self._loop.coulomb:
            return 0.0, 0.0
        return tuple(float(self._zz[i]) for i in self._loop.iF)

    def _arc_force(self, arc) -> float:
        """The friction force (N) on arc 0 or 1, distributed and concentrated."""
        loop = self._loop
        total = self.concentrated[arc]
        for i, seg in enumerate(loop.segs):
            if seg.arc == arc:
                total -= loop.B * float((loop.eps(i, seg.length)[0]
                                         - loop.eps(i, 0.0)[0]) @ self._zz)
        return total

    @property
    def driver_torque(self) -> float:
        """M1 = R1 times the friction force on the driver's arc (N m)."""
        return self.P.geometry.R1 * self._arc_force(0)

    @property
    def efficiency(self) -> float:
        """M2 omega2 / (M1 omega1) (1 when unloaded)."""
        return self.M2 * self.omega2 / (self.driver_torque * self.omega1) \
            if self.M2 > 0 else 1.0

    @property
    def slip_power(self) -> float:
        """The friction's dissipation (W): minus the integral of f v_rel over the slip
        arcs, and for perfect adhesion each concentrated force times minus the mean of
        the sliding speeds on the two sides of its exit (the module docstring)."""
        loop = self._loop
        if loop.coulomb:
            total = 0.0
            for i, seg in enumerate(loop.segs):
                if seg.kind == "slip" and seg.length > 0:
                    t, w = _graded(seg)
                    rim = self._rim(seg.arc)
                    f = loop.friction(i, t) @ self._zz
                    v = loop.fibre_speed(i, t) @ self._zz - rim
                    total -= float(np.sum(w * f * v))
            return total
        total = 0.0
        for arc, i in ((0, 0), (1, 2)):
            seg = loop.segs[i]
            rim = self._rim(arc)
            before = float(loop.fibre_speed(i, seg.length)[0] @ self._zz) - rim
            after = float(loop.fibre_speed(i + 1, 0.0)[0] @ self._zz) - rim
            total -= self.concentrated[arc] * 0.5 * (before + after)
        return total

    def _rim(self, arc) -> float:
        R = self.P.geometry.radii[arc]
        return (self.omega1 if arc == 0 else self.omega2) * R

    def _span_mean(self, i) -> float:
        seg = self._loop.segs[i]
        mean_eps = float(self._loop.int_eps(i, seg.length)[0] @ self._zz) / seg.length
        return self.P.N0 + self.P.b1 * mean_eps

    @property
    def tight_tension(self) -> float:
        """The mean axial force N (N) over the tight span (constant there: no friction acts
        on a span, so B eps' = 0; theta's boundary layers at its ends leave N alone)."""
        return self._span_mean(len(self._loop.segs) - 1)

    @property
    def slack_tension(self) -> float:
        """The mean axial force N (N) over the slack span."""
        return self._span_mean(2 if self._loop.coulomb else 1)

    @property
    def speeds(self) -> tuple[float, float]:
        """The driver's and the driven pulley's speeds (rad/s)."""
        return self.omega1, self.omega2

    def summary(self) -> dict:
        """The drive's figures, under the run summary's names."""
        arcs = self.slip_arcs
        out = {
            "tight_tension": self.tight_tension, "slack_tension": self.slack_tension,
            "belt_speed": self.c, "driven_speed": self.omega2,
            "speed_ratio": self.speed_ratio, "slip_arc_driver": arcs[0],
            "slip_arc_driven": arcs[1], "driver_torque": self.driver_torque,
            "efficiency": self.efficiency, "slip_power": self.slip_power,
        }
        out = {k: float(v) for k, v in out.items()}
        return out | layout_summary(
            self.P.layout, ("driver", "driven"), self.P.rho, self.c,
            (out["slack_tension"], out["tight_tension"]), self.speeds, arcs,
            (self.driver_torque, self.M2))

    # fields ------------------------------------------------------------------------
    def _field(self, x, name):
        loop = self._loop
        x = np.asarray(x, dtype=float)
        xs = np.mod(x.ravel(), self.P.geometry.loop_length)
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
        g = self.P.geometry
        seg = g.segment_of(x)
        R = np.where(seg == 0, g.R1, g.R2)
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
        lam = self.P.geometry.loop_length
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
        loop, P, g = self._loop, self.P, self.P.geometry
        names = ("driver", "driven")
        for arc in (0, 1):
            for i, seg in enumerate(loop.segs):
                if seg.arc != arc:
                    continue
                t = np.concatenate([[0.0, seg.length], _graded(seg)[0]])
                p = loop.pressure(i, t) @ self._zz
                if not np.min(p) > 0:
                    raise LiftOffError(
                        f"drive.installation_tension: {P.N0:g} N leaves the {names[arc]} arc "
                        f"without contact pressure (min {np.min(p):.4g} N/m) at this load and "
                        f"speed: the belt would lift off, which this model does not describe")
                if not loop.coulomb:
                    continue
                f = loop.friction(i, t) @ self._zz
                if seg.kind == "stick":
                    ratio = np.max(np.abs(f) / (P.mu * p))
                    if ratio > 1.0 + 1e-9:
                        raise NoSolutionError(
                            f"beam drive: the {names[arc]} arc's stick zone needs friction "
                            f"{ratio:.6g} times mu p: the stick-then-slip layout does not "
                            f"hold")
                else:
                    v = loop.fibre_speed(i, t) @ self._zz - self._rim(arc)
                    # the creep's scale, and the round-off of v_rel as a difference of speeds
                    tol = self.c * (1e-9 * abs(np.diff(self.strain_constants)[0]) + 1e-13)
                    if np.max(seg.sign * v) > tol:
                        raise NoSolutionError(
                            f"beam drive: the belt slides along its friction on the "
                            f"{names[arc]} arc's slip arc (v_rel {np.max(seg.sign * v):.3g} "
                            f"m/s the wrong way): the stick-then-slip layout does not hold")
        if loop.coulomb:
            tol = 1e-12 * g.loop_length
            for arc, d in enumerate(self.slip_arcs):
                if not -tol <= d * g.radii[arc] <= g.arcs[arc] + tol:
                    raise NoSolutionError(f"beam drive: the {names[arc]} slip arc "
                                          f"{d:.6g} rad lies outside its wrap")


def _loop_quadrature(*sols):
    """Graded Gauss nodes over the loop, split at every piece end of the solutions."""
    breaks = np.unique(np.concatenate([[seg.p for seg in s._loop.segs] + [
        s.P.geometry.loop_length] for s in sols]))
    k = max(s._loop.alpha for s in sols) + max(s._loop.beta for s in sols)
    xs, ws = [], []
    for a, b in zip(breaks[:-1], breaks[1:]):
        if b > a:
            t, w = _graded(_Seg(a, b, "span", -1, k))
            xs.append(a + t)
            ws.append(w)
    return np.concatenate(xs), np.concatenate(ws)
