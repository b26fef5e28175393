"""The rules a scene's keys follow, shared by every kind of scene.

A straight belt (:mod:`beltsim.problem.validation`) and a closed drive
(:class:`~beltsim.beltdrive.scene.DriveScene`) check their keys with the same rules, read the same
profiles and tables and derive the belt's stiffness the same way; this module holds what
they share, so that neither imports the other. Every rule raises
:class:`~beltsim.errors.SceneError` with a one-line message naming the key and the rule.
"""

from __future__ import annotations

import math

from ..errors import SceneError


def show(value) -> str:
    """A value as a message shows it: strings quoted, booleans as TOML writes them,
    tables and arrays by their kind."""
    if isinstance(value, str):
        return repr(value)
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, list):
        return "an array"
    return repr(value)


def number(key: str, value) -> float:
    """A finite number as a float, or the one-line error of a float key."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise SceneError(key, f"must be a number, got {show(value)}")
    if not math.isfinite(value):
        raise SceneError(key, f"must be finite, got {show(value)}")
    return float(value)


class Rule:
    """Type and range rule of one key.

    Parameters
    ----------
    kind : str
        "float", "int", "bool", "str" or "profile" (:func:`check_profile`).
    positive, nonneg : bool, optional
        The number must be > 0, or >= 0.
    choices : tuple of str, optional
        The strings allowed.
    interval : (float, float), optional
        An open interval the number must lie in.
    minimum : float, optional
        An inclusive lower bound.
    """

    def __init__(self, kind, *, positive=False, nonneg=False, choices=None, interval=None,
                 minimum=None):
        self.kind = kind
        self.positive = positive
        self.nonneg = nonneg
        self.choices = choices
        self.interval = interval  # open interval (lo, hi)
        self.minimum = minimum  # inclusive lower bound (ints, floats)

    def check(self, key, value):
        """The value, normalised (ints of float keys as floats), or the key's error.

        Parameters
        ----------
        key : str
            The key's full name, ``SECTION.KEY``, for the message.
        value
            The value as TOML read it.

        Returns
        -------
        object
            The value as the scene keeps it.

        Raises
        ------
        SceneError
            The value breaks the rule.
        """
        if self.kind in ("float", "int"):
            if self.kind == "float":
                value = number(key, value)
            else:
                if isinstance(value, bool) or not isinstance(value, (int, float)):
                    raise SceneError(key, f"must be a number, got {show(value)}")
                if isinstance(value, float):
                    if not (math.isfinite(value) and value == int(value)):
                        raise SceneError(key, f"must be a whole number, got {show(value)}")
                    value = int(value)
            if self.positive and not value > 0:
                raise SceneError(key, f"must be > 0, got {show(value)}")
            if self.nonneg and not value >= 0:
                raise SceneError(key, f"must be >= 0, got {show(value)}")
            if self.minimum is not None and value < self.minimum:
                raise SceneError(key, f"must be >= {self.minimum}, got {show(value)}")
            if self.interval is not None:
                lo, hi = self.interval
                if not lo < value < hi:
                    raise SceneError(key, f"must lie in the open interval ({lo}, {hi}), "
                                     f"got {show(value)}")
            return value
        if self.kind == "bool":
            if not isinstance(value, bool):
                raise SceneError(key, f"must be true or false, got {show(value)}")
            return value
        if self.kind == "str":
            if not isinstance(value, str):
                raise SceneError(key, f"must be a string, got {show(value)}")
            if self.choices is not None and value not in self.choices:
                opts = " | ".join(f'"{c}"' for c in self.choices)
                raise SceneError(key, f"must be one of {opts}, got {show(value)}")
            return value
        if self.kind == "profile":
            return check_profile(key, value)
        raise AssertionError(self.kind)


#: The keys of a sine profile.
SINE_KEYS = ("mean", "amplitude", "period")


def check_table(key, value: list, zero_allowed: bool = False) -> list:
    """A table of [time, value] rows: times increasing strictly, values > 0 (>= 0 with
    ``zero_allowed``), as a list of [float, float]."""
    if not value:
        raise SceneError(key, "a table needs at least one [time, value] row")
    rows = []
    for i, row in enumerate(value, 1):
        name = f"{key} row {i}"
        if not isinstance(row, list) or len(row) != 2:
            raise SceneError(name, f"must be a [time, value] pair, got {show(row)}")
        t, v = number(f"{name} time", row[0]), number(f"{name} value", row[1])
        if rows and not t > rows[-1][0]:
            raise SceneError(name, f"times must increase strictly, got {t!r} after "
                             f"{rows[-1][0]!r}")
        if not (v >= 0 if zero_allowed else v > 0):
            raise SceneError(f"{name} value", f"must be {'>=' if zero_allowed else '>'} 0, "
                             f"got {v!r}")
        rows.append([t, v])
    return rows


def check_profile(key, value):
    """A positive quantity over time: a number, a table of [time, value] rows, or a sine.

    Tables are interpolated linearly and held before the first and after the last row;
    a sine is { mean, amplitude, period } (value mean + amplitude sin(2 pi t / period)).
    """
    if isinstance(value, dict):
        for k in value:
            if k not in SINE_KEYS:
                raise SceneError(f"{key}.{k}", "unknown key of a sine (known: "
                                 f"{', '.join(SINE_KEYS)})")
        for k in SINE_KEYS:
            if k not in value:
                raise SceneError(f"{key}.{k}", "missing key of a sine (a sine is "
                                 "{ mean = ..., amplitude = ..., period = ... })")
        out = {k: number(f"{key}.{k}", value[k]) for k in SINE_KEYS}
        if not out["period"] > 0:
            raise SceneError(f"{key}.period", f"must be > 0, got {out['period']!r}")
        if not out["mean"] - abs(out["amplitude"]) > 0:
            raise SceneError(key, f"must stay > 0, got mean - |amplitude| = "
                             f"{out['mean'] - abs(out['amplitude'])!r}")
        return out
    if isinstance(value, list):
        return check_table(key, value)
    value = number(key, value)
    if not value > 0:
        raise SceneError(key, f"must be > 0, got {value!r}")
    return value


def final_value(value) -> float:
    """The value a profile settles on: the number, the last row, or a sine's mean."""
    if isinstance(value, list):
        return value[-1][1]
    if isinstance(value, dict):
        return value["mean"]
    return value


def profile_extremes(value) -> tuple[float, float]:
    """The smallest and largest value a profile takes."""
    if isinstance(value, list):
        vals = [row[1] for row in value]
        return min(vals), max(vals)
    if isinstance(value, dict):
        return value["mean"] - abs(value["amplitude"]), value["mean"] + abs(value["amplitude"])
    return value, value


POS = Rule("float", positive=True)
PROFILE = Rule("profile")

#: The belt's cross-section and material, as a straight belt's [beam] and a drive's
#: [belt] give them (the drive's without ``length``).
BELT_RULES: dict[str, Rule] = {
    "length": POS,
    "height": POS,
    "width": POS,
    "youngs_modulus": POS,
    "poisson_ratio": Rule("float", interval=(-1.0, 0.5)),
    "density": POS,
    "shear_factor": POS,
}

#: The [stiffness] section: the belt's stiffness and inertia per unit length, given
#: directly instead of derived from the cross-section.
STIFFNESS_RULES: dict[str, Rule] = {
    "bending": POS,
    "tension": POS,
    "shear": POS,
    "mass": POS,
    "rotary_inertia": POS,
}

#: Keys that were, and what replaces them.
RETIRED = {
    ("numerics", "damping"): (
        "removed, damping is physics now: set physics.damping (1/s, the "
        "rate d of d rho u_t and d I theta_t), or, for a fast path to the steady state "
        'whose transient does not matter, numerics.integrator = "pseudo" with '
        "numerics.acceleration (1/s)"),
}


def set_scene_key(data: dict, key: str, value, schema: dict, kind: str = "",
                  known_keys: bool = True) -> None:
    """Set ``SECTION.KEY`` (or ``title``) in a scene's tables.

    The section must be one of ``schema``'s, the key not a retired one and, with
    ``known_keys``, one the section knows; ``kind`` names the kind of scene in the
    message ("a drive scene"). The value is checked when the tables are validated.
    """
    if key == "title":
        data["title"] = value
        return
    sections = ", ".join(schema)
    if "." not in key:
        raise SceneError(key, f"expected SECTION.KEY (sections: {sections})")
    section, name = key.split(".", 1)
    if section not in schema:
        of = f" of {kind}" if kind else ""
        raise SceneError(key, f"unknown section [{section}]{of} (sections: {sections})")
    if (section, name) in RETIRED:
        raise SceneError(key, RETIRED[section, name])
    if known_keys and name not in schema[section]:
        raise SceneError(key, f"unknown key (known in [{section}]: "
                         f"{', '.join(schema[section])})")
    data.setdefault(section, {})[name] = value


def derived_stiffness(d: dict) -> dict:
    """The belt's stiffness and inertia per unit length: a, b1, b2, rho and I.

    Derived from the cross-section and material (``d["beam"]``), each overridden by
    ``d["stiffness"]`` where given; rho and I are zero without inertia
    (``d["physics"]["inertia"]``).

    Raises
    ------
    SceneError
        An inertial belt with neither a density nor its mass and rotary inertia.
    """
    beam = d["beam"]
    over = d.get("stiffness", {})
    E, nu, k = beam["youngs_modulus"], beam["poisson_ratio"], beam["shear_factor"]
    h, w = beam["height"], beam["width"]
    p = {
        "a": over.get("bending", E * w * h**3 / 12.0),
        "b1": over.get("tension", E * w * h),
        "b2": over.get("shear", k * E * w * h / (2.0 * (1.0 + nu))),
        "rho": 0.0,
        "I": 0.0,
    }
    if d["physics"]["inertia"]:
        rho3 = beam.get("density")
        if rho3 is None and ("mass" not in over or "rotary_inertia" not in over):
            raise SceneError("beam.density", "missing key")
        p["rho"] = over.get("mass", (rho3 or 0.0) * h * w)
        p["I"] = over.get("rotary_inertia", (rho3 or 0.0) * h * w * (h * h + w * w) / 12.0)
    return p
