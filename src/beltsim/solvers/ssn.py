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
from .border import Border, finish, gather, schur


class Saddle(NamedTuple):
    """The 3x3 block-banded system and its block LU (n rows), with a loop's border."""

    L2: np.ndarray  # (n, 3, 3) bands
    Lb: np.ndarray
    Db: np.ndarray
    Ub: np.ndarray
    C: np.ndarray  # inverse pivots
    W: np.ndarray  # multipliers of the first and second lower band
    W2: np.ndarray
    U: np.ndarray  # the upper band factorised (saddle_system writes Ub anew)
    R: np.ndarray  # right-hand side (n, 3)
    dx: np.ndarray  # solution (n, 3)
    active: np.ndarray  # (nodes) 1 where the node sticks, at the last assembly
    Gc: np.ndarray  # a loop's global columns (n, 3, ng), rows (ng, n, 3), corner (ng, ng)
    Gr: np.ndarray
    Gd: np.ndarray
    Rg: np.ndarray  # the global rows' right-hand side (ng) and solution (ng)
    dg: np.ndarray
    border: Border | None  # None on an open layout

    @classmethod
    def allocate(cls, n_rows: int, n_globals: int = 0, closed: bool = False) -> Saddle:
        """The arrays for ``n_rows`` rows (N - 1 open, N closed) and a loop's globals."""
        n, ng = max(n_rows, 0), n_globals
        z = np.zeros
        return cls(*(z((n, 3, 3)) for _ in range(8)), z((n, 3)), z((n, 3)),
                   z(n + 2 - 2 * closed),
                   z((n, 3, ng)), z((ng, n, 3)), z((ng, ng)), z(ng), z(ng),
                   Border.allocate(n, 3, ng) if closed else None)


@njit(cache=True)
def saddle_system(lam, c, inv_dt, fs, mesh, p, w, s):
    """The 3x3 blocks and right-hand side -F of the semi-smooth Newton step.

    w holds the model's 2x2 blocks and residual as :func:`beltsim.physics.model.assemble`
    leaves them for an exact law (friction force wf S lam in the residual, no friction
    slope; w.rl = v_rel / v_aug, w.sg = 1 where the node sticks; w.bs the bounds S);
    c is the belt speed of that assembly.
    On a loop the global rows and columns come along: a stuck node's v_rel depends on c
    and on its free pulley's speed, and that pulley's row on the node's ratio. Returns
    the number of friction nodes whose stick/slip state differs from the previous call's.
    """
    n = w.R.shape[0]
    off = mesh.off
    hh, vaug = p.half_height, p.regularisation
    ng = s.Rg.shape[0]
    changed = 0
    if off == 0:
        for k in range(ng):
            s.Rg[k] = -w.Rg[k]
            for m in range(ng):
                s.Gd[k, m] = w.Gd[k, m]
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
        if off == 0:
            for k in range(ng):
                for a in range(2):
                    s.Gc[i, a, k] = w.Gc[i, a, k]
                    s.Gr[k, i, a] = w.Gr[k, i, a]
                s.Gc[i, 2, k] = 0.0
                s.Gr[k, i, 2] = 0.0
        j = i + off
        seg = mesh.seg[j]
        if seg < 0:
            s.Db[i, 2, 2] = 1.0
            s.R[i, 2] = -lam[j]
            continue
        k = mesh.wf[j] * (fs if off == 1 else w.bs[j])
        s.Db[i, 0, 2] = k
        hf = hh * mesh.face[j]  # the lever of the face in contact
        s.Db[i, 1, 2] = hf * k
        K = mesh.seg_speed[seg] if off == 0 else -1
        if K >= 1:
            s.Gr[K, i, 2] = -mesh.seg_radius[seg] * k
        stick = w.sg[j] > 0.5
        if stick != (s.active[j] > 0.5):
            changed += 1
        s.active[j] = 1.0 if stick else 0.0
        if not stick:
            s.Db[i, 2, 2] = 1.0
            s.R[i, 2] = -(lam[j] - math.copysign(1.0, lam[j] + w.rl[j]))
            continue
        s.R[i, 2] = -w.rl[j]
        if off == 0:
            s.Gc[i, 2, 0] = w.vc[j] / vaug
            if K >= 1:
                s.Gc[i, 2, K] = -mesh.seg_radius[seg] / vaug
        for o in range(3):
            if off == 1 and j - 2 + o < 1:
                continue
            dd = slip_velocity_slope(mesh.sw, j, o, c, inv_dt) / vaug
            if dd == 0.0:
                continue
            blk = stencil_band(o, s.L2, s.Lb, s.Db)
            blk[i, 2, 0] += dd
            blk[i, 2, 1] += dd * hf
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
def saddle_factor(s, n):
    """Block LU of the first n rows of the 3x3 block-banded system (as
    newton.block_factor for 2x2 blocks): W2_i = L2_i S_{i-2}^{-1}, L'_i = L_i - W2_i
    U_{i-2}, W_i = L'_i S_{i-1}^{-1}, S_i = D_i - W_i U_{i-1}; s.C receives S_i^{-1}.
    Returns False on a singular pivot. s.U receives a copy of the upper blocks, which
    the substitutions read, so that the factors outlive the next :func:`saddle_system`."""
    Li = np.empty((1, 3, 3))
    S = np.empty((3, 3))
    for i in range(n):
        for r in range(3):
            for q in range(3):
                S[r, q] = s.Db[i, r, q]
                s.U[i, r, q] = s.Ub[i, r, q]
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
def saddle_substitute(s, r, y):
    """y (n, 3) from r (n, 3) with the factors of :func:`saddle_factor` of n rows."""
    n = r.shape[0]
    z = np.empty(3)
    for i in range(n):
        for a in range(3):
            acc = r[i, a]
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
                    acc -= s.U[i, a, b] * y[i + 1, b]
            z[a] = acc
        for a in range(3):
            y[i, a] = s.C[i, a, 0] * z[0] + s.C[i, a, 1] * z[1] + s.C[i, a, 2] * z[2]


@njit(cache=True, no_cpython_wrapper=True)
def saddle_substitute_many(s, r, y):
    """:func:`saddle_substitute` for each right-hand side r[q] (m, n, 3) into y[q], the
    same arithmetic in the same order, the columns interleaved (each row's factors read
    once for all of them; the columns' recurrences overlap)."""
    m, n = r.shape[0], r.shape[1]
    z = np.empty(3)
    for i in range(n):
        for q in range(m):
            for a in range(3):
                acc = r[q, i, a]
                if i > 0:
                    for b in range(3):
                        acc -= s.W[i, a, b] * y[q, i - 1, b]
                if i > 1:
                    for b in range(3):
                        acc -= s.W2[i, a, b] * y[q, i - 2, b]
                y[q, i, a] = acc
    for i in range(n - 1, -1, -1):
        for q in range(m):
            for a in range(3):
                acc = y[q, i, a]
                if i < n - 1:
                    for b in range(3):
                        acc -= s.U[i, a, b] * y[q, i + 1, b]
                z[a] = acc
            for a in range(3):
                y[q, i, a] = s.C[i, a, 0] * z[0] + s.C[i, a, 1] * z[1] + s.C[i, a, 2] * z[2]


@njit(cache=True)
def saddle_solve(s, mesh):
    """Factorise the system (bordered on a loop) and solve it: s.dx (and s.dg) from s.R
    (and s.Rg). Returns False on a singular pivot."""
    if not saddle_factorise(s, mesh):
        return False
    saddle_resolve(s, mesh)
    return True


@njit(cache=True)
def saddle_factorise(s, mesh):
    """Factorise the system (bordered on a loop) for :func:`saddle_resolve`. Returns False
    on a singular pivot."""
    n = s.Db.shape[0]
    if mesh.off == 1:
        return saddle_factor(s, n)
    return saddle_factor_bordered(s, s.border)


@njit(cache=True)
def saddle_resolve(s, mesh):
    """s.dx (and s.dg) from s.R (and s.Rg) with the factors of :func:`saddle_factorise`,
    which may be those of an earlier system (a chord step)."""
    if mesh.off == 1:
        saddle_substitute(s, s.R, s.dx)
        return
    ni = s.Db.shape[0] - 2
    saddle_substitute(s, s.R[:ni], s.dx[:ni])
    finish(s.border, s.R, s.Rg, s.dx, s.dg)


@njit(cache=True, no_cpython_wrapper=True)
def saddle_factor_bordered(s, bd):
    """A loop's part of :func:`saddle_factorise`: the band without the border, then the
    border's columns and Schur complement.

    An open layout's system has no border (``bd`` None) and never comes here; its type
    prunes the body, so an open layout compiles none of the border's kernels.
    """
    if bd is None:
        return False
    ni = s.Db.shape[0] - 2
    if not saddle_factor(s, ni):
        return False
    gather(s.Lb, s.L2, s.Db, s.Ub, s.Gc, s.Gr, s.Gd, bd)
    saddle_substitute_many(s, bd.Bm, bd.X)
    return schur(bd)


@njit(cache=True, no_cpython_wrapper=True)
def project(lam, mesh, code):
    """Ratios of sliding nodes back onto [-1, 1] (Coulomb): the update may overshoot."""
    if code != EXACT:
        return
    for j in mesh.cn:
        lam[j] = min(1.0, max(-1.0, lam[j]))
