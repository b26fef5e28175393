"""The discrete closed drive: residual and Jacobian of the loop's equations (numba).

Fields u, theta at the nodes of a periodic grid on the loop coordinate x in [0, Lambda);
the belt speed c and the driven pulley's speed omega2 are unknowns of the loop. With
B(c) = b1 - rho c^2, A(c) = a - I c^2 and the lever l (h/2 for the beam, 0 for the string)::

    rho (c_t + u_tt + 2 c u_xt + d u_t) = B u_xx + f
    I (theta_tt + 2 c theta_xt + d theta_t) = A theta_xx - b2 theta + l f
    v_rel = c (1 + N0 / b1) + D u_b / Dt - omega_i R_i,   u_b = u + l theta
    |f| <= mu p,  p = (N - rho c^2) / R_i,  N = N0 + b1 u_x     (on arc i)
    J2 omega2_t = -R2 (integral of f over the driven arc) - M2(t)
    mean of u over the loop = 0 (the gauge that removes the loop's rigid mode)

Space, as the straight belt's model (beltsim.physics.model): linear elements, lumped
mass and shear on node-centred control volumes, the gyroscopic term upwind in flux form
2 rho c (u_t,j - u_t,j-1) (its sum over the loop vanishes on any grid, so the axial rows
add up to the loop's momentum balance rho Lambda c_t = sum F), u_x and D u_b / Dt at the
contact nodes with the one-sided three-point derivative over x_{j-2}, x_{j-1}, x_j, and
the friction of node j on the contact part of its control volume.

Friction: each contact node carries its friction ratio lam_j as an unknown, with the
nodal force F_j = -wf_j S_j lam_j (S_j = mu p_j, or the constant scale p_ref for perfect
adhesion) and one equation per law: exact Coulomb lam = proj(lam + v_rel / v_s) on
[-1, 1] (semi-smooth Newton), adhesion v_rel = 0, regularised laws
v_rel / v_s = g^{-1}(lam) (the primal-dual form).

Time: BDF with the leading coefficient a0: rates are a0 y + (history), so the same
residual serves the steady problem (a0 = 0, no history) and every time step.
:mod:`beltsim.beltdrive.reference` writes the same equations with numpy.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from ..physics.friction import ADHESION, EXACT, law_inverse

#: the laws the drive's kernel knows (friction.LAW_CODES' codes)
DRIVE_LAWS = ("exact", "adhesion", "tanh", "sqrt")


class LoopMesh(NamedTuple):
    """The periodic grid as the kernel reads it (N nodes, N elements)."""

    x: np.ndarray  # node coordinates (N)
    he: np.ndarray  # element j = [x_j, x_j+1] lengths (N)
    hb: np.ndarray  # control-volume lengths (N)
    arc: np.ndarray  # 0 driver, 1 driven, -1 span (N, int)
    wf: np.ndarray  # friction weight (m): the contact part of node j's volume
    sw: np.ndarray  # d/dx at node j: weights of the values at j-2, j-1, j (N, 3)
    lidx: np.ndarray  # index of node j's friction ratio among the unknowns' lam block, -1
    radius: np.ndarray  # R of node j's arc (0 on spans)


class LoopParams(NamedTuple):
    """The drive's coefficients as the kernel reads them."""

    a: float
    b1: float
    b2: float
    rho: float
    I: float
    lever: float
    damping: float
    N0: float
    mu: float  # 0 for perfect adhesion
    J2: float
    R2: float
    law: int  # friction.LAW_CODES
    v_scale: float  # v_reg (regularised laws) or v_aug (exact laws)
    p_ref: float  # the adhesion multiplier's scale (N/m)


class Rates(NamedTuple):
    """The time discretisation of one step: rates are a0 y + history."""

    a0: float
    hu: np.ndarray  # u_t = a0 u + hu
    ht: np.ndarray
    hv: np.ndarray  # u_tt = a0 u_t + hv
    hw: np.ndarray
    hc: float  # c_t = a0 c + hc
    h2: float  # omega2_t = a0 omega2 + h2


def n_unknowns(mesh: LoopMesh) -> int:
    """2 N + M + 2: u, theta at N nodes, M friction ratios, c and omega2."""
    return 2 * len(mesh.x) + int(np.sum(mesh.lidx >= 0)) + 2


@njit(cache=True, inline="always")
def _pressure_scale(j, eps, c, mesh, p):
    """S_j: the friction bound mu p_j (Coulomb) or the adhesion scale p_ref."""
    if p.mu == 0.0:
        return p.p_ref
    return p.mu * (p.N0 + p.b1 * eps - p.rho * c * c) / mesh.radius[j]


@njit(cache=True)
def assemble(y, rates, rim1, load, dist, mesh, p, R, rows, cols, vals, want_jac):
    """Residual R of the loop's equations at the unknowns y and, if want_jac, the
    Jacobian as COO triplets (duplicates add up). Returns the number of triplets.

    rim1: the driver's rim speed omega1 R1 at this time; load: M2 at this time; dist: the
    distributed loads (2N: q_u, q_theta at each node, N/m and N m/m; zeros but in
    manufactured solutions), entering as hbar_j q.
    Rows: axial (2j) and bending (2j + 1) at each node, the friction ratios' equations
    (2N + lidx), the gauge (2N + M, divided by Lambda: metres) and the driven pulley
    (2N + M + 1).
    """
    N = mesh.x.shape[0]
    M = y.shape[0] - 2 * N - 2
    ic, iw = 2 * N + M, 2 * N + M + 1
    c, w2 = y[ic], y[iw]
    a0 = rates.a0
    B = p.b1 - p.rho * c * c
    A = p.a - p.I * c * c
    rho, I_, d, lev = p.rho, p.I, p.damping, p.lever
    cd = a0 * c + rates.hc
    he, hb, sw = mesh.he, mesh.hb, mesh.sw
    lam_total = 0.0
    for j in range(N):
        lam_total += hb[j]
    n = 0
    R[ic] = 0.0
    R[iw] = p.J2 * (a0 * w2 + rates.h2) + load
    if want_jac:
        rows[n], cols[n], vals[n] = iw, iw, p.J2 * a0
        n += 1
    for j in range(N):
        jm = j - 1 if j > 0 else N - 1
        jp = j + 1 if j < N - 1 else 0
        u, th = y[2 * j], y[2 * j + 1]
        um, tm = y[2 * jm], y[2 * jm + 1]
        up, tp = y[2 * jp], y[2 * jp + 1]
        ud = a0 * u + rates.hu[j]
        udm = a0 * um + rates.hu[jm]
        td = a0 * th + rates.ht[j]
        tdm = a0 * tm + rates.ht[jm]
        acc = a0 * ud + rates.hv[j]
        acct = a0 * td + rates.hw[j]
        lap_u = (up - u) / he[j] - (u - um) / he[jm]
        lap_t = (tp - th) / he[j] - (th - tm) / he[jm]
        ru = rho * hb[j] * (cd + acc + d * ud) + 2.0 * rho * c * (ud - udm) - B * lap_u
        rt = (I_ * hb[j] * (acct + d * td) + 2.0 * I_ * c * (td - tdm) - A * lap_t
              + p.b2 * hb[j] * th)
        R[ic] += hb[j] * u / lam_total
        if want_jac:
            ku = rho * hb[j] * (a0 * a0 + d * a0) + 2.0 * rho * c * a0
            kt = I_ * hb[j] * (a0 * a0 + d * a0) + 2.0 * I_ * c * a0
            for r_, c_, v_ in (
                    (2 * j, 2 * j, ku + B * (1.0 / he[j] + 1.0 / he[jm])),
                    (2 * j, 2 * jm, -2.0 * rho * c * a0 - B / he[jm]),
                    (2 * j, 2 * jp, -B / he[j]),
                    (2 * j, ic, rho * hb[j] * a0 + 2.0 * rho * (ud - udm) + 2.0 * rho * c * lap_u),
                    (2 * j + 1, 2 * j + 1, kt + A * (1.0 / he[j] + 1.0 / he[jm]) + p.b2 * hb[j]),
                    (2 * j + 1, 2 * jm + 1, -2.0 * I_ * c * a0 - A / he[jm]),
                    (2 * j + 1, 2 * jp + 1, -A / he[j]),
                    (2 * j + 1, ic, 2.0 * I_ * (td - tdm) + 2.0 * I_ * c * lap_t),
                    (ic, 2 * j, hb[j] / lam_total)):
                rows[n], cols[n], vals[n] = r_, c_, v_
                n += 1
        k = mesh.lidx[j]
        if k >= 0:
            il = 2 * N + k
            lam = y[il]
            # u_x and D u_b / Dt at node j from the upwind three-point stencil
            eps = 0.0
            epsb = 0.0
            for o in range(3):
                q = (j - 2 + o) % N
                eps += sw[j, o] * y[2 * q]
                epsb += sw[j, o] * (y[2 * q] + lev * y[2 * q + 1])
            ubd = ud + lev * td
            driven = mesh.arc[j] == 1
            rim = w2 * p.R2 if driven else rim1
            vrel = c * (1.0 + p.N0 / p.b1) + ubd + c * epsb - rim
            S = _pressure_scale(j, eps, c, mesh, p)
            wf = mesh.wf[j]
            F = -wf * S * lam
            ru -= F
            rt -= lev * F
            if driven:
                R[iw] += p.R2 * F
            # the friction ratio's equation, and its slopes in v_rel and lam
            s = vrel / p.v_scale
            if p.law == ADHESION:
                rl, dl, dv = -s, 0.0, -1.0 / p.v_scale
            elif p.law == EXACT:
                z = lam + s
                if abs(z) < 1.0:
                    rl, dl, dv = -s, 0.0, -1.0 / p.v_scale
                else:
                    rl, dl, dv = lam - math.copysign(1.0, z), 1.0, 0.0
            else:
                gi, dgi = law_inverse(p.law, lam)
                rl, dl, dv = s - gi, -dgi, 1.0 / p.v_scale
            R[il] = rl
            if want_jac:
                # -dF/d(.) enters the axial row, lever times it the bending row, and
                # R2 dF/d(.) the pulley's
                dS_deps = 0.0 if p.mu == 0.0 else p.mu * p.b1 / mesh.radius[j]
                dS_dc = 0.0 if p.mu == 0.0 else -2.0 * p.mu * p.rho * c / mesh.radius[j]
                gl = wf * S  # -dF/dlam
                gc = wf * lam * dS_dc  # -dF/dc
                rows[n], cols[n], vals[n] = 2 * j, il, gl
                rows[n + 1], cols[n + 1], vals[n + 1] = 2 * j + 1, il, lev * gl
                rows[n + 2], cols[n + 2], vals[n + 2] = 2 * j, ic, gc
                rows[n + 3], cols[n + 3], vals[n + 3] = 2 * j + 1, ic, lev * gc
                n += 4
                if driven:
                    rows[n], cols[n], vals[n] = iw, il, -p.R2 * gl
                    rows[n + 1], cols[n + 1], vals[n + 1] = iw, ic, -p.R2 * gc
                    n += 2
                rows[n], cols[n], vals[n] = il, il, dl
                rows[n + 1], cols[n + 1], vals[n + 1] = il, ic, dv * (1.0 + p.N0 / p.b1 + epsb)
                n += 2
                if driven:
                    rows[n], cols[n], vals[n] = il, iw, -dv * p.R2
                    n += 1
                for o in range(3):
                    q = (j - 2 + o) % N
                    gu = wf * lam * dS_deps * sw[j, o]  # -dF/du_q through the pressure
                    dvu = c * sw[j, o] + (a0 if o == 2 else 0.0)  # dv_rel/du_b,q
                    rows[n], cols[n], vals[n] = 2 * j, 2 * q, gu
                    rows[n + 1], cols[n + 1], vals[n + 1] = 2 * j + 1, 2 * q, lev * gu
                    rows[n + 2], cols[n + 2], vals[n + 2] = il, 2 * q, dv * dvu
                    rows[n + 3], cols[n + 3], vals[n + 3] = il, 2 * q + 1, dv * dvu * lev
                    n += 4
                    if driven:
                        rows[n], cols[n], vals[n] = iw, 2 * q, -p.R2 * gu
                        n += 1
        R[2 * j] = ru - hb[j] * dist[2 * j]
        R[2 * j + 1] = rt - hb[j] * dist[2 * j + 1]
    return n


def max_triplets(mesh: LoopMesh) -> int:
    """An upper bound of the Jacobian's triplet count (assemble's buffers)."""
    return 10 * len(mesh.x) + 30 * int(np.sum(mesh.lidx >= 0)) + 1
