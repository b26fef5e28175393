"""A drive scene's pulleys: the ``[[pulley]]`` tables, or the two-pulley shorthand of
``[drive]``, checked and read as one list of :class:`PulleySpec` in the belt's order.

``[[pulley]]`` tables, one a pulley in the order the belt runs through them, each with
``name``, ``centre = [x, y]`` (m), ``radius`` (m), ``side`` ("inner": the belt wraps it
with its inner face; "back": a back-side idler), ``inertia`` (kg m^2; not the driver's,
whose speed is prescribed), an optional ``friction_coefficient`` (the default is
``[contact]``'s), and ``speed`` (rad/s, a profile: the one driver) or ``load_torque``
(N m consumed, a load profile: a driven pulley). The rest are idlers.

The shorthand (``[drive] driver_radius``, ``driven_radius``, ``centre_distance``,
``driver_speed``, ``load_torque``, ``driven_inertia``) is the layout with the driver
at the origin and the driven pulley at (centre_distance, 0), both inner, in that order.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import SceneError
from ..problem.rules import (
    PROFILE,
    Rule,
    check_table,
    final_value,
    number,
    profile_extremes,
    show,
)

#: The two-pulley shorthand's keys in [drive].
SHORTHAND = ("driver_radius", "driven_radius", "centre_distance", "driver_speed",
             "load_torque", "driven_inertia")


def check_load(key, value):
    """A load torque (N m): a number >= 0 (ramped from 0) or a table of [time, value] rows."""
    if isinstance(value, list):
        return check_table(key, value, zero_allowed=True)
    value = number(key, value)
    if not value >= 0:
        raise SceneError(key, f"must be >= 0, got {value!r}")
    return value


class LoadRule(Rule):
    """The rule of a load torque (:func:`check_load`)."""

    def __init__(self):
        super().__init__("load")

    def check(self, key, value):
        return check_load(key, value)


def _check_centre(key, value):
    if not isinstance(value, list) or len(value) != 2:
        raise SceneError(key, f"must be a pair [x, y] of numbers (m), got {show(value)}")
    return [number(f"{key}[0]", value[0]), number(f"{key}[1]", value[1])]


class CentreRule(Rule):
    """The rule of a pulley's centre: a pair [x, y] of finite numbers (m)."""

    def __init__(self):
        super().__init__("centre")

    def check(self, key, value):
        return _check_centre(key, value)


#: The keys of a [[pulley]] table and their rules.
PULLEY_RULES: dict[str, Rule] = {
    "name": Rule("str"),
    "centre": CentreRule(),
    "radius": Rule("float", positive=True),
    "side": Rule("str", choices=("inner", "back")),
    "inertia": Rule("float", positive=True),
    "friction_coefficient": Rule("float", positive=True),
    "speed": PROFILE,
    "load_torque": LoadRule(),
}
PULLEY_REQUIRED = ("name", "centre", "radius")


@dataclass(frozen=True)
class PulleySpec:
    """One pulley of a drive, as its scene states it (SI units; profiles as given)."""

    name: str
    centre: tuple[float, float]
    radius: float
    side: int  # +1 inner (inside the loop), -1 back (a back-side idler)
    inertia: float  # 0 for the driver (its speed is prescribed)
    mu: float | None  # its own friction coefficient; None: [contact]'s
    speed: object = None  # the driver's speed profile (rad/s)
    load: object = None  # a driven pulley's load torque profile (N m)

    @property
    def role(self) -> str:
        """"driver", "driven" (a load) or "idler"."""
        if self.speed is not None:
            return "driver"
        return "driven" if self.load is not None else "idler"

    @property
    def final_load(self) -> float:
        """The load torque the drive settles on (N m; 0 for the driver and idlers)."""
        return 0.0 if self.load is None else float(final_value(self.load))


def checked_keys(table: dict, rules: dict, required, prefix: str, section: str) -> dict:
    """A table's keys checked by their rules (named ``PREFIX.KEY``), the required ones
    present; the first broken rule raises SceneError naming its key."""
    clean = {}
    for key, value in table.items():
        if key not in rules:
            raise SceneError(f"{prefix}.{key}", f"unknown key (known in {section}: "
                             f"{', '.join(rules)})")
        clean[key] = rules[key].check(f"{prefix}.{key}", value)
    for key in required:
        if key not in clean:
            raise SceneError(f"{prefix}.{key}", "missing key")
    return clean


def check_pulleys(raw, contact: dict) -> list[dict]:
    """The ``[[pulley]]`` tables checked key by key, normalised (``side`` filled in).

    Raises
    ------
    SceneError
        The first broken rule, naming ``pulley.NAME.KEY`` (or ``pulley[i]`` before the
        name is known).
    """
    if not isinstance(raw, list) or not all(isinstance(p, dict) for p in raw):
        raise SceneError("pulley", "must be an array of tables ([[pulley]] sections)")
    if len(raw) < 2:
        raise SceneError("pulley", f"a drive needs at least 2 pulleys, got {len(raw)}")
    out, names = [], set()
    for i, table in enumerate(raw):
        where = f"pulley[{i}]"
        if "name" not in table:
            raise SceneError(f"{where}.name", "missing key")
        name = PULLEY_RULES["name"].check(f"{where}.name", table["name"])
        if not name or "." in name or name != name.strip():
            raise SceneError(f"{where}.name", f"must be a non-empty name without dots or "
                             f"surrounding spaces, got {show(name)}")
        if name in names:
            raise SceneError(f"pulley.{name}.name", "a second pulley of this name: names "
                             "must be unique")
        names.add(name)
        clean = checked_keys(table, PULLEY_RULES, PULLEY_REQUIRED, f"pulley.{name}",
                             "[[pulley]]")
        clean.setdefault("side", "inner")
        if "speed" in clean and "load_torque" in clean:
            raise SceneError(f"pulley.{name}.load_torque", "not on the driver (the pulley "
                             "with speed): a driver delivers what the others consume")
        if "speed" in clean and "inertia" in clean:
            raise SceneError(f"pulley.{name}.inertia", "not on the driver: its speed is "
                             "prescribed, so its inertia plays no part")
        if "speed" not in clean and "inertia" not in clean:
            raise SceneError(f"pulley.{name}.inertia", "missing key (every pulley but the "
                             "driver turns freely and needs its inertia, kg m^2)")
        if "friction_coefficient" in clean and contact["friction"] == "stick":
            raise SceneError(f"pulley.{name}.friction_coefficient", 'only for '
                             'contact.friction = "coulomb" (this scene is "stick")')
        out.append(clean)
    drivers = [p["name"] for p in out if "speed" in p]
    if not drivers:
        raise SceneError("pulley", "no driver: exactly one [[pulley]] has speed (rad/s)")
    if len(drivers) > 1:
        raise SceneError(f"pulley.{drivers[1]}.speed", f"a second driver (pulley "
                         f"{drivers[0]} has speed already): exactly one pulley has speed")
    return out


def specs_of(d: dict) -> tuple[PulleySpec, ...]:
    """A validated drive scene's pulleys in the belt's order, from ``[[pulley]]`` tables
    or the two-pulley shorthand."""
    if "pulley" not in d:
        drive = d["drive"]
        return (PulleySpec("driver", (0.0, 0.0), drive["driver_radius"], 1, 0.0, None,
                           speed=drive["driver_speed"]),
                PulleySpec("driven", (float(drive["centre_distance"]), 0.0),
                           drive["driven_radius"], 1, drive["driven_inertia"], None,
                           load=drive["load_torque"]))
    return tuple(
        PulleySpec(p["name"], (float(p["centre"][0]), float(p["centre"][1])), p["radius"],
                   1 if p["side"] == "inner" else -1, p.get("inertia", 0.0),
                   p.get("friction_coefficient"), speed=p.get("speed"),
                   load=p.get("load_torque"))
        for p in d["pulley"])


def driver_index(specs) -> int:
    """The index of the driver among the pulleys."""
    return next(i for i, p in enumerate(specs) if p.role == "driver")


def installation_tension(drive: dict, loop_length: float, b1: float) -> float:
    """N0 (N): ``[drive] installation_tension``, or that of an unstretched
    ``belt_length`` L0 on the layout as drawn (b1 (Lambda - L0) = N0 Lambda, the
    closure of the model's linear strain)."""
    if "installation_tension" in drive:
        return drive["installation_tension"]
    L0 = drive["belt_length"]
    N0 = b1 * (loop_length - L0) / loop_length
    if not N0 > 0:
        raise SceneError("drive.belt_length", f"must be shorter than the layout's loop "
                         f"length {loop_length:.6g} m (the belt would be slack), got "
                         f"{L0!r}")
    return N0


def max_rim_speed(specs) -> float:
    """The largest rim speed (m/s) of the driver's speed profile."""
    p = specs[driver_index(specs)]
    return profile_extremes(p.speed)[1] * p.radius

