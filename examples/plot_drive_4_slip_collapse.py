"""
A closed drive's slip arcs against the friction coefficient
===========================================================

The drive's version of the paper's Fig. 7. In the creep theory both pulleys slide over
the same angle, phi_s = (kappa / mu) ln((T1 - rho c^2) / (T2 - rho c^2)), at their exits;
the rest of each arc sticks. As mu grows the slip arcs shrink onto the exits, and the
drive tends to perfect adhesion, in which each arc sticks whole and a concentrated
friction force sits at its exit. As mu falls, the slip arcs grow until they cover the
driver's (smaller) wrap: gross slip. The sweep uses the string model, whose analytic
steady state is :func:`~beltsim.beltdrive.analytic.solve_string`, and the steady solver.
One point from the command line::

    beltsim run drive_flat --set physics.model=string --set contact.friction_coefficient=2 \\
        --set numerics.integrator=steady
"""

import matplotlib.pyplot as plt
import numpy as np
from scipy.optimize import brentq

import beltsim
from beltsim import beltdrive
from beltsim.beltdrive.characteristic import plot_slip_collapse

scene = beltsim.load_scene("drive_flat", [("physics.model", "string")])
P = scene.params
g = P.geometry


def with_mu(mu):
    return scene.with_overrides([("contact.friction_coefficient", float(mu))])


# the smallest mu that carries the rated load: the capacity equals the load there
mu_min = brentq(lambda mu: beltdrive.capacity(with_mu(mu).params) - P.M2, 0.05, P.mu)
print(f"gross slip below mu = {mu_min:.4f} at {P.M2:g} N m")

mus = np.geomspace(1.05 * mu_min, 20.0, 11)
driver, driven, tight = [], [], []
for mu in mus:
    r = beltsim.run(with_mu(mu), overrides={"numerics.integrator": "steady"})
    s = r.summary()
    driver.append(s["slip_arc_driver"])
    driven.append(s["slip_arc_driven"])
    tight.append(s["tight_tension"])
    print(f"mu = {mu:6.3f}: slip arcs {driver[-1]:.4f}, {driven[-1]:.4f} rad "
          f"(analytic {r.reference.phi_s:.4f}), tight tension "
          f"{s['tight_tension']:.2f} N")


def phi_s(mu):
    return beltdrive.solve_string(with_mu(mu).params).phi_s


# perfect adhesion: no friction coefficient, the whole arc sticks
stick = scene.to_dict()
stick["contact"] = {"friction": "stick"}
adhesion = beltdrive.solve_string(beltdrive.DriveScene(stick).params)
print(f"perfect adhesion: tight tension {adhesion.T1:.2f} N, concentrated forces "
      f"{adhesion.concentrated[0]:.2f} N at the exits")

# %%
# Both slip arcs fall as about 1 / mu; the dotted lines are the wraps, the slip arcs'
# limits. The driver's and the driven pulley's markers lie on one analytic curve: the
# slip arc does not depend on the pulley's radius.

fig = plot_slip_collapse(mus, driver, driven, wraps=g.wraps,
                               analytic={"driver": phi_s, "driven": phi_s})
plt.show()

# %%
# Meanwhile the tight tension tends to its perfect-adhesion value: the tension
# difference no longer changes gradually over a slip arc but jumps at the exits.

fine = np.geomspace(mus[0], mus[-1], 101)
fig, ax = plt.subplots(figsize=(7.5, 3.6), layout="constrained")
ax.semilogx(fine, [beltdrive.solve_string(with_mu(mu).params).T1 for mu in fine], "k-",
            lw=1.2, label="Coulomb, analytic")
ax.semilogx(mus, tight, "o", color="tab:blue", mfc="none", mew=1.4, label="steady solve")
ax.axhline(adhesion.T1, color="tab:red", ls="--", lw=1.0, label="perfect adhesion")
ax.set_xlabel("friction coefficient μ")
ax.set_ylabel("tight tension T1 [N]")
ax.grid(alpha=0.3, which="both")
ax.legend(fontsize=8)
plt.show()
