"""Layouts: where the belt runs, as data the one discrete model reads.

A layout is a sequence of segments along the belt (a free span; contact with a moving
plate of prescribed speed, the paper's; contact on a pulley's arc) and a closure: open,
with the material entering at x = 0 and leaving at x = L at the speed c (the paper's
control domain, :func:`beltsim.physics.discrete.mesh_of`), or a closed loop, whose belt
speed c and free pulleys' speeds are global unknowns of the model (:func:`loop_mesh`).
Both come out as a :class:`~beltsim.physics.discrete.Mesh`: the kernels, the schemes and the
linear solve read nothing else.

The two-pulley loop, in the loop coordinate x in [0, Lambda) of the belt's motion:
driver arc (segment 0, its rim speed prescribed), slack span, driven arc (segment 1, its
rim speed omega_2 R_2 the global unknown 1), tight span; global 0 is c.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .discrete import UPWIND, Mesh, ModelParams

#: The fewest elements on each of a loop's segments.
MIN_SEGMENT_ELEMENTS = 4


def loop_nodes(lengths, elements: int) -> tuple[np.ndarray, np.ndarray]:
    """(x, first): the nodes of a periodic grid with a node at each segment's start and
    elements of about equal length (at least MIN_SEGMENT_ELEMENTS a segment), and the
    index of each segment's first node (with the node count appended)."""
    lengths = np.asarray(lengths, dtype=float)
    counts = np.maximum(MIN_SEGMENT_ELEMENTS,
                        np.round(elements * lengths / lengths.sum()).astype(int))
    bounds = np.concatenate([[0.0], np.cumsum(lengths)])
    x = np.concatenate([np.linspace(bounds[k], bounds[k + 1], counts[k], endpoint=False)
                        for k in range(len(lengths))])
    return x, np.concatenate([[0], np.cumsum(counts)])


@dataclass(frozen=True)
class LoopGrid:
    """The nodes of a periodic grid on a loop of length ``loop_length``: x[0] = 0, and
    element j is [x_j, x_{j+1}] with x_N = loop_length."""

    x: np.ndarray  # node coordinates (N)
    loop_length: float
    first: np.ndarray  # each segment's first node, and N

    @classmethod
    def build(cls, lengths, elements: int) -> LoopGrid:
        """About ``elements`` elements of equal length, a node at each segment's start."""
        x, first = loop_nodes(lengths, elements)
        return cls(x, float(np.sum(lengths)), first)

    @property
    def n_elements(self) -> int:
        """Number of elements N (= nodes)."""
        return len(self.x)

    @property
    def he(self) -> np.ndarray:
        """Element lengths (N)."""
        return np.diff(np.append(self.x, self.loop_length))

    @property
    def h_min(self) -> float:
        """The smallest element's length (m)."""
        return float(self.he.min())


def loop_mesh(grid: LoopGrid, contacts, mu, inertia: tuple[float, ...],
              faces=None) -> Mesh:
    """A closed layout on a periodic grid (:class:`LoopGrid`, a node at each segment's
    start).

    contacts: for each contact, a
    tuple (segment index, radius, speed global) with speed global -1 for the driver (its
    rim speed prescribed) or the index of the free pulley's speed among the globals;
    mu: each arc's friction coefficient (0: a constant bound, perfect adhesion);
    inertia: J of each global (0 for c);
    faces: each contact's face, +1 the belt's inner face (default), -1 its outer (a
    back-side idler: the friction's lever about the middle line changes sign).

    Each arc's friction acts from its entry node to its exit node (the next segment's
    first), half volumes at both ends, as on the open layout's plate.
    """
    x, first, loop_length = grid.x, grid.first, grid.loop_length
    N = len(x)
    he = grid.he
    hb = 0.5 * (he + np.roll(he, 1))
    seg = -np.ones(N, dtype=np.int64)
    wf = np.zeros(N)
    faces = np.ones(len(contacts)) if faces is None else np.asarray(faces, dtype=float)
    face = np.ones(N)
    # a span's nodes take the next arc's face (they enter its slip velocity's stencil)
    for s, (k, _, _) in enumerate(contacts):
        start, end = first[contacts[s - 1][0] + 1], first[k + 1]  # the two arcs' exits
        face[np.arange(start + 1, end + 1 + (N if end <= start else 0)) % N] = faces[s]
    for s, (k, _, _) in enumerate(contacts):
        j0, j1 = first[k], first[k + 1]
        js = np.arange(j0, j1 + 1) % N
        seg[js] = s
        wf[js] = hb[js]
        wf[j0 % N] = 0.5 * he[j0 % N]
        wf[j1 % N] = 0.5 * he[(j1 - 1) % N]
    h1 = np.roll(he, 1)  # x_j - x_{j-1}
    h2 = np.roll(he, 2)  # x_{j-1} - x_{j-2}
    sw = np.stack([h1 / (h2 * (h1 + h2)), -(h1 + h2) / (h1 * h2),
                   (2.0 * h1 + h2) / (h1 * (h1 + h2))], axis=1)
    return Mesh(he, hb, 0, 0, 0, wf, sw, off=0,
                cn=np.flatnonzero(seg >= 0).astype(np.int64), seg=seg,
                seg_mu=np.asarray(mu, dtype=float),
                seg_radius=np.array([r for _, r, _ in contacts], dtype=float),
                seg_speed=np.array([k for _, _, k in contacts], dtype=np.int64),
                loop_length=loop_length, inertia=np.asarray(inertia, dtype=float),
                face=face)


def with_arm(mesh: Mesh, grid: LoopGrid, pulley: int, n_pulleys: int, glob: int, table,
             spring: tuple[float, float, float]) -> Mesh:
    """``mesh`` with a tensioner's arm on pulley ``pulley`` (:mod:`beltsim.physics.arm`):
    its angle the global ``glob`` (its rate the next), ``table`` the spans' length
    changes (:class:`beltsim.beltdrive.arm.ArmTable`), ``spring`` (k_t, tau0, damping).
    Each of its two spans is stretched on all its elements but the last two, which the
    next arc's friction stencils reach."""
    first, N, he = grid.first, grid.n_elements, grid.he
    el = -np.ones(N, dtype=np.int64)
    lengths = []
    for s, seg in enumerate((2 * pulley - 1, 2 * pulley + 1)):
        seg %= 2 * n_pulleys
        js = np.arange(first[seg], first[seg + 1] - 2)
        el[js] = s
        lengths.append(float(he[js].sum()))
    span_a_end = first[(2 * pulley - 1) % (2 * n_pulleys) + 1] - 1
    span_b_start = first[(2 * pulley + 1) % (2 * n_pulleys)]
    return mesh._replace(
        arm_el=el, arm_coef=np.ascontiguousarray(table.coef, dtype=float),
        arm_par=np.array([*spring, table.turn, table.lo, table.hi, *lengths]),
        arm_idx=np.array([glob, span_a_end, span_b_start], dtype=np.int64))


def node_x(mesh: Mesh) -> np.ndarray:
    """The nodes' coordinates of a layout's grid (from 0)."""
    return np.concatenate([[0.0], np.cumsum(mesh.he)])[:len(mesh.hb)]


def loop_params(*, a, b1, b2, rho, I, lever, damping, N0, law, dual, regularisation,
                friction_scale=1.0, gyro=UPWIND) -> ModelParams:
    """The model's coefficients on a loop: the stiffnesses b1, a (B and A follow the
    belt speed, an unknown), the installation tension N0, the friction's lever and law;
    friction_scale is the constant bound of perfect adhesion's reaction."""
    return ModelParams(B=b1, A=a, shear=b2, mass=rho, rotary_inertia=I, speed=0.0,
                       half_height=lever, damping=damping, friction_scale=friction_scale,
                       regularisation=regularisation, law=law, dual=dual, gyro=gyro,
                       b1=b1, a=a, N0=N0)
