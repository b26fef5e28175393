"""The stability matrix: stiff and extreme scenes, each by every registered scheme.

Each cell ends in one status, decided from structured outcomes: not applicable (the
registry says the scheme does not apply to the scene), refused (the scene or its
numerics break a rule before anything runs: a SceneError), or the status of the run
(converged within the bounds of the transient simulator, out of bounds, not converged,
diverged: the run's RunStatus and FailureKind). A cell's ``reason_key`` says what its
reason is about, so that alike cells count together: the key a refusal names, the kind
of failure, the run's status, or the errors out of bounds.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

from .. import solvers
from ..api import is_drive_scene, shipped_scene
from ..errors import BeltsimError, NoSolutionError, SceneError
from ..problem.scene import Scene
from ..problem.tables import frozen
from ..simulation.controller import Simulation
from ..simulation.readout import readout_class
from ..simulation.result import RunStatus

#: Bounds of a coarse matrix, against the steady scheme's state on the same grid: each
#: scheme must reach its grid's steady state to within these, about ten times the largest
#: differences that the runs' own steady and Newton tolerances left on the 60-element
#: matrix (3e-7 total friction, 3e-6 u and theta, 1.5e-7 concentrated force, 3e-8 m).
DISCRETE_BOUNDS = {"total_friction": 3e-6, "u": 3e-5, "theta": 3e-5,
                   "concentrated_force": 3e-6, "slip_start": 3e-7}
#: The acceptance bounds of the transient simulator (relative errors; slip start in m).
BOUNDS = {"total_friction": 5e-3, "u": 2e-2, "theta": 2e-2, "concentrated_force": 5e-2,
          "slip_start": 5e-3}


#: A closed drive's bounds, against the steady scheme's state on the same grid (measured on
#: drive_flat's 200 elements: every scheme within 3e-14; the steady test stops at a change
#: of 1e-7 per transit) and against the exact steady state (the default grid's errors:
#: tensions 1e-6, speed loss 1e-6 of itself, slip arcs 1.5e-3 of the wrap)
DRIVE_DISCRETE_BOUNDS = {"tight_tension": 1e-6, "slack_tension": 1e-6, "speed_loss": 1e-5,
                         "slip_arc_driver": 1e-5, "slip_arc_driven": 1e-5}
DRIVE_BOUNDS = {"tight_tension": 1e-4, "slack_tension": 1e-4, "speed_loss": 1e-3,
                "slip_arc_driver": 1e-2, "slip_arc_driven": 1e-2}


class CellStatus(enum.StrEnum):
    """How a cell of the stability matrix or the random study ended."""

    CONVERGED = "converged"
    BOUNDED = "bounded"  # a fixed span of simulated time: finite and bounded throughout
    OUT_OF_BOUNDS = "out of bounds"
    NOT_CONVERGED = "not converged"
    DIVERGED = "diverged"
    REFUSED = "refused"
    NOT_APPLICABLE = "not applicable"
    #: a time-accurate run diverged or did not settle, and the eigenvalues of the model
    #: linearised about its steady state show a growing mode (physics.modes)
    UNSTABLE = "unstable steady state"
    #: a drive ended in gross slip or lift-off, and has no steady state to reach
    OUTCOME = "physical outcome"


#: Statuses that count as a pass: the scheme either delivers or says why it cannot (an
#: unstable steady state is a reason the model itself gives, with its growth rate).
ACCEPTED = (CellStatus.CONVERGED, CellStatus.BOUNDED, CellStatus.REFUSED,
            CellStatus.NOT_APPLICABLE, CellStatus.UNSTABLE, CellStatus.OUTCOME)
#: A growth rate counts as unstable above this fraction of max(|lambda|, 1 / transit): growth
#: of at least 1e-3 per radian of the mode's oscillation and per transit (far above
#: the eigensolver's round-off).
GROWTH_MARGIN = 1e-3
#: a gross slip or a lift-off where the exact steady state exists did not reach it
_RUN_STATUS = {RunStatus.FAILED: CellStatus.DIVERGED, RunStatus.REACHED_END:
               CellStatus.NOT_CONVERGED, RunStatus.INTERRUPTED: CellStatus.NOT_CONVERGED,
               RunStatus.GROSS_SLIP: CellStatus.NOT_CONVERGED,
               RunStatus.LIFT_OFF: CellStatus.NOT_CONVERGED}


@dataclass(frozen=True)
class Case:
    """A scene of the matrix: a base scene and (key, value) overrides of it."""

    name: str
    #: a shipped scene by name (beltsim.scene_names), or a Scene
    base: str | Scene
    overrides: tuple[tuple[str, object], ...] = ()
    #: run over this span of simulated time and ask only that the state stay bounded
    #: (an undamped belt rings for long, a fluttering one grows into a limit cycle; no
    #: steady state is expected within the span)
    span: float | None = None

    @property
    def sets_grid(self) -> bool:
        """Whether the case is about the grid itself (a coarse matrix leaves it out)."""
        return any(key == "numerics.elements" for key, _ in self.overrides)

    def base_scene(self):
        """The base scene (a straight belt or a drive); MissingInputError when a shipped
        base is not installed."""
        return shipped_scene(self.base) if isinstance(self.base, str) else self.base

    def scene(self, extra=(), base=None) -> Scene:
        """The case's scene with ``extra`` (key, value) overrides, from ``base`` (default
        :meth:`base_scene`); raises SceneError when they break a rule, MissingInputError
        when a shipped base is not installed."""
        span = [("numerics.t_end", self.span)] if self.span else []
        base = self.base_scene() if base is None else base
        return base.with_overrides([*self.overrides, *span, *extra])


#: The closed drive's cases, each derived from drive_flat (R = 80 / 160 mm, 12 m/s, 50 N m
#: of its capacity 98.4 N m)
DRIVE_CASES = (
    Case("drive: flat belt", "drive_flat"),
    Case("drive: regularised law (tanh)", "drive_flat", (("numerics.friction_law", "tanh"),)),
    Case("drive: string model", "drive_flat", (("physics.model", "string"),)),
    Case("drive: quasistatic string", "drive_flat",
         (("physics.model", "string"), ("physics.inertia", False))),
    Case("drive: stiff belt (E x 100)", "drive_flat", (("belt.youngs_modulus", 5.0e10),)),
    Case("drive: fast belt (38 m/s, rho c^2 = 0.42 N0)", "drive_flat",
         (("drive.driver_speed", 475.0), ("drive.installation_tension", 1000.0))),
    Case("drive: light driven pulley (J2 / 100)", "drive_flat",
         (("drive.driven_inertia", 2.0e-4),)),
    Case("drive: heavy driven pulley (J2 x 50)", "drive_flat", (("drive.driven_inertia", 1.0),)),
    Case("drive: load at 0.95 of the capacity", "drive_flat", (("drive.load_torque", 93.5),)),
    Case("drive: load at 1.05 of the capacity (gross slip)", "drive_flat",
         (("drive.load_torque", 103.4),)),
    Case("drive: undamped belt", "drive_flat", (("physics.damping", 0.0),)),
)
_THIN = (("beam.height", 0.01),)
_OUTLET = (("contact.start", 0.6466666666666666), ("contact.end", 0.98))
#: Each derived from the paper's data.
STABILITY_CASES = (
    Case("paper quasistatic", "paper_quasistatic"),
    Case("paper inertia", "paper_inertia"),
    Case("paper slip", "paper_slip"),
    Case("stiff friction (v_reg 1e-5, f* 1e8)", "paper_slip",
         (("contact.max_friction", 1e8), ("numerics.regularisation", 1e-5))),
    Case("stiff belt (E x 100)", "paper_slip", (("beam.youngs_modulus", 5e9),)),
    Case("thin belt (h = 0.01 m)", "paper_slip", _THIN),
    Case("thin belt, quasistatic", "paper_slip", _THIN + (("physics.inertia", False),)),
    Case("near-critical (c = 0.97 sqrt(a/I))", "paper_slip",
         (("motion.belt_speed", 125.2265), ("motion.surface_speed", 126.4787))),
    Case("large mismatch (v/c - 1 = 0.05)", "paper_slip", (("motion.surface_speed", 126.0),)),
    Case("v = c (zero state)", "paper_slip", (("motion.surface_speed", 120.0),)),
    Case("v < c (reversed forces)", "paper_slip", (("motion.surface_speed", 118.8),)),
    Case("short contact (x2 - x1 = 0.02 L)", "paper_slip",
         (("contact.start", 0.49), ("contact.end", 0.51))),
    # at the paper's 39 1/s this geometry flutters (a slip-zone mode grows; the
    # CHANGELOG has the eigenvalues): damped at 200 1/s it settles; at 39 1/s it runs a span
    Case("contact ends 0.02 L from the outlet (d = 200 1/s)", "paper_slip",
         (*_OUTLET, ("physics.damping", 200.0))),
    Case("contact ends 0.02 L from the outlet, d = 39 1/s: flutter", "paper_slip", _OUTLET,
         span=0.1),
    Case("very fine grid (20,000 elements)", "paper_slip", (("numerics.elements", 20000),)),
    Case("soft belt (E / 100: c above both critical speeds)", "paper_slip",
         (("beam.youngs_modulus", 5e5),)),
    Case("soft belt (E / 100), quasistatic", "paper_slip",
         (("beam.youngs_modulus", 5e5), ("physics.inertia", False))),
    Case("poisson_ratio -0.99", "paper_slip", (("beam.poisson_ratio", -0.99),)),
    Case("poisson_ratio 0.499", "paper_slip", (("beam.poisson_ratio", 0.499),)),
    Case("tiny mismatch (v/c - 1 = 1e-6)", "paper_slip", (("motion.surface_speed", 120.00012),)),
    Case("the whole contact slides (f* = 5e3)", "paper_slip", (("contact.max_friction", 5e3),)),
    Case("very slow belt (c = 1e-3 m/s)", "paper_slip",
         (("motion.belt_speed", 1e-3), ("motion.surface_speed", 1.01e-3))),
    Case("long domain (L = 50 m)", "paper_slip",
         (("beam.length", 50.0), ("contact.start", 16.666666666666668),
          ("contact.end", 33.333333333333336))),
    Case("contact starts 0.02 L from the inlet", "paper_slip",
         (("contact.start", 0.02), ("contact.end", 0.3533333333333333))),
    Case("paper slip, undamped", "paper_slip", (("physics.damping", 0.0),), span=0.1),
    Case("paper inertia, undamped", "paper_inertia", (("physics.damping", 0.0),), span=0.1),
    *DRIVE_CASES,
)


def stability_cell(case: Case, scheme: str, extra=(), bounds=None, discrete=False) -> dict:
    """One cell: status, reason, reason_key, dt, steps, wall time and errors of one scheme
    on one case; ``extra``: (key, value) overrides of every case (e.g. the grid),
    ``bounds``: the acceptance bounds (default BOUNDS). ``discrete``: measure the errors
    against the steady scheme's state on the same grid with DISCRETE_BOUNDS instead of
    against the exact solution (a coarse matrix, whose grid error would hide whether a
    scheme reached its grid's steady state); where the steady scheme fails, the exact
    solution and BOUNDS serve.

    A shipped base scene that is not installed raises MissingInputError: a missing input
    fails the study, it is never a refused cell.
    """
    base = case.base_scene()
    closed = is_drive_scene(base)
    keys = readout_class(closed).error_keys
    cell = {"scheme": scheme, "status": "", "reason": "", "reason_key": "",
            "dt": float("nan"), "steps": 0, "wall_time": float("nan"),
            **{f"error_{k}": float("nan") for k in keys}}
    try:
        scene = case.scene(extra, base)
    except SceneError as exc:
        cell.update(status=CellStatus.REFUSED, reason=str(exc), reason_key=exc.key or "")
        return cell
    why_not = solvers.applicable(scheme, scene.params.inertia, closed)
    if why_not:
        cell.update(status=CellStatus.NOT_APPLICABLE, reason=why_not)
        return cell
    try:
        sim = Simulation(scene.with_overrides([("numerics.integrator", scheme)]))
    except BeltsimError as exc:
        key = exc.key if isinstance(exc, SceneError) else type(exc).__name__
        cell.update(status=CellStatus.REFUSED, reason=str(exc), reason_key=key or "")
        return cell
    try:
        res = sim.run(raise_on_failure=False)
    except NoSolutionError as exc:  # the steady scheme refuses a drive with no steady state
        cell.update(status=CellStatus.REFUSED, reason=str(exc),
                    reason_key=type(exc).__name__)
        return cell
    own_grid = _discrete_reference(scene) if discrete else None
    if own_grid is not None:
        bounds = DRIVE_DISCRETE_BOUNDS if closed else DISCRETE_BOUNDS
    elif bounds is None:
        bounds = DRIVE_BOUNDS if closed else BOUNDS
    res.reference = own_grid if own_grid is not None else sim.readout.reference()
    err = res.errors() or {}
    cell.update(dt=sim.numerics.dt if sim.scheme.transient else float("nan"),
                steps=res.steps, wall_time=res.wall_time,
                **{f"error_{k}": err[k] for k in keys if err.get(k) is not None})
    if (case.span and sim.scheme.transient
            and res.status in (RunStatus.REACHED_END, RunStatus.CONVERGED)):
        cell.update(status=CellStatus.BOUNDED,
                    reason=f"t = {res.simulated_time:.3g} s, final rate "
                           f"{res.history['rate'][-1]:.3g}")
    elif (res.status in (RunStatus.GROSS_SLIP, RunStatus.LIFT_OFF)
          and sim.readout.reference() is None):
        cell.update(status=CellStatus.OUTCOME, reason=res.reason,
                    reason_key=res.status.value)
    elif not res.converged:
        # what stopped the run: the kind of failure, else the status it ended in
        cell.update(status=_RUN_STATUS[res.status], reason=res.reason,
                    reason_key=(res.failure or res.status).value)
        diverged = res.failure is not None and res.failure.diverged
        # (a loop has no linearisation yet: its cells keep the run's status)
        if (sim.scheme.time_accurate and scene.params.inertia and not closed
                and (diverged or res.status is RunStatus.REACHED_END)):
            unstable, why, decay = steady_state_stability(scene)
            cell.update(status=CellStatus.UNSTABLE if unstable else cell["status"],
                        reason=f"{why}; {res.reason}" if unstable else f"{res.reason}; {why}")
            num = sim.numerics
            span = num.t_end - num.settle_time
            needed = math.log(1.0 / num.steady_tol) / decay if decay > 0 else 0.0
            if (res.status is RunStatus.REACHED_END and scene.params.damping > 0
                    and needed > span):
                # damped and stable, but its slowest mode cannot decay to steady_tol within
                # t_end: the physics is slower than the default span, not a numerical
                # failure (an undamped scene rings on: the random study's own rule)
                cell.update(status=CellStatus.BOUNDED, reason_key="", reason=(
                    f"stable but slow: settling to steady_tol {num.steady_tol:g} takes about "
                    f"{needed:.3g} s after the drive (ln(1/steady_tol) over the decay rate), "
                    f"more than t_end leaves ({span:.3g} s); raise "
                    f"numerics.t_end; {cell['reason']}"))
    else:
        over = {k: b for k, b in bounds.items()
                if err.get(k) is not None and not err[k] <= b}
        cell.update(status=CellStatus.OUT_OF_BOUNDS if over else CellStatus.CONVERGED,
                    reason="; ".join(f"{k} {err[k]:.3g} > {b:g}" for k, b in over.items()),
                    reason_key=", ".join(over))
    return cell


def _steady_key(scene) -> tuple:
    """The scene's steady problem on its grid as a key (its tables frozen,
    :func:`~beltsim.problem.tables.frozen`): the time-stepping keys and the title change
    neither its steady state nor its verdict."""
    from ..physics.modes import steady_scene

    data = steady_scene(scene).to_dict()
    data.pop("title", None)
    return frozen(data)


def _discrete_reference(scene):
    """The steady scheme's state of ``scene`` on its own grid, or None where it fails."""
    key = _steady_key(scene)
    if key not in _STEADY:
        sim = Simulation(scene.with_overrides([("numerics.integrator", "steady")]))
        try:
            res = sim.run(raise_on_failure=False)
        except NoSolutionError:  # a drive beyond its capacity: the exact state serves
            res = None
        _STEADY[key] = (sim.readout.discrete_reference(res.solution)
                        if res is not None and res.converged else None)
    return _STEADY[key]


_STEADY: dict[tuple, object] = {}  # one steady solve per case


def steady_state_stability(scene) -> tuple[bool, str, float]:
    """(unstable, why, decay): whether the scene's discrete steady state (its grid) is
    linearly unstable by a clear margin (GROWTH_MARGIN), a sentence with the growth rate,
    and the least stable mode's decay rate (1/s; 0 when it grows or is unknown)."""
    key = _steady_key(scene)
    if key not in _VERDICTS:
        _VERDICTS[key] = _stability_verdict(scene)
    return _VERDICTS[key]


#: Verdicts by the scene's data (its frozen tables): the schemes of a case share one.
_VERDICTS: dict[tuple, tuple[bool, str, float]] = {}


def _stability_verdict(scene) -> tuple[bool, str, float]:
    from ..physics.modes import growth_rate

    try:
        g = growth_rate(scene)
    except Exception as exc:  # noqa: BLE001  no verdict leaves the cell as it was
        return False, f"no linear stability verdict ({type(exc).__name__}: {exc})", 0.0
    transit = solvers.discretise(scene).window  # either layout's
    margin = GROWTH_MARGIN * max(math.hypot(g.rate, 2 * math.pi * g.frequency), 1.0 / transit)
    if g.rate > margin:
        return True, (f"the steady state is linearly unstable: {g.describe()} on this grid "
                      f"({g.elements} elements), so no run can settle: the model flutters"), 0.0
    return (False, f"the steady state is linearly stable on this grid: {g.describe()}",
            max(-g.rate, 0.0))


def stability_matrix(cases=STABILITY_CASES, schemes=None, extra=(), progress=None,
                     discrete=False):
    """Every case by every scheme (default: all registered), one row per cell;
    ``discrete``: see :func:`stability_cell`."""
    rows = []
    for case in cases:
        for scheme in schemes or solvers.names():
            row = {"case": case.name,
                   **stability_cell(case, scheme, extra=extra, discrete=discrete)}
            rows.append(row)
            if progress:
                progress(row)
    return rows


def error_columns(rows) -> list[str]:
    """The ``error_*`` columns of the rows, in their first appearance's order (a straight
    belt's and a drive's cells report different errors)."""
    return list(dict.fromkeys(k for r in rows for k in r if k.startswith("error_")))


_LABELS = {"total_friction": "total friction", "concentrated_force": "conc. force",
           "slip_start": "slip start [m]"}


def stability_markdown(rows) -> str:
    """A table per layout (its errors' columns): case, scheme, status, dt, steps, wall
    time, errors, reason."""
    def num(v, fmt):
        return "" if v is None or (isinstance(v, float) and not math.isfinite(v)) else fmt % v

    groups: dict[tuple, list] = {}
    for r in rows:
        groups.setdefault(tuple(error_columns([r])), []).append(r)
    tables = []
    for cols, group in groups.items():
        labels = [_LABELS.get(c[6:], c[6:].replace("_", " ")) for c in cols]
        lines = ["| case | scheme | status | dt [s] | steps | wall [s] | " + " | ".join(labels)
                 + " | reason |", "|" + "---|" * (7 + len(cols))]
        for r in group:
            lines.append("| " + " | ".join([
                r["case"], r["scheme"], r["status"].value, num(r["dt"], "%.2e"),
                str(r["steps"]), num(r["wall_time"], "%.3g"),
                *(num(r[c], "%.1e") for c in cols), r["reason"].replace("|", "/")]) + " |")
        tables.append("\n".join(lines) + "\n")
    return "\n".join(tables)
