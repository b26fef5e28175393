"""What every kind of scene is: nested tables, validated, read and written as TOML,
compared and derived alike.

A kind of scene (the straight belt's :class:`~beltsim.problem.scene.Scene`, the closed
drive's :class:`~beltsim.beltdrive.scene.DriveScene`) subclasses :class:`SceneTables`
with its schema, its validation and its key setter; this class holds everything else.
"""

from __future__ import annotations

import copy
from typing import ClassVar

from ..errors import SceneError
from .rules import show
from .tomlio import assignments, parse_toml, read_scene_file, toml_value


class SceneTables:
    """A validated scene: its tables, and where it was read from (``source``).

    Build one from a file (:meth:`load`), TOML text (:meth:`loads`) or nested tables
    (:meth:`from_dict`); derive others with :meth:`with_overrides` and :meth:`replace`.

    Raises
    ------
    SceneError
        On the first broken rule, naming the key and the rule.
    """

    #: the kind's sections, in a file's order (each a dict of its keys' rules)
    SCHEMA: ClassVar[dict] = {}
    #: the sections a scene may leave out
    OPTIONAL: ClassVar[tuple] = ()
    #: the kind in messages ("" for the straight belt's, "a drive scene")
    KIND: ClassVar[str] = ""

    def __init__(self, data: dict, source: str | None = None):
        self._data = self.validate(data)
        self.source = source

    @staticmethod
    def validate(data: dict) -> dict:
        """The kind's validation: the tables, checked and completed; SceneError else."""
        raise NotImplementedError

    @staticmethod
    def set_key(data: dict, key: str, value) -> None:
        """Set ``SECTION.KEY`` in the kind's tables (checked when they are validated)."""
        raise NotImplementedError

    def section_table(self, name: str, value):
        """The table :meth:`replace` puts in for section ``name`` (None: leave it out)."""
        if value is None or (value == {} and name in self.OPTIONAL):
            return None
        if isinstance(value, dict):
            return copy.deepcopy(value)
        raise SceneError(f"[{name}]", f"must be a table (a dict), got {show(value)}")

    # construction -----------------------------------------------------
    @classmethod
    def load(cls, path):
        """Read and validate a scene file (TOML).

        Parameters
        ----------
        path : str or Path
            The scene file.

        Returns
        -------
        SceneTables
            A scene of this kind.

        Raises
        ------
        SceneError
            The file is missing or unreadable, not TOML, or breaks a rule.
        """
        return cls.loads(read_scene_file(path), source=str(path))

    @classmethod
    def loads(cls, text: str, source: str | None = None):
        """Parse and validate a scene from TOML text.

        Parameters
        ----------
        text : str
            A scene file's contents, e.g. what :meth:`to_toml` wrote.
        source : str, optional
            Where the text came from, for messages.

        Returns
        -------
        SceneTables
            A scene of this kind.

        Raises
        ------
        SceneError
            Malformed TOML or a broken rule.
        """
        return cls(parse_toml(text, source), source=source)

    @classmethod
    def from_dict(cls, data: dict):
        """A scene from nested tables (left unchanged: the scene keeps a copy).

        Parameters
        ----------
        data : dict
            A scene file's tables, ``{"section": {...}, ...}``.

        Returns
        -------
        SceneTables
            A scene of this kind.

        Raises
        ------
        SceneError
            On the first broken rule.
        """
        return cls(copy.deepcopy(data))

    # derived scenes ---------------------------------------------------
    def with_overrides(self, overrides):
        """This scene with some keys set, validated again.

        Parameters
        ----------
        overrides : dict, str or iterable of str or (str, value)
            ``{"contact.friction_coefficient": 0.3}``, one
            ``"contact.friction_coefficient=0.3"`` string (as ``--set`` takes it), or an
            iterable of such strings or (key, value) pairs.

        Returns
        -------
        SceneTables
            A new scene of this kind; this one is unchanged.

        Raises
        ------
        SceneError
            An unknown section or key, an unparsable value, or a broken rule.
        """
        data = self.to_dict()
        for key, value in assignments(overrides):
            self.set_key(data, key, value)
        return type(self)(data, source=self.source)

    def replace(self, **changes):
        """This scene with some sections (or the title) replaced, validated again.

        A section given as None is removed (an optional one, and ``title``).

        Parameters
        ----------
        **changes : dict, section or None
            A section by its name, as its table (a dict; a straight belt's scene also
            takes the section's typed class, :mod:`beltsim.problem.builder`), and
            ``title=``.

        Returns
        -------
        SceneTables
            A new scene of this kind; this one is unchanged.

        Raises
        ------
        SceneError
            An unknown section, a section of the wrong type, or a broken rule.
        """
        data = self.to_dict()
        for name, value in changes.items():
            if name == "title":
                if value is None:
                    data.pop("title", None)
                else:
                    data["title"] = value
                continue
            if name not in self.SCHEMA:
                of = f" of {self.KIND}" if self.KIND else ""
                known = ", ".join([*self.SCHEMA, "title"])
                raise SceneError(f"{name}: unknown section{of} (known: {known})")
            table = self.section_table(name, value)
            if table is None:
                data.pop(name, None)
            else:
                data[name] = table
        return type(self)(data, source=self.source)

    # reading ----------------------------------------------------------
    def to_dict(self) -> dict:
        """The scene as nested tables (a copy), as :meth:`from_dict` takes them.

        Returns
        -------
        dict
        """
        return copy.deepcopy(self._data)

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
        for section in self.SCHEMA:
            if not self._data.get(section):
                continue
            lines.append(f"\n[{section}]")
            lines += [f"{key} = {toml_value(value)}"
                      for key, value in self._data[section].items()]
        for name, tables in self._data.items():
            if isinstance(tables, list):  # arrays of tables, e.g. a drive's [[pulley]]
                for table in tables:
                    lines.append(f"\n[[{name}]]")
                    lines += [f"{key} = {toml_value(value)}" for key, value in table.items()]
        return "\n".join(lines).lstrip("\n") + "\n"

    @property
    def title(self) -> str:
        """The scene's title ("" when it has none)."""
        return self._data.get("title", "")

    def __eq__(self, other):
        # the same kind, keys and values; where a scene was read from does not count
        if not isinstance(other, SceneTables):
            return NotImplemented
        return type(self) is type(other) and self._data == other._data

    def __hash__(self):
        # a scene does not change once made: equal scenes hash alike, as dictionary keys
        return hash(frozen(self._data))

    def __repr__(self):
        return f"{type(self).__name__}({self.title or self.source or 'untitled'!r})"


def frozen(value):
    """A scene's tables as nested sorted tuples, which hash (equal tables, equal tuples)."""
    if isinstance(value, dict):
        return tuple(sorted((k, frozen(v)) for k, v in value.items()))
    if isinstance(value, list):
        return tuple(frozen(v) for v in value)
    return value
