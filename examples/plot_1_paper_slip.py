"""
The paper's slip scene against its exact solution
=================================================

Run the paper's stick-and-slip scene from rest to steady state with the default
scheme and grid, and draw the displacement, the rotation and the friction traction
against the exact steady solution of the same scene.
"""

import matplotlib.pyplot as plt

import beltsim

scene = beltsim.paper_scene("slip")
result = beltsim.run(scene)  # from rest; attaches the exact solution as result.reference
print(result.status, f"after {result.steps} steps, t = {result.simulated_time:.3f} s")
for key, value in result.errors().items():
    if value is not None:
        print(f"{key:>16s}  {value:.2e}")

# %%
# :func:`beltsim.plot_fields` draws the final fields on the axes it is given, with the
# exact steady solution dashed and the contact shaded. The friction traction jumps to
# f* at the slip start x* and drops to zero at x2.

fig, axes = plt.subplots(3, 1, figsize=(7, 8), sharex=True, layout="constrained")
beltsim.plot_fields(result, keys=("u", "theta", "friction"), ax=axes)
x_star = result.reference.x_star
axes[2].axvline(x_star, color="tab:blue", lw=0.8, ls=":")
axes[2].text(x_star, 0.5 * scene.params.fstar, "exact x* ", ha="right", color="tab:blue")
axes[0].set_title(scene.title, fontsize=9)
plt.show()

# %%
# The same fields as arrays: ``result.x`` and ``result.fields``, against the exact
# solution at the same nodes.

exact = result.reference.fields(result.x)
for key in ("u", "theta"):
    diff = abs(result.fields[key] - exact[key]).max() / abs(exact[key]).max()
    print(f"{key}: largest difference {diff:.2e} of the largest magnitude")
