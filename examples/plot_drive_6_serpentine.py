"""
A serpentine drive: seven pulleys, a tensioner, modes, fluctuation
==================================================================

The shipped ``serpentine_accessory`` scene is a car's front-end accessory drive: the
crankshaft drives the A/C compressor, the alternator, the power steering pump and the
water pump through a six-rib belt, with two back-side idlers. The run starts at rest and
ends at the steady state, which it compares with the creep theory on N pulleys. The same
from the command line::

    beltsim run serpentine_accessory
    beltsim plot runs/out/serpentine_accessory
    beltsim modes serpentine_accessory --out runs/out/modes
"""

import matplotlib.pyplot as plt
import numpy as np

import beltsim
from beltsim.beltdrive.drawing import draw_drive

scene = beltsim.load_scene("serpentine_accessory")
result = beltsim.run(scene)
s = result.summary()
print(f"{result.status.value} after {result.statistics['steps']} steps, "
      f"{result.wall_time:.2f} s wall; crankshaft torque {s['driver_torque']:.2f} N m, "
      f"efficiency {s['efficiency']:.4f}")
for span in s["spans"]:
    print(f"  {span['from']:>10} -> {span['to']:<10} {span['tension']:8.2f} N")
print("largest errors against the creep theory:",
      ", ".join(f"{k} {v:.1e}" for k, v in result.errors().items()))

# %%
# The drive to scale: the belt coloured by its tension, the slip arcs in red at the exits
# of the loaded pulleys, and each bearing's load (the belt's force on it) as an arrow.

hubs = [p["hub_load"] for p in s["pulleys"]]
draw_drive(scene.params, result.x, result.fields["tension"], result.fields["slip"],
           hub_loads=hubs, title=scene.title)
plt.show()

# %%
# The same drive with its tensioner pulley on a spring-loaded arm
# (``serpentine_tensioner``): the steady solve finds where the arm rests, turned into
# the belt from where the scene draws it.

arm_scene = beltsim.load_scene("serpentine_tensioner")
arm = beltsim.run(arm_scene)
a = arm.summary()
print(f"arm travel {np.degrees(a['arm_travel']):.2f} deg (creep theory's within "
      f"{abs(arm.errors()['arm_travel']):.1e} rad), slack span "
      f"{a['spans'][0]['tension']:.1f} N")

# %%
# The drive's rotational modes about its steady state: the slip arcs damp them.

modes = beltsim.modes(scene, count=6)
print(modes.table())

# %%
# The crankshaft's speed fluctuation: each span's tension amplitude per rad/s of it,
# from the drive linearised about its steady state. The first resonance is the
# alternator's mode.

f = np.geomspace(5.0, 300.0, 300)
response = beltsim.forced_response(scene, f, overrides={"numerics.friction_law": "tanh"})
fig, ax = plt.subplots(figsize=(7, 4), constrained_layout=True)
for key, amp in response.amplitudes().items():
    if key.startswith("tension"):
        ax.loglog(f, amp, label=key[8:-1])
ax.set_xlabel("fluctuation frequency [Hz]")
ax.set_ylabel("span tension amplitude [N per rad/s]")
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=7, ncol=2)
plt.show()
