"""The run loop: compiled stepping between Python-level checks.

As in py-pde's Controller, the scheme's compiled kernel advances the state over one
check interval of simulated time; between intervals the trackers
(:mod:`beltsim.simulation.trackers`) record the history, take snapshots, test for
steady state and divergence, show progress and read stop requests. On a numerical
failure the state goes back to the last good check, so a failed run never holds NaN.
"""

from __future__ import annotations

import math
import sys
import threading
import time

import numpy as np

from .. import solvers
from ..errors import NumericalError
from ..physics.grid import Grid
from ..problem.drive import period_of, profile_times
from ..problem.scene import Scene
from .progress import ProgressTracker
from .readout import readout_of
from .result import RunResult, RunStatus
from .stability import exact_least_stable, physical_sampling, physical_step, stderr_notice
from .trackers import (
    CallbackTracker,
    CheckpointTracker,
    DivergenceGuard,
    HistoryTracker,
    OutcomeTracker,
    PeriodicTracker,
    PowerBalanceTracker,
    SignalTracker,
    SnapshotTracker,
    SteadyStateTracker,
    Stop,
    Tracker,
)

CHECKS_PER_TRANSIT = 4  # checks per transit time L / c
#: A warm-up that takes longer than this (s) compiles the kernels; loading them from
#: numba's cache takes a fraction of a second
COMPILING_AFTER = 2.0
COMPILE_NOTICE = ("beltsim: compiling the numba kernels, once per install (30 to 40 s on "
                  "2 cores; later runs load them from the cache)")
CHECKS_PER_PERIOD = 32  # at least, for a periodic drive (its extremes are read at checks)


class Simulation:
    """A scene on its grid, from rest, with the scheme its numerics name.

    :meth:`run` steps it to steady state (or t_end) and returns a :class:`RunResult`;
    :func:`beltsim.run` does both and attaches the exact steady solution.

    Parameters
    ----------
    scene : Scene
        The scene.
    grid : Grid, optional
        A grid of its own (default: the one the scene's numerics describe).
    snapshot_interval : float, optional
        Store the state every so many seconds of simulated time (default the scene's
        ``numerics.snapshot_interval``; none without it).
    loads : beltsim.physics.discrete.Loads, optional
        Distributed loads on this grid.

    Raises
    ------
    SceneError
        Numerical settings the scene's scheme refuses.

    Examples
    --------
    >>> sim = beltsim.Simulation(beltsim.paper_scene("slip"))      # doctest: +SKIP
    >>> result = sim.run(trackers=[MyTracker()])                   # doctest: +SKIP
    """

    def __init__(self, scene: Scene, grid: Grid | None = None,
                 snapshot_interval: float | None = None, loads=None):
        self._build(scene, grid, loads)
        self.t = 0.0
        self.wall_time = 0.0
        num = self.numerics
        window = self.disc.window
        self.snapshot_interval = snapshot_interval or num.snapshot_interval
        self.check = min(window / CHECKS_PER_TRANSIT, self._sampling)
        if self.snapshot_interval:
            self.check = min(self.check, self.snapshot_interval)
        self.history = HistoryTracker(self.readout.history_keys)
        period = period_of(scene)
        if period is None:
            self.steady = SteadyStateTracker(num.steady_tol, window, num.settle_time,
                                             self.readout.monitor_scale)
        else:  # checks at equal phases of the period
            samples = max(CHECKS_PER_PERIOD, math.ceil(period / self.check))
            self.check = period / samples
            self.steady = PeriodicTracker(num.steady_tol, period, samples, num.settle_time,
                                          self.readout.monitor_scale,
                                          self.readout.periodic_keys,
                                          self.readout.second_scale)
        # chunks end on the drive's table rows, where its rate jumps
        self.breaks = np.array(profile_times(scene))
        self.snapshots = (SnapshotTracker(self.snapshot_interval, self.readout.snapshot_keys)
                          if self.snapshot_interval else None)
        self.power = (PowerBalanceTracker() if hasattr(self.scheme, "work_integrals")
                      and not self.disc.closed else None)
        self._measured = self._solution = None

    arm_solves = 0  # the steady solves of a tensioner's search for its arm's rest angle

    def _build(self, scene, grid=None, loads=None):
        self.disc = solvers.discretise(scene, grid)
        if loads is not None:  # distributed loads (physics.discrete.Loads) on this grid
            self.disc.loads = loads
        self.readout = readout_of(self.disc)
        self.scheme = solvers.get(self.disc.numerics.integrator)(self.disc)
        self._sampling = math.inf  # a physical transient's checks resolve its modes
        if self.disc.numerics.transient == "physical":
            found = exact_least_stable(scene, stderr_notice(sys.stderr.isatty()))
            self.scheme.max_step = physical_step(found, self.disc.numerics.integrator)
            self._sampling = physical_sampling(found)
        self.state = self.disc.new_state()
        self._measured = self._solution = None

    # views ------------------------------------------------------------
    @property
    def scene(self) -> Scene:
        """The scene."""
        return self.disc.scene

    @property
    def params(self):
        """The scene's physical data (``scene.params``)."""
        return self.disc.params

    @property
    def numerics(self):
        """The resolved numerical settings the scheme runs with."""
        return self.scheme.numerics

    @property
    def grid(self):
        """The grid (:class:`beltsim.physics.grid.Grid`)."""
        return self.disc.grid

    @property
    def steps(self) -> int:
        """Time steps taken so far."""
        return self.scheme.steps

    def total_friction(self) -> float:
        """The state's total friction now (N), the sum of the nodal friction forces."""
        return float(self.state.fnode.sum())

    def monitor(self) -> float:
        """What the steady test watches now: the total friction (N) of an open layout,
        the driver's torque (N m) of a drive."""
        return self._measure()[0]

    def rate(self) -> float:
        """Largest local rate, relative to the layout's scales (c abs(e0) on an open
        layout, per unit length for theta; a drive's speeds and the creep speed)."""
        return self._measure()[1]

    def _measure(self):
        if self._measured is None:
            self._measured = (self.readout.monitor(self.state), self.readout.rate(self.state))
        return self._measured

    def solution(self):
        """The state now, read as a solution (fields, totals, the layout's figures); one
        object a check (the trackers read it in turn), made anew after the state moves."""
        if self._solution is None:
            # a steady solve's state is the final drive's, whatever the clock says
            self._solution = self.readout.solution(self.state, self.t,
                                                   self.scheme.transient)
        return self._solution

    # stepping ---------------------------------------------------------
    def warm_up(self, notice: bool = False) -> float:
        """Compile (or load from numba's cache) the kernels; returns the seconds it took.

        With ``notice``, a warm-up still going after ``COMPILING_AFTER`` seconds says
        on stderr that it compiles (the first run after an install waits that long).
        """
        timer = threading.Timer(COMPILING_AFTER, print, (COMPILE_NOTICE,),
                                {"file": sys.stderr, "flush": True}) if notice else None
        if timer is not None:
            timer.daemon = True
            timer.start()
        try:
            return self.scheme.warm_up(self.state)
        finally:
            if timer is not None:
                timer.cancel()

    def advance(self, t_stop: float, max_steps: int = 10**9) -> None:
        """Step until t >= t_stop (transient schemes); raises NumericalError on failure."""
        self.t = self.scheme.advance(self.state, self.t, t_stop, max_steps)
        self._measured = self._solution = None

    def trackers(self, progress=False, handle_signals=False, callback=None,
                 checkpoint=None, extra=()) -> list[Tracker]:
        """The trackers of a run, in the order they handle each check.

        The divergence guard first, then the records (history, power, snapshots), the
        user's ``extra`` trackers, the progress bar, the steady-state test, and the
        stop requests (callback, signals) and the checkpoint last.
        """
        out: list[Tracker] = [DivergenceGuard(), OutcomeTracker(), self.history]
        if self.power is not None:
            out.append(self.power)
        if self.snapshots is not None:
            out.append(self.snapshots)
        out.extend(extra)
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
            handle_signals: bool = False, callback=None, checkpoint=None,
            trackers=()) -> RunResult:
        """Run from the current state until steady (or t_end).

        The analytic reference is not attached: :func:`beltsim.run` does that.

        Parameters
        ----------
        progress : bool, optional
            Show a progress bar (a widget in Jupyter with ipywidgets, text elsewhere),
            and a notice on stderr while a first run compiles the kernels.
        raise_on_failure : bool, optional
            Raise :class:`~beltsim.errors.NumericalError` on a numerical failure; when
            False, return a result with status FAILED and the last good state.
        handle_signals : bool, optional
            SIGINT and SIGTERM stop the run cleanly between chunks (status
            INTERRUPTED), as in the CLI.
        callback : callable, optional
            ``callback(sim)`` after every chunk; a true return value stops the run
            (status INTERRUPTED).
        checkpoint : str or Path, optional
            Where an interrupted or failed run stores what :meth:`resume` needs.
        trackers : sequence of Tracker, optional
            The user's own trackers (:class:`beltsim.Tracker` subclasses), called at
            every check after the run's records and before its steady-state test.

        Returns
        -------
        RunResult

        Raises
        ------
        NumericalError
            On a numerical failure, with ``raise_on_failure``.
        TypeError
            A tracker that is not a :class:`beltsim.Tracker`, or a ``handle`` that
            returns something other than None or a :class:`Stop`.
        """
        trackers = _user_trackers(trackers)
        # the notice where someone watches: a progress bar asked for, or a terminal
        compile_time = self.warm_up(notice=progress or sys.stderr.isatty())
        if not self.scheme.transient:
            return self._run_steady(raise_on_failure, compile_time, trackers)
        trackers = self.trackers(progress, handle_signals, callback, checkpoint, trackers)
        for tr in trackers:
            tr.initialize(self)
        t_end = self.numerics.t_end
        status, reason, failure = RunStatus.REACHED_END, None, None
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
                    status, reason = _stop_of(tr, stop, self.t)
                    break
        except NumericalError as exc:
            status, reason, failure = RunStatus.FAILED, str(exc), exc.kind
            if raise_on_failure:
                raise
        finally:
            self.wall_time += time.perf_counter() - start
            for tr in trackers:
                tr.finalize(self, status)
        if status is RunStatus.REACHED_END:
            reason = self.steady.not_steady(t_end)
        return self._result(status, reason, compile_time, failure)

    def _restore(self, good):
        state, t, scheme = good
        self.state.assign(state)
        self.t = t
        self.scheme.restore(scheme)
        self._measured = self._solution = None

    def _run_steady(self, raise_on_failure, compile_time, trackers=()):
        # a steady solve makes no checks: its trackers start and end around it
        for tr in trackers:
            tr.initialize(self)
        start = time.perf_counter()
        status, reason, failure = RunStatus.CONVERGED, None, None
        try:
            if self.disc.closed and self.params.tensioner is not None:
                self._solve_arm()
            else:
                self.scheme.solve(self.state)
        except NumericalError as exc:
            status, reason, failure = RunStatus.FAILED, str(exc), exc.kind
            if raise_on_failure:
                raise
        finally:
            self.wall_time = time.perf_counter() - start
            self._measured = self._solution = None
            for tr in trackers:
                tr.finalize(self, status)
        return self._result(status, reason, compile_time, failure)

    def _solve_arm(self):
        """The steady state with a tensioner's arm at rest: a steady solve of the layout
        with the arm turned by beta (the same belt), for each beta of a root search on
        the arm's torque (:func:`beltsim.beltdrive.tensioner.equilibrium`) started at the
        creep theory's rest angle; the grid follows the layout, so each beta has its own
        discretisation."""
        from ..beltdrive.exact import string_state
        from ..beltdrive.figures import hub_loads
        from ..beltdrive.tensioner import equilibrium
        from ..errors import NoSolutionError

        scene, P = self.scene, self.params
        try:
            beta0 = string_state(P).arm_travel - P.arm_turn
        except NoSolutionError:
            beta0 = 0.0
        solved = []

        def at(beta):
            self._build(scene.at_arm(beta))
            self.scheme.solve(self.state)
            solved.append(beta)
            return self.solution()

        def hub(sol):
            Q = sol.params
            return hub_loads(Q.layout, Q.rho, sol.c, sol.span_tensions())[P.tensioner.index]

        # the beam's and the grid's arm angle differ from the creep theory's by their
        # errors in the tensions: a first step of 1e-6 rad brackets the root at once
        beta, _ = equilibrium(P.tensioner, P.layout, at, hub, beta0, step=1e-6, xtol=1e-12)
        if solved[-1] != beta:
            at(beta)
        self.arm_solves = len(solved)

    def _result(self, status, reason, compile_time, failure=None) -> RunResult:
        return RunResult(
            scene=self.scene, numerics=self.numerics, status=status, reason=reason,
            failure=failure,
            time_accurate=self.scheme.time_accurate,
            solution=self.solution(), simulated_time=self.t, wall_time=self.wall_time,
            compile_time=compile_time,
            statistics=self.scheme.statistics() | ({"arm_solves": self.arm_solves}
                                                   if self.arm_solves else {}),
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
    def resume(cls, path) -> Simulation:
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


def _user_trackers(trackers) -> list[Tracker]:
    """The user's trackers as a list, each checked to be a Tracker."""
    out = list(trackers or ())
    for tr in out:
        if not isinstance(tr, Tracker):
            raise TypeError(f"trackers: each must be a beltsim.Tracker (a subclass with "
                            f"initialize, handle, finalize), got {tr!r}")
    return out


def _stop_of(tracker: Tracker, stop, t: float):
    """The status and reason of the run a tracker's ``handle`` stopped at time t."""
    if not isinstance(stop, Stop):
        raise TypeError(f"{type(tracker).__name__}.handle: must return None or a "
                        f"beltsim.Stop, got {stop!r}")
    reason = stop.reason
    if reason is None and stop.status is not RunStatus.CONVERGED:
        reason = f"stopped by {type(tracker).__name__} at t = {t:.6g} s"
    return stop.status, reason


def run(scene: Scene, progress: bool = False, raise_on_failure: bool = True,
        snapshot_interval: float | None = None, trackers=()) -> RunResult:
    """Run a scene from rest to steady state and attach its exact steady solution.

    Parameters
    ----------
    scene : Scene
        The scene; its ``numerics`` choose the scheme and the grid.
    progress : bool, optional
        Show a progress bar (a widget in Jupyter with ipywidgets, text elsewhere),
        and a notice on stderr while a first run compiles the kernels.
    raise_on_failure : bool, optional
        Raise on a numerical failure (default); when False, return a result with
        status FAILED holding the last good state.
    snapshot_interval : float, optional
        Store the state every so many seconds of simulated time
        (``result.snapshots``); default the scene's ``numerics.snapshot_interval``.
    trackers : sequence of Tracker, optional
        The user's own trackers (:class:`beltsim.Tracker`), called at every check.

    Returns
    -------
    RunResult
        With ``reference``, the exact steady solution, where the scene has one.
        :func:`beltsim.run` takes a closed drive as well, a shipped scene's name or a
        file's path.

    Raises
    ------
    NumericalError
        On a numerical failure, with ``raise_on_failure``.
    SceneError
        Numerical settings the scene's scheme refuses.

    Examples
    --------
    >>> result = beltsim.run(beltsim.paper_scene("slip"), progress=True)  # doctest: +SKIP
    >>> result.converged, result.errors()["total_friction"]              # doctest: +SKIP
    """
    sim = Simulation(scene, snapshot_interval=snapshot_interval)
    result = sim.run(progress=progress, raise_on_failure=raise_on_failure, trackers=trackers)
    result.reference = sim.readout.reference()
    return result
