"""The discrete rotational model of a belt drive (Hwang, Perkins and Ulsoy 1994): rigid
pulleys coupled by the spans as axial springs, the exact reference of the belt model's
lowest modes in the limit of a belt much lighter than its pulleys in perfect adhesion.

Pulley i turns by theta_i, counted counterclockwise in the layout's counterclockwise
frame (:class:`~beltsim.beltdrive.pulleys.PulleyLayout` mirrors a clockwise listing). Its
rim moves along the belt's direction of motion by q_i theta_i, with the signed radius
q_i = s_i r_i: a back-side idler (s_i = -1) turns clockwise when the belt runs forward.
Span j, from pulley j to pulley j + 1, of length l_j, is a spring k_j = b1 / l_j on its
stretch

    delta_j = q_{j+1} theta_{j+1} - q_j theta_j,

the belt on the arcs stuck to the pulleys (perfect adhesion: the arcs do not stretch
relative to their pulley). The potential energy sum_j k_j delta_j^2 / 2 = theta^T K theta / 2
gives

    K = sum_j k_j a_j a_j^T,   a_j = q_{j+1} e_{j+1} - q_j e_j,

i.e. K_ii = q_i^2 (k_{i-1} + k_i), K_{i,i+1} = K_{i+1,i} = -q_i q_{i+1} k_i. The driver's
rotation is prescribed (held, in a perturbation): its row and column go, leaving N - 1
rotational degrees of freedom with the mass matrix M = diag(J_i). The natural
frequencies solve K x = omega^2 M x (a symmetric definite pencil, scipy.linalg.eigh).

A tensioner's arm (Beikmann, Perkins and Ulsoy 1996) adds its angle beta, with the arm's
inertia J_a: turning it lengthens its two spans a and b by delta_a'(0) beta and
delta_b'(0) beta (:mod:`beltsim.beltdrive.arm`), so a_a and a_b gain those entries in
beta's column, and the arm's own stiffness is its spring's and the spans' geometric one,
k_t + T_a delta_a'' + T_b delta_b'' (T the spans' tensions less rho c^2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg


def stiffness_matrix(signed_radii, span_stiffness, arm=None) -> np.ndarray:
    """The N x N stiffness matrix of N pulleys on a loop of springs (all pulleys free).

    Parameters
    ----------
    signed_radii : array_like
        q_i = s_i r_i (m): negative for a back-side idler.
    span_stiffness : array_like
        k_j = b1 / l_j (N/m) of span j, from pulley j to pulley j + 1 (mod N).
    arm : array_like, optional
        Each span's stretch per unit turn of a tensioner's arm (m/rad): the arm's angle
        is then an (N + 1)-th degree of freedom (its spring not included).

    Returns
    -------
    numpy.ndarray
        K (N m / rad) with theta^T K theta / 2 the springs' energy.
    """
    q = np.asarray(signed_radii, dtype=float)
    k = np.asarray(span_stiffness, dtype=float)
    n = len(q)
    if len(k) != n or n < 2:
        raise ValueError(f"need N >= 2 radii and as many spans, got {n} and {len(k)}")
    m = n if arm is None else n + 1
    K = np.zeros((m, m))
    for j in range(n):
        a = np.zeros(m)
        # two pulleys: spans 0 and 1 both join pulley 0 to pulley 1
        a[(j + 1) % n] += q[(j + 1) % n]
        a[j] -= q[j]
        if arm is not None:
            a[n] = arm[j]
        K += k[j] * np.outer(a, a)
    return K


@dataclass(frozen=True)
class RotationalModel:
    """The pulleys on spring spans, the driver held (N - 1 degrees of freedom).

    Attributes
    ----------
    names : tuple of str
        The free pulleys (every one but the driver), in the belt's order.
    inertia : numpy.ndarray
        Their inertias J_i (kg m^2), the diagonal of M.
    stiffness : numpy.ndarray
        K over their rotations (N m / rad), the driver's row and column removed.
    signed_radii : numpy.ndarray
        q_i of the free pulleys (m).
    span_stiffness : numpy.ndarray
        k_j = b1 / l_j of every span (N/m).
    """

    names: tuple[str, ...]
    inertia: np.ndarray
    stiffness: np.ndarray
    signed_radii: np.ndarray
    span_stiffness: np.ndarray

    def solve(self) -> tuple[np.ndarray, np.ndarray]:
        """(omega, X): the natural angular frequencies (rad/s, ascending) and the mode
        shapes (columns, rotations theta_i in rad, M-normalised: X^T M X = 1)."""
        w2, X = scipy.linalg.eigh(self.stiffness, np.diag(self.inertia))
        # a drive with every span joined to a held pulley has K positive definite; the
        # clip keeps round-off of a nearly free pulley from reading as an imaginary root
        return np.sqrt(np.clip(w2, 0.0, None)), X

    @property
    def frequencies(self) -> np.ndarray:
        """The natural frequencies (Hz, ascending)."""
        return self.solve()[0] / (2.0 * math.pi)


def rotational_model(params, tension: float | None = None) -> RotationalModel:
    """The discrete rotational model of a drive's data.

    Parameters
    ----------
    params : DriveParams
        The drive (a drive scene's ``params``):
        its layout's spans and sides, its pulleys' radii and inertias, b1 = EA; with a
        tensioner, its layout the one with the arm at rest.
    tension : float, optional
        With a tensioner: the spans' tension less rho c^2 (N), equal in every span
        without loads (default: the installation tension N0 of ``params``).

    Returns
    -------
    RotationalModel
        With the driver's rotation held; a tensioner's arm angle the last degree of
        freedom (named "arm").
    """
    layout = params.layout
    q = layout.sides * layout.radii
    k = params.b1 / layout.spans
    K = stiffness_matrix(q, k)
    keep = [i for i in range(len(q)) if i != params.driver]
    names = tuple(layout.names[i] for i in keep)
    inertia = np.array([params.pulleys[i].inertia for i in keep])
    ten = params.tensioner
    if ten is not None:
        from .arm import arm_table

        n = len(q)
        table = arm_table(params)
        T = params.N0 if tension is None else tension
        # each span's stretch per unit of the arm's angle: spans a (into the arm's
        # pulley) and b (out of it)
        g = np.zeros(n)
        g[(ten.index - 1) % n] += table(0.0, 2)
        g[ten.index] += table(0.0, 3)
        K = stiffness_matrix(q, k, g)
        K[n, n] += ten.stiffness + T * (table(0.0, 4) + table(0.0, 5))
        keep = [*keep, n]
        names = (*names, "arm")
        inertia = np.append(inertia, ten.inertia)
        q = np.append(q, 0.0)
    return RotationalModel(names=names, inertia=inertia, stiffness=K[np.ix_(keep, keep)],
                           signed_radii=q[keep], span_stiffness=k)


#: The limit's belt: the scene's density times this. Far smaller loses digits: the belt
#: model's linearisation is read off its Jacobian at rates of the grid's highest frequency
#: sqrt(b1 / rho) / h (at 1e-6 drive_flat's frequency is 1.6e-4 off, and the string's
#: rotary rows show spurious growing pairs at MHz)
LIGHT = 1e-4


def adhesion_limit(scene, light: float = LIGHT, speed: float = 0.5, elements: int = 100):
    """A drive scene in the rotational model's limit.

    Perfect adhesion (``contact.friction = "stick"``), no load torques (both tensions of
    every pulley equal: no creep), the belt ``light`` times as dense, no damping (a
    tensioner's arm's neither), the
    string, the driver at ``speed`` rad/s: so slow that the transport of the strain
    frozen on the stuck arcs shows as overdamped pairs of a few hertz, apart from the
    rotational modes.

    Parameters
    ----------
    scene : DriveScene
        The drive.
    light : float, optional
        The belt's density factor.
    speed : float, optional
        The driver's speed (rad/s).
    elements : int, optional
        The grid (numerics.elements).

    Returns
    -------
    DriveScene
    """
    data = scene.to_dict()
    data["contact"] = {"friction": "stick"}
    for p in data.get("pulley", []):
        p.pop("friction_coefficient", None)
        if "load_torque" in p:
            p["load_torque"] = 0.0
        if "speed" in p:
            p["speed"] = speed
    if "driver_speed" in data["drive"]:
        data["drive"].update(driver_speed=speed, load_torque=0.0)
    data["belt"]["density"] *= light
    data["physics"].update(damping=0.0, model="string")
    if "tensioner" in data:  # its arm undamped too
        data["tensioner"]["damping"] = 0.0
    data.setdefault("numerics", {})["elements"] = elements
    return type(scene).from_dict(data)


__all__ = ["LIGHT", "RotationalModel", "adhesion_limit", "rotational_model",
           "stiffness_matrix"]
