"""Steady state of a belt on N pulleys: the extensible string's creep theory.

The two-pulley theory of :mod:`beltsim.beltdrive.analytic`, carried to a serpentine
layout (:mod:`beltsim.beltdrive.pulleys`). Material order 0 -> span 0 -> 1 -> ... ->
span N-1 -> 0; T_j is span j's tension; on arc i the belt enters at T_in = T_(i-1) and
leaves at T_out = T_i. With kappa = 1 - rho c^2 / b1 (the string's stretching
acceleration):

* every arc adheres at its entry, omega_i r_i = c (1 + T_in / b1): the driver's fixes c;
* integrating kappa N' = -f over an arc, the friction's resultant is kappa (T_out - T_in),
  so a driven pulley consuming M_i raises the tension by M_i / (r_i kappa), an idler
  leaves it, and the driver lowers it by the sum of the others; the driver's torque
  r_d kappa (T_in - T_out) = r_d sum_i M_i / r_i (the factors kappa cancel);
* each loaded arc slips at its exit, where kappa N' = -+ mu (N - rho c^2) / r, so
  N - rho c^2 is exponential in the angle there and the slip arc spans
  phi_s = (kappa / mu) |ln((T_out - rho c^2) / (T_in - rho c^2))|; the stick part keeps
  the entry tension. Perfect adhesion: phi_s = 0 and a jump at the exit;
* closure: the integral of N over the loop is b1 (Lambda - L0), L0 = Lambda0 (1 - N0 / b1)
  the belt's unstretched length (Lambda0 the layout as drawn). With the exponentials
  integrated exactly, each arc contributes r [T_in (wrap - phi_s) + rho c^2 phi_s
  + kappa |T_out - T_in| / mu].

Taking the driver's entry tension T_e as the unknown makes c, kappa and every other
tension explicit in it (c = omega_d r_d / (1 + T_e / b1)), so the coupling through
kappa(c) costs nothing: the closure is one scalar root in T_e, as in analytic.py.

Friction power on arc i: f times the slip velocity c (N - T_in) / b1, with f = -kappa N',
integrates to kappa c (T_out - T_in)^2 / (2 b1), whether the jump is spread over a slip
arc or concentrated (perfect adhesion). Summed round the loop this equals the driver's
power less the delivered power exactly (the tensions' squares telescope).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import NoSolutionError, SceneError
from ..problem.roots import brentq
from .analytic import GrossSlipError, LiftOffError
from .figures import hub_loads, layout_summary
from .params import DriveParams
from .pulleys import PulleyLayout
from .tensioner import Tensioner, equilibrium


@dataclass(frozen=True)
class SerpentineData:
    """A serpentine drive's data (SI units).

    ``mu`` is None for perfect adhesion, else one friction coefficient per pulley (a
    scalar applies to all); ``loads`` holds M_i >= 0 per pulley (0 for idlers and for the
    driver, whose torque is an output); ``omega`` is the driver's speed in the belt's
    running sense; ``N0`` the installation tension with the layout as drawn.
    """

    layout: PulleyLayout
    b1: float
    rho: float
    mu: tuple[float, ...] | float | None
    N0: float
    driver: int
    omega: float
    loads: tuple[float, ...]
    tensioner: Tensioner | None = None

    def __post_init__(self):
        n = len(self.layout)
        for key, v in (("b1", self.b1), ("N0", self.N0), ("omega", self.omega)):
            if not (math.isfinite(v) and v > 0):
                raise SceneError(f"serpentine.{key}", f"must be > 0, got {v!r}")
        if not (math.isfinite(self.rho) and self.rho >= 0):
            raise SceneError("serpentine.rho", f"must be >= 0, got {self.rho!r}")
        if not (isinstance(self.driver, int) and 0 <= self.driver < n):
            raise SceneError("serpentine.driver", f"must be a pulley index 0..{n - 1}")
        loads = tuple(float(m) for m in self.loads)
        if len(loads) != n or not all(math.isfinite(m) and m >= 0 for m in loads):
            raise SceneError("serpentine.loads", f"must be {n} torques >= 0 (N m)")
        if loads[self.driver] != 0:
            raise SceneError("serpentine.loads", "the driver's entry must be 0 (its torque "
                             "is an output)")
        object.__setattr__(self, "loads", loads)
        if self.mu is not None:
            mu = (self.mu,) * n if np.isscalar(self.mu) else tuple(self.mu)
            if len(mu) != n or not all(math.isfinite(m) and m > 0 for m in mu):
                raise SceneError("serpentine.mu", f"must be None or {n} coefficients > 0")
            object.__setattr__(self, "mu", tuple(float(m) for m in mu))
        t = self.tensioner
        if t is not None:
            if not (isinstance(t.index, int) and 0 <= t.index < n) or t.index == self.driver \
                    or loads[t.index] != 0:
                raise SceneError("serpentine.tensioner.index", "must be an idler's index")
            if not (math.isfinite(t.stiffness) and t.stiffness >= 0):
                raise SceneError("serpentine.tensioner.stiffness", "must be >= 0 (N m/rad)")
            if math.dist(t.pivot, self.layout.centres[t.index]) == 0:
                raise SceneError("serpentine.tensioner.pivot", "must differ from the "
                                 "idler's centre (the arm has no length)")

    @property
    def unstretched_length(self) -> float:
        """L0 = Lambda0 (1 - N0 / b1) (m), Lambda0 the drawn layout's loop length."""
        return self.layout.loop_length * (1.0 - self.N0 / self.b1)


def serpentine_data(P: DriveParams) -> SerpentineData:
    """The creep theory's data of a drive (its final speeds and loads; the layout as
    drawn, with a tensioner's arm at its drawn angle)."""
    if P.tensioner is not None and P.arm_turn:
        P = P.at_arm(-P.arm_turn)
    return SerpentineData(layout=P.layout, b1=P.b1, rho=P.rho,
                          mu=None if P.mu is None else P.mus, N0=P.N0,
                          driver=P.driver, omega=P.omega1,
                          loads=tuple(p.final_load for p in P.pulleys),
                          tensioner=P.tensioner)


def _tensions(d: SerpentineData, layout: PulleyLayout, loads, Te):
    """(c, kappa, T) of the driver's entry tension Te: T[j] span j's tension."""
    n = len(layout)
    r_d = layout.radii[d.driver]
    c = d.omega * r_d / (1.0 + Te / d.b1)
    kappa = 1.0 - d.rho * c * c / d.b1
    rise = np.asarray(loads) / (layout.radii * kappa)
    rise[d.driver] = -rise.sum()
    T = np.empty(n)
    for k in range(n):  # from the driver's exit round to its entry
        i = (d.driver + k) % n
        T[i] = (Te if k == 0 else T[i - 1]) + rise[i]
    return c, kappa, T


def _slip_arcs(d: SerpentineData, c, kappa, T) -> np.ndarray:
    """phi_s per pulley (0 at idlers and with perfect adhesion; inf past lift-off)."""
    if d.mu is None:
        return np.zeros(len(T))
    rc = d.rho * c * c
    Tin = np.roll(T, 1)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = (T - rc) / (Tin - rc)
        phi = kappa / np.asarray(d.mu) * np.abs(np.log(ratio))
    phi = np.where((T - rc > 0) & (Tin - rc > 0), phi, np.inf)
    return np.where(T == Tin, 0.0, phi)


def _closure(d: SerpentineData, layout: PulleyLayout, c, kappa, T, phi) -> float:
    """Integral of N over the loop less b1 (Lambda - L0)."""
    rc = d.rho * c * c
    Tin = np.roll(T, 1)
    arcs = Tin * (layout.wraps - phi)
    if d.mu is not None:
        arcs = arcs + rc * phi + kappa * np.abs(T - Tin) / np.asarray(d.mu)
    stretch = d.b1 * (layout.loop_length - d.layout.loop_length) + d.N0 * d.layout.loop_length
    return float(np.dot(T, layout.spans) + np.dot(layout.radii, arcs) - stretch)


def _bracket(fun, start):
    hi = start
    for _ in range(200):
        if fun(hi) > 0:
            return hi
        hi *= 2.0
    raise NoSolutionError("no bracket for the serpentine drive's steady tension")


def _solve_raw(d: SerpentineData, layout: PulleyLayout, loads):
    """(c, kappa, T, phi) closing the loop; LiftOffError when no span keeps pressure.
    Slip arcs beyond their wraps are not refused here (capacity searches pass them)."""
    def state(Te):
        c, kappa, T = _tensions(d, layout, loads, Te)
        return c, kappa, T, _slip_arcs(d, c, kappa, T)

    def margin(Te):  # the slackest span's N - rho c^2: grows with Te (c and jumps fall)
        c, _, T = _tensions(d, layout, loads, Te)
        return T.min() - d.rho * c * c

    def resid(Te):
        return _closure(d, layout, *state(Te))

    rim = d.omega * layout.radii[d.driver]
    top = _bracket(margin, max(2.0 * d.N0, d.rho * rim * rim, 1.0))
    lo = brentq(margin, 0.0, top, xtol=1e-14 * top) if margin(0.0) < 0 else 0.0
    lo_t = lo * (1 + 1e-12) + 1e-300
    if not resid(lo_t) < 0:
        c, _, T = _tensions(d, layout, loads, lo_t)
        j = int(np.argmin(T))
        nm = layout.names
        raise LiftOffError(f"span {nm[j]!r}->{nm[(j + 1) % len(nm)]!r}: its tension would "
                           f"fall to rho c^2 = {d.rho * c * c:.4g} N or below (lift-off): "
                           f"installation tension {d.N0:g} N too low for this load")
    hi = _bracket(resid, max(2.0 * lo_t, 2.0 * d.N0 + sum(loads) / layout.radii.min(), 1.0))
    Te = brentq(resid, lo_t, hi, xtol=1e-14 * hi, rtol=1e-15, maxiter=300)
    return state(Te)


def _load_factor(d: SerpentineData, layout: PulleyLayout, i: int, scale_all: bool) -> float:
    """The factor on pulley i's load (all loads if scale_all) at which i's slip arc
    reaches its wrap; other pulleys' slip arcs are not limited. A lift-off met first
    caps the factor there."""
    base = np.asarray(d.loads, dtype=float)

    def g(lam):
        loads = base * lam if scale_all else base.copy()
        if not scale_all:
            loads[i] *= lam
        try:
            return _solve_raw(d, layout, loads)[3][i] - layout.wraps[i]
        except LiftOffError:
            return math.inf

    lo, hi = 1.0, 1.0
    if g(1.0) < 0:
        while g(hi) < 0:
            lo, hi = hi, 2.0 * hi
            if hi > 1e12:
                return math.inf
    else:
        while g(lo) >= 0:
            hi, lo = lo, 0.5 * lo
    return brentq(lambda lam: min(g(lam), 1e3), lo, hi, xtol=1e-13 * hi, rtol=1e-13)


@dataclass(frozen=True, eq=False)  # arrays inside: identity, not elementwise ==
class SerpentineSolution:
    """The string's steady state on a serpentine layout (SI units; arcs in rad).

    ``layout`` is the layout solved (the tensioner's arm at ``alpha``), ``tensions`` the
    span tensions T_j, ``phi_s`` each pulley's slip arc at its exit.
    """

    data: SerpentineData
    layout: PulleyLayout
    c: float
    tensions: np.ndarray
    phi_s: np.ndarray
    alpha: float | None = None
    alpha_drawn: float | None = None
    sense_tensioner: int | None = None
    _cache: dict = field(default_factory=dict, repr=False, compare=False)

    @property
    def kappa(self) -> float:
        """1 - rho c^2 / b1."""
        return 1.0 - self.data.rho * self.c**2 / self.data.b1

    @property
    def centrifugal(self) -> float:
        """rho c^2 (N)."""
        return self.data.rho * self.c**2

    @property
    def entry_tensions(self) -> np.ndarray:
        """T_in per pulley: the arriving span's tension."""
        return np.roll(self.tensions, 1)

    @property
    def roles(self) -> tuple[str, ...]:
        """'driver', 'driven', 'tensioner' or 'idler' per pulley."""
        t = self.data.tensioner
        out = []
        for i, m in enumerate(self.data.loads):
            out.append("driver" if i == self.data.driver else "driven" if m > 0
                       else "tensioner" if t is not None and t.index == i else "idler")
        return tuple(out)

    @property
    def speeds(self) -> np.ndarray:
        """omega_i = c (1 + T_in / b1) / r_i (rad/s), in each pulley's running sense
        (``layout.spin``: +1 counterclockwise)."""
        return self.c * (1.0 + self.entry_tensions / self.data.b1) / self.layout.radii

    @property
    def torques(self) -> np.ndarray:
        """Each pulley's torque (N m) in its running sense: the driver's supplied
        r_d kappa (T_in - T_out), the loads M_i consumed, 0 at idlers."""
        out = np.asarray(self.data.loads, dtype=float).copy()
        d = self.data.driver
        out[d] = self.layout.radii[d] * self.kappa * (self.entry_tensions[d] - self.tensions[d])
        return out

    @property
    def driver_torque(self) -> float:
        """r_d sum_i M_i / r_i (N m)."""
        return float(self.torques[self.data.driver])

    @property
    def hub_loads(self) -> np.ndarray:
        """The belt's force on each pulley's bearing (N, rows (Fx, Fy)):
        (T_out - rho c^2) t_out - (T_in - rho c^2) t_in, t the spans' directions of
        motion. It points from the centre towards the spans, and sums to zero over the
        pulleys (each span appears once with each sign), as the whole belt's momentum
        balance requires.

        The resultant of this model's contact forces (pressure (N - rho c^2) / r,
        friction -kappa N') differs from it by (rho c^2 / b1) times the integral of
        N' tau over the arc, below ``rho c^2 |T_out - T_in| / b1``: the pressure leaves the
        momentum flux's share rho c^2 N / b1 out (a momentum-exact pressure
        (kappa N - rho c^2) / r would give kappa T - rho c^2 in place of T - rho c^2)."""
        return hub_loads(self.layout, self.data.rho, self.c, self.tensions)

    @property
    def slip_powers(self) -> np.ndarray:
        """The friction's dissipation per pulley, kappa c (T_out - T_in)^2 / (2 b1) (W)."""
        dT = self.tensions - self.entry_tensions
        return self.kappa * self.c * dT * dT / (2.0 * self.data.b1)

    @property
    def slip_power(self) -> float:
        """Total slip power (W) = driver's power - delivered power."""
        return float(self.slip_powers.sum())

    @property
    def efficiency(self) -> float:
        """sum_i M_i omega_i / (M_d omega_d) (1 unloaded)."""
        d = self.data.driver
        P_in = self.driver_torque * self.speeds[d]
        if P_in == 0:
            return 1.0
        loads = np.asarray(self.data.loads)
        return float(np.dot(loads, self.speeds) / P_in)

    @property
    def slip_margins(self) -> np.ndarray:
        """Per pulley: the load at which its slip arc reaches its wrap over its load (the
        others' loads held); for the driver the factor on all loads. inf at idlers and
        with perfect adhesion. Computed on first use (a root search per loaded pulley)."""
        return np.array([self.slip_margin(i) for i in range(len(self.layout))])

    def slip_margin(self, i: int) -> float:
        """Pulley i's entry of :attr:`slip_margins`, its root search alone (a start-up's
        ramp needs only the driver's: a fifth of the accessory drive's searches)."""
        key = ("margin", i)
        if key not in self._cache:
            out = math.inf
            if self.data.mu is not None:
                if i == self.data.driver and sum(self.data.loads) > 0:
                    out = _load_factor(self.data, self.layout, i, True)
                elif self.data.loads[i] > 0:
                    out = _load_factor(self.data, self.layout, i, False)
            self._cache[key] = out
        return self._cache[key]

    @property
    def alpha_offset(self) -> float | None:
        """The tensioner arm's angle less the drawn one (rad), None without a tensioner."""
        return None if self.alpha is None else self.alpha - self.alpha_drawn

    @property
    def arm_travel(self) -> float | None:
        """The tensioner arm's turn into the belt from its drawn angle (rad), None
        without a tensioner."""
        return None if self.alpha is None else self.sense_tensioner * self.alpha_offset

    @property
    def stick_ends(self) -> np.ndarray:
        """Loop coordinates (m) where the slip arcs begin, one per slipping pulley in the
        belt's order (the stick zone of each arc ends there; an idler has none)."""
        g = self.layout
        ends = g.bounds[1::2][:len(g)] - g.radii * self.phi_s
        return ends[self.phi_s > 0]

    def _pieces(self):
        """N as pieces (a, b, const, amp, rate): N = const + amp exp(rate (x - a))."""
        g, rc = self.layout, self.centrifugal
        e, Tin, T = g.bounds, self.entry_tensions, self.tensions
        out = []
        for i in range(len(g)):
            s = e[2 * i + 1] - g.radii[i] * self.phi_s[i]
            out.append((e[2 * i], s, Tin[i], 0.0, 0.0))
            if self.phi_s[i] > 0:
                rate = math.copysign(self.data.mu[i] / (self.kappa * g.radii[i]), T[i] - Tin[i])
                out.append((s, e[2 * i + 1], rc, Tin[i] - rc, rate))
            out.append((e[2 * i + 1], e[2 * i + 2], T[i], 0.0, 0.0))
        return out

    def tension(self, x) -> np.ndarray:
        """Axial force N (N) at loop coordinates x (the value downstream at a jump)."""
        x = np.mod(np.asarray(x, dtype=float), self.layout.loop_length)
        out = np.zeros_like(x)
        for a, b, const, amp, rate in self._pieces():
            on = (x >= a) & (x < b)
            out = np.where(on, const + amp * np.exp(rate * (x - a)), out)
        return out

    def displacement(self, x) -> np.ndarray:
        """u (m) at loop coordinates x: the integral of (N - N0) / b1 from x = 0, less
        its mean over the loop (the model's gauge), exact on every piece."""
        g = self.layout
        starts, ends, means = [], [], 0.0
        for a, b, const, amp, rate in self._pieces():
            # integral of N - N0 over [a, b], and of that integral (for the mean)
            lin = (const - self.data.N0) * (b - a)
            grow = amp * (math.expm1(rate * (b - a)) / rate if rate else (b - a))
            starts.append((a, b, const, amp, rate))
            ends.append(lin + grow)
        cum = np.concatenate([[0.0], np.cumsum(ends)]) / self.data.b1
        x = np.mod(np.asarray(x, dtype=float), g.loop_length)
        out = np.zeros_like(x)
        for k, (a, b, const, amp, rate) in enumerate(starts):
            on = (x >= a) & (x < b)
            dx = x[on] - a
            grow = amp * (np.expm1(rate * dx) / rate if rate else dx)
            out[on] = cum[k] + ((const - self.data.N0) * dx + grow) / self.data.b1
            # the piece's integral of u, for the mean
            L = b - a
            g2 = amp * ((math.expm1(rate * L) / rate - L) / rate if rate else 0.5 * L * L)
            means += cum[k] * L + ((const - self.data.N0) * 0.5 * L * L + g2) / self.data.b1
        return out - means / g.loop_length

    def pressure(self, x) -> np.ndarray:
        """p = (N - rho c^2) / r (N/m) on the arcs, 0 on the spans."""
        g = self.layout
        seg = g.segment_of(x)
        on = seg % 2 == 0
        r = np.where(on, g.radii[seg // 2], 1.0)
        return np.where(on, (self.tension(x) - self.centrifugal) / r, 0.0)

    def friction(self, x) -> np.ndarray:
        """The friction on the belt f = -kappa N' (N/m): -+ mu p on the slip arcs, 0 where
        the belt sticks (the string's stick zones carry no friction)."""
        x = np.mod(np.asarray(x, dtype=float), self.layout.loop_length)
        out = np.zeros_like(x)
        for a, b, _, amp, rate in self._pieces():
            on = (x >= a) & (x < b)
            out = np.where(on, -self.kappa * amp * rate * np.exp(rate * (x - a)), out)
        return out

    def summary(self) -> dict:
        """The drive's figures: spans, pulleys (with each one's slip margin and slip
        power), the totals and the tensioner's arm angle."""
        out = {"belt_speed": float(self.c), "driver_torque": self.driver_torque,
               "efficiency": self.efficiency, "slip_power": self.slip_power,
               **layout_summary(self.layout, self.roles, self.data.rho, self.c,
                                self.tensions, self.speeds, self.phi_s, self.torques,
                                slip_margin=self.slip_margins,
                                slip_power=self.slip_powers)}
        if self.alpha is not None:
            out.update(arm_angle=self.alpha, arm_travel=self.arm_travel)
        return out


def _capacity_error(d: SerpentineData, layout: PulleyLayout, phi) -> GrossSlipError:
    i = int(np.argmax(phi / layout.wraps))
    scale_all = i == d.driver
    lam = _load_factor(d, layout, i, scale_all)
    if scale_all:
        now = layout.radii[i] * float(np.sum(np.asarray(d.loads) / layout.radii))
        what = "driver torque"
    else:
        now, what = d.loads[i], "load"
    return GrossSlipError(
        f"pulley {layout.names[i]!r}: {what} {now:.6g} N m exceeds its capacity "
        f"{lam * now:.6g} N m (gross slip: slip arc {phi[i]:.4g} rad > wrap "
        f"{layout.wraps[i]:.4g} rad)", lam * now)


def _solve_layout(d: SerpentineData, layout: PulleyLayout) -> SerpentineSolution:
    c, kappa, T, phi = _solve_raw(d, layout, d.loads)
    if np.any(phi > layout.wraps):
        raise _capacity_error(d, layout, phi)
    return SerpentineSolution(d, layout, c, T, phi)


def _solve_tensioner(d: SerpentineData) -> SerpentineSolution:
    ten = d.tensioner
    beta, sol = equilibrium(ten, d.layout, lambda b: _solve_layout(d, ten.turned(d.layout, b)),
                            lambda sol: sol.hub_loads[ten.index])
    _, alpha0, s = ten.arm(d.layout)
    return SerpentineSolution(sol.data, sol.layout, sol.c, sol.tensions, sol.phi_s,
                              alpha0 + s * beta, alpha0, s)


def solve_serpentine(data: SerpentineData) -> SerpentineSolution:
    """The string's steady state of a serpentine drive (with the tensioner's arm at its
    equilibrium angle when there is one).

    Parameters
    ----------
    data : SerpentineData
        The layout as drawn, the belt, friction, installation tension, driver and loads.

    Returns
    -------
    SerpentineSolution
        Tensions, belt speed and slip arcs; ``alpha`` and ``layout`` give the tensioner
        arm's angle (rad, counterclockwise from +x about the pivot) and the layout there.

    Raises
    ------
    GrossSlipError
        A load exceeds what a pulley carries (its name and capacity in the message).
    LiftOffError
        A span's tension would not exceed rho c^2 (named in the message).
    NoSolutionError
        The tensioner's arm has no equilibrium in a sensible range ("tensioner: ...").
    """
    if data.tensioner is not None:
        return _solve_tensioner(data)
    return _solve_layout(data, data.layout)


__all__ = ["GrossSlipError", "LiftOffError", "SerpentineData", "SerpentineSolution",
           "Tensioner", "solve_serpentine"]
