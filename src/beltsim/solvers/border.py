"""The linear solve of a closed layout: the block band of an open one, bordered.

A loop's rows couple across its closure (rows 0 and 1 reach back to nodes N-1 and N-2,
row N-1 forward to node 0) and to its global unknowns (the belt speed c in every row,
a free pulley's speed in its arc's rows; the gauge and the pulleys' rows are dense).
The last two nodes and the globals form the border, of size nb = 2 b + ng (b the block
size: 2 for (u, theta), 3 with an exact law's friction ratio). The first N - 2 rows are
then an open layout's block band, factorised by the same block LU (newton.block_factor,
ssn.saddle_factor); the border by its Schur complement

    S = D - C A^{-1} B,

with the band's substitution applied to the nb border columns once per factorisation.
The cost stays linear in the grid: nb + 1 substitutions and an nb x nb inverse.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit


class Border(NamedTuple):
    """The border of a closed layout's Jacobian and its Schur complement.

    Border unknown q < 2 b is unknown q % b of node N - 2 + q // b; q >= 2 b is global
    q - 2 b. Columns and rows are stored as (nb, n_int, b) arrays over the band's rows.
    """

    Bm: np.ndarray  # the band rows' entries in the border columns (nb, n_int, b)
    Cm: np.ndarray  # the border rows' entries in the band columns (nb, n_int, b)
    Dm: np.ndarray  # the border's own block (nb, nb)
    X: np.ndarray  # A^{-1} Bm (nb, n_int, b)
    Sinv: np.ndarray  # the Schur complement's inverse (nb, nb)
    rb: np.ndarray  # the border's right-hand side (nb)
    # each global's band rows [lo, hi) whose entries are not zero: a free pulley
    # couples to its arc's rows only
    span: np.ndarray  # (ng, 2)

    @classmethod
    def allocate(cls, n_rows: int, b: int, n_globals: int) -> Border:
        """The arrays for a loop of ``n_rows`` nodes, blocks of ``b``, ``n_globals``."""
        nb, ni = 2 * b + n_globals, max(n_rows - 2, 0)
        return cls(np.zeros((nb, ni, b)), np.zeros((nb, ni, b)), np.zeros((nb, nb)),
                   np.zeros((nb, ni, b)), np.zeros((nb, nb)), np.zeros(nb),
                   np.zeros((n_globals, 2), np.int64))


@njit(cache=True, no_cpython_wrapper=True)
def gather(Lb, L2, Db, Ub, Gc, Gr, Gd, bd):
    """Fill bd's Bm, Cm, Dm from a loop's wrapped band (rows 0..n-1, each coupling to
    nodes i-2, i-1, i, i+1 modulo n) and its global blocks Gc (n, b, ng), Gr (ng, n, b),
    Gd (ng, ng), with the span of each global's rows that are not zero (bd.span)."""
    n, b = Db.shape[0], Db.shape[1]
    ni = n - 2
    ng = Gd.shape[0]
    # the border nodes' columns and rows reach the band's rows 0, 1, ni - 2 and ni - 1
    # only (below), and the globals' are copied whole: no other entry is ever set
    for i in (0, 1, ni - 2, ni - 1):
        if 0 <= i < ni:
            for q in range(2 * b):
                for a in range(b):
                    bd.Bm[q, i, a] = 0.0
                    bd.Cm[q, i, a] = 0.0
    for a in range(b):
        for q in range(b):
            # band rows into the border nodes: rows 0, 1 back across the closure, row
            # n - 3 forward to node n - 2
            bd.Bm[q, 0, a] += L2[0, a, q]  # node n - 2
            bd.Bm[b + q, 0, a] += Lb[0, a, q]  # node n - 1
            bd.Bm[b + q, 1, a] += L2[1, a, q]
            bd.Bm[q, ni - 1, a] += Ub[ni - 1, a, q]
            # border rows into the band: node n - 2 back to n - 3, n - 4; node n - 1
            # back to n - 3 and forward to node 0
            bd.Cm[a, ni - 1, q] += Lb[n - 2, a, q]
            bd.Cm[a, ni - 2, q] += L2[n - 2, a, q]
            bd.Cm[b + a, ni - 1, q] += L2[n - 1, a, q]
            bd.Cm[b + a, 0, q] += Ub[n - 1, a, q]
            bd.Dm[a, q] = Db[n - 2, a, q]
            bd.Dm[a, b + q] = Ub[n - 2, a, q]
            bd.Dm[b + a, q] = Lb[n - 1, a, q]
            bd.Dm[b + a, b + q] = Db[n - 1, a, q]
    for k in range(ng):
        lo, hi = ni, 0
        for i in range(ni):
            nonzero = False
            for a in range(b):
                bd.Bm[2 * b + k, i, a] = Gc[i, a, k]
                bd.Cm[2 * b + k, i, a] = Gr[k, i, a]
                nonzero = nonzero or Gc[i, a, k] != 0.0 or Gr[k, i, a] != 0.0
            if nonzero:
                lo = min(lo, i)
                hi = i + 1
        bd.span[k, 0], bd.span[k, 1] = lo, hi
        for a in range(b):
            bd.Dm[a, 2 * b + k] = Gc[n - 2, a, k]
            bd.Dm[b + a, 2 * b + k] = Gc[n - 1, a, k]
            bd.Dm[2 * b + k, a] = Gr[k, n - 2, a]
            bd.Dm[2 * b + k, b + a] = Gr[k, n - 1, a]
        for m in range(ng):
            bd.Dm[2 * b + k, 2 * b + m] = Gd[k, m]


@njit(cache=True, no_cpython_wrapper=True)
def block_substitute_many(w, r, x):
    """:func:`beltsim.solvers.newton.block_substitute` for each right-hand side r[q]
    (m, n, 2) into x[q], the same arithmetic in the same order: the columns interleave,
    each row's factors loaded once for all of them, and the columns' recurrences (each a
    chain of dependent steps) overlap. For the border's columns (w: a Newton
    workspace with the band's factors)."""
    C, W, Ub, W2 = w.C, w.W, w.U, w.W2
    m, n = r.shape[0], r.shape[1]
    for i in range(n):
        if i == 0:
            for q in range(m):
                x[q, 0, 0], x[q, 0, 1] = r[q, 0, 0], r[q, 0, 1]
            continue
        w00, w01, w10, w11 = W[i, 0, 0], W[i, 0, 1], W[i, 1, 0], W[i, 1, 1]
        if i > 1:
            v00, v01, v10, v11 = W2[i, 0, 0], W2[i, 0, 1], W2[i, 1, 0], W2[i, 1, 1]
            for q in range(m):
                y0, y1 = x[q, i - 1, 0], x[q, i - 1, 1]
                z0 = r[q, i, 0] - w00 * y0 - w01 * y1
                z1 = r[q, i, 1] - w10 * y0 - w11 * y1
                z0 -= v00 * x[q, i - 2, 0] + v01 * x[q, i - 2, 1]
                z1 -= v10 * x[q, i - 2, 0] + v11 * x[q, i - 2, 1]
                x[q, i, 0], x[q, i, 1] = z0, z1
        else:
            for q in range(m):
                y0, y1 = x[q, i - 1, 0], x[q, i - 1, 1]
                x[q, i, 0] = r[q, i, 0] - w00 * y0 - w01 * y1
                x[q, i, 1] = r[q, i, 1] - w10 * y0 - w11 * y1
    for i in range(n - 1, -1, -1):
        c00, c01, c10, c11 = C[i, 0, 0], C[i, 0, 1], C[i, 1, 0], C[i, 1, 1]
        if i < n - 1:
            u00, u01, u10, u11 = Ub[i, 0, 0], Ub[i, 0, 1], Ub[i, 1, 0], Ub[i, 1, 1]
            for q in range(m):
                x0, x1 = x[q, i + 1, 0], x[q, i + 1, 1]
                z0 = x[q, i, 0] - (u00 * x0 + u01 * x1)
                z1 = x[q, i, 1] - (u10 * x0 + u11 * x1)
                x[q, i, 0] = c00 * z0 + c01 * z1
                x[q, i, 1] = c10 * z0 + c11 * z1
        else:
            for q in range(m):
                z0, z1 = x[q, i, 0], x[q, i, 1]
                x[q, i, 0] = c00 * z0 + c01 * z1
                x[q, i, 1] = c10 * z0 + c11 * z1


@njit(cache=True, no_cpython_wrapper=True)
def border_row_dot(bd, r, y):
    """sum over the band's rows i and unknowns a of Cm[r, i, a] y[i, a]: a border node's
    row reaches only the band's rows 0, ni - 2 and ni - 1 (:func:`gather`), a global's
    every row."""
    ni, b = bd.Cm.shape[1], bd.Cm.shape[2]
    acc = 0.0
    if r < 2 * b:
        for i in (0, ni - 2, ni - 1):
            for a in range(b):
                acc += bd.Cm[r, i, a] * y[i, a]
        return acc
    for i in range(ni):
        for a in range(b):
            acc += bd.Cm[r, i, a] * y[i, a]
    return acc


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True)
def invert(A, out):
    """out = A^{-1} by Gauss-Jordan elimination with partial pivoting (A is overwritten);
    False at a zero pivot. For the border's small matrix (some ten rows), where LAPACK's
    calls (a determinant to test, then the inverse) cost more than the arithmetic."""
    n = A.shape[0]
    for i in range(n):
        for j in range(n):
            out[i, j] = 1.0 if i == j else 0.0
    for k in range(n):
        p, big = k, abs(A[k, k])
        for i in range(k + 1, n):
            if abs(A[i, k]) > big:
                p, big = i, abs(A[i, k])
        if not big > 0.0:  # zero (singular) or NaN
            return False
        if p != k:
            for j in range(n):
                A[k, j], A[p, j] = A[p, j], A[k, j]
                out[k, j], out[p, j] = out[p, j], out[k, j]
        f = 1.0 / A[k, k]
        for j in range(n):
            A[k, j] *= f
            out[k, j] *= f
        for i in range(n):
            if i != k and A[i, k] != 0.0:
                m = A[i, k]
                for j in range(n):
                    A[i, j] -= m * A[k, j]
                    out[i, j] -= m * out[k, j]
    return True


@njit(cache=True, error_model="numpy", no_cpython_wrapper=True)
def schur(bd):
    """bd.Sinv from bd.X = A^{-1} Bm; False when the complement is singular."""
    nb, ni, b = bd.X.shape
    S = bd.Dm.copy()
    for r in range(2 * b):  # the border nodes' rows: three band rows each
        for q in range(nb):
            S[r, q] -= border_row_dot(bd, r, bd.X[q])
    for k in range(nb - 2 * b):  # the globals' rows, over their spans (BLAS)
        lo, hi = bd.span[k, 0] * b, bd.span[k, 1] * b
        if hi > lo:
            row = bd.Cm[2 * b + k].reshape(ni * b)[lo:hi]
            for q in range(nb):
                S[2 * b + k, q] -= np.dot(row, bd.X[q].reshape(ni * b)[lo:hi])
    # scale rows and columns to unit diagonal-ish size: the border mixes metres, N and 1/s
    d = np.ones(nb)
    for r in range(nb):
        m = 0.0
        for q in range(nb):
            m = max(m, abs(S[r, q]))
        if m > 0.0:
            d[r] = 1.0 / m
    Sd = S * d.reshape(nb, 1)
    if not np.all(np.isfinite(Sd)):
        return False
    if not invert(Sd, bd.Sinv):
        return False
    bd.Sinv[:, :] = bd.Sinv * d.reshape(1, nb)
    return np.all(np.isfinite(bd.Sinv))


@njit(cache=True, no_cpython_wrapper=True)
def finish(bd, r, rg, x, dg):
    """Complete a bordered solve: x[:n-2] holds A^{-1} r[:n-2] on entry; on return x
    (n, b) and dg (ng) solve the whole system with right-hand sides r (n, b), rg (ng).

    An open layout's workspace has no border (``bd`` None) and never comes here; its
    type prunes the body, so an open layout does not compile it."""
    if bd is None:
        return
    n, b = r.shape[0], r.shape[1]
    ni = n - 2
    nb = bd.Dm.shape[0]
    for a in range(b):
        bd.rb[a] = r[n - 2, a]
        bd.rb[b + a] = r[n - 1, a]
    for k in range(nb - 2 * b):
        bd.rb[2 * b + k] = rg[k]
    for q in range(2 * b):
        bd.rb[q] -= border_row_dot(bd, q, x)
    xf = x[:ni].reshape(ni * b)  # the band's rows, flat: contiguous loops vectorise
    for k in range(nb - 2 * b):  # the globals' rows, over their spans (BLAS)
        lo, hi = bd.span[k, 0] * b, bd.span[k, 1] * b
        if hi > lo:
            bd.rb[2 * b + k] -= np.dot(bd.Cm[2 * b + k].reshape(ni * b)[lo:hi], xf[lo:hi])
    z = bd.Sinv @ bd.rb
    for q in range(nb):
        Xq = bd.X[q].reshape(ni * b)
        zq = z[q]
        for i in range(ni * b):
            xf[i] -= Xq[i] * zq
    for a in range(b):
        x[n - 2, a] = z[a]
        x[n - 1, a] = z[b + a]
    for k in range(nb - 2 * b):
        dg[k] = z[2 * b + k]
