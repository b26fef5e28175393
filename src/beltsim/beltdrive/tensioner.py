"""A tensioner: an idler on a spring-loaded arm about a fixed pivot, and the arm's
equilibrium.

The arm of length a = |P_k - O| turns about the pivot O; its angle alpha is measured
counterclockwise from +x. Its spring has the rate k_t (N m/rad) and gives the torque
``preload`` tau0 with the arm as drawn, in the sense s that turns the pulley into the belt
(the sense in which the loop lengthens, :func:`arm_sense`). With the arm turned by beta
in that sense, the spring's torque is tau0 - k_t beta and the belt's is
s (P_k - O) x F_hub (F_hub the belt's force on the pulley's bearing); the arm rests where
they cancel (:func:`equilibrium`). The belt's unstretched length stays that of the layout
as drawn, so a turned layout carries the same belt (:func:`installation_tension_at`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import NoSolutionError, SceneError
from ..problem.roots import brentq
from ..problem.rules import Rule, show
from .pulley_tables import CentreRule, checked_keys
from .pulleys import GeometryError, PulleyLayout


@dataclass(frozen=True)
class Tensioner:
    """An idler on a spring-loaded arm about a fixed pivot.

    ``index`` the idler's pulley, ``pivot`` O (m), ``stiffness`` k_t (N m/rad),
    ``preload`` tau0 (N m): the spring's torque with the arm as drawn, in the sense that
    turns the pulley into the belt (the sense in which the loop length grows);
    ``inertia`` (kg m^2, about the pivot, the pulley's mass included) and ``damping``
    (N m s) are the arm's, for transients.
    """

    index: int
    pivot: tuple[float, float]
    stiffness: float
    preload: float
    inertia: float = 0.0
    damping: float = 0.0

    def arm(self, layout: PulleyLayout) -> tuple[float, float, int]:
        """The arm's length a (m), its angle alpha (rad, counterclockwise from +x) in
        ``layout`` and the sense s (+1 counterclockwise) that turns it into the belt."""
        arm = layout.centres[self.index] - np.asarray(self.pivot, dtype=float)
        return (float(np.hypot(*arm)), math.atan2(arm[1], arm[0]),
                arm_sense(layout, self.index, self.pivot))

    def turned(self, layout: PulleyLayout, beta: float) -> PulleyLayout:
        """``layout`` with the arm turned by ``beta`` (rad) into the belt (GeometryError
        where the turned layout makes no loop)."""
        a, alpha, s = self.arm(layout)
        alpha += s * beta
        O = np.asarray(self.pivot, dtype=float)
        return layout.moved(self.index, O + a * np.array([math.cos(alpha), math.sin(alpha)]))

    def torque(self, layout: PulleyLayout, beta: float, hub) -> float:
        """The net torque on the arm (N m) in the sense into the belt: the spring's
        tau0 - k_t beta and the belt's s (P - O) x F with ``hub`` = F (N), the belt's
        force on the pulley; ``layout`` is the layout with the arm at beta, whose sense is
        taken as the drawn one's."""
        _, _, s = self.arm(layout)
        P = layout.centres[self.index] - np.asarray(self.pivot, dtype=float)
        return self.preload - self.stiffness * beta + s * float(P[0] * hub[1] - P[1] * hub[0])


def arm_sense(layout: PulleyLayout, k: int, pivot) -> int:
    """The sense in which turning pulley k's arm lengthens the loop.

    dLambda / dP_k = t_in - t_out (a span's length changes by its end's motion along it;
    the wraps' change is of second order) and dP_k / dalpha = J (P_k - O).

    Parameters
    ----------
    layout : PulleyLayout
    k : int
        The tensioner pulley's index.
    pivot : (float, float)
        The arm's pivot O (m).

    Returns
    -------
    int
        +1 when turning the arm counterclockwise lengthens the loop, else -1.
    """
    t = layout.span_directions
    arm = layout.centres[k] - np.asarray(pivot, dtype=float)
    grad = t[k - 1] - t[k]
    return 1 if float(np.dot(grad, [-arm[1], arm[0]])) > 0 else -1


def installation_tension_at(N0: float, b1: float, drawn: float, loop_length: float) -> float:
    """The installation tension (N) on a layout of loop length Lambda' that carries the
    belt installed at N0 on the drawn layout (loop length ``drawn``): the same
    unstretched length L0 = Lambda (1 - N0 / b1), so N0' = b1 (Lambda' - L0) / Lambda'."""
    L0 = drawn * (1.0 - N0 / b1)
    return b1 * (loop_length - L0) / loop_length


def equilibrium(ten: Tensioner, layout: PulleyLayout, at, hub_of, beta0: float = 0.0,
                step: float = 1e-3, xtol: float = 1e-14):
    """The arm's rest angle: the root in beta of
    :meth:`~beltsim.beltdrive.tensioner.Tensioner.torque`.

    Parameters
    ----------
    ten : Tensioner
    layout : PulleyLayout
        The layout as drawn (beta = 0).
    at : callable
        ``at(beta)``: the steady state with the arm turned by beta; it raises
        GeometryError or NoSolutionError where there is none.
    hub_of : callable
        ``hub_of(solution)``: the belt's force on the tensioner's pulley (N, (Fx, Fy)).
    beta0, step : float, optional
        Where the search starts (rad, e.g. a model's estimate) and its first step.
    xtol : float, optional
        The root's tolerance in beta (rad).

    Returns
    -------
    (float, object)
        beta and the steady state there.

    Raises
    ------
    NoSolutionError
        No equilibrium within half a turn ("tensioner: no equilibrium ...").
    """
    solved = {}  # the root's own solve is brentq's last call: kept, not repeated

    def solve(beta):
        if beta not in solved:
            try:
                solved[beta] = at(beta)
            except (GeometryError, NoSolutionError) as exc:
                solved[beta] = exc
        return solved[beta]

    def h(sol, beta):
        return ten.torque(ten.turned(layout, beta), beta, hub_of(sol))

    first = solve(beta0)
    if isinstance(first, Exception):
        raise NoSolutionError(f"tensioner: no equilibrium: the layout at the search's start "
                              f"has no steady state ({first})")
    f0 = h(first, beta0)
    if f0 == 0:
        return beta0, first
    step = math.copysign(step, f0)
    b_ok, b_try, reason = beta0, beta0 + step, None
    while abs(b_try - beta0) <= math.pi:
        sol = solve(b_try)
        if isinstance(sol, Exception):
            reason, fails = sol, b_try
            for _ in range(60):  # close in on the last valid angle before the failure
                mid = 0.5 * (b_ok + fails)
                sm = solve(mid)
                if isinstance(sm, Exception):
                    fails = mid
                    continue
                if h(sm, mid) * f0 <= 0:
                    b_try, sol = mid, sm
                    break
                b_ok = mid
            if isinstance(sol, Exception):
                break
        if h(sol, b_try) * f0 <= 0:
            beta = brentq(lambda b: h(_valid(solve(b)), b), b_ok, b_try, xtol=xtol,
                          rtol=4 * np.finfo(float).eps)
            return beta, solve(beta)
        b_ok, b_try = b_try, beta0 + 2.0 * (b_try - beta0)
    where = "the spring" if f0 > 0 else "the belt"
    raise NoSolutionError(
        f"tensioner: no equilibrium of pulley {layout.names[ten.index]!r}'s arm: {where} "
        f"wins up to {math.degrees(b_ok):.4g} deg from the drawn angle"
        + (f", where {reason}" if reason is not None else ""))


def _valid(sol):
    if isinstance(sol, Exception):
        raise sol
    return sol


#: The keys of [tensioner] and their rules.
TENSIONER_RULES: dict[str, Rule] = {
    "pulley": Rule("str"),
    "pivot": CentreRule(),
    "stiffness": Rule("float", nonneg=True),
    "preload": Rule("float"),
    "inertia": Rule("float", positive=True),
    "damping": Rule("float", nonneg=True),
}
TENSIONER_REQUIRED = ("pulley", "pivot", "stiffness", "preload")


def check_tensioner(table, pulleys) -> dict:
    """``[tensioner]`` checked key by key against the scene's checked ``[[pulley]]``
    tables: the pulley is an idler, the pivot is not its centre.

    Raises
    ------
    SceneError
        The first broken rule, naming ``tensioner.KEY``.
    """
    if not isinstance(table, dict):
        raise SceneError("[tensioner]", f"must be a table (section), got {show(table)}")
    if pulleys is None:
        raise SceneError("[tensioner]", "only in a scene with [[pulley]] tables (the "
                         "two-pulley shorthand has no idler to put on an arm)")
    clean = checked_keys(table, TENSIONER_RULES, TENSIONER_REQUIRED, "tensioner",
                         "[tensioner]")
    names = [p["name"] for p in pulleys]
    if clean["pulley"] not in names:
        raise SceneError("tensioner.pulley", f"must name one of the pulleys "
                         f"({', '.join(names)}), got {show(clean['pulley'])}")
    p = pulleys[names.index(clean["pulley"])]
    if "speed" in p or "load_torque" in p:
        role = "the driver" if "speed" in p else "a driven pulley (it has load_torque)"
        raise SceneError("tensioner.pulley", f"must be an idler, and pulley "
                         f"{p['name']} is {role}")
    if math.dist(p["centre"], clean["pivot"]) < 1e-9 * max(p["radius"], 1e-300):
        raise SceneError("tensioner.pivot", f"must differ from pulley {p['name']}'s centre "
                         f"(an arm of length 0 does not move the pulley)")
    return clean


def tensioner_of(table: dict | None, names) -> Tensioner | None:
    """The :class:`Tensioner` of a checked ``[tensioner]`` table (None without one)."""
    if table is None:
        return None
    return Tensioner(list(names).index(table["pulley"]),
                     (float(table["pivot"][0]), float(table["pivot"][1])),
                     table["stiffness"], table["preload"], table.get("inertia", 0.0),
                     table.get("damping", 0.0))


__all__ = ["TENSIONER_REQUIRED", "TENSIONER_RULES", "Tensioner", "arm_sense",
           "check_tensioner", "equilibrium", "installation_tension_at", "tensioner_of"]
