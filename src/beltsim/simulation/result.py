"""The outcome of a run: its status, its final state read as a solution, its records."""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

from ..problem import analytic
from ..problem.drive import period_of
from ..problem.scene import Scene
from ..solvers.settings import Numerics
from .solution import DiscreteSolution, compare


class RunStatus(enum.Enum):
    """How a run ended."""

    CONVERGED = "converged"  # steady state reached
    REACHED_END = "reached t_end"  # t_end reached before steady state
    FAILED = "failed"  # stopped on a numerical failure; the state is the last good one
    INTERRUPTED = "interrupted"  # a signal or a callback asked it to stop


@dataclass
class RunResult:
    """The outcome of a run: status, final state, history, statistics and records."""

    scene: Scene
    numerics: Numerics
    status: RunStatus
    reason: str | None
    time_accurate: bool  # the scheme follows the scene's path, not only its end
    solution: DiscreteSolution
    simulated_time: float
    wall_time: float
    compile_time: float
    statistics: dict
    history: dict
    snapshots: dict = field(default_factory=dict)
    #: E(t) - E(0) against the integrated power terms (schemes that integrate them)
    power_balance: dict | None = None
    #: a periodic drive's last period: extremes and means (None for a drive that settles)
    periodic: dict | None = None
    #: the exact steady solution of the same scene, attached by the caller (None: not
    #: attached, or the scene has none)
    reference: analytic.AnalyticSolution | None = None

    @property
    def converged(self) -> bool:
        return self.status is RunStatus.CONVERGED

    @property
    def failed(self) -> bool:
        return self.status is RunStatus.FAILED

    @property
    def interrupted(self) -> bool:
        return self.status is RunStatus.INTERRUPTED

    @property
    def steps(self) -> int:
        return self.statistics["steps"]

    @property
    def newton_iterations(self) -> int:
        return self.statistics.get("newton_iterations", 0)

    def errors(self) -> dict | None:
        if self.reference is None:
            return None
        return compare(self.solution, self.reference)

    def summary(self) -> dict:
        out = self.solution.summary()
        out.update(converged=self.converged, simulated_time=self.simulated_time,
                   steps=self.steps, rejected_steps=self.statistics.get("rejected_steps", 0),
                   time_accurate=self.time_accurate, wall_time=self.wall_time,
                   compile_time=self.compile_time,
                   reason=self.reason, elements=self.numerics.elements,
                   integrator=self.numerics.integrator, power_balance=self.power_balance,
                   periodic=self.periodic,
                   error=self.errors())
        return out


def reference_of(scene: Scene, model: str | None = None):
    """The exact steady solution of a scene, or None where it has none (a periodic drive
    never settles)."""
    if period_of(scene) is not None:
        return None
    try:
        return analytic.solve(scene, model=model)
    except analytic.NoSolutionError:
        return None
