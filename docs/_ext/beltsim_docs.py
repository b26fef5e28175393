"""Tables of the documentation that are read from the code, so they cannot drift from it.

``scene-keys SECTION``
    The keys of one scene section, from :data:`beltsim.problem.scene.SCHEMA`: key, rule
    (generated from the schema's rule), default and meaning (the directive's content, one
    line a key: ``key | default | meaning``, where ``{NAME}`` or ``{NAME:format}`` quotes a
    constant of :mod:`beltsim.solvers.settings`). The build fails when the content names a key
    the schema does not have, or leaves out one it has.

``drive-keys SECTION``
    The same for a closed drive's scene, from :data:`beltsim.beltdrive.scene.SCHEMA`; a
    default may quote the constants of :mod:`beltsim.beltdrive.scene`,
    :mod:`beltsim.physics.layout` and :mod:`beltsim.solvers.settings`.

``beltsim-cli COMMAND``
    Usage, description and options of one subcommand of ``beltsim``, from
    :func:`beltsim.cli.build_parser`.

At the end of a build every section of both schemas and every subcommand must have been
shown.
The module pages of the API reference leave out what the package exports at its top
level, which has a page of its own.
"""

from __future__ import annotations

import argparse
import re

from docutils import nodes
from docutils.statemachine import StringList
from sphinx.util import logging
from sphinx.util.docutils import SphinxDirective

import beltsim
from beltsim.beltdrive import scene as drive_scene
from beltsim.cli import build_parser
from beltsim.physics import layout as loop_layout
from beltsim.problem import scene as scene_module
from beltsim.solvers import settings

LOG = logging.getLogger(__name__)


def _cell(text: str) -> str:
    """Text for a Markdown table cell."""
    return str(text).replace("|", "\\|").replace("\n", " ")


def rule_text(rule, key="", closed=False) -> str:
    """A rule of the schema in words (``key``: the section.key it belongs to; ``closed``:
    a closed drive's schema, whose integrators are the registry's closed-layout ones)."""
    if key == "numerics.integrator":  # the registry checks it: its names
        from beltsim import solvers
        return ", ".join(f'`"{n}"`' for n in solvers.names()
                         if not closed or solvers.registry.get(n).closed)
    if rule.kind == "profile":
        return "number > 0, table or sine ([drive profiles](drive-profiles.md))"
    if rule.kind == "load":
        return "number >= 0, or a table of `[time, value]` rows with values >= 0"
    if rule.kind == "bool":
        return "true or false"
    if rule.kind == "str":
        if rule.choices:
            return ", ".join(f'`"{c}"`' for c in rule.choices)
        return "string"
    word = "whole number" if rule.kind == "int" else "number"
    parts = []
    if rule.positive:
        parts.append("> 0")
    if rule.nonneg:
        parts.append(">= 0")
    if rule.minimum is not None:
        parts.append(f">= {rule.minimum:g}")
    if rule.interval is not None:
        lo, hi = rule.interval
        parts.append(f"in ({lo:g}, {hi:g})")
    return " ".join([word, *parts])


def _constants(*modules) -> dict:
    """Names a default may quote as ``{NAME}``: the modules' numeric and string constants."""
    return {k: v for m in modules for k, v in vars(m).items() if k.isupper()
            and isinstance(v, (int, float, str)) and not isinstance(v, bool)}


CONSTANT = re.compile(r"\{([A-Z][A-Z0-9_]*)(?::([^}]*))?\}")


def _substitute(text, consts, directive, key):
    """Replace ``{NAME}`` or ``{NAME:format}`` by a constant of the directive's modules."""
    def value(match):
        name, fmt = match.group(1), match.group(2) or ""
        if name not in consts:
            where = ", ".join(m.__name__ for m in directive.constant_modules)
            raise directive.error(f"{directive.name} {key}: the default names {name}, which "
                                  f"is not a constant of {where}")
        text = format(consts[name], fmt)
        return re.sub(r"e([+-])0*(\d)", lambda m: "e" + m.group(1).strip("+") + m.group(2),
                      text)  # 6e-06 as 6e-6, 2e+10 as 2e10
    return CONSTANT.sub(value, text)


class SceneKeys(SphinxDirective):
    """The table of one scene section's keys."""

    required_arguments = 1
    has_content = True
    schema_module = scene_module
    constant_modules = (settings,)
    kind = "sections"  # what _shown records
    closed = False  # the layout whose schemes the integrator's rule lists

    def run(self):
        section = self.arguments[0]
        schema = self.schema_module.SCHEMA
        if section not in schema:
            raise self.error(f"{self.name}: no section [{section}] in SCHEMA "
                             f"(sections: {', '.join(schema)})")
        rules = schema[section]
        given = {}
        for line in self.content:
            if not line.strip():
                continue
            parts = [p.strip() for p in line.split(" | ", 2)]
            if len(parts) != 3:
                raise self.error(f"{self.name} {section}: expected 'key | default | "
                                 f"meaning', got {line!r}")
            key = parts[0]
            if key not in rules:
                raise self.error(f"{self.name} {section}: {key} is not a key of [{section}] "
                                 f"(SCHEMA has {', '.join(rules)})")
            if key in given:
                raise self.error(f"{self.name} {section}: {key} twice")
            given[key] = parts[1:]
        missing = [k for k in rules if k not in given]
        if missing:
            raise self.error(f"{self.name} {section}: undocumented keys "
                             f"{', '.join(missing)}")
        consts = _constants(*self.constant_modules)
        lines = ["| key | rule | default | meaning |", "|---|---|---|---|"]
        for key in rules:  # the schema's order
            default, meaning = given[key]
            default = _substitute(default, consts, self, f"{section}.{key}")
            meaning = _substitute(meaning, consts, self, f"{section}.{key}")
            rule = _cell(rule_text(rules[key], f"{section}.{key}", self.closed))
            lines.append(f"| `{key}` | {rule} | {default} | "
                         f"{meaning} |")
        for module in (self.schema_module, *self.constant_modules):
            self.env.note_dependency(module.__file__)
        _shown(self.env, self.kind).add(section)
        node = nodes.container(classes=["scene-keys"])
        self.state.nested_parse(StringList(lines, self.get_source_info()[0]),
                                self.content_offset, node)
        return [node]


class DriveKeys(SceneKeys):
    """The table of one closed-drive scene section's keys."""

    schema_module = drive_scene
    constant_modules = (drive_scene, loop_layout, settings)
    kind = "drive sections"
    closed = True


def _subparsers(parser) -> dict:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def _option_row(action) -> str | None:
    if isinstance(action, argparse._HelpAction):
        return None
    if action.option_strings:
        name = ", ".join(action.option_strings)
        if action.nargs != 0:
            name += " " + (action.metavar or action.dest.upper())
    else:
        name = action.metavar or action.dest.upper()
        if action.nargs == "?":
            name = f"[{name}]"
    helptext = action.help or ""
    if action.choices and not isinstance(action, argparse._SubParsersAction):
        helptext += (" " if helptext else "") + "(one of " + ", ".join(
            f"`{c}`" for c in action.choices) + ")"
    if getattr(action, "required", False) and action.option_strings:
        helptext += " (required)"
    if (isinstance(action, argparse._AppendAction) or action.nargs == 0
            or action.default is None):
        default = ""
    else:
        default = f"`{action.default}`"
    return f"| `{_cell(name)}` | {_cell(default)} | {_cell(helptext)} |"


class BeltsimCli(SphinxDirective):
    """Usage and options of one ``beltsim`` subcommand."""

    required_arguments = 1

    def run(self):
        name = self.arguments[0]
        commands = _subparsers(build_parser())
        if name not in commands:
            raise self.error(f"beltsim-cli: no subcommand {name!r} "
                             f"(commands: {', '.join(commands)})")
        parser = commands[name]
        usage = parser.format_usage().strip().removeprefix("usage: ")
        lines = ["```text", usage, "```", ""]
        if parser.description:
            lines += [parser.description, ""]
        rows = [r for r in map(_option_row, parser._actions) if r]
        if rows:
            lines += ["| argument | default | meaning |", "|---|---|---|", *rows]
        self.env.note_dependency(build_parser.__code__.co_filename)
        func = parser.get_default("func")  # a command registered from its own module
        if func is not None:
            self.env.note_dependency(func.__code__.co_filename)
        _shown(self.env, "commands").add(name)
        node = nodes.container(classes=["beltsim-cli"])
        self.state.nested_parse(StringList(lines, self.get_source_info()[0]),
                                self.content_offset, node)
        return [node]


def _shown(env, kind) -> set:
    if not hasattr(env, "beltsim_shown"):
        env.beltsim_shown = {k: set() for k in SHOWN}
    return env.beltsim_shown.setdefault(kind, set())


#: what the build records as shown: schema sections of both kinds, subcommands
SHOWN = ("sections", "drive sections", "commands")


def _merge(app, env, docnames, other):
    if hasattr(other, "beltsim_shown"):
        for kind in SHOWN:
            _shown(env, kind).update(other.beltsim_shown.get(kind, ()))


def _check(app, env):
    sections = set(scene_module.SCHEMA) - _shown(env, "sections")
    if sections:
        LOG.warning("scene sections without a scene-keys table: %s", ", ".join(sorted(sections)))
    sections = set(drive_scene.SCHEMA) - _shown(env, "drive sections")
    if sections:
        LOG.warning("drive scene sections without a drive-keys table: %s",
                    ", ".join(sorted(sections)))
    commands = set(_subparsers(build_parser())) - _shown(env, "commands")
    if commands:
        LOG.warning("beltsim commands without a beltsim-cli entry: %s",
                    ", ".join(sorted(commands)))


def _skip_reexported(app, what, name, obj, skip, options):
    """Leave out of the module pages what the package exports: it has its own page."""
    if name in beltsim.__all__ and getattr(beltsim, name) is obj:
        return True
    return None


def _field_names():
    """Full names of the fields of beltsim's dataclasses and named tuples.

    A field is documented by a ``#:`` comment or its annotation, never by a docstring of
    its own (its value's ``__doc__`` is what numpydoc would validate), so the validation
    of docstrings leaves fields out.
    """
    import importlib
    import inspect
    import pkgutil

    names = set()
    for info in pkgutil.walk_packages(beltsim.__path__, "beltsim."):
        if info.name.endswith("__main__"):  # runs the command line when imported
            continue
        module = importlib.import_module(info.name)
        for _, cls in inspect.getmembers(module, inspect.isclass):
            fields = (*getattr(cls, "__dataclass_fields__", ()), *getattr(cls, "_fields", ()))
            for field in fields:
                for prefix in {cls.__module__, "beltsim"}:
                    names.add(f"{prefix}.{cls.__qualname__}.{field}")
    return names


def _exclude_fields(app, config):
    config.numpydoc_validation_exclude = {
        *config.numpydoc_validation_exclude,
        *(re.escape(name) + "$" for name in _field_names())}


def setup(app):
    app.connect("autodoc-skip-member", _skip_reexported)
    # before numpydoc compiles its exclusion pattern (at the default priority, 500)
    app.connect("config-inited", _exclude_fields, priority=400)
    app.add_directive("scene-keys", SceneKeys)
    app.add_directive("drive-keys", DriveKeys)
    app.add_directive("beltsim-cli", BeltsimCli)
    app.connect("env-merge-info", _merge)
    app.connect("env-check-consistency", _check)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
