"""A discrete state read as a solution: fields, friction totals, errors.

How the analytic quantities are read off the discrete state:

* the nodal friction forces F_j (N) sit on the friction nodes of the contact
  (physics.discrete.contact_stencil), the traction f_j = F_j / wf_j;
  ``total_friction`` is their sum;
* perfect adhesion: the concentrated force is what the last three friction nodes
  (ending at x2) carry beyond the distributed traction, extrapolated (quadratic)
  from the three nodes upstream of them; the rest of the total is distributed;
* stick and slip: a node slides when abs(f) >= 0.99 f* (1 - 1e-12 for the ramp
  law); the run of sliding nodes that ends at x2 starts at node p + 1, and node p
  is partly stuck: ``slip_start`` x* is read inside its control volume [a, b] from
  F_p = f_stick (x* - a) + s f* (b - x*), f_stick the stick traction extrapolated
  from upstream (x2 itself if node j2 sticks, x1 if every node slides); the
  friction of sliding nodes and of node p's sliding part is ``slip_friction``, the
  rest ``stick_friction``.
"""

from __future__ import annotations

import numpy as np

from ..physics.discrete import contact_stencil
from ..physics.friction import saturation
from ..physics.grid import Grid
from ..physics.model import traction
from ..physics.reference import strain
from ..problem.analytic import AnalyticSolution
from ..problem.validation import Params

LAYER, FIT = 3, 3  # nodes of the discrete force layer at x2, and of the smooth fit


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
    """abs(value - exact) / abs(exact), or the absolute difference where exact is 0."""
    return abs(value - exact) / abs(exact) if exact != 0 else abs(value - exact)


class DiscreteSolution:
    """A discrete state read as a solution: nodal fields, friction totals, read-outs."""

    def __init__(self, params: Params, grid: Grid, u, theta, fnode, law_code, friction_scale,
                 ud=None, td=None, mismatch=None, stencil=None):
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
        self.friction_scale = friction_scale
        # v(t) - c at the state's time (the drive's final value by default)
        self.mismatch = params.v - params.c if mismatch is None else float(mismatch)
        # the friction nodes, their weights and slip-velocity stencils (physics.discrete;
        # a run passes its mesh's rather than rebuild them at every check)
        self.c0, self.wf, self.sw = (contact_stencil(grid.x, grid.j1, grid.j2)
                                     if stencil is None else stencil)
        self._slides = None  # the sliding mask, once read (the state does not change)

    @property
    def x(self):
        """The grid's nodes (m)."""
        return self.grid.x

    @property
    def traction(self) -> np.ndarray:
        """The friction traction (N/m) at the nodes, as ``fields()['friction']``."""
        return traction(self.fnode, self.wf)

    def errors(self, ref) -> dict:
        """The errors against the exact steady state ``ref`` (:func:`compare`)."""
        return compare(self, ref)

    def snapshot_arrays(self, snaps: dict) -> dict:
        """What snapshots.npz holds of a run's snapshots: u, theta and the traction (N/m)."""
        return {"u": snaps["u"], "theta": snaps["theta"],
                "friction": traction(snaps["fnode"], self.wf)}

    def fields(self) -> dict:
        """Nodal fields with the analytic header: strain and moment averaged from elements."""
        he = self.grid.he
        return {"u": self.u, "theta": self.theta, "strain": nodal_slope(self.u, he),
                **stress_resultants(self.params, self.u, self.theta, he),
                "friction": self.traction}

    # totals ---------------------------------------------------------
    @property
    def total_friction(self) -> float:
        """The sum of the nodal friction forces (N)."""
        return float(self.fnode.sum())

    def _sliding(self):
        """Boolean per node: the friction node slides (abs(f) >= saturation f*)."""
        if self._slides is None:
            s = np.zeros_like(self.fnode, dtype=bool)
            on = self.wf > 0.0
            s[on] = (np.abs(self.fnode[on] / self.wf[on]) / self.friction_scale
                     >= saturation(self.law_code))
            self._slides = s
        return self._slides

    def _control_volume(self, j):
        """The contact part [a, b] of node j's control volume."""
        x, g = self.grid.x, self.grid
        a = x[j] if j == g.j1 else 0.5 * (x[j - 1] + x[j])
        b = x[j] if j == g.j2 else 0.5 * (x[j] + x[j + 1])
        return a, b

    def _stick_fit(self, p):
        """The FIT friction nodes before p (fewer near x1): their x and traction, as lists."""
        lo = max(self.c0, p - FIT)
        return (self.grid.x[lo:p].tolist(), (self.fnode[lo:p] / self.wf[lo:p]).tolist())

    @staticmethod
    def _extrapolate(fit, xq):
        """The Lagrange polynomial through the points ``fit`` (quadratic for three) at xq."""
        x, f = fit
        value = 0.0
        for i, (xi, fi) in enumerate(zip(x, f)):
            li = 1.0
            for m, xm in enumerate(x):
                if m != i:
                    li *= (xq - xm) / (xi - xm)
            value += li * fi
        return float(value)

    def _slip_front(self):
        """(x*, p): the slip start read inside the cell, and the node whose control volume
        holds it (None when no node slides).

        The friction nodes from p + 1 to x2 slide; node p is partly stuck: its force
        F_p = f_stick (x* - a) + s f* (b - x*) over the contact part [a, b] of its
        control volume, f_stick the stick traction extrapolated from the nodes
        upstream of p, gives x* (clipped to [a, b]).
        """
        sl = self._sliding()
        g = self.grid
        j = g.j2
        if not sl[j]:
            return float(g.x[j]), None
        stuck = np.flatnonzero(~sl[self.c0:j])  # the sliding run ending at x2 starts after
        j = self.c0 + stuck[-1] + 1 if len(stuck) else self.c0
        if j == self.c0:
            return float(g.x[g.j1]), None
        # the partly stuck node is j - 1, or j itself when x* lies at the very start of
        # its volume (|f_j| >= 0.99 f* already): the one whose x* falls furthest
        # inside its volume (the other then reads x* at its end)
        best = None
        for p in (j - 1, j):
            xs, depth = self._front_in(p)
            if best is None or depth > best[2]:
                best = (xs, p, depth)
        return best[0], best[1]

    def _front_in(self, p):
        """x* read from node p's force, clipped to its volume [a, b], and how far
        inside it lies (min(x* - a, b - x*) / (b - a))."""
        a, b = (float(v) for v in self._control_volume(p))
        fslip = float(np.sign(self.fnode[self.grid.j2])) * self.friction_scale
        fp = float(self.fnode[p])
        fit = self._stick_fit(p)
        xs = 0.5 * (a + b)
        for _ in range(3):  # f_stick at the middle of [a, x*]
            fst = self._extrapolate(fit, 0.5 * (a + xs))
            if fslip == fst:
                break
            xs = (fp - fslip * b + fst * a) / (fst - fslip)
            xs = min(b, max(a, xs))
        return float(xs), min(xs - a, b - xs) / (b - a)

    @property
    def slip_start(self) -> float:
        """Where the slip zone that ends at x2 starts (m), read inside its first cell."""
        return self._slip_front()[0]

    @property
    def slip_power(self) -> float:
        """The friction law's dissipation now, -sum F_j v_rel,j over the contact nodes (W).

        The numpy twin of the "slip" term of physics.model.power_terms, v_rel read the
        same way (the nodal stencil of physics.discrete.contact_stencil). v_rel / c =
        eps_b - e0 is a small difference of the strains, so its relative error is large;
        and a perfect-adhesion layer, far thinner than an element, does not show its
        dissipation here at all.
        """
        g, P = self.grid, self.params
        j = np.arange(self.c0, g.j2 + 1)
        hh = 0.5 * P.h
        ub = self.u + hh * self.theta
        vrel = (self.ud[j] + hh * self.td[j] + P.c * strain(ub, self.sw, j)
                - self.mismatch)
        return float(-np.dot(self.fnode[j], vrel))

    @property
    def steady_slip_power(self) -> float:
        """The slip power of a steady state from its energy balance (W):

            D = c e0 F_tot + (c/2) [B eps^2 + A theta_x^2] from x = 0 to L

        (problem.analytic derives it), with the discrete total friction and the end
        elements' strains. It inherits the total friction's accuracy, far better than the
        local sum's (:attr:`slip_power`), and holds for perfect adhesion, whose
        concentrated force dissipates at the strain jump.
        """
        P, he = self.params, self.grid.he
        eps = np.diff(self.u)[[0, -1]] / he[[0, -1]]
        kappa = np.diff(self.theta)[[0, -1]] / he[[0, -1]]
        ends = P.B * eps**2 + P.A * kappa**2
        return float(P.c * P.e0 * self.total_friction + 0.5 * P.c * (ends[1] - ends[0]))

    @property
    def concentrated_force(self) -> float:
        """What the last LAYER nodes (ending at x2) carry beyond the smooth traction.

        The force sits on node j2 (at x2); the adhesion layer (width delta upstream of
        x2) leaks a little of it into the nodes before. The smooth traction is fitted
        (quadratic) on the FIT nodes upstream of the layer and integrated with the nodes'
        weights.
        """
        g = self.grid
        layer = np.arange(max(self.c0, g.j2 - LAYER + 1), g.j2 + 1)
        fit = self._stick_fit(layer[0])
        smooth = np.array([self._extrapolate(fit, g.x[j]) for j in layer])
        return float(np.sum(self.fnode[layer] - smooth * self.wf[layer]))

    def summary(self, path: bool = False) -> dict:
        """The analytic solution's quantities read off this state. slip_power: the steady
        energy balance's (:attr:`steady_slip_power`), or with ``path`` (a state on the way,
        where that balance does not hold) the friction law's dissipation now
        (:attr:`slip_power`)."""
        total = self.total_friction
        power = self.slip_power if path else self.steady_slip_power
        if self.model == "stick":
            conc = self.concentrated_force
            return {"model": "stick", "inertia": self.params.inertia, "total_friction": total,
                    "concentrated_force": conc, "distributed_friction": total - conc,
                    "stick_friction": None, "slip_friction": None, "slip_start": None,
                    "slip_power": power}
        xs, p = self._slip_front()
        s = self._sliding()
        slip = float(self.fnode[s].sum())
        if p is not None:  # the sliding part of the partly stuck node
            slip += float(np.sign(self.fnode[self.grid.j2]) * self.friction_scale
                          * (self._control_volume(p)[1] - xs))
        return {"model": "slip", "inertia": self.params.inertia, "total_friction": total,
                "concentrated_force": None, "distributed_friction": None,
                "stick_friction": total - slip, "slip_friction": slip,
                "slip_start": xs, "slip_power": power}


class DiscreteReference:
    """A discrete steady state as the reference of :func:`compare`, in place of the
    analytic solution: the errors of another state on the same grid against it.

    A coarse grid's discretisation error hides whether a scheme reached its grid's steady
    state; measured against the steady scheme's state on that grid, it does not.
    """

    def __init__(self, sol: DiscreteSolution):
        self.sol = sol
        self.model = "stick" if sol.params.friction == "stick" else "slip"

    def fields(self, x) -> dict:
        """The state's nodal fields; ``x`` must be its own grid's nodes."""
        if not np.array_equal(np.asarray(x), self.sol.x):
            raise ValueError("a discrete reference compares states on its own grid only")
        return self.sol.fields()

    @property
    def total_friction(self) -> float:
        """The state's total friction (N)."""
        return self.sol.total_friction

    @property
    def slip_power(self) -> float:
        """The state's slip power from the steady energy balance (W)."""
        return self.sol.steady_slip_power

    @property
    def concentrated_force(self) -> float:
        """The state's concentrated force at x2 (N, perfect adhesion)."""
        return self.sol.concentrated_force

    @property
    def x_star(self) -> float:
        """The state's slip start (m), in the analytic solution's name."""
        return self.sol.slip_start


def compare(sim: DiscreteSolution, ref: AnalyticSolution | DiscreteReference) -> dict:
    """Errors of a discrete state against the analytic solution of the same scene (or a
    :class:`DiscreteReference` on the same grid).

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
