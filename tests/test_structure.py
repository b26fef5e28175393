"""The package's structure: no import circles between its modules (at module level or
inside functions), no private name imported from another package, and no module longer
than MAX_LINES."""

import ast

import pytest

from helpers import ROOT

pytestmark = pytest.mark.unit

SRC = ROOT / "src"

#: Private names still imported across packages, each with its reason: none may be added.
KNOWN_PRIVATE: set = set()


def _modules():
    out = {}
    for path in SRC.rglob("*.py"):
        parts = list(path.relative_to(SRC).with_suffix("").parts)
        is_package = parts[-1] == "__init__"
        out[".".join(parts[:-1] if is_package else parts)] = (path, is_package)
    return out


def _imports(modules):
    """(module, imported module, imported name) of every ``from beltsim... import``."""
    for module, (path, is_package) in modules.items():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not isinstance(node, ast.ImportFrom):
                continue
            if node.level:
                base = module.split(".")[:None if is_package else -1]
                base = base[:len(base) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target.split(".")[0] != "beltsim":
                continue
            for alias in node.names:
                sub = f"{target}.{alias.name}"
                yield module, sub if sub in modules else target, target, alias.name


def test_no_import_circles():
    modules = _modules()
    graph = {m: set() for m in modules}
    for module, imported, _, _ in _imports(modules):
        if imported in modules and imported != module:
            graph[module].add(imported)

    def reaches(start, goal, seen):
        for nxt in graph[start]:
            if nxt == goal:
                return [nxt]
            if nxt not in seen:
                seen.add(nxt)
                path = reaches(nxt, goal, seen)
                if path:
                    return [nxt, *path]
        return None

    # a package imports its own modules (its __init__), which is no circle
    circles = [[m, *path] for m in graph
               if (path := reaches(m, m, set())) and not any(
                   modules[p][1] and q.startswith(p + ".")
                   for p, q in zip([m, *path], path))]
    assert not circles, circles[0]


def test_no_private_names_across_packages():
    found = {(module, target, name) for module, _, target, name in _imports(_modules())
             if name.startswith("_") and not name.endswith("__")  # __version__ is public
             and target.split(".")[:2] != module.split(".")[:2]}
    assert found <= KNOWN_PRIVATE, found - KNOWN_PRIVATE


#: The longest a module may be, in lines: a longer one is split along a seam (as
#: physics.model was, into the kernels and physics.discrete, the data they read).
MAX_LINES = 600


def test_no_module_is_longer_than_max_lines():
    long = {module: n for module, (path, _) in _modules().items()
            if (n := len(path.read_text(encoding="utf-8").splitlines())) > MAX_LINES}
    assert not long, long
