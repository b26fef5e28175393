"""Friction laws: regularised and exact Coulomb, regularised and exact adhesion.

The traction on the belt is f = -f_s lam. The regularised laws give the friction
ratio as lam = g(v_rel / v_reg), with g odd, increasing and (for Coulomb) saturating
at 1; perfect adhesion is the "linear" law g(s) = s with a stiff slope f_s / v_reg.
As v_reg -> 0 (Coulomb) or the slope -> infinity (adhesion) they tend to the exact
laws, which are set-valued and carry no regularisation:

* EXACT (Coulomb): abs(lam) <= 1 where v_rel = 0, lam = sign(v_rel) where it slides;
* ADHESION: v_rel = 0, lam unbounded (the contact's reaction).

Both are written as lam = proj(lam + v_rel / v_aug) (Alart and Curnier's
complementarity function; proj onto [-1, 1] for Coulomb, the identity for adhesion),
which holds for any v_aug > 0 exactly when the law does: v_aug is a numerical scale
of the iteration (how fast stick converges), not a regularisation, and the solution
does not depend on it.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

LINEAR, TANH, SQRT, RAMP, EXACT, ADHESION = 0, 1, 2, 3, 4, 5
LAW_CODES = {"linear": LINEAR, "tanh": TANH, "sqrt": SQRT, "ramp": RAMP, "exact": EXACT,
             "adhesion": ADHESION}


# v_aug over the default regularisation velocity (settings): v_aug = |v - c|, the scale
# of the slip velocities, so the stick/slip test lam + v_rel / v_aug follows the ratio
# near the slip front; a much smaller v_aug lets a node whose slip velocity has the
# wrong sign in one iterate jump to the opposite slip, and the iteration cycles
AUGMENTATION = 1e4


def is_exact(code) -> bool:
    """Whether the law is set-valued (solved by augmentation, without regularisation)."""
    return code >= EXACT


@njit(cache=True)
def law(code, s):
    """g(s) and g'(s) of the regularisation ``code`` (the exact laws have none)."""
    if code == TANH:
        # through exp, which is cheaper than libm's tanh; exact to round-off
        e = math.exp(-2.0 * abs(s))
        g = math.copysign((1.0 - e) / (1.0 + e), s)
        return g, 1.0 - g * g
    if code == SQRT:
        r = 1.0 / math.sqrt(1.0 + s * s)
        return s * r, r * r * r
    if code == RAMP:
        if s > 1.0:
            return 1.0, 0.0
        if s < -1.0:
            return -1.0, 0.0
        return s, 1.0
    return s, 1.0


@njit(cache=True)
def law_inverse(code, lam):
    """g^{-1}(lam) and its derivative, for the laws with a smooth inverse (abs(lam) < 1).

    The primal-dual Newton iteration carries lam = g(v_rel / v_reg) as an unknown:
    its inverse is well conditioned where the primal law is nearly flat (sliding)
    and the other way round in stick.
    """
    if code == LINEAR:
        return lam, 1.0
    q = 1.0 - lam * lam  # > 0: the iteration keeps |lam| < 1
    if code == TANH:
        return math.atanh(lam), 1.0 / q
    return lam / math.sqrt(q), 1.0 / (q * math.sqrt(q))  # SQRT


def law_inverse_numpy(code, lam):
    """Vectorised twin of :func:`law_inverse` (the numpy port of the BDF2 scheme)."""
    lam = np.asarray(lam, dtype=float)
    if code == LINEAR:
        return lam, np.ones_like(lam)
    q = 1.0 - lam * lam
    if code == TANH:
        return np.arctanh(lam), 1.0 / q
    return lam / np.sqrt(q), 1.0 / (q * np.sqrt(q))  # SQRT


def has_dual(code) -> bool:
    """Whether the primal-dual iteration applies (the ramp's inverse is set-valued)."""
    return code != RAMP


def law_numpy(code, s):
    """Vectorised twin of :func:`law` (tests, post-processing)."""
    s = np.asarray(s, dtype=float)
    if code == TANH:
        g = np.tanh(s)
        return g, 1.0 - g * g
    if code == SQRT:
        r = 1.0 / np.sqrt(1.0 + s * s)
        return s * r, r**3
    if code == RAMP:
        return np.clip(s, -1.0, 1.0), (np.abs(s) <= 1.0).astype(float)
    return s, np.ones_like(s)


def saturation(code) -> float:
    """Level of abs(g) above which an element counts as sliding (adhesion never slides)."""
    if code == ADHESION:
        return math.inf
    return 0.99 if code in (TANH, SQRT) else 1.0 - 1e-12
