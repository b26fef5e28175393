"""Sparse eigenvalues of a quadratic's pencil (:func:`beltsim.physics.modes.pencil`) by
shift-invert: a closed drive's modes and least stable eigenvalue on fine grids
(:mod:`beltsim.physics.loop_modes`).

About a shift sigma the operator (A - sigma B)^-1 B (:class:`ShiftInvert`) has the
eigenvalues mu = 1 / (lambda - sigma): ARPACK's largest mu are the eigenvalues nearest
sigma, a :class:`Disk`. :func:`sweep` places disks up the imaginary axis so that no
eigenvalue near the axis lies between them; the listed modes come from the same disks,
and :func:`distinct` merges what overlapping disks found twice.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

#: Eigenvalues ARPACK finds about each shift of :func:`sweep`: more per shift means
#: fewer shifts, but larger disks that find more of the damped eigenvalues left of the
#: band, and restarts where a disk's edge cuts a dense cloud of them (the accessory drive
#: on 200 elements, best of three on two loaded cores: 8, 10, 12, 14, 16 and 20 took
#: 0.52, 0.54, 0.53, 0.57, 0.64 and 0.79 s)
SWEEP_NEAREST = 12
#: The sweep's shifts reach this many times the grid's highest axial frequency, the band
#: the least stable eigenvalue is sought in. Above it lie grid-scale eigenvalues whose
#: frequency follows the grid, and the central form's can grow (drive_flat at d = 20
#: 1/s, by QZ: +21.5 1/s at 6.5 kHz on 60 elements, +31.8 at 25.5 kHz on 240): they are
#: the discretisation's, not the drive's, and the band leaves them out
SWEEP_REACH = 1.5
#: ARPACK's relative tolerance on the shift-inverted eigenvalues 1 / (lambda - sigma)
ARPACK_TOL = 1e-10
#: Two disks' eigenvalues closer than this times their distance to their shifts are one
#: eigenvalue found twice. Measured on the accessory drive (60, 120 and 200 elements,
#: tanh and exact laws; 12 and 16 per shift) and drive_flat's sweeps: the copies of one
#: eigenvalue at most 7.6e-6 apart (ARPACK's tolerance times the eigenvalue's
#: condition), distinct ones found by one disk 1.0e-3 apart at least
REPEAT = 1e-4


def _openblas_libraries():
    """ctypes handles of the OpenBLAS copies numpy and scipy ship (empty where unknown)."""
    import ctypes
    import glob
    import os

    import scipy

    found = []
    for pkg in (np, scipy):
        libs = os.path.join(os.path.dirname(os.path.dirname(pkg.__file__)),
                            pkg.__name__ + ".libs")
        for path in glob.glob(os.path.join(libs, "libscipy_openblas*.so")):
            try:
                lib = ctypes.CDLL(path)
                found.append((lib.scipy_openblas_get_num_threads,
                              lib.scipy_openblas_set_num_threads))
            except (OSError, AttributeError):
                pass
    return found


class one_blas_thread:
    """Run ARPACK's small dense operations on one OpenBLAS thread, then restore the count.
    On a machine whose cores are busy, OpenBLAS's threads wait for each other on these
    n by 100 products: measured ten times slower on two loaded cores."""

    def __enter__(self):
        self.saved = [(get(), put) for get, put in _openblas_libraries()]
        for _, put in self.saved:
            put(1)
        return self

    def __exit__(self, *exc):
        for count, put in self.saved:
            put(count)
        return False


@dataclass(frozen=True)
class Disk:
    """One shift's eigenvalues: every one within ``radius`` of ``shift`` (the farthest
    found's distance), and their modes over (z, z') as columns (None unless asked
    for)."""

    shift: complex
    radius: float
    eigenvalues: np.ndarray
    modes: np.ndarray | None = None


class ShiftInvert:
    """(A - sigma B)^-1 B of a quadratic's pencil about a complex shift, applied with one
    sparse LU of the n by n Q(sigma) = sigma^2 M + sigma C + K instead of the 2n by 2n
    pencil's: (A - sigma B) y = B (z, v) gives y1 = -Q(sigma)^-1 (M v + (C + sigma M) z)
    and y2 = z + sigma y1."""

    def __init__(self, M, C, K, sigma: complex):
        self.n, self.sigma = K.shape[0], complex(sigma)
        # [C + sigma M, M] in one product: the operator is applied thousands of times
        self.W = sp.hstack([C + self.sigma * M, M]).astype(complex).tocsr()
        Q = (K + self.sigma * C + self.sigma ** 2 * M).astype(complex).tocsc()
        self.lu = spla.splu(Q)

    def matvec(self, x):
        y1 = self.lu.solve(self.W @ x)
        y1 *= -1.0
        return np.concatenate([y1, x[:self.n] + self.sigma * y1])

    def nearest(self, k: int, vectors: bool = False):
        """The k eigenvalues nearest sigma (ARPACK's largest 1 / (lambda - sigma)), and,
        with ``vectors``, their modes over (z, z') as columns."""
        op = spla.LinearOperator((2 * self.n, 2 * self.n), matvec=self.matvec, dtype=complex)
        ncv = min(2 * k + 20, 2 * self.n - 1)
        out = spla.eigs(op, k=k, which="LM", ncv=ncv, tol=ARPACK_TOL, maxiter=5000,
                        return_eigenvectors=vectors)
        mu, V = out if vectors else (out, None)
        return self.sigma + 1.0 / mu, V

    def disk(self, k: int, vectors: bool = False) -> Disk:
        """:meth:`nearest` as a :class:`Disk`."""
        lam, V = self.nearest(k, vectors)
        return Disk(self.sigma, float(np.max(np.abs(lam - self.sigma))), lam, V)


def sweep(M, C, K, reach: float, vectors=None) -> list[Disk]:
    """Shift-invert disks up the imaginary axis that leave no eigenvalue of the pencil of
    M z'' + C z' + K z = 0 with 0 <= Im lambda <= ``reach`` to the right of the largest
    real part they find.

    About each shift sigma = i w (the first at 0) ARPACK finds the SWEEP_NEAREST nearest
    eigenvalues, so the disk of radius r (the farthest found) holds no other. With x the
    largest real part found so far, the disk covers the band x <= Re lambda <= abs(x) for
    abs(Im lambda - w) <= h = sqrt(r^2 - x^2), and the next shift is w + h: the disks
    together leave no point of that band between 0 and ``reach`` uncovered. (A growing
    eigenvalue whose rate exceeds abs(x) might only lie outside the disks; none is missed
    that the dense QZ would find in the tests' scenes.)

    Parameters
    ----------
    M, C, K : scipy.sparse matrix
        The quadratic's parts (:func:`beltsim.physics.modes.linearisation`).
    reach : float
        Im lambda (rad/s) up to which the band is swept.
    vectors : callable, optional
        Given the disks so far, whether the next one keeps its modes (default: none
        does; ARPACK's modes cost a sixth of a disk's time).

    Returns
    -------
    list of Disk
        By increasing shift; overlapping disks repeat some eigenvalues (:func:`distinct`).
    """
    k = min(SWEEP_NEAREST, 2 * K.shape[0] - 2)
    disks, w, x = [], 0.0, -math.inf
    while w <= reach:
        disk = ShiftInvert(M, C, K, 1j * w).disk(k, vectors is not None and vectors(disks))
        disks.append(disk)
        x = max(x, float(np.max(disk.eigenvalues.real)))
        h = math.sqrt(max(disk.radius ** 2 - x * x, 0.0))
        if h <= 1e-9 * max(disk.radius, 1.0):
            raise RuntimeError(f"sweep: the shifts' disks do not reach the band at "
                               f"{w:.4g} rad/s (radius {disk.radius:.3g}, x {x:.3g})")
        w += h
    return disks


def distinct(disks) -> tuple[np.ndarray, np.ndarray]:
    """The disks' eigenvalues, each once, and their modes.

    An eigenvalue found by two overlapping disks is one whose copies lie within REPEAT
    of the farther copy's distance to its shift; the copy kept is one with its mode if
    any has it, of those the nearer its shift (the more accurate). Copies are paired one
    to one, so a multiple eigenvalue found as often by each disk is kept as often.

    Returns
    -------
    lam : numpy.ndarray
    V : numpy.ndarray
        Their modes over (z, z') as columns; NaN where no disk kept one.
    """
    size = next((d.modes.shape[0] for d in disks if d.modes is not None), 0)
    lam = np.zeros(0, complex)
    rank = np.zeros((0, 2))  # (no mode, distance to the shift): the lower the better
    cols: list = []
    for d in disks:
        e = np.abs(d.eigenvalues - d.shift)
        close = (np.abs(d.eigenvalues[:, None] - lam[None, :])
                 <= REPEAT * np.maximum(e[:, None], rank[None, :, 1]))
        paired = np.zeros(lam.size, bool)
        new = []
        for i in np.argsort(e):
            match = np.flatnonzero(close[i] & ~paired)
            if match.size == 0:
                new.append(i)
                continue
            m = match[np.argmin(np.abs(lam[match] - d.eigenvalues[i]))]
            paired[m] = True
            mine = (d.modes is None, e[i])
            if mine < tuple(rank[m]):
                lam[m], rank[m] = d.eigenvalues[i], mine
                cols[m] = None if d.modes is None else d.modes[:, i]
        new = np.sort(np.asarray(new, dtype=int))
        lam = np.concatenate([lam, d.eigenvalues[new]])
        rank = np.concatenate([rank, np.column_stack([np.full(new.size, d.modes is None),
                                                      e[new]])])
        cols.extend(None if d.modes is None else d.modes[:, i] for i in new)
    V = np.full((size, len(cols)), np.nan, complex)
    for j, c in enumerate(cols):
        if c is not None:
            V[:, j] = c
    return lam, V
