"""Geometry of a belt on N pulleys in the plane (a serpentine drive).

Pulley i has centre P_i, radius r_i and side s_i: +1 when the belt wraps it with its inner
face (the pulley is inside the loop), -1 for a back-side idler touching the belt's outer
face. The belt runs through the pulleys in the order they are listed; span j runs from
pulley j to pulley j + 1 (mod N).

Walk the loop counterclockwise round the inner pulleys. With J the rotation by +90 degrees
and t the unit direction of a span, the inside of the loop lies on the left, J t. An inner
pulley's centre is therefore at (touch point) + r J t and a back-side pulley's at
(touch point) - r J t: with the signed radius q = s r both read P = touch + q J t, i.e. the
touch point is P + r n with the outward normal n = -s J t. For the span from i to j with
D = P_j - P_i = d (cos psi, sin psi) the two touch points differ by D - (q_j - q_i) J t,
which must be parallel to t: D . J t = q_j - q_i, so

    t = (cos phi, sin phi),  phi = psi - asin((q_j - q_i) / d),
    span length = D . t = sqrt(d^2 - (q_j - q_i)^2)

(the root with the positive length). No such line exists when |q_j - q_i| >= d. On pulley
i the belt's direction turns from the arriving span's t to the departing span's, by the
wrap in the sense s_i (counterclockwise round inner pulleys, clockwise round back-side
ones), and over the closed loop the direction turns once: the inner wraps minus the
back-side wraps sum to 2 pi.

Pulleys listed clockwise are handled by mirroring: reflect y, solve the counterclockwise
layout, reflect the points and directions back. The loop coordinate x runs in the belt's
direction of motion from the entry of pulley 0's arc (the arrival point of the last span);
its segments are arc 0, span 0, arc 1, span 1, ... For two inner pulleys listed driver
first this is :class:`~beltsim.beltdrive.geometry.Geometry`'s loop.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from .geometry import GeometryError

TWO_PI = 2.0 * math.pi
#: A wrap this close to 0 (or 2 pi) is a belt running straight past a pulley (rad).
WRAP_TOL = 1e-9
#: Tolerance of the sum rule (rad): round-off of N atan2 is far below it.
SUM_TOL = 1e-7


@dataclass(frozen=True)
class Pulley:
    """One pulley: centre (m), radius (m) and side (+1 inner, -1 back-side idler)."""

    name: str
    centre: tuple[float, float]
    radius: float
    side: int


def _key(p: Pulley) -> str:
    return f"pulley {p.name!r}"


class _Frame:
    """The layout's figures in the counterclockwise frame (y mirrored when sense = -1)."""

    def __init__(self, pulleys: tuple[Pulley, ...], sense: int):
        self.sense = sense
        n = len(pulleys)
        P = np.array([p.centre for p in pulleys], dtype=float)
        if sense < 0:
            P[:, 1] = -P[:, 1]
        self.centres = P
        self.radii = np.array([p.radius for p in pulleys], dtype=float)
        self.sides = np.array([p.side for p in pulleys], dtype=int)
        q = self.sides * self.radii
        nxt = np.roll(np.arange(n), -1)
        D = P[nxt] - P
        d = np.hypot(D[:, 0], D[:, 1])
        dq = q[nxt] - q
        self.phi = np.arctan2(D[:, 1], D[:, 0]) - np.arcsin(dq / d)
        self.t = np.column_stack([np.cos(self.phi), np.sin(self.phi)])
        Jt = np.column_stack([-self.t[:, 1], self.t[:, 0]])
        self.spans = np.sqrt((d - dq) * (d + dq))  # d^2 - dq^2 without cancellation
        self.departure = P - q[:, None] * Jt
        self.arrival = P[nxt] - q[nxt, None] * Jt
        # the direction turns from the arriving span (j - 1) to the departing one (j)
        turn = self.phi - np.roll(self.phi, 1)
        self.wraps = np.mod(self.sides * turn, TWO_PI)
        self.turning = float(np.sum(self.sides * self.wraps))

    def problem(self, pulleys) -> str | None:
        """The first rule this reading breaks (a one-line message), None if it keeps
        them all."""
        n = len(pulleys)
        for i, w in enumerate(self.wraps):
            if w < WRAP_TOL or w > TWO_PI - WRAP_TOL:
                return (f"{_key(pulleys[i])}.centre: the belt runs straight past it "
                        f"(wrap <= 0): move it into the belt")
        ends = list(zip(self.departure, self.arrival))
        for i in range(n):
            # a pulley whose arriving and departing spans cross: the direction turns the
            # long way round it, which is how a bend against its side (wrap < 0) reads
            # modulo 2 pi
            if _segments_cross(*ends[i - 1], *ends[i]):
                return (f"{_key(pulleys[i])}.side: its two spans cross: the belt would "
                        f"bend against this pulley's side (wrap <= 0) or cross itself")
        for j in range(n):
            for m in range(j + 2, n if j > 0 else n - 1):  # the neighbours are done
                if _segments_cross(*ends[j], *ends[m]):
                    return (f"{_key(pulleys[(m + 1) % n])}.centre: span "
                            f"{pulleys[j].name!r}->{pulleys[(j + 1) % n].name!r} crosses "
                            f"span {pulleys[m].name!r}->{pulleys[(m + 1) % n].name!r} "
                            f"(the belt would cross itself)")
        for j in range(n):
            for k in range(n):
                if k in (j, (j + 1) % n):
                    continue
                gap = _distance_to_segment(self.centres[k], *ends[j])
                if gap < self.radii[k] * (1.0 - 1e-12):
                    return (f"{_key(pulleys[k])}.centre: span {pulleys[j].name!r}->"
                            f"{pulleys[(j + 1) % n].name!r} runs through it")
        if abs(self.turning - TWO_PI) > SUM_TOL:
            # an excess of 2 pi m: m inner wraps measured the long way round (the belt bends
            # against their side); a deficit: back-side wraps. Name the likeliest one.
            excess = self.turning - TWO_PI
            side = 1 if excess > 0 else -1
            cand = [i for i in range(n) if self.sides[i] == side] or list(range(n))
            i = max(cand, key=lambda k: self.wraps[k])
            return (f"{_key(pulleys[i])}.side: the wraps' sum rule (inner minus back-side "
                    f"wraps = 2 pi) fails in both senses ({self.turning:.6g} rad in the "
                    f"listed sense): the belt bends against this pulley's side")
        return None


def _listed_sense(pulleys) -> int:
    """The sense the pulleys are listed in, by the signed area of the polygon of the
    inner pulleys' centres (of all centres with fewer than three inner pulleys); +1 when
    it vanishes (two pulleys)."""
    inner = [p.centre for p in pulleys if p.side > 0]
    pts = np.array(inner if len(inner) >= 3 else [p.centre for p in pulleys], dtype=float)
    x, y = pts[:, 0], pts[:, 1]
    area = 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))
    scale = float(np.ptp(x) + np.ptp(y)) ** 2
    return -1 if area < -1e-12 * scale else 1


def _cross(o, a, b) -> float:
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def _segments_cross(a, b, c, d) -> bool:
    """Whether the segments ab and cd intersect (touching counts)."""
    d1, d2 = _cross(c, d, a), _cross(c, d, b)
    d3, d4 = _cross(a, b, c), _cross(a, b, d)
    return d1 * d2 <= 0.0 and d3 * d4 <= 0.0 and not (d1 == d2 == 0.0)


def _distance_to_segment(p, a, b) -> float:
    ab = b - a
    s = np.clip(np.dot(p - a, ab) / np.dot(ab, ab), 0.0, 1.0)
    return float(np.hypot(*(a + s * ab - p)))


def _check_pulleys(pulleys: tuple[Pulley, ...]) -> None:
    """The rules each pulley and each pair keeps whatever the sense."""
    if len(pulleys) < 2:
        raise GeometryError(f"pulleys: a belt needs at least 2 pulleys, got {len(pulleys)}")
    seen = set()
    for p in pulleys:
        if p.name in seen:
            raise GeometryError(f"{_key(p)}.name: two pulleys share this name")
        seen.add(p.name)
        if len(p.centre) != 2 or not all(math.isfinite(v) for v in p.centre):
            raise GeometryError(f"{_key(p)}.centre: must be two finite numbers (x, y) in m, "
                                f"got {p.centre!r}")
        if not (math.isfinite(p.radius) and p.radius > 0):
            raise GeometryError(f"{_key(p)}.radius: must be > 0, got {p.radius!r}")
        if p.side not in (1, -1):
            raise GeometryError(f"{_key(p)}.side: must be +1 (inner face) or -1 (back-side), "
                                f"got {p.side!r}")
    for i, a in enumerate(pulleys):
        for b in pulleys[i + 1:]:
            d = math.dist(a.centre, b.centre)
            if d < a.radius + b.radius:
                raise GeometryError(
                    f"{_key(b)}.centre: overlaps {_key(a)} (centre distance {d:.6g} m < "
                    f"sum of radii {a.radius + b.radius:.6g} m)")
    n = len(pulleys)
    for i, a in enumerate(pulleys):
        b = pulleys[(i + 1) % n]
        d = math.dist(a.centre, b.centre)
        dq = b.side * b.radius - a.side * a.radius
        if abs(dq) >= d:
            raise GeometryError(
                f"{_key(b)}.centre: no common tangent with {_key(a)} (|signed radii "
                f"difference| {abs(dq):.6g} m >= centre distance {d:.6g} m)")


class PulleyLayout:
    """A belt on N >= 2 pulleys in the plane, listed in the order the belt runs.

    Parameters
    ----------
    pulleys : sequence of Pulley
        In material order: span j runs from pulley j to pulley j + 1 (mod N). Either
        sense of listing is accepted; ``sense`` tells which it is.
    sense : {None, 1, -1}
        None (default) finds the sense in which the pulleys make a belt loop, trying
        first the sense of the polygon of the inner pulleys' centres (counterclockwise
        for two pulleys). A few layouts make a valid loop in both senses (two different
        belts, e.g. two inner pulleys and a back-side idler that can sit on either
        span): then that polygon's sense is taken unless ``sense`` asks for the other.

    Raises
    ------
    GeometryError
        The pulleys make no belt loop; the one-line message names the key
        (``pulley 'name'.radius`` etc.) and the rule.
    """

    def __init__(self, pulleys: Sequence[Pulley], sense: int | None = None):
        self.pulleys = tuple(pulleys)
        _check_pulleys(self.pulleys)
        if sense not in (None, 1, -1):
            raise GeometryError(f"pulleys.sense: must be None, 1 or -1, got {sense!r}")
        found = []
        # the listed sense first: it wins for the layouts that make a belt both ways
        # round, and its message is the one reported when neither does
        guess = _listed_sense(self.pulleys)
        for trial in (guess, -guess) if sense is None else (sense,):
            frame = _Frame(self.pulleys, trial)
            bad = frame.problem(self.pulleys)
            if bad is None:
                break
            found.append(bad)
        else:
            raise GeometryError(found[0])
        self._f = frame
        self.sense = frame.sense
        self.wraps = frame.wraps.copy()
        self.spans = frame.spans.copy()
        self.radii = frame.radii.copy()
        self.sides = frame.sides.copy()
        arcs = self.radii * self.wraps
        self.lengths = np.column_stack([arcs, self.spans]).ravel()
        self.bounds = np.concatenate([[0.0], np.cumsum(self.lengths)])
        self.loop_length = float(self.bounds[-1])
        flip = np.array([1.0, float(self.sense)])  # mirror back to the caller's frame
        self.centres = frame.centres * flip
        self.span_directions = frame.t * flip
        self.departure_points = frame.departure * flip
        self.arrival_points = frame.arrival * flip

    def __len__(self) -> int:
        return len(self.pulleys)

    def __repr__(self) -> str:
        names = ", ".join(p.name for p in self.pulleys)
        return f"PulleyLayout([{names}], loop_length={self.loop_length:.6g})"

    @property
    def names(self) -> tuple[str, ...]:
        """The pulleys' names in loop order."""
        return tuple(p.name for p in self.pulleys)

    @property
    def arcs(self) -> np.ndarray:
        """Arc lengths r_i wrap_i (m)."""
        return self.radii * self.wraps

    @property
    def span_angles(self) -> np.ndarray:
        """Each span's direction angle (rad) in the counterclockwise frame (the caller's,
        y mirrored when ``sense`` = -1): with q_i = side_i r_i, the wrap of pulley i
        changes by side_i times the change of span i's angle less span i - 1's."""
        return self._f.phi.copy()

    @property
    def spin(self) -> np.ndarray:
        """Each pulley's turning sense in the caller's frame (+1 counterclockwise), with
        the belt running in the loop's direction: sense s_i."""
        return self.sense * self.sides

    def index(self, name: str) -> int:
        """The index of the pulley called ``name``."""
        return self.names.index(name)

    def segment_of(self, x) -> np.ndarray:
        """Index into the 2N segments (arc i = 2 i, span j = 2 j + 1) of each loop
        coordinate x (taken modulo the loop length)."""
        xs = np.mod(np.asarray(x, dtype=float), self.loop_length)
        top = 2 * len(self.pulleys) - 1
        return np.clip(np.searchsorted(self.bounds, xs, side="right") - 1, 0, top)

    def path(self, x) -> tuple[np.ndarray, np.ndarray]:
        """Points (X, Y) (m) of the belt line at loop coordinates x: arcs on the pulleys'
        circles, spans straight."""
        f = self._f
        xs = np.mod(np.asarray(x, dtype=float), self.loop_length)
        seg = self.segment_of(xs)
        X = np.empty_like(xs)
        Y = np.empty_like(xs)
        n = len(self.pulleys)
        for i in range(n):
            on = seg == 2 * i
            # start at the arrival normal of span i - 1, turn in the sense of the side
            a0 = f.arrival[i - 1] - f.centres[i]
            ang = (math.atan2(a0[1], a0[0])
                   + f.sides[i] * (xs[on] - self.bounds[2 * i]) / f.radii[i])
            X[on] = f.centres[i, 0] + f.radii[i] * np.cos(ang)
            Y[on] = f.centres[i, 1] + f.radii[i] * np.sin(ang)
            on = seg == 2 * i + 1
            s = xs[on] - self.bounds[2 * i + 1]
            X[on] = f.departure[i, 0] + s * f.t[i, 0]
            Y[on] = f.departure[i, 1] + s * f.t[i, 1]
        return X, self.sense * Y

    def moved(self, index: int, centre: tuple[float, float]) -> PulleyLayout:
        """A new layout with pulley ``index``'s centre at ``centre`` (a tensioner's
        stroke), in this layout's sense (a stroke never flips the belt to the other
        reading); raises GeometryError when the moved layout breaks a rule."""
        pulleys = list(self.pulleys)
        pulleys[index] = replace(pulleys[index], centre=(float(centre[0]), float(centre[1])))
        return PulleyLayout(pulleys, sense=self.sense)


__all__ = ["GeometryError", "Pulley", "PulleyLayout"]
