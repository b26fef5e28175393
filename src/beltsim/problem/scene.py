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
from .tables import SceneTables
from .tomlio import parse_assignment, parse_toml, read_scene_file
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


class Scene(SceneTables):
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

    SCHEMA = SCHEMA
    OPTIONAL = OPTIONAL_SECTIONS
    validate = staticmethod(validate)
    set_key = staticmethod(set_key)

    def section_table(self, name: str, value):
        """A section for :meth:`replace`: its typed class (:mod:`beltsim.problem.builder`) or
        its table."""
        return _table(name, value)

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

