"""
Flutter: an unstable steady state grows and saturates
=====================================================

The paper's inertial steady states are unstable in the model: a stick zone carries the
bottom fibre's displacement to its exit, where the friction force feeds it back into the
spans (theory: *Linear stability*, "The delay loop, and what saturates it"). Every run
says so in its summary. The default run (``numerics.transient = "fast"``) still settles,
because its scheme damps the growing modes by hundreds of 1/s; a physical transient
(``numerics.transient = "physical"``) keeps that damping below a tenth of the least stable
rate and follows the growth.

Here paper_slip without damping (d = 0, where the growth is fastest) starts from its
discrete steady state, perturbed by 3 % of its displacement, and runs for one simulated
second on a coarse grid (100 elements, to stay quick; the flutter page converges it on
finer ones). The friction leaves its steady distribution, the slip front starts to move,
and the growth stops when the stick zone has shrunk and slides at its exit: a limit cycle.
"""

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.animation import FuncAnimation

import beltsim
from beltsim.simulation.stability import exact_least_stable
from beltsim.studies.flutter import flutter_run

scene = beltsim.load_scene("paper_slip").with_overrides({"physics.damping": 0.0})
root = exact_least_stable(scene)
print(root.describe())


class FrictionFrames(beltsim.Tracker):
    """The friction traction along the contact and the slip start, every ``interval`` s
    of simulated time."""

    def __init__(self, interval):
        self.interval = interval

    def initialize(self, sim):
        P = sim.params
        self.on = (sim.grid.x >= P.x1) & (sim.grid.x <= P.x2)
        self.x = sim.grid.x[self.on]
        self.t, self.friction, self.front = [], [], []

    def handle(self, sim):
        if self.t and sim.t < self.t[-1] + self.interval * (1 - 1e-9):
            return None
        sol = sim.solution()
        self.t.append(sim.t)
        self.friction.append(sol.fields()["friction"][self.on])
        self.front.append(sol.slip_start)
        return None


frames = FrictionFrames(interval=0.02)
run = flutter_run(scene, 1.0, elements=100, from_steady=0.03, trackers=[frames])
cycle = run.limit_cycle()
print(f"{run.steps} steps of at most {run.step:.2e} s, wall {run.wall_time:.1f} s")
print(f"limit cycle over the last 0.2 s: total friction +- {cycle['friction']:.1%}, "
      f"slip front between {cycle['front_range'][0]:.3f} and {cycle['front_range'][1]:.3f} m")

# %%
# The envelope of the total friction's deviation from its steady value, per 20 ms
# window: after the start's transient it grows exponentially (the fitted line), then
# levels off. The rate on this coarse grid differs from the exact root's by its
# discretisation error, which is large on 100 elements (the flutter page follows the
# rate and the cycle on finer grids).
centres, peaks = run.envelope()
t0, t1 = 0.15, 0.45
rate = run.growth(t0, t1)
print(f"growth from {t0} to {t1} s: {rate:.1f} 1/s on 100 elements; the exact least "
      f"stable root: {root.rate:.1f} 1/s at {root.frequency:.0f} Hz")
fig, ax = plt.subplots(figsize=(7, 3.5), constrained_layout=True)
ax.semilogy(centres, peaks, "o-", ms=3, label="largest |F - F_s| / F_s per window")
fit = (centres >= t0) & (centres <= t1)
level = np.mean(np.log(peaks[fit]) - rate * centres[fit])  # the fit's intercept
ts = np.linspace(t0, t1, 20)
ax.semilogy(ts, np.exp(level + rate * ts), "k--", label=f"fitted growth: {rate:.1f} 1/s")
ax.set_xlabel("t [s]")
ax.set_ylabel("deviation of the total friction")
ax.set_title("paper_slip, d = 0: growth and saturation")
ax.legend(loc="lower right")
plt.show()

# %%
# The friction traction along the contact every 20 ms of simulated time, against the
# steady state (grey): the oscillation grows from the stick zone's exit until the slip
# front moves with it.
fig2, ax2 = plt.subplots(figsize=(7, 3.5), dpi=72, constrained_layout=True)
F = np.array(frames.friction)
ax2.plot(frames.x, F[0], color="0.6", lw=2, label="steady state (start)")
line, = ax2.plot(frames.x, F[0], color="C0", label="friction traction")
front = ax2.axvline(frames.front[0], color="C3", ls=":", label="slip start")
label = ax2.text(0.02, 0.92, "", transform=ax2.transAxes)
ax2.set_ylim(1.15 * F.min() if F.min() < 0 else 0.0, 1.15 * F.max())
ax2.set_xlabel("x [m]")
ax2.set_ylabel("friction [N/m]")
ax2.legend(loc="lower left")


def draw(i):
    line.set_ydata(F[i])
    front.set_xdata([frames.front[i]] * 2)
    label.set_text(f"t = {frames.t[i]:.2f} s")
    return line, front, label


animation = FuncAnimation(fig2, draw, frames=len(F), interval=120, blit=True)
plt.show()
