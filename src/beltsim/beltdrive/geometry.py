"""Geometry of an open belt drive: wrap angles, spans and the loop coordinate.

Driver pulley of radius R1, driven pulley R2, centre distance C. With
sin(b) = (R2 - R1) / C the belt wraps phi1 = pi - 2 b on the driver and
phi2 = pi + 2 b on the driven pulley, each span is C cos(b) long, and the loop
is Lambda = 2 C cos(b) + R1 phi1 + R2 phi2 long.

The loop coordinate x in [0, Lambda) runs in the belt's direction of motion:
driver arc, slack span, driven arc, tight span. The driver pulls the belt in from
the tight span, so x = 0 is the driver arc's entry.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: The loop's four segments in the order of the loop coordinate.
SEGMENTS = ("driver", "slack", "driven", "tight")


class GeometryError(ValueError):
    """A drive whose pulleys do not make an open drive (the key and the rule)."""


@dataclass(frozen=True)
class Geometry:
    """An open drive's geometry (m, rad)."""

    R1: float
    R2: float
    C: float

    def __post_init__(self):
        if not self.C > self.R1 + self.R2:
            raise GeometryError(
                f"drive.centre_distance: must exceed driver_radius + driven_radius = "
                f"{self.R1 + self.R2:g} m (the pulleys would overlap), got {self.C:g}")

    @property
    def b(self) -> float:
        """The spans' inclination b (rad) to the line of centres: sin b = (R2 - R1) / C."""
        return math.asin((self.R2 - self.R1) / self.C)

    @property
    def wraps(self) -> tuple[float, float]:
        """Wrap angles (phi1, phi2) (rad) of the driver and the driven pulley."""
        return math.pi - 2.0 * self.b, math.pi + 2.0 * self.b

    @property
    def span(self) -> float:
        """Length of each free span, C cos b (m)."""
        return self.C * math.cos(self.b)

    @property
    def arcs(self) -> tuple[float, float]:
        """Arc lengths R1 phi1 and R2 phi2 of the contacts (m)."""
        phi1, phi2 = self.wraps
        return self.R1 * phi1, self.R2 * phi2

    @property
    def radii(self) -> tuple[float, float]:
        """(R1, R2)."""
        return self.R1, self.R2

    @property
    def lengths(self) -> tuple[float, float, float, float]:
        """Lengths of the segments in SEGMENTS order: driver arc, slack, driven arc, tight."""
        l1, l2 = self.arcs
        return l1, self.span, l2, self.span

    @property
    def bounds(self) -> np.ndarray:
        """The segments' ends on the loop coordinate: 0, x_a, x_b, x_c, Lambda."""
        return np.concatenate([[0.0], np.cumsum(self.lengths)])

    @property
    def loop_length(self) -> float:
        """Lambda (m)."""
        return float(sum(self.lengths))

    def segment_of(self, x) -> np.ndarray:
        """Index into SEGMENTS of each loop coordinate x (taken modulo Lambda)."""
        xs = np.mod(np.asarray(x, dtype=float), self.loop_length)
        return np.clip(np.searchsorted(self.bounds, xs, side="right") - 1, 0, 3)

    def path(self, x) -> tuple[np.ndarray, np.ndarray]:
        """Points (X, Y) (m) of the belt's path at loop coordinates x, to scale.

        The driver's centre is at the origin, the driven pulley's at (C, 0). Both spans are
        the pulleys' outer tangents, touching each pulley at the angle pi/2 + b (top) and
        -(pi/2 + b) (bottom); the belt runs counter-clockwise, the tight span on top.
        """
        xs = np.mod(np.asarray(x, dtype=float), self.loop_length)
        X = np.empty_like(xs)
        Y = np.empty_like(xs)
        R1, R2, C = self.R1, self.R2, self.C
        top = 0.5 * math.pi + self.b
        e = self.bounds
        seg = self.segment_of(xs)
        centres = ((0.0, 0.0), None, (C, 0.0), None)
        starts = (top, None, -top, None)
        radii = (R1, None, R2, None)
        for k in (0, 2):
            on = seg == k
            ang = starts[k] + (xs[on] - e[k]) / radii[k]
            X[on] = centres[k][0] + radii[k] * np.cos(ang)
            Y[on] = centres[k][1] + radii[k] * np.sin(ang)
        ends = {1: ((R1, 0.0, -top), (R2, C, -top)), 3: ((R2, C, top), (R1, 0.0, top))}
        for k, ((ra, xa, aa), (rb, xb, ab)) in ends.items():
            on = seg == k
            r = (xs[on] - e[k]) / self.span
            pa = np.array([xa + ra * math.cos(aa), ra * math.sin(aa)])
            pb = np.array([xb + rb * math.cos(ab), rb * math.sin(ab)])
            X[on] = pa[0] + r * (pb[0] - pa[0])
            Y[on] = pa[1] + r * (pb[1] - pa[1])
        return X, Y
