"""The outcome of a run: its status, its final state read as a solution, its records."""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

import numpy as np

from ..errors import FailureKind
from ..problem import analytic
from ..problem.drive import period_of
from ..problem.scene import Scene
from ..solvers.settings import Numerics
from .solution import DiscreteSolution


class RunStatus(enum.Enum):
    """How a run ended (``RunResult.status``)."""

    CONVERGED = "converged"  # steady state reached
    REACHED_END = "reached t_end"  # t_end reached before steady state
    FAILED = "failed"  # stopped on a numerical failure; the state is the last good one
    INTERRUPTED = "interrupted"  # a signal or a callback asked it to stop
    GROSS_SLIP = "gross slip"  # a whole wrap slides and the load wins: a physical outcome
    LIFT_OFF = "lift-off"  # the contact pressure fell to zero: outside this model


@dataclass
class RunResult:
    """A run's outcome: how it ended, its final state, its history.

    The final state reads as arrays over the grid (:attr:`x`, :attr:`fields`), the
    checks as arrays over time (``history``), the numbers the analytic solution
    also gives in :meth:`summary`, and the errors against it in :meth:`errors`.

    Attributes
    ----------
    scene : Scene
        The scene that ran.
    numerics : beltsim.solvers.settings.Numerics
        The settings it ran with, every default resolved.
    status : RunStatus
        How it ended.
    reason : str or None
        Why it stopped, when not steady.
    time_accurate : bool
        The scheme follows the scene's path in time, not only to its end.
    solution : DiscreteSolution
        The final state, read as a solution (totals, slip start, concentrated force).
    simulated_time, wall_time, compile_time : float
        Seconds: simulated, of stepping, of compiling (or loading) the kernels.
    statistics : dict
        The scheme's counters: ``steps`` and, where it has them, ``rejected_steps``,
        ``newton_iterations``; a tensioner's steady search adds ``arm_solves``.
    history : dict of str to numpy.ndarray
        One value per check: ``t`` (s), ``total_friction`` (N), ``rate`` and, for a
        coulomb scene, ``slip_start`` (m), ``stick_friction``, ``slip_friction`` (N)
        and ``slip_power`` (W), or for perfect adhesion ``concentrated_force`` (N).
    snapshots : dict of str to numpy.ndarray
        ``t`` and the states ``u``, ``theta``, ``fnode`` (times, nodes) at every
        snapshot interval (empty unless asked for).
    power_balance : dict or None
        The energy balance over the run (schemes that integrate the power terms).
    periodic : dict or None
        A periodic drive's last period: extremes and means of the history.
    reference : AnalyticSolution or None
        The exact steady solution of the scene, where :func:`beltsim.run` attached it.
    stability : Stability, str or None
        Whether the steady state is stable in the model
        (:class:`beltsim.simulation.stability.Stability`), attached by :func:`beltsim.run`
        and ``beltsim run`` to an inertial scene that settles.

    Examples
    --------
    >>> result = beltsim.run(beltsim.paper_scene("slip"))          # doctest: +SKIP
    >>> result.fields["u"].max(), result.history["total_friction"][-1]  # doctest: +SKIP
    """

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
    #: what stopped a FAILED run (None for any other status)
    failure: FailureKind | None = None
    #: whether the steady state is stable in the model, with the run's damping of its least
    #: stable mode (:mod:`beltsim.simulation.stability`); a sentence where it could not be
    #: computed; None where not checked (quasistatic, periodic, or the check off)
    stability: object = None

    @property
    def converged(self) -> bool:
        """Whether the run reached steady state (status CONVERGED)."""
        return self.status is RunStatus.CONVERGED

    @property
    def failed(self) -> bool:
        """Whether a numerical failure stopped it (status FAILED; see :attr:`failure`)."""
        return self.status is RunStatus.FAILED

    @property
    def interrupted(self) -> bool:
        """Whether a signal, a callback or a tracker's :class:`~beltsim.Stop` ended it."""
        return self.status is RunStatus.INTERRUPTED

    @property
    def steps(self) -> int:
        """Time steps taken (the steady scheme: its continuation stages)."""
        return self.statistics["steps"]

    @property
    def newton_iterations(self) -> int:
        """Newton iterations over the run (0 for the explicit scheme)."""
        return self.statistics.get("newton_iterations", 0)

    @property
    def x(self) -> np.ndarray:
        """The grid's nodes (m)."""
        return self.solution.x

    @property
    def fields(self) -> dict[str, np.ndarray]:
        """The final state over :attr:`x`, as the analytic solution gives its own.

        Returns
        -------
        dict of str to numpy.ndarray
            ``x`` (m), ``u`` (m), ``theta`` (rad), ``strain``, ``tension`` (N),
            ``moment`` (N m) and ``friction`` (N/m), one value per node: the columns of
            ``fields.csv``. ``AnalyticSolution.fields(result.x)`` has the same keys but x.
        """
        fields = {"x": self.solution.x, **self.solution.fields()}
        return {k: np.array(v) for k, v in fields.items()}  # copies: the state stays as it is

    def errors(self) -> dict | None:
        """The final state's errors against :attr:`reference` (None without one).

        Returns
        -------
        dict or None
            Relative errors of ``total_friction``, ``u``, ``theta`` (largest difference
            over the nodes over the exact field's largest magnitude), ``slip_power`` and
            ``concentrated_force`` (perfect adhesion), and the absolute error of
            ``slip_start`` in m (stick and slip); keys that do not apply are None.
        """
        if self.reference is None:
            return None
        return self.solution.errors(self.reference)

    def summary(self) -> dict:
        """What ``summary.json`` holds: the final state's totals and how the run went.

        Returns
        -------
        dict
            The keys of :meth:`beltsim.AnalyticSolution.summary`, read off the final
            state, and ``converged``, ``simulated_time``, ``steps``, ``rejected_steps``,
            ``time_accurate``, ``wall_time``, ``compile_time``, ``reason``, ``failure``
            (a :class:`~beltsim.errors.FailureKind` value or None), ``elements``,
            ``integrator``, ``power_balance``, ``periodic``, ``error``
            (:meth:`errors`) and ``stability`` (``Stability.to_dict()``, or
            {"stable": None, "summary": why not checked}; None where it does not apply).
        """
        out = self.solution.summary()
        out.update(status=self.status.value, converged=self.converged,
                   simulated_time=self.simulated_time,
                   steps=self.steps, rejected_steps=self.statistics.get("rejected_steps", 0),
                   time_accurate=self.time_accurate, wall_time=self.wall_time,
                   compile_time=self.compile_time,
                   reason=self.reason,
                   failure=self.failure.value if self.failure is not None else None,
                   elements=self.numerics.elements,
                   integrator=self.numerics.integrator, power_balance=self.power_balance,
                   periodic=self.periodic,
                   error=self.errors(), stability=self._stability())
        return out

    def _stability(self) -> dict | None:
        if self.stability is None or isinstance(self.stability, str):
            return (None if self.stability is None
                    else {"stable": None, "summary": self.stability})
        return self.stability.to_dict()


def reference_of(scene: Scene, model: str | None = None):
    """The exact steady solution of a scene, or None where it has none (a periodic drive
    never settles)."""
    if period_of(scene) is not None:
        return None
    try:
        return analytic.solve(scene, model=model)
    except analytic.NoSolutionError:
        return None
