"""The discrete model's data, as its kernels read them.

The kernels (:mod:`beltsim.physics.model`) read the coefficients (:class:`ModelParams`), a
layout on its grid (:class:`Mesh`; the open layout's from :func:`mesh_of`, a loop's from
:mod:`beltsim.physics.layout`), the state (:class:`State`) and the distributed loads
(:class:`Loads`, tabulated in time, with the kernels that interpolate them).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from .friction import ADHESION, AUGMENTATION, EXACT, LINEAR, TANH, has_dual

#: The gyroscopic term's forms (``numerics.gyroscopic``): first-order upwind, which damps
#: the spans' modes numerically, or the Galerkin (skew) form, second order and without
#: numerical damping (docs/theory/discretisation.md, "The gyroscopic term").
UPWIND, CENTRAL = 0, 1
GYROSCOPIC_FORMS = {"upwind": UPWIND, "central": CENTRAL}


class ModelParams(NamedTuple):
    """The coefficients of the discrete model, as the kernels read them."""

    B: float  # effective tension stiffness b1 - rho c^2
    A: float  # effective bending stiffness a - I c^2
    shear: float  # b2
    mass: float  # rho, per unit length (0 when quasistatic)
    rotary_inertia: float  # I, per unit length (0 when quasistatic)
    speed: float  # c
    half_height: float  # h / 2: lever of the friction about the middle line
    damping: float  # d (1/s) of d rho u_t and d I theta_t
    friction_scale: float  # f_s in f = -f_s g(v_rel / v_reg)
    regularisation: float  # the law's velocity scale: v_reg; v_aug for the exact laws
    law: int  # friction law code (friction.LAW_CODES)
    dual: int  # 1: the friction ratio is a Newton unknown (primal-dual form)
    gyro: int = 0  # the gyroscopic term's form: UPWIND or CENTRAL
    # a closed loop's belt speed c is an unknown: its stiffnesses b1 - rho c^2, a - I c^2
    # follow it, and N0 (the installation tension) enters the pressure and the creep
    b1: float = 0.0
    a: float = 0.0
    N0: float = 0.0


class Mesh(NamedTuple):
    """A layout on its grid as the kernels read it: the nodes, the contact's friction
    stencil, the contact segments and the closure.

    Open (the paper's belt, ``off`` = 1): nodes 0..N with u = theta = 0 at both ends,
    the unknowns at the interior nodes 1..N-1 (row i is node i + 1). Closed (a loop,
    ``off`` = 0): nodes 0..N-1, periodic, every node an unknown (row i is node i), and
    element j is [x_j, x_{j+1}] with x_N = x_0 + the loop's length.

    Friction acts at the nodes ``cn``: node j carries the nodal force F_j = -wf_j S_j
    lam_j, lam_j the friction ratio of its slip velocity v_rel,j = d/dt u_b,j + c sum_o
    sw[j, o] u_b,{j-2+o} - target (offsets -2..0, periodic on a loop). On segment s
    = seg[j] the bound S_j is f_s (a plate; seg_mu[s] = 0) or seg_mu[s] p_j with the
    pressure p_j = (N0 + b1 u_x - rho c^2) / seg_radius[s] (a pulley's arc); the target
    is v(t) - c on an open layout, and on a loop the rim speed less the belt's material
    speed c (1 + N0 / b1): the drive's prescribed rim speed where seg_speed[s] < 0, else
    that of the free pulley whose speed is the global unknown seg_speed[s].
    """

    he: np.ndarray  # element lengths (N)
    hb: np.ndarray  # nodal control-volume lengths (N + 1 open, N closed)
    j1: int  # open: node at x1
    j2: int  # open: node at x2
    c0: int  # open: first friction node
    wf: np.ndarray  # friction weight (m) of each node, 0 off the friction nodes
    sw: np.ndarray  # d/dx u_b at node j: weights of u_b at j-2, j-1, j (nodes, 3)
    off: int = 1  # node of row 0: 1 open, 0 closed
    cn: np.ndarray = np.zeros(0, dtype=np.int64)  # the friction nodes, in order
    seg: np.ndarray = np.zeros(0, dtype=np.int64)  # contact segment of each node, -1 off
    seg_mu: np.ndarray = np.zeros(0)  # friction coefficient of a pulley arc; 0: a plate
    seg_radius: np.ndarray = np.zeros(0)  # pulley radius (m)
    seg_speed: np.ndarray = np.zeros(0, dtype=np.int64)  # global of the rim speed, or -1
    loop_length: float = 0.0  # closed: the loop's length Lambda (m)
    #: closed: the factor of each global's rate in its row: 0 for c, J (kg m^2) for a
    #: pulley's speed, 1 for a tensioner arm's angle and its J for its rate
    inertia: np.ndarray = np.zeros(0)
    #: the face in contact at each node: +1 the bottom fibre (lever +h/2), -1 the top
    #: (a back-side idler's arc); a span's nodes take the next arc's, whose stencil they
    #: enter
    face: np.ndarray = np.ones(0)
    #: a tensioner's arm (:mod:`beltsim.physics.arm`; empty without one): each
    #: element's stretched span (0: a, arriving at the arm's pulley; 1: b, leaving it;
    #: -1 neither), ...
    arm_el: np.ndarray = np.zeros(0, dtype=np.int64)
    #: ... the Chebyshev rows of the spans' length changes and their derivatives in the
    #: arm's angle (:class:`beltsim.beltdrive.arm.ArmTable`), ...
    arm_coef: np.ndarray = np.zeros((0, 0))
    #: ... (k_t, tau0, damping, the reference's turn, lo, hi, l_a, l_b): the spring, the
    #: table's interval and the stretched lengths of the two spans, ...
    arm_par: np.ndarray = np.zeros(0)
    #: ... and (the global of its angle (its rate the next), span a's last element,
    #: span b's first)
    arm_idx: np.ndarray = np.zeros(0, dtype=np.int64)


class State(NamedTuple):
    """The discrete state: nodal fields, their local rates, the friction unknowns and
    the layout's global unknowns.

    ``lam`` holds, at contact nodes, the friction ratio g(v_rel / v_reg) (Newton
    schemes) or the argument v_rel / v_reg itself (the explicit scheme's warm start);
    ``fnode`` the nodal friction forces of the state (N). ``g`` holds a loop's global
    unknowns (its belt speed c, then the free pulleys' speeds), ``gd`` their rates;
    both are empty on an open layout.
    """

    u: np.ndarray
    theta: np.ndarray
    lam: np.ndarray
    ud: np.ndarray
    td: np.ndarray
    fnode: np.ndarray
    g: np.ndarray = np.zeros(0)
    gd: np.ndarray = np.zeros(0)

    @classmethod
    def zeros(cls, n_nodes: int, n_globals: int = 0) -> State:
        """The state at rest on ``n_nodes`` nodes with ``n_globals`` global unknowns."""
        return cls(*(np.zeros(n_nodes) for _ in range(6)), np.zeros(n_globals),
                   np.zeros(n_globals))

    def copy(self) -> State:
        """A copy of every array."""
        return State(*(a.copy() for a in self))

    def assign(self, other) -> None:
        """Copy another state's arrays into this one's, in place."""
        for a, b in zip(self, other):
            a[:] = b


class Loads(NamedTuple):
    """Distributed loads on the belt, tabulated in time: q_u (N/m) and q_theta (N m/m).

    At the nodes, at ``times`` (K), with their time derivatives; cubic Hermite
    interpolation in between (error O(dt_table^4)), held constant outside. They enter
    the model as hbar_j q at node j. No times: no loads (the default; an API feature
    for manufactured solutions and external excitation, not a scene key).
    """

    times: np.ndarray  # (K,)
    qu: np.ndarray  # (K, N + 1)
    qt: np.ndarray
    dqu: np.ndarray  # d/dt of qu, qt
    dqt: np.ndarray

    @classmethod
    def none(cls, n_nodes: int) -> Loads:
        """No loads on ``n_nodes`` nodes."""
        empty = np.zeros((0, n_nodes))
        return cls(np.zeros(0), empty, empty, empty, empty)


@njit(cache=True)
def hermite_weights(times, t):
    """(k, w0, w1, v0, v1): q(t) = w0 q_k + w1 q_{k+1} + v0 q'_k + v1 q'_{k+1}; k = -1: none."""
    K = times.shape[0]
    if K == 0:
        return -1, 0.0, 0.0, 0.0, 0.0
    if K == 1 or t <= times[0]:
        return 0, 1.0, 0.0, 0.0, 0.0
    if t >= times[K - 1]:
        return K - 2, 0.0, 1.0, 0.0, 0.0
    lo, hi = 0, K - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if times[mid] <= t:
            lo = mid
        else:
            hi = mid
    dt = times[lo + 1] - times[lo]
    s = (t - times[lo]) / dt
    s2, s3 = s * s, s * s * s
    return (lo, 2.0 * s3 - 3.0 * s2 + 1.0, -2.0 * s3 + 3.0 * s2, (s3 - 2.0 * s2 + s) * dt,
            (s3 - s2) * dt)


@njit(cache=True)
def load_at(q, dq, k, w0, w1, v0, v1, j):
    """A tabulated load at node j, from the weights of :func:`hermite_weights` (0 for k < 0)."""
    if k < 0:
        return 0.0
    if q.shape[0] == 1:  # one row: a constant load (there is no q[k + 1])
        return q[0, j]
    return w0 * q[k, j] + w1 * q[k + 1, j] + v0 * dq[k, j] + v1 * dq[k + 1, j]


def model_params(P, damping, friction_scale, regularisation, law_code,
                 gyro=UPWIND) -> ModelParams:
    """The model's coefficients from the physical parameters, the friction settings and
    the gyroscopic term's form (UPWIND or CENTRAL)."""
    # the linear law's dual and primal forms coincide; saturating laws need the dual
    dual = int(has_dual(law_code) and law_code != LINEAR)
    return ModelParams(
        B=P.B, A=P.A, shear=P.b2, mass=P.rho, rotary_inertia=P.I,
        speed=P.c, half_height=0.5 * P.h, damping=damping, friction_scale=friction_scale,
        regularisation=regularisation, law=law_code, dual=dual, gyro=gyro)


def regularised(p: ModelParams) -> ModelParams:
    """The regularised twin of an exact law, the exact law's starting point: tanh with the
    default v_reg = v_aug / AUGMENTATION for Coulomb, the linear law of the default
    adhesion layer (slope f_s / v_aug) for adhesion."""
    if p.law == EXACT:
        return p._replace(law=TANH, dual=1, regularisation=p.regularisation / AUGMENTATION)
    if p.law == ADHESION:
        return p._replace(law=LINEAR, dual=0)
    return p


def contact_stencil(x, j1, j2):
    """(c0, wf, sw) of the contact [x_j1, x_j2] on the nodes x (see :class:`Mesh`).

    The slip velocity at node j with the one-sided three-point derivative over x_{j-2},
    x_{j-1}, x_j (second order, exact for quadratics on any grid), its friction on the
    contact part of node j's control volume (c0 = j1, half volumes at x1 and x2:
    trapezoidal quadrature). On a uniform grid the homogeneous solutions of the
    three-point upwind difference are 1 and 3^-k (k nodes downstream): no odd-even mode.
    """
    x = np.asarray(x, dtype=float)
    N = len(x) - 1
    he = np.diff(x)
    wf = np.zeros(N + 1)
    sw = np.zeros((N + 1, 3))
    j = np.arange(j1, j2 + 1)
    wf[j] = 0.5 * (np.where(j > j1, he[j - 1], 0.0) + np.where(j < j2, he[j], 0.0))
    h1, h2 = he[j - 1], he[j - 2]
    sw[j, 0] = h1 / (h2 * (h1 + h2))
    sw[j, 1] = -(h1 + h2) / (h1 * h2)
    sw[j, 2] = (2.0 * h1 + h2) / (h1 * (h1 + h2))
    return j1, wf, sw


def mesh_of(grid) -> Mesh:
    """The open layout of a grid as the kernels read it (:class:`Mesh`): one plate
    contact on [x1, x2], with its friction stencil."""
    c0, wf, sw = contact_stencil(grid.x, grid.j1, grid.j2)
    seg = -np.ones(len(grid.x), dtype=np.int64)
    seg[c0:grid.j2 + 1] = 0
    return Mesh(grid.he, grid.hbar, grid.j1, grid.j2, c0, wf, sw, off=1,
                cn=np.arange(c0, grid.j2 + 1, dtype=np.int64), seg=seg,
                seg_mu=np.zeros(1), seg_radius=np.zeros(1),
                seg_speed=-np.ones(1, dtype=np.int64), face=np.ones(len(grid.x)))
