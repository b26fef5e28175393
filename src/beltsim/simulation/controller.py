"""The run loop: compiled stepping between Python-level checks.

As in py-pde's Controller, the scheme's compiled kernel advances the state over one
check interval of simulated time; between intervals the trackers
(:mod:`beltsim.simulation.trackers`) record the history, take snapshots, test for
steady state and divergence, show progress and read stop requests. On a numerical
failure the state goes back to the last good check, so a failed run never holds NaN.
"""

from __future__ import annotations

import math
import time

import numpy as np

from .. import solvers
from ..errors import NumericalError
from ..physics.grid import Grid
from ..problem.drive import mismatch as mismatch_at
from ..problem.drive import period_of, profile_times
from ..problem.scene import Scene
from .result import RunResult, RunStatus
from .solution import DiscreteSolution
from .trackers import (
    CallbackTracker,
    CheckpointTracker,
    DivergenceGuard,
    HistoryTracker,
    PeriodicTracker,
    PowerBalanceTracker,
    ProgressTracker,
    SignalTracker,
    SnapshotTracker,
    SteadyStateTracker,
    Tracker,
)

CHECKS_PER_TRANSIT = 4  # checks per transit time L / c
CHECKS_PER_PERIOD = 32  # at least, for a periodic drive (its extremes are read at checks)


class Simulation:
    """A scene on its grid, from rest, with the scheme its numerics name.

    ``run()`` steps it to steady state (or t_end) and returns a :class:`RunResult`.
    """

    def __init__(self, scene: Scene, grid: Grid | None = None,
                 snapshot_interval: float | None = None, loads=None):
        self.disc = solvers.Discretisation(scene, grid)
        if loads is not None:  # distributed loads (physics.model.Loads) on this grid
            self.disc.loads = loads
        self.scheme = solvers.get(self.disc.numerics.integrator)(self.disc)
        self.state = self.disc.new_state()
        self.t = 0.0
        self.wall_time = 0.0
        P, num = self.disc.params, self.numerics
        window = P.L / P.c
        self.snapshot_interval = snapshot_interval or num.snapshot_interval
        self.check = window / CHECKS_PER_TRANSIT
        if self.snapshot_interval:
            self.check = min(self.check, self.snapshot_interval)
        self.history = HistoryTracker("stick" if self.params.friction == "stick" else "slip")
        friction_scale = P.B * self.disc.scales.theta * 1e-3
        period = period_of(scene)
        if period is None:
            self.steady = SteadyStateTracker(num.steady_tol, window, num.settle_time,
                                             friction_scale)
        else:  # checks at equal phases of the period
            samples = max(CHECKS_PER_PERIOD, math.ceil(period / self.check))
            self.check = period / samples
            self.steady = PeriodicTracker(num.steady_tol, period, samples, num.settle_time,
                                          friction_scale, P.L, self.history.model)
        # chunks end on the drive's table rows, where its rate jumps
        self.breaks = np.array(profile_times(scene))
        self.snapshots = (SnapshotTracker(self.snapshot_interval) if self.snapshot_interval
                          else None)
        self.power = PowerBalanceTracker() if hasattr(self.scheme, "work_integrals") else None
        self._measured = None

    # views ------------------------------------------------------------
    @property
    def scene(self) -> Scene:
        return self.disc.scene

    @property
    def params(self):
        return self.disc.params

    @property
    def numerics(self):
        return self.scheme.numerics

    @property
    def grid(self):
        return self.disc.grid

    @property
    def steps(self) -> int:
        return self.scheme.steps

    def total_friction(self) -> float:
        return self._measure()[0]

    def rate(self) -> float:
        """Largest local rate, relative to c abs(e0) (per unit length for theta)."""
        return self._measure()[1]

    def _measure(self):
        if self._measured is None:
            P, s = self.disc.params, self.disc.scales
            v = P.c * s.theta
            rate = max(np.max(np.abs(self.state.ud)), P.L * np.max(np.abs(self.state.td))) / v
            self._measured = (float(self.state.fnode.sum()), float(rate))
        return self._measured

    def solution(self) -> DiscreteSolution:
        n = self.numerics
        # a steady solve's state is the final drive's, whatever the clock says
        mismatch = mismatch_at(self.disc.drive, self.t) if self.scheme.transient else None
        return DiscreteSolution(self.params, self.grid, self.state.u, self.state.theta,
                                self.state.fnode, n.law_code, n.fs, self.state.ud,
                                self.state.td, mismatch,
                                (self.disc.mesh.c0, self.disc.mesh.wf, self.disc.mesh.sw))

    # stepping ---------------------------------------------------------
    def warm_up(self) -> float:
        """Compile (or load from numba's cache) the kernels; returns the seconds it took."""
        return self.scheme.warm_up(self.state)

    def advance(self, t_stop: float, max_steps: int = 10**9) -> None:
        """Step until t >= t_stop (transient schemes); raises NumericalError on failure."""
        self.t = self.scheme.advance(self.state, self.t, t_stop, max_steps)
        self._measured = None

    def trackers(self, progress=False, handle_signals=False, callback=None,
                 checkpoint=None) -> list[Tracker]:
        """The trackers of a run, in the order they handle each check."""
        out: list[Tracker] = [DivergenceGuard(), self.history]
        if self.power is not None:
            out.append(self.power)
        if self.snapshots is not None:
            out.append(self.snapshots)
        if progress:
            out.append(ProgressTracker())
        out.append(self.steady)
        if callback is not None:
            out.append(CallbackTracker(callback))
        if handle_signals:
            out.append(SignalTracker())
        if checkpoint is not None:
            out.append(CheckpointTracker(checkpoint))
        return out

    def run(self, progress: bool = False, raise_on_failure: bool = True,
            handle_signals: bool = False, callback=None, checkpoint=None) -> RunResult:
        """Run from the current state until steady (or t_end).

        With ``handle_signals`` (the CLI), SIGINT and SIGTERM stop the run cleanly
        between chunks (status INTERRUPTED); ``checkpoint`` is a path where an
        interrupted or failed run stores what :meth:`resume` needs. ``callback(sim)`` is
        called after every chunk; a true return value stops the run the same way. The
        analytic reference is not attached: :func:`beltsim.run` does that.
        """
        compile_time = self.warm_up()
        if not self.scheme.transient:
            return self._run_steady(raise_on_failure, compile_time)
        trackers = self.trackers(progress, handle_signals, callback, checkpoint)
        for tr in trackers:
            tr.initialize(self)
        t_end = self.numerics.t_end
        status, reason = RunStatus.REACHED_END, None
        start = time.perf_counter()
        try:
            # a fixed-step scheme's t carries round-off: within 1e-9 of a check is there
            while self.t < t_end - 1e-9 * self.check:
                good = (self.state.copy(), self.t, self.scheme.checkpoint())
                try:
                    # checks on a fixed grid k * check: a scheme that steps past a
                    # check (explicit, fixed dt) does not drift from it
                    t_next = self.check * (math.floor(self.t / self.check + 1e-9) + 1)
                    # the next table row after t (one within round-off of t is passed)
                    k = np.searchsorted(self.breaks, self.t + 1e-9 * self.check, side="right")
                    if k < self.breaks.size and self.breaks[k] < t_next - 1e-9 * self.check:
                        t_next = self.breaks[k]
                    # the last chunk absorbs a round-off remainder rather than leave a sliver
                    self.advance(t_end if t_next > t_end - 1e-9 * self.check else t_next)
                    stop = None
                    for tr in trackers:
                        stop = tr.handle(self)
                        if stop is not None:
                            break
                except NumericalError:
                    self._restore(good)
                    raise
                if stop is not None:
                    status, reason = stop.status, stop.reason
                    break
        except NumericalError as exc:
            status, reason = RunStatus.FAILED, str(exc)
            if raise_on_failure:
                raise
        finally:
            self.wall_time += time.perf_counter() - start
            for tr in trackers:
                tr.finalize(self, status)
        if status is RunStatus.REACHED_END:
            reason = self.steady.not_steady(t_end)
        return self._result(status, reason, compile_time)

    def _restore(self, good):
        state, t, scheme = good
        self.state.assign(state)
        self.t = t
        self.scheme.restore(scheme)
        self._measured = None

    def _run_steady(self, raise_on_failure, compile_time):
        start = time.perf_counter()
        status, reason = RunStatus.CONVERGED, None
        try:
            self.scheme.solve(self.state)
        except NumericalError as exc:
            status, reason = RunStatus.FAILED, str(exc)
            if raise_on_failure:
                raise
        finally:
            self.wall_time = time.perf_counter() - start
            self._measured = None
        return self._result(status, reason, compile_time)

    def _result(self, status, reason, compile_time) -> RunResult:
        return RunResult(
            scene=self.scene, numerics=self.numerics, status=status, reason=reason,
            time_accurate=self.scheme.time_accurate,
            solution=self.solution(), simulated_time=self.t, wall_time=self.wall_time,
            compile_time=compile_time, statistics=self.scheme.statistics(),
            history=self.history.arrays(),
            power_balance=self.power.balance(self) if self.power is not None else None,
            periodic=(self.steady.last_period()
                      if isinstance(self.steady, PeriodicTracker) else None),
            snapshots=self.snapshots.arrays() if self.snapshots is not None else {})

    # checkpoints ------------------------------------------------------
    def tracker_states(self) -> dict:
        """The state of every tracker a resumed run continues with, by name."""
        out = {"history": self.history.state(), "steady": self.steady.state()}
        if self.power is not None:
            out["power"] = self.power.state()
        if self.snapshots is not None:
            out["snapshots"] = self.snapshots.state()
        return out

    @classmethod
    def resume(cls, path) -> "Simulation":
        """A simulation restored from a checkpoint (:func:`beltsim.io.results.write_checkpoint`)."""
        from ..io.results import read_checkpoint

        ck = read_checkpoint(path)
        trackers = ck["trackers"]
        interval = float(trackers["snapshots"]["interval"]) if "snapshots" in trackers else None
        sim = cls(ck["scene"], snapshot_interval=interval)
        sim.state.assign([ck["state"][k] for k in sim.state._fields])
        sim.t, sim.wall_time = ck["t"], ck["wall_time"]
        sim.scheme.restore(ck["scheme"])
        sim.history.restore(trackers["history"])
        sim.steady.restore(trackers["steady"])
        if sim.snapshots is not None:
            sim.snapshots.restore(trackers["snapshots"])
        if sim.power is not None:
            sim.power.restore(trackers["power"])
        return sim


def run(scene: Scene, progress: bool = False, raise_on_failure: bool = True,
        snapshot_interval: float | None = None) -> RunResult:
    """Run a scene from rest to steady state and attach its exact steady solution."""
    from .result import reference_of

    result = Simulation(scene, snapshot_interval=snapshot_interval).run(
        progress=progress, raise_on_failure=raise_on_failure)
    result.reference = reference_of(scene)
    return result
