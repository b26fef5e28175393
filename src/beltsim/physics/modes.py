"""Linear stability of the discrete steady state: the eigenvalue with the largest real part.

The semi-discrete model of either layout linearised about the steady state y0 (zero
rates),

    M z'' + C z' + K z = 0,   M = diag(rho hbar_j, I hbar_j) (lumped),

comes from the numba kernel's Jacobian (:func:`beltsim.solvers.linearise.linearisation`),
which the tests check against the vectorised reference
(:func:`beltsim.physics.reference.linearisation`) and against transients started on a
mode. The friction enters through its slope at the steady slip velocities (an exact
law's through the stuck nodes' penalty slope). A perturbation y = y0 + z e^{lambda t}
solves (M lambda^2 + C lambda + K) z = 0. On the open layout the eigenvalues are those of
the companion matrix [[0, 1], [-M^-1 K, -M^-1 C]] (4 (N - 1) of them); a loop's globals
are first-order unknowns and its gauge row algebraic, so its M is singular and the
eigenvalues are the finite ones of the pencil (:func:`pencil`, the QZ algorithm).

How the largest real part is found (:func:`growth_rate`):

* grids up to DENSE_ELEMENTS elements (a loop's: DENSE_LOOP_ELEMENTS): every
  eigenvalue, dense (LAPACK; its cost grows as the cube of the grid);
* finer grids: the dense spectrum of the same scene on that many elements gives the
  candidate modes, then ARPACK in shift-invert mode finds the NEAREST eigenvalues of the
  fine grid around each. This can miss a mode that is unstable on the fine grid only
  (the coarse grid's upwind gyroscopic term damps more), so it errs towards "stable",
  never towards "unstable" on a grid where no unstable mode exists: an unstable
  eigenvalue it reports is one of the fine grid's.

A closed drive's modes (:mod:`beltsim.physics.loop_modes`) use the same pencil; on all
but tiny grids they come from shifts up the imaginary axis whose disks hold the least
stable eigenvalue and the lowest modes (:mod:`beltsim.physics.shift_invert`).

See docs/theory/stability.md.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from . import continuum
from .discrete import State

#: Up to this many elements the spectrum is computed whole (dense); above, see above. A
#: loop's pencil needs the QZ algorithm, about four times the cost: 8 s on 250 elements.
DENSE_ELEMENTS = 500
DENSE_LOOP_ELEMENTS = 200
#: Eigenvalues ARPACK finds around each candidate on a fine grid, and the candidates:
#: the coarse grid's least stable modes.
NEAREST = 12
CANDIDATES = 4
#: The exact spectrum's seeds: the discrete model with the central gyroscopic form on
#: this many elements, whose eigenvalues lie within a few hertz of the exact ones below
#: a few kilohertz; and the seeds kept: real parts above SEED_FLOOR (1/s).
SEED_ELEMENTS = 600
SEED_FLOOR = -400.0
#: A loop's pencil: eigenvalues beyond this many times the grid's highest frequency are
#: its infinite ones (beta = 0 in round-off)
INFINITE = 1e6


@dataclass(frozen=True)
class Growth:
    """The eigenvalue with the largest real part of a linearised steady state."""

    rate: float  # Re lambda (1/s): > 0 grows
    frequency: float  # |Im lambda| / (2 pi) (Hz)
    elements: int  # of the grid the eigenvalue belongs to
    method: str  # "dense", or "shift-invert near the N-element mode"
    coarse: Growth | None = None  # the coarse grid's, when the method is shift-invert

    def describe(self) -> str:
        """The mode in words: its frequency and its growth or decay rate."""
        return (f"a mode at {self.frequency:.4g} Hz grows at {self.rate:.3g} 1/s"
                if self.rate > 0 else
                f"its least stable mode ({self.frequency:.4g} Hz) decays at "
                f"{-self.rate:.3g} 1/s")


def linearisation(disc, state: State):
    """(M, C, K) of the semi-discrete model about the steady ``state`` on either layout
    (sparse), from the kernel's Jacobian (:func:`beltsim.solvers.linearise.linearisation`,
    which the tests check against the vectorised reference)."""
    from ..solvers.linearise import linearisation as kernel_linearisation

    return kernel_linearisation(disc, state)


def companion(M, C, K):
    """The first-order system matrix [[0, 1], [-M^-1 K, -M^-1 C]] (sparse; M diagonal and
    positive: an open layout's)."""
    n = K.shape[0]
    minv = sp.diags(1.0 / M.diagonal())
    return sp.bmat([[None, sp.identity(n)], [-minv @ K, -minv @ C]], format="csc")


def pencil(M, C, K):
    """(A, B): the first-order form A x = lambda B x of M z'' + C z' + K z = 0, x = (z, z')
    (sparse). With a diagonal positive M, B is None (the identity) and A the companion
    matrix; a loop's globals have no mass (first-order unknowns) and its gauge row is
    algebraic, so its B is singular and the pencil has infinite eigenvalues besides the
    model's."""
    n = K.shape[0]
    if M.nnz == n and np.all(M.diagonal() > 0.0):
        return companion(M, C, K), None
    A = sp.bmat([[None, sp.identity(n)], [-K, -C]], format="csc")
    B = sp.bmat([[sp.identity(n), None], [None, M]], format="csc")
    return A, B


def _largest(eigs) -> complex:
    return complex(eigs[np.argmax(eigs.real)])


def _growth(lam, elements, method, coarse=None) -> Growth:
    return Growth(lam.real, abs(lam.imag) / (2.0 * math.pi), elements, method, coarse)


def steady_discretisation(scene, elements=None):
    """The scene's steady state by the steady scheme on its grid (or on `elements`):
    (Discretisation, State). Raises NumericalError when the steady solve fails."""
    from ..simulation.controller import Simulation

    over = ["numerics.integrator=steady"]
    if elements is not None:
        over.append(f"numerics.elements={elements}")
    sim = Simulation(steady_scene(scene).with_overrides(over))
    sim.run(raise_on_failure=True)
    disc, state = sim.disc, sim.state
    if getattr(disc.params, "tensioner", None) is not None:
        # the arm's angle and rate join the globals, from its rest on the solved layout
        from ..solvers.base import LoopDiscretisation

        disc = LoopDiscretisation(disc.scene, disc.grid, arm=True)
        state = state._replace(g=np.append(state.g, [0.0, 0.0]),
                               gd=np.append(state.gd, [0.0, 0.0]))
    return disc, state


def steady_scene(scene):
    """The scene without the numerics keys of time stepping (the steady scheme refuses
    them; they change neither the grid nor the steady state)."""
    data = scene.to_dict()
    nm = data.get("numerics", {})
    for key in ("dt", "t_end", "time_tol", "max_work", "acceleration", "integrator"):
        nm.pop(key, None)
    if nm.pop("transient", None) == "physical":  # its grid's form, without its step limit
        nm["gyroscopic"] = "central"
    return type(scene).from_dict(data)


def spectrum(disc, state) -> np.ndarray:
    """Every finite eigenvalue of the linearisation (dense; small grids)."""
    A, B = pencil(*linearisation(disc, state))
    if B is None:
        return scipy.linalg.eigvals(A.toarray(), overwrite_a=True, check_finite=False)
    alpha, beta = scipy.linalg.eigvals(A.toarray(), B.toarray(), homogeneous_eigvals=True,
                                       overwrite_a=True, check_finite=False)
    # B's null space (a loop's massless globals and gauge) gives beta = 0, or round-off
    # of it: eigenvalues beyond INFINITE times the grid's highest frequency
    from ..solvers.linearise import highest_frequency

    finite = np.abs(beta) * INFINITE * highest_frequency(disc) > np.abs(alpha)
    return alpha[finite] / beta[finite]


def eigenpairs(disc, state) -> tuple[np.ndarray, np.ndarray]:
    """Every finite eigenvalue of the linearisation and its mode (dense; small grids).

    Returns
    -------
    lam : numpy.ndarray
        The finite eigenvalues (complex, 1/s), in LAPACK's order.
    Z : numpy.ndarray
        Their modes z (columns) over the unknowns of :func:`linearisation`: each node's
        (u, theta), then a loop's globals (its speeds, first-order unknowns: their
        perturbations, not displacements). Each column has unit 2-norm over (z, z').
    """
    M, C, K = linearisation(disc, state)
    A, B = pencil(M, C, K)
    n = K.shape[0]
    if B is None:
        lam, V = scipy.linalg.eig(A.toarray(), overwrite_a=True, check_finite=False)
        return lam, V[:n]
    (alpha, beta), V = scipy.linalg.eig(A.toarray(), B.toarray(), homogeneous_eigvals=True,
                                        overwrite_a=True, check_finite=False)
    from ..solvers.linearise import highest_frequency

    # as in spectrum: B's null space gives beta = 0 or its round-off
    finite = np.abs(beta) * INFINITE * highest_frequency(disc) > np.abs(alpha)
    return alpha[finite] / beta[finite], V[:n, finite]


def growth_rate(scene, dense_elements=None) -> Growth:
    """The largest real part of the eigenvalues of the scene's discrete model (its own
    grid, numerics.elements or the default) linearised about its steady state.

    Raises NumericalError when the steady state cannot be solved for, ValueError for a
    quasistatic scene (no dynamics)."""
    if not scene.params.inertia:
        raise ValueError("a quasistatic scene has no dynamics to linearise")
    disc, state = steady_discretisation(scene)
    N = disc.grid.n_elements
    if dense_elements is None:
        dense_elements = DENSE_LOOP_ELEMENTS if disc.closed else DENSE_ELEMENTS
    if N <= dense_elements:
        return _growth(_largest(spectrum(disc, state)), N, "dense")
    cdisc, cstate = steady_discretisation(scene, dense_elements)
    eigs = spectrum(cdisc, cstate)
    coarse = _growth(_largest(eigs), dense_elements, "dense")
    A, B = pencil(*linearisation(disc, state))
    found = [eigenvalues_near(A, sigma, NEAREST, B) for sigma in _candidates(eigs, CANDIDATES)]
    return _growth(_largest(np.concatenate(found)), N,
                   f"shift-invert near the {dense_elements}-element grid's least stable "
                   f"modes", coarse)


def eigenvalues_near(A, sigma, k=1, B=None) -> np.ndarray:
    """The k eigenvalues of A x = lambda B x (:func:`pencil`; B None: the identity) nearest
    to sigma: ARPACK on (A - sigma B)^-1 B, whose largest eigenvalues mu are
    1 / (lambda - sigma)."""
    if B is None:
        return spla.eigs(A.astype(complex), k=k, sigma=sigma, which="LM",
                         return_eigenvectors=False, tol=1e-10, maxiter=5000)
    lu = spla.splu((A - sigma * B).astype(complex).tocsc())
    Bc = B.astype(complex)
    op = spla.LinearOperator(A.shape, matvec=lambda x: lu.solve(Bc @ x), dtype=complex)
    mu = spla.eigs(op, k=k, which="LM", return_eigenvectors=False, tol=1e-10, maxiter=5000)
    return sigma + 1.0 / mu


def nearest_eigenvalue(scene, target, elements=None) -> complex:
    """The eigenvalue nearest to ``target`` of the scene's discrete model (its grid, or
    ``elements``) linearised about its steady state."""
    A, B = pencil(*linearisation(*steady_discretisation(scene, elements)))
    return complex(eigenvalues_near(A, target, 1, B)[0])


def _candidates(eigs, k):
    """The k least stable eigenvalues of distinct frequency (upper half plane)."""
    out = []
    for lam in eigs[np.argsort(-eigs.real)]:
        if lam.imag < 0.0:
            continue
        if all(abs(lam - o) > 1e-6 * (1.0 + abs(o)) for o in out):
            out.append(complex(lam))
        if len(out) == k:
            break
    return out


def exact_spectrum(scene, f_max: float, damping: float | None = None,
                   seed_elements: int = SEED_ELEMENTS) -> np.ndarray:
    """The eigenvalues up to f_max Hz of the continuous model linearised about the exact
    steady state (:mod:`beltsim.physics.continuum`: no discretisation), sorted by
    decreasing real part.

    Newton's method on the characteristic determinant starts from every eigenvalue of
    the discrete model with the central gyroscopic form on ``seed_elements`` elements
    (second order, within a few hertz of the exact roots in the band) and from a scan of
    the band; each root is exact to 1e-12 relative. A root that neither finds is missed,
    so compare bands against a finer seed grid when completeness matters.
    """
    over = [("numerics.gyroscopic", "central")]
    if damping is not None:
        over.append(("physics.damping", damping))
    seeded = scene.with_overrides(over)
    ch = continuum.characteristic(seeded)
    disc, state = steady_discretisation(seeded, seed_elements)
    eigs = spectrum(disc, state)
    seeds = eigs[(eigs.imag > 0.0) & (eigs.imag < 2.0 * math.pi * 1.05 * f_max)
                 & (eigs.real > SEED_FLOOR)]
    return ch.roots(f_max, seeds=seeds)


def exact_growth(scene, f_max: float, damping: float | None = None) -> Growth:
    """The least stable eigenvalue up to f_max Hz of :func:`exact_spectrum`."""
    roots = exact_spectrum(scene, f_max, damping)
    return _growth(roots[0], 0, f"exact characteristic roots up to {f_max:g} Hz")
