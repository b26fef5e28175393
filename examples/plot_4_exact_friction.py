"""
Exact Coulomb friction
======================

``numerics.friction_law = "exact"`` solves the set-valued Coulomb law itself by a
semi-smooth Newton method: the friction ratio is exactly -1 or +1 where the belt
slides and anywhere in between where it sticks, with no regularisation. Here the
steady scheme with the default law (tanh) and with the exact law, on a ladder of grids,
against the exact steady solution.
"""

import matplotlib.pyplot as plt
import numpy as np

import beltsim

scene = beltsim.paper_scene("slip", [("numerics.integrator", "steady")])
exact_law = scene.with_overrides([("numerics.friction_law", "exact")])
res = beltsim.run(exact_law)
fstar = scene.params.fstar
ratio = res.fields["friction"] / fstar
on = (res.x >= scene.params.x1) & (res.x <= scene.params.x2)
print(f"largest |ratio| on the contact: {np.abs(ratio[on]).max():.15f}")

# %%
# The traction over f* near the slip start: the exact law's ratio is exactly 1 on the
# slip zone; the tanh law's approaches 1 over a layer far thinner than an element. The
# grid has a node at the expected slip start, whose control volume is half stuck and
# half sliding.

x_exact, f_exact = res.reference.sample(2001)
tanh = beltsim.run(scene)
fig, ax = plt.subplots(figsize=(7, 3.5), constrained_layout=True)
ax.plot(x_exact, f_exact["friction"] / fstar, "k-", lw=1, label="exact solution")
ax.plot(res.x[on], ratio[on], "o", mfc="none", label='friction_law = "exact"')
ax.plot(tanh.x[on], tanh.fields["friction"][on] / fstar, "+", label='"tanh" (default)')
ax.set_xlim(0.58, 0.67)
ax.set_xlabel("x [m]")
ax.set_ylabel("f / f*")
ax.legend()
ax.grid(alpha=0.3)

# %%
# Both laws converge at second order in the element size; the default regularisation
# shrinks with the grid, so it leaves no error floor.

ladder = [125, 250, 500, 1000, 2000]
errors = {}
for name, sc in (("tanh", scene), ("exact", exact_law)):
    errors[name] = [beltsim.run(sc.with_overrides([("numerics.elements", n)]))
                    .errors()["total_friction"] for n in ladder]
fig, ax = plt.subplots(figsize=(6, 4), constrained_layout=True)
for name, marker in (("tanh", "s"), ("exact", "o")):
    ax.loglog(ladder, errors[name], marker + "-", mfc="none", label=f'"{name}"')
ref = errors["exact"][0] * (ladder[0] / np.array(ladder)) ** 2
ax.loglog(ladder, ref, "k:", label="second order")
ax.set_xticks(ladder, [str(n) for n in ladder])
ax.xaxis.set_minor_formatter(plt.NullFormatter())
ax.set_xlabel("elements")
ax.set_ylabel("relative error of the total friction")
ax.legend()
ax.grid(alpha=0.3, which="both")
plt.show()
