"""The primal-dual Newton iteration's friction ratios: their update and their release.

A regularised law's ratio lam = g(v_rel / v_reg) is an unknown of the primal-dual form
of :func:`beltsim.solvers.newton.newton`, condensed node by node into the rows by
:func:`beltsim.physics.model.assemble` (its residual rl = v_rel / v_reg - g^{-1}(lam)
and slope sg = dlam/ds in the workspace). After each condensed solve the ratios are
updated here; near the bound, where the dual slope vanishes, they are moved by the law
itself (:func:`update_multipliers`) or released (:func:`release_stuck_ratios`).
"""

from __future__ import annotations

from numba import njit

from ..physics.friction import law, law_inverse
from ..physics.model import LAM_MAX, slip_velocity_slope, wrap

# A friction ratio with slope dlam/ds below NEAR_BOUND (|lam| > 0.995 for tanh) that
# differs from the law at its slip velocity by more than LAW_GAP is stuck at the bound;
# while Newton's updates grow, one whose g^-1(lam) lies beyond that slip velocity (over
# v_reg) by more than SLIP_GAP
NEAR_BOUND = 1e-2
LAW_GAP = 1e-3
SLIP_GAP = 0.1


@njit(cache=True)
def update_multipliers(lam, dx, dg, inv_dt, c, mesh, p, w):
    """Newton update of the friction ratios after the condensed solve (dx the rows'
    update, dg the globals'; c the belt speed of the assembly).

    Each lam moves at most 99% of the way to the boundary of (-1, 1) (fraction to
    the boundary) and stays within LAM_MAX of it, so g^{-1}(lam) stays finite. A ratio
    that lands near the bound (slope dlam/ds below NEAR_BOUND) takes the primal value
    instead, the law at the linearised slip velocity, where that lies between it and
    zero: there the dual slope g'(g^{-1}(lam)) is tiny, and a node whose slip slows (a
    slip arc shrinking) would crawl off the bound over many iterations, while the law
    is flat and its linearisation accurate. Both forms have the same solution: this
    changes the iterates, not the answer. Returns the largest change.
    """
    hh = p.half_height
    rl, sg, sw = w.rl, w.sg, mesh.sw
    off = mesh.off
    nn = sw.shape[0]
    big = 0.0
    for j in mesh.cn:
        dvrel = 0.0
        for o in range(3):
            k = wrap(j - 2 + o, nn)
            if k >= off:
                dvrel += (slip_velocity_slope(sw, j, o, c, inv_dt)
                          * (dx[k - off, 0] + hh * mesh.face[j] * dx[k - off, 1]))
        if off == 0:
            dvrel += w.vc[j] * dg[0]
            K = mesh.seg_speed[mesh.seg[j]]
            if K >= 1:
                dvrel -= mesh.seg_radius[mesh.seg[j]] * dg[K]
        dl = sg[j] * (rl[j] + dvrel / p.regularisation)
        if lam[j] + dl >= 1.0:
            dl = 0.99 * (1.0 - lam[j])
        elif lam[j] + dl <= -1.0:
            dl = -0.99 * (1.0 + lam[j])
        new = min(LAM_MAX, max(-LAM_MAX, lam[j] + dl))
        if 1.0 < NEAR_BOUND * law_inverse(p.law, new)[1]:
            # the law at the linearised slip velocity, if on the same side: a ratio sent
            # to the opposite bound cycles (release_stuck_ratios restarts those from 0)
            s = law_inverse(p.law, lam[j])[0] + rl[j] + dvrel / p.regularisation
            gs = law(p.law, s)[0]
            if new * (gs - new) < 0.0 and gs * new > 0.0:
                new = min(LAM_MAX, max(-LAM_MAX, gs))
        dl = new - lam[j]
        lam[j] = new
        if abs(dl) > big:
            big = abs(dl)
    return big


@njit(cache=True, no_cpython_wrapper=True)
def release_stuck_ratios(lam, w, mesh, code, growing):
    """Restart the friction ratios stuck near +-1 against their slip velocity; returns
    the largest change (0: none).

    Near the bound the dual update sg (rl + ...) is tiny (slope sg = 1 - lam^2 for tanh)
    even when the slip velocity has turned: a node leaving the slip at a stick
    transition stays at lam = -1 with v_rel / v_reg = +50, and the updates pass every
    convergence test. At convergence, such a ratio (sg below NEAR_BOUND, off
    g(v_rel / v_reg) of the iterate before the update by more than LAW_GAP) is not
    converged: it restarts from 0, where the slope is largest (from the bound the update
    grows only by a factor 1 + 2 abs(rl) per iteration), and Newton goes on. While the
    updates grow (``growing``: a ratio the fraction-to-the-boundary rule took near the
    bound coming back, some ten iterations), a ratio whose g^-1(lam) lies beyond that
    slip velocity by more than SLIP_GAP is set to the law's value there instead.
    """
    big = 0.0
    for j in mesh.cn:
        if w.sg[j] < NEAR_BOUND and lam[j] * w.rl[j] < 0.0:
            s = w.rl[j] + law_inverse(code, w.lam0[j])[0]
            g = law(code, s)[0]
            if growing:
                if abs(law_inverse(code, lam[j])[0] - s) <= SLIP_GAP:
                    continue
                g = min(LAM_MAX, max(-LAM_MAX, g))
            elif abs(g - lam[j]) > LAW_GAP:
                g = 0.0
            else:
                continue
            big = max(big, abs(g - lam[j]))
            lam[j] = g
    return big
