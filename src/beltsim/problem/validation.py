"""The straight belt's scene rules: its sections and keys,
:func:`~beltsim.problem.validation.validate` and the derived physical data
(:class:`~beltsim.problem.validation.Params`).

Validation happens in one place for files, dictionaries and ``--set`` overrides alike,
and every rule raises :class:`~beltsim.errors.SceneError` with a one-line message that
names the key and the rule. The rules shared with the closed drive are in
:mod:`beltsim.problem.rules`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import SceneError
from .rules import (
    BELT_RULES,
    POS,
    PROFILE,
    RETIRED,
    STIFFNESS_RULES,
    Rule,
    derived_stiffness,
    final_value,
    profile_extremes,
    set_scene_key,
    show,
)

#: The fewest elements of a grid: two in each of [0, x1], [x1, x2], [x2, L].
MIN_ELEMENTS = 6

#: Sections, their keys and rules.
SCHEMA: dict[str, dict[str, Rule]] = {
    "beam": dict(BELT_RULES),
    "motion": {"belt_speed": POS, "surface_speed": PROFILE},
    "contact": {
        "start": Rule("float"),
        "end": Rule("float"),
        "friction": Rule("str", choices=("stick", "coulomb")),
        "max_friction": PROFILE,
    },
    "physics": {"inertia": Rule("bool"), "damping": Rule("float", nonneg=True)},
    "stiffness": dict(STIFFNESS_RULES),
    "numerics": {
        "integrator": Rule("str"),  # a registered scheme: beltsim.solvers checks it
        "elements": Rule("int", minimum=MIN_ELEMENTS),
        "grading": Rule("float", minimum=1.0),
        "dt": POS,
        "t_end": POS,
        "ramp_time": Rule("float", nonneg=True),
        "regularisation": POS,
        "friction_law": Rule("str", choices=("tanh", "sqrt", "ramp", "exact")),
        "adhesion_layer": POS,
        "acceleration": Rule("float", nonneg=True),
        "time_tol": POS,
        "steady_tol": POS,
        "snapshot_interval": POS,
        "newton_tol": POS,
        "newton_max_iterations": Rule("int", minimum=1),
        "max_work": POS,
        "gyroscopic": Rule("str", choices=("upwind", "central")),
        "transient": Rule("str", choices=("fast", "physical")),
    },
}

REQUIRED_SECTIONS = ("beam", "motion", "contact", "physics")
OPTIONAL_SECTIONS = ("stiffness", "numerics")
TOP_LEVEL_KEYS = ("title",)

# Keys that only make sense for some scenes ("a scene holds only what it needs").
_ONLY_COULOMB = {("contact", "max_friction"), ("numerics", "regularisation")}
_ONLY_STICK = {("numerics", "adhesion_layer")}
# (physics.damping, like beam.density, describes the belt and is ignored without inertia)
_ONLY_INERTIA = {("stiffness", "mass"), ("stiffness", "rotary_inertia"),
                 ("numerics", "acceleration"), ("numerics", "gyroscopic"),
                 ("numerics", "transient")}
# Keys of required sections that may be left out (default in Params).
_OPTIONAL_KEYS = {("physics", "damping")}


def validate(data: dict) -> dict:
    """Check a scene dictionary and return a normalised deep copy.

    Raises SceneError on the first broken rule.
    """
    if not isinstance(data, dict):
        raise SceneError("scene: must be a TOML table")
    out: dict = {}
    if "drive" in data:
        raise SceneError("[drive]", "a closed drive: read it with beltsim.load_scene or "
                         "beltsim.beltdrive.scene.DriveScene")
    for key, value in data.items():
        if key in SCHEMA:
            if not isinstance(value, dict):
                raise SceneError(f"[{key}]", f"must be a table (section), got {show(value)}")
            continue
        if key == "title":
            if not isinstance(value, str):
                raise SceneError("title", f"must be a string, got {show(value)}")
            out["title"] = value
            continue
        known = ", ".join([f"[{s}]" for s in SCHEMA] + list(TOP_LEVEL_KEYS))
        raise SceneError(key, f"unknown section or key (known: {known})")
    for section in REQUIRED_SECTIONS:
        if section not in data:
            raise SceneError(f"[{section}]", "missing section")
    for section, rules in SCHEMA.items():
        if section not in data:
            continue
        table = data[section]
        clean = {}
        for key, value in table.items():
            name = f"{section}.{key}"
            if (section, key) in RETIRED:
                raise SceneError(f"{section}.{key}", RETIRED[section, key])
            if key not in rules:
                raise SceneError(name, f"unknown key (known in [{section}]: "
                                 f"{', '.join(rules)})")
            clean[key] = rules[key].check(name, value)
        out[section] = clean

    friction = out["contact"].get("friction")
    inertia = out["physics"].get("inertia")
    for section, rules in SCHEMA.items():
        if section in OPTIONAL_SECTIONS:
            continue
        for key in rules:
            if key in out[section]:
                continue
            name = f"{section}.{key}"
            if (section, key) == ("contact", "max_friction"):
                if friction == "coulomb":
                    raise SceneError(name, "missing key (required when contact.friction = "
                                     '"coulomb")')
                continue
            if (section, key) == ("beam", "density") and inertia is False:
                continue  # a quasistatic scene needs no density
            if (section, key) in _OPTIONAL_KEYS:
                continue
            raise SceneError(name, "missing key")

    for section, key in _ONLY_COULOMB:
        if key in out.get(section, {}) and friction != "coulomb":
            raise SceneError(f"{section}.{key}", f'only for contact.friction = "coulomb" '
                             f'(this scene is "{friction}")')
    for section, key in _ONLY_STICK:
        if key in out.get(section, {}) and friction != "stick":
            raise SceneError(f"{section}.{key}", f'only for contact.friction = "stick" '
                             f'(this scene is "{friction}")')
    law = out.get("numerics", {}).get("friction_law")
    if friction == "stick" and law not in (None, "exact"):
        raise SceneError("numerics.friction_law", f'a "stick" scene takes only "exact" (exact '
                         f'adhesion) or none (the adhesion layer), got "{law}"')
    if law == "exact":
        for key in ("regularisation", "adhesion_layer"):
            if key in out["numerics"]:
                raise SceneError(f"numerics.{key}", 'not with numerics.friction_law = "exact" '
                                 "(exact friction has no regularisation)")
    numerics = out.get("numerics", {})
    if numerics.get("gyroscopic", "upwind") != "upwind" and (
            numerics.get("integrator") == "explicit"):
        raise SceneError("numerics.gyroscopic", '"central" is for the implicit schemes; the '
                         'explicit scheme has the upwind form only')
    for section, key in _ONLY_INERTIA:
        if key in out.get(section, {}) and not inertia:
            raise SceneError(f"{section}.{key}", "only for physics.inertia = true "
                             "(a quasistatic scene has no inertia terms)")

    beam, contact = out["beam"], out["contact"]
    L, x1, x2 = beam["length"], contact["start"], contact["end"]
    if not x1 < x2:
        raise SceneError("contact.start", f"must be < contact.end, got start = {x1!r}, "
                         f"end = {x2!r}")
    if not (0.0 < x1 and x2 < L):
        raise SceneError("contact.start/end", f"the contact must lie inside the beam, "
                         f"0 < start < end < beam.length = {L!r}, got [{x1!r}, {x2!r}]")

    P = params_of(out)
    if P.inertia and (P.rho * P.c**2 >= P.b1 or P.I * P.c**2 >= P.a):
        c_t, c_b = P.critical_speeds
        raise SceneError(
            "motion.belt_speed", f"must stay below both critical speeds, "
            f"sqrt(b1/rho) = {c_t:.6g} m/s and sqrt(a/I) = {c_b:.6g} m/s, got {P.c!r} m/s")
    speed = out["motion"]["surface_speed"]
    if P.inertia and not isinstance(speed, float):
        top, crit = profile_extremes(speed)[1], min(P.critical_speeds)
        if top >= crit:
            raise SceneError("motion.surface_speed", f"every speed of the profile must stay "
                             f"below both critical speeds (the lower is {crit:.6g} m/s), "
                             f"got {top!r} m/s")
    periods = {k: v["period"] for k, v in (("motion.surface_speed", speed),
               ("contact.max_friction", out["contact"].get("max_friction")))
               if isinstance(v, dict)}
    if len(set(periods.values())) > 1:
        raise SceneError("contact.max_friction.period", "must equal motion.surface_speed.period "
                         "(a run has one periodic steady state), got "
                         f"{periods['contact.max_friction']!r} and "
                         f"{periods['motion.surface_speed']!r}")
    return out


@dataclass(frozen=True)
class Params:
    """The physical data a solver needs, in SI units.

    ``rho`` and ``I`` are zero for a quasistatic scene and ``fstar`` is None
    for a stick scene: a scene carries only the terms it has.
    """

    L: float
    h: float
    x1: float
    x2: float
    c: float
    v: float  # the surface speed the drive settles on (a profile's final value)
    a: float
    b1: float
    b2: float
    rho: float
    I: float
    inertia: bool
    friction: str
    fstar: float | None  # the friction limit the drive settles on (final value)
    damping: float = 0.0  # d (1/s) of the viscous damping d rho u_t, d I theta_t

    @property
    def e0(self) -> float:
        """Imposed strain of the bottom fibre in stick, v/c - 1."""
        return self.v / self.c - 1.0

    @property
    def A(self) -> float:
        """Effective bending stiffness a - I c^2."""
        return self.a - self.I * self.c**2

    @property
    def B(self) -> float:
        """Effective tension stiffness b1 - rho c^2."""
        return self.b1 - self.rho * self.c**2

    @property
    def critical_speeds(self) -> tuple[float, float]:
        """sqrt(b1/rho) and sqrt(a/I); infinite for a quasistatic scene."""
        if not self.inertia:
            return math.inf, math.inf
        return math.sqrt(self.b1 / self.rho), math.sqrt(self.a / self.I)


def params_of(d: dict) -> Params:
    """The physical data of a validated scene's tables."""
    p = derived_stiffness(d)
    contact = d["contact"]
    return Params(
        L=d["beam"]["length"], h=d["beam"]["height"],
        x1=contact["start"], x2=contact["end"],
        c=d["motion"]["belt_speed"], v=final_value(d["motion"]["surface_speed"]),
        a=p["a"], b1=p["b1"], b2=p["b2"], rho=p["rho"], I=p["I"],
        inertia=d["physics"]["inertia"], friction=contact["friction"],
        fstar=(final_value(contact["max_friction"]) if "max_friction" in contact else None),
        damping=d["physics"].get("damping", 0.0) if d["physics"]["inertia"] else 0.0,
    )



def set_key(data: dict, key: str, value) -> None:
    """Set ``SECTION.KEY`` in a scene dict; the key must be one the schema knows."""
    set_scene_key(data, key, value, SCHEMA)

