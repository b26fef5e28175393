"""The drive: the surface speed v(t) and the friction limit f*(t) over time.

``[motion] surface_speed`` and ``[contact] max_friction`` are each a number, a table of
``[time, value]`` rows or a sine ``{ mean, amplitude, period }``:

* a number: the surface speed starts at the belt speed c (the belt starts from rest)
  and goes smoothly to v over ``ramp_time``: v(t) - c = (v - c) s(t / ramp_time) with
  the C2 smoothstep s(r) = r^3 (10 - 15 r + 6 r^2), which starts and ends with zero
  velocity and acceleration, so the ramp itself excites no jump in the belt; a number
  max_friction is constant;
* a table: interpolated linearly between rows, the first row's value before it and
  the last row's after it (no ramp: the table says what happens when);
* a sine: mean + amplitude sin(2 pi t / period); a speed sine is ramped from c like a
  number, v(t) - c = (mean - c + amplitude sin(2 pi t / period)) s(t / ramp_time).

The steady solver's continuation scales the final mismatch from 0 to 1.
``Drive`` is the named structure the kernels read (numba compiles namedtuples): the
speed profile gives v(t) - c, the friction profile f*(t) / f*, f* the final value
(``Params.fstar``, the friction scale of the model).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from .rules import profile_extremes


class Profile(NamedTuple):
    """One quantity over time as the kernels read it: a table, a sine or a number."""

    times: np.ndarray  # table times (empty: not a table)
    values: np.ndarray  # table values
    level: float  # a number's value, or a sine's mean
    amplitude: float
    period: float  # 0: not a sine
    ramp_time: float  # s; the value grows from 0 with the smoothstep over it; 0: none

    @classmethod
    def constant(cls, value: float, ramp_time: float = 0.0) -> Profile:
        """A profile that holds ``value`` (reached over ``ramp_time``, if given)."""
        return cls(np.zeros(0), np.zeros(0), float(value), 0.0, 0.0, float(ramp_time))


class Drive(NamedTuple):
    """The drive of a run: the surface speed and the friction limit's factor, and on a
    loop the free pulley's load.

    On an open layout ``speed`` is the mismatch v(t) - c; on a loop it is the driver's
    rim speed omega_1(t) R_1 and ``load`` the torque M(t) that the free pulley delivers.
    """

    speed: Profile  # v(t) - c (m/s), or a loop's driver rim speed (m/s)
    friction: Profile  # f*(t) / f* (1 for perfect adhesion)
    load: Profile = Profile.constant(0.0)  # a loop's load torque (N m)

    @classmethod
    def constant(cls, mismatch: float, load: float = 0.0) -> Drive:
        """The full mismatch (or rim speed) and load at once and a constant friction
        limit (the steady solver)."""
        return cls(Profile.constant(mismatch), Profile.constant(1.0), Profile.constant(load))


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
def value(profile, t):
    """A profile's value at time t."""
    times, vals = profile.times, profile.values
    n = times.shape[0]
    if n > 0:
        if t <= times[0]:
            return vals[0]
        if t >= times[n - 1]:
            return vals[n - 1]
        k = np.searchsorted(times, t) - 1
        r = (t - times[k]) / (times[k + 1] - times[k])
        return vals[k] + r * (vals[k + 1] - vals[k])
    out = profile.level
    if profile.period > 0.0:
        out += profile.amplitude * math.sin(2.0 * math.pi * t / profile.period)
    return out * ramp(t, profile.ramp_time)


@njit(cache=True)
def mismatch(drive, t):
    """v(t) - c."""
    return value(drive.speed, t)


@njit(cache=True)
def friction_factor(drive, t):
    """f*(t) / f*."""
    return value(drive.friction, t)


def as_profile(raw, offset: float, scale: float, ramp_time: float) -> Profile:
    """(raw - offset) / scale as a Profile; numbers and sines ramp over ramp_time."""
    if isinstance(raw, list):
        rows = np.array(raw, dtype=float)
        return Profile(rows[:, 0].copy(), (rows[:, 1] - offset) / scale, 0.0, 0.0, 0.0, 0.0)
    if isinstance(raw, dict):
        return Profile(np.zeros(0), np.zeros(0), (raw["mean"] - offset) / scale,
                       raw["amplitude"] / scale, raw["period"], ramp_time)
    return Profile.constant((raw - offset) / scale, ramp_time)


def drive_of(scene, ramp_time: float) -> Drive:
    """The scene's drive; ``ramp_time`` is the speed ramp (numerics.ramp_time)."""
    P = scene.params
    raw_speed, raw = _profiles(scene)
    speed = as_profile(raw_speed, P.c, 1.0, ramp_time)
    friction = Profile.constant(1.0) if raw is None else as_profile(raw, 0.0, P.fstar, 0.0)
    return Drive(speed, friction)


def _profiles(scene):
    """The scene's two profiles: the surface speed and the friction limit of the paper's
    belt, a drive's driver speed and load."""
    data = scene.to_dict()
    if "drive" in data:
        return data["drive"]["driver_speed"], data["drive"]["load_torque"]
    return data["motion"]["surface_speed"], data["contact"].get("max_friction")


def profile_times(scene) -> tuple[float, ...]:
    """The times of every row of the scene's profile tables, sorted (for marking plots)."""
    return tuple(sorted({float(row[0]) for v in _profiles(scene) if isinstance(v, list)
                         for row in v}))


def has_profiles(scene) -> bool:
    """Whether the drive is more than the start-up ramp (a table or a sine anywhere)."""
    return any(isinstance(v, (list, dict)) for v in _profiles(scene))


def period_of(scene) -> float | None:
    """The period of a periodic drive (a sine), None for a drive that settles."""
    periods = [v["period"] for v in _profiles(scene) if isinstance(v, dict)]
    return periods[0] if periods else None


def speed_ramped(scene) -> bool:
    """Whether the surface speed ramps from c (a number or a sine, not a table)."""
    return not isinstance(_profiles(scene)[0], list)


def largest_mismatch(scene) -> float:
    """max abs(v(t) - c) over the profile."""
    lo, hi = profile_extremes(_profiles(scene)[0])
    c = scene.params.c
    return max(abs(lo - c), abs(hi - c))
