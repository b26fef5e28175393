"""Newton's method on the loop's equations, the steady solve and BDF2 time steps."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

from ..errors import FailureKind, NumericalError
from .discrete import Layout, residual_scale, update_scale
from .model import LoopMesh, LoopParams, Rates, assemble, max_triplets

#: a scaled residual this small is converged whatever the last update (round-off level)
RESIDUAL_TOL = 1e-12


@dataclass
class System:
    """One discretised drive: the kernel's inputs and the Newton's buffers and scales."""

    mesh: LoopMesh
    params: LoopParams
    lay: Layout
    yscale: np.ndarray
    rscale: np.ndarray

    def __post_init__(self):
        n = max_triplets(self.mesh)
        self.R = np.zeros(self.lay.size)
        self.rows = np.zeros(n, dtype=np.int64)
        self.cols = np.zeros(n, dtype=np.int64)
        self.vals = np.zeros(n)

    def residual(self, y, rates, rim1, load):
        """R(y) (a copy)."""
        assemble(y, rates, rim1, load, self.mesh, self.params, self.R, self.rows, self.cols,
                 self.vals, False)
        return self.R.copy()

    def jacobian(self, y, rates, rim1, load):
        """(R(y), J(y)) with J a CSC matrix."""
        n = assemble(y, rates, rim1, load, self.mesh, self.params, self.R, self.rows,
                     self.cols, self.vals, True)
        size = self.lay.size
        J = sp.csc_matrix((self.vals[:n], (self.rows[:n], self.cols[:n])), shape=(size, size))
        return self.R.copy(), J


def steady_rates(N: int) -> Rates:
    """The rates of the steady problem: a0 = 0 and no history."""
    z = np.zeros(N)
    return Rates(0.0, z, z, z, z, 0.0, 0.0)


def _clip_ratios(y, lay: Layout, law_is_regularised: bool):
    if law_is_regularised:
        lam = lay.lam(y)
        np.clip(lam, -1.0 + 1e-14, 1.0 - 1e-14, out=lam)


def newton(sys_: System, y, rates, rim1, load, tol=1e-10, max_iterations=40):
    """Solve R(y) = 0 from y (changed in place): semi-smooth Newton with a backtracking
    line search on the scaled residual. Returns the number of iterations.

    Raises NumericalError (kind NEWTON) when it does not converge.
    """
    from ..physics.friction import EXACT, LAW_CODES

    regular = sys_.params.law not in (EXACT, LAW_CODES["adhesion"])
    lay = sys_.lay
    R = sys_.residual(y, rates, rim1, load)
    merit = np.linalg.norm(R / sys_.rscale)
    for it in range(1, max_iterations + 1):
        R, J = sys_.jacobian(y, rates, rim1, load)
        try:
            dy = splu(J).solve(-R)
        except RuntimeError as exc:
            raise NumericalError(f"singular Jacobian in the drive's Newton iteration ({exc})",
                                 kind=FailureKind.NEWTON) from None
        if not np.all(np.isfinite(dy)):
            raise NumericalError("non-finite Newton update", kind=FailureKind.NON_FINITE)
        step = 1.0
        if regular:
            # keep the friction ratios inside (-1, 1): g^{-1} is singular on the boundary
            lam, dl = lay.lam(y), lay.lam(dy)
            out = np.abs(lam + dl) >= 1.0
            if np.any(out):
                room = (np.sign(dl[out]) - lam[out]) / dl[out]
                step = min(1.0, 0.99 * float(np.min(room)))
        trial = y + step * dy
        new = np.linalg.norm(sys_.residual(trial, rates, rim1, load) / sys_.rscale)
        while new > merit and step > 1e-3:
            step *= 0.5
            trial = y + step * dy
            new = np.linalg.norm(sys_.residual(trial, rates, rim1, load) / sys_.rscale)
        y[:] = trial
        _clip_ratios(y, lay, regular)
        merit = new
        if step == 1.0 and np.max(np.abs(dy) / sys_.yscale) < tol or merit < RESIDUAL_TOL:
            return it
    raise NumericalError(f"the drive's Newton iteration did not converge in "
                         f"{max_iterations} iterations (scaled residual {merit:.3g})",
                         kind=FailureKind.NEWTON)


def make_system(mesh, params, lay, P) -> System:
    """The System of a discretised drive."""
    return System(mesh, params, lay, update_scale(lay, P), residual_scale(lay, mesh, P))
