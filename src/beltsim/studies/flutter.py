"""The flutter of an unstable steady state: a physical transient
(``numerics.transient = "physical"``) sampled finely enough to resolve its modes, its
linear growth, and its limit cycle where it has one.

A run records, at every check (a physical transient's are
:func:`~beltsim.simulation.stability.physical_sampling` apart: 8 per period of the
highest growing root in the band), the total friction, the slip zone's start (or, for perfect
adhesion, the concentrated force) and u at a probe in the outflow span. From these:

* the growth rate of the linear phase: a straight line fitted to the logarithm of the
  deviation's envelope (its largest ``abs(F - F_s)`` per window of ``WINDOW`` s);
* the limit cycle over the run's last ``WINDOW_CYCLE`` s: half the peak-to-peak of
  each record, the mean shift of the friction, the slip front's range and the leading
  frequencies of the friction (Hann-windowed spectrum).

Perfect adhesion has no bound on the friction, so its growth need not saturate; a run
whose deviation passes ``NO_CYCLE`` of the steady friction stops with that reason.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..simulation.controller import Simulation
from ..simulation.trackers import Stop, Tracker

#: The envelope's window (s): several periods of the slowest growing mode
WINDOW = 0.02
#: The limit cycle is measured over the run's last so many seconds
WINDOW_CYCLE = 0.2
#: A deviation of the total friction beyond this fraction of its steady value ends a run:
#: past it no saturation is in sight, and the small-strain model is stretched
NO_CYCLE = 1.0


class FlutterLog(Tracker):
    """Records, at every check, the total friction, the slip start (or concentrated
    force) and u at ``probe`` (m); stops a run whose friction leaves the steady value by
    more than ``NO_CYCLE`` of it."""

    def __init__(self, probe: float, steady_friction: float):
        self.probe, self.steady = probe, steady_friction

    def initialize(self, sim):
        """Empty records, and the probe's place on the grid."""
        self.t, self.friction, self.front, self.u = [], [], [], []
        x = sim.grid.x
        self._j = int(np.clip(np.searchsorted(x, self.probe), 1, x.size - 1))
        self._w = (self.probe - x[self._j - 1]) / (x[self._j] - x[self._j - 1])
        # the slip front where the belt slides, the concentrated force in perfect adhesion
        self._front = ("slip_start" if sim.params.friction == "coulomb"
                       else "concentrated_force")

    def handle(self, sim):
        """Record this check; a stop once the friction leaves its steady value by more
        than ``NO_CYCLE`` of it."""
        u = sim.state.u
        self.t.append(sim.t)
        self.friction.append(sim.total_friction())
        self.front.append(getattr(sim.solution(), self._front))
        self.u.append((1 - self._w) * u[self._j - 1] + self._w * u[self._j])
        if abs(self.friction[-1] - self.steady) > NO_CYCLE * abs(self.steady):
            return Stop(reason=f"no limit cycle: the total friction left its steady value "
                               f"by more than {NO_CYCLE:.0%} at t = {sim.t:.4g} s")
        return None


@dataclass
class Flutter:
    """A physical transient's records and how they were made."""

    scene: object
    elements: int
    step: float  # the step limit (s)
    steady_friction: float  # the grid's steady state's (N)
    t: np.ndarray
    friction: np.ndarray
    front: np.ndarray  # slip start (m) or concentrated force (N)
    u: np.ndarray  # at the probe (m)
    wall_time: float
    steps: int
    reason: str | None
    extras: dict = field(default_factory=dict)

    def deviation(self) -> np.ndarray:
        """``abs(F - F_s) / abs(F_s)`` at every sample."""
        return np.abs(self.friction - self.steady_friction) / abs(self.steady_friction)

    def envelope(self, window: float = WINDOW) -> tuple[np.ndarray, np.ndarray]:
        """(window centres, largest deviation in each window)."""
        edges = np.arange(self.t[0], self.t[-1] + 1e-12, window)
        dev = self.deviation()
        centres, peaks = [], []
        for a in edges[:-1]:
            m = (self.t >= a) & (self.t < a + window)
            if m.any():
                centres.append(a + 0.5 * window)
                peaks.append(dev[m].max())
        return np.array(centres), np.array(peaks)

    def growth(self, t0: float, t1: float) -> float:
        """The growth rate (1/s) of the envelope between t0 and t1: the slope of its
        logarithm, fitted by least squares."""
        c, p = self.envelope()
        m = (c >= t0) & (c <= t1) & (p > 0)
        if m.sum() < 3:
            raise ValueError(f"growth: fewer than 3 windows between {t0} and {t1} s")
        return float(np.polyfit(c[m], np.log(p[m]), 1)[0])

    def limit_cycle(self, window: float = WINDOW_CYCLE) -> dict:
        """Over the last ``window`` s: half the peak-to-peak of the friction (relative to
        the steady value), of the front and of u at the probe; the friction's mean shift
        (relative) and its three leading frequencies (Hz)."""
        m = self.t >= self.t[-1] - window
        F, t = self.friction[m], self.t[m]
        half = lambda v: 0.5 * float(np.nanmax(v) - np.nanmin(v))  # noqa: E731
        dt = float(np.median(np.diff(t)))
        spec = np.abs(np.fft.rfft((F - F.mean()) * np.hanning(F.size)))
        freqs = np.fft.rfftfreq(F.size, dt)
        peaks = [i for i in range(1, spec.size - 1)
                 if spec[i] >= spec[i - 1] and spec[i] >= spec[i + 1]]
        peaks.sort(key=lambda i: -spec[i])
        return {"friction": half(F) / abs(self.steady_friction),
                "friction_mean": float(F.mean() / self.steady_friction - 1.0),
                "front": half(self.front[m]),
                "front_range": (float(np.nanmin(self.front[m])),
                                float(np.nanmax(self.front[m]))),
                "u": half(self.u[m]),
                "frequencies": [float(freqs[i]) for i in peaks[:3]]}


def flutter_run(scene, t_end: float, elements: int | None = None,
                step_factor: float = 1.0, probe: float | None = None,
                from_steady: float | None = None, trackers=()) -> Flutter:
    """A physical transient of ``scene`` from rest to ``t_end`` (s), finely sampled.

    Parameters
    ----------
    scene : Scene
        An inertial straight-belt scene with an exact steady state.
    t_end : float
        Simulated seconds.
    elements : int, optional
        The grid (default the scene's).
    step_factor : float, optional
        The physical step limit times this (a time ladder: 1, 1/2, 1/4).
    probe : float, optional
        Where u is recorded (m); default the middle of the outflow span.
    from_steady : float, optional
        Start from the discrete steady state (the surface at its speed, no ramp) with u
        perturbed by this fraction of its largest value in the shape sin(pi x / L), so
        that the linear phase starts from a known small amplitude; default from rest.
    trackers : sequence of Tracker, optional
        More trackers for the run (a :class:`~beltsim.simulation.trackers.SnapshotTracker`
        for an animation), called at every check after the flutter's own.

    Returns
    -------
    Flutter
    """
    from ..physics.modes import steady_discretisation

    over = [("numerics.transient", "physical"), ("numerics.t_end", t_end),
            ("numerics.steady_tol", 1e-300)]
    if elements is not None:
        over.append(("numerics.elements", elements))
    if from_steady is not None:
        over.append(("numerics.ramp_time", 0.0))
    sc = scene.with_overrides(over)
    P = sc.params
    sim = Simulation(sc)
    sim.scheme.max_step *= step_factor
    # the deviation is measured from the grid's own steady state, not the exact one: the
    # discretisation's error in it would otherwise floor the linear phase
    steady = steady_discretisation(sc, sim.grid.n_elements)[1]
    if from_steady is not None:
        sim.state.assign(steady)
        x = sim.grid.x
        sim.state.u[:] += from_steady * np.abs(steady.u).max() * np.sin(np.pi * x / P.L)
    log = FlutterLog(probe if probe is not None else 0.5 * (P.x2 + P.L),
                     float(steady.fnode.sum()))
    start = time.perf_counter()
    res = sim.run(raise_on_failure=False, trackers=[log, *trackers])
    wall = time.perf_counter() - start
    return Flutter(scene=sc, elements=sim.grid.n_elements, step=sim.scheme.max_step,
                   steady_friction=log.steady, t=np.array(log.t),
                   friction=np.array(log.friction), front=np.array(log.front),
                   u=np.array(log.u), wall_time=wall, steps=res.steps,
                   reason=res.reason, extras={"status": res.status.value})


def observed_order(a: float, b: float, c: float, ratio: float = 2.0) -> float:
    """The observed order of a sequence a, b, c on grids refined by ``ratio``:
    ``log(abs(a - b) / abs(b - c)) / log(ratio)`` (nan when b = c)."""
    d1, d2 = abs(a - b), abs(b - c)
    return math.log(d1 / d2) / math.log(ratio) if d2 > 0 and d1 > 0 else math.nan
