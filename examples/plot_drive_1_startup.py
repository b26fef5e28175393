"""
A closed drive: start-up to the rated load
==========================================

The shipped ``drive_flat`` scene is a flat-belt drive: a 60 mm x 4 mm belt on a driver
and a driven pulley of radius R = 80 / 160 mm, 0.6 m apart, pretensioned to 600 N, with
mu = 0.4.
The run starts at rest (no belt speed, uniform tension); the driver's speed and the
load ramp smoothly to 150 rad/s and 50 N m, and the run goes on until the drive is
steady, then compares its state with the analytic steady state. The same from the
command line, with the pictures::

    beltsim run drive_flat
    beltsim plot runs/out/drive_flat

(``beltsim analytic drive_flat`` prints the analytic state alone.)
"""

import matplotlib.pyplot as plt

import beltsim
from beltsim.beltdrive import plots

scene = beltsim.load_scene("drive_flat")
result = beltsim.run(scene)
s = result.summary()
print(f"{result.status.value} at t = {result.history['t'][-1]:.3f} s after "
      f"{result.statistics['steps']} steps, {result.wall_time:.2f} s wall")
print(f"tight / slack tension {s['tight_tension']:.1f} / {s['slack_tension']:.1f} N, "
      f"speed ratio {s['speed_ratio']:.5f}, efficiency {s['efficiency']:.5f}")
print(f"slip arcs {s['slip_arc_driver']:.3f} rad (driver), {s['slip_arc_driven']:.3f} rad "
      f"(driven); driver torque {s['driver_torque']:.3f} N m; slip power "
      f"{s['slip_power']:.2f} W")
print("relative errors against the analytic steady state:")
for key, err in result.errors().items():
    print(f"  {key:16s} {err:+.2e}")

# %%
# The drive to scale at its steady state: the belt coloured by its tension, tight on
# top, slack below, and the slip arcs in red at each pulley's exit; the rest of each
# arc sticks, holding the tension the belt came in with.

g = scene.params.geometry
plots.draw_drive(g, result.x, result.fields["tension"], result.fields["slip"],
                 title=scene.title,
                 rim_speeds=(scene.params.omega1 * g.R1, s["driven_speed"] * g.R2))
plt.show()

# %%
# Along the loop (from the driver arc's entry, in the direction of motion): the tension
# keeps its entry value on each arc's stick part and changes exponentially across its
# slip part, where the friction is mu times the contact pressure. The dashed lines are
# the analytic steady state (the string's creep theory; the beam's friction has a short
# boundary layer at the slip fronts).

plots.plot_loop_fields(result.x, result.fields, g, analytic=result.reference)
plt.show()

# %%
# The start-up: the belt and the driven pulley follow the driver's ramp, and the span
# tensions split as the load comes on. The driver's torque settles at R1 / R2 of the
# load; dashed, the analytic steady values. (In the first steps both speeds are tiny and
# their ratio says little.)

plots.plot_drive_history(result.history["t"], result.history,
                         steady=result.reference.summary())
plt.show()
