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
result = beltsim.run(scene)  # from rest; attaches the exact solution
exact = result.reference
print(result.status, f"after {result.steps} steps, t = {result.simulated_time:.3f} s")
for key, value in result.summary()["error"].items():
    if value is not None:
        print(f"{key:>16s}  {value:.2e}")

# %%
# The simulated fields are nodal; the exact ones are sampled finely, with both
# one-sided limits at x1, x* and x2. The friction traction jumps to f* at the slip
# start x* and drops to zero at x2.

sol = result.solution
x_exact, f_exact = exact.sample(1201)
fields = sol.fields()
fig, axes = plt.subplots(3, 1, figsize=(7, 8), sharex=True, constrained_layout=True)
for ax, key, label in zip(axes, ("u", "theta", "friction"),
                          ("u [m]", "theta [rad]", "friction f [N/m]")):
    ax.axvspan(scene.params.x1, scene.params.x2, color="0.93")
    ax.plot(x_exact, f_exact[key], "k-", lw=1.2, label="exact")
    ax.plot(sol.x[::6], fields[key][::6], "o", ms=3, mfc="none", label="simulated")
    ax.set_ylabel(label)
    ax.grid(alpha=0.3)
axes[2].axvline(exact.x_star, color="tab:red", lw=0.8, ls="--", label="exact slip start")
axes[0].legend(loc="upper left")
axes[2].legend(loc="upper left")
axes[2].set_xlabel("x [m]")
axes[0].set_title(scene.title, fontsize=9)
plt.show()
