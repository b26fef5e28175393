"""The run's progress bar: simulated time toward the estimated time of steady state.

A run ends when its steady test passes, usually long before t_end (paper_slip: at 0.43 s
of 3.35 s), so a bar out of t_end ends at about a tenth. The bar's total here is the
simulated time at which the steady test is expected to pass (:class:`SteadyEstimate`),
from the decay of the test's own measure; it ends full when the run becomes steady.
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np

from .result import RunStatus
from .trackers import Tracker, progress_bar

#: The decay is fitted over this many of the steady test's windows (or periods)
FIT_WINDOWS = 4
#: and needs at least this many checks in them
FIT_POINTS = 4


class SteadyEstimate:
    """When the steady test will pass, from the decay of its measure.

    The steady test passes once its measure (the largest of the relative rate and the
    relative change over a window; a periodic drive's change between periods) stays below
    ``tol`` for ``hold`` checks after ``t_min``. Such a measure decays about
    exponentially as the transient dies out: the log of the measure is fitted by a line
    over the last FIT_WINDOWS windows, and extrapolated to ``tol``.

    Parameters
    ----------
    tol, t_min, hold, check : float, float, int, float
        The steady test's tolerance, earliest time and checks in a row; the checks'
        interval (s).
    window : float
        The steady test's window (s): the fit's span is FIT_WINDOWS of them.
    t_end : float
        The run's end: no estimate goes beyond it.
    """

    def __init__(self, tol, t_min, hold, check, window, t_end):
        self.tol, self.t_min, self.hold, self.check = tol, t_min, hold, check
        self.span, self.t_end = FIT_WINDOWS * window, t_end
        self._points: deque = deque()

    def update(self, t: float, measure: float) -> float | None:
        """Record the measure at t; returns the estimated time of steady state (s), or
        None while the measure does not decay (or is not yet defined)."""
        if not (math.isfinite(measure) and measure > 0.0):
            return None
        self._points.append((t, math.log(measure)))
        while self._points and self._points[0][0] < t - self.span:
            self._points.popleft()
        earliest = max(self.t_min, t) + self.hold * self.check
        if measure < self.tol:
            return min(earliest, self.t_end)
        if len(self._points) < FIT_POINTS:
            return None
        ts, ys = np.array(self._points).T
        slope = np.polyfit(ts - t, ys, 1)[0]
        if not slope < 0.0:
            return None
        reach = t + (math.log(measure) - math.log(self.tol)) / -slope
        return min(max(reach + self.hold * self.check, earliest), self.t_end)


def set_total(bar, total: float) -> None:
    """Change a tqdm bar's total, in a terminal or as a Jupyter widget (whose bar keeps
    the total it was made with in its own ``max``)."""
    bar.total = total
    container = getattr(bar, "container", None)
    if container is not None:
        container.children[1].max = total


class ProgressTracker(Tracker):
    """A progress bar of simulated time toward the estimated steady state (or t_end),
    with the steady test's measure and the monitored quantity.

    A widget in Jupyter with ipywidgets (the ``notebook`` extra), else text
    (:func:`~beltsim.simulation.trackers.progress_bar`): on a terminal, in a notebook
    without ipywidgets, or in whatever takes stderr (the CLI asks for it only on a
    terminal). The total starts at t_end and follows :class:`SteadyEstimate` once the
    measure decays; a run that becomes steady ends full. In a terminal the bar goes
    when done, for every layout; in a notebook it stays.
    """

    def __init__(self):
        self.bar = None
        self.estimate = None

    def initialize(self, sim):
        """Open the bar, its total the run's t_end until the steady test's measure decays."""
        num, steady = sim.numerics, sim.steady
        self.estimate = SteadyEstimate(steady.tol, steady.t_min, steady.hold, sim.check,
                                       steady.span, num.t_end)
        self.bar = progress_bar(total=num.t_end, initial=sim.t, unit="s",
                                unit_scale=True, desc="to steady", leave=False,
                                bar_format="{l_bar}{bar}| {n:.4g}/{total:.4g} s "
                                           "[{elapsed}<{remaining}]{postfix}")

    def handle(self, sim):
        """Move the bar to the check's time, its total to the estimated steady time."""
        if self.bar is None:
            return None
        t = min(sim.t, sim.numerics.t_end)
        # the steady test comes after this tracker: its measure is the last check's
        reach = self.estimate.update(t, sim.steady.measure())
        if reach is not None:
            set_total(self.bar, max(reach, t))
        self.bar.update(t - self.bar.n)
        self.bar.set_postfix(steady=f"{sim.steady.measure():.2e}",
                             monitor=f"{sim.monitor():.5g}", refresh=False)
        return None

    def finalize(self, sim, status):
        """Fill the bar where the run became steady, and close it."""
        if self.bar is None:
            return
        if status is RunStatus.CONVERGED:  # full: the estimate's end is now
            set_total(self.bar, self.bar.n)
            self.bar.refresh()
        self.bar.close()
