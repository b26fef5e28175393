"""Steady state of the closed drive: the shear-deformable beam, solved exactly.

Two pulleys first: the loop x in [0, Lambda) runs driver arc, slack span, driven arc,
tight span. At steady
state, with B = b1 - rho c^2, A = a - I c^2 and the friction's lever l (h/2 for the beam,
0 for the string)::

    B eps' + f = 0,     A theta'' - b2 theta + l f = 0,     N = N0 + b1 eps.

On arc i (rim speed omega_i R_i) the bottom fibre slides at
v_rel = c (1 + N0/b1 + eps + l theta') - omega_i R_i against the contact pressure
p = (N - rho c^2) / R_i. Each arc sticks from its entry to s_i and slides from s_i to its
exit with f = s_i mu p (s_1 = +1 on the driver, s_2 = -1 on the driven pulley). Per piece:

* span: f = 0, eps constant, theta'' = beta^2 theta with beta^2 = b2 / A;
* stick: v_rel = 0 gives eps = e_i - l theta' (e_i = omega_i R_i / c - 1 - N0/b1), so
  f = B l theta'' and theta'' = alpha^2 theta, alpha^2 = b2 / (A + l^2 B);
* slip: n = N - rho c^2 obeys n' = lam n with lam = -s_i mu b1 / (B R_i), and
  theta'' - beta^2 theta = g n with g = -l s_i mu / (A R_i).

On a piece [p, q] of length L, theta = P e^{-k t} + Q e^{-k (L - t)} (+ g n(p) psi(t) on a
slip arc), t = x - p: both exponentials stay bounded however long the piece. psi solves
psi'' - beta^2 psi = e^{lam t} and is anchored where the forcing resonates (psi(L) = 0 when
lam > 0, psi(0) = 0 when lam < 0), which with E(z) = (e^z - 1)/z reads

    lam > 0:  psi = -e^{lam t} (L - t) E((lam - beta)(L - t)) / (lam + beta)
    lam < 0:  psi =  e^{lam t} t E(-(lam + beta) t) / (lam - beta)

finite and accurate through lam = +-beta, which a growing mu crosses.

Closing the problem. For given c and slip-arc lengths d_i = e_i - s_i the problem is
linear in 18 constants (theta's 12, the strain at the start of each slip arc and in each
span, e_1 and e_2). Its 21 conditions are the continuity of theta, theta' and eps at the six
interfaces, the fixed length (integral of eps over the loop = 0), the driven pulley's
balance (integral of f over its arc = -M2/R2) and e_1's definition by c. Eighteen of them
fix the constants; the other three (the strain's continuity where the loop closes at x = 0,
the length and the balance) are the residuals of a damped Newton iteration on (c, d_1, d_2).
Perfect adhesion (mu None) sticks on the whole arc, with a concentrated force F_i at each
exit where [[B eps]] = -F_i and [[A theta']] = -l F_i; then only c is iterated. omega_2
follows from e_2.

N pulleys. The same pieces close the loop on any layout
(:class:`~beltsim.beltdrive.pulleys.PulleyLayout`, x from pulley 0's entry): every arc
sticks, then slips at its exit (s_i = +1 on the driver, -1 on a loaded pulley). An
idler's stick zone carries the friction B l theta'' of theta's boundary layers, whose
resultant has either sign; its
slip arc balances it, so its slip variable is signed and passes through 0 (a slip piece
of length 0 is the same state whatever its sign). A back-side pulley's friction acts on
the belt's outer face: the lever is -l on its arc, in the moment, the fibre's speed, the
stick zone's friction, g and an adhesive exit's jump (alpha sees l^2). Newton iterates c
and the N slip arcs on the closure, the length and every non-driver pulley's balance
(R_i times the integral of f over its arc = -M_i, 0 for an idler), from the creep
theory's state (:mod:`beltsim.beltdrive.creep`, exact at l = 0) with the continuation in
l behind it. The frictions sum to zero round the loop (B eps is periodic), so the
driver's torque is r_d sum_i M_i / r_i as on the string; the power argument below holds
arc by arc.

Starts. Newton starts from the string's closed-form state (exact at l = 0, so a
continuation in l backs it up); near the capacity from the beam's capacity state; failing
both, from a continuation in the load from the unloaded drive (uniform strain, no slip),
which also tells gross slip (a slip arc leaves its wrap) from lift-off (the continuation
stalls as the slack side's pressure vanishes). Where the tension ratio across the slip
arcs is huge (the slack side nearly without pressure) the exponentials' range raises the
residual's round-off floor, and Newton stops there (FLOOR_STEP).

Power. Multiplying B eps' + f = 0 by eps and the moment balance by theta' and integrating
over the loop (periodic fields) gives integral f (eps + l theta') = 0, and integral f = 0,
so integral f v_b = 0 for the fibre speed v_b = c (1 + N0/b1 + eps + l theta'). Hence
M1 omega1 - M2 omega2 = integral of f omega_i R_i = -integral of f v_rel: the slip power.
With perfect adhesion the concentrated forces act where v_rel jumps from 0 to
c [[eps + l theta']] = -c F_i (1/B + l^2/A); the same integration, with the jumps, charges
each of them F_i times minus the mean of the sliding speeds on its two sides,
(c/2) F_i^2 (1/B + l^2/A).

Capacity. Gross slip sets in when a slip arc covers its whole wrap; the beam's capacity is
the load at which it does, solved for in the same model (:func:`capacity`; on N pulleys
each pulley's, :func:`layout_capacity`), not the string's (the two differ by O(l)).

This module finds the steady state from its starts; the exact pieces and Newton's
iteration are in :mod:`beltsim.beltdrive.beam_loop`, the solution's fields and summary in
:mod:`beltsim.beltdrive.beam_solution`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import replace

import numpy as np

from ..errors import NoSolutionError
from ..problem.roots import brentq
from . import analytic, creep
from .analytic import GrossSlipError, LiftOffError, solve_string
from .beam_loop import (
    FLOOR_STEP,
    MAX_DAMPED,
    MAX_ITERATIONS,
    STEP_TOL,
    _converge,
    _frame,
    _graded,
    _Loop,
    _newton,
    _NotConverged,
    _unpack,
)
from .beam_solution import BeamSolution, _loop_quadrature
from .creep import serpentine_data, solve_serpentine
from .params import DriveParams

#: A load continuation that stalls with the slack side's N - rho c^2 below this fraction of
#: the tight side's is taken for lift-off: the slip arcs grow as ln(1 / p) there and, with
#: a large mu, reach the wrap only as p -> 0.
LIFT_OFF_MARGIN = 0.05


# --------------------------------------------------------------------------------------
# Solvers


def _defaults(P, omega1, M2):
    omega1 = P.omega1 if omega1 is None else float(omega1)
    M2 = P.M2 if M2 is None else float(M2)
    if not omega1 > 0:
        raise ValueError(f"omega1: must be > 0, got {omega1!r}")
    if not M2 >= 0:
        raise ValueError(f"M2: must be >= 0, got {M2!r}")
    return omega1, M2


def _check_bending(P: DriveParams, omega1: float):
    """Refuse a drive whose belt, near the rim speed, has A = a - I c^2 <= 0: there theta's
    equation loses its decaying solutions and the beam has no steady state."""
    # the unloaded belt speed
    c = omega1 * P.layout.radii[P.driver] / (1.0 + P.N0 / P.b1)
    if P.lever > 0 and not P.a - P.I * c * c > 0:
        raise NoSolutionError(
            f"drive.driver_speed: at the belt speed {c:.6g} m/s the rotary inertia I c^2 = "
            f"{P.I * c * c:.4g} N m^2 reaches the bending stiffness a = {P.a:.4g} N m^2: "
            f"the beam has no steady state (a - I c^2 <= 0)")


def _fits(P: DriveParams, d) -> bool:
    """Whether both slip arcs of lengths d (m) lie within their wraps."""
    return bool(np.all(np.abs(d) <= np.asarray(_frame(P).arcs)))


def _string_start(P: DriveParams, omega1: float, M2: float):
    """The iterated unknowns (c, w1, w2) of the string's state, or None where the string
    has none (its gross slip or lift-off, or its root bracket failing near lift-off)."""
    try:
        s = solve_string(P, omega1, M2)
    except ValueError:  # NoSolutionError included
        return None
    return s.c, P.mu * s.phi_s, P.mu * s.phi_s


def _lowest_pressure(loop: _Loop, z) -> float:
    """The smallest contact pressure (N/m) on the arcs (the pieces' ends and the graded
    quadrature's nodes)."""
    zz = np.append(z, 1.0)
    low = math.inf
    for i, seg in enumerate(loop.segs):
        if seg.arc >= 0:
            t = np.concatenate([[0.0, seg.length], _graded(seg)[0]])
            low = min(low, float(np.min(loop.pressure(i, t) @ zz)))
    return low


def _march(P: DriveParams, omega1: float, target: float):
    """Continuation in the load from the unloaded drive (exact: uniform strain, c from the
    driver's rim, no slip) towards ``target`` (may be inf), the step doubling while Newton
    converges to an admissible state (both slip arcs inside their wraps, the pressure
    positive) and halving otherwise.

    Returns
    -------
    (M, y, found, status)
        The last load reached, its unknowns and its (loop, z) (None if only the unloaded
        drive); ``status`` "done" (M is the target), "over" (a slip arc leaves its wrap
        beyond M), "lift" (the pressure vanishes beyond M) or "stall" (Newton fails).
    """
    g = P.geometry
    c0 = omega1 * g.R1 / (1.0 + P.N0 / P.b1)
    if not P.N0 > P.rho * c0 * c0:
        return 0.0, None, None, "lift"
    M, y = 0.0, np.array([c0, 0.0, 0.0])
    dM = min(target, 0.1 * g.R2 * P.N0)
    found, status = None, "stall"
    while M < target:
        trial = min(M + dM, target)
        try:
            loop, z, y_new = _newton(P, P.lever, omega1, (0.0, trial), "load", y)
            ok = _fits(P, _unpack(P, "load", y_new, (0.0, trial))[1]) or "over"
            if ok is True and not _lowest_pressure(loop, z) > 0:
                ok = "lift"
        except _NotConverged:
            ok = "stall"
        if ok is True:
            M, y, found = trial, y_new, (loop, z)
            if status == "stall":
                dM *= 2
            continue
        if status == "stall":
            status = ok
        dM /= 2
        if dM < 1e-3 * M or dM < 1e-9 * g.R2 * P.N0:
            if status == "stall" and found is not None and _margin(found) < LIFT_OFF_MARGIN:
                status = "lift"  # Newton fails as the slack side's pressure vanishes
            return M, y, found, status
    return M, y, found, "done"


def _capacity_near(P: DriveParams, omega1: float, M: float, y):
    """(capacity, loop, z) by Newton with a slip arc pinned to its whole wrap and the load
    unknown, started from an admissible state (load M, unknowns y) close below it."""
    g = P.geometry
    c, d, _ = _unpack(P, "load", y, (0.0, M))
    w = (y[1], y[2])
    first = 0 if abs(d[0]) / g.arcs[0] >= abs(d[1]) / g.arcs[1] else 1
    failures = []
    for arc in (first, 1 - first):
        mode = ("cap1", "cap2")[arc]
        y0 = [c, w[0], w[1]]
        y0[1 + arc] = M / (g.R2 * P.N0)
        try:
            loop, z, y_cap = _newton(P, P.lever, omega1, (0.0, 0.0), mode, y0)
        except (_NotConverged, NoSolutionError) as exc:
            failures.append(str(exc))
            continue
        _, d_cap, (_, cap) = _unpack(P, mode, y_cap, (0.0, 0.0))
        if abs(d_cap[1 - arc]) <= g.arcs[1 - arc] * (1.0 + 1e-12):
            return cap, loop, z
    raise NoSolutionError(f"beam drive: no capacity found at {omega1:g} rad/s "
                          f"({'; '.join(failures) or 'no slip arc fits its wrap'})")


def _capacity_by_string(P: DriveParams, omega1: float):
    """(capacity, loop, z) started from the string's state just below the string's
    capacity (the two differ by O(l)), or None where the string gives no such state."""
    try:
        cap_s = analytic.capacity(P, omega1)
    except ValueError:  # the string's bracket can fail where the belt lifts off
        return None
    start = _string_start(P, omega1, cap_s * (1.0 - 1e-9))
    if start is None:
        return None
    try:
        return _capacity_near(P, omega1, cap_s, np.array(start))
    except NoSolutionError:
        return None


def _capacity_state(P: DriveParams, omega1: float):
    """(capacity, loop, z): the load at which a slip arc first covers its whole wrap; from
    the string's capacity, else from the end of a load continuation."""
    found = _capacity_by_string(P, omega1)
    if found is not None:
        return found
    M, y, _, status = _march(P, omega1, math.inf)
    if status != "over":
        raise NoSolutionError(f"beam drive: no capacity found at {omega1:g} rad/s (the "
                              f"load continuation stops at {M:.6g} N m before gross slip)")
    return _capacity_near(P, omega1, M, y)


def capacity(P: DriveParams, omega1: float | None = None) -> float:
    """The largest load torque M2 (N m) the beam drive carries at the driver speed omega1:
    a slip arc then covers its whole wrap (inf for perfect adhesion).

    The string's capacity (:func:`beltsim.beltdrive.analytic.capacity`) is its l -> 0
    limit; this one is solved in the beam's own model.
    """
    if P.mu is None:
        return math.inf
    omega1, _ = _defaults(P, omega1, 0.0)
    _check_bending(P, omega1)
    return float(_capacity_state(P, omega1)[0])


def _gross_slip(P, omega1, M2, cap):
    return GrossSlipError(f"drive.load_torque: {M2:g} N m exceeds the beam drive's capacity "
                          f"{cap:.6g} N m at {omega1:g} rad/s (gross slip: no steady state)",
                          cap)


def _solve_coulomb(P: DriveParams, omega1: float, M2: float):
    """(loop, z) of the Coulomb solution, or GrossSlipError / NoSolutionError."""
    start = _string_start(P, omega1, M2)
    if start is not None:
        try:
            loop, z, y = _converge(P, omega1, (0.0, M2), "load", start)
            if _fits(P, _unpack(P, "load", y, (0.0, M2))[1]):
                return loop, z
        except _NotConverged:
            pass
    # near or beyond the capacity: the beam's capacity from the string's, and below it a
    # start from the capacity state
    found = _capacity_by_string(P, omega1)
    if found is not None:
        cap, loop, _ = found
        if M2 > cap:
            raise _gross_slip(P, omega1, M2, cap)
        d = [seg.length for seg in loop.segs if seg.kind == "slip"]
        try:
            loop, z, y = _newton(P, P.lever, omega1, (0.0, M2), "load",
                                 (loop.c, d[0] * P.mu / P.geometry.R1,
                                  d[1] * P.mu / P.geometry.R2))
            if _fits(P, _unpack(P, "load", y, (0.0, M2))[1]):
                return loop, z
        except _NotConverged:
            pass
    M, y, found, status = _march(P, omega1, M2)
    if status == "done":
        return found
    if status == "over":
        cap = _capacity_near(P, omega1, M, y)[0]
        if M2 > cap:
            raise _gross_slip(P, omega1, M2, cap)
    elif status == "lift" and not P.N0 > P.rho * (omega1 * P.geometry.R1) ** 2 / (
            1.0 + P.N0 / P.b1) ** 2:
        c0 = omega1 * P.geometry.R1 / (1.0 + P.N0 / P.b1)
        raise LiftOffError(
            f"drive.installation_tension: {P.N0:g} N does not exceed the centrifugal "
            f"tension rho c^2 = {P.rho * c0 * c0:.4g} N: the belt lifts off even unloaded")
    elif status == "lift":
        raise LiftOffError(
            f"drive.installation_tension: {P.N0:g} N leaves the belt without contact "
            f"pressure beyond {M:.4g} N m, below the load {M2:g} N m: it would lift off, "
            f"which this model does not describe")
    raise NoSolutionError(f"beam drive: no steady state found at {M2:g} N m (the load "
                          f"continuation stops at {M:.6g} N m)")


def _margin(found) -> float:
    """(T2 - rho c^2) / (T1 - rho c^2) of a state (loop, z): the slack side's share."""
    loop, z = found
    zz = np.append(z, 1.0)
    n = [float(loop.pressure(i, 0.0)[0] @ zz) * loop.radii[seg.arc]
         for i, seg in enumerate(loop.segs) if seg.kind == "stick"]
    return n[1] / n[0]


def _layout_state(P: DriveParams, omega1: float, loads):
    """(loop, z, d) of the beam on N pulleys at ``loads`` (N m per pulley, the driver's
    0), by Newton (backed by the continuation in the lever) from the creep theory's state
    at the same loads, which is exact at l = 0: its belt speed and slip arcs, the idlers'
    slip arcs 0. The slip arcs d (m, signed) may pass their wraps: the capacity search
    steps across them."""
    data = replace(serpentine_data(replace(P, tensioner=None)), omega=omega1,
                   loads=tuple(float(m) for m in loads))
    loads = np.array(data.loads)
    mus = np.ones(len(loads)) if P.mu is None else np.asarray(P.mus)
    if P.mu is None:
        mode, y0 = "stick", (solve_serpentine(data).c,)
    else:
        c, _, _, phi = creep._solve_raw(data, data.layout, loads)
        mode, y0 = "load", (c, *(mus * phi))
    try:
        loop, z, y = _converge(P, omega1, loads, mode, y0)
    except _NotConverged as exc:
        raise NoSolutionError(f"beam drive: no steady state found from the creep "
                              f"theory's ({exc})") from None
    return loop, z, _unpack(P, mode, y, loads)[1]


def layout_capacity(P: DriveParams, omega1: float, i: int) -> float:
    """The load (N m) at which pulley i's slip arc covers its whole wrap on N pulleys:
    its own load raised with the others' held or, for the driver, every load raised
    together (its torque then), as the creep theory's slip margins
    (:func:`beltsim.beltdrive.creep` ``slip_margins``); other pulleys' slip arcs are not
    limited.

    A root in the load factor of the beam's slip arc less the wrap, bracketed from the
    creep theory's factor (the two differ by O(l)) outwards by steps of 1 % doubling. As
    in the creep theory, a state lost first (lift-off) caps the factor where it is lost.

    Raises
    ------
    NoSolutionError
        No bracket: the beam's state is lost (lift-off, Newton) before the slip arc
        reaches its wrap.
    """
    lay = P.layout
    data = replace(serpentine_data(replace(P, tensioner=None)), omega=omega1)
    base = np.asarray(data.loads, dtype=float)
    scale_all = i == P.driver

    def loads_at(lam):
        if scale_all:
            return base * lam
        out = base.copy()
        out[i] *= lam
        return out

    def excess(lam):  # the slip arc's share of the wrap, less 1; inf where no state
        try:
            d = _layout_state(P, omega1, loads_at(lam))[2]
        except NoSolutionError:
            return math.inf
        return abs(d[i]) / lay.arcs[i] - 1.0

    lam0 = creep._load_factor(data, lay, i, scale_all)
    lo = hi = lam0
    step = 0.01
    while excess(lo) >= 0.0:
        hi, lo, step = lo, lo * (1.0 - step), min(2.0 * step, 0.5)
        if lo < 1e-6 * lam0:
            raise NoSolutionError(f"pulley {lay.names[i]!r}: no beam capacity found")
    step, e_hi = 0.01, excess(hi)
    while e_hi < 0.0:
        if hi > 1e6 * lam0:
            raise NoSolutionError(f"pulley {lay.names[i]!r}: no beam capacity found")
        lo, hi, step = hi, hi * (1.0 + step), 2.0 * step
        e_hi = excess(hi)
    lam = brentq(lambda m: min(excess(m), 1e3), lo, hi, xtol=1e-12 * hi, rtol=1e-12)
    now = lay.radii[i] * float(np.sum(base / lay.radii)) if scale_all else base[i]
    return float(lam * now)


def _solve_layout(P: DriveParams, omega1: float):
    """(loop, z, loads) of a drive on N pulleys (:func:`_layout_state`).

    The creep theory's lift-off is this drive's too; a beam slip arc beyond its wrap is
    gross slip (or, where Newton is lost, a creep theory's one), with the capacity of the
    pulley whose slip arc passes its wrap the most (:func:`layout_capacity`)."""
    data = replace(serpentine_data(replace(P, tensioner=None)), omega=omega1)
    loads = np.array(data.loads)
    try:
        loop, z, d = _layout_state(P, omega1, loads)
    except LiftOffError:
        raise
    except NoSolutionError:
        # Newton lost beyond a wrap: the creep theory's overloaded pulley is the one
        phi = creep._solve_raw(data, data.layout, loads)[3]
        if P.mu is None or not np.any(phi > P.layout.wraps):
            raise
        loop = z = None
        d = phi * P.layout.radii
    if d is not None and not _fits(P, d):
        i = int(np.argmax(np.abs(d) / P.layout.arcs))
        try:
            cap = layout_capacity(P, omega1, i)
        except NoSolutionError:
            cap = math.nan
        if i == P.driver:
            now = P.layout.radii[i] * float(np.sum(loads / P.layout.radii))
            what = "driver torque"
        else:
            now, what = loads[i], "load"
        raise GrossSlipError(f"pulley {P.layout.names[i]!r}: {what} {now:.6g} N m exceeds "
                             f"its beam capacity {cap:.6g} N m (gross slip: slip arc "
                             f"{abs(d[i]) / P.layout.radii[i]:.4g} rad > wrap "
                             f"{P.layout.wraps[i]:.4g} rad)", cap)
    return loop, z, loads


def solve_beam(P: DriveParams, omega1: float | None = None,
               M2: float | None = None) -> BeamSolution:
    """The shear-deformable beam's steady state at driver speed omega1 and load M2 (the
    scene's final values by default); ``P.lever`` = 0 (the string model) gives the string.

    On two pulleys Newton starts from the string's closed-form state; where that fails,
    from a continuation in the load. On N pulleys (M2 then must be None: the loads are
    the pulleys' own) it starts from the creep theory's state (``_solve_layout``).

    Raises
    ------
    GrossSlipError
        The load exceeds the beam drive's capacity
        (:func:`beltsim.beltdrive.beam.capacity`, in the message; on N pulleys the
        overloaded pulley's, ``layout_capacity``).
    LiftOffError
        The contact pressure does not stay positive on the arcs.
    NoSolutionError
        No steady state of the assumed layout (the message names what fails).
    """
    if not P.two_pulley:
        if M2 is not None:
            raise ValueError("M2: only for the two-pulley drive (the pulleys carry their "
                             "own loads)")
        omega1, _ = _defaults(P, omega1, 0.0)
        _check_bending(P, omega1)
        loop, z, loads = _solve_layout(P, omega1)
        sol = BeamSolution(P, omega1, loads, loop, z)
        sol._check()
        return sol
    omega1, M2 = _defaults(P, omega1, M2)
    g = P.geometry
    _check_bending(P, omega1)
    if P.mu is None:
        try:
            c0 = solve_string(P, omega1, M2).c
        except ValueError:  # the string lifts off: start from the unloaded belt speed
            c0 = omega1 * g.R1 / (1.0 + P.N0 / P.b1)
        try:
            loop, z, _ = _converge(P, omega1, (0.0, M2), "stick", (c0,))
        except _NotConverged as exc:
            raise NoSolutionError(f"beam drive: no steady state found ({exc})") from None
    else:
        loop, z = _solve_coulomb(P, omega1, M2)
    sol = BeamSolution(P, omega1, (0.0, M2), loop, z)
    sol._check()
    return sol


def slip_collapse(P: DriveParams, mus, omega1: float | None = None,
                  M2: float | None = None) -> dict:
    """The slip arcs' collapse onto the exits as mu grows (the drive's Fig. 7).

    For each friction coefficient the Coulomb solution is compared with perfect adhesion
    on a grid resolving both. The tension's difference is taken outside the slip arcs:
    inside them the Coulomb tension runs across the jump that adhesion concentrates at
    the exit, so its maximum there stays near the concentrated force however narrow the
    arc; its integral (``tension_diff_l1``) covers the whole loop.

    Returns
    -------
    dict
        Arrays over ``mu``: ``slip_arc_driver``, ``slip_arc_driven`` (rad),
        ``tight_tension``, ``slack_tension`` (N), ``theta_diff`` (max abs theta difference,
        rad), ``tension_diff`` (N, outside the slip arcs), ``tension_diff_l1`` (N m); and
        ``adhesion``, the perfect-adhesion summary.
    """
    stick = solve_beam(dataclasses.replace(P, mu=None, friction="stick"), omega1, M2)
    keys = ("slip_arc_driver", "slip_arc_driven", "tight_tension", "slack_tension",
            "theta_diff", "tension_diff", "tension_diff_l1")
    out = {k: [] for k in keys}
    mus = np.asarray(mus, dtype=float)
    e = P.geometry.bounds
    for mu in mus:
        sol = solve_beam(dataclasses.replace(P, mu=float(mu), friction="coulomb"),
                         omega1, M2)
        sm = sol.summary()
        for k in keys[:4]:
            out[k].append(sm[k])
        x = np.unique(np.concatenate([sol.grid(), stick.grid()]))
        out["theta_diff"].append(float(np.max(np.abs(sol.theta(x) - stick.theta(x)))))
        dN = np.abs(sol.tension(x) - stick.tension(x))
        s1, s2 = sol.stick_ends
        outside = ~(((x >= s1) & (x < e[1])) | ((x >= s2) & (x < e[3])))
        out["tension_diff"].append(float(np.max(dN[outside])))
        xq, wq = _loop_quadrature(sol, stick)
        out["tension_diff_l1"].append(float(np.sum(
            wq * np.abs(sol.tension(xq) - stick.tension(xq)))))
    res = {k: np.array(v) for k, v in out.items()}
    res["mu"] = mus
    res["adhesion"] = stick.summary()
    return res


__all__ = ["FLOOR_STEP", "MAX_DAMPED", "MAX_ITERATIONS", "STEP_TOL", "BeamSolution",
           "capacity", "layout_capacity", "slip_collapse", "solve_beam"]

