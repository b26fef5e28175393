"""A tensioner's arm as a degree of freedom of the loop model: the geometry its angle
changes, tabled for the kernels, and the drive's state at rest with the arm settled.

The grid is laid on the layout with the arm at a reference angle (the creep theory's
rest angle of the running drive). Turning the arm by beta from there moves the tensioner
pulley: spans a (arriving at it) and b (leaving it) change length and direction, and
with them the wraps of the tensioner and its two neighbours. The loop's length changes
by::

    delta_a(beta) + delta_b(beta),   delta_a = dl_a + (q_{k-1} - q_k) dphi_a,
                                      delta_b = dl_b + (q_k - q_{k+1}) dphi_b,

with dl the spans' length changes, dphi their directions' and q = side r each pulley's
signed radius: each span's change with the share of the wraps its turning takes from the
arcs at its two ends (the wraps' changes are of the first order each, and cancel with the
spans' to the second). The model takes delta_a and delta_b up as a stretch of the grid
in each span (``Mesh.arm_el``), so the arcs keep their nodes; the arm's moment from the
two spans' tensions T is -(T_a delta_a' + T_b delta_b') by virtual work, and its
equation is J beta'' + d beta' = tau0 - k_t (beta_ref + beta) - T_a delta_a' - T_b delta_b'.
The moving spans' own inertia (axial frame motion, transverse swing) is not in the
model, as it is not in the discrete model of Hwang, Perkins and Ulsoy.

delta_a and delta_b are tabled as Chebyshev series on an interval of beta about the
reference (``TRAVEL``), which the run's arm must not leave.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.polynomial import chebyshev as C

from ..errors import NoSolutionError
from ..problem.roots import brentq
from .pulleys import GeometryError

#: The tabled travel of the arm on either side of its reference and rest angles (rad)
TRAVEL = 0.25
#: Chebyshev coefficients of each table (the lengths are analytic in beta: the series
#: reaches round-off well before this many)
DEGREE = 40


@dataclass(frozen=True)
class ArmTable:
    """The arm's geometry about the reference layout, as the kernels read it.

    ``coef`` (6, DEGREE + 1): Chebyshev coefficients on [lo, hi] of delta_a, delta_b
    and their first and second derivatives in beta (m, m/rad, m/rad^2); ``lo``, ``hi``
    the tabled interval of beta (rad, from the reference); ``turn`` the reference's turn
    into the belt from the drawn angle (rad).
    """

    coef: np.ndarray
    lo: float
    hi: float
    turn: float

    def __call__(self, beta, row: int = 0):
        """Row ``row`` of the table at beta (rad from the reference)."""
        x = (2.0 * np.asarray(beta, dtype=float) - self.lo - self.hi) / (self.hi - self.lo)
        return C.chebval(x, self.coef[row])


def _deltas(ten, layout, beta):
    """(delta_a, delta_b) of ``layout`` with the arm turned by a further beta."""
    k = ten.index
    n = len(layout)
    moved = ten.turned(layout, beta)
    q = layout.sides * layout.radii
    dl = moved.spans - layout.spans
    dphi = np.angle(np.exp(1j * (moved.span_angles - layout.span_angles)))
    a, b = (k - 1) % n, k
    return (dl[a] + (q[a] - q[k]) * dphi[a], dl[b] + (q[k] - q[(k + 1) % n]) * dphi[b])


def arm_table(P, rest: float = 0.0) -> ArmTable:
    """The arm's geometry of drive ``P`` (its layout the reference: the arm turned by
    ``P.arm_turn``), tabled over TRAVEL about the reference and about ``rest`` (rad from
    the reference: the arm's angle at rest), within the turns that keep a layout.

    Raises
    ------
    NoSolutionError
        Not even 0.01 rad about both angles keeps a belt loop.
    """
    ten, layout = P.tensioner, P.layout
    lo, hi = min(0.0, rest) - TRAVEL, max(0.0, rest) + TRAVEL
    for _ in range(30):
        x = np.cos(np.pi * (np.arange(DEGREE + 1) + 0.5) / (DEGREE + 1))  # Chebyshev pts
        try:
            vals = np.array([_deltas(ten, layout, 0.5 * (hi + lo) + 0.5 * (hi - lo) * xi)
                             for xi in x])
            break
        except GeometryError:
            lo, hi = 0.5 * (lo + min(0.0, rest)), 0.5 * (hi + max(0.0, rest))
            if hi - lo < 0.01:
                break
    else:
        vals = None
    if vals is None or hi - lo < 0.01:
        raise NoSolutionError(f"tensioner: the arm of pulley {layout.names[ten.index]!r} "
                              f"cannot turn 0.01 rad without breaking the belt's loop")
    scale = 2.0 / (hi - lo)
    rows = []
    for col in range(2):
        c = C.chebfit(x, vals[:, col], DEGREE)
        c1 = C.chebder(c) * scale
        rows += [c, np.append(c1, 0.0), np.append(C.chebder(c1) * scale, [0.0, 0.0])]
    coef = np.array([rows[0], rows[3], rows[1], rows[4], rows[2], rows[5]])
    return ArmTable(coef, lo, hi, P.arm_turn)


def rest_angle(P, table: ArmTable) -> tuple[float, float]:
    """The arm's angle at rest (rad from the reference) and the belt's tension there
    (N), in the model's small-strain measure: the grid's belt takes the loop's change
    delta_a + delta_b as a uniform strain over the loop length Lambda, so its tension is
    N0 + b1 (delta_a + delta_b) / Lambda, and the spring balances its pull.

    Raises
    ------
    NoSolutionError
        No rest angle in the tabled travel.
    """
    ten = P.tensioner
    L = P.layout.loop_length

    def tension(b):
        return P.N0 + P.b1 * (table(b, 0) + table(b, 1)) / L

    def torque(b):
        return (ten.preload - ten.stiffness * (table.turn + b)
                - tension(b) * (table(b, 2) + table(b, 3)))

    grid = np.linspace(table.lo, table.hi, 81)
    vals = np.array([torque(b) for b in grid])
    # the root nearest the reference: the arm's spring turns into the belt until the
    # belt's pull balances it
    cross = np.flatnonzero(np.sign(vals[:-1]) != np.sign(vals[1:]))
    if len(cross) == 0:
        raise NoSolutionError(f"tensioner: the arm of pulley "
                              f"{P.layout.names[ten.index]!r} has no rest angle within "
                              f"{math.degrees(TRAVEL):.3g} deg of its running rest angle")
    i = cross[np.argmin(np.abs(grid[cross]))]
    beta = brentq(torque, grid[i], grid[i + 1], xtol=1e-15)
    return float(beta), float(tension(beta))


__all__ = ["ArmTable", "TRAVEL", "arm_table", "rest_angle"]
