"""What the drive's pictures take: arrays checked with one-line messages, and the drive
they are drawn on as a :class:`~beltsim.beltdrive.pulleys.PulleyLayout`.

Every picture of :mod:`beltsim.beltdrive.drawing`, :mod:`beltsim.beltdrive.plots` and
:mod:`beltsim.beltdrive.characteristic` reads its input through these functions, so a
bad argument is refused alike everywhere: a ValueError naming the argument and the rule.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from .geometry import Geometry
from .pulleys import Pulley, PulleyLayout

#: The two-pulley drive's pulleys, as the shorthand of a scene names them.
TWO_PULLEY_ROLES = ("driver", "driven")


def vector(name, values, n=None, per="node") -> np.ndarray:
    """``values`` as a 1-D array of finite floats (``n`` of them, one per ``per``)."""
    try:
        a = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: must be an array of numbers") from None
    if a.ndim != 1:
        raise ValueError(f"{name}: must be one-dimensional, got shape {a.shape}")
    if n is not None and len(a) != n:
        raise ValueError(f"{name}: {len(a)} values for {n} {per}s (one per {per})")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: must be finite (holds NaN or inf)")
    return a


def mask(name, values, n) -> np.ndarray:
    """A boolean mask of ``n`` nodes (booleans, or integers 0 and 1)."""
    m = np.asarray(values)
    if m.ndim != 1 or len(m) != n:
        raise ValueError(f"{name}: {m.size} values of shape {m.shape} for {n} nodes (one "
                         f"boolean per node)")
    if m.dtype != bool:
        if m.dtype.kind not in "iu" or not np.all((m == 0) | (m == 1)):
            raise ValueError(f"{name}: must be booleans (or 0 and 1), got dtype {m.dtype}")
        m = m.astype(bool)
    return m


def loads(name, values, n) -> np.ndarray:
    """``n`` plane vectors (Fx, Fy), shape (n, 2), finite."""
    try:
        a = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: must be an array of numbers") from None
    if a.shape != (n, 2):
        raise ValueError(f"{name}: shape {a.shape} for {n} pulleys (one (Fx, Fy) per "
                         f"pulley)")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: must be finite (holds NaN or inf)")
    return a


def nodes(layout, x) -> np.ndarray:
    """The loop's node coordinates: increasing in [0, Lambda), at least three."""
    x = vector("x", x)
    lam = layout.loop_length
    if len(x) < 3:
        raise ValueError(f"x: needs at least 3 nodes on the loop, got {len(x)}")
    if not np.all(np.diff(x) > 0):
        raise ValueError("x: the nodes must increase strictly along the loop")
    if x[0] < 0 or not x[-1] < lam:
        raise ValueError(f"x: nodes must lie in [0, {lam:.6g}) m, the loop without its "
                         f"end point, got [{x[0]:.6g}, {x[-1]:.6g}]")
    return x


def drive_layout(drive, roles=None) -> tuple[PulleyLayout, tuple[str, ...] | None]:
    """The layout a picture draws and the pulleys' roles, if known.

    Parameters
    ----------
    drive : PulleyLayout, DriveParams or Geometry
        A layout as it is; a drive's parameters by their ``layout`` (and their pulleys'
        roles); a two-pulley :class:`~beltsim.beltdrive.geometry.Geometry` as the layout
        of its shorthand (the driver's centre at the origin, the driven pulley's at
        (C, 0), both inner), so that two pulleys are drawn by the same code as N.
    roles : sequence of str, optional
        ``"driver"``, ``"driven"``, ``"idler"``... per pulley, in the belt's order; they
        name the tight span (arriving at the driver) and the slack one (leaving it).

    Returns
    -------
    (PulleyLayout, tuple of str or None)

    Raises
    ------
    ValueError
        Another kind of object, or roles of another number than the pulleys.
    """
    if isinstance(drive, Geometry):
        layout = PulleyLayout([Pulley("driver", (0.0, 0.0), drive.R1, 1),
                               Pulley("driven", (drive.C, 0.0), drive.R2, 1)])
        found = TWO_PULLEY_ROLES
    elif isinstance(drive, PulleyLayout):
        layout, found = drive, None
    elif isinstance(getattr(drive, "layout", None), PulleyLayout):
        layout, found = drive.layout, tuple(p.role for p in drive.pulleys)
    else:
        raise ValueError(f"layout: must be a PulleyLayout, a drive's DriveParams or a "
                         f"two-pulley Geometry, got {type(drive).__name__}")
    if roles is not None:
        found = tuple(str(r) for r in roles)
        if len(found) != len(layout):
            raise ValueError(f"roles: {len(found)} values for {len(layout)} pulleys (one "
                             f"per pulley)")
    return layout, found


def span_names(layout, roles) -> list[str]:
    """Each span's name in the belt's order: ``"tight span"`` arriving at the driver
    (the loop's largest tension), ``"slack span"`` leaving it (its smallest), ``""`` for
    the others and for all when the roles are not known."""
    n = len(layout)
    out = [""] * n
    if roles is not None and "driver" in roles:
        d = list(roles).index("driver")
        out[(d - 1) % n] = "tight span"
        out[d] = "slack span"
    return out


def curve(name, spec, at, grid):
    """An analytic curve: a callable sampled on ``grid``, or an array beside ``at``."""
    if callable(spec):
        return grid, np.array([float(spec(v)) for v in grid])
    return at, vector(name, spec, len(at), "point")


def analytic_parts(name, analytic, keys) -> dict:
    """The analytic curves given (a mapping with some of ``keys``)."""
    if analytic is None:
        return {}
    if not isinstance(analytic, Mapping):
        raise ValueError(f"{name}: must be a mapping with keys {', '.join(keys)}, got "
                         f"{type(analytic).__name__}")
    unknown = [k for k in analytic if k not in keys]
    if unknown:
        raise ValueError(f"{name}: unknown key {unknown[0]!r} (known: {', '.join(keys)})")
    return dict(analytic)


__all__ = ["analytic_parts", "curve", "drive_layout", "loads", "mask", "nodes",
           "span_names", "vector"]
