"""A drive's exact steady states, whatever its layout: the string's creep theory (the
two-pulley closed form of :mod:`~beltsim.beltdrive.analytic`, or its N-pulley form of
:mod:`~beltsim.beltdrive.creep`) and the beam's (:mod:`~beltsim.beltdrive.beam`, on any
layout, with a tensioner's arm at rest by the same search as the creep theory's)."""

from __future__ import annotations

from ..errors import NoSolutionError
from .analytic import solve_string
from .beam import solve_beam
from .creep import serpentine_data, solve_serpentine
from .params import DriveParams
from .tensioner import equilibrium


def string_state(P: DriveParams):
    """The string's exact steady state of a drive (the creep theory).

    Raises
    ------
    NoSolutionError
        The drive has no steady state (gross slip, lift-off).
    """
    if P.two_pulley and P.tensioner is None:
        return solve_string(P)
    return solve_serpentine(serpentine_data(P))


def beam_state(P: DriveParams):
    """The beam's exact steady state of a drive; with a tensioner, its arm at rest: the
    root of the arm's torque (:func:`~beltsim.beltdrive.tensioner.equilibrium`, the
    creep theory's search) over beam states of the same belt on the turned layouts,
    started from the creep theory's rest angle (the two differ by O(l))."""
    if P.tensioner is None:
        return solve_beam(P)
    drawn = P.at_arm(-P.arm_turn) if P.arm_turn else P
    ten = drawn.tensioner
    try:
        beta0 = string_state(drawn).arm_travel
    except NoSolutionError:
        beta0 = 0.0
    # the beam's rest angle is within O(l) of the string's: a small first step
    # brackets it at once
    _, sol = equilibrium(ten, drawn.layout, lambda beta: solve_beam(drawn.at_arm(beta)),
                         lambda sol: sol.hub_loads[ten.index], beta0, step=1e-6,
                         xtol=1e-13)
    return sol


def exact_state(P: DriveParams):
    """The exact steady state a drive's run is compared with: the beam's for the beam
    model (:func:`~beltsim.beltdrive.exact.beam_state`), the creep theory's for the string.

    Raises
    ------
    NoSolutionError
        The drive has no steady state (gross slip, lift-off), or none of the beam's
        stick-then-slip layout.
    """
    if P.model == "beam":
        return beam_state(P)
    return string_state(P)
