"""Closed-drive scenes: a belt loop on a driver and a driven pulley.

A scene with a ``[drive]`` section is a closed drive. Its sections:

* ``[belt]``: the belt's cross-section and material (the ``[beam]`` keys without
  ``length``: the loop's length follows from the geometry);
* ``[stiffness]`` (optional): a, b1, b2, rho, I given directly, as for a straight belt;
* ``[drive]``: the pulleys, the pretension, the driver's speed, the load and the driven
  pulley's inertia;
* ``[contact]``: ``friction`` ("coulomb" or "stick") and ``friction_coefficient`` (mu);
* ``[physics]``: ``inertia``, ``damping`` and ``model`` ("beam": the shear-deformable
  beam; "string": the extensible string, whose friction has no lever about the middle
  line);
* ``[tensioner]`` (optional): an idler on a spring-loaded arm
  (:mod:`beltsim.beltdrive.tensioner`);
* ``[numerics]``: how the problem is solved, never which problem.

Validation happens in :func:`validate`; every rule raises a one-line
:class:`~beltsim.errors.SceneError` naming the key.
"""

from __future__ import annotations

import copy
import math
from dataclasses import replace

from ..errors import NoSolutionError, SceneError
from ..problem.rules import (
    BELT_RULES,
    POS,
    PROFILE,
    RETIRED,
    STIFFNESS_RULES,
    Rule,
    set_scene_key,
    show,
)
from ..problem.tables import SceneTables
from .analytic import LiftOffError
from .creep import solve_serpentine
from .exact import serpentine_data, string_state
from .geometry import Geometry, GeometryError
from .params import DriveParams, params_of
from .pulley_tables import SHORTHAND, LoadRule, check_pulleys, specs_of
from .pulley_tables import max_rim_speed as driver_rim_speed
from .tensioner import TENSIONER_RULES, check_tensioner

__all__ = ["MIN_SEGMENT_ELEMENTS", "OPTIONAL_SECTIONS", "REQUIRED", "SCHEMA", "DriveParams",
           "DriveScene", "driver_speed_key", "max_rim_speed", "set_key", "validate"]

#: The fewest elements on each of the loop's four segments.
MIN_SEGMENT_ELEMENTS = 4


#: Sections of a drive scene, their keys and rules.
SCHEMA: dict[str, dict[str, Rule]] = {
    # the straight belt's [beam] keys but its length (the loop's follows from the drive)
    "belt": {k: rule for k, rule in BELT_RULES.items() if k != "length"},
    "stiffness": dict(STIFFNESS_RULES),
    "drive": {
        "driver_radius": POS,
        "driven_radius": POS,
        "centre_distance": POS,
        "installation_tension": POS,
        "belt_length": POS,
        "driver_speed": PROFILE,
        "load_torque": LoadRule(),
        "driven_inertia": POS,
    },
    "contact": {
        "friction": Rule("str", choices=("stick", "coulomb")),
        "friction_coefficient": POS,
    },
    "physics": {
        "inertia": Rule("bool"),
        "damping": Rule("float", nonneg=True),
        "model": Rule("str", choices=("beam", "string")),
    },
    "numerics": {
        "integrator": Rule("str"),  # a registered scheme: beltsim.solvers checks it
        "elements": Rule("int", minimum=4 * MIN_SEGMENT_ELEMENTS),
        "dt": POS,
        "t_end": POS,
        "ramp_time": Rule("float", nonneg=True),
        "friction_law": Rule("str", choices=("exact", "tanh", "sqrt")),
        "regularisation": POS,
        "time_tol": POS,
        "steady_tol": POS,
        "newton_tol": POS,
        "newton_max_iterations": Rule("int", minimum=1),
        "snapshot_interval": POS,
        "gyroscopic": Rule("str", choices=("upwind", "central")),
        "transient": Rule("str", choices=("fast", "physical")),
        "acceleration": Rule("float", nonneg=True),
        "max_work": POS,
    },
    "tensioner": dict(TENSIONER_RULES),
}
REQUIRED = {"belt": ("height", "width", "youngs_modulus", "poisson_ratio", "shear_factor"),
            "contact": ("friction",),
            "physics": ("inertia",)}
OPTIONAL_SECTIONS = ("stiffness", "numerics", "tensioner")


def validate(data: dict) -> dict:
    """Check a drive scene's data and return a normalised deep copy.

    Raises
    ------
    SceneError
        On the first broken rule, naming the key and the rule.
    """
    if not isinstance(data, dict):
        raise SceneError("scene: must be a TOML table")
    out: dict = {}
    for key, value in data.items():
        if key == "title":
            if not isinstance(value, str):
                raise SceneError("title", f"must be a string, got {show(value)}")
            out["title"] = value
        elif key in SCHEMA:
            if not isinstance(value, dict):
                raise SceneError(f"[{key}]", f"must be a table (section), got {show(value)}")
        elif key == "pulley":
            pass  # checked below, with [contact] (the pulleys' default friction)
        elif key in ("beam", "motion"):
            raise SceneError(f"[{key}]", "not in a closed drive (a scene with [drive] "
                             "describes its belt in [belt] and its motion in [drive])")
        else:
            known = ", ".join([f"[{s}]" for s in SCHEMA] + ["title"])
            raise SceneError(key, f"unknown section or key of a drive scene (known: {known})")
    for section, rules in SCHEMA.items():
        if section not in data:
            if section not in OPTIONAL_SECTIONS:
                raise SceneError(f"[{section}]", "missing section")
            continue
        clean = {}
        for key, value in data[section].items():
            name = f"{section}.{key}"
            if (section, key) in RETIRED:
                raise SceneError(name, RETIRED[section, key])
            if key not in rules:
                raise SceneError(name, f"unknown key (known in [{section}]: "
                                 f"{', '.join(rules)})")
            clean[key] = rules[key].check(name, value)
        out[section] = clean
    for section, keys in REQUIRED.items():
        for key in keys:
            if key not in out[section]:
                raise SceneError(f"{section}.{key}", "missing key")
    if "pulley" in data:
        out["pulley"] = check_pulleys(data["pulley"], out["contact"])
    if "tensioner" in out:
        out["tensioner"] = check_tensioner(out["tensioner"], out.get("pulley"))
    check_drive_keys(out)
    contact, physics = out["contact"], out["physics"]
    if contact["friction"] == "coulomb" and "friction_coefficient" not in contact:
        raise SceneError("contact.friction_coefficient",
                         'missing key (required when contact.friction = "coulomb")')
    if contact["friction"] == "stick" and "friction_coefficient" in contact:
        raise SceneError("contact.friction_coefficient",
                         'only for contact.friction = "coulomb" (this scene is "stick")')
    if physics["inertia"] and "density" not in out["belt"] and not {
            "mass", "rotary_inertia"} <= set(out.get("stiffness", {})):
        raise SceneError("belt.density", "missing key (required when physics.inertia = true)")
    if not physics["inertia"]:
        for key in ("mass", "rotary_inertia"):
            if key in out.get("stiffness", {}):
                raise SceneError(f"stiffness.{key}", "only for physics.inertia = true (a "
                                 "quasistatic scene has no inertia terms)")
    num = out.get("numerics", {})
    law = num.get("friction_law")
    if contact["friction"] == "stick" and law not in (None, "exact"):
        raise SceneError("numerics.friction_law", f'a "stick" drive takes only "exact", '
                         f'got "{law}"')
    if num.get("gyroscopic", "upwind") != "upwind" and num.get("integrator") == "explicit":
        raise SceneError("numerics.gyroscopic", '"central" is for the implicit schemes; the '
                         'explicit scheme has the upwind form only')
    if "regularisation" in num and (law in (None, "exact")):
        raise SceneError("numerics.regularisation", 'only with a regularised '
                         'numerics.friction_law ("tanh" or "sqrt"): exact friction has none')
    try:
        if "pulley" not in out:  # the shorthand's rule names its own key
            d = out["drive"]
            Geometry(d["driver_radius"], d["driven_radius"], d["centre_distance"])
        P = params_of(out)
    except GeometryError as exc:
        raise SceneError(str(exc)) from None
    speed_key = driver_speed_key(out)
    if P.rho > 0 and max_rim_speed(out) ** 2 * P.rho >= P.b1:
        raise SceneError(speed_key, f"the rim speed reaches the belt's critical "
                         f"speed sqrt(b1 / rho) = {math.sqrt(P.b1 / P.rho):.4g} m/s")
    if P.model == "beam" and P.I > 0 and max_rim_speed(out) ** 2 * P.I >= P.a:
        raise SceneError(speed_key, f"the rim speed reaches the beam's bending "
                         f"critical speed sqrt(a / I) = {math.sqrt(P.a / P.I):.4g} m/s "
                         f'(a - I c^2 <= 0: no steady state; physics.model = "string" has '
                         f"none)")
    if P.tensioner is not None:
        unloaded = replace(serpentine_data(P), loads=(0.0,) * len(P.pulleys))
        try:
            solve_serpentine(unloaded)
        except NoSolutionError as exc:
            raise SceneError("tensioner.preload", f"the arm has no equilibrium with the "
                             f"drive unloaded: {exc}") from None
    try:
        string_state(P)
    except LiftOffError as exc:
        raise SceneError(str(exc)) from None
    except NoSolutionError:
        pass  # gross slip is a run's physical outcome; the steady solve refuses it
    return out


def set_key(data: dict, key: str, value) -> None:
    """Set ``SECTION.KEY`` (or ``title``) in a drive scene's tables; the section must be
    one a drive has (:func:`validate` checks the key and its value)."""
    if key.startswith("pulley."):
        parts = key.split(".")
        tables = data.get("pulley", [])
        names = [t.get("name") for t in tables]
        if len(parts) != 3 or parts[1] not in names:
            raise SceneError(key, f"expected pulley.NAME.KEY with NAME one of the scene's "
                             f"pulleys ({', '.join(map(str, names)) or 'none'})")
        tables[names.index(parts[1])][parts[2]] = value
        return
    set_scene_key(data, key, value, SCHEMA, "a drive scene", known_keys=False)


def driver_speed_key(data: dict) -> str:
    """The key of the driver's speed in a drive scene's tables: ``drive.driver_speed`` in
    the two-pulley shorthand, else ``pulley.NAME.speed`` of the pulley that has one."""
    if "pulley" not in data:
        return "drive.driver_speed"
    return f"pulley.{next(t['name'] for t in data['pulley'] if 'speed' in t)}.speed"


def max_rim_speed(data: dict) -> float:
    """The largest rim speed omega r (m/s) of the driver's speed profile."""
    return driver_rim_speed(specs_of(data))


def check_drive_keys(out: dict) -> None:
    """[drive]'s keys with or without [[pulley]] tables: the shorthand's six keys, or
    none of them, and one of installation_tension and belt_length."""
    drive = out["drive"]
    if "pulley" in out:
        for key in SHORTHAND:
            if key in drive:
                raise SceneError(f"drive.{key}", "the two-pulley shorthand is not for a "
                                 "scene with [[pulley]] tables (give the pulleys there)")
    else:
        for key in SHORTHAND:
            if key not in drive:
                raise SceneError(f"drive.{key}", "missing key (or give the pulleys as "
                                 "[[pulley]] tables)")
    given = [k for k in ("installation_tension", "belt_length") if k in drive]
    if len(given) != 1:
        raise SceneError("drive.installation_tension", "give exactly one of "
                         "installation_tension and belt_length" + (
                             "" if given else " (missing)"))


class DriveScene(SceneTables):
    """A validated closed-drive scene (:class:`~beltsim.problem.tables.SceneTables`:
    read, written and derived as a straight belt's scene is).

    Raises
    ------
    SceneError
        On the first broken rule, naming the key and the rule.

    Examples
    --------
    >>> heavier = scene.replace(drive=scene.drive | {"load_torque": 40.0})  # doctest: +SKIP
    """

    SCHEMA = SCHEMA
    OPTIONAL = OPTIONAL_SECTIONS
    KIND = "a drive scene"
    validate = staticmethod(validate)
    set_key = staticmethod(set_key)

    def __init__(self, data: dict, source: str | None = None):
        super().__init__(data, source)
        self.params = params_of(self._data)

    def at_arm(self, beta: float) -> DriveScene:
        """This scene with its tensioner's arm turned by ``beta`` (rad) into the belt:
        the same tables (the scene as written), ``params`` on the turned layout with the
        same belt (:meth:`DriveParams.at_arm`). A steady solve takes it as one layout of
        its search for the arm's rest angle."""
        out = copy.copy(self)
        out.params = self.params.at_arm(beta)
        return out

    @property
    def numerics(self) -> dict:
        """The ``[numerics]`` table as given (defaults are resolved by the solver)."""
        return dict(self._data.get("numerics", {}))

    @property
    def drive(self) -> dict:
        """The ``[drive]`` table."""
        return dict(self._data["drive"])
