"""The explicit scheme's stable step: a von Neumann analysis of one step.

On a uniform grid of elements h, the mode e^{i kh j} of both fields (u, theta), the
velocities after the last kick and the last kick's bottom-fibre increment is advanced by
one step of :mod:`beltsim.solvers.explicit` (the trapezoidal velocity terms with the
drift, the kick, friction at a slope k with its velocity estimate and the transport of
the slip velocity). :func:`explicit_stable_dt` is the largest step whose amplification
is at most 1 for every kh and every friction slope of FRICTION_Z on the smallest
element. A loop's belt speed varies: :func:`loop_stable_dt` takes the smallest of the
limits at the belt speeds it can reach.
"""

from __future__ import annotations

import math
from functools import lru_cache
from types import SimpleNamespace

import numpy as np

from ..physics.discrete import contact_stencil
from .explicit_friction import A_EST, ALPHA, C_EST

# friction slopes of the von Neumann analysis, as dt k (1/rho + (h/2)^2 / I): the
# relaxation of the bottom-fibre velocity per step, from none (sliding) to stick
FRICTION_Z = np.concatenate([[0.0], np.logspace(-3.0, 9.0, 17)])
# amplification accepted as 1: eigenvalues on the unit circle carry round-off
TOL = 1e-9


def _gyro_symbol(c, h, kh):
    """G over the lumped mass on a uniform grid (1/s), for the mode e^{i kh j}."""
    return 2.0 * c * (1.0 - np.exp(-1j * kh)) / h


def _transport_symbol(c, h, kh):
    """c d/dx of the slip velocity on a uniform grid (1/s), for the mode e^{i kh j}: the
    model's stencil (physics.discrete.contact_stencil) read at an inner contact node of a
    uniform grid: (3 - 4 e^{-i kh} + e^{-2 i kh}) / (2 h)."""
    _, _, sw = contact_stencil(h * np.arange(8.0), 2, 6)
    return c * sum(sw[4, o] * np.exp(1j * kh * (o - 2)) for o in range(3))


def _amplification_matrices(params, h, dt, damping, kh, z):
    """Amplification matrices (..., 5, 5) of one step on a uniform grid of elements h.

    The state (u, theta, v_a, w_a, delta_b of the last kick) of the mode e^{i kh j},
    every node in contact with a friction law of slope k, z = dt k (1/rho + (h/2)^2 / I);
    kh and z broadcast against each other.
    """
    P = params
    rho, rot, c, hh = P.rho, P.I, P.c, 0.5 * P.h
    kh, z = np.broadcast_arrays(np.asarray(kh, float), np.asarray(z, float))
    trap = (2.0 / dt) / (2.0 / dt + damping + _gyro_symbol(c, h, kh))  # vm = trap v_a
    lap = -(2.0 - 2.0 * np.cos(kh)) / h**2
    up = dt * _transport_symbol(c, h, kh)  # c dt D (the slip velocity's transport)
    kb = 1.0 / rho + hh * hh / rot
    a = A_EST + ALPHA * up
    cols = []
    for col in range(5):
        u, th, va, wa, dp = (1.0 if i == col else 0.0 for i in range(5))
        vm, wm = trap * va, trap * wa
        vb, wb = 2.0 * vm - va, 2.0 * wm - wa
        u1, t1 = u + dt * vm, th + dt * wm
        eu = dt * (P.B / rho) * lap * u1
        et = dt * ((P.A / rot) * lap - P.b2 / rot) * t1
        eb = eu + hh * et
        vrel = ((vb + hh * wb) - C_EST * dp + (up / dt) * (u1 + hh * t1) + a * eb) / (1.0 + a * z)
        du = eu - z / (rho * kb) * vrel
        dw = et - z * hh / (rot * kb) * vrel
        cols.append(np.stack([u1, t1, vb + du, wb + dw, du + hh * dw], axis=-1))
    return np.stack(cols, axis=-1)


def _wave_amplification(params, h, dt, damping):
    """Largest amplification without friction, in closed form (each field on its own).

    Per field, in (u, dt v_a): [[1, tau], [q, 2 tau - 1 + q tau]] with q = -dt^2 omega^2,
    tau = 1 / (1 + s) and s = (d + G) dt / 2; its eigenvalues
    tau ((1 + q/2) +- sqrt(s^2 + q + q^2/4)) carry no cancellation at small dt.
    """
    P = params
    kh = np.linspace(np.pi / 4096, np.pi, 4096)
    s = 0.5 * dt * (damping + _gyro_symbol(P.c, h, kh))
    tau = 1.0 / (1.0 + s)
    worst = 0.0
    for stiff, inertia, spring in ((P.B, P.rho, 0.0), (P.A, P.I, P.b2)):
        q = -dt * dt * ((stiff / inertia) * (2.0 - 2.0 * np.cos(kh)) / h**2 + spring / inertia)
        root = np.sqrt(s * s + q + 0.25 * q * q + 0j)
        lam = np.maximum(np.abs(1.0 + 0.5 * q + root), np.abs(1.0 + 0.5 * q - root))
        worst = max(worst, float((np.abs(tau) * lam).max()))
    return worst


def _coupled_amplification(params, h, dt, damping):
    """Largest amplification with friction: all slopes of FRICTION_Z, both fields coupled."""
    kh = np.linspace(np.pi / 96, np.pi, 96)
    G = _amplification_matrices(params, h, dt, damping, kh[None, :], FRICTION_Z[:, None])
    return float(np.abs(np.linalg.eigvals(G)).max())


def explicit_amplification(params, h, dt, damping):
    """Largest von Neumann amplification of the explicit scheme on elements of size h.

    Both fields with their gyroscopic, damping, stiffness and shear terms, and friction
    at every slope of FRICTION_Z with its velocity estimate and the transport of the
    slip velocity (the stick limit included).
    """
    return max(_wave_amplification(params, h, dt, damping),
               _coupled_amplification(params, h, dt, damping))


@lru_cache(maxsize=256)
def _stable_dt(B, A, b2, rho, rot, c, height, h_min, damping):
    P = SimpleNamespace(B=B, A=A, b2=b2, rho=rho, I=rot, c=c, h=height)
    # the stiffness terms' limit, in closed form, by bisection
    w2 = max(4.0 * B / (rho * h_min**2), 4.0 * A / (rot * h_min**2) + b2 / rot)
    lo, hi = 0.0, 4.0 / math.sqrt(w2)  # twice the leapfrog's 2 / omega_max
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if _wave_amplification(P, h_min, mid, damping) <= 1.0 + TOL:
            lo = mid
        else:
            hi = mid
    wave = lo
    # friction can lower it (modes it couples weakly near the waves' limit): the first
    # stable fraction of it, refined between that and the last unstable one
    unstable = wave
    for frac in (1.0, 0.999, 0.99, 0.97, 0.9, 0.8, 0.65, 0.5, 0.35, 0.2, 0.1, 0.05):
        stable = frac * wave
        if _coupled_amplification(P, h_min, stable, damping) <= 1.0 + TOL:
            break
        unstable = stable
    else:
        return 0.0
    for _ in range(4 if unstable > stable else 0):
        mid = 0.5 * (stable + unstable)
        if _coupled_amplification(P, h_min, mid, damping) <= 1.0 + TOL:
            stable = mid
        else:
            unstable = mid
    return stable


def explicit_stable_dt(params, h_min, damping):
    """The largest step with amplification <= 1 on the smallest element; 0 when none is."""
    P = params
    return _stable_dt(float(P.B), float(P.A), float(P.b2), float(P.rho), float(P.I),
                      float(P.c), float(P.h), float(h_min), float(damping))


#: belt speeds at which a loop's limit is evaluated, as fractions of the largest
LOOP_SPEEDS = (0.0, 0.5, 1.0)


def loop_stable_dt(params, h_min, damping, speed):
    """A loop's stable step: the smallest of :func:`explicit_stable_dt` at the belt
    speeds c in LOOP_SPEEDS times ``speed`` (the driver's largest rim speed, which c stays
    below), with the stiffnesses b1 - rho c^2, a - I c^2 of each and the lever's height.

    params: a drive's DriveParams. The pulleys' speeds (implicit with their arcs), the
    belt speed's change (a weak, lagged coupling) and the bound's dependence on the
    pressure (relative size mu h / R of the elastic force) are not in the analysis.
    """
    P = params
    limits = []
    for f in LOOP_SPEEDS:
        c = f * speed
        at = SimpleNamespace(B=P.b1 - P.rho * c * c, A=P.a - P.I * c * c, b2=P.b2, rho=P.rho,
                             I=P.I, c=c, h=2.0 * P.lever)
        limits.append(explicit_stable_dt(at, h_min, damping))
    return min(limits)
