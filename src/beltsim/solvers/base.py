"""What every scheme works on (:class:`~beltsim.solvers.base.Discretisation`) and the
interface it offers."""

from __future__ import annotations

import time
from typing import ClassVar, NamedTuple

import numpy as np

from ..errors import SceneError
from ..physics.discrete import Loads, Mesh, ModelParams, State, mesh_of, model_params
from ..physics.friction import EXACT, LINEAR, has_dual
from ..physics.grid import Grid
from ..physics.layout import LoopGrid, loop_mesh, loop_params, with_arm
from ..problem.drive import Drive, Profile, Profiles, as_profile, drive_of
from ..problem.scene import Scene
from .registry import get
from .settings import Numerics, build_grid, resolve, resolve_loop


class Scales(NamedTuple):
    """Scales of the residual rows and of the unknowns (Newton norms, rates, growth)."""

    force: float
    moment: float
    u: float
    theta: float
    glob: np.ndarray = np.zeros(0)  # a loop's global unknowns (their updates' scales)
    gres: np.ndarray = np.zeros(0)  # and their rows' (the residuals')


def scales_of(P) -> Scales:
    """Force, moment, displacement and rotation scales of a scene's physical parameters."""
    eps = abs(P.e0) if P.e0 != 0.0 else 1e-6
    force = P.B * eps
    return Scales(force, force * 0.5 * P.h, eps * P.L, eps)


class Discretisation:
    """A scene on its grid: the named structures the kernels read.

    ``grid`` replaces the default grid (e.g. a bisected one); the element count
    follows it.
    """

    def __init__(self, scene: Scene, grid: Grid | None = None):
        self.scene = scene
        self.params = P = scene.params
        num = resolve(scene, None if grid is None else grid.n_elements)
        self.numerics: Numerics = num
        self.grid: Grid = grid if grid is not None else build_grid(scene, num)
        self.mesh: Mesh = mesh_of(self.grid)
        self.model: ModelParams = model_params(P, P.damping + num.acceleration,
                                               num.friction_scale, num.regularisation,
                                               num.law_code, num.gyro_code)
        self.drive = drive_of(scene, num.ramp_time)
        self.loads: Loads = Loads.none(self.grid.n_elements + 1)
        self.scales: Scales = scales_of(P)

    #: the layout's global unknowns (none on the open layout)
    n_globals = 0

    #: an open layout's transport speed is the scene's c; a loop's is a global unknown
    closed = False

    def new_state(self) -> State:
        """The belt at rest."""
        return State.zeros(len(self.mesh.hb), self.n_globals)

    @property
    def window(self) -> float:
        """The layout's transit time (s): how long the material takes through it."""
        return self.params.L / self.params.c

    def steady_drive(self, s: float = 1.0) -> Drive:
        """The drive of the steady problem, its final values; ``s`` scales the surface's
        mismatch (the steady scheme's continuation)."""
        return Drive.constant((self.params.v - self.params.c) * s)


class LoopDiscretisation(Discretisation):
    """A closed drive on its periodic grid: the loop layout (each pulley's arc and the
    span to the next, in the belt's order), its global unknowns (the belt speed c, the
    speed of every pulley but the driver, in the pulleys' order, and a moving tensioner
    arm's angle and rate) and the named structures the kernels read.

    ``grid`` replaces the default grid (a :class:`~beltsim.physics.layout.LoopGrid`).
    ``arm``: whether a tensioner's arm moves (its two globals, from the layout as given);
    by default it does in a transient, from the exact steady state's rest angle, and a
    steady solve holds it (its search turns the layout instead).
    """

    closed = True

    #: a tensioner's arm in a transient (beltsim.beltdrive.arm.ArmTable; None without)
    arm = None

    def __init__(self, scene, grid: LoopGrid | None = None, arm: bool | None = None):
        num = resolve_loop(scene, None if grid is None else grid.n_elements)
        if arm is None:  # a transient moves a tensioner's arm from the exact rest angle
            arm = scene.params.tensioner is not None and get(num.integrator).transient
            if arm:
                scene = _arm_reference(scene)
        self.scene = scene
        self.params = P = scene.params
        self.numerics: Numerics = num
        layout = P.layout
        self.grid = grid if grid is not None else LoopGrid.build(layout.lengths,
                                                                 num.elements)
        pulleys = P.pulleys
        #: each pulley's global unknown (its speed), -1 for the driver
        free = np.array([p.role != "driver" for p in pulleys])
        self.speed_global = np.where(free, np.cumsum(free), -1)
        self.n_globals = len(pulleys)  # c and every pulley's speed but the driver's
        self.mesh: Mesh = loop_mesh(
            self.grid, [(2 * i, p.radius, int(k)) for i, (p, k)
                        in enumerate(zip(pulleys, self.speed_global))],
            [0.0 if mu is None else mu for mu in P.mus],
            (0.0, *(p.inertia for p in pulleys if p.role != "driver")),
            [p.side for p in pulleys])
        code = num.law_code
        self.model: ModelParams = loop_params(
            a=P.a, b1=P.b1, b2=P.b2, rho=P.rho, I=P.I, lever=P.lever,
            damping=P.damping + num.acceleration,
            N0=P.N0, law=code, dual=int(has_dual(code) and code != LINEAR and code < EXACT),
            regularisation=num.regularisation, friction_scale=num.friction_scale,
            gyro=num.gyro_code)
        driver = pulleys[P.driver]
        free = [p for p in pulleys if p.role != "driver"]
        # the rim speed omega_d(t) r_d and the loads M_k(t): numbers and sines ramp from 0
        self.drive = Drive(as_profile(driver.speed, 0.0, 1.0 / driver.radius, num.ramp_time),
                           Profile.constant(1.0),
                           Profiles.of([Profile.constant(0.0)] + [
                               Profile.constant(0.0) if p.load is None
                               else as_profile(p.load, 0.0, 1.0, num.ramp_time)
                               for p in free]))
        self.loads: Loads = Loads.none(self.grid.n_elements)
        rim = P.driver_rim_speed
        strain = P.N0 / P.b1
        L = layout.loop_length
        radii = np.array([p.radius for p in free])
        self.scales: Scales = Scales(P.N0, P.N0 * max(P.h, 1e-300), L * strain, strain,
                                     np.concatenate([[rim], rim / radii]),
                                     np.concatenate([[L * strain], P.N0 * radii]))
        if arm and P.tensioner is not None:
            self._add_arm()

    def _add_arm(self):
        """The tensioner's arm as two more globals, its angle from the grid's layout and
        its rate (:mod:`beltsim.physics.arm`), and the state at rest with the arm
        settled."""
        from ..beltdrive.arm import TRAVEL, arm_table, rest_angle

        P, ten = self.params, self.params.tensioner
        if not ten.inertia > 0:
            raise SceneError("tensioner.inertia", "must be > 0 in a transient (the arm's "
                             "moment of inertia about its pivot, kg m^2, its pulley's mass "
                             "included)")
        table = arm_table(P)
        rest, _ = rest_angle(P, table)
        if abs(rest) > 0.5 * TRAVEL:  # the table reaches round the rest angle too
            table = arm_table(P, rest)
            rest, _ = rest_angle(P, table)
        self.arm, self.arm_rest = table, rest
        ng = self.n_globals
        self.n_globals = ng + 2
        self.mesh = with_arm(self.mesh._replace(inertia=np.append(self.mesh.inertia,
                                                                  [1.0, ten.inertia])),
                             self.grid, ten.index, len(P.pulleys), ng, table,
                             (ten.stiffness, ten.preload, ten.damping))
        d = self.drive
        self.drive = d._replace(load=Profiles.of(
            [d.load.profile(k) for k in range(ng)] + [Profile.constant(0.0)] * 2))
        # the arm's scales: the turn that takes up the belt's stretch (its length times
        # the installation strain over the arm's length), that turn at the driver's speed,
        # and the spring's torque over it
        arm_length = ten.arm(P.layout)[0]
        turn = P.layout.loop_length * P.N0 / P.b1 / arm_length
        rate = turn * P.omega1
        sc = self.scales
        self.scales = sc._replace(glob=np.append(sc.glob, [turn, rate]),
                                  gres=np.append(sc.gres, [rate, P.N0 * arm_length]))

    def new_state(self) -> State:
        """The belt at rest: with a tensioner's arm, the arm settled at its rest angle and
        the belt's tension uniform (its spans' stretch taken up by u)."""
        state = super().new_state()
        if self.arm is None:
            return state
        from ..physics.arm import element_stretches

        P, m = self.params, self.mesh
        state.g[m.arm_idx[0]] = self.arm_rest
        e = element_stretches(m, state.g)
        # uniform strain N_s / b1: u_x = (N_s - N0) / b1 - e, periodic with zero mean
        ux = np.sum(e * m.he) / P.layout.loop_length - e
        u = np.concatenate([[0.0], np.cumsum(ux * m.he)[:-1]])
        state.u[:] = u - np.sum(m.hb * u) / P.layout.loop_length
        return state

    @property
    def window(self) -> float:
        """The loop's transit time (s): how long the belt takes once round it."""
        return self.params.layout.loop_length / self.params.driver_rim_speed

    def steady_drive(self, s: float = 1.0) -> Drive:
        """The final rim speed and loads (``s`` is the open layout's continuation)."""
        P = self.params
        return Drive.constant(P.driver_rim_speed,
                              (0.0, *(p.final_load for p in P.pulleys if p.role != "driver")))

    def with_grid(self, grid: LoopGrid) -> LoopDiscretisation:
        """The same drive on another grid."""
        return LoopDiscretisation(self.scene, grid, arm=self.arm is not None)


def _arm_reference(scene):
    """A drive scene with a tensioner, its arm turned to where the grid of a transient is
    laid: the exact steady state's rest angle (the creep theory's where the model has
    none), so that the run's own rest angle, near it, is read on that geometry; the
    drawn angle where the drive has no steady state (a run into gross slip)."""
    data = scene.to_dict()
    data.pop("numerics", None)  # the exact state is the physics'
    key = repr(data)
    if key not in _REST_TRAVEL:
        if len(_REST_TRAVEL) >= 16:
            _REST_TRAVEL.pop(next(iter(_REST_TRAVEL)))
        _REST_TRAVEL[key] = _rest_travel(scene.params)
    travel = _REST_TRAVEL[key]
    return scene if travel is None else scene.at_arm(travel - scene.params.arm_turn)


#: the exact rest angles of the last scenes' physics (the beam's arm search takes seconds)
_REST_TRAVEL: dict[str, float | None] = {}


def _rest_travel(P) -> float | None:
    """The exact rest angle's turn from the drawn angle (rad; None without a steady
    state)."""
    from ..beltdrive.exact import exact_state, string_state
    from ..errors import NoSolutionError

    for solve in (exact_state, string_state):
        try:
            return solve(P).arm_travel
        except NoSolutionError:
            continue
    return None


def discretise(scene, grid=None) -> Discretisation:
    """A scene on its grid: a straight belt's open layout, or a closed drive's loop."""
    from ..beltdrive.scene import DriveScene

    if isinstance(scene, DriveScene):
        return LoopDiscretisation(scene, grid)
    return Discretisation(scene, grid)


class Scheme:
    """A way to take a discretisation from rest to steady state.

    Transient schemes advance the state through simulated time in chunks between
    the controller's checks; a non-transient scheme (``transient = False``) solves
    the steady equations at once in :meth:`solve`.
    """

    name: ClassVar[str]
    transient: ClassVar[bool] = True
    #: whether the path through time is the scene's (to a controlled error), not only the end
    time_accurate: ClassVar[bool] = True
    #: whether numerics.acceleration (a damping that only speeds the approach) applies
    accelerated: ClassVar[bool] = False
    needs_inertia: ClassVar[bool] = False
    #: whether it runs closed layouts (loops) too
    closed: ClassVar[bool] = True

    def __init__(self, disc: Discretisation):
        self.disc = disc
        self.numerics = disc.numerics  # a scheme may settle some of them (the explicit dt)
        self.steps = 0

    def warm_up(self, state: State) -> float:
        """Compile the kernels (or load them from numba's cache); returns the seconds."""
        start = time.perf_counter()
        self._compile(state)
        return time.perf_counter() - start

    def _compile(self, state: State) -> None:
        # a transient scheme compiles its kernel by advancing zero steps
        self.advance(state, 0.0, 0.0, max_steps=0)

    def advance(self, state: State, t: float, t_stop: float, max_steps: int = 10**9) -> float:
        """Step from t until t_stop; returns the new time. Raises NumericalError."""
        raise NotImplementedError

    def solve(self, state: State) -> None:
        """Non-transient schemes: the steady state, in place. Raises NumericalError."""
        raise NotImplementedError

    @property
    def dt(self) -> float:
        """The step a transient scheme takes next (nan for non-transient ones)."""
        return float("nan")

    def statistics(self) -> dict:
        """Counters of the work done so far (steps, Newton iterations, ...)."""
        return {"steps": self.steps}

    def checkpoint(self) -> dict:
        """What a resumed run needs to continue exactly as this scheme would."""
        return {"steps": np.array(self.steps)}

    def restore(self, data: dict) -> None:
        """Take back what :meth:`checkpoint` returned."""
        self.steps = int(data["steps"])
