"""A discrete state read as a solution: fields, friction totals, errors.

How the analytic quantities are read off the discrete state:

* the nodal friction forces F_j (N) are the element tractions lumped on the
  downstream node; ``total_friction`` is their sum;
* perfect adhesion: the concentrated force is what the last three contact
  elements (ending at x2) carry beyond the distributed traction, which is
  extrapolated linearly from the three elements upstream of them; the rest of
  the total is distributed;
* stick and slip: an element slides when |f| >= 0.99 f* (1 - 1e-12 for the ramp
  law); ``slip_start`` x* is the upstream end of the run of sliding elements
  that ends at x2 (x2 itself if the last element sticks); the friction of
  sliding elements is ``slip_friction``, the rest ``stick_friction``.
"""

from __future__ import annotations

import numpy as np

from ..physics.friction import saturation
from ..physics.grid import Grid
from ..physics.model import traction
from ..problem.analytic import AnalyticSolution
from ..problem.scene import Params


def nodal_slope(values, he):
    """d/dx at the nodes: the mean of the two adjacent elements' slopes (one at the ends).

    Works on the last axis, so a stack of snapshots goes through at once.
    """
    e = np.diff(values, axis=-1) / he
    return np.concatenate([e[..., :1], 0.5 * (e[..., 1:] + e[..., :-1]), e[..., -1:]],
                          axis=-1)


def stress_resultants(P: Params, u, theta, he) -> dict:
    """Tension b1 u_x and moment a theta_x at the nodes (works on stacks of states)."""
    return {"tension": P.b1 * nodal_slope(u, he), "moment": P.a * nodal_slope(theta, he)}


def relative_error(value, exact) -> float:
    """|value - exact| / |exact|, or the absolute difference where exact is 0."""
    return abs(value - exact) / abs(exact) if exact != 0 else abs(value - exact)


LAYER, FIT = 3, 3  # elements of the discrete force layer at x2, and of the smooth fit


class DiscreteSolution:
    def __init__(self, params: Params, grid: Grid, u, theta, fnode, law_code, fs, ud=None,
                 td=None, mismatch=None):
        self.params = params
        self.grid = grid
        self.u = np.asarray(u, dtype=float).copy()
        self.theta = np.asarray(theta, dtype=float).copy()
        # local time derivatives of the state (zero for a steady solve)
        self.ud = np.zeros_like(self.u) if ud is None else np.asarray(ud, dtype=float).copy()
        self.td = np.zeros_like(self.u) if td is None else np.asarray(td, dtype=float).copy()
        self.fnode = np.asarray(fnode, dtype=float).copy()
        self.model = "stick" if params.friction == "stick" else "slip"
        self.law_code = law_code
        self.fs = fs
        # v(t) - c at the state's time (the drive's final value by default)
        self.mismatch = params.v - params.c if mismatch is None else float(mismatch)

    @property
    def x(self):
        return self.grid.x

    @property
    def traction(self) -> np.ndarray:
        return traction(self.fnode, self.grid.he)

    def fields(self) -> dict:
        """Nodal fields with the analytic header: strain and moment averaged from elements."""
        he = self.grid.he
        return {"u": self.u, "theta": self.theta, "strain": nodal_slope(self.u, he),
                **stress_resultants(self.params, self.u, self.theta, he),
                "friction": self.traction}

    # totals ---------------------------------------------------------
    @property
    def total_friction(self) -> float:
        return float(self.fnode.sum())

    def _sliding(self):
        """Boolean per node: the element upstream of the node slides."""
        g = np.abs(self.fnode[1:] / self.grid.he) / self.fs
        s = np.zeros_like(self.fnode, dtype=bool)
        s[1:] = g >= saturation(self.law_code)
        s[: self.grid.j1 + 1] = False
        s[self.grid.j2 + 1:] = False
        return s

    @property
    def slip_start(self) -> float:
        s = self._sliding()
        j = self.grid.j2
        while j > self.grid.j1 and s[j]:
            j -= 1
        return float(self.grid.x[j])

    @property
    def slip_power(self) -> float:
        """The friction law's dissipation now, -sum F_j v_rel,j over the contact nodes (W).

        The numpy twin of the "slip" term of physics.model.power_terms, v_rel read the
        same way (upwind bottom strain). First order in the element size, with a large
        constant: v_rel / c = eps_b - e0 is a small difference of the strains (1.2% low
        on the paper slip scene at 1000 elements); and a perfect-adhesion layer, far
        thinner than an element, does not show its dissipation here at all.
        """
        g, P = self.grid, self.params
        j = np.arange(g.j1 + 1, g.j2 + 1)
        hh = 0.5 * P.h
        ub = self.u + hh * self.theta
        vrel = (self.ud[j] + hh * self.td[j] + P.c * (ub[j] - ub[j - 1]) / g.he[j - 1]
                - self.mismatch)
        return float(-np.sum(self.fnode[j] * vrel))

    @property
    def steady_slip_power(self) -> float:
        """The slip power of a steady state from its energy balance (W):

            D = c e0 F_tot + (c/2) [B eps^2 + A theta_x^2] from x = 0 to L

        (problem.analytic derives it), with the discrete total friction and the end
        elements' strains. It inherits the total friction's accuracy (8.5e-4 on the paper
        slip scene at 1000 elements against 1.2e-2 of the local sum) and holds for
        perfect adhesion, whose concentrated force dissipates at the strain jump.
        """
        P, he = self.params, self.grid.he
        eps = np.diff(self.u)[[0, -1]] / he[[0, -1]]
        kappa = np.diff(self.theta)[[0, -1]] / he[[0, -1]]
        ends = P.B * eps**2 + P.A * kappa**2
        return float(P.c * P.e0 * self.total_friction + 0.5 * P.c * (ends[1] - ends[0]))

    @property
    def concentrated_force(self) -> float:
        """Excess over a smooth traction in the last LAYER elements before x2.

        The discrete force is not all on the last element: the element before it
        carries a little of it too (a discrete layer of one or two elements), so the
        smooth traction is fitted on the FIT elements upstream of that layer.
        """
        g, f = self.grid, self.traction
        last = g.j2 - 1  # element index; element e ends at node e + 1
        layer = np.arange(max(g.j1, last - LAYER + 1), last + 1)
        fit = np.arange(max(g.j1, layer[0] - FIT), layer[0])
        xm = 0.5 * (g.x[1:] + g.x[:-1])
        if len(fit) >= 2:
            coef = np.polyfit(xm[fit], f[fit + 1], 1)
            smooth = np.polyval(coef, xm[layer])
        else:
            smooth = np.full(len(layer), f[fit + 1].mean() if len(fit) else 0.0)
        return float(np.sum(self.fnode[layer + 1] - smooth * g.he[layer]))

    def summary(self) -> dict:
        total = self.total_friction
        if self.model == "stick":
            conc = self.concentrated_force
            return {"model": "stick", "inertia": self.params.inertia, "total_friction": total,
                    "concentrated_force": conc, "distributed_friction": total - conc,
                    "stick_friction": None, "slip_friction": None, "slip_start": None,
                    "slip_power": self.steady_slip_power}
        s = self._sliding()
        slip = float(self.fnode[s].sum())
        return {"model": "slip", "inertia": self.params.inertia, "total_friction": total,
                "concentrated_force": None, "distributed_friction": None,
                "stick_friction": total - slip, "slip_friction": slip,
                "slip_start": self.slip_start, "slip_power": self.steady_slip_power}


def compare(sim: DiscreteSolution, ref: AnalyticSolution) -> dict:
    """Errors of a discrete state against the analytic solution of the same scene.

    Relative errors for total friction, u and theta (max over the grid nodes,
    relative to the analytic field's max), the slip power, the concentrated force (stick), and
    the absolute error of the slip start in metres (slip).
    """
    a = ref.fields(sim.x)

    def rel_field(name):
        scale = np.max(np.abs(a[name]))
        diff = np.max(np.abs(getattr(sim, name) - a[name]))
        return float(diff / scale) if scale > 0 else float(diff)

    out = {"total_friction": relative_error(sim.total_friction, ref.total_friction),
           "u": rel_field("u"), "theta": rel_field("theta"),
           "slip_power": relative_error(sim.steady_slip_power, ref.slip_power)}
    if ref.model == "stick":
        out["concentrated_force"] = relative_error(sim.concentrated_force,
                                                   ref.concentrated_force)
        out["slip_start"] = None
    else:
        out["concentrated_force"] = None
        out["slip_start"] = abs(sim.slip_start - ref.x_star)
    return out
