"""Trackers: what the controller does between two chunks of simulated time.

As in py-pde's TrackerCollection, each tracker has ``initialize(sim)``,
``handle(sim)`` (after every chunk; it may return a :class:`Stop`) and
``finalize(sim, status)``. Trackers that a resumed run needs carry a
``state()``/``restore()`` pair, stored in the checkpoint under their ``name``.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

import numpy as np

from ..errors import FailureKind, NumericalError
from .result import RunStatus

GROWTH_LIMIT = 1e4  # |u| / (|e0| L) or |theta| / |e0| beyond this counts as divergence


@dataclass(frozen=True)
class Stop:
    """A tracker's request to end the run, returned by :meth:`Tracker.handle`.

    Parameters
    ----------
    status : RunStatus, optional
        The status the run's result reports; INTERRUPTED (the default) for a run
        stopped on the user's request.
    reason : str, optional
        Why, for ``RunResult.reason`` (default: which tracker stopped it, and when).

    Examples
    --------
    >>> Stop(reason="friction above 2 kN")
    Stop(status=<RunStatus.INTERRUPTED: 'interrupted'>, reason='friction above 2 kN')
    """

    status: RunStatus = RunStatus.INTERRUPTED
    reason: str | None = None

    def __post_init__(self):
        if not isinstance(self.status, RunStatus):
            raise TypeError(f"Stop: status must be a RunStatus, got {self.status!r} (give "
                            f"a reason as Stop(reason=...))")


class Tracker:
    """Something done between two chunks of a run's simulated time; subclass it.

    A run calls :meth:`initialize` once before the first chunk, :meth:`handle` after
    every chunk (a check: every quarter of the transit time L / c, or more often) and
    :meth:`finalize` once at the end, whatever the end. Pass instances to
    :func:`beltsim.run` or :meth:`beltsim.Simulation.run` as ``trackers=[...]``; they
    handle each check after the run's own records (history, snapshots) and before its
    steady-state test, so they see every check, the last one too.

    What ``sim`` (a :class:`beltsim.Simulation`) offers at a check: ``sim.t`` (s),
    ``sim.total_friction()`` (N), ``sim.rate()``, ``sim.solution()`` (the state read as
    a solution: ``.fields()``, ``.summary()``), ``sim.state`` (the raw arrays, not to be
    changed), ``sim.scene``, ``sim.params``, ``sim.numerics`` and ``sim.grid``.

    A user's tracker is not stored in a checkpoint: a resumed run starts it afresh.

    Examples
    --------
    >>> class FrictionLog(beltsim.Tracker):
    ...     def initialize(self, sim):
    ...         self.t, self.friction = [], []
    ...     def handle(self, sim):
    ...         self.t.append(sim.t)
    ...         self.friction.append(sim.total_friction())
    ...         if sim.total_friction() > 2e3:
    ...             return beltsim.Stop(reason="friction above 2 kN")
    >>> log = FrictionLog()
    >>> result = beltsim.run(scene, trackers=[log])               # doctest: +SKIP
    """

    #: the key of the tracker's state in a checkpoint (built-in trackers that have one)
    name = ""

    def initialize(self, sim) -> None:
        """Called once, before the first chunk (and on a resumed run, before its first).

        Parameters
        ----------
        sim : beltsim.Simulation
            The simulation, at its starting time.
        """

    def handle(self, sim) -> Stop | None:
        """Called after every chunk of simulated time.

        Parameters
        ----------
        sim : beltsim.Simulation
            The simulation at the check (``sim.t``).

        Returns
        -------
        Stop or None
            A :class:`Stop` ends the run here (the trackers after this one skip the
            check); None lets it go on.
        """
        return None

    def finalize(self, sim, status: RunStatus) -> None:
        """Called once at the end, also after a numerical failure or an interruption.

        Parameters
        ----------
        sim : beltsim.Simulation
            The simulation as it ends (after a failure: at its last good check).
        status : RunStatus
            How the run ends.
        """

    def state(self) -> dict:
        """Arrays a resumed run needs (built-in trackers with a :attr:`name`)."""
        return {}

    def restore(self, data: dict) -> None:
        """Take back what :meth:`state` returned, from a checkpoint."""


class DivergenceGuard(Tracker):
    """Non-finite values or growth beyond GROWTH_LIMIT times the scales: a numerical failure."""

    def handle(self, sim):
        s = sim.disc.scales
        # a NaN or inf anywhere makes the largest magnitude non-finite
        gu = float(np.max(np.abs(sim.state.u))) / s.u
        gt = float(np.max(np.abs(sim.state.theta))) / s.theta
        if not (math.isfinite(gu) and math.isfinite(gt)):
            raise NumericalError(f"non-finite displacement or rotation at t = {sim.t:.6g} s",
                                 kind=FailureKind.NON_FINITE, t=sim.t, quantity="u/theta")
        if gu > GROWTH_LIMIT or gt > GROWTH_LIMIT:
            q, g = ("u", gu) if gu >= gt else ("theta", gt)
            raise NumericalError(
                f"{q} grew without bound at t = {sim.t:.6g} s ({g:.3g} times its scale)",
                kind=FailureKind.GREW, t=sim.t, quantity=q)
        return None


class OutcomeTracker(Tracker):
    """A physical outcome that ends the run (a drive's gross slip or lift-off): reported
    as such, with its status, not as a numerical failure."""

    def handle(self, sim):
        out = sim.readout.outcome(sim)
        return None if out is None else Stop(*out)


class HistoryTracker(Tracker):
    """At every check: t, the largest local rate and the layout's figures.

    ``keys`` come from the layout's readout (:mod:`beltsim.simulation.readout`): on the
    paper's belt the total friction and, for Coulomb scenes, the slip start, the stick
    and slip parts of the friction and the slip power (the friction law's dissipation at
    that moment), for perfect adhesion the concentrated force; on a drive its span
    tensions, speeds, slip arcs, torque and powers. Each is read off the state as in the
    summary.
    """

    name = "history"

    def __init__(self, keys):
        self.keys = tuple(keys)
        self.data = {k: [] for k in self.keys}

    def handle(self, sim):
        summary = sim.solution().summary(path=True)
        self.data["t"].append(sim.t)
        self.data["rate"].append(sim.rate())
        for k in self.keys:
            if k not in ("t", "rate"):
                self.data[k].append(summary[k])
        return None

    def arrays(self) -> dict:
        """The history as arrays, one entry a check (``RunResult.history``)."""
        return {k: np.array(v) for k, v in self.data.items()}

    def state(self):
        return {"rows": np.array([self.data[k] for k in self.keys])}

    def restore(self, data):
        for k, row in zip(self.keys, data["rows"]):
            self.data[k] = list(row)


class SteadyStateTracker(Tracker):
    """Steady when, ``hold`` checks in a row after the ramp, both the largest local rate
    (``sim.rate()``: on the paper's belt max abs(u_t) and L max abs(theta_t), relative to
    c abs(e0)) and the change of the monitored quantity (``sim.monitor()``: the total
    friction, or a drive's torque) over one window of simulated time (relative to its
    value, or to ``friction_scale`` where that is larger) are below ``tol``.
    """

    name = "steady"

    def __init__(self, tol: float, window: float, t_min: float, friction_scale: float,
                 hold: int = 3):
        self.tol, self.window, self.t_min, self.hold = tol, window, t_min, hold
        self.friction_scale = friction_scale
        self._hist: deque = deque()
        self._count = 0
        self.change = math.inf
        self.rate = math.inf

    def update(self, t: float, rate: float, total_friction: float) -> bool:
        """Record a check; True once the state has been steady ``hold`` times in a row."""
        self.rate = rate
        self._hist.append((t, total_friction))
        while len(self._hist) > 1 and self._hist[1][0] <= t - self.window:
            self._hist.popleft()
        t0, f0 = self._hist[0]
        if t - t0 >= self.window * (1 - 1e-9):
            denom = max(abs(total_friction), self.friction_scale)
            self.change = abs(total_friction - f0) / denom
        else:
            self.change = math.inf
        if t >= self.t_min and rate < self.tol and self.change < self.tol:
            self._count += 1
        else:
            self._count = 0
        return self._count >= self.hold

    def handle(self, sim):
        if self.update(sim.t, sim.rate(), sim.monitor()):
            return Stop(RunStatus.CONVERGED)
        return None

    @property
    def span(self) -> float:
        """The window (s) over which the change is measured."""
        return self.window

    def measure(self) -> float:
        """What must stay below ``tol``: the larger of the rate and the change at the
        last check (the rate alone in the first window, where no change is defined)."""
        return self.rate if math.isinf(self.change) else max(self.rate, self.change)

    def not_steady(self, t_end: float) -> str:
        """The reason of a run that reached t_end before steady state."""
        return (f"not steady by t_end = {t_end:.6g} s (rate {self.rate:.3g}, friction change "
                f"{self.change:.3g} per window; tolerance {self.tol:.3g})")

    def state(self):
        return {"scalars": np.array([self._count, self.change, self.rate]),
                "window": np.array(list(self._hist)).reshape(-1, 2)}

    def restore(self, data):
        count, self.change, self.rate = data["scalars"]
        self._count = int(count)
        self._hist = deque(map(tuple, data["window"]))


class PeriodicTracker(Tracker):
    """A periodic steady state of a periodic drive.

    The checks fall at ``samples`` equal phases of each period; after ``t_min`` (the
    ramp) the first two of the history's ``keys`` (the total friction and the slip start
    or the concentrated force; a drive's torque and driven speed) of the last period are
    compared, phase by phase, with the period before: periodic when the largest change is
    below ``tol`` (relative to the first's magnitude, at least ``friction_scale``, and to
    ``second_scale``, or the first's scale) at ``hold`` checks in a row.
    """

    name = "steady"

    def __init__(self, tol: float, period: float, samples: int, t_min: float,
                 friction_scale: float, keys, second_scale: float | None, hold: int = 3):
        self.tol, self.period, self.samples, self.t_min = tol, period, samples, t_min
        # reported over the last period; the first two are compared between periods
        self.keys = tuple(keys)
        self.friction_scale, self.second_scale, self.hold = (friction_scale, second_scale,
                                                             hold)
        self._rows: deque = deque(maxlen=2 * samples)
        self._count = 0
        self.change = math.inf

    def handle(self, sim):
        h = sim.history.data
        if sim.t < self.t_min:
            return None
        self._rows.append((sim.t, *(h[k][-1] for k in self.keys)))
        if len(self._rows) < 2 * self.samples:
            return None
        rows = np.array(self._rows)
        old, new = rows[: self.samples], rows[self.samples:]
        scale = max(np.abs(new[:, 1]).max(), self.friction_scale)
        second_scale = self.second_scale if self.second_scale is not None else scale
        self.change = max(np.abs(new[:, 1] - old[:, 1]).max() / scale,
                          np.abs(new[:, 2] - old[:, 2]).max() / second_scale)
        self._count = self._count + 1 if self.change < self.tol else 0
        return Stop(RunStatus.CONVERGED) if self._count >= self.hold else None

    def last_period(self) -> dict | None:
        """Minimum, maximum, mean and amplitude (half the range) over the last period of
        the quantities in ``keys``."""
        if len(self._rows) < self.samples:
            return None
        rows = np.array(self._rows)[-self.samples:]
        out = {"period": self.period, "change": float(self.change)}
        for col, key in enumerate(self.keys, 1):
            lo, hi = float(rows[:, col].min()), float(rows[:, col].max())
            out[key] = {"min": lo, "max": hi, "amplitude": 0.5 * (hi - lo),
                        "mean": float(rows[:, col].mean())}  # equal phases: exact for a sine
        return out

    @property
    def span(self) -> float:
        """The period (s): the change is measured between two."""
        return self.period

    def measure(self) -> float:
        """What must stay below ``tol``: the change between the last two periods."""
        return self.change

    def not_steady(self, t_end: float) -> str:
        """The reason of a run that reached t_end before its periodic steady state."""
        return (f"no periodic steady state by t_end = {t_end:.6g} s (change between the "
                f"last two periods {self.change:.3g}; tolerance {self.tol:.3g})")

    def state(self):
        return {"scalars": np.array([self._count, self.change]),
                "rows": np.array(list(self._rows)).reshape(-1, 1 + len(self.keys))}

    def restore(self, data):
        count, self.change = data["scalars"]
        self._count = int(count)
        self._rows = deque(map(tuple, data["rows"]), maxlen=2 * self.samples)


class SnapshotTracker(Tracker):
    """The state at (about) every ``interval`` of simulated time, and at the end: the
    arrays ``keys`` of the state (the layout's readout names them)."""

    name = "snapshots"

    def __init__(self, interval: float, keys=("u", "theta", "fnode")):
        self.interval = interval
        self.keys = tuple(keys)
        self.times: list = []
        self.fields: dict = {k: [] for k in self.keys}

    def take(self, sim):
        """Store the state now."""
        self.times.append(sim.t)
        for k in self.keys:
            self.fields[k].append(getattr(sim.state, k).copy())

    def initialize(self, sim):
        if not self.times:
            self.take(sim)

    def handle(self, sim):
        if sim.t >= self.times[-1] + self.interval * (1 - 1e-9):
            self.take(sim)
        return None

    def finalize(self, sim, status):
        if status is not RunStatus.INTERRUPTED and self.times[-1] < sim.t:
            self.take(sim)

    def arrays(self) -> dict:
        """The snapshots as arrays (``RunResult.snapshots``): ``t`` and (times, nodes)."""
        return {"t": np.array(self.times), **{k: np.array(v) for k, v in self.fields.items()}}

    def state(self):
        return {"interval": np.array(self.interval), **self.arrays()}

    def restore(self, data):
        self.times = list(data["t"])
        for k in self.keys:
            self.fields[k] = list(data[k])


class PowerBalanceTracker(Tracker):
    """The power balance over the run, for schemes that integrate the power terms.

    E(t) - E(0) = W_surface + W_transport + W_loads - D_slip - D_damping
    (physics.model.POWER_TERMS); the residual, relative to the dissipated energy
    D_slip + D_damping, measures how well the time integration keeps it.
    """

    name = "power"

    def __init__(self):
        self.initial_energy = None

    def initialize(self, sim):
        from ..physics.model import stored_energy
        if self.initial_energy is None:
            self.initial_energy = stored_energy(sim.state, sim.disc.mesh, sim.disc.model)

    def balance(self, sim) -> dict:
        """The energy balance over the run so far (J): ``RunResult.power_balance``."""
        from ..physics.model import stored_energy
        work = sim.scheme.work_integrals()
        change = stored_energy(sim.state, sim.disc.mesh, sim.disc.model) - self.initial_energy
        dissipated = work["slip"] + work["damping"] + work["gyroscopic"]
        residual = change - (work["surface"] + work["transport"] + work["loads"] - dissipated)
        return {"stored_energy_change": change, "surface_work": work["surface"],
                "transport_work": work["transport"], "load_work": work["loads"],
                "slip_dissipation": work["slip"], "damping_dissipation": work["damping"],
                "gyroscopic_dissipation": work["gyroscopic"],
                "residual": residual,
                "relative_residual": abs(residual) / dissipated if dissipated > 0 else None}

    def state(self):
        return {"initial_energy": np.array(self.initial_energy)}

    def restore(self, data):
        self.initial_energy = float(data["initial_energy"])


def progress_bar(**kwargs):
    """A tqdm progress bar: a widget in Jupyter with ipywidgets, text everywhere else.

    ``tqdm.auto`` picks the widget in any Jupyter kernel and, where ipywidgets is
    missing, warns "IProgress not found" before it falls back to text; this asks first
    and goes straight to the text bar. In a kernel the text bar stays when closed
    (``leave=True``), so that a saved notebook shows where the run ended, not a bar
    frozen halfway or a cleared line.

    Parameters
    ----------
    **kwargs
        Passed to ``tqdm``.

    Returns
    -------
    tqdm.std.tqdm
        A ``tqdm.notebook.tqdm`` in a kernel with ipywidgets.
    """
    if _in_kernel():
        if _has_widgets():
            from tqdm.notebook import tqdm
            return tqdm(**kwargs)
        kwargs["leave"] = True
    from tqdm.std import tqdm
    return tqdm(**kwargs)


def _in_kernel() -> bool:
    """Whether this runs in a Jupyter kernel (as tqdm.autonotebook tells)."""
    import sys

    ipython = sys.modules.get("IPython")
    try:
        return ipython is not None and "IPKernelApp" in ipython.get_ipython().config
    except Exception:  # no shell, or one without a config: not a kernel
        return False


def _has_widgets() -> bool:
    from importlib.util import find_spec

    return find_spec("ipywidgets") is not None


class CallbackTracker(Tracker):
    """``callback(sim)`` after every chunk; a true return value stops the run."""

    def __init__(self, callback):
        self.callback = callback

    def handle(self, sim):
        if self.callback(sim):
            return Stop(RunStatus.INTERRUPTED, f"interrupted (callback) at t = {sim.t:.6g} s")
        return None


class SignalTracker(Tracker):
    """SIGINT and SIGTERM set a flag that ends the run at the next check.

    A KeyboardInterrupt raised while a kernel returns could leave the time and the
    state out of step; a flag read at a chunk boundary cannot.
    """

    def __init__(self):
        self.requested = None
        self._old = {}

    def initialize(self, sim):
        import signal
        import threading
        if threading.current_thread() is not threading.main_thread():
            return
        for sig in (signal.SIGINT, signal.SIGTERM):
            self._old[sig] = signal.signal(sig, self._handler)

    def _handler(self, signum, frame):
        import signal
        self.requested = signal.Signals(signum).name

    def handle(self, sim):
        if self.requested:
            return Stop(RunStatus.INTERRUPTED,
                        f"interrupted ({self.requested}) at t = {sim.t:.6g} s")
        return None

    def finalize(self, sim, status):
        import signal
        for sig, old in self._old.items():
            signal.signal(sig, old)
        self._old = {}


class CheckpointTracker(Tracker):
    """At the end: a checkpoint when the run was interrupted or failed, none otherwise."""

    def __init__(self, path):
        self.path = path

    def finalize(self, sim, status):
        from pathlib import Path

        from ..io.results import write_checkpoint
        if status in (RunStatus.INTERRUPTED, RunStatus.FAILED):
            write_checkpoint(self.path, sim)
        else:
            Path(self.path).unlink(missing_ok=True)
