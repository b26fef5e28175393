"""The fixed (Eulerian) grid over the control domain [0, L].

Nodes sit exactly at x1 and x2, so the contact zone is a union of whole
elements, and at the expected slip start x* (where friction jumps to f*) when it lies
inside the contact. Elements can be graded towards x2, where the concentrated force
and the steepest gradients are, and towards x*: the element size grows linearly with
the distance from the nearest of them, up to ``grading`` times the smallest element.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import SceneError
from ..problem.scene import MIN_ELEMENTS

# fewest elements on either side of an anchored point (see make_grid)
ANCHOR_ELEMENTS = 2


@dataclass(frozen=True)
class Grid:
    """The nodes of a fixed (Eulerian) grid on [0, L], with nodes at x1 and x2."""

    x: np.ndarray  # node coordinates, x[0] = 0, x[-1] = L
    j1: int  # node index of x1
    j2: int  # node index of x2

    @property
    def n_elements(self) -> int:
        """Number of elements N."""
        return len(self.x) - 1

    @property
    def he(self) -> np.ndarray:
        """Element lengths (N)."""
        return np.diff(self.x)

    @property
    def hbar(self) -> np.ndarray:
        """Nodal control-volume lengths (N + 1): half of each adjacent element."""
        he = self.he
        hb = np.zeros(len(self.x))
        hb[:-1] += 0.5 * he
        hb[1:] += 0.5 * he
        return hb

    @property
    def h_min(self) -> float:
        """The smallest element's length (m)."""
        return float(self.he.min())


def make_grid(L: float, x1: float, x2: float, elements: int, grading: float = 1.0,
              refine_at: tuple = ()) -> Grid:
    """A grid of ``elements`` elements with nodes at x1 and x2.

    The mesh density 1/h(x) is integrated numerically and inverted on each segment
    between breakpoints, so any density works; the number of elements of each segment
    follows its share of the integrated density (at least 2). ``refine_at`` adds
    further points (e.g. an expected slip start) towards which the grid is graded as
    towards x2; those inside (x1, x2) are also breakpoints, nodes of the grid, where
    each side gets at least ANCHOR_ELEMENTS elements of its share (else the point is
    only graded towards). A node at the slip start x* keeps the front inside the same
    control volume, at its node, as the grid is refined, so the observed orders of the
    slip scene stay steady instead of scattering as x* crosses control-volume edges
    (docs/theory/discretisation.md, "The grid").
    """
    if elements < MIN_ELEMENTS:
        raise SceneError("numerics.elements", f"must be >= {MIN_ELEMENTS}, got {elements}")
    if grading < 1.0:
        raise SceneError("numerics.grading", f"must be >= 1, got {grading}")
    centres = [x2, *refine_at]
    span = max(x2, L - x2)

    def h_rel(x):  # relative element size, 1 at the refinement centres
        d = np.min(np.abs(np.subtract.outer(x, np.asarray(centres))), axis=-1)
        return 1.0 + (grading - 1.0) * d / span

    inner = sorted(r for r in refine_at if x1 < r < x2)
    fine = np.linspace(0.0, L, 20001)
    fine = np.union1d(fine, [x1, x2, *inner])
    dens = 1.0 / h_rel(fine)
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (dens[1:] + dens[:-1]) * np.diff(fine))])
    scale = elements / cum[-1]  # elements per unit of integrated density
    anchors = [r for r in inner
               if min(np.interp(r, fine, cum) - np.interp(x1, fine, cum),
                      np.interp(x2, fine, cum) - np.interp(r, fine, cum)) * scale
               >= ANCHOR_ELEMENTS]
    breaks = [0.0, x1, *anchors, x2, L]
    sb = np.interp(breaks, fine, cum)
    shares = np.diff(sb) / cum[-1]
    counts = np.maximum(2, np.round(shares * elements).astype(int))
    while counts.sum() > elements:
        counts[np.argmax(counts)] -= 1
    while counts.sum() < elements:
        counts[np.argmax(shares * elements - counts)] += 1
    nodes = [np.array([0.0])]
    for k, n in enumerate(counts):
        xs = np.interp(np.linspace(sb[k], sb[k + 1], n + 1)[1:], cum, fine)
        xs[-1] = breaks[k + 1]  # exact breakpoints
        nodes.append(xs)
    x = np.concatenate(nodes)
    j1 = int(counts[0])
    j2 = int(counts[:-1].sum())
    if np.any(np.diff(x) <= 0.0):
        raise SceneError("numerics.elements", "too few elements for this grading and geometry")
    return Grid(x=x, j1=j1, j2=j2)


def bisect(grid: Grid) -> Grid:
    """The grid with every element halved: nested, so coarse nodes are fine nodes."""
    mid = 0.5 * (grid.x[1:] + grid.x[:-1])
    x = np.empty(2 * len(grid.x) - 1)
    x[0::2], x[1::2] = grid.x, mid
    return Grid(x=x, j1=2 * grid.j1, j2=2 * grid.j2)
