"""The registry of schemes, by name.

A scheme is a class registered under its name (``numerics.integrator``): the
numerics' validation, the convergence study's choices and the stability matrix all
come from :func:`names`, :func:`get` and :func:`applicable`. Adding a scheme is one
new module under ``beltsim/solvers`` that defines a
:class:`~beltsim.solvers.base.Scheme` subclass decorated with :func:`register`, and
one import line in ``beltsim/solvers/__init__.py``.
"""

from __future__ import annotations

from ..errors import SceneError

_REGISTRY: dict[str, type] = {}


def register(cls):
    """Class decorator: make a scheme available under ``cls.name``."""
    _REGISTRY[cls.name] = cls
    return cls


def names() -> tuple[str, ...]:
    """The registered schemes' names, the values of ``numerics.integrator``."""
    return tuple(_REGISTRY)


def get(name: str) -> type:
    """The scheme class registered as ``name``; SceneError for an unknown name."""
    try:
        return _REGISTRY[name]
    except KeyError:
        raise SceneError("numerics.integrator", "must be one of "
                         f"{' | '.join(repr(n) for n in _REGISTRY)}, got {name!r}") from None


def applicable(name: str, inertia: bool, closed: bool = False) -> str | None:
    """Why a scheme does not apply to a scene (None when it does); ``closed``: a loop."""
    cls = get(name)
    if cls.needs_inertia and not inertia:
        return (f'numerics.integrator: "{name}" needs physics.inertia = true (a quasistatic '
                f'scene has no dynamics to step explicitly)')
    if closed and not cls.closed:
        usable = " | ".join(f'"{n}"' for n, c in _REGISTRY.items() if c.closed)
        return (f'numerics.integrator: "{name}" does not run a closed drive yet (one of '
                f'{usable})')
    return None
