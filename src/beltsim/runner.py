"""The run loop: compiled time stepping between Python-level checks.

As in py-pde's controller, a compiled kernel advances the state over one check
interval of simulated time; between intervals Python-level trackers record the
history, take snapshots, test for steady state and for divergence, and update
the progress bar.
"""

from __future__ import annotations

import dataclasses
import time
import tomllib
from dataclasses import dataclass, field

import numpy as np

from . import analytic
from .errors import NumericalError
from .integrators import (FAILED, NONFINITE, Workspace, advance_explicit, advance_implicit,
                          solve_steady)
from .model import P_TRAMP
from .numerics import Numerics, build_grid, pack, resolve, scales, with_explicit_step
from .scene import Scene
from .solution import DiscreteSolution, compare
from .steady import SteadyDetector

GROWTH_LIMIT = 1e4  # |u| / (|e0| L) or |theta| / |e0| beyond this counts as divergence


@dataclass
class RunResult:
    scene: Scene
    numerics: Numerics
    solution: DiscreteSolution
    reference: analytic.AnalyticSolution | None
    converged: bool
    simulated_time: float
    steps: int
    wall_time: float
    history: dict
    reason: str | None = None
    failed: bool = False  # stopped on a numerical failure (else: converged or reached t_end)
    snapshots: dict = field(default_factory=dict)
    newton_iterations: int = 0
    compile_time: float = 0.0
    interrupted: bool = False

    def errors(self) -> dict | None:
        if self.reference is None:
            return None
        return compare(self.solution, self.reference)

    def summary(self) -> dict:
        out = self.solution.summary()
        out.update(converged=self.converged, simulated_time=self.simulated_time,
                   steps=self.steps, wall_time=self.wall_time, compile_time=self.compile_time,
                   reason=self.reason,
                   elements=self.numerics.elements, integrator=self.numerics.integrator,
                   error=self.errors())
        return out


class Simulation:
    """A scene on its grid, from rest. ``run()`` steps it to steady state."""

    def __init__(self, scene: Scene, grid=None):
        self.scene = scene
        self.params = scene.params
        self.numerics = resolve(scene)
        if grid is not None:  # a given grid (e.g. a bisected one); elements follow it
            self.numerics = dataclasses.replace(self.numerics, elements=grid.n_elements)
        self.grid = grid if grid is not None else build_grid(scene, self.numerics)
        if self.numerics.integrator == "explicit":
            self.numerics = with_explicit_step(scene, self.numerics, self.grid)
        self.prm, self.iprm = pack(self.params, self.numerics, self.grid)
        self.scales = scales(self.params)
        N = self.grid.n_elements
        self.he, self.hb = self.grid.he, self.grid.hbar
        self.u = np.zeros(N + 1)
        self.theta = np.zeros(N + 1)
        # contact nodes: friction ratio g(v_rel / v_reg) (implicit), or the argument
        # v_rel / v_reg itself (explicit: the warm start of the per-node friction solve)
        self.lam = np.zeros(N + 1)
        self.ud = np.zeros(N + 1)
        self.td = np.zeros(N + 1)
        self.t = 0.0
        self.steps = 0
        self.dt = self.numerics.dt
        self.wall_time = 0.0
        self.work = Workspace(N)

    # ------------------------------------------------------------------
    def rate(self) -> float:
        """Largest local rate, relative to c |e0| (per unit length for theta)."""
        P = self.params
        v = P.c * self.scales[3]
        return float(max(np.max(np.abs(self.ud)), P.L * np.max(np.abs(self.td))) / v)

    def state(self) -> DiscreteSolution:
        return DiscreteSolution(self.params, self.grid, self.u, self.theta, self.work.fnode,
                                self.numerics.law_code, self.numerics.fs, self.ud, self.td)

    def warm_up(self) -> float:
        """Compile (or load from numba's cache) the kernels; returns the seconds it took."""
        start = time.perf_counter()
        if self.numerics.integrator == "steady":
            w, z = self.work, np.zeros_like(self.u)
            solve_steady(self.u, self.theta, self.lam, self.he, self.hb, self.prm, self.iprm,
                         self.scales, 1.0, 0, z, z, z, z, w.R, w.Lb, w.Db, w.Ub, w.C, w.dx,
                         w.u_try, w.th_try, w.fnode, w.rl, w.sg, w.stats, 0.0)
            w.stats[:] = 0.0
        else:
            self.advance(self.t, max_steps=0)
        return time.perf_counter() - start

    def advance(self, t_stop: float, max_steps: int = 10**9):
        """Step until t >= t_stop; raises NumericalError on failure."""
        num = self.numerics
        if num.integrator == "explicit":
            t, steps = advance_explicit(self.u, self.theta, self.ud, self.td, self.lam, self.t,
                                        t_stop, num.dt, max_steps, self.he, self.hb, self.prm,
                                        self.iprm, self.work.fnode)
            self.t, self.steps = t, self.steps + steps
            if not (np.all(np.isfinite(self.u)) and np.all(np.isfinite(self.theta))):
                raise NumericalError(f"non-finite displacement or rotation at t = {t:.6g} s",
                                     t=t, quantity="u/theta")
            self._check_growth()
            return
        status, t, dt, steps = advance_implicit(
            self.u, self.theta, self.lam, self.ud, self.td, self.t, t_stop, self.dt, num.dt, max_steps,
            self.he, self.hb, self.prm, self.iprm, self.scales, num.newton_tol,
            num.newton_max_it, *self.work.arrays())
        self.t, self.dt, self.steps = t, dt, self.steps + steps
        if status == FAILED:
            raise NumericalError(
                f"Newton iteration failed at t = {t:.6g} s even with the step cut to "
                f"dt = {dt:.3g} s (residual norm {self.work.stats[3]:.3g})", t=t,
                quantity="newton")
        if status == NONFINITE:
            raise NumericalError(f"non-finite displacement or rotation at t = {t:.6g} s",
                                 t=t, quantity="u/theta")
        self._check_growth()

    def _check_growth(self):
        s = self.scales
        gu = np.max(np.abs(self.u)) / s[2]
        gt = np.max(np.abs(self.theta)) / s[3]
        if gu > GROWTH_LIMIT or gt > GROWTH_LIMIT:
            q, g = ("u", gu) if gu >= gt else ("theta", gt)
            raise NumericalError(
                f"{q} grew without bound at t = {self.t:.6g} s ({g:.3g} times its scale)",
                t=self.t, quantity=q)

    # ------------------------------------------------------------------
    STATE = ("u", "theta", "lam", "ud", "td")

    def _trackers(self, snapshot_interval):
        """History, steady detector and snapshots: attributes, so a resumed run keeps them."""
        if hasattr(self, "detector"):
            return
        num, P = self.numerics, self.params
        window = P.L / P.c
        self.check = window / 4.0
        self.snap_dt = snapshot_interval or num.snapshot_interval
        if self.snap_dt:
            self.check = min(self.check, self.snap_dt)
        self.detector = SteadyDetector(num.steady_tol, window, t_min=num.ramp_time)
        self.history = {"t": [], "total_friction": [], "rate": []}
        self.snaps = _Snapshots(self) if self.snap_dt else None
        if self.snaps is not None:
            self.snaps.take()
        self.wall_time = 0.0

    def _copy_state(self):
        return [getattr(self, k).copy() for k in self.STATE] + [self.work.fnode.copy(), self.t,
                                                                 self.steps, self.dt]

    def _restore_state(self, saved):
        for k, arr in zip(self.STATE, saved):
            getattr(self, k)[:] = arr
        self.work.fnode[:] = saved[len(self.STATE)]
        self.t, self.steps, self.dt = saved[len(self.STATE) + 1:]

    def run(self, progress: bool = False, raise_on_failure: bool = True,
            snapshot_interval: float | None = None, handle_signals: bool = False,
            callback=None) -> RunResult:
        """Run from the current state until steady (or t_end); compare with the analytic state.

        Between chunks of simulated time the trackers record the history, take snapshots
        and test for steady state. On a numerical failure the state goes back to the last
        good check (never a NaN state). With ``handle_signals`` (the CLI), SIGINT and
        SIGTERM stop the run cleanly between chunks: ``result.interrupted`` is set and
        :meth:`save_checkpoint` can store the state for :meth:`resume`. ``callback(sim)``
        is called after every chunk (a user tracker); a true return value stops the run
        the same way.
        """
        num, P = self.numerics, self.params
        if num.integrator == "steady":
            return self._run_steady(raise_on_failure)
        self._trackers(snapshot_interval)
        hist, detector, snaps = self.history, self.detector, self.snaps
        fscale = P.B * self.scales[3] * 1e-3
        compile_time = self.warm_up()
        bar = _progress(progress, num.t_end, self.t)
        converged, reason, failed, interrupted = False, None, False, False
        start = time.perf_counter()
        with _StopRequests(handle_signals) as stop:
            try:
                while self.t < num.t_end:
                    if stop.requested:
                        interrupted = True
                        reason = f"interrupted ({stop.requested}) at t = {self.t:.6g} s"
                        break
                    good = self._copy_state()
                    try:
                        self.advance(min(self.t + self.check, num.t_end))
                    except NumericalError:
                        self._restore_state(good)
                        raise
                    total = float(self.work.fnode.sum())
                    rate = self.rate()
                    hist["t"].append(self.t)
                    hist["total_friction"].append(total)
                    hist["rate"].append(rate)
                    if snaps is not None and self.t >= snaps.next_time(self.snap_dt):
                        snaps.take()
                    if bar is not None:
                        bar.update(min(self.t, num.t_end) - bar.n)
                        bar.set_postfix(rate=f"{rate:.2e}", friction=f"{total:.5g}",
                                        refresh=False)
                    if detector.update(self.t, rate, total, fscale):
                        converged = True
                        break
                    if callback is not None and callback(self):
                        stop.requested = "callback"
            except NumericalError as exc:
                reason, failed = str(exc), True
                if raise_on_failure:
                    raise
            finally:
                if bar is not None:
                    bar.close()
        self.wall_time += time.perf_counter() - start
        if snaps is not None and not interrupted and snaps.times[-1] < self.t:
            snaps.take()
        if reason is None and not converged:
            reason = (f"not steady by t_end = {num.t_end:.6g} s (rate {hist['rate'][-1]:.3g}, "
                      f"friction change {detector.change:.3g} per window; tolerance "
                      f"{num.steady_tol:.3g})")
        return self._result(converged, reason, failed, compile_time,
                            {k: np.array(v) for k, v in hist.items()},
                            snaps.arrays() if snaps is not None else {}, interrupted)

    def _result(self, converged, reason, failed, compile_time, history, snapshots,
                interrupted=False):
        try:
            ref = analytic.solve(self.scene)
        except analytic.NoSolutionError:
            ref = None
        return RunResult(
            scene=self.scene, numerics=self.numerics, solution=self.state(), reference=ref,
            converged=converged, simulated_time=self.t, steps=self.steps,
            wall_time=self.wall_time, history=history, reason=reason, failed=failed,
            snapshots=snapshots, newton_iterations=int(self.work.stats[0]),
            compile_time=compile_time, interrupted=interrupted)

    # checkpoints ------------------------------------------------------
    def save_checkpoint(self, path):
        """Store everything a resumed run needs to continue exactly as this one would."""
        import io

        from .results import write_atomic
        det = self.detector
        data = {k: getattr(self, k) for k in self.STATE}
        data.update(
            fnode=self.work.fnode, stats=self.work.stats,
            scalars=np.array([self.t, self.steps, self.dt, self.wall_time, det._count,
                              det.change, self.check, self.snap_dt or 0.0]),
            detector=np.array(list(det._hist)).reshape(-1, 2),
            hist=np.array([self.history[k] for k in ("t", "total_friction", "rate")]),
            scene=np.array(self.scene.to_toml()),
        )
        if self.snaps is not None:
            for k, v in self.snaps.arrays().items():
                data[f"snap_{k}"] = v
        buf = io.BytesIO()
        np.savez(buf, **data)
        return write_atomic(path, buf.getvalue())

    @classmethod
    def resume(cls, path) -> "Simulation":
        """A simulation restored from :meth:`save_checkpoint`."""
        from collections import deque

        from .errors import SceneError
        try:
            z = np.load(path)
            scene = Scene(tomllib.loads(str(z["scene"])))
        except (OSError, ValueError, KeyError, tomllib.TOMLDecodeError) as exc:
            raise SceneError(f"--resume: cannot read checkpoint {path} ({exc})") from None
        sim = cls(scene)
        for k in cls.STATE:
            getattr(sim, k)[:] = z[k]
        sim.work.fnode[:] = z["fnode"]
        sim.work.stats[:] = z["stats"]
        t, steps, dt, wall, count, change, check, snap_dt = z["scalars"]
        sim._trackers(snap_dt or None)
        sim.t, sim.steps, sim.dt, sim.wall_time = float(t), int(steps), float(dt), float(wall)
        sim.check = float(check)
        sim.detector._count, sim.detector.change = int(count), float(change)
        sim.detector._hist = deque(map(tuple, z["detector"]))
        for k, row in zip(("t", "total_friction", "rate"), z["hist"]):
            sim.history[k] = list(row)
        if sim.snaps is not None:
            sim.snaps.times = list(z["snap_t"])
            for k in ("u", "theta", "fnode"):
                setattr(sim.snaps, k, list(z[f"snap_{k}"]))
        return sim

    def solve_steady(self):
        """Newton on the discrete steady equations, with continuation in v - c.

        The surface speed goes from c to v through the same smooth ramp as a run,
        in stages that double after a success and shrink fourfold after a failure.
        Returns the number of stages; raises NumericalError when the stage size
        falls below 1e-6 of the full mismatch.
        """
        num = self.numerics
        w = self.work
        self.prm[P_TRAMP] = 1.0  # ramp(s, 1) is the continuation parameter
        s_done, ds, stages = 0.0, 1.0, 0
        zeros = np.zeros_like(self.u)
        try:
            while s_done < 1.0:
                s = min(1.0, s_done + ds)
                u0, th0, lam0 = self.u.copy(), self.theta.copy(), self.lam.copy()
                self.prm[P_TRAMP] = 1.0
                ok = solve_steady(self.u, self.theta, self.lam, self.he, self.hb, self.prm,
                                  self.iprm, self.scales, num.newton_tol, 4 * num.newton_max_it,
                                  zeros, zeros, zeros, zeros, w.R, w.Lb, w.Db, w.Ub, w.C, w.dx,
                                  w.u_try, w.th_try, w.fnode, w.rl, w.sg, w.stats,
                                  _stage_time(s))
                stages += 1
                if ok:
                    s_done, ds = s, 2.0 * ds
                else:
                    self.u[:], self.theta[:], self.lam[:] = u0, th0, lam0
                    ds *= 0.25
                    if ds < 1e-6:
                        raise NumericalError(
                            f"steady Newton iteration failed at {100 * s_done:.4g}% of the "
                            f"speed mismatch (continuation step below 1e-6)", t=0.0,
                            quantity="newton")
        finally:
            self.prm[P_TRAMP] = num.ramp_time
        return stages

    def _run_steady(self, raise_on_failure):
        compile_time = self.warm_up()
        start = time.perf_counter()
        reason, failed = None, False
        stages = 0
        try:
            stages = self.solve_steady()
        except NumericalError as exc:
            reason, failed = str(exc), True
            if raise_on_failure:
                raise
        self.wall_time = time.perf_counter() - start
        self.t, self.steps = 0.0, stages
        empty = {"t": np.zeros(0), "total_friction": np.zeros(0), "rate": np.zeros(0)}
        return self._result(not failed, reason, failed, compile_time, empty, {})


def _stage_time(s):
    """The ramp time at which ramp(t, 1) = s (inverse of the smoothstep)."""
    if s >= 1.0:
        return 1.0
    lo, hi = 0.0, 1.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if mid**3 * (10 - 15 * mid + 6 * mid * mid) < s:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


class _Snapshots:
    """States at (about) every snapshot interval of simulated time."""

    def __init__(self, sim: Simulation):
        self.sim = sim
        self.times, self.u, self.theta, self.fnode = [], [], [], []

    def next_time(self, interval):
        return (self.times[-1] if self.times else 0.0) + interval * (1 - 1e-9)

    def take(self):
        s = self.sim
        self.times.append(s.t)
        self.u.append(s.u.copy())
        self.theta.append(s.theta.copy())
        self.fnode.append(s.work.fnode.copy())

    def arrays(self):
        return {"t": np.array(self.times), "u": np.array(self.u),
                "theta": np.array(self.theta), "fnode": np.array(self.fnode)}


def _progress(enabled, total, initial=0.0):
    if not enabled:
        return None
    import sys

    from tqdm import tqdm
    if not sys.stderr.isatty():
        return None
    return tqdm(total=total, initial=initial, unit="s", unit_scale=True, desc="simulated",
                leave=False,
                bar_format="{l_bar}{bar}| {n:.4g}/{total:.4g} s [{elapsed}<{remaining}]{postfix}")


class _StopRequests:
    """SIGINT and SIGTERM set a flag that the run loop reads between chunks.

    A KeyboardInterrupt raised while a kernel returns could leave the time and the
    state out of step; a flag checked at a chunk boundary cannot.
    """

    def __init__(self, enabled):
        import threading
        self.enabled = enabled and threading.current_thread() is threading.main_thread()
        self.requested = None
        self._old = {}

    def __enter__(self):
        if self.enabled:
            import signal
            for sig in (signal.SIGINT, signal.SIGTERM):
                self._old[sig] = signal.signal(sig, self._handler)
        return self

    def _handler(self, signum, frame):
        import signal
        self.requested = signal.Signals(signum).name

    def __exit__(self, *exc):
        import signal
        for sig, old in self._old.items():
            signal.signal(sig, old)
        return False


def run(scene: Scene, progress: bool = False, raise_on_failure: bool = True,
        snapshot_interval: float | None = None) -> RunResult:
    """Run a scene from rest to steady state (API entry point)."""
    return Simulation(scene).run(progress=progress, raise_on_failure=raise_on_failure,
                                 snapshot_interval=snapshot_interval)
