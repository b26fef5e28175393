"""
A tracker of your own: the slip zone opening
============================================

A run stops at every check (a quarter of the transit time L/c) to record its history
and test for steady state. A :class:`beltsim.Tracker` of your own is called there too.
This one keeps the friction traction along the contact at every check, and ends the run
with :class:`beltsim.Stop` once the slip front has stopped moving, before the run's own
steady-state test (which waits for every rate to die out) would. The scene is built from
typed sections: the paper's belt on a longer contact with a lower friction limit, on a
coarse grid to stay quick.
"""

import matplotlib.pyplot as plt
import numpy as np

import beltsim
from beltsim import Beam, Contact, Motion, NumericsSection, Physics

scene = beltsim.Scene.build(
    beam=Beam(length=1.0, height=0.1, width=0.1, youngs_modulus=5e7,
              poisson_ratio=0.45, density=1500.0, shear_factor=1.1),
    motion=Motion(belt_speed=120.0, surface_speed=121.2),
    contact=Contact(start=0.2, end=0.8, friction="coulomb", max_friction=4e4),
    physics=Physics(inertia=True, damping=39.0),
    numerics=NumericsSection(elements=240),
    title="a long contact, f* = 4e4 N/m",
)


class SlipZone(beltsim.Tracker):
    """The friction along the contact and the slip start at every check; a Stop once
    the slip start has moved less than ``tol`` metres over the last ``span`` checks."""

    def __init__(self, tol=1e-5, span=8):
        self.tol, self.span = tol, span

    def initialize(self, sim):
        P = sim.params
        self.on = (sim.grid.x >= P.x1) & (sim.grid.x <= P.x2)
        self.t, self.x_star, self.friction = [], [], []

    def handle(self, sim):
        sol = sim.solution()
        self.t.append(sim.t)
        self.x_star.append(sol.slip_start)
        self.friction.append(sol.fields()["friction"][self.on])
        recent = self.x_star[-self.span:]
        ramped = sim.t > sim.numerics.ramp_time
        if ramped and len(recent) == self.span and np.ptp(recent) < self.tol:
            return beltsim.Stop(reason=f"slip front settled at t = {sim.t:.3f} s")
        return None


watch = SlipZone()
result = beltsim.run(scene, trackers=[watch])
print(result.status.value, "-", result.reason)
print(f"slip start {watch.x_star[-1]:.5f} m, exact {result.reference.x_star:.5f} m")

# %%
# The traction along the contact at the checks of the first 30 ms, coloured by time,
# against the exact steady traction (dashed): the slip zone opens at x2 and runs
# upstream as the surface speeds up over the ramp (2 L/c = 17 ms). Below, the slip
# start at every check against its exact steady value.

x = result.x[watch.on]
early = [k for k, t in enumerate(watch.t) if t <= 0.03]
norm = plt.Normalize(0.0, 1e3 * watch.t[early[-1]])
fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7, 7), layout="constrained")
for k in early:
    ax1.plot(x, watch.friction[k], color=plt.cm.viridis(norm(1e3 * watch.t[k])), lw=0.9)
x_exact, exact = result.reference.sample(1201)
ax1.plot(x_exact, exact["friction"], "k--", lw=1.2, label="exact steady state")
fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap="viridis"), ax=ax1, label="t [ms]")
ax1.set_xlim(scene.contact.start, scene.contact.end)
ax1.set_xlabel("x [m]")
ax1.set_ylabel("friction f [N/m]")
ax1.legend()
ax1.grid(alpha=0.3)
ax2.plot(watch.t, watch.x_star, "o-", ms=3, label="tracked")
ax2.axhline(result.reference.x_star, color="k", ls="--", lw=1.0, label="exact steady")
ax2.set_xlabel("t [s]")
ax2.set_ylabel("slip start x* [m]")
ax2.legend()
ax2.grid(alpha=0.3)
plt.show()
