"""
A drive profile: the friction limit drops
=========================================

The shipped ``load_drop`` scene is the paper's slip scene whose friction limit f* falls
tenfold within 0.1 ms once the start-up has settled, as when the normal force drops.
The slip front runs upstream, overshoots its new steady position and rings about it
with the free spans' axial mode until the damping settles it. The run uses a coarse
grid to stay quick, and checks the state every 0.25 ms of simulated time (through the
snapshot interval) to resolve the ringing in its history.
"""

import matplotlib.pyplot as plt

import beltsim

scene = beltsim.load_scene("load_drop", ["numerics.elements=200"])
print(scene.to_dict()["contact"]["max_friction"])  # [[time, value], ...] rows
res = beltsim.run(scene, snapshot_interval=2.5e-4)
print(res.status, f"at t = {res.simulated_time:.3f} s after {res.steps} steps")

# %%
# The slip start and the total friction over time; the exact steady state of the final
# f* is dashed, and the drop is marked.

h = {key: values[res.history["t"] >= 0.25] for key, values in res.history.items()}
fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7, 6), sharex=True, constrained_layout=True)
ax1.plot(h["t"], h["slip_start"], lw=1)
ax1.axhline(res.reference.x_star, color="k", ls="--", lw=0.8, label="exact steady, final f*")
ax1.set_ylabel("slip start x* [m]")
ax1.legend()
ax2.plot(h["t"], h["total_friction"], lw=1)
ax2.axhline(res.reference.total_friction, color="k", ls="--", lw=0.8)
ax2.set_ylabel("total friction [N]")
ax2.set_xlabel("t [s]")
for ax in (ax1, ax2):
    ax.axvline(0.3, color="tab:red", lw=0.8, ls=":")
    ax.grid(alpha=0.3)
ax1.set_xlim(0.25, 0.5)
plt.show()
