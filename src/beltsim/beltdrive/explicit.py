"""The explicit scheme of the closed drive (inertial scenes, exact friction laws).

Symplectic Euler on the semi-discrete loop of :mod:`beltsim.beltdrive.model`: the
velocities take the step's forces, the displacements the new velocities. Elastic, shear,
gyroscopic (upwind) and damping forces are explicit in the state at t_n; friction is
implicit in each contact node's own velocity, which is what its slope needs: the force
that would stop the node on the rim, -v_rel* / k with the predicted slip velocity v_rel*
and the node's compliance k = dt (1 / (rho hbar) + l^2 / (I hbar)), is taken where it is
within the bound wf mu p (stick) and the bound with the sign of -v_rel* otherwise
(slip): exact Coulomb, and perfect adhesion without a bound. The driven arc's nodes are
solved together with the driven pulley's new speed (one scalar equation for the arc's
total friction): with the pulley's speed lagging one step, its coupling to the stuck
belt grew into a slow oscillation. The belt speed follows the loop's momentum balance
rho Lambda c_t = sum F (its coupling to the nodes is weak: a change of c and the uniform
velocity correction that keeps the gauge sum hbar u = 0 exact move the material by
(N0 / b1 + eps_b) of it).
The fixed point is the semi-discrete steady state the other schemes solve.

The step is EXPLICIT_SAFETY of the waves' limit h_min / (c_max + sqrt(b1 / rho)) (the
axial waves are the fastest: the bending waves' sqrt(a / I) and the shear's sqrt(b2 / I)
are slower on any grid a user runs).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..physics.friction import ADHESION, EXACT
from ..problem.drive import value

EXPLICIT_SAFETY = 0.9


@njit(cache=True)
def advance(u, th, vu, vt, lam, F, state, t, dt, n_steps, speed, load, mesh, p, loop_length):
    """n_steps explicit steps from t (arrays changed in place). ``state``: [c, omega2,
    c_t] (changed in place). Returns the time reached."""
    N = u.shape[0]
    he, hb, sw, wf = mesh.he, mesh.hb, mesh.sw, mesh.wf
    rho, I_, lev, d = p.rho, p.I, p.lever, p.damping
    fu = np.empty(N)
    ft = np.empty(N)
    vstar = np.zeros(N)
    kk = np.ones(N)
    bound = np.zeros(N)
    for _ in range(n_steps):
        c, w2 = state[0], state[1]
        t_new = t + dt
        rim1 = value(speed, t_new)
        m2 = value(load, t_new)
        B = p.b1 - rho * c * c
        A = p.a - I_ * c * c
        # the forces of the state at t_n, but friction
        for j in range(N):
            jm = j - 1 if j > 0 else N - 1
            jp = j + 1 if j < N - 1 else 0
            lap_u = (u[jp] - u[j]) / he[j] - (u[j] - u[jm]) / he[jm]
            lap_t = (th[jp] - th[j]) / he[j] - (th[j] - th[jm]) / he[jm]
            fu[j] = (B * lap_u - 2.0 * rho * c * (vu[j] - vu[jm]) - d * rho * hb[j] * vu[j])
            ft[j] = (A * lap_t - p.b2 * hb[j] * th[j] - 2.0 * I_ * c * (vt[j] - vt[jm])
                     - d * I_ * hb[j] * vt[j])
        # velocities without friction; the contact nodes' predicted slip velocities
        for j in range(N):
            vu[j] += dt * fu[j] / (rho * hb[j])
            vt[j] += dt * ft[j] / (I_ * hb[j])
            F[j] = 0.0
            if mesh.lidx[j] < 0:
                continue
            eps = 0.0
            epsb = 0.0
            for o in range(3):
                q = (j - 2 + o) % N
                eps += sw[j, o] * u[q]
                epsb += sw[j, o] * (u[q] + lev * th[q])
            rim = w2 * p.R2 if mesh.arc[j] == 1 else rim1
            vstar[j] = c * (1.0 + p.N0 / p.b1 + epsb) + vu[j] + lev * vt[j] - rim
            kk[j] = dt * (1.0 / (rho * hb[j]) + lev * lev / (I_ * hb[j]))
            bound[j] = (math.inf if p.law == ADHESION else
                        wf[j] * p.mu * (p.N0 + p.b1 * eps - rho * c * c) / mesh.radius[j])
        # the driven arc's nodes all see the pulley's new speed, which their friction sets:
        # omega2 R2 falls by alpha (G + M2 / R2), G the arc's total friction; G solves
        # G = sum clamp(-(v*_j + alpha (G + M2 / R2)) / k_j) (monotone: Newton converges)
        alpha = p.R2 * p.R2 * dt / p.J2
        G = 0.0
        for _it in range(50):
            shift = alpha * (G + m2 / p.R2)
            total_f = 0.0
            slope = 0.0
            for j in range(N):
                if mesh.arc[j] != 1:
                    continue
                f = -(vstar[j] + shift) / kk[j]
                if abs(f) <= bound[j]:
                    slope += alpha / kk[j]
                else:
                    f = math.copysign(bound[j], f)
                total_f += f
            step = (G - total_f) / (1.0 + slope)
            G -= step
            if abs(step) <= 1e-13 * (abs(G) + 1e-300) or step == 0.0:
                break
        shift = alpha * (G + m2 / p.R2)
        total = 0.0
        driven = 0.0
        for j in range(N):
            if mesh.lidx[j] < 0:
                continue
            v = vstar[j] + (shift if mesh.arc[j] == 1 else 0.0)
            f_stick = -v / kk[j]
            if abs(f_stick) <= bound[j]:
                F[j] = f_stick
            else:
                F[j] = math.copysign(bound[j], f_stick)
            if p.law == ADHESION:
                lam[j] = -F[j] / (wf[j] * p.p_ref)
            elif bound[j] > 0.0:
                lam[j] = -F[j] / bound[j]
            else:
                lam[j] = 0.0
            vu[j] += dt * F[j] / (rho * hb[j])
            vt[j] += dt * lev * F[j] / (I_ * hb[j])
            total += F[j]
            if mesh.arc[j] == 1:
                driven += F[j]
        # the loop's momentum: c_t = sum F / (rho Lambda), and each node's share of it
        # (the c_t term of its row) keeps sum hbar u_t = 0 (the gauge); it moves the stuck
        # nodes' material by only (N0 / b1 + eps_b) dt c_t, with the rise of c
        cd_new = total / (rho * loop_length)
        for j in range(N):
            vu[j] -= dt * cd_new
            u[j] += dt * vu[j]
            th[j] += dt * vt[j]
        state[0] = c + dt * cd_new
        state[1] = w2 + dt * (-p.R2 * driven - m2) / p.J2
        state[2] = cd_new
        t = t_new
    return t


def stable_step(mesh, P, rim_max: float) -> float:
    """EXPLICIT_SAFETY of the axial waves' limit on the smallest element (s)."""
    return EXPLICIT_SAFETY * float(np.min(mesh.he)) / (rim_max + math.sqrt(P.b1 / P.rho))


def explicit_law_ok(law_code: int) -> bool:
    """Whether the explicit scheme takes the law (the exact ones)."""
    return law_code in (EXACT, ADHESION)
