"""A stability map of a scene's steady state: the least stable root over one parameter,
and the damping a stable steady state needs; of a straight belt or a closed drive.

For a straight belt each point is the least stable root of the continuous model
linearised about the exact steady state, up to ``BAND_HZ`` of
:mod:`beltsim.simulation.stability`
(:func:`~beltsim.simulation.stability.exact_least_stable`, cached per scene: seconds
when computed, milliseconds when cached). No run and no grid is involved. For a closed
drive, which has no exact spectrum, it is the rightmost eigenvalue of the discrete model
(central form) on the scene's grid with its error, the difference from half the grid
(:func:`~beltsim.simulation.stability_check.discrete_least_stable`, as a run reports
it; cached too); a point whose rate lies within that error is ``UNDECIDED``.

A straight belt's parameters (``PARAMS``):

``damping``
    d (1/s), ``physics.damping``; the steady state does not depend on it, only its
    spectrum does.
``max_friction``
    f* (N/m), ``contact.max_friction``; stick-and-slip scenes only (perfect adhesion has
    no friction limit).
``belt_speed``
    c (m/s), ``motion.belt_speed``, with ``motion.surface_speed`` moved with it so that
    the slip ratio v/c stays the scene's (1.01 in the paper's scenes). The damping d and
    the friction limit stay the scene's: d is a rate in 1/s, not a fraction of a mode's
    critical damping, so it is not rescaled with c.

A closed drive's (``DRIVE_PARAMS``): ``damping`` as above; ``friction_coefficient``, the
default coefficient mu of every pulley, ``contact.friction_coefficient`` (a pulley with a
coefficient of its own keeps it); ``driver_speed`` (rad/s), the driver's speed
(``pulley.NAME.speed``, or ``drive.driver_speed`` in the two-pulley shorthand), a number.

A value at which the scene has no exact steady state (lift-off, gross slip:
:class:`~beltsim.errors.NoSolutionError`) is recorded as such, never as a number; so is
one at which the search finds no root in the band. A value that the scene's rules refuse
(a negative damping, a speed at or above a critical speed) raises
:class:`~beltsim.errors.SceneError`: it is an input error, not a point of the map.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

from ..errors import BeltsimError, NoSolutionError, UsageError
from ..problem.kinds import is_drive_scene

#: The parameters a straight belt's map sweeps, each with the scene key it sets
PARAMS = {"damping": "physics.damping", "max_friction": "contact.max_friction",
          "belt_speed": "motion.belt_speed"}
#: A closed drive's (the driver's speed key depends on the layout: :func:`overrides`)
DRIVE_PARAMS = {"damping": "physics.damping",
                "friction_coefficient": "contact.friction_coefficient",
                "driver_speed": "the driver's speed"}
#: Their units, for tables
UNITS = {"damping": "1/s", "max_friction": "N/m", "belt_speed": "m/s",
         "friction_coefficient": "1", "driver_speed": "rad/s"}
#: The values a map takes when none are given: around the paper's scenes (d = 39 1/s,
#: f* = 1e5 N/m, c = 120 m/s); f* down to full slip (no stick zone below about 1.5e4),
#: c up to just below the critical speed sqrt(a/I) = 129.1 m/s
DEFAULT_VALUES = {"damping": (0.0, 20.0, 39.0, 60.0, 100.0, 150.0, 200.0, 300.0),
                  "max_friction": (1e4, 2e4, 3e4, 5e4, 1e5, 3e5, 1e6, 1e7),
                  "belt_speed": (40.0, 60.0, 80.0, 100.0, 110.0, 120.0, 125.0, 128.0)}
#: A closed drive's: d around the shipped drives' 20 1/s; mu down towards gross slip of
#: the shipped drives' rated loads; driver speeds around their 150 rad/s
DRIVE_DEFAULT_VALUES = {"damping": (0.0, 5.0, 10.0, 20.0, 40.0, 80.0),
                        "friction_coefficient": (0.3, 0.4, 0.5, 0.7, 1.0),
                        "driver_speed": (50.0, 100.0, 150.0, 200.0, 300.0)}
#: The width (1/s in d) to which :func:`critical_damping` narrows its bracket
TOLERANCE = 0.5
#: The largest damping (1/s) :func:`critical_damping` tries before it gives up
MAX_DAMPING = 1.0e4

#: A point's status: the least stable root grows
UNSTABLE = "unstable"
#: Every root found in the band decays (or is neutral: rate 0 counts as stable)
STABLE = "stable"
#: A discrete estimate whose rate lies within its error either way (a closed drive)
UNDECIDED = "undecided"
#: No exact steady state at this value (NoSolutionError)
NO_STEADY_STATE = "no steady state"
#: A steady state, but the search found no root in the band
NO_ROOT = "no root found"


def params_of(scene) -> dict:
    """The parameters a map of ``scene`` sweeps: ``DRIVE_PARAMS`` for a closed drive,
    else ``PARAMS``."""
    return DRIVE_PARAMS if is_drive_scene(scene) else PARAMS


def default_values(scene, param: str) -> tuple:
    """The values a map of ``param`` takes when none are given."""
    return (DRIVE_DEFAULT_VALUES if is_drive_scene(scene) else DEFAULT_VALUES)[param]


def check_scene(scene, param: str) -> None:
    """Refuse a scene or a parameter that a map cannot take, with one line.

    Parameters
    ----------
    scene : Scene or DriveScene
        The scene to map.
    param : str
        One of :func:`params_of` the scene.

    Raises
    ------
    UsageError
        A parameter that is not the layout's; a quasistatic scene or a periodic one (no
        steady state to linearise about); ``max_friction`` of a perfect-adhesion scene;
        ``belt_speed`` with a surface speed that is a profile, not a number; a drive's
        ``driver_speed`` that is a table, not a number.
    """
    from ..simulation.stability import applies

    names = params_of(scene)
    if param not in names:
        kind = "a closed drive" if is_drive_scene(scene) else "a straight belt"
        raise UsageError(f"--param: {param!r} is not a parameter of {kind}'s map "
                         f"({', '.join(names)})")
    if not applies(scene):
        raise UsageError("stability-map: the scene must be inertial (physics.inertia = true) "
                         "and settle (no sine in its profiles)")
    if is_drive_scene(scene):
        P = scene.params
        if param == "driver_speed" and not isinstance(P.pulleys[P.driver].speed,
                                                      (int, float)):
            raise UsageError("--param driver_speed: the driver's speed must be a number "
                             "(ramped from rest), not a table")
        return
    data = scene.to_dict()
    if param == "max_friction" and data["contact"]["friction"] == "stick":
        raise UsageError("--param max_friction: the scene is perfect adhesion "
                         '(contact.friction = "stick"), which has no friction limit')
    if param == "belt_speed" and not all(
            isinstance(data["motion"][k], (int, float)) for k in ("belt_speed",
                                                                   "surface_speed")):
        raise UsageError("--param belt_speed: the map holds v/c fixed and needs constant "
                         "motion.belt_speed and motion.surface_speed, not profiles")


def overrides(scene, param: str, value: float) -> list:
    """The keys that set ``param`` to ``value`` in ``scene``.

    Parameters
    ----------
    scene : Scene
        The scene mapped.
    param : str
        One of :func:`params_of` the scene.
    value : float
        The parameter's value.

    Returns
    -------
    list of (str, float)
        ``belt_speed`` sets the surface speed too, at the scene's ratio v/c.
    """
    if param == "driver_speed":
        from ..beltdrive.scene import driver_speed_key

        return [(driver_speed_key(scene.to_dict()), float(value))]
    keys = [(params_of(scene)[param], float(value))]
    if param == "belt_speed":
        motion = scene.to_dict()["motion"]
        ratio = motion["surface_speed"] / motion["belt_speed"]
        keys.append(("motion.surface_speed", ratio * float(value)))
    return keys


def check_values(scene, param: str, values) -> list[float]:
    """The values as floats, each checked by the scene's rules before any root search.

    Parameters
    ----------
    scene : Scene
        The scene mapped.
    param : str
        One of :func:`params_of` the scene.
    values : iterable of float
        The parameter's values.

    Returns
    -------
    list of float

    Raises
    ------
    SceneError
        The first value the scene's rules refuse (its message names the key and the rule).
    """
    values = [float(v) for v in values]
    for v in values:
        scene.with_overrides(overrides(scene, param, v))
    return values


def point(scene, param: str, value: float) -> dict:
    """The least stable root of ``scene`` with ``param`` set to ``value``.

    Parameters
    ----------
    scene : Scene or DriveScene
        A scene that :func:`check_scene` accepts.
    param : str
        One of :func:`params_of` the scene.
    value : float
        The parameter's value.

    Returns
    -------
    dict
        ``value``; ``status`` (``UNSTABLE``, ``STABLE``, ``UNDECIDED``,
        ``NO_STEADY_STATE`` or ``NO_ROOT``); ``rate`` (1/s), ``frequency``
        (Hz) and ``growing`` (how many roots in the band grow; a drive's estimate: 1 or
        0), each None unless a root was found; ``error`` (1/s, a drive's estimate's;
        None for exact roots); ``reason`` (why there is none, else empty); ``cached``
        (whether the root came from the cache) and ``wall_time`` (s).

    Raises
    ------
    SceneError
        The scene's rules refuse the value.
    """
    from ..simulation.stability import exact_least_stable
    from ..simulation.stability_check import discrete_least_stable

    varied = scene.with_overrides(overrides(scene, param, value))
    computed = []
    row = {"value": float(value), "status": NO_ROOT, "rate": None, "frequency": None,
           "growing": None, "error": None, "reason": "", "cached": True}
    search = discrete_least_stable if is_drive_scene(scene) else exact_least_stable
    start = time.perf_counter()
    try:
        found = search(varied, notice=computed.append)
    except NoSolutionError as exc:
        row.update(status=NO_STEADY_STATE, reason=str(exc))
    except BeltsimError as exc:  # the steady state exists, but no root was found
        row.update(status=NO_ROOT, reason=str(exc))
    else:
        # an exact root's rate of 0 counts as stable; an estimate's sign within its error
        # is undecided
        status = found.verdict if found.error is not None else (
            UNSTABLE if found.rate > 0.0 else STABLE)
        row.update(status=status, rate=found.rate, frequency=found.frequency,
                   growing=found.growing, error=found.error)
    row.update(cached=not computed, wall_time=time.perf_counter() - start)
    return row


def sweep(scene, param: str, values, progress=None) -> list[dict]:
    """The map of one parameter: :func:`point` at each value, in the order given.

    Parameters
    ----------
    scene : Scene
        A straight belt that :func:`check_scene` accepts.
    param : str
        One of :func:`params_of` the scene.
    values : iterable of float
        The parameter's values.
    progress : callable, optional
        ``progress(row)`` after each point.

    Returns
    -------
    list of dict
        One row per value (:func:`point`), with ``param`` added.

    Raises
    ------
    UsageError
        :func:`check_scene` refuses the scene or the parameter.
    SceneError
        A value the scene's rules refuse; checked for every value before any root
        search.
    """
    check_scene(scene, param)
    values = check_values(scene, param, values)
    rows = []
    for v in values:
        row = {"param": param, **point(scene, param, v)}
        rows.append(row)
        if progress is not None:
            progress(row)
    return rows


@dataclass
class CriticalDamping:
    """The damping d at which a scene's steady state turns stable in the model.

    Attributes
    ----------
    damping : float or None
        The smallest damping found (1/s) at which the least stable rate in the band is
        <= 0: the upper end of the final bracket. 0 when the undamped state is stable;
        None when there is no steady state, or no stable d up to ``max_damping``.
    lower : float or None
        The bracket's lower end (1/s), where the least stable rate is > 0 (None when
        ``damping`` is 0 or None); ``damping - lower <= tolerance``.
    tolerance : float
        The bracket's width asked for (1/s).
    evaluations : list of dict
        Every point computed (:func:`point` rows with ``param`` ``"damping"``), in order.
    reason : str
        Why ``damping`` is None; else empty.
    """

    damping: float | None
    lower: float | None
    tolerance: float
    evaluations: list = field(default_factory=list)
    reason: str = ""

    def describe(self) -> str:
        """One line: the critical damping and its bracket, or why there is none."""
        if self.damping is None:
            return f"no critical damping: {self.reason}"
        if self.lower is None:
            return "stable without damping (d = 0)"
        return (f"critical damping d = {self.damping:.4g} 1/s: the least stable rate is "
                f"> 0 at d = {self.lower:.4g} and <= 0 at d = {self.damping:.4g} 1/s "
                f"({len(self.evaluations)} root searches, tolerance {self.tolerance:g} 1/s)")


def critical_damping(scene, tol: float = TOLERANCE, max_damping: float = MAX_DAMPING,
                     progress=None) -> CriticalDamping:
    """The smallest damping d at which the scene's least stable rate is <= 0 (a drive's:
    the discrete estimate's, whose error each evaluation records).

    Bracketing, then bisection on d. From the scene's own d: if the rate there is > 0,
    d is doubled (from 50 1/s when it is 0) until the rate is <= 0; if it is already
    <= 0, the bracket is [0, d] unless the undamped state is stable too. The bracket is
    then halved until narrower than ``tol``. The rate is the largest real part among
    the roots in the band, a continuous function of d (the maximum of continuous root
    branches) but for a root that crosses the band's edge; bisection finds a sign change
    of it, which is the smallest one where the rate falls with d, as in every map of the
    paper's scenes.

    Parameters
    ----------
    scene : Scene or DriveScene
        An inertial scene that settles (:func:`check_scene`).
    tol : float, optional
        The bracket's final width (1/s in d); default ``TOLERANCE``.
    max_damping : float, optional
        The largest d tried (1/s); default ``MAX_DAMPING``.
    progress : callable, optional
        ``progress(row)`` after each root search (:func:`point`).

    Returns
    -------
    CriticalDamping

    Raises
    ------
    UsageError
        :func:`check_scene` refuses the scene, or ``tol`` is not > 0.
    """
    check_scene(scene, "damping")
    if not (tol > 0 and math.isfinite(tol)):
        raise UsageError(f"tol: must be > 0 1/s, got {tol}")
    evaluations = []

    def rate(d):
        row = {"param": "damping", **point(scene, "damping", d)}
        evaluations.append(row)
        if progress is not None:
            progress(row)
        return row

    def give_up(row):
        return CriticalDamping(None, None, tol, evaluations,
                               f"{row['status']} at d = {row['value']:g} 1/s: {row['reason']}")

    d0 = float(scene.params.damping)
    first = rate(d0)
    if first["rate"] is None:  # no steady state, whatever d: the state does not depend on it
        return give_up(first)
    if first["rate"] <= 0.0:
        if d0 == 0.0:
            return CriticalDamping(0.0, None, tol, evaluations)
        below = rate(0.0)
        if below["rate"] is None:
            return give_up(below)
        if below["rate"] <= 0.0:
            return CriticalDamping(0.0, None, tol, evaluations)
        lo, hi = 0.0, d0
    else:
        lo, hi = d0, max(2.0 * d0, 50.0)
        while True:
            if hi > max_damping:
                return CriticalDamping(None, None, tol, evaluations,
                                       f"the rate is still > 0 at d = {lo:g} 1/s, and "
                                       f"max_damping is {max_damping:g} 1/s")
            row = rate(hi)
            if row["rate"] is None:
                return give_up(row)
            if row["rate"] <= 0.0:
                break
            lo, hi = hi, 2.0 * hi
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        row = rate(mid)
        if row["rate"] is None:
            return give_up(row)
        if row["rate"] > 0.0:
            lo = mid
        else:
            hi = mid
    return CriticalDamping(hi, lo, tol, evaluations)


#: The columns of a map's CSV, in order (text columns: ``TEXT_COLUMNS``)
COLUMNS = ("value", "status", "rate", "frequency", "growing", "error", "cached",
           "wall_time", "reason")
TEXT_COLUMNS = ("status", "reason")


def csv_columns(rows) -> list:
    """The rows as the columns of ``COLUMNS`` (None as NaN, booleans as 0 or 1), for
    :func:`beltsim.io.files.write_csv`.

    Parameters
    ----------
    rows : list of dict
        Rows of :func:`sweep`.

    Returns
    -------
    list of list
    """
    def value(row, c):
        v = row[c]
        if c in TEXT_COLUMNS:
            return v
        return math.nan if v is None else float(v)
    return [[value(r, c) for r in rows] for c in COLUMNS]
