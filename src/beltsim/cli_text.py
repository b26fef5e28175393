"""The command line's text: summary tables, the run's summary lines, table cells and
lists of grids (beltsim.cli prints them)."""

from __future__ import annotations

from .errors import UsageError


def format_summary(summary: dict, title: str = "") -> str:
    """A short human-readable table of a summary dict (a drive's: its figures)."""
    if "tight_tension" in summary or "spans" in summary:
        from .beltdrive.io import format_drive
        return format_drive(summary, title)
    rows = [("model", summary["model"]), ("inertia", str(summary["inertia"]).lower())]
    for key, unit in (("total_friction", "N"), ("concentrated_force", "N"),
                      ("distributed_friction", "N"), ("stick_friction", "N"),
                      ("slip_friction", "N"), ("slip_start", "m"), ("slip_power", "W")):
        value = summary.get(key)
        if value is not None:
            rows.append((key, f"{value:.6g} {unit}"))
    width = max(len(k) for k, _ in rows)
    lines = [title] if title else []
    lines += [f"  {k:<{width}}  {v}" for k, v in rows]
    return "\n".join(lines)


def format_run(summary: dict) -> str:
    """A run's lines: steps, simulated time, the solve's wall time beside the kernels'
    compile or load time, the last period of a periodic drive, the errors."""
    from .simulation.controller import COMPILING_AFTER

    kernels = summary.get("compile_time") or 0.0
    lines = [f"  converged       {str(summary['converged']).lower()} after "
             f"{summary['steps']} steps, t = {summary['simulated_time']:.4g} s, "
             f"wall {summary['wall_time']:.3g} s (+ {kernels:.2g} s "
             f"{'compiling' if kernels > COMPILING_AFTER else 'loading'} the kernels)"]
    if summary.get("status") not in (None, "converged"):
        lines.append(f"  status          {summary['status']}")
    per = summary.get("periodic")
    if per:
        for key, part in per.items():
            if isinstance(part, dict):
                lines.append(f"  last period     {key} min {part['min']:.6g}, mean "
                             f"{part['mean']:.6g}, max {part['max']:.6g}")
    stab = summary.get("stability")
    if stab:
        lines.append(f"  stability       {stab['summary']}")
    err = summary.get("error")
    if err:
        parts = [f"{k} {v:.2e}" for k, v in err.items() if v is not None]
        lines.append("  error vs exact  " + ", ".join(parts)
                     + (" (slip_start in m)" if "slip_start" in err else ""))
    return "\n".join(lines)


def int_list(text, name):
    """Comma-separated element counts (``--ladder``), each a grid beltsim accepts."""
    from .problem.scene import MIN_ELEMENTS

    try:
        vals = [int(v) for v in text.split(",")]
    except ValueError:
        raise UsageError(f"{name}: expected comma-separated whole numbers, got {text!r}") from None
    if any(v < MIN_ELEMENTS for v in vals):
        raise UsageError(f"{name}: every grid needs at least {MIN_ELEMENTS} elements")
    return vals


def cell(v):
    """A value right-aligned in a table column twelve characters wide."""
    if isinstance(v, str):
        return f"{v:>12s}"
    if isinstance(v, bool):
        return f"{str(v).lower():>12s}"
    if isinstance(v, int):
        return f"{v:>12d}"
    return f"{v:>12.4g}"


def float_list(text, name):
    """Comma-separated finite numbers (``--values``)."""
    import math

    try:
        vals = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise UsageError(f"{name}: expected comma-separated numbers, got {text!r}") from None
    if not vals or not all(math.isfinite(v) for v in vals):
        raise UsageError(f"{name}: expected comma-separated finite numbers, got {text!r}")
    return vals


def map_header(param: str, unit: str) -> str:
    """The header of ``beltsim stability-map``'s table."""
    return (f"{param + ' [' + unit + ']':>24s}  {'status':<15s}  {'rate [1/s]':>11s}  "
            f"{'error [1/s]':>11s}  {'frequency [Hz]':>14s}  {'growing':>7s}  "
            f"{'wall [s]':>8s}")


def map_row(row: dict) -> str:
    """One point of a stability map as a line of its table (a point without a root: its
    status and why; an exact root: no error)."""
    head = f"{row['value']:>24.6g}  {row['status']:<15s}  "
    wall = f"{row['wall_time']:>8.3g}" + (" (cached)" if row["cached"] else "")
    if row["rate"] is None:
        return head + f"{'':>11s}  {'':>11s}  {'':>14s}  {'':>7s}  {wall}  {row['reason']}"
    error = "" if row.get("error") is None else f"{row['error']:.2g}"
    return (head + f"{row['rate']:>+11.4g}  {error:>11s}  {row['frequency']:>14.6g}  "
            f"{row['growing']:>7d}  {wall}")


def scene_kind(scene) -> tuple[str, str]:
    """A shipped scene's kind (closed drive or straight belt, and its friction) and title
    (``beltsim scenes``)."""
    from .problem.kinds import is_drive_scene

    if is_drive_scene(scene):
        return "closed drive", scene.title
    friction = {"stick": "perfect adhesion", "coulomb": "stick and slip"}
    return f"straight belt, {friction.get(scene.contact.friction, scene.contact.friction)}", \
        scene.title
