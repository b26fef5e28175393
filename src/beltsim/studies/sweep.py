"""Parameter sweeps on any concurrent.futures.Executor.

Each point is a full run from rest to steady state of the scene with one key
changed, compared with the analytic solution of the same scene. Points run in
worker processes by default; ``scheduler`` sends them to a Dask distributed
cluster instead (``pip install beltsim[dask]``), so a study that outgrows one
machine runs unchanged on many.
"""

from __future__ import annotations

import os
from concurrent.futures import Executor, ProcessPoolExecutor

from ..errors import UsageError
from ..problem.scene import Scene, parse_assignment, set_key

KEYS = ("total_friction", "stick_friction", "slip_friction", "slip_start")
EXACT_SAMPLES = 801  # points of the exact fields kept for a figure


def parse_vary(text: str, scene=None):
    """``SECTION.KEY=V1,V2,...`` -> (key, [values]); each value validated with the scene
    (a closed drive's keys with the drive's schema)."""
    from ..beltdrive.scene import DriveScene

    if "=" not in text:
        raise UsageError(f"--vary {text}: expected SECTION.KEY=V1,V2,...")
    key, raw = text.split("=", 1)
    values = [parse_assignment(f"{key}={v.strip()}")[1] for v in raw.split(",") if v.strip()]
    if not values:
        raise UsageError(f"--vary {text}: no values")
    if isinstance(scene, DriveScene):
        scene.with_overrides([(key.strip(), values[0])])
    else:
        set_key({}, key.strip(), values[0])  # the key must be one the schema knows
    return key.strip(), values


def run_drive_point(scene_dict: dict, key: str, value) -> dict:
    """One sweep point of a closed drive: its run from rest and its analytic steady state
    (none beyond the capacity: gross slip is then the run's expected outcome)."""
    from ..beltdrive.analytic import capacity
    from ..beltdrive.scene import DriveScene
    from ..simulation.controller import run
    from ..simulation.loop_solution import SUMMARY_KEYS

    scene = DriveScene(scene_dict).with_overrides([(key, value)])
    res = run(scene, raise_on_failure=False)
    summary = res.solution.summary()
    row = {"value": value, **{k: summary[k] for k in SUMMARY_KEYS}}
    exact = res.reference.summary() if res.reference is not None else {}
    row.update({f"{k}_analytic": exact.get(k) for k in SUMMARY_KEYS})
    row.update(status=res.status.value, converged=res.converged, wall_time=res.wall_time,
               reason=res.reason, capacity=capacity(scene.params))
    return row


def run_point(scene_dict: dict, key: str, value, keep_theta=False) -> dict:
    """One sweep point (module level, so worker processes can run it).

    The exact solutions of the point are computed once here: the scene's own and, for
    Coulomb friction, its perfect-adhesion limit. ``keep_theta`` adds the simulated and
    exact rotation fields (for the creep-collapse figure).
    """
    from ..simulation.controller import Simulation
    from ..simulation.result import reference_of

    scene = Scene(scene_dict).with_overrides([(key, value)])
    res = Simulation(scene).run(raise_on_failure=False)
    sim = res.solution.summary()
    row = {"value": value, **{k: sim.get(k) for k in KEYS}}
    ref = reference_of(scene)
    exact = ref.summary() if ref is not None else {}
    row.update({f"{k}_analytic": exact.get(k) for k in KEYS})
    adhesion = reference_of(scene, model="stick") if scene.params.friction == "coulomb" else None
    row["total_friction_adhesion"] = adhesion.total_friction if adhesion else None
    row.update(converged=res.converged, wall_time=res.wall_time, reason=res.reason,
               h_min=res.solution.grid.h_min, x2=scene.params.x2)
    if keep_theta:
        row.update(x=res.solution.x, theta=res.solution.theta)
        if ref is not None and adhesion is not None:
            x_exact, fields = ref.sample(EXACT_SAMPLES)
            row.update(x_exact=x_exact, theta_exact=fields["theta"],
                       theta_adhesion=adhesion.fields(x_exact)["theta"])
    return row


def make_executor(workers: int | None = None, scheduler: str | None = None) -> Executor:
    """A pool of ``workers`` processes (default one per core), or a Dask cluster's client."""
    if scheduler:
        try:
            from distributed import Client
        except ImportError:
            raise UsageError("--scheduler: Dask is not installed (pip install "
                             "'beltsim[dask]')") from None
        try:
            client = Client(scheduler, timeout="10s")
        except (OSError, TimeoutError) as exc:
            raise UsageError(f"--scheduler {scheduler}: cannot connect ({exc})") from None
        return client.get_executor()
    return ProcessPoolExecutor(max_workers=workers or os.cpu_count() or 1)


def sweep(scene, key: str, values, executor: Executor | None = None,
          keep_theta: bool = False, progress=None) -> list[dict]:
    """Run every value on the executor; rows in the order of ``values``."""
    # validate every point up front: a bad value fails before any run starts
    for v in values:
        scene.with_overrides([(key, v)])
    from ..beltdrive.scene import DriveScene

    own = executor is None
    executor = executor or make_executor()
    try:
        if isinstance(scene, DriveScene):
            futures = [executor.submit(run_drive_point, scene.to_dict(), key, v)
                       for v in values]
        else:
            futures = [executor.submit(run_point, scene.to_dict(), key, v, keep_theta)
                       for v in values]
        rows = []
        for f in futures:
            rows.append(f.result())
            if progress:
                progress(rows[-1])
    finally:
        if own:
            executor.shutdown(cancel_futures=True)
    return rows
