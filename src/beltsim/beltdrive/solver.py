"""Newton's method on the loop's equations, the steady solve and BDF2 time steps."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numba import njit
from scipy.linalg.lapack import dgbsv

from ..errors import FailureKind, NumericalError
from .discrete import Layout, residual_scale, update_scale
from .model import LoopMesh, LoopParams, Rates, assemble, max_triplets

#: a scaled residual whose root mean square is this small is converged whatever the last
#: update: round-off level (the semi-smooth Newton can flip a front node back and forth
#: at that level)
RESIDUAL_TOL = 1e-13
#: a scaled residual of root mean square below this that a full step no longer halves is
#: at its round-off floor
FLOOR_TOL = 1e-9


@njit(cache=True)
def scatter_bordered(rows, cols, vals, n, pos, n_int, kl, ku, ab, Bm, Cm, Dm):
    """Scatter the Jacobian's COO triplets into the bordered band form: the interior block
    in LAPACK band storage ab[kl + ku + i - j, j], the border columns Bm, rows Cm and
    corner Dm (pos: the unknowns' places, the interior first)."""
    ab[:, :] = 0.0
    Bm[:, :] = 0.0
    Cm[:, :] = 0.0
    Dm[:, :] = 0.0
    for k in range(n):
        i, j = pos[rows[k]], pos[cols[k]]
        if i < n_int and j < n_int:
            ab[kl + ku + i - j, j] += vals[k]
        elif i < n_int:
            Bm[i, j - n_int] += vals[k]
        elif j < n_int:
            Cm[i - n_int, j] += vals[k]
        else:
            Dm[i - n_int, j - n_int] += vals[k]


class BorderedBand:
    """The Newton's linear solve in the loop's own structure.

    With the unknowns ordered node by node (u_j, theta_j, lam_j), nodes 2..N-1 form a
    banded block (the stencils reach j - 2 .. j + 1); the unknowns of nodes 0 and 1 (where
    the loop closes) and c, omega2 (whose column and rows are dense) form a border of at
    most 8. The band is factored by LAPACK's gbsv with partial pivoting (the stuck
    friction ratios' rows have no diagonal), the border by its Schur complement: the cost
    is linear in the grid.
    """

    def __init__(self, sys_):
        lay, lidx = sys_.lay, sys_.mesh.lidx
        N = lay.N
        def node(j):
            return [2 * j, 2 * j + 1] + ([2 * N + lidx[j]] if lidx[j] >= 0 else [])
        interior = [k for j in range(2, N) for k in node(j)]
        border = node(0) + node(1) + [lay.c, lay.omega2]
        order = np.array(interior + border)
        self.order = order
        self.n_int = len(interior)
        self.pos = np.empty_like(order)
        self.pos[order] = np.arange(len(order))
        n = assemble(np.zeros(lay.size), steady_rates(N), 1.0, 0.0, sys_.q, sys_.mesh, sys_.params,
                     sys_.R, sys_.rows, sys_.cols, sys_.vals, True)
        pi, pj = self.pos[sys_.rows[:n]], self.pos[sys_.cols[:n]]
        inner = (pi < self.n_int) & (pj < self.n_int)
        self.kl = int(np.max(pi[inner] - pj[inner]))
        self.ku = int(np.max(pj[inner] - pi[inner]))
        nb = len(border)
        self.ab = np.zeros((2 * self.kl + self.ku + 1, self.n_int), order="F")
        self.Bm = np.zeros((self.n_int, nb))
        self.Cm = np.zeros((nb, self.n_int))
        self.Dm = np.zeros((nb, nb))

    def solve(self, sys_, n, R):
        """The Newton update -J^{-1} R from the triplets of the last assembly."""
        scatter_bordered(sys_.rows, sys_.cols, sys_.vals, n, self.pos, self.n_int, self.kl,
                         self.ku, self.ab, self.Bm, self.Cm, self.Dm)
        r = -R[self.order]
        ni = self.n_int
        rhs = np.empty((ni, 1 + self.Bm.shape[1]), order="F")
        rhs[:, 0] = r[:ni]
        rhs[:, 1:] = self.Bm
        _, _, X, info = dgbsv(self.kl, self.ku, self.ab, rhs, overwrite_ab=1, overwrite_b=1)
        if info != 0:
            raise NumericalError(f"singular Jacobian in the drive's Newton iteration (band "
                                 f"pivot {info})", kind=FailureKind.NEWTON)
        S = self.Dm - self.Cm @ X[:, 1:]
        try:
            z = np.linalg.solve(S, r[ni:] - self.Cm @ X[:, 0])
        except np.linalg.LinAlgError:
            raise NumericalError("singular Jacobian in the drive's Newton iteration (border)",
                                 kind=FailureKind.NEWTON) from None
        out = np.empty_like(R)
        out[self.order[:ni]] = X[:, 0] - X[:, 1:] @ z
        out[self.order[ni:]] = z
        return out


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
        self.q = np.zeros(2 * self.lay.N)  # distributed loads: manufactured solutions only

        self.band = BorderedBand(self)

    def update(self, y, rates, rim1, load):
        """(R(y), the Newton update -J^{-1} R)."""
        n = assemble(y, rates, rim1, load, self.q, self.mesh, self.params, self.R, self.rows,
                     self.cols, self.vals, True)
        R = self.R.copy()
        return R, self.band.solve(self, n, R)

    def residual(self, y, rates, rim1, load):
        """R(y) (a copy)."""
        assemble(y, rates, rim1, load, self.q, self.mesh, self.params, self.R, self.rows, self.cols,
                 self.vals, False)
        return self.R.copy()

    def jacobian(self, y, rates, rim1, load):
        """(R(y), J(y)) with J a CSC matrix."""
        n = assemble(y, rates, rim1, load, self.q, self.mesh, self.params, self.R, self.rows,
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
        R, dy = sys_.update(y, rates, rim1, load)
        if not np.all(np.isfinite(dy)):
            raise NumericalError("non-finite Newton update", kind=FailureKind.NON_FINITE)
        step = 1.0
        if regular:
            # each friction ratio moves at most 99% of the way to the boundary of (-1, 1),
            # node by node (g^{-1} is singular there), as the straight belt's Newton does
            lam, dl = lay.lam(y), lay.lam(dy)
            up, down = lam + dl >= 1.0, lam + dl <= -1.0
            dl[up] = 0.99 * (1.0 - lam[up])
            dl[down] = -0.99 * (1.0 + lam[down])
        trial = y + step * dy
        new = np.linalg.norm(sys_.residual(trial, rates, rim1, load) / sys_.rscale)
        while new > merit and step > 1e-3:
            step *= 0.5
            trial = y + step * dy
            new = np.linalg.norm(sys_.residual(trial, rates, rim1, load) / sys_.rscale)
        y[:] = trial
        _clip_ratios(y, lay, regular)
        # at round-off the residual stops falling: its floor grows as the stiffness b1 / h
        # of fine grids, so a small residual that a full step no longer halves is converged
        stalled = step == 1.0 and new > 0.5 * merit and new < FLOOR_TOL * np.sqrt(len(y))
        merit = new
        small = merit < RESIDUAL_TOL * np.sqrt(len(y))
        if step == 1.0 and np.max(np.abs(dy) / sys_.yscale) < tol or small or stalled:
            return it
    raise NumericalError(f"the drive's Newton iteration did not converge in "
                         f"{max_iterations} iterations (scaled residual {merit:.3g})",
                         kind=FailureKind.NEWTON)


def make_system(mesh, params, lay, P) -> System:
    """The System of a discretised drive."""
    return System(mesh, params, lay, update_scale(lay, P), residual_scale(lay, mesh, P))
