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

scene = beltsim.load_scene("load_drop", [("numerics.elements", 200)])
print(scene.contact.max_friction)  # ((time, value), ...) rows
res = beltsim.run(scene, snapshot_interval=2.5e-4)
print(res.status, f"at t = {res.simulated_time:.3f} s after {res.steps} steps")

# %%
# The slip start and the total friction with its stick and slip parts over time, from
# :func:`beltsim.plot_history`: the exact steady state of the final f* is dashed, and
# the dotted lines mark the rows of the friction limit's table, the drop.

fig, axes = plt.subplots(2, 1, figsize=(7, 6), sharex=True, layout="constrained")
beltsim.plot_history(res, keys=("slip_start", "total_friction"), ax=axes)
axes[1].set_xlim(0.25, 0.5)
plt.show()
