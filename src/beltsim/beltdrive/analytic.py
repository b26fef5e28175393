"""Steady state of the closed drive: the extensible string (classic creep theory).

Derived in the code's frame (docs/theory/drive.md has the derivation). At steady state
the axial equation reads kappa N' = -f with kappa = 1 - rho c^2 / b1 (the string's
stretching acceleration), and the slip velocity on arc i is
v_rel = c (1 + N / b1) - omega_i R_i. With T1, T2 the tight and the slack span's
tension:

* each arc adheres at its entry (v_rel = 0, so N keeps the entry tension and f = 0):
  c (1 + T1 / b1) = omega1 R1 and omega2 R2 = c (1 + T2 / b1);
* each arc slides at its exit, where kappa N' = -+ mu (N - rho c^2) / R_i, so N - rho c^2
  is exponential and both slip arcs span phi_s = (kappa / mu) ln((T1 - rho c^2) /
  (T2 - rho c^2));
* the driven pulley's balance: M2 = R2 kappa (T1 - T2). (Not R2 (T1 - T2): the belt
  speeds up across the driven arc, and part of the tension difference goes into its
  momentum flux); the driver's torque M1 = R1 kappa (T1 - T2);
* closure: the belt's length is fixed, so the integral of N over the loop is N0 Lambda;
  with the slip arcs' exponentials integrated exactly, one scalar equation in T1.

Then speed ratio = efficiency = (b1 + T2) / (b1 + T1), slip power = kappa c dT^2 / b1
(dT = T1 - T2), and gross slip sets in when phi_s reaches the smaller wrap. Perfect
adhesion (mu -> infinity): phi_s = 0 and a concentrated force kappa dT at each arc's
exit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import NoSolutionError
from ..problem.roots import brentq
from .figures import layout_summary
from .geometry import SEGMENTS
from .params import DriveParams


class GrossSlipError(NoSolutionError):
    """The load exceeds what the drive carries: no steady state (``capacity`` in N m)."""

    def __init__(self, message: str, capacity: float):
        super().__init__(message)
        self.capacity = capacity


class LiftOffError(NoSolutionError):
    """The slack side's pressure would fall to zero: this model has no lift-off."""


@dataclass(frozen=True)
class StringSolution:
    """The string's steady state of a drive (SI units; arcs in rad)."""

    P: DriveParams
    omega1: float
    M2: float
    T1: float
    T2: float
    c: float
    phi_s: float  # slip arc of each pulley (0 for perfect adhesion)

    @property
    def kappa(self) -> float:
        """1 - rho c^2 / b1."""
        return 1.0 - self.P.rho * self.c**2 / self.P.b1

    @property
    def centrifugal(self) -> float:
        """rho c^2 (N)."""
        return self.P.rho * self.c**2

    @property
    def omega2(self) -> float:
        """The driven pulley's speed (rad/s)."""
        return self.c * (1.0 + self.T2 / self.P.b1) / self.P.geometry.R2

    @property
    def speeds(self) -> tuple[float, float]:
        """The driver's and the driven pulley's speeds (rad/s)."""
        return self.omega1, self.omega2

    @property
    def speed_ratio(self) -> float:
        """omega2 R2 / (omega1 R1) = (b1 + T2) / (b1 + T1)."""
        return (self.P.b1 + self.T2) / (self.P.b1 + self.T1)

    @property
    def driver_torque(self) -> float:
        """M1 = R1 kappa (T1 - T2) (N m)."""
        return self.P.geometry.R1 * self.kappa * (self.T1 - self.T2)

    @property
    def slip_power(self) -> float:
        """kappa c (T1 - T2)^2 / b1 (W), the friction's dissipation on both arcs."""
        return self.kappa * self.c * (self.T1 - self.T2) ** 2 / self.P.b1

    @property
    def efficiency(self) -> float:
        """M2 omega2 / (M1 omega1); equal to the speed ratio."""
        return self.M2 * self.omega2 / (self.driver_torque * self.omega1) \
            if self.M2 > 0 else 1.0

    @property
    def stick_ends(self) -> tuple[float, float]:
        """Loop coordinates where the driver's and the driven arc's slip arcs begin."""
        g = self.P.geometry
        e = g.bounds
        return e[1] - g.R1 * self.phi_s, e[3] - g.R2 * self.phi_s

    def summary(self) -> dict:
        """The drive's figures, under the run summary's names."""
        return {
            "tight_tension": self.T1, "slack_tension": self.T2, "belt_speed": self.c,
            "driven_speed": self.omega2, "speed_ratio": self.speed_ratio,
            "slip_arc_driver": self.phi_s, "slip_arc_driven": self.phi_s,
            "driver_torque": self.driver_torque, "efficiency": self.efficiency,
            "slip_power": self.slip_power,
        } | layout_summary(self.P.layout, ("driver", "driven"), self.P.rho, self.c,
                           (self.T2, self.T1), self.speeds, (self.phi_s, self.phi_s),
                           (self.driver_torque, self.M2))

    def tension(self, x) -> np.ndarray:
        """Axial force N (N) at loop coordinates x (the value downstream at a jump)."""
        P, g = self.P, self.P.geometry
        x = np.mod(np.asarray(x, dtype=float), g.loop_length)
        seg = g.segment_of(x)
        out = np.where((seg == 1), self.T2, self.T1)
        out = np.where(seg == 2, self.T2, out)
        if P.mu is not None:
            s1, s2 = self.stick_ends
            rc = self.centrifugal
            k = P.mu / self.kappa
            on = (seg == 0) & (x > s1)
            out = np.where(on, rc + (self.T1 - rc) * np.exp(-k * (x - s1) / g.R1), out)
            on = (seg == 2) & (x > s2)
            out = np.where(on, rc + (self.T2 - rc) * np.exp(k * (x - s2) / g.R2), out)
        return out

    def friction(self, x) -> np.ndarray:
        """Distributed friction f (N/m) on the belt at x (the concentrated forces of perfect
        adhesion excluded: see :attr:`concentrated`)."""
        P, g = self.P, self.P.geometry
        x = np.mod(np.asarray(x, dtype=float), g.loop_length)
        if P.mu is None:
            return np.zeros_like(x)
        seg = g.segment_of(x)
        s1, s2 = self.stick_ends
        p = (self.tension(x) - self.centrifugal) / np.where(seg == 0, g.R1, g.R2)
        out = np.where((seg == 0) & (x > s1), P.mu * p, 0.0)
        return np.where((seg == 2) & (x > s2), -P.mu * p, out)

    @property
    def concentrated(self) -> tuple[float, float]:
        """Concentrated friction forces (N) at the driver's and the driven arc's exits:
        kappa dT and -kappa dT for perfect adhesion, zero with Coulomb friction."""
        if self.P.mu is not None:
            return 0.0, 0.0
        F = self.kappa * (self.T1 - self.T2)
        return F, -F

    def pressure(self, x) -> np.ndarray:
        """Contact pressure (N - rho c^2) / R_i (N/m) on the arcs, 0 on the spans."""
        g = self.P.geometry
        seg = g.segment_of(x)
        R = np.where(seg == 0, g.R1, g.R2)
        return np.where(seg % 2 == 0, (self.tension(x) - self.centrifugal) / R, 0.0)

    def displacement(self, x) -> np.ndarray:
        """u (m) at x: the integral of (N - N0) / b1 from 0, less its mean over the loop (the
        gauge). The mean is (1 / Lambda) times the integral of (Lambda - s) eps(s)."""
        g = self.P.geometry
        lam = g.loop_length
        xs, w = _gauss_nodes(self._breakpoints())
        mean = np.sum(w * (lam - xs) * (self.tension(xs) - self.P.N0)) / (self.P.b1 * lam)
        x = np.mod(np.asarray(x, dtype=float), lam)
        return self._antiderivative(x) - mean

    def _pieces(self):
        """The tension as pieces (a, b, const, amp, rate): N = const + amp exp(rate (x - a))
        on [a, b] (rate 0: constant)."""
        g = self.P.geometry
        e = g.bounds
        rc = self.centrifugal
        if self.P.mu is None:
            s1, s2 = e[1], e[3]
        else:
            s1, s2 = self.stick_ends
        k = 0.0 if self.P.mu is None else self.P.mu / self.kappa
        return [(e[0], s1, self.T1, 0.0, 0.0),
                (s1, e[1], rc, self.T1 - rc, -k / g.R1),
                (e[1], s2, self.T2, 0.0, 0.0),
                (s2, e[3], rc, self.T2 - rc, k / g.R2),
                (e[3], e[4], self.T1, 0.0, 0.0)]

    def _antiderivative(self, x) -> np.ndarray:
        """The integral of (N - N0) / b1 from 0 to x, piece by piece in closed form."""
        flat = np.ravel(np.asarray(x, dtype=float))
        out = np.zeros_like(flat)
        for a, b, const, amp, rate in self._pieces():
            hi = np.clip(flat, a, b) - a
            part = (const - self.P.N0) * hi
            if amp != 0.0 and rate != 0.0:
                part = part + amp * np.expm1(rate * hi) / rate
            elif amp != 0.0:
                part = part + amp * hi
            out += part
        return out.reshape(np.shape(x)) / self.P.b1

    def _breakpoints(self) -> np.ndarray:
        pts = list(self.P.geometry.bounds)
        if self.P.mu is not None:
            pts += list(self.stick_ends)
        return np.unique(pts)


_GAUSS = np.polynomial.legendre.leggauss(24)


def _gauss_nodes(breaks):
    """Gauss-Legendre nodes and weights on each piece between sorted breakpoints."""
    xg, wg = _GAUSS
    xs, ws = [], []
    for a, b in zip(breaks[:-1], breaks[1:]):
        xs.append(0.5 * (b - a) * xg + 0.5 * (a + b))
        ws.append(0.5 * (b - a) * wg)
    return np.concatenate(xs), np.concatenate(ws)


def _state(P: DriveParams, omega1: float, M2: float, T1: float):
    """(c, kappa, dT, T2) of the tight tension T1."""
    R1, R2 = P.geometry.radii
    c = omega1 * R1 / (1.0 + T1 / P.b1)
    kappa = 1.0 - P.rho * c * c / P.b1
    dT = M2 / (R2 * kappa)
    return c, kappa, dT, T1 - dT


def _slip_arc(P: DriveParams, c, kappa, T1, T2) -> float:
    rc = P.rho * c * c
    if P.mu is None or T1 == T2:
        return 0.0
    return kappa / P.mu * math.log((T1 - rc) / (T2 - rc))


def _closure(P: DriveParams, c, kappa, T1, T2, phi_s) -> float:
    """Integral of N over the loop minus N0 Lambda."""
    g = P.geometry
    (phi1, phi2), (R1, R2), ls = g.wraps, g.radii, g.span
    out = T1 * (ls + R1 * (phi1 - phi_s)) + T2 * (ls + R2 * (phi2 - phi_s))
    if P.mu is not None:
        out += (R1 + R2) * (P.rho * c * c * phi_s + kappa * (T1 - T2) / P.mu)
    return out - P.N0 * g.loop_length


def _bracket(fun, hi_start):
    hi = hi_start
    for _ in range(200):
        if fun(hi) > 0:
            return hi
        hi = 2.0 * hi
    raise NoSolutionError("no bracket for the drive's steady tension")


def capacity(P: DriveParams, omega1: float | None = None) -> float:
    """The largest load torque M2 (N m) the drive carries at the driver speed omega1: the
    slip arcs then cover the smaller wrap (inf for perfect adhesion)."""
    if P.mu is None:
        return math.inf
    omega1 = P.omega1 if omega1 is None else omega1
    g = P.geometry
    phi_min = min(g.wraps)
    R1, R2 = g.radii

    def parts(T1):
        c = omega1 * R1 / (1.0 + T1 / P.b1)
        kappa = 1.0 - P.rho * c * c / P.b1
        rc = P.rho * c * c
        dT = (T1 - rc) * (1.0 - math.exp(-P.mu * phi_min / kappa))
        return c, kappa, dT

    def resid(T1):
        c, kappa, dT = parts(T1)
        return _closure(P, c, kappa, T1, T1 - dT, phi_min)

    lo = P.rho * (omega1 * R1) ** 2
    if not resid(lo) < 0:
        raise LiftOffError(f"drive.installation_tension: {P.N0:g} N leaves the belt without "
                           f"contact pressure (it lifts off) even unloaded at {omega1:g} "
                           f"rad/s (the centrifugal tension rho c^2 is about {lo:.4g} N)")
    hi = _bracket(resid, max(2.0 * P.N0, 2.0 * lo, 1.0))
    T1 = brentq(resid, lo, hi, xtol=1e-13 * hi, rtol=1e-15, maxiter=200)
    c, kappa, dT = parts(T1)
    return R2 * kappa * dT


def solve_string(P: DriveParams, omega1: float | None = None,
                 M2: float | None = None) -> StringSolution:
    """The string's steady state at driver speed omega1 and load M2 (the scene's final
    values by default).

    Raises
    ------
    GrossSlipError
        The load exceeds the drive's capacity (given in the message).
    LiftOffError
        The slack span's tension does not exceed rho c^2 (the belt would lift off).
    """
    omega1 = P.omega1 if omega1 is None else omega1
    M2 = P.M2 if M2 is None else M2
    rim = omega1 * P.geometry.R1

    def margin(T1):  # T2 - rho c^2: the slack side's pressure times R
        c, _, _, T2 = _state(P, omega1, M2, T1)
        return T2 - P.rho * c * c

    def resid(T1):
        c, kappa, dT, T2 = _state(P, omega1, M2, T1)
        return _closure(P, c, kappa, T1, T2, _slip_arc(P, c, kappa, T1, T2))

    # margin grows with T1 (c falls): below its root the slack side has no pressure
    top = _bracket(margin, max(2.0 * P.N0, P.rho * rim * rim, 1.0))
    lo = brentq(margin, 0.0, top, xtol=1e-14 * top) if margin(0.0) < 0 else 0.0
    lo_t = lo * (1 + 1e-12) + 1e-300
    if not resid(lo_t) < 0:
        raise LiftOffError(f"drive.installation_tension: {P.N0:g} N leaves the slack span "
                           f"without contact pressure at this load and speed")
    hi = _bracket(resid, max(2.0 * lo_t, 2.0 * P.N0 + M2 / P.geometry.R2, 1.0))
    T1 = brentq(resid, lo_t, hi, xtol=1e-14 * hi, rtol=1e-15, maxiter=300)
    c, kappa, dT, T2 = _state(P, omega1, M2, T1)
    phi_s = _slip_arc(P, c, kappa, T1, T2)
    if phi_s > min(P.geometry.wraps):
        cap = capacity(P, omega1)
        raise GrossSlipError(f"drive.load_torque: {M2:g} N m exceeds the drive's capacity "
                             f"{cap:.6g} N m at {omega1:g} rad/s (gross slip: no steady "
                             f"state)", cap)
    return StringSolution(P, omega1, M2, T1, T2, c, phi_s)


__all__ = ["SEGMENTS", "GrossSlipError", "LiftOffError", "StringSolution", "capacity",
           "solve_string"]


def creep_speed(P: DriveParams) -> float:
    """The slip velocities' scale omega1 R1 N0 / b1 (m/s), the creep of the pretension."""
    return P.driver_rim_speed * P.N0 / P.b1


def transit_time(P: DriveParams) -> float:
    """Lambda / (omega1 R1): how long the belt takes once round the loop (s)."""
    return P.layout.loop_length / P.driver_rim_speed
