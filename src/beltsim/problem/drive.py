"""The drive: the surface speed the belt is driven against, as a function of time.

A run starts from rest with the surface moving at the belt speed c and takes it
smoothly to v over ``ramp_time``: the mismatch v(t) - c = (v - c) s(t / ramp_time)
with the C2 smoothstep s(r) = r^3 (10 - 15 r + 6 r^2), which starts and ends with
zero velocity and acceleration, so the ramp itself excites no jump in the belt.
The steady solver's continuation scales the same mismatch from 0 to 1.

``Drive`` is the named structure the kernels read (numba compiles namedtuples).
"""

from __future__ import annotations

from typing import NamedTuple

from numba import njit


class Drive(NamedTuple):
    mismatch: float  # v - c (m/s) once the ramp is over
    ramp_time: float  # s; 0 applies the full mismatch at once


@njit(cache=True)
def ramp(t, t_ramp):
    """Smooth (C2) ramp from 0 to 1 over [0, t_ramp]."""
    if t_ramp <= 0.0 or t >= t_ramp:
        return 1.0
    if t <= 0.0:
        return 0.0
    s = t / t_ramp
    return s * s * s * (10.0 - 15.0 * s + 6.0 * s * s)


@njit(cache=True)
def mismatch(drive, t):
    """v(t) - c."""
    return drive.mismatch * ramp(t, drive.ramp_time)


def profile_times(scene) -> tuple[float, ...]:
    """The times of every row of the scene's profile tables, sorted (for marking plots)."""
    data = scene.to_dict()
    values = (data["motion"]["surface_speed"], data["contact"].get("max_friction"))
    return tuple(sorted({float(row[0]) for v in values if isinstance(v, list) for row in v}))
