"""A drive's exact steady states, whatever its layout: the string's creep theory (the
two-pulley closed form of :mod:`~beltsim.beltdrive.analytic`, or its N-pulley form of
:mod:`~beltsim.beltdrive.creep`) and the beam's (:mod:`~beltsim.beltdrive.beam`, two
pulleys)."""

from __future__ import annotations

from ..errors import NoSolutionError
from .analytic import solve_string
from .beam import solve_beam
from .creep import SerpentineData, solve_serpentine
from .params import DriveParams


def serpentine_data(P: DriveParams) -> SerpentineData:
    """The creep theory's data of a drive (its final speeds and loads; the layout as
    drawn, with a tensioner's arm at its drawn angle)."""
    if P.tensioner is not None and P.arm_turn:
        P = P.at_arm(-P.arm_turn)
    return SerpentineData(layout=P.layout, b1=P.b1, rho=P.rho,
                          mu=None if P.mu is None else P.mus, N0=P.N0,
                          driver=P.driver, omega=P.omega1,
                          loads=tuple(p.final_load for p in P.pulleys),
                          tensioner=P.tensioner)


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


def exact_state(P: DriveParams):
    """The exact steady state a drive's run is compared with: the beam's for the beam
    model, the creep theory's for the string.

    Raises
    ------
    NoSolutionError
        The drive has no steady state (gross slip, lift-off), or it is a beam on more
        than two pulleys, whose exact steady state is not derived yet.
    """
    if P.model == "beam":
        if not P.two_pulley:
            raise NoSolutionError("the beam's exact steady state is derived for two "
                                  "pulleys only; this drive has none to compare with")
        return solve_beam(P)
    return string_state(P)
