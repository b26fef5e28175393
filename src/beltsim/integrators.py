"""Time integrators (numba kernels on plain arrays).

Implicit: backward Euler on the residual of :mod:`beltsim.model`, solved by
Newton with a backtracking line search on a scaled residual norm. A plain
Newton step cycles on sharp friction (slope f*/v_reg ~ 1e8 or more; NOTES,
trap 2); the line search globalises it. A step whose Newton iteration fails is
retried with a quarter of the time step; after a run of successes the step
grows back towards its nominal value. The same kernel serves inertial and
quasistatic scenes: with rho = I = 0 the residual is algebraic except for the
slip velocity, an index-1 DAE that backward Euler handles as is.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .friction import law
from .model import (I_DUAL, I_J1, I_J2, I_LAW, P_A, P_B, P_B2, P_C, P_DAMP, P_DV, P_FS, P_HH, P_I,
                    P_RHO, P_TRAMP, P_VREG, assemble, block_solve, ramp, update_multipliers)

# status codes of advance_implicit
OK, FAILED, NONFINITE = 0, 1, 2


class Workspace:
    """Preallocated arrays for the implicit kernels (grid of N elements)."""

    def __init__(self, N):
        n = N - 1
        self.R = np.zeros((n, 2))
        self.Lb = np.zeros((n, 2, 2))
        self.Db = np.zeros((n, 2, 2))
        self.Ub = np.zeros((n, 2, 2))
        self.C = np.zeros((n, 2, 2))
        self.dx = np.zeros((n, 2))
        self.uo = np.zeros(N + 1)
        self.tho = np.zeros(N + 1)
        self.udo = np.zeros(N + 1)
        self.tdo = np.zeros(N + 1)
        self.u_try = np.zeros(N + 1)
        self.th_try = np.zeros(N + 1)
        self.fnode = np.zeros(N + 1)
        self.lamo = np.zeros(N + 1)
        self.rl = np.zeros(N + 1)
        self.sg = np.zeros(N + 1)
        self.stats = np.zeros(4)  # newton iterations, failed steps, line-search cuts, last merit

    def arrays(self):
        return (self.R, self.Lb, self.Db, self.Ub, self.C, self.dx, self.uo, self.tho, self.udo,
                self.tdo, self.lamo, self.u_try, self.th_try, self.fnode, self.rl, self.sg,
                self.stats)

    def newton_arrays(self):
        return (self.R, self.Lb, self.Db, self.Ub, self.C, self.dx, self.u_try, self.th_try,
                self.fnode, self.rl, self.sg, self.stats)


# How far above newton_tol a stalled Newton update may be and still count as
# converged: 1e3 * 1e-9 = 1e-6, an order below the discretisation error of the finest
# grid tried (1.4e-5 on 20,000 elements).
ROUNDOFF_FLOOR = 1e3


@njit(cache=True)
def merit(R, scales):
    m = 0.0
    for i in range(R.shape[0]):
        a = R[i, 0] / scales[0]
        b = R[i, 1] / scales[1]
        m += a * a + b * b
    return m


@njit(cache=True)
def newton(u, th, lam, uo, tho, udo, tdo, inv_dt, t, he, hb, prm, iprm, scales, tol, max_it,
           R, Lb, Db, Ub, C, dx, u_try, th_try, fnode, rl, sg, stats):
    """Solve the step's residual for (u, th, lam) in place, starting from their values.

    scales = [force scale, moment scale, u scale, theta scale]. Converged when the
    update is below tol (scaled max norm; absolute for lam), or when it has reached the
    round-off floor: below ROUNDOFF_FLOOR * tol and no longer halving. The floor grows
    with the condition number of the Jacobian, ~ (L / h_min)^2: on 20,000 elements the
    update stalls near 1e-8 and a fixed 1e-9 failed every step. Primal form:
    backtracking line search on the scaled residual norm. Primal-dual form: full
    steps, lam kept inside (-1, 1). Returns True on convergence.
    """
    n = R.shape[0]
    dual = iprm[I_DUAL] != 0
    assemble(u, th, lam, uo, tho, udo, tdo, inv_dt, t, he, hb, prm, iprm, R, Lb, Db, Ub, fnode,
             rl, sg, True)
    m0 = merit(R, scales)
    if m0 == 0.0:
        return True
    previous = np.inf
    for it in range(max_it):
        stats[0] += 1
        for i in range(n):
            R[i, 0] = -R[i, 0]
            R[i, 1] = -R[i, 1]
        if not block_solve(Lb, Db, Ub, R, dx, C):
            return False
        step = 0.0
        for i in range(n):
            s = max(abs(dx[i, 0]) / scales[2], abs(dx[i, 1]) / scales[3])
            if s > step:
                step = s
        if not np.isfinite(step):
            return False
        if dual:
            dlam = update_multipliers(lam, dx, inv_dt, he, prm, iprm, rl, sg)
            for i in range(n):
                u[i + 1] += dx[i, 0]
                th[i + 1] += dx[i, 1]
            assemble(u, th, lam, uo, tho, udo, tdo, inv_dt, t, he, hb, prm, iprm, R, Lb, Db, Ub,
                     fnode, rl, sg, True)
            stats[3] = merit(R, scales)
            update = max(step, dlam)
            if update < tol or (update < ROUNDOFF_FLOOR * tol and update > 0.5 * previous):
                return True
            previous = update
            continue
        alpha = 1.0
        accepted = False
        m = m0
        while alpha >= 1.0 / 4096.0:
            for i in range(n):
                u_try[i + 1] = u[i + 1] + alpha * dx[i, 0]
                th_try[i + 1] = th[i + 1] + alpha * dx[i, 1]
            assemble(u_try, th_try, lam, uo, tho, udo, tdo, inv_dt, t, he, hb, prm, iprm,
                     R, Lb, Db, Ub, fnode, rl, sg, True)
            m = merit(R, scales)
            if m <= (1.0 - 1e-4 * alpha) * m0:
                accepted = True
                break
            alpha *= 0.5
            stats[2] += 1
        if not accepted:
            # no decrease possible: fine if already at round-off, else a failure
            assemble(u, th, lam, uo, tho, udo, tdo, inv_dt, t, he, hb, prm, iprm,
                     R, Lb, Db, Ub, fnode, rl, sg, True)
            stats[3] = m0
            return step < ROUNDOFF_FLOOR * tol
        for i in range(n):
            u[i + 1] = u_try[i + 1]
            th[i + 1] = th_try[i + 1]
        m0 = m
        stats[3] = m
        if alpha * step < tol or m < 1e-30:
            return True
    return False


@njit(cache=True)
def advance_implicit(u, th, lam, ud, td, t, t_stop, dt, dt_nominal, max_steps, he, hb, prm,
                     iprm, scales, tol, max_it, R, Lb, Db, Ub, C, dx, uo, tho, udo, tdo, lamo,
                     u_try, th_try, fnode, rl, sg, stats):
    """Backward-Euler steps from t until t >= t_stop (or max_steps).

    Updates u, th, lam, ud, td in place. Returns (status, t, dt, steps).
    """
    N = u.shape[0] - 1
    steps = 0
    good = 0
    dt_min = dt_nominal * 1e-7
    while t < t_stop and steps < max_steps:
        for j in range(N + 1):
            uo[j] = u[j]
            tho[j] = th[j]
            udo[j] = ud[j]
            tdo[j] = td[j]
            lamo[j] = lam[j]
        h = dt
        inv = 1.0 / h
        # predictor: constant local velocity over the step
        for j in range(1, N):
            u[j] = uo[j] + h * udo[j]
            th[j] = tho[j] + h * tdo[j]
        ok = newton(u, th, lam, uo, tho, udo, tdo, inv, t + h, he, hb, prm, iprm, scales, tol,
                    max_it, R, Lb, Db, Ub, C, dx, u_try, th_try, fnode, rl, sg, stats)
        if ok:
            finite = True
            for j in range(N + 1):
                ud[j] = (u[j] - uo[j]) * inv
                td[j] = (th[j] - tho[j]) * inv
                if not (np.isfinite(u[j]) and np.isfinite(th[j])):
                    finite = False
            if not finite:
                for j in range(N + 1):
                    u[j], th[j], ud[j], td[j], lam[j] = uo[j], tho[j], udo[j], tdo[j], lamo[j]
                return NONFINITE, t, dt, steps
            t += h
            steps += 1
            good += 1
            if good >= 4 and dt < dt_nominal:
                dt = min(2.0 * dt, dt_nominal)
                good = 0
        else:
            stats[1] += 1
            for j in range(N + 1):
                u[j], th[j], ud[j], td[j], lam[j] = uo[j], tho[j], udo[j], tdo[j], lamo[j]
            dt *= 0.25
            good = 0
            if dt < dt_min:
                return FAILED, t, dt, steps
    return OK, t, dt, steps


@njit(cache=True)
def solve_steady(u, th, lam, he, hb, prm, iprm, scales, tol, max_it, uo, tho, udo, tdo,
                 R, Lb, Db, Ub, C, dx, u_try, th_try, fnode, rl, sg, stats, t):
    """Newton on the discrete steady equations (inv_dt = 0) from the given state.

    t sets the surface speed through the ramp (continuation).
    """
    return newton(u, th, lam, uo, tho, udo, tdo, 0.0, t, he, hb, prm, iprm, scales, tol,
                  max_it, R, Lb, Db, Ub, C, dx, u_try, th_try, fnode, rl, sg, stats)


# ---------------------------------------------------------------------------
# Explicit scheme (inertial scenes)
#
# Staggered leapfrog: u, theta at whole steps, their local velocities v, w at half
# steps. Elastic, shear and damping forces use the state at step n; the gyroscopic
# term 2 c u_xt is upwind in space, explicit in time (central in space it grows at
# any step: the explicit skew term has |amplification| = sqrt(1 + (g dt)^2)); at
# steady state it vanishes, so the steady state is the implicit scheme's. Friction
# is implicit in the node's own velocity (one monotone scalar equation per contact
# node), so its stiffness f*/v_reg sets no step limit; the transport part of the
# slip velocity uses step n and obeys the CFL condition of the waves.


SMALL_STEP = 1e-5  # relative Newton step below which the friction solve stops
# fast-math flags that keep NaN and inf semantics (a failing run must still show them)
SAFE_FASTMATH = {"reassoc", "contract", "arcp"}


@njit(cache=True)
def _friction_scalar(code, s_pred, kappa, s0):
    """Solve s + kappa g(s) = s_pred; returns (s, g(s)).

    g is odd, increasing and |g| <= 1 (unless linear), so the root lies in
    [s_pred - kappa, s_pred + kappa]. Newton from s0 (the node's value at the previous
    step, so one or two iterations in a settled state), safeguarded by bisection.
    """
    if code == 0:  # linear law: closed form
        s = s_pred / (1.0 + kappa)
        return s, s
    if code == 3:  # ramp
        if abs(s_pred) <= 1.0 + kappa:
            s = s_pred / (1.0 + kappa)
            return s, s
        return (s_pred - kappa, 1.0) if s_pred > 0 else (s_pred + kappa, -1.0)
    lo, hi = s_pred - kappa, s_pred + kappa
    s = s0 if lo < s0 < hi else s_pred / (1.0 + kappa)
    tol = 1e-13 * (abs(s_pred) + kappa)
    g = 0.0
    for _ in range(80):
        g, gp = law(code, s)
        r = s + kappa * g - s_pred
        ds = -r / (1.0 + kappa * gp)
        if abs(ds) <= SMALL_STEP * (1.0 + abs(s)) and lo < s + ds < hi:
            # g linearised over the step: error g'' ds^2 / 2 < 1e-10, and none at a
            # fixed point; in a settled run this is the first iteration (ds ~ 1e-7)
            return s + ds, g + gp * ds
        if abs(r) <= tol:
            return s, g
        if r > 0.0:
            hi = s
        else:
            lo = s
        s_new = s + ds
        if not (lo < s_new < hi):
            s_new = 0.5 * (lo + hi)
        s = s_new
    return s, g


@njit(cache=True, fastmath=SAFE_FASTMATH)
def advance_explicit(u, th, v, w, sfr, t, t_stop, dt, max_steps, he, hb, prm, iprm, fnode):
    """Explicit steps from t until t >= t_stop (or max_steps). Returns (t, steps).

    v, w: local velocities (half steps); sfr: each contact node's last friction
    argument v_rel / v_reg, the warm start of its scalar solve. The wave, shear,
    gyroscopic and damping update is one branch-free pass over precomputed
    coefficients into new velocity buffers; friction then corrects the contact nodes.
    """
    N = u.shape[0] - 1
    B, A, b2 = prm[P_B], prm[P_A], prm[P_B2]
    rho, I, c, hh = prm[P_RHO], prm[P_I], prm[P_C], prm[P_HH]
    damp, fs, vreg = prm[P_DAMP], prm[P_FS], prm[P_VREG]
    code, j1, j2 = iprm[I_LAW], iprm[I_J1], iprm[I_J2]
    ar = np.zeros(N + 1)
    al = np.zeros(N + 1)
    br = np.zeros(N + 1)
    bl = np.zeros(N + 1)
    gl = np.zeros(N + 1)
    kap = np.zeros(N + 1)
    fm = np.zeros(N + 1)
    fi = np.zeros(N + 1)
    ch = np.zeros(N + 1)
    fh = np.zeros(N + 1)
    ivreg = 1.0 / vreg
    for j in range(1, N):
        m, mi = rho * hb[j], I * hb[j]
        ar[j] = dt * B / (m * he[j])
        al[j] = dt * B / (m * he[j - 1])
        br[j] = dt * A / (mi * he[j])
        bl[j] = dt * A / (mi * he[j - 1])
        gl[j] = 2.0 * c * dt / he[j - 1]  # upwind gyroscopic term
        fm[j] = dt / m
        fi[j] = dt * hh / mi
        kap[j] = dt * he[j - 1] * fs * (1.0 / m + hh * hh / mi) / vreg
        ch[j] = c / he[j - 1]
        fh[j] = he[j - 1] * fs
    keep = 1.0 - dt * damp
    spring = dt * b2 / I
    vn = v.copy()
    wn = w.copy()
    steps = 0
    while t < t_stop and steps < max_steps:
        target = prm[P_DV] * ramp(t + 0.5 * dt, prm[P_TRAMP])
        for j in range(1, N):
            vn[j] = (keep * v[j] - gl[j] * (v[j] - v[j - 1]) + ar[j] * (u[j + 1] - u[j])
                     - al[j] * (u[j] - u[j - 1]))
            wn[j] = (keep * w[j] - gl[j] * (w[j] - w[j - 1]) + br[j] * (th[j + 1] - th[j])
                     - bl[j] * (th[j] - th[j - 1]) - spring * th[j])
        ub_l = u[j1] + hh * th[j1]
        for j in range(j1 + 1, j2 + 1):
            ub = u[j] + hh * th[j]
            s_pred = (vn[j] + hh * wn[j] + ch[j] * (ub - ub_l) - target) * ivreg
            ub_l = ub
            sj, g = _friction_scalar(code, s_pred, kap[j], sfr[j])
            sfr[j] = sj
            F = -fh[j] * g
            fnode[j] = F
            vn[j] += fm[j] * F
            wn[j] += fi[j] * F
        for j in range(1, N):
            u[j] += dt * vn[j]
            th[j] += dt * wn[j]
        v, vn = vn, v
        w, wn = wn, w
        t += dt
        steps += 1
    if steps % 2 == 1:  # the caller's arrays hold the buffers of the previous step
        vn[:] = v
        wn[:] = w
    return t, steps


def explicit_amplification(params, h, dt, damping):
    """Largest von Neumann amplification of the explicit scheme on elements of size h.

    Both fields: the axial one (wave speed sqrt(b1/rho)) and the rotation (sqrt(a/I)
    with the shear term b2/I); the upwind gyroscopic term and the damping included.
    """
    kh = np.linspace(1e-4, np.pi, 2000)
    worst = 0.0
    P = params
    for stiff, inertia, spring in ((P.B, P.rho, 0.0), (P.A, P.I, P.b2)):
        G = 2.0 * P.c * (1.0 - np.exp(-1j * kh)) / h
        w2 = (stiff / inertia) * (2.0 - 2.0 * np.cos(kh)) / h**2 + spring / inertia
        # amplification matrix of (u^n, v^{n-1/2}): [[1 - dt^2 w2, dt a], [-dt w2, a]];
        # its discriminant from p - s = dt (G + d) - dt^2 w2 and q r = -dt^2 w2 a, with
        # no cancellation at small dt (tr^2/4 - det would lose it all)
        a = 1.0 - dt * (G + damping)
        half_tr = 0.5 * (1.0 - dt * dt * w2 + a)
        disc = np.sqrt((0.5 * (dt * (G + damping) - dt * dt * w2)) ** 2 - dt * dt * w2 * a
                       + 0j)
        lam = np.maximum(np.abs(half_tr + disc), np.abs(half_tr - disc))
        worst = max(worst, float(lam.max()))
    return worst


def explicit_stable_dt(params, h_min, damping):
    """The largest step with amplification <= 1 on the smallest element (bisection).

    Bounded by the CFL step h_min / (c + max characteristic speed); returns 0 when no
    step is stable (the rotation equation needs some damping: see the module notes).
    """
    P = params
    speed = P.c + max(np.sqrt(P.b1 / P.rho), np.sqrt(P.a / P.I))
    hi = 2.0 * h_min / speed
    lo = 0.0
    tol = 1e-12
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if explicit_amplification(P, h_min, mid, damping) <= 1.0 + tol:
            lo = mid
        else:
            hi = mid
    return lo
