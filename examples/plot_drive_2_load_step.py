"""
A closed drive: a load step
===========================

The shipped ``drive_load_step`` scene is ``drive_flat`` with the load as a table: it
comes on once the belt is moving, rises to 30 N m by the end of the start-up, holds until
the drive has settled, and doubles to 60 N m within 10 ms at t = 1 s. The slip arcs grow,
the tight side takes the extra tension from the slack side, the driven pulley falls back
a little further behind the driver, and the drive settles on the steady state of the new
load. From the command line (``--snapshots`` keeps the frames for ``beltsim animate --from``)::

    beltsim run drive_load_step --snapshots 0.02
    beltsim plot runs/out/drive_load_step
    beltsim animate --from runs/out/drive_load_step
"""

import matplotlib.pyplot as plt
import numpy as np

import beltsim
from beltsim import beltdrive
from beltsim.beltdrive import plots

scene = beltsim.load_scene("drive_load_step")
print(scene.drive["load_torque"])
result = beltsim.run(scene)
h = result.history
print(f"{result.status.value} at t = {h['t'][-1]:.3f} s after "
      f"{result.statistics['steps']} steps, {result.wall_time:.2f} s wall")

# the analytic steady states of both loads (the string's creep theory)
before = beltdrive.solve_string(scene.params, M2=30.0)
after = beltdrive.solve_string(scene.params, M2=60.0)
i = int(np.searchsorted(h["t"], 1.0)) - 1  # the last step before the load moves
print(f"{'':18s}{'run, t = 1 s':>14s}{'30 N m':>12s}{'run, end':>12s}{'60 N m':>12s}")
for key in ("tight_tension", "slack_tension", "speed_ratio", "slip_arc_driver",
            "driver_torque", "slip_power"):
    print(f"{key:18s}{h[key][i]:14.6g}{before.summary()[key]:12.6g}"
          f"{result.summary()[key]:12.6g}{after.summary()[key]:12.6g}")

# %%
# The history against the analytic states of both loads: dashed before the step (30 N
# m), dotted after it (60 N m). Each quantity settles on the first, then on the second;
# the step excites the loop's axial motion, which the damping and the friction settle
# within a few transits of the loop.

fig = plots.plot_drive_history(h["t"], h)
keys = [("belt_speed",), ("driven_speed",), ("speed_ratio",),
        ("tight_tension", "slack_tension"), ("driver_torque", "load_torque")]
for ax, group in zip(fig.axes, keys):
    for key in group:
        for state, t0, t1, ls in ((before, 0.5, 1.0, "--"), (after, 1.0, h["t"][-1], ":")):
            value = state.M2 if key == "load_torque" else state.summary()[key]
            ax.hlines(value, t0, t1, colors="k", linestyles=ls, lw=1.0)
    ax.axvline(1.0, color="0.5", lw=0.8)
fig.axes[0].plot([], [], "k--", lw=1.0, label="analytic, 30 N m")
fig.axes[0].plot([], [], "k:", lw=1.0, label="analytic, 60 N m")
fig.axes[0].legend(fontsize=8, loc="lower right")
plt.show()

# %%
# The speed ratio around the step, enlarged: the speed loss 1 - omega2 R2 / (omega1 R1)
# doubles with the load (it grows with the tension difference), and the slip arcs on
# both pulleys grow to carry it. The analytic states are the string's; the beam's slip
# arc on the small driver is a little shorter, by the boundary layer of its friction at
# the slip front.

fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 5.5), sharex=True, layout="constrained")
on = h["t"] > 0.8
ax1.plot(h["t"][on], 100 * (1 - h["speed_ratio"][on]), color="tab:red", label="run")
ax2.plot(h["t"][on], h["slip_arc_driver"][on], color="tab:blue", label="driver, run")
ax2.plot(h["t"][on], h["slip_arc_driven"][on], color="tab:orange", ls="--",
         label="driven, run")
for state, ls in ((before, "--"), (after, ":")):
    ax1.axhline(100 * (1 - state.speed_ratio), color="k", ls=ls, lw=1.0,
                label=f"analytic, {state.M2:g} N m")
    ax2.axhline(state.phi_s, color="k", ls=ls, lw=1.0, label=f"analytic, {state.M2:g} N m")
ax1.set_ylabel("speed loss [%]")
ax2.set_ylabel("slip arc [rad]")
ax2.set_xlabel("t [s]")
for ax in (ax1, ax2):
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
plt.show()
