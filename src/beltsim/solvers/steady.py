"""Steady scheme: Newton on the discrete equations with d/dt = 0.

On a grid up to COARSEST times the scene's default elements, Newton starts from rest.
The surface speed goes from c to v in stages of continuation (the mismatch v - c
scaled by s in (0, 1]): a stage that converges doubles the next one, a failed stage is
undone and retried with a quarter of its size. A saturating friction law is first
solved with a regularisation velocity REGULARISATION_START times the scene's (smooth
friction, few iterations) and then with the scene's from there, which takes fewer
Newton iterations than the scene's law from rest.

From rest, Newton moves a slip front by about a node an iteration, so its iterations
grow with the grid. A finer grid therefore starts from the steady state of one
COARSENING times coarser (every COARSENING-th node of its own), interpolated: the
front is then within a few nodes of its place, and Newton needs a few iterations per
grid whatever its size. Every grid solves the scene's model (the finest grid's
regularisation), so the iterate lands on the same discrete steady state as the
transient schemes (docs/theory/time-schemes.md).
"""

from __future__ import annotations

import copy
from dataclasses import replace

import numpy as np

from ..beltdrive.analytic import creep_speed
from ..beltdrive.exact import string_state
from ..errors import FailureKind, NumericalError
from ..physics.discrete import Loads, mesh_of, regularised
from ..physics.friction import EXACT, TANH, is_exact
from ..physics.grid import Grid
from ..physics.layout import LoopGrid
from .newton import NewtonScheme, NewtonSettings, newton
from .registry import register
from .settings import LOOP_ELEMENTS, LOOP_REGULARISATION, default_elements

MIN_STAGE = 1e-6  # smallest continuation stage, relative to the full mismatch
STAGE_ITERATIONS = 4  # Newton iterations per stage, in units of newton_max_iterations
REGULARISATION_START = 1e3  # v_reg of the first solve of a saturating law, in units of the scene's
COARSENING = 4  # element ratio of successive grids of the sequence
COARSEST = 4  # largest grid solved from rest, in units of the scene's default elements
# an exact law's regularised twin: its v_reg over the creep speed
TWIN_REGULARISATION = 0.3 * LOOP_REGULARISATION


@register
class SteadyScheme(NewtonScheme):
    """Newton on the steady equations: from rest with continuation in v - c on coarse
    grids, from the next coarser grid's steady state on fine ones; no time stepping."""

    name = "steady"
    transient = False
    time_accurate = False

    def __init__(self, disc):
        super().__init__(disc)
        self.grid_iterations: list[int] = []  # Newton iterations on each grid, coarsest first

    def statistics(self) -> dict:
        return {**super().statistics(), "grid_iterations": list(self.grid_iterations)}

    def _stage(self, state, s, settings):
        d = self.disc
        drive = d.steady_drive(s)
        return newton(state, self.old, 0.0, 0.0, d.mesh, d.model, drive, d.loads, d.scales,
                      settings, self.work)

    def _compile(self, state) -> None:
        trial = state.copy()
        self._stage(trial, 0.0, NewtonSettings(1.0, 0))
        self.work.stats[:] = 0

    @property
    def _stage_settings(self) -> NewtonSettings:
        return self.settings._replace(
            max_iterations=STAGE_ITERATIONS * self.settings.max_iterations)

    def solve(self, state) -> None:
        """The steady state, in place: from rest on a grid up to COARSEST times the
        default elements, else from the steady state of a grid COARSENING times
        coarser, interpolated (:func:`coarsened`, :func:`interpolate`). The stages of
        continuation of every grid are counted as steps, their Newton iterations with
        this scheme's (and each grid's apart, ``grid_iterations``).

        Raises NumericalError when a stage from rest falls below MIN_STAGE of the
        mismatch, or Newton does not converge from a coarser grid's steady state (on
        grids so fine that its update stalls above its round-off floor).
        """
        d = self.disc
        if d.closed:
            self._solve_loop(state)
            return
        if d.grid.n_elements <= COARSEST * default_elements(d.params):
            self._solve_from_rest(state)
            self.grid_iterations = [int(self.work.stats[0]["newton_iterations"])]
            return
        coarse = copy.copy(d)
        coarse.grid, index = coarsened(d.grid, COARSENING)
        coarse.mesh = mesh_of(coarse.grid)
        coarse.loads = Loads(*(q if q.ndim == 1 else q[:, index] for q in d.loads))
        level, coarse_state, before = self._coarse_level(coarse)
        stats = self.work.stats[0]
        interpolate(coarse.grid, coarse_state, d.grid, state)
        if not self._stage(state, 1.0, self._stage_settings):
            raise NumericalError(
                f"steady Newton iteration on {d.grid.n_elements} elements did not converge "
                f"from the steady state of {coarse.grid.n_elements} elements (residual "
                f"norm {stats['merit']:.3g})",
                kind=FailureKind.CONTINUATION, t=0.0, quantity="newton")
        self.grid_iterations = [*level.grid_iterations,
                                int(stats["newton_iterations"]) - before]

    def _coarse_level(self, coarse):
        """The steady state of a coarser discretisation (grid sequencing), its steps and
        Newton counts added to this scheme's; returns the coarse scheme, its state and the
        Newton iterations counted so far."""
        level = SteadyScheme(coarse)
        coarse_state = coarse.new_state()
        level.solve(coarse_state)
        self.steps += level.steps
        stats, level_stats = self.work.stats[0], level.work.stats[0]
        for key in ("newton_iterations", "line_search_cuts"):
            stats[key] += level_stats[key]
        return level, coarse_state, int(stats["newton_iterations"])

    def _solve_from_rest(self, state) -> None:
        """Continuation in v - c (after one in v_reg for a saturating law); the number of
        stages is counted as steps. An exact law first solves its regularised twin
        (physics.discrete.regularised) so, and then itself from there at full speed: the
        semi-smooth Newton cycles from rest, where every node's stick/slip state is
        wrong, and converges from the twin's (a few iterations).
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
            if not self._stage(state, 1.0, self._stage_settings):
                raise NumericalError(
                    "steady semi-smooth Newton iteration of the exact friction law did not "
                    "converge from its regularised twin's steady state",
                    kind=FailureKind.CONTINUATION, t=0.0, quantity="newton")

    def _solve_loop(self, state) -> None:
        """A loop's steady state: Newton from the creep theory's (the extensible string's
        exact steady state, theta = 0) on grids up to COARSEST times the default
        elements, else from the steady state of a grid COARSENING times coarser. Exact
        Coulomb friction first solves its regularised twin (tanh, :meth:`_twin`) from
        there: the semi-smooth Newton from the string's
        state, whose slip fronts the beam moves, cycles between stick and slip at the
        fronts; a sharp regularised law comes down to its v_reg from the creep speed in
        steps of ten."""
        d = self.disc
        model = d.model
        if d.grid.n_elements > COARSEST * LOOP_ELEMENTS:
            coarse = d.with_grid(LoopGrid.build(d.params.layout.lengths,
                                                d.grid.n_elements // COARSENING))
            level, coarse_state, before = self._coarse_level(coarse)
            stats = self.work.stats[0]
            interpolate_loop(coarse.grid, coarse_state, d.grid, d.mesh.cn, state)
            self._loop_stage(state, model, "from the steady state of "
                             f"{coarse.grid.n_elements} elements")
            self.grid_iterations = [*level.grid_iterations,
                                    int(stats["newton_iterations"]) - before]
            return
        creep_state(d, state)
        creep = creep_speed(d.params)
        try:
            if model.law == EXACT:
                self._twin(state, model, creep)
            elif model.law < EXACT:
                v = creep
                while v > 10.0 * model.regularisation:
                    self.disc.model = model._replace(regularisation=v)
                    self._loop_stage(state, self.disc.model, f"at v_reg = {v:.3g} m/s")
                    v /= 10.0
        finally:
            self.disc.model = model
        self._loop_stage(state, model, "from the creep theory's state")
        self.grid_iterations = [int(self.work.stats[0]["newton_iterations"])]

    def _twin(self, state, model, creep) -> None:
        """The regularised twin's steady state from the creep theory's (in ``state``):
        at TWIN_REGULARISATION times the creep speed, nearer the exact law's fronts than
        LOOP_REGULARISATION's (the semi-smooth Newton moves a front by about a node an
        iteration: serpentine_accessory 8 iterations from it instead of 13), or, where
        that fails, at LOOP_REGULARISATION."""
        start = state.copy()
        for i, v in enumerate((TWIN_REGULARISATION, LOOP_REGULARISATION)):
            self.disc.model = model._replace(law=TANH, dual=1, regularisation=v * creep)
            try:
                self._loop_stage(state, self.disc.model, "of the regularised twin")
                return
            except NumericalError:
                if i == 1:
                    raise
                state.assign(start)

    def _loop_stage(self, state, model, what) -> None:
        # the twin's regularised law needs the regularised workspace's arrays only
        self.steps += 1
        if not self._stage(state, 1.0, self._stage_settings):
            raise NumericalError(
                f"steady Newton iteration on {self.disc.grid.n_elements} elements did not "
                f"converge {what} (residual norm {self.work.stats[0]['merit']:.3g})",
                kind=FailureKind.CONTINUATION, t=0.0, quantity="newton")

    def _continue_in_speed(self, state) -> None:
        stage_settings = self._stage_settings
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


def coarsened(grid: Grid, factor: int) -> tuple[Grid, np.ndarray]:
    """A grid of about 1/factor of ``grid``'s elements, on a subset of its nodes, and the
    indices of that subset.

    Each segment between 0, x1, x2 and L keeps about every factor-th of its nodes
    (evenly spaced in index, so the coarse grid is graded as the fine one), its ends
    among them, and at least two elements (all it has, if fewer).
    """
    ends = (0, grid.j1, grid.j2, grid.n_elements)
    parts = []
    for a, b in zip(ends[:-1], ends[1:]):
        k = min(b - a, max(2, round((b - a) / factor)))
        parts.append(np.rint(np.linspace(a, b, k + 1)).astype(np.int64)[:-1])
    index = np.concatenate([*parts, [grid.n_elements]])
    j1, j2 = np.searchsorted(index, [grid.j1, grid.j2])
    return Grid(grid.x[index], int(j1), int(j2)), index


def interpolate(coarse: Grid, state, fine: Grid, out) -> None:
    """A coarse grid's steady state on a finer grid, as Newton's start: u, theta and the
    friction ratios (on the contact nodes of each) linear in x; the rates zero, the
    friction forces left to Newton's first assembly."""
    out.assign(type(out).zeros(fine.n_elements + 1))
    out.u[:] = np.interp(fine.x, coarse.x, state.u)
    out.theta[:] = np.interp(fine.x, coarse.x, state.theta)
    cc, cf = slice(coarse.j1, coarse.j2 + 1), slice(fine.j1, fine.j2 + 1)
    out.lam[cf] = np.interp(fine.x[cf], coarse.x[cc], state.lam[cc])


def creep_state(d, state) -> None:
    """A loop's state at the creep theory's steady state (the extensible string's exact
    one; theta = 0): Newton's start. Raises NoSolutionError where the string has none
    (gross slip, lift-off)."""
    P, x = d.params, d.grid.x
    # on the layout as the grid has it: a tensioner's arm held there (its rest angle is
    # the controller's search, Simulation._solve_arm)
    sol = string_state(replace(P, tensioner=None))
    state.assign(type(state).zeros(len(x), d.n_globals))
    state.u[:] = sol.displacement(x)
    cn = d.mesh.cn
    if P.mu is not None:
        p = sol.pressure(x[cn])
        mu = d.mesh.seg_mu[d.mesh.seg[cn]]
        lam = np.where(p > 0, -sol.friction(x[cn]) / (mu * np.where(p > 0, p, 1.0)), 0.0)
        # inside (-1, 1): the regularised laws' inverse is singular on the boundary
        state.lam[cn] = np.clip(lam, -1.0 + 1e-9, 1.0 - 1e-9)
    else:
        state.lam[cn] = -sol.friction(x[cn]) / d.model.friction_scale
    speeds = np.asarray(sol.speeds)
    state.g[:] = (sol.c, *speeds[d.speed_global >= 0])


def interpolate_loop(coarse, state, fine, contact, out) -> None:
    """A coarse loop's steady state on a finer grid: u, theta and the friction ratios
    (on the fine grid's ``contact`` nodes) linear in x, periodic; the globals as they
    are."""
    out.assign(type(out).zeros(fine.n_elements, len(state.g)))
    xc = np.append(coarse.x, coarse.loop_length)
    for name in ("u", "theta", "lam"):
        v = getattr(state, name)
        getattr(out, name)[:] = np.interp(fine.x, xc, np.append(v, v[0]))
    off = np.ones(len(fine.x), bool)
    off[contact] = False
    out.lam[off] = 0.0
    out.g[:] = state.g
