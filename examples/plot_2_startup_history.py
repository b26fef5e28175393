"""
A start-up, from rest to steady state
=====================================

The surface speeds up smoothly from the belt speed c to v over the ramp time; the
friction drags the contact along, a slip zone opens at x2 and grows upstream, and the
free spans ring until the damping settles them. ``result.history`` holds the friction
totals at every check of the run as arrays, and :func:`beltsim.plot_history` draws them
on the axes it is given.
"""

import matplotlib.pyplot as plt

import beltsim

slip = beltsim.run(beltsim.paper_scene("slip"))
stick = beltsim.run(beltsim.paper_scene("inertia"))
for name, res in (("paper slip", slip), ("paper inertia", stick)):
    h = res.history
    print(f"{name}: steady at t = {h['t'][-1]:.3f} s after {len(h['t'])} checks, "
          f"total friction {h['total_friction'][-1]:.1f} N")

# %%
# Left, stick and slip: the total friction with its stick and slip parts, and the slip
# start. Right, perfect adhesion: the total friction and the concentrated force at x2.
# The exact steady values are dashed.

fig, axes = plt.subplots(2, 2, figsize=(10, 6), sharex=True, layout="constrained")
beltsim.plot_history(slip, keys=("total_friction", "slip_start"), ax=axes[:, 0])
beltsim.plot_history(stick, keys=("total_friction", "concentrated_force"), ax=axes[:, 1])
axes[0, 0].set_title("stick and slip (paper_slip)", fontsize=10)
axes[0, 1].set_title("perfect adhesion (paper_inertia)", fontsize=10)
axes[0, 0].set_xlim(0.0, 0.15)
plt.show()
