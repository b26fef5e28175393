"""The physical data of a closed drive (:class:`DriveParams`), derived from a validated
drive scene's tables.

The scene (:mod:`beltsim.beltdrive.scene`) validates with the string's creep solution
(:mod:`beltsim.beltdrive.analytic`, :mod:`beltsim.beltdrive.creep`), which needs these
data: both import them from here, so neither imports the other's importer.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from ..problem.rules import derived_stiffness, final_value
from .geometry import Geometry
from .pulley_tables import PulleySpec, driver_index, installation_tension, specs_of
from .pulleys import Pulley, PulleyLayout
from .tensioner import Tensioner, installation_tension_at, tensioner_of


@dataclass(frozen=True)
class DriveParams:
    """The physical data of a closed drive, in SI units (the final values of profiles).

    ``rho`` and ``I`` are zero for a quasistatic scene; ``mu`` is None for perfect
    adhesion ("stick"); ``lever`` is h / 2 for the beam and 0 for the string.
    ``pulleys`` are in the belt's order and ``layout`` is their geometry. ``tensioner``
    is the arm of one idler (None without one); ``arm_turn`` is how far that arm is
    turned into the belt from its drawn angle (rad) in ``layout`` and ``pulleys``, whose
    belt is the one installed at N0 on the layout as drawn (:meth:`at_arm`).
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
    mu: float | None  # [contact]'s friction coefficient, each pulley's default
    N0: float
    pulleys: tuple[PulleySpec, ...]
    layout: PulleyLayout
    tensioner: Tensioner | None = None
    arm_turn: float = 0.0

    def at_arm(self, beta: float) -> DriveParams:
        """The same drive with the tensioner's arm turned by a further ``beta`` (rad)
        into the belt: the pulley moved, the same belt (its N0 on the turned layout)."""
        ten = self.tensioner
        layout = ten.turned(self.layout, beta)
        pulleys = list(self.pulleys)
        pulleys[ten.index] = replace(pulleys[ten.index],
                                     centre=tuple(map(float, layout.centres[ten.index])))
        return replace(self, layout=layout, pulleys=tuple(pulleys),
                       N0=installation_tension_at(self.N0, self.b1, self.layout.loop_length,
                                                  layout.loop_length),
                       arm_turn=self.arm_turn + beta)

    @property
    def roles(self) -> tuple[str, ...]:
        """Each pulley's role: "driver", "driven", "tensioner" or "idler"."""
        ten = self.tensioner
        return tuple("tensioner" if ten is not None and i == ten.index else p.role
                     for i, p in enumerate(self.pulleys))

    def arm_figures(self) -> dict:
        """``arm_angle`` (rad, counterclockwise from +x about the pivot) and
        ``arm_travel`` (rad, into the belt from the drawn angle) of the tensioner's arm;
        empty without one."""
        if self.tensioner is None:
            return {}
        return {"arm_angle": self.tensioner.arm(self.layout)[1],
                "arm_travel": self.arm_turn}

    @property
    def lever(self) -> float:
        """The friction's lever about the middle line: h / 2 (beam) or 0 (string)."""
        return 0.5 * self.h if self.model == "beam" else 0.0

    @property
    def mus(self) -> tuple[float | None, ...]:
        """Each pulley's friction coefficient: its own, else ``mu`` (None for perfect
        adhesion)."""
        if self.mu is None:
            return (None,) * len(self.pulleys)
        return tuple(self.mu if p.mu is None else p.mu for p in self.pulleys)

    @property
    def driver(self) -> int:
        """The driver's index among the pulleys."""
        return driver_index(self.pulleys)

    @property
    def omega1(self) -> float:
        """The driver's final speed (rad/s)."""
        return float(final_value(self.pulleys[self.driver].speed))

    @property
    def driver_rim_speed(self) -> float:
        """The driver's final rim speed omega r (m/s)."""
        return self.omega1 * self.pulleys[self.driver].radius

    @property
    def two_pulley(self) -> bool:
        """Whether this is the two-pulley drive of the shorthand, up to a rigid motion:
        two inner pulleys, the driver first, one friction coefficient (what the
        two-pulley solutions and figures take)."""
        ps = self.pulleys
        return (len(ps) == 2 and ps[0].role == "driver" and all(p.side == 1 for p in ps)
                and self.mus[0] == self.mus[1])

    @property
    def geometry(self) -> Geometry:
        """The two-pulley geometry (R1, R2, C); only for :attr:`two_pulley` drives."""
        if not self.two_pulley:
            raise ValueError("a two-pulley figure of a drive that is not the two-pulley "
                             "layout (driver first, both inner)")
        p1, p2 = self.pulleys
        return Geometry(p1.radius, p2.radius, math.dist(p1.centre, p2.centre))

    @property
    def J2(self) -> float:
        """The driven pulley's inertia (two-pulley drives)."""
        return self.pulleys[1].inertia

    @property
    def M2(self) -> float:
        """The driven pulley's final load (two-pulley drives, N m)."""
        return self.pulleys[1].final_load


def params_of(d: dict) -> DriveParams:
    """The physical data of a validated drive scene's tables (final values of profiles)."""
    beam = dict(d["belt"])
    stiff = derived_stiffness({"beam": beam, "stiffness": d.get("stiffness", {}),
                               "physics": d["physics"]})
    contact, physics = d["contact"], d["physics"]
    specs = specs_of(d)
    layout = layout_of(specs)
    return DriveParams(
        h=beam["height"], a=stiff["a"], b1=stiff["b1"], b2=stiff["b2"], rho=stiff["rho"],
        I=stiff["I"], inertia=physics["inertia"],
        damping=physics.get("damping", 0.0) if physics["inertia"] else 0.0,
        model=physics.get("model", "beam"), friction=contact["friction"],
        mu=contact.get("friction_coefficient"),
        N0=installation_tension(d["drive"], layout.loop_length, stiff["b1"]),
        pulleys=specs, layout=layout,
        tensioner=tensioner_of(d.get("tensioner"), [p.name for p in specs]))


def layout_of(specs) -> PulleyLayout:
    """The geometry of the pulleys (GeometryError: a layout that makes no belt loop)."""
    return PulleyLayout([Pulley(p.name, p.centre, p.radius, p.side) for p in specs])
