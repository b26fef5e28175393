"""beltsim's default scheme ported to vectorised numpy and scipy.sparse (no numba).

The same formulation and the same steps as :mod:`beltsim.solvers.implicit`: variable-
step BDF2 on the system in (u, u_t), one primal-dual Newton solve per step with the
friction ratios condensed node by node (:func:`beltsim.solvers.newton.newton`, its
convergence tests, its chord steps, the fraction-to-the-boundary update of the ratios,
the law's value near the bound and the restart of ratios stuck there), the
Hairer-Wanner filtered local error estimate with the step's Newton matrix, the same
step control, steps landing on the controller's checks, the same power integrals. Only
the implementation differs:

* the residual and the Jacobian of :func:`beltsim.physics.model.assemble` are built
  with numpy array operations over all nodes at once;
* the Jacobian (block banded: two lower block bands, one upper) is a scipy.sparse CSC
  matrix of fixed pattern, interleaved unknowns (u_1, theta_1, u_2, ...), whose values
  are written into precomputed slots, and factorised by ``scipy.sparse.linalg.splu``
  in its natural (banded) order, preferring the diagonal pivot (the numba block LU
  inverts its 2x2 pivot blocks with no row interchanges either);
  the factors serve the Newton update and the error filter, as the numba block LU
  does. ``solver="banded"`` uses LAPACK's banded LU instead (not scipy.sparse; faster).

It runs inside beltsim's own :class:`~beltsim.simulation.controller.Simulation` (the
scheme object is swapped), so the check times, trackers and steady criterion are the
run's. The ratio of its wall time to the numba scheme's is what the compiled kernels
buy (``kernel_speedup`` of :func:`beltsim.studies.bench.bench`). The drive's profile
(``mismatch``, ``friction_factor``) is evaluated by the scene's own functions (compiled
scalar functions of t, a few calls per Newton iteration, as ``forces_numpy`` does).
Saturating friction laws with the primal-dual form only (the default coulomb/tanh and
sqrt); no distributed loads.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from beltsim.errors import FailureKind, NumericalError
from beltsim.physics import reference
from beltsim.physics.discrete import State
from beltsim.physics.friction import SQRT, TANH, law_inverse_numpy, law_numpy
from beltsim.physics.model import LAM_MAX, POWER_TERMS
from beltsim.simulation.controller import Simulation
from beltsim.solvers.base import Scheme
from beltsim.solvers.dual import LAW_GAP, NEAR_BOUND, SLIP_GAP
from beltsim.solvers.implicit import (
    BDF2_ERROR,
    MAX_GROWTH,
    MIN_SHRINK,
    NEWTON_CUT,
    SAFETY,
    ImplicitScheme,
)
from beltsim.solvers.newton import CHORD, CONTRACTION, ROUNDOFF_FLOOR

from .peers import FixedPattern, coo_parts


class Assembly(NamedTuple):
    R: np.ndarray  # residual (n, 2)
    J: object  # CSC Jacobian (or None)
    rl: np.ndarray  # friction equation residuals at the contact nodes
    sg: np.ndarray  # friction slopes there
    k: np.ndarray  # the friction stiffnesses -dF/dv_rel of the Jacobian


class BandedLU(NamedTuple):
    """Factors of scipy.linalg.lapack.dgbtrf with the ``solve`` of a SuperLU object."""

    lu: np.ndarray
    piv: np.ndarray
    kl: int
    ku: int

    def solve(self, b):
        from scipy.linalg import lapack

        return lapack.dgbtrs(self.lu, self.kl, self.ku, b, self.piv)[0]


class PortScheme(Scheme):
    """The implicit scheme (variable-step BDF2, primal-dual Newton) in numpy/scipy.sparse."""

    name = "implicit-port"
    SOLVERS = ("splu", "banded")

    def __init__(self, disc, solver="splu"):
        super().__init__(disc)
        if solver not in self.SOLVERS:
            raise ValueError(f"solver: one of {self.SOLVERS}, got {solver!r}")
        self.solver = solver
        self._band = None
        p, m = disc.model, disc.mesh
        if not p.dual or p.law not in (TANH, SQRT):
            raise ValueError("the port implements the primal-dual form (tanh, sqrt laws)")
        N = disc.grid.n_elements
        self.N, self.n = N, N - 1
        self.jc = reference.contact_nodes(m)
        # the Jacobian K + inv_dt C + inv_dt^2 M, friction's entries on top (those in
        # the q' columns times inv_dt)
        self.ops = ops = reference.operators(m, p)
        self.fric = fr = reference.friction_pattern(m, p)
        n2 = 2 * self.n
        self.rate_entry = fr.cols >= n2
        diagonal = np.arange(n2)
        self.pattern = FixedPattern((n2, n2), [coo_parts(ops.stiffness),
                                               coo_parts(ops.damping),
                                               (diagonal, diagonal, ops.mass)],
                                    fr.rows, fr.cols % n2)
        n_nodes = N + 1
        self.hist = {k: np.zeros(n_nodes) for k in ("u", "theta", "ud", "td", "au", "at", "lam")}
        self.base = State.zeros(n_nodes)
        self.h_prev = 0.0
        self.h_next = self.numerics.dt
        self.power = np.zeros(len(POWER_TERMS))
        self.work_done = np.zeros(len(POWER_TERMS))
        self.newton_iterations = 0
        self.failed_steps = 0
        self.factorisations = 0
        self.lu = None  # factors of the last factorised Jacobian
        self.kf = None  # and the friction stiffnesses it was assembled with

    @property
    def dt(self) -> float:
        return self.h_next

    # the model ----------------------------------------------------------------
    def assemble(self, u, th, lam, fnode, old, inv_dt, t, want_jac=True) -> Assembly:
        """:func:`beltsim.physics.model.assemble` in the primal-dual form: the reference's
        residual with the condensed friction ratio lam + sg rl, and its Jacobian with the
        slopes sg of the ratios."""
        d = self.disc
        p, mesh, jc = d.model, d.mesh, self.jc
        vrel = reference.slip_velocity(u, th, (u - old.u) * inv_dt, (th - old.theta) * inv_dt,
                                       t, mesh, p, d.drive)
        gi, dgi = law_inverse_numpy(p.law, lam[jc])
        rl = vrel / p.regularisation - gi
        sg = 1.0 / dgi
        fnode[:], k = reference.friction(vrel, t, mesh, p, d.drive, ratios=lam, slopes=sg)
        condensed = np.zeros_like(lam)
        condensed[jc] = lam[jc] + sg * rl
        R, _ = reference.residual(u, th, old, inv_dt, t, mesh, p, d.drive, d.loads, condensed)
        J = None
        if want_jac:
            values = k[self.fric.node] * self.fric.coef
            values[self.rate_entry] *= inv_dt
            J = self.pattern.matrix(values, (1.0, inv_dt, inv_dt * inv_dt))
        return Assembly(R, J, rl, sg, k)

    def factorise(self, J):
        from scipy.sparse.linalg import splu

        self.factorisations += 1
        if self.solver == "banded":
            return self._banded(J)
        try:
            return splu(J, permc_spec="NATURAL", diag_pivot_thresh=0.0,
                        options={"SymmetricMode": True})
        except RuntimeError:  # exactly singular
            return None

    def _banded(self, J):
        """LAPACK's banded LU (dgbtrf) of J, partial pivoting; None if singular."""
        from scipy.linalg import lapack

        if self._band is None:
            cols = np.repeat(np.arange(J.shape[1]), np.diff(J.indptr))
            kl, ku = int((J.indices - cols).max()), int((cols - J.indices).max())
            self._band = (kl, ku, (2 * kl + ku + 1, J.shape[0]),
                          (kl + ku + J.indices - cols, cols))
        kl, ku, shape, pos = self._band
        ab = np.zeros(shape)
        ab[pos] = J.data
        lu, piv, info = lapack.dgbtrf(ab, kl, ku)
        return None if info != 0 else BandedLU(lu, piv, kl, ku)

    def update_multipliers(self, lam, dx, inv_dt, asm):
        """Vectorised :func:`beltsim.solvers.dual.update_multipliers`; the largest change."""
        d = self.disc
        p, jc = d.model, self.jc
        du, dth = np.zeros(self.N + 1), np.zeros(self.N + 1)
        du[1:-1], dth[1:-1] = dx[:, 0], dx[:, 1]
        # the slip velocities' change: linear in the update
        dv = reference.slip_velocity(du, dth, inv_dt * du, inv_dt * dth, 0.0, d.mesh, p)
        lj = lam[jc]
        dl = asm.sg * (asm.rl + dv / p.regularisation)
        dl = np.where(lj + dl >= 1.0, 0.99 * (1.0 - lj),
                      np.where(lj + dl <= -1.0, -0.99 * (1.0 + lj), dl))
        new = np.minimum(LAM_MAX, np.maximum(-LAM_MAX, lj + dl))
        # near the bound, the law at the linearised slip velocity on the same side
        near = 1.0 < NEAR_BOUND * law_inverse_numpy(code := p.law, new)[1]
        if near.any():
            s = law_inverse_numpy(code, lj)[0] + asm.rl + dv / p.regularisation
            if code == TANH:  # the kernel's formula (friction.law), to the bit
                e = np.exp(-2.0 * np.abs(s))
                gs = np.copysign((1.0 - e) / (1.0 + e), s)
            else:
                gs = law_numpy(code, s)[0]
            primal = near & (new * (gs - new) < 0.0) & (gs * new > 0.0)
            new = np.where(primal, np.minimum(LAM_MAX, np.maximum(-LAM_MAX, gs)), new)
        dl = new - lj
        lam[jc] = new
        return float(np.abs(dl).max()) if dl.size else 0.0

    def release_stuck_ratios(self, lam, lam0, asm, growing):
        """Vectorised :func:`beltsim.solvers.dual.release_stuck_ratios`: the largest
        change."""
        jc, code = self.jc, self.disc.model.law
        lj = lam[jc]
        cand = (asm.sg < NEAR_BOUND) & (lj * asm.rl < 0.0)
        if not cand.any():
            return 0.0
        s = asm.rl[cand] + law_inverse_numpy(code, lam0[cand])[0]
        g = law_numpy(code, s)[0]
        if growing:
            off = np.abs(law_inverse_numpy(code, lj[cand])[0] - s) > SLIP_GAP
            new = np.clip(g[off], -LAM_MAX, LAM_MAX)
        else:
            off = np.abs(g - lj[cand]) > LAW_GAP
            new = np.zeros(int(off.sum()))
        if not off.any():
            return 0.0
        idx = jc[cand][off]
        big = float(np.abs(new - lam[idx]).max())
        lam[idx] = new
        return big

    def newton(self, state, old, inv_dt, t):
        """Vectorised :func:`beltsim.solvers.newton.newton` (primal-dual branch)."""
        u, th, lam, fnode = state.u, state.theta, state.lam, state.fnode
        sc = self.disc.scales
        tol, max_it = self.numerics.newton_tol, self.numerics.newton_max_iterations
        asm = self.assemble(u, th, lam, fnode, old, inv_dt, t)
        if not np.any(asm.R):
            self.lu, self.kf = self.factorise(asm.J), asm.k
            return self.lu is not None
        previous = math.inf
        reuse = False
        for it in range(max_it):
            self.newton_iterations += 1
            if not reuse:
                lu = self.factorise(asm.J)
                if lu is None:
                    return False
                self.lu, self.kf = lu, asm.k
            dx = self.lu.solve(-asm.R.reshape(-1)).reshape(-1, 2)
            step = max(np.abs(dx[:, 0]).max() / sc.u, np.abs(dx[:, 1]).max() / sc.theta)
            if not math.isfinite(step):
                return False
            lam0 = lam[self.jc].copy()
            dlam = self.update_multipliers(lam, dx, inv_dt, asm)
            u[1:-1] += dx[:, 0]
            th[1:-1] += dx[:, 1]
            update = max(step, dlam)
            rate = update / previous if it > 0 and previous > 0.0 else 1.0
            converged = (update < tol
                         or (update < ROUNDOFF_FLOOR * tol and update > 0.5 * previous)
                         or (rate < CONTRACTION and rate / (1.0 - rate) * update < tol))
            if converged or update > previous:
                moved = self.release_stuck_ratios(lam, lam0, asm, not converged)
                if moved > 0.0:
                    update = max(update, moved)
                    converged = False
            if converged:
                d = self.disc
                vrel = np.zeros(self.jc.size)  # the forces of the ratios alone
                fnode[:] = reference.friction(vrel, t, d.mesh, d.model, d.drive, lam)[0]
                return True
            asm = self.assemble(u, th, lam, fnode, old, inv_dt, t)
            reuse = it >= 1 and update < CHORD * previous  # the kernel's chord step
            previous = update
        return False

    def filtered_error(self, e, a0):
        """Vectorised :func:`beltsim.solvers.implicit.filtered_error`: J^{-1} T e, T the
        a0 part a0^2 M + a0 C of the last factorised Jacobian."""
        ops = self.ops
        Cf = reference.friction_matrices(self.kf, self.fric, self.n)[1]
        x = e.reshape(-1)
        Te = a0 * a0 * ops.mass * x + a0 * ((ops.damping + Cf) @ x)
        return self.lu.solve(Te).reshape(-1, 2)

    # the scheme -----------------------------------------------------------------
    def advance(self, state, t, t_stop, max_steps=10**9):
        """Vectorised :func:`beltsim.solvers.implicit.advance_bdf2`, same arguments."""
        num = self.numerics
        h_min = num.dt * 1e-7
        h_max = t_stop - t if t_stop > t else num.dt
        tol = num.time_tol
        hist, base = self.hist, self.base
        u, th, lam, ud, td = state.u, state.theta, state.lam, state.ud, state.td
        steps = 0
        h_prev, h_next = self.h_prev, self.h_next
        d = self.disc
        while t < t_stop and steps < max_steps:
            remaining = t_stop - t
            if remaining <= 1e-9 * h_next:
                t = t_stop
                break
            parts = math.ceil(remaining / min(h_next, h_max) * (1.0 - 1e-12))
            h = remaining / parts
            u_n, th_n, ud_n, td_n, lam_n = u.copy(), th.copy(), ud.copy(), td.copy(), lam.copy()
            if h_prev > 0.0:
                r = h / h_prev
                a0 = (1.0 + 2.0 * r) / ((1.0 + r) * h)
                cn = (1.0 + r) * (1.0 + r) / (1.0 + 2.0 * r)
                cp = r * r / (1.0 + 2.0 * r)
                base.u[:] = cn * u_n - cp * hist["u"]
                base.theta[:] = cn * th_n - cp * hist["theta"]
                base.ud[:] = cn * ud_n - cp * hist["ud"]
                base.td[:] = cn * td_n - cp * hist["td"]
                err_const = BDF2_ERROR
            else:
                a0 = 1.0 / h
                base.u[:], base.theta[:] = u_n, th_n
                base.ud[:], base.td[:] = ud_n, td_n
                err_const = 0.5
            u[1:-1] = u_n[1:-1] + h * ud_n[1:-1] + 0.5 * h * h * hist["au"][1:-1]
            th[1:-1] = th_n[1:-1] + h * td_n[1:-1] + 0.5 * h * h * hist["at"][1:-1]
            if h_prev > 0.0:
                jc = self.jc
                lam[jc] = np.minimum(LAM_MAX, np.maximum(
                    -LAM_MAX, lam[jc] + (h / h_prev) * (lam[jc] - hist["lam"][jc])))
            ok = self.newton(state, base, a0, t + h)
            err = 0.0
            finite = True
            if ok:
                ud[:] = a0 * (u - base.u)
                td[:] = a0 * (th - base.theta)
                au_new = a0 * (ud - base.ud)
                at_new = a0 * (td - base.td)
                finite = bool(np.all(np.isfinite(u)) and np.all(np.isfinite(th)))
                e = np.empty((self.n, 2))
                e[:, 0] = err_const * h * h * (au_new[1:-1] - hist["au"][1:-1])
                e[:, 1] = err_const * h * h * (at_new[1:-1] - hist["at"][1:-1])
                e = self.filtered_error(e, a0)
                err = max(np.abs(e[:, 0]).max() / d.scales.u,
                          np.abs(e[:, 1]).max() / d.scales.theta)
                if not math.isfinite(err):
                    err = math.inf
            if ok and not finite:
                state_restore(state, u_n, th_n, ud_n, td_n, lam_n)
                self._store(h_prev, h_next, steps)
                raise NumericalError(f"non-finite displacement or rotation at t = {t:.6g} s",
                                     kind=FailureKind.NON_FINITE, t=t, quantity="u/theta")
            if ok and err <= tol:
                hist["u"][:], hist["theta"][:] = u_n, th_n
                hist["ud"][:], hist["td"][:] = ud_n, td_n
                hist["au"][:], hist["at"][:] = au_new, at_new
                hist["lam"][:] = lam_n
                t = t_stop if parts == 1 else t + h
                steps += 1
                h_prev = h
                p_new = reference.power_terms(state, t, d.mesh, d.model, d.drive, d.loads)
                self.work_done += 0.5 * h * (self.power + p_new)
                self.power = p_new
                factor = MAX_GROWTH if err == 0.0 else SAFETY * (tol / err) ** (1.0 / 3.0)
                h_next = h * min(MAX_GROWTH, max(MIN_SHRINK, factor))
                continue
            self.failed_steps += 1
            state_restore(state, u_n, th_n, ud_n, td_n, lam_n)
            if ok:
                h_next = h * max(MIN_SHRINK, SAFETY * (tol / err) ** (1.0 / 3.0))
            else:
                h_next = h * NEWTON_CUT
            if h_next < h_min:
                self._store(h_prev, h_next, steps)
                raise NumericalError(
                    f"Newton iteration failed at t = {t:.6g} s even with the step cut to "
                    f"dt = {h_next:.3g} s", kind=FailureKind.NEWTON, t=t, quantity="newton")
        self._store(h_prev, h_next, steps)
        return t

    def _store(self, h_prev, h_next, steps):
        self.h_prev, self.h_next = h_prev, h_next
        self.steps += steps

    def work_integrals(self) -> dict:
        return dict(zip(POWER_TERMS, (float(v) for v in self.work_done)))

    def statistics(self) -> dict:
        return {"steps": self.steps, "newton_iterations": self.newton_iterations,
                "rejected_steps": self.failed_steps, "line_search_cuts": 0,
                "factorisations": self.factorisations}

    def checkpoint(self) -> dict:
        return {**super().checkpoint(), "h": np.array([self.h_prev, self.h_next]),
                "power": self.power.copy(), "work_done": self.work_done.copy(),
                "counts": np.array([self.newton_iterations, self.failed_steps,
                                    self.factorisations]),
                **{f"hist_{k}": a.copy() for k, a in self.hist.items()}}

    def restore(self, data: dict) -> None:
        super().restore(data)
        self.h_prev, self.h_next = (float(v) for v in data["h"])
        self.power[:], self.work_done[:] = data["power"], data["work_done"]
        self.newton_iterations, self.failed_steps, self.factorisations = (
            int(v) for v in data["counts"])
        for k, a in self.hist.items():
            a[:] = data[f"hist_{k}"]


def state_restore(state, u, th, ud, td, lam):
    state.u[:], state.theta[:], state.ud[:], state.td[:], state.lam[:] = u, th, ud, td, lam


def port_simulation(scene, grid=None, solver="splu") -> Simulation:
    """beltsim's Simulation of ``scene`` (its checks, trackers, steady test) stepped by
    the port instead of the numba implicit scheme. The scene must use the implicit
    scheme (the default). ``solver``: "splu" (scipy.sparse.linalg.splu, natural order,
    the bench's) or "banded" (LAPACK's dgbtrf/dgbtrs through scipy.linalg.lapack:
    measured 22% faster on 250 elements, 44% on 1000)."""
    sim = Simulation(scene, grid)
    if not isinstance(sim.scheme, ImplicitScheme):
        raise ValueError(f"the port is of the implicit scheme, not {sim.numerics.integrator!r}")
    sim.scheme = PortScheme(sim.disc, solver)
    return sim


def run_port(scene, repeat: int = 1, solver="splu"):
    """The port's run of ``scene`` from rest (the shortest of ``repeat``): a RunResult,
    timed as beltsim's (the run loop, trackers included)."""
    results = [port_simulation(scene, solver=solver).run() for _ in range(repeat)]
    return min(results, key=lambda r: r.wall_time)
