"""A run's stability entry: the scene's least stable mode (exact, or the discrete
estimate where there is no exact spectrum), and the run's numerical damping of it.

Apart from :mod:`beltsim.simulation.stability` because it linearises the discrete model
about a steady state that a :class:`~beltsim.simulation.controller.Simulation` solves
for: :func:`beltsim.run` and ``beltsim run`` call it after the run.
"""

from __future__ import annotations

import math
from dataclasses import asdict

import numpy as np

from ..errors import BeltsimError
from ..io import cache
from ..problem.kinds import is_drive_scene
from .stability import (
    FORMAT,
    NOTICE,
    Stability,
    applies,
    enabled,
    exact_least_stable,
    physics_of,
    step_damping,
)

#: The discrete estimate's finest grid: a finer scene's estimate is made on this many
#: elements. The sparse sweep's band follows the grid's highest frequency, so its cost
#: grows about as the square of the grid (the estimate with its half grid on drive_flat:
#: 1.6 s on 400 elements, 5.4 s on 800, 23 s on 1600, 60 s on 3200), and a run on a fine
#: grid must not wait for it.
CHECK_ELEMENTS = 800


def least_stable(scene, notice=None) -> Stability:
    """The least stable eigenvalue of the scene's model about its steady state: the exact
    roots (:func:`~beltsim.simulation.stability.exact_least_stable`) for a straight belt
    with an exact steady state, else the discrete estimate (:func:`discrete_least_stable`).

    Parameters
    ----------
    scene : Scene or DriveScene
        An inertial scene that settles (:func:`~beltsim.simulation.stability.applies`).
    notice : callable, optional
        ``notice(text)`` once before a computation of seconds (not for a cached one).

    Raises
    ------
    BeltsimError
        The steady state or its spectrum cannot be computed.
    """
    if not is_drive_scene(scene) and _has_exact(scene):
        return exact_least_stable(scene, notice)
    return discrete_least_stable(scene, notice)


def discrete_least_stable(scene, notice=None) -> Stability:
    """The rightmost eigenvalue of the discrete model with the central gyroscopic form on
    the scene's grid (at most CHECK_ELEMENTS), its error estimated as its difference from
    the same on half that grid; cached per scene and grid."""
    # the grid as the scene states it (its default when unset): no discretisation needed
    elements = scene.to_dict().get("numerics", {}).get("elements")
    if elements is not None:
        elements = min(elements, CHECK_ELEMENTS)
    key = cache.key_of("stability", [FORMAT, "discrete", physics_of(scene), elements])
    found = cache.load(key)
    if found is not None:
        return Stability.from_dict(found)
    if notice is not None:
        notice(NOTICE)
    lam, n = _rightmost(scene, elements)
    coarse, _ = _rightmost(scene, max(n // 2, 20))
    out = Stability(rate=float(lam.real), frequency=float(abs(lam.imag) / (2 * math.pi)),
                    method="discrete", elements=n, error=abs(lam.real - coarse.real),
                    growing=int(lam.real > 0.0))
    cache.store(key, asdict(out))
    return out


def _has_exact(scene) -> bool:
    from ..problem import analytic

    try:
        analytic.solve(scene)
    except analytic.NoSolutionError:
        return False
    return True


def _rightmost(scene, elements=None) -> tuple[complex, int]:
    """The central form's least stable eigenvalue on the scene's grid (or ``elements``)
    and that grid's element count."""
    central = scene.with_overrides([("numerics.gyroscopic", "central")])
    if is_drive_scene(scene):
        from ..physics.loop_modes import drive_modes

        found = drive_modes(central, count=1, elements=elements, method="sparse")
        return complex(found.least_stable), found.elements
    from ..physics.modes import growth_rate

    if elements is not None:
        central = central.with_overrides([("numerics.elements", elements)])
    g = growth_rate(central)
    return complex(g.rate, 2 * math.pi * g.frequency), g.elements


def with_damping(found: Stability, scene, integrator: str, step: float | None) -> Stability:
    """``found`` with the run's damping of its mode: its grid's and its steps' (1/s).

    The grid's is the exact (or central) rate minus that of the run's own discrete model's
    eigenvalue nearest to the mode; the steps' is that eigenvalue's rate minus
    ``ln(abs(R(lambda h))) / h`` at the run's last step h
    (:func:`~beltsim.simulation.stability.step_damping`)."""
    if not found.unstable:
        return found
    target = complex(found.rate, 2 * math.pi * found.frequency)
    key = cache.key_of("grid-mode", [FORMAT, scene.to_dict(), target.real, target.imag])
    entry = cache.load(key)
    if entry is None:
        lam = _nearest(scene, target)
        entry = {"re": lam.real, "im": lam.imag}
        cache.store(key, entry)
    lam = complex(entry["re"], entry["im"])
    steps = step_damping(integrator, lam, step) if step is not None and step > 0.0 else None
    return Stability(**{**asdict(found), "grid_damping": found.rate - lam.real,
                        "step_damping": steps})


def _nearest(scene, target: complex) -> complex:
    """The eigenvalue nearest to ``target`` of the scene's own discrete model (its grid and
    gyroscopic form)."""
    from ..physics.modes import eigenvalues_near, linearisation, pencil, steady_discretisation

    A, B = pencil(*linearisation(*steady_discretisation(scene)))
    return complex(eigenvalues_near(A, target, 1, B)[0])


def check(result, notice=None) -> Stability | str | None:
    """The run's stability entry: the scene's least stable mode, with the run's damping of
    it when it grows; a sentence where it could not be computed; None where it does not
    apply (:func:`~beltsim.simulation.stability.applies`) or the check is off
    (:func:`~beltsim.simulation.stability.enabled`)."""
    scene = result.scene
    if not (enabled() and applies(scene)):
        return None
    try:
        found = least_stable(scene, notice)
        if not result.time_accurate:
            return found
        return with_damping(found, scene, result.numerics.integrator,
                            result.statistics.get("last_step"))
    except (BeltsimError, ArithmeticError, np.linalg.LinAlgError) as exc:
        return f"not checked: {exc}"


def attach(result, notice: bool = False) -> None:
    """Set ``result.stability`` (:func:`check`), printing a notice on stderr while a
    scene's spectrum is computed when ``notice``."""
    from .stability import stderr_notice

    result.stability = check(result, notice=stderr_notice(notice))


def warn(result) -> None:
    """Print the one-line warning of a run whose steady state is unstable in the model
    (on stderr, as ``beltsim: warning: ...``)."""
    import sys

    if isinstance(result.stability, Stability) and result.stability.warning():
        print(f"beltsim: warning: {result.stability.warning()}", file=sys.stderr)
