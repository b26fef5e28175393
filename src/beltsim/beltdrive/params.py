"""The physical data of a closed drive (:class:`DriveParams`), derived from a validated
drive scene's tables.

The scene (:mod:`beltsim.beltdrive.scene`) validates with the string's creep solution
(:mod:`beltsim.beltdrive.analytic`), which needs these data: both import them from
here, so neither imports the other's importer.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..problem.rules import derived_stiffness, final_value
from .geometry import Geometry


@dataclass(frozen=True)
class DriveParams:
    """The physical data of a closed drive, in SI units (the final values of profiles).

    ``rho`` and ``I`` are zero for a quasistatic scene; ``mu`` is None for perfect
    adhesion ("stick"); ``lever`` is h / 2 for the beam and 0 for the string.
    """

    h: float
    a: float
    b1: float
    b2: float
    rho: float
    I: float
    inertia: bool
    damping: float
    model: str
    friction: str
    mu: float | None
    N0: float
    J2: float
    omega1: float
    M2: float
    geometry: Geometry

    @property
    def lever(self) -> float:
        """The friction's lever about the middle line: h / 2 (beam) or 0 (string)."""
        return 0.5 * self.h if self.model == "beam" else 0.0


def params_of(d: dict) -> DriveParams:
    """The physical data of a validated drive scene's tables (final values of profiles)."""
    beam = dict(d["belt"])
    stiff = derived_stiffness({"beam": beam, "stiffness": d.get("stiffness", {}),
                        "physics": d["physics"]})
    drive, contact, physics = d["drive"], d["contact"], d["physics"]
    load = drive["load_torque"]
    return DriveParams(
        h=beam["height"], a=stiff["a"], b1=stiff["b1"], b2=stiff["b2"], rho=stiff["rho"],
        I=stiff["I"], inertia=physics["inertia"],
        damping=physics.get("damping", 0.0) if physics["inertia"] else 0.0,
        model=physics.get("model", "beam"), friction=contact["friction"],
        mu=contact.get("friction_coefficient"), N0=drive["installation_tension"],
        J2=drive["driven_inertia"], omega1=final_value(drive["driver_speed"]),
        M2=float(load[-1][1] if isinstance(load, list) else load),
        geometry=Geometry(drive["driver_radius"], drive["driven_radius"],
                          drive["centre_distance"]))
