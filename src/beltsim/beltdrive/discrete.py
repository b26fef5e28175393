"""The drive's discretisation: the periodic grid, the kernel's coefficients, unknowns."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..physics.friction import LAW_CODES
from .geometry import Geometry
from .model import LoopMesh, LoopParams, n_unknowns
from .scene import MIN_SEGMENT_ELEMENTS, DriveParams

#: default elements on the loop
DEFAULT_ELEMENTS = 800


def loop_mesh(geometry: Geometry, elements: int) -> LoopMesh:
    """A periodic grid with nodes at the four segments' ends and elements of about equal
    length (at least MIN_SEGMENT_ELEMENTS per segment), with the contact stencils."""
    lengths = np.array(geometry.lengths)
    counts = np.maximum(MIN_SEGMENT_ELEMENTS,
                        np.round(elements * lengths / lengths.sum()).astype(int))
    bounds = geometry.bounds
    x = np.concatenate([np.linspace(bounds[k], bounds[k + 1], counts[k], endpoint=False)
                        for k in range(4)])
    N = len(x)
    he = np.diff(np.append(x, geometry.loop_length))
    hb = 0.5 * (he + np.roll(he, 1))
    first = np.concatenate([[0], np.cumsum(counts)])  # node index of each segment's start
    arc = -np.ones(N, dtype=np.int64)
    wf = np.zeros(N)
    radius = np.zeros(N)
    for a, seg in ((0, 0), (1, 2)):
        j0, j1 = first[seg], first[seg + 1]  # entry and exit nodes (exit = next seg's start)
        js = np.arange(j0, j1 + 1) % N
        arc[js] = a
        radius[js] = geometry.radii[a]
        wf[js] = hb[js]
        wf[j0 % N] = 0.5 * he[j0 % N]
        wf[j1 % N] = 0.5 * he[(j1 - 1) % N]
    h1 = np.roll(he, 1)  # x_j - x_{j-1}
    h2 = np.roll(he, 2)  # x_{j-1} - x_{j-2}
    sw = np.stack([h1 / (h2 * (h1 + h2)), -(h1 + h2) / (h1 * h2),
                   (2.0 * h1 + h2) / (h1 * (h1 + h2))], axis=1)
    lidx = -np.ones(N, dtype=np.int64)
    on = np.flatnonzero(arc >= 0)
    lidx[on] = np.arange(len(on))
    return LoopMesh(x, he, hb, arc, wf, sw, lidx, radius)


def law_of(P: DriveParams, friction_law: str | None) -> str:
    """The kernel's law: "exact" (Coulomb), "adhesion" (stick) or a regularised one."""
    if P.mu is None:
        return "adhesion"
    return friction_law or "exact"


def creep_speed(P: DriveParams) -> float:
    """The slip velocities' scale omega1 R1 N0 / b1 (m/s), the creep of the pretension."""
    return P.omega1 * P.geometry.R1 * P.N0 / P.b1


def loop_params(P: DriveParams, law: str, regularisation: float | None = None) -> LoopParams:
    """The kernel's coefficients. ``regularisation`` is v_reg of a regularised law; the
    exact laws' augmentation velocity is the creep speed (a numerical scale only)."""
    v = regularisation if law in ("tanh", "sqrt") else creep_speed(P)
    return LoopParams(
        a=P.a, b1=P.b1, b2=P.b2, rho=P.rho, I=P.I, lever=P.lever, damping=P.damping,
        N0=P.N0, mu=0.0 if P.mu is None else P.mu, J2=P.J2, R2=P.geometry.R2,
        law=LAW_CODES[law], v_scale=v, p_ref=P.N0 / P.geometry.R1)


@dataclass(frozen=True)
class Layout:
    """Where each unknown sits in the vector y: u at 2j, theta at 2j + 1, the friction
    ratios from 2N, then c and omega2."""

    N: int
    M: int

    @property
    def size(self) -> int:
        return 2 * self.N + self.M + 2

    @property
    def c(self) -> int:
        return 2 * self.N + self.M

    @property
    def omega2(self) -> int:
        return 2 * self.N + self.M + 1

    def u(self, y):
        return y[0:2 * self.N:2]

    def theta(self, y):
        return y[1:2 * self.N:2]

    def lam(self, y):
        return y[2 * self.N:2 * self.N + self.M]


def layout_of(mesh: LoopMesh) -> Layout:
    """The :class:`Layout` of a grid's unknowns."""
    N = len(mesh.x)
    lay = Layout(N, int(np.sum(mesh.lidx >= 0)))
    assert lay.size == n_unknowns(mesh)
    return lay


def scales(P: DriveParams) -> np.ndarray:
    """Magnitudes of u (m), theta, lam, c (m/s), omega2 (rad/s) for norms of updates."""
    g = P.geometry
    strain = P.N0 / P.b1
    return np.array([g.loop_length * strain, strain, 1.0, P.omega1 * g.R1,
                     max(P.omega1 * g.R1 / g.R2, 1e-300)])


def update_scale(lay: Layout, P: DriveParams) -> np.ndarray:
    """Per-unknown scale vector (see :func:`scales`)."""
    s = scales(P)
    out = np.empty(lay.size)
    out[0:2 * lay.N:2] = s[0]
    out[1:2 * lay.N:2] = s[1]
    out[2 * lay.N:2 * lay.N + lay.M] = s[2]
    out[lay.c] = s[3]
    out[lay.omega2] = s[4]
    return out


def residual_scale(lay: Layout, mesh: LoopMesh, P: DriveParams) -> np.ndarray:
    """Per-row scale of the residual (its size for an O(1) relative error)."""
    out = np.empty(lay.size)
    out[0:2 * lay.N:2] = P.N0
    out[1:2 * lay.N:2] = P.N0 * max(P.h, 1e-300)
    out[2 * lay.N:2 * lay.N + lay.M] = 1.0
    out[lay.c] = P.geometry.loop_length * P.N0 / P.b1
    out[lay.omega2] = P.N0 * P.geometry.R2
    return out


def string_guess(sol, mesh: LoopMesh, lay: Layout) -> np.ndarray:
    """The unknowns of a string solution on the grid (theta = 0): a Newton start."""
    P = sol.P
    y = np.zeros(lay.size)
    y[0:2 * lay.N:2] = sol.displacement(mesh.x)
    on = mesh.lidx >= 0
    if P.mu is not None:
        p = sol.pressure(mesh.x[on])
        lam = np.where(p > 0, -sol.friction(mesh.x[on]) / (P.mu * np.where(p > 0, p, 1.0)),
                       0.0)
        # inside (-1, 1): the regularised laws' inverse is singular on the boundary
        y[2 * lay.N:2 * lay.N + lay.M] = np.clip(lam, -1.0 + 1e-9, 1.0 - 1e-9)
    y[lay.c] = sol.c
    y[lay.omega2] = sol.omega2
    return y


