"""Convergence ladders: each scheme on a ladder of grids, Richardson, observed orders.

Timing lives here and in the CLI commands built on it, never in tests. Every
wall time excludes numba compilation, which is reported in its own column.
"""

from __future__ import annotations

import numpy as np

from .. import solvers
from ..api import is_drive_scene
from ..errors import SceneError
from ..physics.grid import bisect
from ..problem.scene import Scene
from ..simulation.controller import Simulation
from ..simulation.readout import Readout, readout_class
from ..simulation.result import reference_of
from ..simulation.solution import DiscreteSolution, compare, relative_error

LADDER = (125, 250, 500, 1000, 2000)
ERROR_KEYS = Readout.error_keys  # the open layout's
RICHARDSON = "richardson"  # the extrapolated steady scheme, a study rather than a scheme


def schemes_for(scene) -> tuple[str, ...]:
    """The registered schemes that apply to a scene, then Richardson's extrapolation (a
    straight belt's: it extrapolates on a bisected open grid)."""
    inertia, closed = scene.params.inertia, is_drive_scene(scene)
    return tuple(n for n in solvers.names()
                 if solvers.applicable(n, inertia, closed) is None) + (
        () if closed else (RICHARDSON,))


def error_keys(scene) -> tuple[str, ...]:
    """The errors a study reports for a scene's layout (its readout's)."""
    return readout_class(is_drive_scene(scene)).error_keys


def richardson(scene: Scene, reference=None):
    """Steady solutions on a grid and on its bisection, extrapolated to zero element size.

    The errors are second order in the element size (three-point upwind transport,
    trapezoidal friction), so (4 q(h/2) - q(h)) / 3 cancels their leading term for the
    total friction, the concentrated force, u and theta (at the coarse nodes, which the
    bisected grid shares). The slip start's error depends on where x* falls in its
    cell (bounded by ~7 h^2, not smooth in h): the fine grid's is kept.
    Returns (coarse result, fine result, extrapolated errors, wall time of both).
    """
    steady = scene.with_overrides([("numerics.integrator", "steady")])
    coarse = Simulation(steady)
    r1 = coarse.run(raise_on_failure=False)
    r2 = Simulation(steady, grid=bisect(coarse.grid)).run(raise_on_failure=False)
    ref = reference if reference is not None else reference_of(scene)
    if ref is None or not (r1.converged and r2.converged):
        return r1, r2, None, r1.wall_time + r2.wall_time
    s1, s2 = r1.solution, r2.solution
    def ext_of(fine, coarse):
        return (4.0 * fine - coarse) / 3.0

    ext = DiscreteSolution(s1.params, s1.grid, ext_of(s2.u[::2], s1.u),
                           ext_of(s2.theta[::2], s1.theta), s1.fnode, s1.law_code,
                           s1.friction_scale)
    err = compare(ext, ref)
    err["total_friction"] = relative_error(ext_of(s2.total_friction, s1.total_friction),
                                           ref.total_friction)
    if ref.model == "stick":
        err["concentrated_force"] = relative_error(
            ext_of(s2.concentrated_force, s1.concentrated_force), ref.concentrated_force)
    else:
        err["slip_start"] = abs(s2.slip_start - ref.x_star)
    return r1, r2, err, r1.wall_time + r2.wall_time


def _row(scheme, elements, h_min, dt, steps, newton_iterations, wall_time, compile_time,
         converged, err, keys, reason=""):
    err = err or {}
    return {"scheme": scheme, "elements": elements, "h_min": h_min, "dt": dt, "steps": steps,
            "newton_iterations": newton_iterations, "wall_time": wall_time,
            "compile_time": compile_time, "converged": converged,
            **{f"error_{k}": err[k] if err.get(k) is not None else float("nan")
               for k in keys}, "reason": reason}


def convergence(scene, ladder=LADDER, schemes=None, progress=None) -> list[dict]:
    """Run each scheme on each grid of the ladder; one row per run.

    ``scene`` is a straight belt or a closed drive; each row carries its layout's errors
    (:func:`error_keys`) against the exact steady state. A rung refused before running
    (a SceneError, e.g. the explicit scheme's numerics.max_work on a fine grid) is a row
    that did not converge, with the refusal as its reason: the rest of the ladder still
    runs and reports.
    """
    rows = []
    keys = error_keys(scene)
    reference = readout_class(is_drive_scene(scene)).exact(scene)
    nan = float("nan")
    for scheme in schemes or schemes_for(scene):
        for n in ladder:
            sc = scene.with_overrides([("numerics.elements", n)])
            try:
                row = _rung(sc, scheme, n, reference, keys)
            except SceneError as exc:
                row = _row(scheme, n, nan, nan, 0, 0, nan, nan, False, None, keys, str(exc))
            rows.append(row)
            if progress:
                progress(row)
    return rows


def _rung(sc, scheme, n, reference, keys) -> dict:
    """One scheme on one grid of the ladder."""
    if scheme == RICHARDSON:
        if is_drive_scene(sc):
            raise SceneError("--schemes", "richardson extrapolates a straight belt's "
                             "bisected grid; a drive has none")
        r1, r2, err, wall = richardson(sc, reference)
        return _row(scheme, n, r1.solution.grid.h_min, float("nan"), r1.steps + r2.steps,
                    r1.newton_iterations + r2.newton_iterations, wall,
                    r1.compile_time + r2.compile_time, err is not None, err, keys)
    sim = Simulation(sc.with_overrides([("numerics.integrator", scheme)]))
    res = sim.run(raise_on_failure=False)
    res.reference = reference
    dt = sim.numerics.dt if sim.scheme.transient else float("nan")
    return _row(scheme, n, sim.grid.h_min, dt, res.steps, res.newton_iterations,
                res.wall_time, res.compile_time, res.converged, res.errors(), keys)


def observed_orders(rows, key) -> dict:
    """Per scheme: orders between successive grids and the least-squares slope."""
    out = {}
    for scheme in dict.fromkeys(r["scheme"] for r in rows):
        rs = [r for r in rows if r["scheme"] == scheme and r["converged"]]
        h = np.array([r["h_min"] for r in rs])
        e = np.abs(np.array([r[f"error_{key}"] for r in rs]))  # a drive's are signed
        ok = np.isfinite(e) & (e > 0)
        h, e = h[ok], e[ok]
        if len(e) < 2:
            continue
        pair = np.log(e[:-1] / e[1:]) / np.log(h[:-1] / h[1:])
        fit = float(np.polyfit(np.log(h), np.log(e), 1)[0])
        out[scheme] = {"pairs": [float(p) for p in pair], "fit": fit}
    return out
