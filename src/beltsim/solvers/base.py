"""What every scheme works on, the interface every scheme offers, and the registry.

A scheme is a class registered under its name (``numerics.integrator``): the CLI's
choices, the scene schema, the studies' scheme lists and the stability matrix all
come from :func:`names` and :func:`get`. Adding a scheme is one new module under
``beltsim/solvers`` that defines a :class:`Scheme` subclass decorated with
:func:`register`, and one import line in ``beltsim/solvers/__init__.py``.
"""

from __future__ import annotations

import time
from typing import ClassVar

import numpy as np

from ..errors import SceneError
from ..physics.grid import Grid
from ..physics.model import Mesh, ModelParams, State, mesh_of, model_params
from ..problem.drive import Drive
from ..problem.scene import Scene
from .newton import Scales, scales_of
from .settings import Numerics, build_grid, resolve

_REGISTRY: dict[str, type["Scheme"]] = {}


def register(cls):
    """Class decorator: make a scheme available under ``cls.name``."""
    _REGISTRY[cls.name] = cls
    return cls


def names() -> tuple[str, ...]:
    return tuple(_REGISTRY)


def get(name: str) -> type["Scheme"]:
    try:
        return _REGISTRY[name]
    except KeyError:
        raise SceneError(f"numerics.integrator: must be one of "
                         f"{' | '.join(repr(n) for n in _REGISTRY)}, got {name!r}") from None


def applicable(name: str, inertia: bool) -> str | None:
    """Why a scheme does not apply to a scene (None when it does)."""
    cls = get(name)
    if cls.needs_inertia and not inertia:
        return (f'numerics.integrator: "{name}" needs physics.inertia = true (a quasistatic '
                f'scene has no dynamics to step explicitly)')
    return None


class Discretisation:
    """A scene on its grid: the named structures the kernels read.

    ``grid`` replaces the default grid (e.g. a bisected one); the element count
    follows it.
    """

    def __init__(self, scene: Scene, grid: Grid | None = None):
        import dataclasses

        self.scene = scene
        self.params = P = scene.params
        num = resolve(scene)
        if grid is not None:
            num = dataclasses.replace(num, elements=grid.n_elements)
        self.numerics: Numerics = num
        self.grid: Grid = grid if grid is not None else build_grid(scene, num)
        self.mesh: Mesh = mesh_of(self.grid)
        self.model: ModelParams = model_params(P, num.damping, num.fs, num.vreg, num.law_code)
        self.drive = Drive(P.v - P.c, num.ramp_time)
        self.scales: Scales = scales_of(P)

    def new_state(self) -> State:
        """The belt at rest."""
        return State.zeros(self.grid.n_elements + 1)


class Scheme:
    """A way to take a discretisation from rest to steady state.

    Transient schemes advance the state through simulated time in chunks between
    the controller's checks; a non-transient scheme (``transient = False``) solves
    the steady equations at once in :meth:`solve`.
    """

    name: ClassVar[str]
    transient: ClassVar[bool] = True
    needs_inertia: ClassVar[bool] = False

    def __init__(self, disc: Discretisation):
        reason = applicable(self.name, disc.params.inertia)
        if reason:
            raise SceneError(reason)
        self.disc = disc
        self.numerics = disc.numerics  # a scheme may settle some of them (the explicit dt)
        self.steps = 0

    def warm_up(self, state: State) -> float:
        """Compile the kernels (or load them from numba's cache); returns the seconds."""
        start = time.perf_counter()
        self._compile(state)
        return time.perf_counter() - start

    def _compile(self, state: State) -> None:
        raise NotImplementedError

    def advance(self, state: State, t: float, t_stop: float, max_steps: int = 10**9) -> float:
        """Step from t until t_stop; returns the new time. Raises NumericalError."""
        raise NotImplementedError

    def solve(self, state: State) -> None:
        """Non-transient schemes: the steady state, in place. Raises NumericalError."""
        raise NotImplementedError

    @property
    def dt(self) -> float:
        """The step a transient scheme takes next (nan for non-transient ones)."""
        return float("nan")

    def statistics(self) -> dict:
        """Counters of the work done so far (steps, Newton iterations, ...)."""
        return {"steps": self.steps}

    def checkpoint(self) -> dict:
        """What a resumed run needs to continue exactly as this scheme would."""
        return {"steps": np.array(self.steps)}

    def restore(self, data: dict) -> None:
        self.steps = int(data["steps"])
