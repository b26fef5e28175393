"""A manufactured steady solution on the loop: smooth periodic u*, theta*, given c*,
omega2*, the regularised law's friction on the arcs, and the distributed loads that make
them exact. The discrete steady state must converge to them at second order."""

import math

import numpy as np
import pytest

from beltsim.beltdrive.scene import DriveScene
from beltsim.physics.discrete import Loads
from beltsim.problem.drive import Drive
from beltsim.solvers import LoopDiscretisation
from beltsim.solvers.newton import NewtonSettings, Workspace, newton
from helpers import scene_path

U, THETA = 1.0e-3, 2.0e-3  # amplitudes (m, rad): strains ~3e-3, as N0 / b1
C_STAR, W2_STAR = 11.9, 74.0
V_REG = 0.05  # m/s: a smooth law, so the friction's own scale is resolved by every grid


def fields(x, lam):
    """u*, u*', u*'', theta*, theta*', theta*'' at x on a loop of length lam."""
    k = 2.0 * math.pi / lam
    u = U * (np.sin(k * x) + 0.5 * np.cos(2 * k * x + 0.3))
    du = U * k * (np.cos(k * x) - np.sin(2 * k * x + 0.3))
    ddu = -U * k * k * (np.sin(k * x) + 2.0 * np.cos(2 * k * x + 0.3))
    th = THETA * np.sin(3 * k * x + 0.1)
    dth = 3 * k * THETA * np.cos(3 * k * x + 0.1)
    ddth = -9 * k * k * THETA * np.sin(3 * k * x + 0.1)
    return u, du, ddu, th, dth, ddth


def source(x, P, rim1):
    """(q_u, q_theta, f) of the continuous steady equations at x (0 friction off the arcs)."""
    g = P.geometry
    lam = g.loop_length
    u, du, ddu, th, dth, ddth = fields(x, lam)
    seg = g.segment_of(x)
    R = np.where(seg == 0, g.R1, g.R2)
    rim = np.where(seg == 0, rim1, W2_STAR * g.R2)
    vrel = C_STAR * (1 + P.N0 / P.b1 + du + P.lever * dth) - rim
    p = (P.N0 + P.b1 * du - P.rho * C_STAR**2) / R
    f = np.where(seg % 2 == 0, -P.mu * p * np.tanh(vrel / V_REG), 0.0)
    B = P.b1 - P.rho * C_STAR**2
    A = P.a - P.I * C_STAR**2
    return -B * ddu - f, -A * ddth + P.b2 * th - P.lever * f, f


def cell_average(fun, a, b, pieces):
    """(1 / (b - a)) times the integral of fun over [a, b] (Gauss-Legendre on each smooth
    piece between the breakpoints inside)."""
    xg, wg = np.polynomial.legendre.leggauss(12)
    cuts = np.unique(np.concatenate([[a, b], pieces[(pieces > a) & (pieces < b)]]))
    total = 0.0
    for lo, hi in zip(cuts[:-1], cuts[1:]):
        xs = 0.5 * (hi - lo) * xg + 0.5 * (hi + lo)
        total += 0.5 * (hi - lo) * np.sum(wg * fun(xs))
    return total / (b - a)


def manufactured_error(scene, elements):
    """The discrete steady state of the one model's loop layout, with the manufactured
    loads, against the manufactured fields and speeds (relative max errors)."""
    P = scene.params
    g = P.geometry
    d = LoopDiscretisation(scene.with_overrides({
        "numerics.elements": elements, "numerics.friction_law": "tanh",
        "numerics.regularisation": V_REG}))
    mesh, x = d.mesh, d.grid.x
    rim1 = P.omega1 * g.R1
    lam = g.loop_length
    N = len(x)
    # each node's load is its control volume's average of the continuous source
    lo = x - 0.5 * np.roll(mesh.he, 1)
    hi = x + 0.5 * mesh.he
    breaks = np.concatenate([g.bounds - lam, g.bounds, g.bounds + lam])
    q = np.zeros((2, N))
    for j in range(N):
        for k in range(2):
            q[k, j] = cell_average(lambda z, k=k: source(np.mod(z, lam), P, rim1)[k],
                                   lo[j], hi[j], breaks)
    zero = np.zeros((1, N))
    loads = Loads(np.zeros(1), q[0][None, :], q[1][None, :], zero, zero)
    # the load torque that holds the driven pulley at omega2*: -R2 times the friction's
    # integral over the driven arc
    xg, wg = np.polynomial.legendre.leggauss(40)
    a, b = g.bounds[2], g.bounds[3]
    xs = 0.5 * (b - a) * xg + 0.5 * (a + b)
    M2 = -g.R2 * 0.5 * (b - a) * np.sum(wg * source(xs, P, rim1)[2])
    u, du, _, th, dth, _ = fields(x, lam)
    state = d.new_state()
    state.u[:], state.theta[:] = u, th
    state.g[:] = C_STAR, W2_STAR
    # the friction ratios' start: the law at the manufactured state (from lam = 0 the
    # Newton can find another of this nonlinear problem's solutions)
    cn = mesh.cn
    rim = np.where(mesh.seg[cn] == 0, rim1, W2_STAR * g.R2)
    v = C_STAR * (1 + P.N0 / P.b1 + du[cn] + P.lever * dth[cn]) - rim
    # inside (-1, 1): the law's inverse is singular on the bound
    state.lam[cn] = np.clip(np.tanh(v / V_REG), -1.0 + 1e-12, 1.0 - 1e-12)
    work = Workspace.allocate(N, False, True, 2)
    assert newton(state, d.new_state(), 0.0, 0.0, mesh, d.model, Drive.constant(rim1, (0.0, M2)),
                  loads, d.scales, NewtonSettings(1e-12, 40), work)
    return (np.max(np.abs(state.u - u)) / U, np.max(np.abs(state.theta - th)) / THETA,
            abs(state.g[0] - C_STAR) / C_STAR, abs(state.g[1] - W2_STAR) / W2_STAR)


@pytest.mark.verification
@pytest.mark.parametrize("model", ["beam", "string"])
def test_manufactured_solution_converges_at_second_order(model):
    scene = DriveScene.load(scene_path("drive_flat")).with_overrides(
        [("physics.model", model)])
    # from 400 elements: theta's boundary layers (sqrt(A / b2) = 2 mm for the beam) are
    # then resolved
    ladder = (400, 800, 1600, 3200)
    errs = np.array([manufactured_error(scene, n) for n in ladder])
    h = 1.0 / np.array(ladder)
    names = ("u", "theta", "c", "omega2")
    for k, name in enumerate(names):
        order = np.polyfit(np.log(h), np.log(errs[:, k]), 1)[0]
        assert order >= 1.8, (name, errs[:, k], order)
