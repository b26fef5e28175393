"""Scenes: parsing, validation and the derived physical parameters.

A scene is a TOML file in SI units. Validation happens in one place
(:func:`validate`) for files, dictionaries and ``--set`` overrides alike, and
every rule raises :class:`~beltsim.errors.SceneError` with a one-line message
that names the key and the rule.
"""

from __future__ import annotations

import copy
import math
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Generic, TypeVar

from ..errors import MissingInputError, SceneError
from .builder import (
    SECTIONS,
    Beam,
    Contact,
    Motion,
    NumericsSection,
    Physics,
    Section,
    Stiffness,
)

# ---------------------------------------------------------------------------
# Schema


class _Rule:
    """Type and range rule of one key."""

    def __init__(self, kind, *, positive=False, nonneg=False, choices=None, interval=None,
                 minimum=None):
        self.kind = kind  # "float", "int", "bool", "str"
        self.positive = positive
        self.nonneg = nonneg
        self.choices = choices
        self.interval = interval  # open interval (lo, hi)
        self.minimum = minimum  # inclusive lower bound (ints, floats)

    def check(self, key, value):
        if self.kind in ("float", "int"):
            if self.kind == "float":
                value = _number(key, value)
            else:
                if isinstance(value, bool) or not isinstance(value, (int, float)):
                    raise SceneError(key, f"must be a number, got {_show(value)}")
                if isinstance(value, float):
                    if not (math.isfinite(value) and value == int(value)):
                        raise SceneError(key, f"must be a whole number, got {_show(value)}")
                    value = int(value)
            if self.positive and not value > 0:
                raise SceneError(key, f"must be > 0, got {_show(value)}")
            if self.nonneg and not value >= 0:
                raise SceneError(key, f"must be >= 0, got {_show(value)}")
            if self.minimum is not None and value < self.minimum:
                raise SceneError(key, f"must be >= {self.minimum}, got {_show(value)}")
            if self.interval is not None:
                lo, hi = self.interval
                if not lo < value < hi:
                    raise SceneError(key, f"must lie in the open interval ({lo}, {hi}), "
                                     f"got {_show(value)}")
            return value
        if self.kind == "bool":
            if not isinstance(value, bool):
                raise SceneError(key, f"must be true or false, got {_show(value)}")
            return value
        if self.kind == "str":
            if not isinstance(value, str):
                raise SceneError(key, f"must be a string, got {_show(value)}")
            if self.choices is not None and value not in self.choices:
                opts = " | ".join(f'"{c}"' for c in self.choices)
                raise SceneError(key, f"must be one of {opts}, got {_show(value)}")
            return value
        if self.kind == "profile":
            return _check_profile(key, value)
        raise AssertionError(self.kind)


SINE_KEYS = ("mean", "amplitude", "period")


def _number(key, value):
    """A finite number as a float, or the one-line error of a float key."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise SceneError(key, f"must be a number, got {_show(value)}")
    if not math.isfinite(value):
        raise SceneError(key, f"must be finite, got {_show(value)}")
    return float(value)


def check_table(key, value: list, zero_allowed: bool = False) -> list:
    """A table of [time, value] rows: times increasing strictly, values > 0 (>= 0 with
    ``zero_allowed``), as a list of [float, float]."""
    if not value:
        raise SceneError(key, "a table needs at least one [time, value] row")
    rows = []
    for i, row in enumerate(value, 1):
        name = f"{key} row {i}"
        if not isinstance(row, list) or len(row) != 2:
            raise SceneError(name, f"must be a [time, value] pair, got {_show(row)}")
        t, v = _number(f"{name} time", row[0]), _number(f"{name} value", row[1])
        if rows and not t > rows[-1][0]:
            raise SceneError(name, f"times must increase strictly, got {t!r} after "
                             f"{rows[-1][0]!r}")
        if not (v >= 0 if zero_allowed else v > 0):
            raise SceneError(f"{name} value", f"must be {'>=' if zero_allowed else '>'} 0, "
                             f"got {v!r}")
        rows.append([t, v])
    return rows


def _check_profile(key, value):
    """A positive quantity over time: a number, a table of [time, value] rows, or a sine.

    Tables are interpolated linearly and held before the first and after the last row;
    a sine is { mean, amplitude, period } (value mean + amplitude sin(2 pi t / period)).
    """
    if isinstance(value, dict):
        for k in value:
            if k not in SINE_KEYS:
                raise SceneError(f"{key}.{k}", "unknown key of a sine (known: "
                                 f"{', '.join(SINE_KEYS)})")
        for k in SINE_KEYS:
            if k not in value:
                raise SceneError(f"{key}.{k}", "missing key of a sine (a sine is "
                                 "{ mean = ..., amplitude = ..., period = ... })")
        out = {k: _number(f"{key}.{k}", value[k]) for k in SINE_KEYS}
        if not out["period"] > 0:
            raise SceneError(f"{key}.period", f"must be > 0, got {out['period']!r}")
        if not out["mean"] - abs(out["amplitude"]) > 0:
            raise SceneError(key, f"must stay > 0, got mean - |amplitude| = "
                             f"{out['mean'] - abs(out['amplitude'])!r}")
        return out
    if isinstance(value, list):
        return check_table(key, value)
    value = _number(key, value)
    if not value > 0:
        raise SceneError(key, f"must be > 0, got {value!r}")
    return value


def final_value(value) -> float:
    """The value a profile settles on: the number, the last row, or a sine's mean."""
    if isinstance(value, list):
        return value[-1][1]
    if isinstance(value, dict):
        return value["mean"]
    return value


def profile_extremes(value) -> tuple[float, float]:
    """The smallest and largest value a profile takes."""
    if isinstance(value, list):
        vals = [row[1] for row in value]
        return min(vals), max(vals)
    if isinstance(value, dict):
        return value["mean"] - abs(value["amplitude"]), value["mean"] + abs(value["amplitude"])
    return value, value


def _show(value):
    if isinstance(value, str):
        return repr(value)
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, list):
        return "an array"
    return repr(value)


POS = _Rule("float", positive=True)
PROFILE = _Rule("profile")
#: The fewest elements of a grid: two in each of [0, x1], [x1, x2], [x2, L].
MIN_ELEMENTS = 6

#: Sections, their keys and rules. ``None`` in REQUIRED means optional section.
SCHEMA: dict[str, dict[str, _Rule]] = {
    "beam": {
        "length": POS,
        "height": POS,
        "width": POS,
        "youngs_modulus": POS,
        "poisson_ratio": _Rule("float", interval=(-1.0, 0.5)),
        "density": POS,
        "shear_factor": POS,
    },
    "motion": {"belt_speed": POS, "surface_speed": PROFILE},
    "contact": {
        "start": _Rule("float"),
        "end": _Rule("float"),
        "friction": _Rule("str", choices=("stick", "coulomb")),
        "max_friction": PROFILE,
    },
    "physics": {"inertia": _Rule("bool"), "damping": _Rule("float", nonneg=True)},
    "stiffness": {
        "bending": POS,
        "tension": POS,
        "shear": POS,
        "mass": POS,
        "rotary_inertia": POS,
    },
    "numerics": {
        "integrator": _Rule("str"),  # a registered scheme: beltsim.solvers checks it
        "elements": _Rule("int", minimum=MIN_ELEMENTS),
        "grading": _Rule("float", minimum=1.0),
        "dt": POS,
        "t_end": POS,
        "ramp_time": _Rule("float", nonneg=True),
        "regularisation": POS,
        "friction_law": _Rule("str", choices=("tanh", "sqrt", "ramp", "exact")),
        "adhesion_layer": POS,
        "acceleration": _Rule("float", nonneg=True),
        "time_tol": POS,
        "steady_tol": POS,
        "snapshot_interval": POS,
        "newton_tol": POS,
        "newton_max_iterations": _Rule("int", minimum=1),
        "max_work": POS,
        "gyroscopic": _Rule("str", choices=("upwind", "central")),
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
                 ("numerics", "acceleration"), ("numerics", "gyroscopic")}
# Keys of required sections that may be left out (default in Params).
_OPTIONAL_KEYS = {("physics", "damping")}
# Keys that were, and what replaces them.
_RETIRED = {
    ("numerics", "damping"): (
        "removed, damping is physics now: set physics.damping (1/s, the "
        "rate d of d rho u_t and d I theta_t), or, for a fast path to the steady state "
        'whose transient does not matter, numerics.integrator = "pseudo" with '
        "numerics.acceleration (1/s)"),
}


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
                raise SceneError(f"[{key}]", f"must be a table (section), got {_show(value)}")
            continue
        if key == "title":
            if not isinstance(value, str):
                raise SceneError("title", f"must be a string, got {_show(value)}")
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
            if (section, key) in _RETIRED:
                raise SceneError(f"{section}.{key}", _RETIRED[section, key])
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

    P = _params(out)
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


def _stiffness(d: dict) -> dict:
    """Stiffness and inertia per unit length: derived from [beam], overridden by [stiffness]."""
    beam = d["beam"]
    over = d.get("stiffness", {})
    E, nu, k = beam["youngs_modulus"], beam["poisson_ratio"], beam["shear_factor"]
    h, w = beam["height"], beam["width"]
    p = {
        "a": over.get("bending", E * w * h**3 / 12.0),
        "b1": over.get("tension", E * w * h),
        "b2": over.get("shear", k * E * w * h / (2.0 * (1.0 + nu))),
        "rho": 0.0,
        "I": 0.0,
    }
    if d["physics"]["inertia"]:
        rho3 = beam.get("density")
        if rho3 is None and ("mass" not in over or "rotary_inertia" not in over):
            raise SceneError("beam.density", "missing key")
        p["rho"] = over.get("mass", (rho3 or 0.0) * h * w)
        p["I"] = over.get("rotary_inertia", (rho3 or 0.0) * h * w * (h * h + w * w) / 12.0)
    return p


# ---------------------------------------------------------------------------
# Parameters


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


def _params(d: dict) -> Params:
    p = _stiffness(d)
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


# ---------------------------------------------------------------------------
# Scene


S = TypeVar("S", bound=Section)


class _SectionOf(Generic[S]):
    """A scene's section as its dataclass: ``scene.beam`` is a :class:`Beam`."""

    def __init__(self, cls: type[S]):
        self.cls = cls
        self.__doc__ = f"The ``[{cls.section}]`` section, a :class:`{cls.__name__}`."

    def __get__(self, scene, owner=None) -> S:
        if scene is None:
            return self
        return self.cls(**scene._data.get(self.cls.section, {}))


class Scene:
    """A validated scene: the contents of one scene file.

    Build it from a file (:meth:`load`), TOML text (:meth:`loads`), a nested dictionary
    (:meth:`from_dict`) or typed sections (:meth:`build`); derive others with
    :meth:`replace` (sections) or :meth:`with_overrides` (``SECTION.KEY=VALUE``). Every
    way goes through :func:`~beltsim.problem.scene.validate`, so a scene that exists is a valid one.

    Parameters
    ----------
    data : dict
        The scene as nested tables, ``{"beam": {...}, "motion": {...}, ...}``.
    source : str, optional
        Where it came from (a path or a shipped scene's name), for messages.

    Raises
    ------
    SceneError
        On the first broken rule, naming the key and the rule.

    Examples
    --------
    >>> scene = Scene.load("my_scene.toml")                       # doctest: +SKIP
    >>> stiffer = scene.replace(physics=Physics(inertia=True, damping=100.0))  # doctest: +SKIP
    >>> scene.contact.max_friction                                # doctest: +SKIP
    100000.0
    """

    def __init__(self, data: dict, source: str | None = None):
        self._data = validate(data)
        self.source = source

    # construction -----------------------------------------------------
    @classmethod
    def load(cls, path) -> Scene:
        """Read and validate a scene file (TOML).

        Parameters
        ----------
        path : str or Path
            The scene file.

        Returns
        -------
        Scene

        Raises
        ------
        SceneError
            The file is missing or unreadable, not TOML, or breaks a rule.
        """
        return cls.loads(read_scene_file(path), source=str(path))

    @classmethod
    def loads(cls, text: str, source: str | None = None) -> Scene:
        """Parse and validate a scene from TOML text.

        Parameters
        ----------
        text : str
            A scene file's contents, e.g. what :meth:`to_toml` wrote.
        source : str, optional
            Where the text came from, for messages.

        Returns
        -------
        Scene

        Raises
        ------
        SceneError
            Malformed TOML or a broken rule.
        """
        return cls(parse_toml(text, source), source=source)

    @classmethod
    def from_dict(cls, data: dict) -> Scene:
        """A scene from nested tables (left unchanged: the scene keeps a copy).

        Parameters
        ----------
        data : dict
            ``{"beam": {...}, "motion": {...}, ...}`` as a scene file's tables.

        Returns
        -------
        Scene

        Raises
        ------
        SceneError
            On the first broken rule.
        """
        return cls(copy.deepcopy(data))

    @classmethod
    def build(cls, beam: Beam, motion: Motion, contact: Contact, physics: Physics,
              stiffness: Stiffness | None = None, numerics: NumericsSection | None = None,
              title: str | None = None) -> Scene:
        """A scene from typed sections (:mod:`beltsim.problem.builder`).

        The sections become the tables of a scene file and are validated as a file is,
        so the errors are the same, naming the key (``contact.max_friction: ...``).

        Parameters
        ----------
        beam, motion, contact, physics : Beam, Motion, Contact, Physics
            The required sections.
        stiffness : Stiffness, optional
            Overrides of the stiffnesses derived from ``beam``.
        numerics : NumericsSection, optional
            Numerical keys; every one left out takes its default.
        title : str, optional
            Free text, shown by the CLI and on figures.

        Returns
        -------
        Scene

        Raises
        ------
        SceneError
            A section of the wrong class, or a broken rule.

        Examples
        --------
        >>> scene = Scene.build(
        ...     beam=Beam(length=1.0, height=0.1, width=0.1, youngs_modulus=5e7,
        ...               poisson_ratio=0.45, density=1500.0, shear_factor=1.1),
        ...     motion=Motion(belt_speed=120.0, surface_speed=121.2),
        ...     contact=Contact(start=1 / 3, end=2 / 3, friction="coulomb",
        ...                     max_friction=1e5),
        ...     physics=Physics(inertia=True, damping=39.0),
        ...     numerics=NumericsSection(elements=300))
        >>> scene.numerics.elements
        300
        """
        data: dict = {} if title is None else {"title": title}
        given = {"beam": beam, "motion": motion, "contact": contact, "physics": physics,
                 "stiffness": stiffness, "numerics": numerics}
        for name, section in given.items():
            table = _table(name, section)
            if table is not None:
                data[name] = table
        return cls(data)

    def replace(self, **changes) -> Scene:
        """This scene with some sections (or the title) replaced, validated again.

        ``dataclasses.replace`` changes a key of a section; this puts the new section
        into a new scene. A section given as None is removed (the optional ``stiffness``
        and ``numerics``, and ``title``).

        Parameters
        ----------
        **changes : Section, dict, str or None
            ``beam=``, ``motion=``, ``contact=``, ``physics=``, ``stiffness=``,
            ``numerics=`` (a section of that class, or its table as a dict) and
            ``title=``.

        Returns
        -------
        Scene
            A new scene; this one is unchanged.

        Raises
        ------
        SceneError
            An unknown section, a section of the wrong class, or a broken rule.

        Examples
        --------
        >>> import dataclasses
        >>> faster = scene.replace(                                     # doctest: +SKIP
        ...     motion=dataclasses.replace(scene.motion, surface_speed=121.8))
        """
        data = self.to_dict()
        for name, value in changes.items():
            if name == "title":
                if value is None:
                    data.pop("title", None)
                else:
                    data["title"] = value
                continue
            if name not in SCHEMA:
                known = ", ".join([*SCHEMA, *TOP_LEVEL_KEYS])
                raise SceneError(f"{name}: unknown section (known: {known})")
            table = _table(name, value)
            if table is None:
                data.pop(name, None)
            else:
                data[name] = table
        return Scene(data, source=self.source)

    def to_dict(self) -> dict:
        """The scene as nested tables (a copy), as :meth:`from_dict` takes them.

        Returns
        -------
        dict
        """
        return copy.deepcopy(self._data)

    def with_overrides(self, assignments) -> Scene:
        """Apply ``SECTION.KEY=VALUE`` strings (or (key, value) pairs) and revalidate.

        Parameters
        ----------
        assignments : iterable of str or (str, value)
            As ``--set`` takes them, e.g. ``"contact.max_friction=2e5"``.

        Returns
        -------
        Scene

        Raises
        ------
        SceneError
            An unknown key, an unparsable value, or a broken rule.
        """
        data = self.to_dict()
        for item in assignments:
            if isinstance(item, str):
                key, value = parse_assignment(item)
            else:
                key, value = item
            set_key(data, key, value)
        return Scene(data, source=self.source)

    # sections ---------------------------------------------------------
    @property
    def title(self) -> str:
        """The scene's title ("" when it has none)."""
        return self._data.get("title", "")

    # the sections, as the typed dataclasses of beltsim.problem.builder
    beam = _SectionOf(Beam)
    motion = _SectionOf(Motion)
    contact = _SectionOf(Contact)
    physics = _SectionOf(Physics)
    #: every field None when the scene has no [stiffness]
    stiffness = _SectionOf(Stiffness)
    #: the keys the scene sets (None: the default applies); the settings a run uses,
    #: with the defaults filled in, are :func:`beltsim.solvers.settings.resolve` of it
    numerics = _SectionOf(NumericsSection)

    @property
    def params(self) -> Params:
        """The physical data a solver needs, derived from the sections."""
        return _params(self._data)

    def to_toml(self) -> str:
        """The scene as a scene file; :meth:`loads` reads it back as the same scene.

        Returns
        -------
        str
            TOML text: the title, then one table per section, in the schema's order.
        """
        lines = []
        if "title" in self._data:
            lines.append(f"title = {_toml_value(self._data['title'])}")
        for section in SCHEMA:
            if section not in self._data:
                continue
            lines.append(f"\n[{section}]")
            for key, value in self._data[section].items():
                lines.append(f"{key} = {_toml_value(value)}")
        return "\n".join(lines).lstrip("\n") + "\n"

    def __eq__(self, other):
        # the same keys and values; where a scene was read from does not count
        if not isinstance(other, Scene):
            return NotImplemented
        return self._data == other._data

    def __hash__(self):
        # a scene does not change once made: equal scenes hash alike, as dictionary keys
        return hash(_frozen(self._data))

    def __repr__(self):
        return f"Scene({self.title or self.source or 'untitled'!r})"


def read_scene_file(path) -> str:
    """A scene file's text, or the one-line error of a missing, unreadable or non-UTF-8
    file."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        raise SceneError(f"{path}: scene file not found") from None
    except IsADirectoryError:
        raise SceneError(f"{path}: is a directory, not a scene file") from None
    except OSError as exc:
        raise SceneError(f"{path}: cannot read scene file ({exc.strerror})") from None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        raise SceneError(f"{path}: not a UTF-8 text file") from None


def parse_toml(text: str, source: str | None = None) -> dict:
    """A scene file's TOML text as tables, or the one-line error of malformed TOML."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{source or 'scene'}: malformed TOML ({exc})") from None


def _frozen(value):
    """A scene's tables as nested sorted tuples, which hash (equal tables, equal tuples)."""
    if isinstance(value, dict):
        return tuple(sorted((k, _frozen(v)) for k, v in value.items()))
    if isinstance(value, list):
        return tuple(_frozen(v) for v in value)
    return value


def _table(name: str, section):
    """The table of a section given to :meth:`Scene.build` or :meth:`Scene.replace`: its
    keys as a dict, or None for a section left out (an empty optional one too)."""
    if section is None:
        return None
    cls = SECTIONS[name]
    if isinstance(section, Section):
        if not isinstance(section, cls):
            raise SceneError(f"[{name}]: must be a {cls.__name__}, got a "
                             f"{type(section).__name__}")
        table = section.to_dict()
    elif isinstance(section, dict):
        table = copy.deepcopy(section)
    else:
        raise SceneError(f"[{name}]: must be a {cls.__name__} (or a table), got "
                         f"{_show(section)}")
    if not table and name in OPTIONAL_SECTIONS:
        return None
    return table


# TOML basic strings escape these (and every other control character, as \uXXXX)
_TOML_ESCAPES = {"\\": "\\\\", '"': '\\"', "\b": "\\b", "\t": "\\t", "\n": "\\n",
                 "\f": "\\f", "\r": "\\r"}


def _toml_value(value) -> str:
    if isinstance(value, list):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{k} = {_toml_value(v)}" for k, v in value.items()) + " }"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, int):
        return str(value)
    escaped = "".join(_TOML_ESCAPES.get(ch) or (f"\\u{ord(ch):04x}" if ord(ch) < 0x20
                                                 or ord(ch) == 0x7F else ch)
                      for ch in value)
    return f'"{escaped}"'


def parse_assignment(text: str):
    """Split ``SECTION.KEY=VALUE`` and parse VALUE as a TOML value (bare words as strings)."""
    if "=" not in text:
        raise SceneError(f"--set {text}: expected SECTION.KEY=VALUE")
    key, raw = text.split("=", 1)
    key, raw = key.strip(), raw.strip()
    if raw == "":
        raise SceneError(key, "empty value in --set")
    try:
        value = tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        if raw.replace("_", "").isalnum() and not raw[0].isdigit():
            value = raw  # bare word, e.g. friction=coulomb
        else:
            raise SceneError(key, f"cannot parse value {raw!r} in --set") from None
    if isinstance(value, str) and raw.lower() in ("nan", "inf", "+inf", "-inf"):
        value = float(raw)
    return key, value


def set_key(data: dict, key: str, value) -> None:
    """Set ``SECTION.KEY`` in a scene dict; the key must be one the schema knows."""
    if key == "title":
        data["title"] = value
        return
    if "." not in key:
        raise SceneError(key, f"expected SECTION.KEY (sections: {', '.join(SCHEMA)})")
    section, name = key.split(".", 1)
    if section not in SCHEMA:
        raise SceneError(key, f"unknown section [{section}] (sections: {', '.join(SCHEMA)})")
    if (section, name) in _RETIRED:
        raise SceneError(key, _RETIRED[section, name])
    if name not in SCHEMA[section]:
        raise SceneError(key, f"unknown key (known in [{section}]: "
                         f"{', '.join(SCHEMA[section])})")
    data.setdefault(section, {})[name] = value


def scene_names() -> tuple[str, ...]:
    """The names of the scenes shipped with beltsim (``beltsim run NAME`` runs one); none
    where the package was installed without them."""
    folder = _scenes_dir()
    if not folder.is_dir():
        return ()
    return tuple(sorted(f.name[:-5] for f in folder.iterdir() if f.name.endswith(".toml")))


def _scenes_dir():
    from importlib.resources import files

    return files("beltsim") / "scenes"


def shipped_scene(name: str, overrides=()) -> Scene:
    """A scene shipped with beltsim, by name (see :func:`scene_names`).

    Raises :class:`~beltsim.errors.MissingInputError` when the package holds no such
    scene (an installation without its scene files included).
    """
    resource = _scenes_dir() / f"{name}.toml"
    if not resource.is_file():
        known = ", ".join(scene_names()) or "none installed"
        raise MissingInputError(f"{name}: no scene of that name ships with beltsim "
                                f"(shipped: {known})")
    scene = _loads_any(resource.read_text(encoding="utf-8"), source=name)
    return scene.with_overrides(overrides) if overrides else scene


def _loads_any(text: str, source: str):
    """A Scene, or a DriveScene where the text has a [drive] section (a closed drive)."""
    data = parse_toml(text, source)
    # beltdrive.scene.is_drive, without importing beltdrive (numba, scipy) for a straight belt
    if isinstance(data, dict) and "drive" in data:
        from ..beltdrive.scene import DriveScene

        return DriveScene(data, source=source)
    return Scene(data, source=source)


def load_scene(path_or_name, overrides=()) -> Scene:
    """A scene from a TOML file, or a shipped scene by name, with ``SECTION.KEY=VALUE``
    overrides applied.

    A name without a path separator or suffix (``"paper_slip"``) that is not an existing
    file is looked up among the shipped scenes (:func:`scene_names`).
    """
    text = str(path_or_name)
    if not Path(text).exists() and "/" not in text and "\\" not in text \
            and not text.endswith(".toml"):
        return shipped_scene(text, overrides)
    scene = _loads_any(read_scene_file(path_or_name), source=str(path_or_name))
    return scene.with_overrides(overrides) if overrides else scene


#: The paper's three scenes, by the short name :func:`paper_scene` takes.
PAPER_SCENES = ("quasistatic", "inertia", "slip")


def paper_scene(name: str, overrides=()) -> Scene:
    """One of the paper's scenes: "quasistatic", "inertia" or "slip"."""
    if name not in PAPER_SCENES:
        raise SceneError(f"{name}: not one of the paper's scenes ({', '.join(PAPER_SCENES)})")
    return shipped_scene(f"paper_{name}", overrides)
