"""A drive's figures span by span and pulley by pulley, as every solution reports them
(a run's state, the creep theory, the beam's exact steady state): the ``spans`` and
``pulleys`` lists of a summary, and each under a scalar name for histories and tables."""

from __future__ import annotations

import numpy as np


def hub_loads(layout, rho: float, c: float, tensions) -> np.ndarray:
    """The belt's force on each pulley's bearing (N, shape (n, 2)): (T_out - rho c^2)
    t_out - (T_in - rho c^2) t_in, with span i leaving pulley i and span i - 1 arriving,
    t the spans' directions of motion (the centrifugal part of the tension does not load
    the hubs). It points from the centre towards the spans and sums to zero over the
    pulleys."""
    t = np.asarray(layout.span_directions)
    Tc = (np.asarray(tensions, dtype=float) - rho * c * c)[:, None]
    return Tc * t - np.roll(Tc * t, 1, axis=0)


def figure_keys(names) -> tuple[str, ...]:
    """The scalar names of each span's tension and each pulley's speed, slip arc and
    torque, for pulleys ``names`` in the belt's order: ``tension[A-B]`` (the span from
    pulley A to B), ``speed[A]``, ``slip_arc[A]``, ``torque[A]``."""
    names = list(names)
    spans = [f"tension[{a}-{b}]" for a, b in zip(names, names[1:] + names[:1])]
    return (*spans, *(f"{q}[{n}]" for q in ("speed", "slip_arc", "torque") for n in names))


def layout_summary(layout, roles, rho, c, tensions, speeds, slip_arcs, torques,
                   **extra) -> dict:
    """``spans`` (a list in the belt's order of {from, to, tension}), ``pulleys`` (a list
    of {name, role, speed, slip_arc, wrap, torque, hub_load [Fx, Fy]} and each array of
    ``extra`` by its name, e.g. slip_margin) and the same figures under
    :func:`figure_keys`' names.

    ``torques``: what the driver puts into the belt and each other pulley takes out (N m).
    """
    names = list(layout.names)
    n = len(names)
    hubs = hub_loads(layout, rho, c, tensions)
    out = {"spans": [{"from": names[i], "to": names[(i + 1) % n],
                      "tension": float(tensions[i])} for i in range(n)],
           "pulleys": []}
    for i in range(n):
        row = {"name": names[i], "role": roles[i], "speed": float(speeds[i]),
               "slip_arc": float(slip_arcs[i]), "wrap": float(layout.wraps[i]),
               "torque": float(torques[i]),
               "hub_load": [float(hubs[i, 0]), float(hubs[i, 1])]}
        row.update({k: float(v[i]) for k, v in extra.items()})
        out["pulleys"].append(row)
    values = [*tensions, *speeds, *slip_arcs, *torques]
    out.update(zip(figure_keys(names), map(float, values)))
    return out
