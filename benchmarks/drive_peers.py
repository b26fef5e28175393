"""Generic peers of the closed drive's solvers: the same equations, solved by generic tools.

Every peer works on the drive's own discretisation, on the same grid: the residual and the
Jacobian of :mod:`beltsim.beltdrive.reference` (numpy and scipy.sparse, the twin of the
numba kernel :func:`beltsim.beltdrive.model.assemble`), the same coefficients, layout and
start.

* :class:`ReferenceSystem` stands in for :class:`beltsim.beltdrive.solver.System`: the
  residual by numpy, the Jacobian by scipy.sparse, the Newton update by
  ``scipy.sparse.linalg.splu`` (or ``spsolve``). Inside :func:`generic_pieces`,
  :func:`beltsim.beltdrive.run.simulate` and ``solve_steady`` run on it: the same
  semi-smooth Newton, the same BDF2 steps and step control, the same steady test; only
  the pieces are generic (:func:`run_generic_transient`, :func:`run_generic_steady`).
* :func:`run_root_peer`: ``scipy.optimize.root`` on the scaled steady residual from the
  same start (the string's analytic state): "hybr" (MINPACK's Powell hybrid) and "lm"
  (MINPACK's Levenberg-Marquardt) with the reference Jacobian, densified, or "krylov"
  (Newton-Krylov, Jacobian-free).
* :class:`DriveODE` and :func:`run_ode_peer`: ``scipy.integrate``'s BDF or Radau from rest
  on the method-of-lines ODE of the same semi-discretisation, which exists for a
  regularised law only: the friction ratios are then explicit, lam = g(v_rel / v_reg), and
  the gauge (mean of u = 0) is kept by taking c_t from the loop's momentum balance, so
  that the accelerations satisfy the gauge's second derivative. Its Jacobian
  (:func:`ode_jacobian`, from the reference Jacobian) is dense: c_t, a sum over the
  contact nodes, enters every axial acceleration, a rank-one coupling that scipy's
  integrators cannot keep apart from the sparse rest (our Newton keeps c in a border).

Wall times are of the whole call; the peers that run through our run functions also give
the run's own (``solve_wall_time``), as ours do.
"""

from __future__ import annotations

import dataclasses
import time
from contextlib import contextmanager
from typing import NamedTuple
from unittest import mock

import numpy as np

from beltsim.beltdrive import reference, run
from beltsim.beltdrive.discrete import (
    layout_of,
    loop_mesh,
    loop_params,
    residual_scale,
    string_guess,
    update_scale,
)
from beltsim.beltdrive.model import Rates
from beltsim.beltdrive.solver import steady_rates
from beltsim.errors import FailureKind, NumericalError
from beltsim.physics.friction import law_numpy
from beltsim.problem.drive import value

#: The summary keys compared between a peer's final state and ours.
COMPARED = ("tight_tension", "slack_tension", "belt_speed", "driven_speed", "speed_ratio",
            "driver_torque")
#: A peer reached "the same state" when every COMPARED figure is within this of the
#: reference's, relative to its size. Our own runs stop (steady test 1e-7 per transit)
#: ~1e-8 from the discrete steady state in these figures, 2e-6 in the speed loss.
SAME_STATE = 1e-6


class PeerResult(NamedTuple):
    name: str
    wall_time: float  # s, the whole call
    converged: bool  # the peer's own test passed (steady state or root found)
    reason: str  # "converged", or why not
    summary: dict | None  # the drive's summary of the peer's final state
    statistics: dict  # iterations, steps, evaluations as the peer counts them
    #: s, the run's own wall time where it goes through our run functions (without their
    #: setup and the analytic solution); None: the whole call
    solve_wall_time: float | None = None


class ReferenceSystem:
    """:class:`beltsim.beltdrive.solver.System`'s interface on generic pieces: the residual
    and the Jacobian of :mod:`beltsim.beltdrive.reference`, the Newton update by
    ``scipy.sparse.linalg.splu`` (``linear="splu"``, COLAMD ordering) or ``spsolve``."""

    def __init__(self, mesh, params, lay, P, linear: str = "splu"):
        if linear not in ("splu", "spsolve"):
            raise ValueError(f"linear: must be 'splu' or 'spsolve', got {linear!r}")
        self.mesh, self.params, self.lay = mesh, params, lay
        self.yscale = update_scale(lay, P)
        self.rscale = residual_scale(lay, mesh, P)
        self.linear = linear
        self.counts = {"residuals": 0, "jacobians": 0}
        self.linear_time = 0.0  # s in the sparse LU and its solves

    def residual(self, y, rates, rim1, load):
        self.counts["residuals"] += 1
        return reference.residual(y, rates, rim1, load, self.mesh, self.params)

    def update(self, y, rates, rim1, load):
        """(R(y), the Newton update -J^{-1} R)."""
        from scipy.sparse.linalg import splu, spsolve

        R = self.residual(y, rates, rim1, load)
        J = reference.jacobian(y, rates, rim1, load, self.mesh, self.params).tocsc()
        self.counts["jacobians"] += 1
        start = time.perf_counter()
        try:
            dy = splu(J).solve(-R) if self.linear == "splu" else spsolve(J, -R)
        except RuntimeError as exc:  # splu: "Factor is exactly singular"
            raise NumericalError(f"singular Jacobian in the generic Newton update ({exc})",
                                 kind=FailureKind.NEWTON) from None
        finally:
            self.linear_time += time.perf_counter() - start
        return R, dy


@contextmanager
def generic_pieces(linear: str = "splu"):
    """Within it, the drive's runs build a :class:`ReferenceSystem` instead of the numba
    system; yields the list of the systems built (their counters)."""
    built = []

    def make(mesh, params, lay, P):
        built.append(ReferenceSystem(mesh, params, lay, P, linear))
        return built[-1]

    with mock.patch.object(run, "make_system", make):
        yield built


def _counts(built) -> dict:
    if not built or not any(s.counts["jacobians"] for s in built):
        # a run that built its system elsewhere would time our kernels as the peer's
        raise RuntimeError("the drive's run did not use the generic pieces (it no longer "
                           "builds its system through beltsim.beltdrive.run.make_system)")
    return {"residual_evaluations": sum(s.counts["residuals"] for s in built),
            "jacobian_evaluations": sum(s.counts["jacobians"] for s in built),
            "linear_solve_time": sum(s.linear_time for s in built)}


def run_generic_transient(scene, elements=None, linear="splu") -> PeerResult:
    """The drive's own BDF2 run from rest (:func:`beltsim.beltdrive.run.simulate`) on the
    generic pieces."""
    start = time.perf_counter()
    with generic_pieces(linear) as built:
        res = run.simulate(scene, elements)
    wall = time.perf_counter() - start
    stats = dict(res.statistics, **_counts(built))
    return PeerResult(f"BDF2 steps, numpy residual, scipy.sparse Jacobian, {linear}", wall,
                      res.converged, res.reason or res.status.value, res.summary, stats,
                      res.wall_time)


def run_generic_steady(scene, elements=None, linear="spsolve") -> PeerResult:
    """The drive's steady Newton (:func:`beltsim.beltdrive.run.solve_steady`, from the
    string's state) on the generic pieces."""
    start = time.perf_counter()
    try:
        with generic_pieces(linear) as built:
            res = run.solve_steady(scene, elements)
    except NumericalError as exc:
        return PeerResult(f"Newton, numpy residual, scipy.sparse Jacobian, {linear}",
                          time.perf_counter() - start, False, str(exc), None, {})
    wall = time.perf_counter() - start
    stats = dict(res.statistics, **_counts(built))
    return PeerResult(f"Newton, numpy residual, scipy.sparse Jacobian, {linear}", wall,
                      True, "converged", res.summary, stats, res.wall_time)


class _WallCap(Exception):
    """Raised from inside a scipy call to stop it at the wall-time cap."""


def _discretised(scene, elements=None, law=None):
    """(numerics, params, mesh, layout, kernel params) of a scene, as the drive's runs
    build them; ``law`` overrides the friction law."""
    num = run.resolve(scene, elements)
    if law is not None and law != num.friction_law:
        reg = num.regularisation
        if reg is None:
            reg = 0.1 * run.creep_speed(scene.params)
        num = dataclasses.replace(num, friction_law=law, regularisation=reg)
    P = scene.params
    mesh = loop_mesh(P.geometry, num.elements)
    lay = layout_of(mesh)
    return num, P, mesh, lay, loop_params(P, num.friction_law, num.regularisation)


def run_root_peer(scene, method: str = "hybr", elements=None, max_wall: float = 300.0,
                  tol: float | None = None, options: dict | None = None) -> PeerResult:
    """``scipy.optimize.root`` on the steady residual (rows scaled as the drive's Newton
    scales them) from the string's analytic state, the drive's own start.

    "hybr" and "lm" get the reference Jacobian (dense, as MINPACK takes it); "krylov" is
    Jacobian-free. Success is scipy's own test; the peer is stopped at ``max_wall``.
    ``tol`` defaults to the drive's ``newton_tol``; ``options`` are added to scipy's.
    """
    from scipy.optimize import root

    start = time.perf_counter()
    num, P, mesh, lay, prm = _discretised(scene, elements)
    rs = residual_scale(lay, mesh, P)
    rates = steady_rates(lay.N)
    rim1 = P.omega1 * P.geometry.R1
    y0 = string_guess(run.solve_string(P), mesh, lay)
    counts = {"residual_evaluations": 0, "jacobian_evaluations": 0}

    def fun(y):
        if time.perf_counter() - start > max_wall:
            raise _WallCap
        counts["residual_evaluations"] += 1
        return reference.residual(y, rates, rim1, P.M2, mesh, prm) / rs

    def jac(y):
        if time.perf_counter() - start > max_wall:
            raise _WallCap
        counts["jacobian_evaluations"] += 1
        J = reference.jacobian(y, rates, rim1, P.M2, mesh, prm)
        return (J.multiply(1.0 / rs[:, None])).toarray()

    tol = num.newton_tol if tol is None else tol
    opts = {"hybr": {"xtol": tol}, "lm": {"xtol": tol},
            "krylov": {"fatol": tol * 1e-3, "maxiter": 500}}[method] | (options or {})
    name = {"hybr": "scipy.optimize.root hybr (MINPACK), dense reference Jacobian",
            "lm": "scipy.optimize.root lm (MINPACK), dense reference Jacobian",
            "krylov": "scipy.optimize.root krylov (Newton-LGMRES, no preconditioner)"}[method]
    try:
        sol = root(fun, y0, method=method, jac=None if method == "krylov" else jac,
                   options=opts)
    except _WallCap:
        return PeerResult(name, time.perf_counter() - start, False,
                          f"stopped at the {max_wall:g} s wall-time cap", None, counts)
    wall = time.perf_counter() - start
    y = sol.x
    scaled = np.abs(reference.residual(y, rates, rim1, P.M2, mesh, prm) / rs).max()
    counts["scaled_residual"] = float(scaled)
    summary = None
    if np.all(np.isfinite(y)):
        flds = run.fields_of(y, lay, mesh, P, prm, rim1)
        summary = run.summary_of(y, flds, lay, mesh, P, P.M2, P.omega1, rim1)
    reason = "converged" if sol.success else f"not converged: {' '.join(sol.message.split())}"
    return PeerResult(name, wall, bool(sol.success), reason, summary, counts)


class DriveODE:
    """The drive's semi-discretisation as an ODE z' = f(t, z), for a regularised law.

    z = (u, theta, c, omega2, u_t, theta_t): u and theta at the N nodes, their rates.
    The reference residual with a0 = 0 and the rates given as history is the forces'
    imbalance at zero acceleration, R0; the accelerations then solve
    rho hb (c_t + u_tt) = -R0 (axial), I hb theta_tt = -R0 (bending), J2 omega2_t = -R0
    (pulley), with sum(hb u_tt) = 0 (the gauge, twice differentiated), which gives
    c_t = -sum(R0 axial) / (rho Lambda). The friction ratios are lam = g(v_rel / v_reg).
    """

    def __init__(self, scene, elements=None, law="tanh"):
        if law not in ("tanh", "sqrt"):
            raise ValueError(f"law: the ODE form needs a regularised law (tanh or sqrt), "
                             f"got {law!r}")
        P = scene.params
        if not P.inertia or P.J2 <= 0.0:
            raise ValueError("the ODE form needs an inertial belt and driven_inertia > 0")
        self.num, self.P, self.mesh, self.lay, self.prm = _discretised(scene, elements, law)
        self.speed, self.load = run.profiles(scene, self.num.ramp_time)
        self.N = N = self.lay.N
        self.size = 4 * N + 2
        self.y = np.zeros(self.lay.size)
        self._zero = np.zeros(N)
        self._mass_u = P.rho * self.mesh.hb
        self._mass_t = P.I * self.mesh.hb
        self.evaluations = 0

    def state(self, z):
        """(y in the kernel's layout with lam = g(s), the Rates of a0 = 0, rim1, load)."""
        N, lay = self.N, self.lay
        y = self.y
        y[0:2 * N:2], y[1:2 * N:2] = z[:N], z[N:2 * N]
        y[lay.c], y[lay.omega2] = z[2 * N], z[2 * N + 1]
        zero = self._zero
        return y, Rates(0.0, z[2 * N + 2:3 * N + 2], z[3 * N + 2:], zero, zero, 0.0, 0.0)

    def rhs(self, t, z):
        self.evaluations += 1
        N, lay, prm = self.N, self.lay, self.prm
        rim1, load = value(self.speed, t), value(self.load, t)
        y, rates = self.state(z)
        s = reference.slip_velocity(y, rates, rim1, self.mesh, prm) / prm.v_scale
        y[2 * N:2 * N + lay.M] = law_numpy(prm.law, s)[0]
        with np.errstate(divide="ignore", invalid="ignore"):
            # a saturated ratio (|lam| = 1 to round-off) makes its own row infinite only
            R0 = reference.residual(y, rates, rim1, load, self.mesh, prm)
        axial, bending = R0[0:2 * N:2], R0[1:2 * N:2]
        ct = -axial.sum() / self._mass_u.sum()
        out = np.empty(self.size)
        out[:2 * N] = z[2 * N + 2:]
        out[2 * N] = ct
        out[2 * N + 1] = -R0[lay.omega2] / self.P.J2
        out[2 * N + 2:3 * N + 2] = -axial / self._mass_u - ct
        out[3 * N + 2:] = -bending / self._mass_t
        return out

    def scale(self) -> np.ndarray:
        """Magnitude of each unknown (the drive's update scales; the rates' are the rim
        speed times the strain for u_t and over the loop length for theta_t)."""
        s = update_scale(self.lay, self.P)
        N, lay = self.N, self.lay
        rim = self.P.omega1 * self.P.geometry.R1
        strain = self.P.N0 / self.P.b1
        return np.concatenate([np.full(N, s[0]), np.full(N, s[1]), [s[lay.c], s[lay.omega2]],
                               np.full(N, rim * strain),
                               np.full(N, rim * strain / self.P.geometry.loop_length)])

    def summary(self, t, z) -> dict:
        rim1, load = value(self.speed, t), value(self.load, t)
        y, rates = self.state(z)
        s = reference.slip_velocity(y, rates, rim1, self.mesh, self.prm) / self.prm.v_scale
        y = y.copy()
        y[2 * self.N:2 * self.N + self.lay.M] = law_numpy(self.prm.law, s)[0]
        flds = run.fields_of(y, self.lay, self.mesh, self.P, self.prm, rim1,
                             (rates.hu, rates.ht))
        return run.summary_of(y, flds, self.lay, self.mesh, self.P, load,
                              rim1 / self.P.geometry.R1, rim1)


def _rates_at(a0, z, ode):
    """Rates of leading coefficient a0 whose rates are the ODE state's (u_t, theta_t given,
    every other rate zero): the residual is then R0 whatever a0, and its Jacobian
    J0 + a0 J1 + a0^2 J2, J1 the slopes in the first rates."""
    N = ode.N
    u, th = z[:N], z[N:2 * N]
    ut, tt = z[2 * N + 2:3 * N + 2], z[3 * N + 2:]
    return Rates(a0, ut - a0 * u, tt - a0 * th, -a0 * ut, -a0 * tt, -a0 * z[2 * N],
                 -a0 * z[2 * N + 1])


def ode_jacobian(ode, t, z) -> np.ndarray:
    """df/dz (dense) from the reference Jacobian.

    The positions' slopes are the Jacobian at a0 = 0, the rates' its a0-linear part
    (J(a) - J(-a)) / 2a (exact: the Jacobian is quadratic in a0 at fixed rates); the
    ratios lam = g(s) enter by the chain rule, ds/dz being their rows (r = s - g^{-1}(lam)).
    The rows are dense where c_t, the loop's momentum balance, enters every axial
    acceleration: a generic solver cannot keep this rank-one coupling apart.
    """
    N, lay, mesh, prm = ode.N, ode.lay, ode.mesh, ode.prm
    rim1, load = value(ode.speed, t), value(ode.load, t)
    y, _ = ode.state(z)
    s = reference.slip_velocity(y, _rates_at(0.0, z, ode), rim1, mesh, prm) / prm.v_scale
    lam, dlam = law_numpy(prm.law, s)
    y = y.copy()
    y[2 * N:2 * N + lay.M] = lam
    a = 1.0
    with np.errstate(divide="ignore", invalid="ignore"):  # saturated ratios' own entries
        J0, Jp, Jm = (reference.jacobian(y, _rates_at(b, z, ode), rim1, load, mesh, prm)
                      .tocsr() for b in (0.0, a, -a))
    J1 = (Jp - Jm) / (2.0 * a)
    pos = np.concatenate([np.arange(0, 2 * N, 2), np.arange(1, 2 * N, 2), [lay.c, lay.omega2]])
    rate = pos[:2 * N]
    lam_idx = np.arange(2 * N, 2 * N + lay.M)
    # d(R rows)/dz at fixed lam, and the ratios' ds/dz, over z's columns
    rows = np.concatenate([pos, lam_idx])
    Jz = np.hstack([J0[rows][:, pos].toarray(), J1[rows][:, rate].toarray()])
    dRz, dsz = Jz[:2 * N + 2], Jz[2 * N + 2:]
    dR = dRz + J0[pos][:, lam_idx].toarray() @ (dlam[:, None] * dsz)
    axial, bending, pulley = dR[:N], dR[N:2 * N], dR[2 * N + 1]
    dct = -axial.sum(axis=0) / ode._mass_u.sum()
    out = np.zeros((ode.size, ode.size))
    out[np.arange(2 * N), 2 * N + 2 + np.arange(2 * N)] = 1.0
    out[2 * N] = dct
    out[2 * N + 1] = -pulley / ode.P.J2
    out[2 * N + 2:3 * N + 2] = -axial / ode._mass_u[:, None] - dct[None, :]
    out[3 * N + 2:] = -bending / ode._mass_t[:, None]
    return out


def run_ode_peer(scene, method: str = "BDF", rtol: float = 1e-6, elements=None,
                 law: str = "tanh", max_wall: float = 600.0) -> PeerResult:
    """scipy's BDF or Radau (the classes behind ``solve_ivp``) from rest on
    :class:`DriveODE`, stepped by hand only so that the drive's steady test can stop
    them: after the ramps, (|c_t| / rim, |omega2_t| R2 / rim, max |u_t| / (rim N0 / b1))
    times the transit time below ``numerics.steady_tol``, as
    :func:`beltsim.beltdrive.run.simulate` tests. The Jacobian is :func:`ode_jacobian`
    (dense); atol is rtol times each unknown's scale (:meth:`DriveODE.scale`).
    """
    from scipy.integrate import BDF, Radau

    start = time.perf_counter()
    ode = DriveODE(scene, elements, law)
    num, P, N = ode.num, ode.P, ode.N
    settle = max(num.ramp_time, run._last_table_time(scene))
    transit = run.transit_time(P)
    strain = P.N0 / P.b1
    cls = {"BDF": BDF, "Radau": Radau}[method]
    solver = cls(ode.rhs, 0.0, np.zeros(ode.size), num.t_end, rtol=rtol,
                 atol=rtol * ode.scale(), jac=lambda t, z: ode_jacobian(ode, t, z))
    converged, reason, steps = False, "not steady by t_end", 0
    while solver.status == "running":
        if time.perf_counter() - start > max_wall:
            reason = f"stopped at the {max_wall:g} s wall-time cap at t = {solver.t:.4g} s"
            break
        solver.step()
        steps += 1
        if solver.status == "failed":
            reason = f"solver failed at t = {solver.t:.4g} s"
            break
        if solver.t < settle:
            continue
        rim1 = value(ode.speed, solver.t)
        dz = ode.rhs(solver.t, solver.y)
        rate = max(abs(dz[2 * N]) / rim1, abs(dz[2 * N + 1]) * P.geometry.R2 / rim1,
                   float(np.abs(solver.y[2 * N + 2:3 * N + 2]).max()) / (rim1 * strain))
        if rate * transit < num.steady_tol:
            converged, reason = True, "converged"
            break
    summary = ode.summary(solver.t, solver.y)
    wall = time.perf_counter() - start
    name = f"solve_ivp {method} (rtol {rtol:g}), {law} law, reference Jacobian (dense)"
    stats = {"steps": steps, "simulated_time": float(solver.t), "rhs_evaluations": solver.nfev,
             "jacobian_evaluations": solver.njev, "factorisations": solver.nlu,
             "ode_rhs_calls": ode.evaluations}
    return PeerResult(name, wall, converged, reason, summary, stats)


def difference(summary: dict | None, reference: dict) -> float | None:
    """The largest relative difference of the COMPARED figures between a summary and the
    reference's, each relative to its own size; None without a summary."""
    if summary is None:
        return None
    out = 0.0
    for key in COMPARED:
        a, b = float(summary[key]), float(reference[key])
        out = max(out, abs(a - b) / abs(b) if b != 0.0 else abs(a - b))
    return out


def speed_loss_difference(summary: dict | None, reference: dict) -> float | None:
    """The relative difference of the speed loss 1 - speed_ratio (the figure most
    sensitive to where a run stops: a small difference of two numbers near 1)."""
    if summary is None:
        return None
    loss = 1.0 - float(reference["speed_ratio"])
    return abs(float(summary["speed_ratio"]) - float(reference["speed_ratio"])) / abs(loss)
