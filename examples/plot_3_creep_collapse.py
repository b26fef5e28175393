"""
Creep-zone collapse
===================

As the friction limit f* grows, the slip (creep) zone shrinks and the Coulomb solution
tends to perfect adhesion, whose friction ends in a concentrated force at x2 (the
paper's Sect. 5). A small sweep with the steady scheme, which solves the steady
equations directly, against the exact solutions.
"""

import matplotlib.pyplot as plt
import numpy as np

import beltsim

base = beltsim.paper_scene("slip", [("numerics.integrator", "steady")])
x2 = base.params.x2
limits = np.geomspace(5e4, 5e6, 7)
simulated, exact = [], []
for fstar in limits:
    scene = base.with_overrides([("contact.max_friction", fstar)])
    res = beltsim.run(scene)
    simulated.append((x2 - res.solution.slip_start, res.solution.total_friction))
    exact.append((x2 - res.reference.x_star, res.reference.total_friction))
    print(f"f* = {fstar:9.3g} N/m: slip zone {simulated[-1][0] * 1e3:7.3f} mm "
          f"(exact {exact[-1][0] * 1e3:7.3f} mm)")
simulated, exact = np.array(simulated), np.array(exact)
adhesion = beltsim.solve(base, model="stick")  # the perfect-adhesion limit

# %%
# The slip zone shrinks roughly as 1/f*, and the total friction approaches the
# perfect-adhesion value, concentrated force included.

fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
ax1.loglog(limits, exact[:, 0], "k-", label="exact")
ax1.loglog(limits, simulated[:, 0], "o", mfc="none", label="simulated (steady scheme)")
ax1.set_xlabel("f* [N/m]")
ax1.set_ylabel("slip zone x2 - x* [m]")
ax1.legend()
ax1.grid(alpha=0.3, which="both")
ax2.semilogx(limits, exact[:, 1], "k-", label="exact, stick and slip")
ax2.semilogx(limits, simulated[:, 1], "o", mfc="none", label="simulated")
ax2.axhline(adhesion.total_friction, color="tab:blue", ls="--",
            label="perfect adhesion")
ax2.set_xlabel("f* [N/m]")
ax2.set_ylabel("total friction [N]")
ax2.legend()
ax2.grid(alpha=0.3, which="both")
plt.show()
