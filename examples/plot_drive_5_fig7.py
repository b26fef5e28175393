"""
The beam's rotation as friction grows: the drive's Fig. 7
=========================================================

The paper's Fig. 7 shows the belt's rotation theta for three friction limits f*: as f*
grows, the slip zone shrinks onto the contact's exit and theta tends to the
perfect-adhesion solution. This is the same picture for the closed drive, from the
beam's exact steady state (``beltsim.beltdrive.beam.solve_beam``) at friction
coefficients mu = 0.4, 2 and 10 and for perfect adhesion, around the driver's arc (left)
and the driven arc (right); the markers are the discrete steady state at mu = 0.4 on the
default grid. The rotation is small (the friction's moment (h/2) f over a 4 mm belt), and
it is largest in the stick zones' boundary layers next to the slip arcs' starts and the
arcs' exits. From the command line, the steady state at one mu::

    beltsim run drive_flat --set contact.friction_coefficient=2 \\
        --set numerics.integrator=steady
"""

import matplotlib.pyplot as plt
import numpy as np

import beltsim
from beltsim.beltdrive import DriveScene
from beltsim.beltdrive.beam import solve_beam

scene = beltsim.load_scene("drive_flat")
g = scene.params.geometry
e = g.bounds


def with_mu(mu):
    return scene.with_overrides([("contact.friction_coefficient", float(mu))])


adhesion_data = scene.to_dict()
adhesion_data["contact"] = {"friction": "stick"}
adhesion = solve_beam(DriveScene(adhesion_data).params)

fig, axes = plt.subplots(1, 2, figsize=(10, 4), layout="constrained", sharey=True)
windows = ((e[0] - 0.02, e[1] + 0.03), (e[2] - 0.02, e[3] + 0.03))
for ax, (lo, hi), name in zip(axes, windows, ("driver arc", "driven arc")):
    x = np.linspace(lo, hi, 4001)
    for mu, style in ((0.4, "-"), (2.0, "--"), (10.0, "-.")):
        sol = solve_beam(with_mu(mu).params)
        ax.plot(x, 1e3 * sol.theta(x), style, lw=1.4, label=f"mu = {mu:g}")
    ax.plot(x, 1e3 * adhesion.theta(x), "k:", lw=1.6, label="perfect adhesion")
    arc = (e[0], e[1]) if name == "driver arc" else (e[2], e[3])
    ax.axvspan(*arc, color="0.9", zorder=0)
    ax.set_title(name)
    ax.set_xlabel("loop coordinate x [m]")
axes[0].set_ylabel("rotation theta [mrad]")

discrete = beltsim.run(scene, overrides={"numerics.integrator": "steady"})
for ax, (lo, hi) in zip(axes, windows):
    on = (discrete.x >= lo) & (discrete.x <= hi)
    ax.plot(discrete.x[on][::2], 1e3 * discrete.fields["theta"][on][::2], "o", ms=2.5,
            color="C0", label="discrete, mu = 0.4" if ax is axes[0] else None)
axes[0].legend(fontsize=8)
fig.suptitle("the beam's rotation tends to perfect adhesion as mu grows")
plt.show()
