"""A manufactured steady solution on the loop: smooth periodic u*, theta*, given c*,
omega2*, the regularised law's friction on the arcs, and the distributed loads that make
them exact. The discrete steady state must converge to them at second order."""

import math

import numpy as np
import pytest

from beltsim.beltdrive import reference
from beltsim.beltdrive.discrete import layout_of, loop_mesh, loop_params
from beltsim.beltdrive.scene import DriveScene
from beltsim.beltdrive.solver import make_system, newton, steady_rates
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
    P = scene.params
    g = P.geometry
    mesh = loop_mesh(g, elements)
    lay = layout_of(mesh)
    prm = loop_params(P, "tanh", V_REG)
    S = make_system(mesh, prm, lay, P)
    rim1 = P.omega1 * g.R1
    lam = g.loop_length
    # each node's load is its control volume's average of the continuous source
    lo = mesh.x - 0.5 * np.roll(mesh.he, 1)
    hi = mesh.x + 0.5 * mesh.he
    breaks = np.concatenate([g.bounds - lam, g.bounds, g.bounds + lam])
    for j in range(lay.N):
        S.q[2 * j] = cell_average(lambda z: source(np.mod(z, lam), P, rim1)[0], lo[j], hi[j],
                                  breaks)
        S.q[2 * j + 1] = cell_average(lambda z: source(np.mod(z, lam), P, rim1)[1], lo[j],
                                      hi[j], breaks)
    # the load torque that holds the driven pulley at omega2*: -R2 times the friction's
    # integral over the driven arc
    xg, wg = np.polynomial.legendre.leggauss(40)
    a, b = g.bounds[2], g.bounds[3]
    xs = 0.5 * (b - a) * xg + 0.5 * (a + b)
    M2 = -g.R2 * 0.5 * (b - a) * np.sum(wg * source(xs, P, rim1)[2])
    u, _, _, th, _, _ = fields(mesh.x, lam)
    y = np.zeros(lay.size)
    y[0:2 * lay.N:2] = u
    y[1:2 * lay.N:2] = th
    y[lay.c], y[lay.omega2] = C_STAR, W2_STAR
    # the friction ratios' start: the law at the manufactured state (from lam = 0 the
    # Newton can find another of this nonlinear problem's solutions)
    v = reference.slip_velocity(y, steady_rates(lay.N), rim1, mesh, prm)
    y[2 * lay.N:2 * lay.N + lay.M] = np.tanh(v / V_REG)
    y_star = y.copy()
    newton(S, y, steady_rates(lay.N), rim1, M2, 1e-12, 40)
    err_u = np.max(np.abs(lay.u(y) - lay.u(y_star))) / U
    err_t = np.max(np.abs(lay.theta(y) - lay.theta(y_star))) / THETA
    return (err_u, err_t, abs(y[lay.c] - C_STAR) / C_STAR,
            abs(y[lay.omega2] - W2_STAR) / W2_STAR)


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
