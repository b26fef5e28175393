"""Steady-state detection.

A state is steady when, over ``hold`` consecutive checks after the ramp,
both the local rates (max |u_t| and L max |theta_t|, relative to c |e0|) and the
change of the total friction over a window of simulated time (relative to its
value) stay below the tolerance.
"""

from __future__ import annotations

from collections import deque


class SteadyDetector:
    def __init__(self, tol: float, window: float, t_min: float, hold: int = 3):
        self.tol = tol
        self.window = window
        self.t_min = t_min
        self.hold = hold
        self._hist: deque = deque()
        self._count = 0
        self.change = float("inf")

    def update(self, t: float, rate: float, total_friction: float, friction_scale: float) -> bool:
        """Record a check; True once the state has been steady ``hold`` times in a row."""
        self._hist.append((t, total_friction))
        while len(self._hist) > 1 and self._hist[1][0] <= t - self.window:
            self._hist.popleft()
        t0, f0 = self._hist[0]
        if t - t0 >= self.window * (1 - 1e-9):
            denom = max(abs(total_friction), friction_scale)
            self.change = abs(total_friction - f0) / denom
        else:
            self.change = float("inf")
        if t >= self.t_min and rate < self.tol and self.change < self.tol:
            self._count += 1
        else:
            self._count = 0
        return self._count >= self.hold
