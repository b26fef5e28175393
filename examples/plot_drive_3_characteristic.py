"""
A closed drive's characteristic curve
=====================================

How much speed and power does the drive lose as the load grows, and where does the belt
slip through? Below the drive's capacity (the load at which the slip arcs cover the
smaller wrap) every load has a steady state, which the steady scheme
(``numerics.integrator = "steady"``) finds by Newton's method in milliseconds; beyond it
there is none, and a run from rest ends in gross slip: the belt slides over the driver's
whole wrap and the driven pulley falls back. The analytic curves are the string's creep
theory (:func:`~beltsim.beltdrive.analytic.solve_string`). One point from the command
line::

    beltsim run drive_flat --set drive.load_torque=80 --set numerics.integrator=steady

and a run beyond the capacity, which exits with status 1 and the reason::

    beltsim run drive_flat --set drive.load_torque=110
"""

import matplotlib.pyplot as plt
import numpy as np

import beltsim
from beltsim import beltdrive
from beltsim.beltdrive.characteristic import plot_characteristic

scene = beltsim.load_scene("drive_flat")
P = scene.params
cap = beltdrive.capacity(P)
print(f"capacity at {P.omega1:g} rad/s: {cap:.2f} N m")

loads = np.linspace(5.0, 0.98 * cap, 14)
loss, eff = [], []
for m2 in loads:
    r = beltsim.run(scene, overrides={"drive.load_torque": float(m2),
                                      "numerics.integrator": "steady"})
    loss.append(1.0 - r.summary()["speed_ratio"])
    eff.append(r.summary()["efficiency"])


def exact(m2, key):
    return beltdrive.solve_string(P, M2=m2).summary()[key]


analytic = {"speed_loss": lambda m2: 1.0 - exact(m2, "speed_ratio"),
            "efficiency": lambda m2: exact(m2, "efficiency")}

# a run whose load rises slowly past the capacity, once the drive is up to speed
ramp = scene.with_overrides([("drive.load_torque",
                              [[0.0, 0.0], [0.4, 40.0], [3.0, 1.1 * cap]])])
slow = beltsim.run(ramp, raise_on_failure=False)
print(f"load ramped to {1.1 * cap:.1f} N m: {slow.status.value}, {slow.reason}")

# %%
# Speed loss and efficiency against the load: the steady states (markers) lie on the
# analytic curves up to the capacity. In this theory the efficiency equals the speed
# ratio, so the two panels mirror each other: the power lost is the slip power, the
# tension difference times the creep speed. The slowly loaded run (thin line) follows
# the curve while it can and leaves it at the capacity, where it stops with gross slip
# (cross). There the driven pulley slows down and gives up kinetic energy to the load, so
# the momentary ratio of output to input power rises: a transient, not an efficiency.

fig = plot_characteristic(loads, np.array(loss), np.array(eff), capacity=cap,
                                analytic=analytic)
h = slow.history
on = h["t"] > 0.5  # up to speed: the efficiency of a start-up is not a characteristic
for ax, values in zip(fig.axes, (1.0 - h["speed_ratio"], h["efficiency"])):
    ax.plot(h["load_torque"][on], 100 * values[on], color="tab:green", lw=1.0,
            label="run, load rising slowly")
    ax.plot(h["load_torque"][-1], 100 * values[-1], "x", color="tab:green", ms=9, mew=2,
            label=slow.status.value)
fig.axes[0].legend(fontsize=8, loc="upper left")
plt.show()

# %%
# Three runs from rest at 0.95, 1.05 and 1.2 times the capacity (the load ramps up with
# the driver's speed). The first settles; the other two end as soon as a whole arc
# slides while the driven pulley slows down: gross slip is a physical outcome of the
# run, reported as its status, not a numerical failure.

fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 6), sharex=True, layout="constrained")
for factor, color in ((0.95, "tab:blue"), (1.05, "tab:orange"), (1.2, "tab:red")):
    run = beltsim.run(scene, raise_on_failure=False,
                      overrides={"drive.load_torque": factor * cap})
    print(f"{factor:.2f} x capacity: {run.status.value}"
          + (f" ({run.reason})" if run.reason else ""))
    rh = run.history
    label = f"{factor:g} x capacity: {run.status.value}"
    ax1.plot(rh["t"], rh["driven_speed"] * P.geometry.R2 / (rh["omega1"] * P.geometry.R1),
             color=color, label=label)
    ax2.plot(rh["t"], rh["slip_arc_driver"], color=color, label=label)
ax2.axhline(P.geometry.wraps[0], color="k", ls=":", lw=1.0, label="driver's wrap")
ax1.set_ylim(0.85, 1.005)
ax1.set_ylabel("speed ratio ω2R2 / ω1R1")
ax2.set_ylabel("driver's slip arc [rad]")
ax2.set_xlabel("t [s]")
for ax in (ax1, ax2):
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
plt.show()
