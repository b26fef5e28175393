"""Explicit scheme (inertial scenes): staggered leapfrog.

u, theta at whole steps, their local velocities v, w at half steps. Elastic, shear
and damping forces use the state at step n; the gyroscopic term 2 c u_xt is upwind
in space, explicit in time (central in space it grows at any step: the explicit
skew term has |amplification| = sqrt(1 + (g dt)^2)); at steady state it vanishes,
so the steady state is the implicit scheme's. Friction is implicit in the node's
own velocity (one monotone scalar equation per contact node), so its stiffness
f*/v_reg sets no step limit; the transport part of the slip velocity uses step n
and obeys the CFL condition of the waves.

The step is EXPLICIT_SAFETY of the limit found by a von Neumann analysis of the
scheme on the smallest element; a requested step above the limit is refused.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from numba import njit

from ..errors import SceneError
from ..physics.friction import LINEAR, RAMP, law
from ..physics.model import hermite_weights, load_at
from ..problem.drive import mismatch
from .base import Scheme
from .registry import register

EXPLICIT_SAFETY = 0.9  # default explicit step as a fraction of the stability limit
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
    if code == LINEAR:  # closed form
        s = s_pred / (1.0 + kappa)
        return s, s
    if code == RAMP:
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
def advance_explicit(state, t, t_stop, dt, max_steps, mesh, p, drive, loads):
    """Explicit steps from t until t >= t_stop (or max_steps). Returns (t, steps).

    state.ud, state.td hold the local velocities v, w (half steps); state.lam each
    contact node's last friction argument v_rel / v_reg, the warm start of its
    scalar solve. The wave, shear, gyroscopic and damping update is one branch-free
    pass over precomputed coefficients into new velocity buffers; friction then
    corrects the contact nodes.
    """
    u, th, v, w, sfr, fnode = state.u, state.theta, state.ud, state.td, state.lam, state.fnode
    N = u.shape[0] - 1
    B, A, b2 = p.tension_eff, p.bending_eff, p.shear
    rho, I, c, hh = p.mass, p.rotary_inertia, p.speed, p.half_height
    damp, fs, vreg = p.damping, p.friction_scale, p.v_reg
    code, j1, j2, he, hb = p.law, mesh.j1, mesh.j2, mesh.he, mesh.hb
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
        target = mismatch(drive, t + 0.5 * dt)
        for j in range(1, N):
            vn[j] = (keep * v[j] - gl[j] * (v[j] - v[j - 1]) + ar[j] * (u[j + 1] - u[j])
                     - al[j] * (u[j] - u[j - 1]))
            wn[j] = (keep * w[j] - gl[j] * (w[j] - w[j - 1]) + br[j] * (th[j + 1] - th[j])
                     - bl[j] * (th[j] - th[j - 1]) - spring * th[j])
        lk, l0, l1, m0, m1 = hermite_weights(loads.times, t)
        if lk >= 0:  # distributed loads at step n: dt hbar q / (rho hbar)
            for j in range(1, N):
                vn[j] += dt / rho * load_at(loads.qu, loads.dqu, lk, l0, l1, m0, m1, j)
                wn[j] += dt / I * load_at(loads.qt, loads.dqt, lk, l0, l1, m0, m1, j)
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


@register
class ExplicitScheme(Scheme):
    """Staggered leapfrog at EXPLICIT_SAFETY of the von Neumann limit (inertial scenes)."""

    name = "explicit"
    needs_inertia = True

    def __init__(self, disc):
        super().__init__(disc)
        P, num, grid = disc.params, self.numerics, disc.grid
        damping = disc.model.damping
        limit = explicit_stable_dt(P, grid.h_min, damping)
        cfl = grid.h_min / (P.c + max(math.sqrt(P.b1 / P.rho), math.sqrt(P.a / P.I)))
        if limit < 0.05 * cfl:
            raise SceneError(
                f"physics.damping: the explicit scheme is unstable with damping = "
                f"{damping:.6g} 1/s on this grid (its explicit gyroscopic term in the "
                f"rotation equation needs damping); use the implicit integrator")
        requested = disc.scene.numerics.get("dt")
        if requested is not None and requested > limit:
            raise SceneError(
                f"numerics.dt: {requested:.6g} s exceeds the explicit stability limit "
                f"{limit:.6g} s (characteristic speeds c + sqrt(b1/rho), c + sqrt(a/I) on the "
                f"smallest element, {grid.h_min:.3g} m, with the gyroscopic and shear terms)")
        dt = requested if requested is not None else EXPLICIT_SAFETY * limit
        self.numerics = dataclasses.replace(num, dt=dt)

    @property
    def dt(self) -> float:
        return self.numerics.dt

    def _compile(self, state) -> None:
        self.advance(state, 0.0, 0.0, max_steps=0)

    def advance(self, state, t, t_stop, max_steps=10**9):
        d = self.disc
        t, steps = advance_explicit(state, t, t_stop, self.numerics.dt, max_steps, d.mesh,
                                    d.model, d.drive, d.loads)
        self.steps += steps
        return t
