"""The entry points for every kind of scene: a straight belt or a closed drive.

A straight belt (:class:`~beltsim.problem.scene.Scene`) and a closed drive
(:class:`~beltsim.beltdrive.scene.DriveScene`) are read, run and solved by different
parts of the package; this module, above both, is the one place that tells them apart.
Every function here takes either kind, as a scene, a shipped scene's name (its file's
stem, ``"paper_slip"``, ``"drive_flat"``; :func:`beltsim.scene_names`), a scene file's path or
a scene's tables::

    import beltsim
    scene = beltsim.load_scene("drive_flat", {"drive.load_torque": 40.0})
    exact = beltsim.solve(scene)              # the exact steady state
    result = beltsim.run("paper_slip")        # from rest to steady state
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from .errors import SceneError, UsageError
from .problem.kinds import is_drive_scene, scene_from_tables
from .problem.scene import Scene
from .problem.shipped import paper_scene_name, scene_names, shipped_text
from .problem.tomlio import parse_toml, read_scene_file

__all__ = ["forced_response", "is_drive_scene", "load_scene", "modes", "paper_scene", "run",
           "scene_from_tables", "scene_names", "shipped_scene", "solve"]

if TYPE_CHECKING:
    from .beltdrive.scene import DriveScene


def _looks_like_name(text: str) -> bool:
    """Whether ``text`` is meant as a shipped scene's name rather than a path."""
    return "/" not in text and "\\" not in text and not text.endswith(".toml")


def load_scene(scene, overrides=()) -> Scene | DriveScene:
    """A scene of either kind, with overrides applied.

    Parameters
    ----------
    scene : Scene, DriveScene, str, Path or dict
        A scene; a shipped scene's name, its file's stem (:func:`beltsim.scene_names`); a scene
        file's path; or a scene's tables. A name that is not an existing file
        (``"paper_slip"``) is looked up among the shipped scenes.
    overrides : dict, str or iterable of str or (str, value), optional
        Keys to set, as :meth:`Scene.with_overrides <beltsim.Scene.with_overrides>` takes
        them.

    Returns
    -------
    Scene or DriveScene
        A closed drive where the scene has a ``[drive]`` section.

    Raises
    ------
    SceneError
        A missing or unreadable file, malformed TOML, or a broken rule.
    MissingInputError
        A name no shipped scene has (the message lists those that ship).

    Examples
    --------
    >>> scene = beltsim.load_scene("paper_slip", ["contact.max_friction=2e5"])  # doctest: +SKIP
    >>> drive = beltsim.load_scene("runs/drive_flat.toml")                     # doctest: +SKIP
    """
    if isinstance(scene, Scene) or is_drive_scene(scene):
        loaded = scene
    elif isinstance(scene, dict):
        loaded = scene_from_tables(scene)
    elif isinstance(scene, (str, Path)):
        text = str(scene)
        if isinstance(scene, str) and _looks_like_name(text) and not Path(text).is_file():
            return shipped_scene(text, overrides)
        loaded = scene_from_tables(parse_toml(read_scene_file(scene), text), source=text)
    else:
        raise SceneError(f"scene: must be a Scene, a DriveScene, a shipped scene's name, a "
                         f"scene file's path or a dict of tables, got "
                         f"{type(scene).__name__}")
    return loaded.with_overrides(overrides) if overrides else loaded


def shipped_scene(name: str, overrides=()) -> Scene | DriveScene:
    """A scene shipped with beltsim, by name: its file's stem (see :func:`beltsim.scene_names`).

    Parameters
    ----------
    name : str
        ``"paper_slip"``, ``"drive_flat"``, ...
    overrides : dict, str or iterable of str or (str, value), optional
        Keys to set, as :meth:`Scene.with_overrides <beltsim.Scene.with_overrides>` takes
        them.

    Returns
    -------
    Scene or DriveScene

    Raises
    ------
    MissingInputError
        The package holds no such scene (or was installed without its scene files); the
        message lists the names that ship and the nearest one.
    """
    scene = scene_from_tables(parse_toml(shipped_text(name), name), source=name)
    return scene.with_overrides(overrides) if overrides else scene


def paper_scene(name: str, overrides=()) -> Scene:
    """One of the paper's scenes: "quasistatic", "inertia" or "slip".

    Parameters
    ----------
    name : str
        The short name, or the shipped scene's (``"slip"`` or ``"paper_slip"``).
    overrides : dict, str or iterable of str or (str, value), optional
        Keys to set.

    Returns
    -------
    Scene

    Raises
    ------
    SceneError
        Not one of the paper's scenes.
    """
    return shipped_scene(paper_scene_name(name), overrides)


def run(scene, progress: bool = False, raise_on_failure: bool = True,
        snapshot_interval: float | None = None, trackers=(), overrides=(),
        stability: bool = True):
    """Run a scene of either kind from rest to steady state, against its exact one.

    Parameters
    ----------
    scene : Scene, DriveScene, str, Path or dict
        What :func:`load_scene` takes: a scene, a shipped scene's name, a file's path.
    progress : bool, optional
        Show a progress bar (``tqdm.auto``: a widget in Jupyter, text elsewhere).
    raise_on_failure : bool, optional
        Raise on a numerical failure (default); when False, return a result with status
        FAILED holding the last good state.
    snapshot_interval : float, optional
        Store the state every so many seconds of simulated time; default the scene's
        ``numerics.snapshot_interval``.
    trackers : sequence of Tracker, optional
        The user's own trackers (:class:`beltsim.Tracker`), called at every check.
    overrides : dict, str or iterable of str or (str, value), optional
        Keys to set first.
    stability : bool, optional
        Check whether the steady state is stable in the model (``result.stability``);
        seconds once per scene, then cached.

    Returns
    -------
    RunResult
        The run's outcome, for either layout (see
        :func:`beltsim.simulation.controller.run`), with its exact steady state.

    Raises
    ------
    SceneError, MissingInputError
        A scene that cannot be read.
    NumericalError
        On a numerical failure, with ``raise_on_failure``.

    Examples
    --------
    >>> result = beltsim.run("paper_slip", overrides={"numerics.elements": 300})  # doctest: +SKIP
    >>> result.converged, result.errors()["total_friction"]                      # doctest: +SKIP
    """
    from .simulation.controller import run as run_scene

    result = run_scene(load_scene(scene, overrides), progress=progress,
                       raise_on_failure=raise_on_failure, snapshot_interval=snapshot_interval,
                       trackers=trackers)
    if stability:
        import sys

        from .simulation.stability_check import attach

        attach(result, notice=progress or sys.stderr.isatty())
    return result


def solve(scene, model: str | None = None, overrides=()):
    """The exact steady state of a scene of either kind.

    Parameters
    ----------
    scene : Scene, DriveScene, str, Path or dict
        What :func:`load_scene` takes.
    model : str, optional
        A straight belt: "stick" (perfect adhesion) or "slip" (stick and slip); default
        from ``contact.friction``. A closed drive: "string" (the creep theory of the
        extensible string) or the scene's own ``physics.model``; default the scene's
        model, the solution ``beltsim analytic`` writes and a run is compared with.
    overrides : dict, str or iterable of str or (str, value), optional
        Keys to set first.

    Returns
    -------
    AnalyticSolution, StringSolution or the beam's solution
        Each has ``summary()``.

    Raises
    ------
    NoSolutionError
        The scene has no steady state (gross slip, lift-off).
    UsageError
        A model the scene has no exact solution for.

    Examples
    --------
    >>> beltsim.solve("drive_flat").summary()["speed_ratio"]        # doctest: +SKIP
    """
    scene = load_scene(scene, overrides)
    if is_drive_scene(scene):
        from .beltdrive.exact import exact_state, string_state

        P = scene.params
        if model is None or model == P.model:
            return exact_state(P)  # as `beltsim analytic` and a run's comparison
        if model == "string":
            return string_state(P)
        raise UsageError(f'model: must be "string" or "{P.model}" for this drive, '
                         f"got {model!r}")
    from .problem.analytic import solve as solve_straight

    if model not in (None, "stick", "slip"):
        raise UsageError(f'model: must be "stick" or "slip" for a straight belt, got {model!r}')
    return solve_straight(scene, model)


def modes(scene, count: int | None = None, f_max: float | None = None,
          elements: int | None = None, overrides=()):
    """The lowest modes of a closed drive linearised about its steady state.

    Parameters
    ----------
    scene : DriveScene, str, Path or dict
        What :func:`load_scene` takes; a closed drive with inertia.
    count : int, optional
        List at most this many modes, the lowest (default 10 when ``f_max`` is None).
    f_max : float, optional
        List only the modes up to this frequency (Hz).
    elements : int, optional
        The grid (default the scene's ``numerics.elements``, else 200: a dense
        eigensolver).
    overrides : dict, str or iterable of str or (str, value), optional
        Keys to set first.

    Returns
    -------
    DriveModes
        The modes by increasing frequency (:mod:`beltsim.physics.loop_modes`): each
        one's eigenvalue and shape, and the least stable eigenvalue.

    Raises
    ------
    UsageError
        A straight belt (no pulleys), or a bad count, bound or grid.
    SceneError
        A quasistatic drive.
    NumericalError
        The steady state could not be solved for.

    Examples
    --------
    >>> found = beltsim.modes("serpentine_accessory", count=6)   # doctest: +SKIP
    >>> print(found.table())                                   # doctest: +SKIP
    """
    scene = load_scene(scene, overrides)
    if not is_drive_scene(scene):
        raise UsageError("modes: a closed drive's (a scene with [drive]); this is a straight "
                         "belt")
    from .physics.loop_modes import drive_modes

    return drive_modes(scene, count=count, f_max=f_max, elements=elements)


def forced_response(scene, frequencies, elements: int | None = None, overrides=()):
    """A closed drive's linear response to a sine on its driver's speed.

    Parameters
    ----------
    scene : DriveScene, str, Path or dict
        What :func:`load_scene` takes; a closed drive with inertia.
    frequencies : array_like
        The fluctuation's frequencies (Hz).
    elements : int, optional
        The grid (default the scene's ``numerics.elements``, else 200).
    overrides : dict, str or iterable of str or (str, value), optional
        Keys to set first.

    Returns
    -------
    ForcedResponse
        Each span's tension and each free pulley's speed per rad/s of the driver's
        amplitude, complex (:mod:`beltsim.physics.loop_modes`).

    Raises
    ------
    UsageError
        A straight belt, or bad frequencies.
    SceneError
        A quasistatic drive.

    Examples
    --------
    >>> fr = beltsim.forced_response("serpentine_accessory", [20, 48, 100])  # doctest: +SKIP
    >>> fr.amplitudes(1.5)["tension[pump-crankshaft]"]                     # doctest: +SKIP
    """
    scene = load_scene(scene, overrides)
    if not is_drive_scene(scene):
        raise UsageError("forced_response: a closed drive's (a scene with [drive]); this is "
                         "a straight belt")
    from .physics.loop_modes import forced_response as linear_response

    return linear_response(scene, frequencies, elements=elements)
