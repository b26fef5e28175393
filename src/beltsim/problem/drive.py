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


class Profiles(NamedTuple):
    """Several profiles in one structure, which numba reads with one type whatever
    their number: profile k's table rows are ``times[start[k]:start[k + 1]]``."""

    start: np.ndarray  # int64 (n + 1)
    times: np.ndarray
    values: np.ndarray
    level: np.ndarray  # (n) each as in Profile
    amplitude: np.ndarray
    period: np.ndarray
    ramp_time: np.ndarray

    @classmethod
    def of(cls, profiles) -> Profiles:
        """The bank of a sequence of :class:`Profile`."""
        ps = list(profiles)
        counts = [len(p.times) for p in ps]
        times = [p.times for p in ps] or [np.zeros(0)]
        values = [p.values for p in ps] or [np.zeros(0)]
        return cls(np.concatenate([[0], np.cumsum(counts)]).astype(np.int64),
                   np.concatenate(times).astype(float),
                   np.concatenate(values).astype(float),
                   *(np.array([getattr(p, f) for p in ps], dtype=float)
                     for f in ("level", "amplitude", "period", "ramp_time")))

    @classmethod
    def constants(cls, values) -> Profiles:
        """A bank of constant profiles."""
        return cls.of(Profile.constant(v) for v in values)

    def profile(self, k: int) -> Profile:
        """Profile k."""
        a, b = self.start[k], self.start[k + 1]
        return Profile(self.times[a:b], self.values[a:b], float(self.level[k]),
                       float(self.amplitude[k]), float(self.period[k]),
                       float(self.ramp_time[k]))


NO_LOADS = Profiles.of([])


class Drive(NamedTuple):
    """The drive of a run: the surface speed and the friction limit's factor, and on a
    loop each free pulley's load.

    On an open layout ``speed`` is the mismatch v(t) - c; on a loop it is the driver's
    rim speed omega_d(t) r_d and ``load`` the torques M_k(t) (N m) that the pulleys
    whose speeds are the globals k deliver (entry 0, the belt speed's, is zero).
    """

    speed: Profile  # v(t) - c (m/s), or a loop's driver rim speed (m/s)
    friction: Profile  # f*(t) / f* (1 for perfect adhesion)
    load: Profiles = NO_LOADS  # a loop's load torques (N m), one per global

    @classmethod
    def constant(cls, mismatch: float, loads=()) -> Drive:
        """The full mismatch (or rim speed) and loads at once and a constant friction
        limit (the steady solver)."""
        return cls(Profile.constant(mismatch), Profile.constant(1.0),
                   Profiles.constants(loads))


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
def profile_value(times, vals, level, amplitude, period, ramp_time, t):
    """The value at time t of the profile with these fields (:class:`Profile`)."""
    n = times.shape[0]
    if n > 0:
        if t <= times[0]:
            return vals[0]
        if t >= times[n - 1]:
            return vals[n - 1]
        k = np.searchsorted(times, t) - 1
        r = (t - times[k]) / (times[k + 1] - times[k])
        return vals[k] + r * (vals[k + 1] - vals[k])
    out = level
    if period > 0.0:
        out += amplitude * math.sin(2.0 * math.pi * t / period)
    return out * ramp(t, ramp_time)


@njit(cache=True)
def value(profile, t):
    """A profile's value at time t."""
    return profile_value(profile.times, profile.values, profile.level, profile.amplitude,
                         profile.period, profile.ramp_time, t)


@njit(cache=True)
def value_at(bank, k, t):
    """The value at time t of profile k of a :class:`Profiles` bank."""
    a, b = bank.start[k], bank.start[k + 1]
    return profile_value(bank.times[a:b], bank.values[a:b], bank.level[k],
                         bank.amplitude[k], bank.period[k], bank.ramp_time[k], t)


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
    raw_speed, raw = scene_profiles(scene)
    speed = as_profile(raw_speed, P.c, 1.0, ramp_time)
    friction = Profile.constant(1.0) if raw is None else as_profile(raw, 0.0, P.fstar, 0.0)
    return Drive(speed, friction)


def scene_profiles(scene):
    """The scene's profiles, the speed first: the surface speed and the friction limit
    of the paper's belt, a drive's driver speed and loads."""
    data = scene.to_dict()
    if "drive" in data:
        P = scene.params
        return (P.pulleys[P.driver].speed,
                *(p.load for p in P.pulleys if p.load is not None))
    return data["motion"]["surface_speed"], data["contact"].get("max_friction")


def profile_times(scene) -> tuple[float, ...]:
    """The times of every row of the scene's profile tables, sorted (for marking plots)."""
    return tuple(sorted({float(row[0]) for v in scene_profiles(scene) if isinstance(v, list)
                         for row in v}))


def has_profiles(scene) -> bool:
    """Whether the drive is more than the start-up ramp (a table or a sine anywhere)."""
    return any(isinstance(v, (list, dict)) for v in scene_profiles(scene))


def period_of(scene) -> float | None:
    """The period of a periodic drive (a sine), None for a drive that settles."""
    periods = [v["period"] for v in scene_profiles(scene) if isinstance(v, dict)]
    return periods[0] if periods else None


def speed_ramped(scene) -> bool:
    """Whether the surface speed ramps from c (a number or a sine, not a table)."""
    return not isinstance(scene_profiles(scene)[0], list)


def largest_mismatch(scene) -> float:
    """max abs(v(t) - c) over the profile."""
    lo, hi = profile_extremes(scene_profiles(scene)[0])
    c = scene.params.c
    return max(abs(lo - c), abs(hi - c))
