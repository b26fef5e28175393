"""Steady scheme: Newton on the discrete equations with d/dt = 0, from rest.

The surface speed goes from c to v in stages of continuation (the mismatch
v - c scaled by s in (0, 1]): a stage that converges doubles the next one, a
failed stage is undone and retried with a quarter of its size. A saturating friction
law is first solved with a regularisation velocity REGULARISATION_START times the
scene's (smooth friction, few iterations) and then with the scene's from there, which
takes fewer Newton iterations than the scene's law from rest. It lands on the same
discrete steady state as the transient schemes (docs/theory/time-schemes.md).
"""

from __future__ import annotations

from ..errors import FailureKind, NumericalError
from ..physics.friction import is_exact
from ..physics.model import regularised
from ..problem.drive import Drive
from .newton import NewtonScheme, NewtonSettings, newton
from .registry import register

MIN_STAGE = 1e-6  # smallest continuation stage, relative to the full mismatch
STAGE_ITERATIONS = 4  # Newton iterations per stage, in units of newton_max_iterations
REGULARISATION_START = 1e3  # v_reg of the first solve of a saturating law, in units of the scene's


@register
class SteadyScheme(NewtonScheme):
    """Newton on the steady equations with continuation in v - c; no time stepping."""

    name = "steady"
    transient = False
    time_accurate = False

    def _stage(self, state, s, settings):
        d = self.disc
        drive = Drive.constant((d.params.v - d.params.c) * s)
        return newton(state, self.old, 0.0, 0.0, d.mesh, d.model, drive, d.loads, d.scales,
                      settings, self.work)

    def _compile(self, state) -> None:
        trial = state.copy()
        self._stage(trial, 0.0, NewtonSettings(1.0, 0))
        self.work.stats[:] = 0

    def solve(self, state) -> None:
        """Continuation in v - c (after one in v_reg for a saturating law); the number of
        stages is counted as steps. An exact law first solves its regularised twin
        (physics.model.regularised) so, and then itself from there at full speed: the
        semi-smooth Newton cycles from rest, where every node's stick/slip state is
        wrong, and converges from the twin's (a few iterations).

        Raises NumericalError when the stage falls below MIN_STAGE of the mismatch.
        """
        model = self.disc.model
        exact = is_exact(model.law)
        smooth = regularised(model)  # the model itself for a regularised law
        try:
            if smooth.dual:
                self.disc.model = smooth._replace(
                    regularisation=REGULARISATION_START * smooth.regularisation)
                self._continue_in_speed(state)
            self.disc.model = smooth
            self._continue_in_speed(state)
        finally:
            self.disc.model = model
        if exact:
            self.steps += 1
            if not self._stage(state, 1.0, self.settings._replace(
                    max_iterations=STAGE_ITERATIONS * self.settings.max_iterations)):
                raise NumericalError(
                    "steady semi-smooth Newton iteration of the exact friction law did not "
                    "converge from its regularised twin's steady state",
                    kind=FailureKind.CONTINUATION, t=0.0, quantity="newton")

    def _continue_in_speed(self, state) -> None:
        stage_settings = self.settings._replace(
            max_iterations=STAGE_ITERATIONS * self.settings.max_iterations)
        s_done, ds = 0.0, 1.0
        while s_done < 1.0:
            s = min(1.0, s_done + ds)
            saved = state.copy()
            ok = self._stage(state, s, stage_settings)
            self.steps += 1
            if ok:
                s_done, ds = s, 2.0 * ds
            else:
                state.assign(saved)
                ds *= 0.25
                if ds < MIN_STAGE:
                    raise NumericalError(
                        f"steady Newton iteration failed at {100 * s_done:.4g}% of the "
                        f"speed mismatch (continuation step below {MIN_STAGE:g})",
                        kind=FailureKind.CONTINUATION, t=0.0, quantity="newton")
