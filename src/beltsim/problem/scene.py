"""The straight belt's scene: :class:`Scene`, the contents of one scene file.

A scene is a TOML file in SI units. Its rules and derived physical data are in
:mod:`beltsim.problem.validation`, the rules it shares with a closed drive in
:mod:`beltsim.problem.rules`, reading and writing TOML in :mod:`beltsim.problem.tomlio`
and the shipped scenes in :mod:`beltsim.problem.shipped`. A file or name of either kind
of scene is read by :func:`beltsim.load_scene`. This module also gives the names of
those modules its importers have long used (``SCHEMA``, ``Params``, ``MIN_ELEMENTS``, ...).
"""

from __future__ import annotations

import copy
from typing import Generic, TypeVar

from ..errors import SceneError
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
from .rules import check_table, final_value, profile_extremes, show
from .shipped import scene_names
from .tomlio import assignments, parse_assignment, parse_toml, read_scene_file, toml_value
from .validation import (
    MIN_ELEMENTS,
    OPTIONAL_SECTIONS,
    REQUIRED_SECTIONS,
    SCHEMA,
    TOP_LEVEL_KEYS,
    Params,
    params_of,
    set_key,
    validate,
)

__all__ = [
    "MIN_ELEMENTS", "OPTIONAL_SECTIONS", "REQUIRED_SECTIONS", "SCHEMA", "TOP_LEVEL_KEYS",
    "Scene", "check_table", "final_value", "parse_assignment", "parse_toml",
    "profile_extremes", "read_scene_file", "scene_names", "set_key",
]

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
    way goes through :func:`~beltsim.problem.validation.validate`, so a scene that exists
    is a valid one.

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

    def with_overrides(self, overrides) -> Scene:
        """This scene with some keys set, validated again.

        Parameters
        ----------
        overrides : dict, str or iterable of str or (str, value)
            ``{"contact.max_friction": 2e5}``, one ``"contact.max_friction=2e5"`` string
            (as ``--set`` takes it), or an iterable of such strings or (key, value)
            pairs.

        Returns
        -------
        Scene
            A new scene; this one is unchanged.

        Raises
        ------
        SceneError
            An unknown key, an unparsable value, or a broken rule.

        Examples
        --------
        >>> stiffer = scene.with_overrides({"contact.max_friction": 2e5})  # doctest: +SKIP
        >>> finer = scene.with_overrides("numerics.elements=600")         # doctest: +SKIP
        """
        data = self.to_dict()
        for key, value in assignments(overrides):
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
        return params_of(self._data)

    def to_toml(self) -> str:
        """The scene as a scene file; :meth:`loads` reads it back as the same scene.

        Returns
        -------
        str
            TOML text: the title, then one table per section, in the schema's order.
        """
        lines = []
        if "title" in self._data:
            lines.append(f"title = {toml_value(self._data['title'])}")
        for section in SCHEMA:
            if section not in self._data:
                continue
            lines.append(f"\n[{section}]")
            for key, value in self._data[section].items():
                lines.append(f"{key} = {toml_value(value)}")
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
                         f"{show(section)}")
    if not table and name in OPTIONAL_SECTIONS:
        return None
    return table

