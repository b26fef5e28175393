"""The exact spectrum of the continuous model linearised about its exact steady state.

A perturbation z(x) e^{lambda t}, phi(x) e^{lambda t} of u and theta solves, with the
friction's linearisation held fixed at the exact steady state's stick and slip zones,

* where the belt is free or slides (the friction stays at its bound f*)::

      rho (lambda^2 + d lambda) z + 2 rho c lambda z' - B z'' = 0
      I (lambda^2 + d lambda) phi + 2 I c lambda phi' - A phi'' + b2 phi = 0

* where it sticks, the same equations with a friction force mu on the right of the first
  and (h/2) mu on the right of the second, and the constraint that the bottom fibre
  moves with the surface, lambda z_b + c z_b' = 0 with z_b = z + (h/2) phi: z_b is carried
  with the flow, z_b = Z exp(-lambda (x - a) / c) from the zone's start a, and phi
  solves the equation left when mu is eliminated,

      (I + rho hh^2) ((lambda^2 + d lambda) phi + 2 c lambda phi') - (A + B hh^2) phi''
          + b2 phi = hh (rho (lambda^2 + d lambda) z_b + 2 rho c lambda z_b' - B z_b'').

This is the limit of a regularised law's linearisation as its stick slope f*/v_reg
grows, which the discrete model reaches once v_reg is far below the element size times
the strain rate (always, for the scenes' regularisations). On each zone the solution
is a sum of exponentials (and the carried z_b), so the eigenvalues are the roots of
the determinant of a small matrix of boundary and interface conditions
(:func:`characteristic_matrix`): z = phi = 0 at both ends; z and phi continuous at
every zone boundary; z' and phi' continuous too, except where a stick zone ends, where
the concentrated friction force P of the zone's outflow (the material leaves the
surface) sets B [z'] = -P and A [phi'] = -(h/2) P, one condition A [phi'] = (h/2) B [z'].
There is no discretisation: the roots are exact to the root finder's tolerance.

The carried z_b makes the determinant a function of exp(-lambda tau), tau the stick
zone's transit time, as in a neutral delay equation: the roots form chains that run
to arbitrarily high frequencies with real parts that do not decay. Which chain is
least stable, and whether it grows, is what the discrete models must reproduce.

See docs/theory/stability.md.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: Starting points of the root search per hertz of the band searched, and their real
#: parts (1/s): roots are spaced by the slowest waves' round trips, about 5 to 15 Hz in
#: the paper's scenes.
STARTS_PER_HZ = 0.25
START_RATES = (-40.0, 0.0, 20.0)
#: Newton stops when its step is below this, relative to |lambda|.
ROOT_TOL = 1e-12
#: Roots closer to 0 than this (1/s) are the neutral mode lambda = 0 of a stick zone: at
#: rest its carried displacement may take any constant (the steady problem fixes it by
#: the material balance of the control domain, which the frozen linearisation drops).
NEUTRAL = 1e-3


@dataclass(frozen=True)
class Zone:
    """[a, b] of the steady state: "free" (or sliding: no friction slope) or "stick"."""

    a: float
    b: float
    kind: str


def zones_of(solution) -> list[Zone]:
    """The zones of an exact steady solution (:mod:`beltsim.problem.analytic`): its stick
    segments stick, all others are free (slip zones keep f* whatever the perturbation)."""
    out = []
    for seg in solution.segments:
        kind = "stick" if seg.kind == "stick" else "free"
        if out and out[-1].kind == kind == "free":
            out[-1] = Zone(out[-1].a, seg.q, kind)
        else:
            out.append(Zone(seg.p, seg.q, kind))
    return out


def _pair(a2, a1, a0):
    """The roots of a2 s^2 + a1 s + a0, by increasing real part."""
    disc = np.sqrt(a1 * a1 - 4.0 * a2 * a0 + 0j)
    r = ((-a1 - disc) / (2.0 * a2), (-a1 + disc) / (2.0 * a2))
    return r if r[0].real <= r[1].real else r[::-1]


class Characteristic:
    """The characteristic matrix of the linearised continuous model on given zones.

    Parameters
    ----------
    params : beltsim.problem.scene.Params
        The scene's physical parameters (rho, I, c, h, B, A, b2, L).
    zones : list of Zone
        The zones covering [0, L] in order.
    damping : float
        d (1/s) of d rho u_t and d I theta_t.
    """

    def __init__(self, params, zones, damping):
        self.P, self.zones, self.d = params, list(zones), float(damping)
        self.cols, n = [], 0
        for z in self.zones:
            m = 3 if z.kind == "stick" else 4
            self.cols.append(slice(n, n + m))
            n += m
        self.n = n

    def wavenumbers(self, lam):
        """The spatial exponents s (e^{s x}) of u and theta in free zones and of phi in
        stick zones, each pair by increasing real part."""
        P, lt = self.P, lam * lam + self.d * lam
        hh = 0.5 * P.h
        Ie, Ae = P.I + P.rho * hh * hh, P.A + P.B * hh * hh
        return (_pair(P.B, -2.0 * P.rho * P.c * lam, -P.rho * lt),
                _pair(P.A, -2.0 * P.I * P.c * lam, -(P.I * lt + P.b2)),
                _pair(Ae, -2.0 * Ie * P.c * lam, -(Ie * lt + P.b2)))

    def _basis(self, lam, zi, x, ks):
        """(z, phi, z', phi') of each basis function of zone zi at x: (4, columns).

        Exponentials are scaled to be at most 1 on their zone (e^{s (x - a)} when Re s <= 0,
        e^{s (x - b)} otherwise), so the matrix holds no overflow."""
        P, zone = self.P, self.zones[zi]
        hh = 0.5 * P.h

        def ex(s):
            e = np.exp(s * (x - (zone.a if s.real <= 0.0 else zone.b)))
            return e, s * e

        free_u, free_t, stick_t = ks
        if zone.kind != "stick":
            out = np.zeros((4, 4), complex)
            for m, s in enumerate(free_u):
                out[0, m], out[2, m] = ex(s)
            for m, s in enumerate(free_t):
                out[1, 2 + m], out[3, 2 + m] = ex(s)
            return out
        out = np.zeros((4, 3), complex)
        lt = lam * lam + self.d * lam
        sig = -lam / P.c  # z_b carried with the flow
        Ie, Ae = P.I + P.rho * hh * hh, P.A + P.B * hh * hh
        q = (hh * (P.rho * lt + 2.0 * P.rho * P.c * lam * sig - P.B * sig * sig)
             / (Ie * lt + 2.0 * Ie * P.c * lam * sig - Ae * sig * sig + P.b2))
        zb = np.exp(sig * (x - zone.a))
        out[:, 0] = (zb * (1.0 - hh * q), q * zb, sig * zb * (1.0 - hh * q), sig * q * zb)
        for m, s in enumerate(stick_t):
            e, de = ex(s)
            out[:, 1 + m] = (-hh * e, e, -hh * de, de)
        return out

    def matrix(self, lam, ks=None):
        """The characteristic matrix at lambda (n x n); singular at the eigenvalues."""
        P = self.P
        ks = self.wavenumbers(lam) if ks is None else ks
        Mt = np.zeros((self.n, self.n), complex)
        scale = 1.0 / (abs(lam) / P.c + 10.0)  # derivative rows to the size of the others
        last = len(self.zones) - 1
        Mt[0:2, self.cols[0]] = self._basis(lam, 0, 0.0, ks)[:2]
        Mt[2:4, self.cols[last]] = self._basis(lam, last, P.L, ks)[:2]
        row = 4
        for zi in range(last):
            x = self.zones[zi].b
            left, right = self._basis(lam, zi, x, ks), self._basis(lam, zi + 1, x, ks)
            cl, cr = self.cols[zi], self.cols[zi + 1]
            Mt[row:row + 2, cl], Mt[row:row + 2, cr] = left[:2], -right[:2]
            row += 2
            if self.zones[zi].kind == "stick":
                # the outflow's concentrated force: A [phi'] = (h/2) B [z']
                w = scale / P.B
                Mt[row, cl] = w * (P.A * left[3] - 0.5 * P.h * P.B * left[2])
                Mt[row, cr] = -w * (P.A * right[3] - 0.5 * P.h * P.B * right[2])
                row += 1
            else:
                Mt[row:row + 2, cl], Mt[row:row + 2, cr] = scale * left[2:], -scale * right[2:]
                row += 2
        return Mt

    def determinant(self, lam, ks=None):
        """det of :meth:`matrix`."""
        return np.linalg.det(self.matrix(lam, ks))

    def _near(self, lam, ref):
        """The wavenumbers at lam, each pair in the order of the pair ref (continuity)."""
        out = []
        for a, b in zip(self.wavenumbers(lam), ref):
            same = abs(a[0] - b[0]) + abs(a[1] - b[1])
            swapped = abs(a[0] - b[1]) + abs(a[1] - b[0])
            out.append(a if same <= swapped else a[::-1])
        return out

    def root(self, lam, tol=ROOT_TOL, max_iterations=60):
        """A root of the determinant by Newton's method from lam (None if it fails).

        The derivative is a central difference in the complex plane (the determinant is
        analytic); the wavenumbers there follow the start's labels, so a root pair that
        swaps its order does not flip the determinant's sign."""
        for _ in range(max_iterations):
            ks = self.wavenumbers(lam)
            eps = 1e-7 * (abs(lam) + 1.0)
            f0 = self.determinant(lam, ks)
            fp = (self.determinant(lam + eps, self._near(lam + eps, ks))
                  - self.determinant(lam - eps, self._near(lam - eps, ks))) / (2.0 * eps)
            if not (np.isfinite(f0) and np.isfinite(fp)) or fp == 0.0:
                return None
            step = f0 / fp
            cap = 0.2 * (abs(lam) + 100.0)  # Newton from far away: a bounded step
            if abs(step) > cap:
                step *= cap / abs(step)
            lam = lam - step
            if abs(step) <= tol * (abs(lam) + 1.0):
                return complex(lam)
        return None

    def roots(self, f_max, f_min=0.0, starts_per_hz=STARTS_PER_HZ, rates=START_RATES,
              seeds=()):
        """The roots with frequencies in [f_min, f_max] Hz (upper half plane, the neutral
        root left out), by Newton from a grid of starts in the band and from ``seeds``
        (approximate eigenvalues, e.g. a discrete model's); sorted by decreasing real
        part."""
        n = max(2, int(math.ceil((f_max - f_min) * starts_per_hz)))
        starts = [complex(r, 2.0 * math.pi * max(f, 1e-3))
                  for f in np.linspace(f_min, f_max, n + 1) for r in rates]
        found: list[complex] = []
        for start in [*starts, *(complex(z) for z in seeds)]:
            lam = self.root(start)
            if (lam is None or lam.imag < 0.0 or abs(lam) < NEUTRAL
                    or not f_min <= lam.imag / (2 * math.pi) <= f_max):
                continue
            if all(abs(lam - o) > 1e-7 * abs(lam) for o in found):
                found.append(lam)
        return np.array(sorted(found, key=lambda z: -z.real))


def characteristic(scene) -> Characteristic:
    """The characteristic matrix of a straight-belt scene about its exact steady state,
    with the scene's damping. Raises ValueError for a quasistatic scene."""
    from ..problem import analytic

    P = scene.params
    if not P.inertia:
        raise ValueError("a quasistatic scene has no dynamics to linearise")
    return Characteristic(P, zones_of(analytic.solve(scene)), P.damping)
