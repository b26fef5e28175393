"""Exact friction: the semi-smooth Newton system with the friction ratios as unknowns.

With the set-valued laws (physics.friction.EXACT, ADHESION) the friction ratio lam_j of
each friction node is an unknown beside (u_j, theta_j), with Alart and Curnier's
complementarity equation lam = proj(lam + v_rel / v_aug). Its generalised Jacobian
row at a node that sticks (lam + v_rel / v_aug inside [-1, 1]; always for adhesion) is
that of v_rel / v_aug (the stick constraint: the ratio itself has no entry), at a
node that slides that of lam - sign. The stick rows cannot be condensed into the
(u, theta) rows node by node as the regularised laws' are, so the system is solved
whole: per interior node the unknowns (u_j, theta_j, lam_j) (lam_j = 0, identity row,
off the friction nodes), 3x3 blocks with the same band as the model's 2x2 Jacobian
(two lower bands from the friction stencil, one upper), factorised by block LU with
each 3x3 pivot inverted whole (the stick rows have a zero diagonal entry; the pivot
block is regular where c sw_jj + inv_dt > 0). See docs/theory/exact-friction.md.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from ..physics.friction import EXACT
from ..physics.model import slip_velocity_slope, stencil_band


class Saddle(NamedTuple):
    """The 3x3 block-banded system and its block LU (n interior nodes)."""

    L2: np.ndarray  # (n, 3, 3) bands
    Lb: np.ndarray
    Db: np.ndarray
    Ub: np.ndarray
    C: np.ndarray  # inverse pivots
    W: np.ndarray  # multipliers of the first and second lower band
    W2: np.ndarray
    R: np.ndarray  # right-hand side (n, 3)
    dx: np.ndarray  # solution (n, 3)
    active: np.ndarray  # (N + 1) 1 where the node sticks, at the last assembly

    @classmethod
    def allocate(cls, n_elements: int) -> Saddle:
        """The arrays for a grid of ``n_elements``."""
        n = max(n_elements - 1, 0)
        z = np.zeros
        return cls(z((n, 3, 3)), z((n, 3, 3)), z((n, 3, 3)), z((n, 3, 3)), z((n, 3, 3)),
                   z((n, 3, 3)), z((n, 3, 3)), z((n, 3)), z((n, 3)), z(n_elements + 1))

    @classmethod
    def empty(cls) -> Saddle:
        """Zero-size arrays, for a law that needs none (a regularised one)."""
        return cls.allocate(0)


@njit(cache=True)
def saddle_system(lam, inv_dt, fs, mesh, p, w, s):
    """The 3x3 blocks and right-hand side -F of the semi-smooth Newton step.

    w holds the model's 2x2 blocks and residual as :func:`beltsim.physics.model.assemble`
    leaves them for an exact law (friction force wf f_s lam in the residual, no friction
    slope; w.rl = v_rel / v_aug, w.sg = 1 where the node sticks). Returns the number of
    friction nodes whose stick/slip state differs from the previous call's.
    """
    n = w.R.shape[0]
    c, hh, vaug = p.speed, p.half_height, p.regularisation
    changed = 0
    for i in range(n):
        for a in range(3):
            s.R[i, a] = 0.0
            for b in range(3):
                s.L2[i, a, b] = 0.0
                s.Lb[i, a, b] = 0.0
                s.Db[i, a, b] = 0.0
                s.Ub[i, a, b] = 0.0
        for a in range(2):
            s.R[i, a] = -w.R[i, a]
            for b in range(2):
                s.L2[i, a, b] = w.L2[i, a, b]
                s.Lb[i, a, b] = w.Lb[i, a, b]
                s.Db[i, a, b] = w.Db[i, a, b]
                s.Ub[i, a, b] = w.Ub[i, a, b]
        j = i + 1
        if j < mesh.c0 or j > mesh.j2:
            s.Db[i, 2, 2] = 1.0
            s.R[i, 2] = -lam[j]
            continue
        k = mesh.wf[j] * fs
        s.Db[i, 0, 2] = k
        s.Db[i, 1, 2] = hh * k
        stick = w.sg[j] > 0.5
        if stick != (s.active[j] > 0.5):
            changed += 1
        s.active[j] = 1.0 if stick else 0.0
        if not stick:
            s.Db[i, 2, 2] = 1.0
            s.R[i, 2] = -(lam[j] - math.copysign(1.0, lam[j] + w.rl[j]))
            continue
        s.R[i, 2] = -w.rl[j]
        for o in range(3):
            if j - 2 + o < 1:
                continue
            dd = slip_velocity_slope(mesh.sw, j, o, c, inv_dt) / vaug
            if dd == 0.0:
                continue
            blk = stencil_band(o, s.L2, s.Lb, s.Db)
            blk[i, 2, 0] += dd
            blk[i, 2, 1] += dd * hh
    return changed


@njit(cache=True, inline="always")
def _inv3(a, out, i):
    """out[i] = a^{-1} (3x3, cofactors); False when singular or not finite."""
    c00 = a[1, 1] * a[2, 2] - a[1, 2] * a[2, 1]
    c01 = a[1, 2] * a[2, 0] - a[1, 0] * a[2, 2]
    c02 = a[1, 0] * a[2, 1] - a[1, 1] * a[2, 0]
    det = a[0, 0] * c00 + a[0, 1] * c01 + a[0, 2] * c02
    if not (abs(det) > 0.0 and abs(det) < math.inf):
        return False
    g = 1.0 / det
    out[i, 0, 0] = c00 * g
    out[i, 1, 0] = c01 * g
    out[i, 2, 0] = c02 * g
    out[i, 0, 1] = (a[0, 2] * a[2, 1] - a[0, 1] * a[2, 2]) * g
    out[i, 1, 1] = (a[0, 0] * a[2, 2] - a[0, 2] * a[2, 0]) * g
    out[i, 2, 1] = (a[0, 1] * a[2, 0] - a[0, 0] * a[2, 1]) * g
    out[i, 0, 2] = (a[0, 1] * a[1, 2] - a[0, 2] * a[1, 1]) * g
    out[i, 1, 2] = (a[0, 2] * a[1, 0] - a[0, 0] * a[1, 2]) * g
    out[i, 2, 2] = (a[0, 0] * a[1, 1] - a[0, 1] * a[1, 0]) * g
    return True


@njit(cache=True, inline="always")
def _mul(a, ia, b, ib, out, io):
    """out[io] = a[ia] b[ib] (3x3 blocks, by index: views would cost a reference count)."""
    for r in range(3):
        a0, a1, a2 = a[ia, r, 0], a[ia, r, 1], a[ia, r, 2]
        for q in range(3):
            out[io, r, q] = a0 * b[ib, 0, q] + a1 * b[ib, 1, q] + a2 * b[ib, 2, q]


@njit(cache=True, inline="always")
def _mul_sub(a, ia, b, ib, acc):
    """acc -= a[ia] b[ib] (acc a 3x3 array)."""
    for r in range(3):
        a0, a1, a2 = a[ia, r, 0], a[ia, r, 1], a[ia, r, 2]
        for q in range(3):
            acc[r, q] -= a0 * b[ib, 0, q] + a1 * b[ib, 1, q] + a2 * b[ib, 2, q]


@njit(cache=True)
def saddle_factor(s):
    """Block LU of the 3x3 block-banded system (as newton.block_factor for 2x2 blocks):
    W2_i = L2_i S_{i-2}^{-1}, L'_i = L_i - W2_i U_{i-2}, W_i = L'_i S_{i-1}^{-1},
    S_i = D_i - W_i U_{i-1}; s.C receives S_i^{-1}. Returns False on a singular pivot."""
    n = s.Db.shape[0]
    Li = np.empty((1, 3, 3))
    S = np.empty((3, 3))
    for i in range(n):
        for r in range(3):
            for q in range(3):
                S[r, q] = s.Db[i, r, q]
        if i > 0:
            for r in range(3):
                for q in range(3):
                    Li[0, r, q] = s.Lb[i, r, q]
            if i > 1:
                _mul(s.L2, i, s.C, i - 2, s.W2, i)
                _mul_sub(s.W2, i, s.Ub, i - 2, Li[0])
            _mul(Li, 0, s.C, i - 1, s.W, i)
            _mul_sub(s.W, i, s.Ub, i - 1, S)
        if not _inv3(S, s.C, i):
            return False
    return True


@njit(cache=True)
def saddle_substitute(s):
    """s.dx from s.R with the factors of :func:`saddle_factor`."""
    n = s.R.shape[0]
    y = s.dx
    z = np.empty(3)
    for i in range(n):
        for a in range(3):
            acc = s.R[i, a]
            if i > 0:
                for b in range(3):
                    acc -= s.W[i, a, b] * y[i - 1, b]
            if i > 1:
                for b in range(3):
                    acc -= s.W2[i, a, b] * y[i - 2, b]
            y[i, a] = acc
    for i in range(n - 1, -1, -1):
        for a in range(3):
            acc = y[i, a]
            if i < n - 1:
                for b in range(3):
                    acc -= s.Ub[i, a, b] * y[i + 1, b]
            z[a] = acc
        for a in range(3):
            y[i, a] = s.C[i, a, 0] * z[0] + s.C[i, a, 1] * z[1] + s.C[i, a, 2] * z[2]


@njit(cache=True)
def project(lam, mesh, code):
    """Ratios of sliding nodes back onto [-1, 1] (Coulomb): the update may overshoot."""
    if code != EXACT:
        return
    for j in range(mesh.c0, mesh.j2 + 1):
        lam[j] = min(1.0, max(-1.0, lam[j]))
