"""
A start-up, from rest to steady state
=====================================

The surface speeds up smoothly from the belt speed c to v over the ramp time; the
friction drags the contact along, a slip zone opens at x2 and grows upstream, and the
free spans ring until the damping settles them. ``result.history`` holds the friction
totals at every check of the run as arrays.
"""

import matplotlib.pyplot as plt

import beltsim

slip = beltsim.run(beltsim.paper_scene("slip"))
stick = beltsim.run(beltsim.paper_scene("inertia"))
print(f"paper slip: steady at t = {slip.simulated_time:.3f} s; "
      f"paper inertia: steady at t = {stick.simulated_time:.3f} s")

# %%
# The total friction of both scenes against its exact steady value, and the slip
# start of the Coulomb scene against the exact steady x*.

fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7, 6), sharex=True, constrained_layout=True)
for res, color, name in ((slip, "tab:red", "stick and slip"),
                         (stick, "tab:blue", "perfect adhesion")):
    h = res.history
    ax1.plot(h["t"], h["total_friction"], color=color, lw=1.2, label=name)
    ax1.axhline(res.reference.total_friction, color=color, ls="--", lw=0.8)
ax1.set_ylabel("total friction [N]")
ax1.legend()
ax1.grid(alpha=0.3)
h = slip.history
ax2.plot(h["t"], h["slip_start"], color="tab:red", lw=1.2, label="simulated")
ax2.axhline(slip.reference.x_star, color="tab:red", ls="--", lw=0.8, label="exact steady")
ax2.set_ylabel("slip start x* [m]")
ax2.set_xlabel("t [s]")
ax2.legend()
ax2.grid(alpha=0.3)
plt.show()
