"""Scene files and text: reading a file, parsing TOML, writing values back as TOML, and
``SECTION.KEY=VALUE`` assignments (``--set`` and ``with_overrides``).

Shared by every kind of scene; the errors are one-line
:class:`~beltsim.errors.SceneError` messages.
"""

from __future__ import annotations

import tomllib
from collections.abc import Iterable, Mapping
from pathlib import Path

from ..errors import SceneError
from .rules import show


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


# TOML basic strings escape these (and every other control character, as \uXXXX)
_TOML_ESCAPES = {"\\": "\\\\", '"': '\\"', "\b": "\\b", "\t": "\\t", "\n": "\\n",
                 "\f": "\\f", "\r": "\\r"}


def toml_value(value) -> str:
    """A scene's value (number, bool, string, array or inline table) as TOML text."""
    if isinstance(value, list):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{k} = {toml_value(v)}" for k, v in value.items()) + " }"
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


def assignments(overrides) -> list[tuple[str, object]]:
    """Overrides as (key, value) pairs, in order.

    Parameters
    ----------
    overrides : dict, str or iterable of str or (str, value)
        ``{"contact.max_friction": 2e5}`` (values as Python gives them), one
        ``"SECTION.KEY=VALUE"`` string, or an iterable of such strings (the values
        parsed as TOML, as ``--set`` parses them) or (key, value) pairs. None is no
        override.

    Returns
    -------
    list of (str, object)

    Raises
    ------
    SceneError
        An item that is neither a ``SECTION.KEY=VALUE`` string nor a (key, value) pair,
        or a string without ``=``.
    """
    if overrides is None:
        return []
    if isinstance(overrides, str):
        # one string is one assignment, never the characters of one
        return [parse_assignment(overrides)]
    if isinstance(overrides, Mapping):
        items = list(overrides.items())
    elif isinstance(overrides, Iterable):
        items = list(overrides)
    else:
        raise SceneError(f"overrides: must be a dict, a 'SECTION.KEY=VALUE' string or an "
                         f"iterable of them, got {type(overrides).__name__}")
    pairs = []
    for item in items:
        if isinstance(item, str):
            pairs.append(parse_assignment(item))
        elif isinstance(item, (tuple, list)) and len(item) == 2 and isinstance(item[0], str):
            pairs.append((item[0], item[1]))
        else:
            raise SceneError(f"overrides: each must be a 'SECTION.KEY=VALUE' string or a "
                             f"(key, value) pair, got {show(item)}")
    return pairs
