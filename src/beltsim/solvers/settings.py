"""Resolved numerical settings: the scene's [numerics] with scene-dependent defaults.

:func:`resolve` fills every key a scene leaves out; the keys, their rules and their
defaults are listed in the user guide (docs/user-guide/scenes.md, "[numerics]"). The
defaults are chosen as follows (the theory pages say why, the verification pages show
the errors they give):

* the grid: ``DEFAULT_ELEMENTS`` elements, or ``ELEMENTS_PER_LAYER`` per decay length
  of theta where that is shorter than the paper's, graded ``DEFAULT_GRADING`` towards
  x2 and the expected slip start (docs/theory/discretisation.md, "The grid");
* the regularisation (``regularisation``, ``adhesion_layer``) shrinks with the grid's
  error on grids finer than the default, so its own first-order error stays a fixed
  fraction of the grid's (docs/theory/friction.md);
* ``time_tol`` keeps the paper slip history within 1e-3 of a converged one
  (docs/theory/time-schemes.md);
* ``max_work`` refuses, before it starts, an explicit run whose estimated work (steps
  times nodes) exceeds it; the message quotes the estimate and points to the implicit
  scheme.

Every grid is first checked against the machine's available memory (MEMORY_PER_NODE
bytes a node, the largest a scheme needs at its peak, with a margin): an oversized grid
is refused before anything is allocated.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

from ..errors import SceneError
from ..physics.discrete import GYROSCOPIC_FORMS
from ..physics.friction import AUGMENTATION, LAW_CODES, is_exact
from ..physics.grid import Grid, make_grid
from ..problem import analytic
from ..problem.analytic import decay_rates
from ..problem.drive import (
    largest_mismatch,
    period_of,
    profile_times,
    scene_profiles,
    speed_ramped,
)
from ..problem.scene import Scene
from ..problem.validation import Params
from . import registry

DEFAULT_ELEMENTS = 600
DEFAULT_GRADING = 5.0
# default elements per L / l_min, l_min the shortest decay length of theta (1/beta in
# free segments, 1/alpha in stick): 10 resolves the paper's 17 mm layer as the default
# elements do, and thinner layers as well
ELEMENTS_PER_LAYER = 10.0
#: The default scheme (third-order ESDIRK: the same path error as BDF2 in about half the
#: wall time) and each time-accurate scheme's default local error per step, chosen so
#: that the paper slip history's time error stays within 1e-3 (validation page "paths")
DEFAULT_INTEGRATOR = "esdirk3"
TIME_TOLS = {"esdirk3": 2e-5, "implicit": 6e-6}
DEFAULT_TIME_TOL = TIME_TOLS[DEFAULT_INTEGRATOR]
#: Newton iterations of a step before it is cut, by friction law: the exact laws' semi-smooth
#: iteration damps a cycling stick/slip pattern (solvers.newton.CYCLE_ITERATIONS) and needs
#: more (a quasistatic string drive's start-up: 60 left steps that cycle at every size,
#: 100 converged)
NEWTON_ITERATIONS = 30
EXACT_NEWTON_ITERATIONS = 100
#: the first step of an adaptive scheme (the fixed step of the pseudo-transient one): this
#: fraction of the ramp time or the transit time, whichever is longer
FIRST_STEPS = 50.0
MIN_MISMATCH = 1e-8  # smallest nonzero |v/c - 1| a run accepts
DEFAULT_MAX_WORK = 2e10  # node-steps of an explicit run
EXPLICIT_RATE = 8e7  # node-steps per second of the explicit kernel (bench), for messages
EXPLICIT_LOOP_RATE = 2e7  # the same on a loop (drive_flat, 800 elements: 2.0-2.6e7)
MEMORY_PER_NODE = 600  # bytes a grid node costs a run at its peak
MIN_REGULARISATION = 1e-12  # smallest regularisation velocity, relative to c
DEFAULT_ADHESION_LAYER = 1e-6  # delta / L
# Smallest factor on the default v_reg and delta as the grid is refined (reached at 10
# times the default elements): a stiffer adhesion law leaves the concentrated force at
# Newton's round-off floor
MIN_REFINE = 1e-2


@dataclass(frozen=True)
class Numerics:
    """The numerical settings of a scene with every default resolved (:func:`resolve`)."""

    integrator: str
    elements: int
    grading: float
    dt: float
    t_end: float
    ramp_time: float
    friction_law: str  # the scene key's law, or the stick scene's linear/adhesion
    regularisation: float  # the friction law's velocity scale: v_reg, v_aug (exact), 1 (linear)
    friction_scale: float  # f_s in f = -f_s g(v_rel / v_reg)
    acceleration: float  # numerical damping (1/s) of the pseudo-transient scheme
    steady_tol: float
    snapshot_interval: float | None
    newton_tol: float = 1e-9
    newton_max_iterations: int = NEWTON_ITERATIONS
    time_tol: float = DEFAULT_TIME_TOL
    max_work: float = DEFAULT_MAX_WORK
    settle_time: float = 0.0  # when the drive stops changing (steady tests start there)
    gyroscopic: str = "upwind"  # the gyroscopic term's form (physics.discrete.GYROSCOPIC_FORMS)
    #: "fast" or "physical" (the central form, and steps that resolve the least stable mode)
    transient: str = "fast"

    @property
    def gyro_code(self) -> int:
        """The gyroscopic form's code as the kernels read it."""
        return GYROSCOPIC_FORMS[self.gyroscopic]

    @property
    def law_code(self) -> int:
        """The friction law's code as the kernels read it (``physics.friction.LAW_CODES``)."""
        return LAW_CODES[self.friction_law]


def resolve(scene: Scene, elements: int | None = None) -> Numerics:
    """The scene's numerical settings with their defaults; ``elements`` stands for
    numerics.elements (a grid given apart, e.g. a bisected one)."""
    P = scene.params
    nm = scene.numerics
    if elements is None:
        elements = nm.get("elements", default_elements(P))
    check_memory(elements)
    # the regularisation's own error (first order in v_reg or delta) shrinks with the
    # grid's, as h^2, on grids finer than the default, down to MIN_REFINE
    refine = min(1.0, max(MIN_REFINE, (default_elements(P) / elements) ** 2))
    transit = P.L / P.c
    ramp_time = nm.get("ramp_time", 2.0 * transit)
    dt = nm.get("dt", max(ramp_time, transit) / FIRST_STEPS)
    t_end = nm.get("t_end", settle_time(scene, ramp_time) + 400.0 * transit)
    if dt > t_end:
        raise SceneError("numerics.dt", f"must be <= numerics.t_end = {t_end!r}, got {dt!r}")
    integrator = nm.get("integrator", DEFAULT_INTEGRATOR)
    reason = registry.applicable(integrator, P.inertia)  # unknown names raise here
    if reason:
        raise SceneError(reason)
    if 0.0 < abs(P.e0) < MIN_MISMATCH:
        raise SceneError(
            "motion.surface_speed", f"|v/c - 1| = {abs(P.e0):.3g} is below {MIN_MISMATCH:g} "
            f"but not 0: in double precision v - c then carries a round-off of "
            f"{2.2e-16 / abs(P.e0):.1%} and the friction law cannot resolve it; use v = c "
            f"for the zero state")
    dv = abs(P.v - P.c)
    if dv == 0.0 or period_of(scene) is not None:
        dv = largest_mismatch(scene)
    default_regularisation = 1e-4 * dv if dv > 0 else 1e-6 * P.c
    if nm.get("friction_law") == "exact":
        # v_aug: the augmentation velocity, numerical only (physics.friction). For
        # adhesion f_s makes f_s / v_aug the default adhesion layer's slope B / (c delta)
        regularisation = AUGMENTATION * default_regularisation
        if P.friction == "coulomb":
            law, friction_scale = "exact", P.fstar
        else:
            law = "adhesion"
            friction_scale = P.B * regularisation / (P.c * DEFAULT_ADHESION_LAYER * P.L)
    elif P.friction == "coulomb":
        regularisation = nm.get("regularisation", max(default_regularisation * refine,
                                                      MIN_REGULARISATION * P.c))
        law, friction_scale = nm.get("friction_law", "tanh"), P.fstar
        if regularisation < MIN_REGULARISATION * P.c:
            raise SceneError("numerics.regularisation",
                             f"must be >= {MIN_REGULARISATION:g} c = "
                             f"{MIN_REGULARISATION * P.c:.3g} m/s (below it slip velocities "
                             f"drown in round-off), got {regularisation!r}")
    else:
        delta = nm.get("adhesion_layer", DEFAULT_ADHESION_LAYER * P.L * refine)
        law, regularisation = "linear", 1.0
        friction_scale = P.B / (P.c * delta)
    acceleration = acceleration_of(nm, integrator, P.inertia, math.pi * P.B / (
        P.L * math.sqrt(P.rho * P.b1)) if P.inertia else 0.0)
    transient, gyroscopic = transient_of(nm, integrator)
    if "max_work" in nm and integrator != "explicit":
        raise SceneError("numerics.max_work", 'only for numerics.integrator = "explicit" (the '
                         "other schemes' steps adapt)")
    return Numerics(
        integrator=integrator,
        elements=elements,
        grading=nm.get("grading", DEFAULT_GRADING),
        dt=dt, t_end=t_end, ramp_time=ramp_time, friction_law=law,
        regularisation=regularisation,
        friction_scale=friction_scale,
        acceleration=acceleration, steady_tol=nm.get("steady_tol", 1e-6),
        snapshot_interval=nm.get("snapshot_interval"),
        newton_tol=nm.get("newton_tol", 1e-9),
        newton_max_iterations=newton_iterations(nm, law),
        time_tol=nm.get("time_tol", TIME_TOLS.get(integrator, DEFAULT_TIME_TOL)),
        settle_time=settle_time(scene, ramp_time),
        max_work=nm.get("max_work", DEFAULT_MAX_WORK),
        gyroscopic=gyroscopic, transient=transient,
    )


#: The schemes a physical transient takes: adaptive, implicit, with the central form
PHYSICAL_SCHEMES = ("esdirk3", "implicit")


def transient_of(nm: dict, integrator: str, closed: bool = False) -> tuple[str, str]:
    """(numerics.transient, numerics.gyroscopic) with their defaults: a physical transient
    takes the central form, and one of PHYSICAL_SCHEMES; a straight belt's only (its step
    limit comes from the exact spectrum, which a closed drive does not have)."""
    transient = nm.get("transient", "fast")
    gyroscopic = nm.get("gyroscopic", "upwind")
    if transient == "physical":
        if closed:
            raise SceneError("numerics.transient", '"physical" is for a straight belt: its '
                             "step limit comes from the exact spectrum, and a drive has only "
                             "the discrete one (beltsim modes)")
        if "gyroscopic" in nm and gyroscopic != "central":
            raise SceneError("numerics.gyroscopic", 'must be "central" with '
                             'numerics.transient = "physical" (the upwind form damps the '
                             "spans' modes)")
        if integrator not in PHYSICAL_SCHEMES:
            raise SceneError("numerics.transient", '"physical" needs numerics.integrator '
                             f'= {" or ".join(repr(s) for s in PHYSICAL_SCHEMES)}, got '
                             f"{integrator!r}")
        gyroscopic = "central"
    return transient, gyroscopic


def acceleration_of(nm: dict, integrator: str, inertia: bool, omega1: float) -> float:
    """numerics.acceleration (1/s) with its default, twice the layout's lowest string
    frequency ``omega1``: a damping that speeds the approach of a scheme that does not
    follow the path (none elsewhere: a time-accurate run's damping is physics.damping)."""
    accelerated = registry.get(integrator).accelerated
    if "acceleration" in nm and not accelerated:
        allowed = " | ".join(f'"{n}"' for n in registry.names()
                             if registry.get(n).accelerated)
        raise SceneError("numerics.acceleration", f"only for numerics.integrator = {allowed} "
                         f"(the damping of a time-accurate run is physics.damping)")
    return nm.get("acceleration", 2.0 * omega1) if accelerated and inertia else 0.0


def newton_iterations(nm: dict, law: str) -> int:
    """numerics.newton_max_iterations with its default for the friction law ``law``."""
    return nm.get("newton_max_iterations", EXACT_NEWTON_ITERATIONS
                  if is_exact(LAW_CODES[law]) else NEWTON_ITERATIONS)


def available_memory() -> float | None:
    """Bytes the system can give a new allocation (MemAvailable), None where unknown."""
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024.0
    except OSError:
        pass
    return None


def check_memory(elements: int) -> None:
    """Refuse a grid whose run would not fit in the available memory."""
    need, have = MEMORY_PER_NODE * (elements + 1.0), available_memory()
    if have is not None and need > have:
        raise SceneError("numerics.elements", f"{elements} elements need about {need / 2**30:.3g} "
                         f"GiB ({MEMORY_PER_NODE} bytes a node), more than the "
                         f"{have / 2**30:.3g} GiB this machine has available")


def settle_time(scene: Scene, ramp_time: float) -> float:
    """When the drive stops changing (for a periodic drive, when its ramp ends): the
    steady-state test starts there."""
    times = profile_times(scene)
    return max(ramp_time if speed_ramped(scene) else 0.0, times[-1] if times else 0.0)


def default_elements(P: Params) -> int:
    """DEFAULT_ELEMENTS, or more when the scene's boundary layers are thinner than the paper's."""
    alpha, beta = decay_rates(P)
    return max(DEFAULT_ELEMENTS, math.ceil(ELEMENTS_PER_LAYER * P.L * max(alpha, beta)))


def build_grid(scene: Scene, num: Numerics) -> Grid:
    """The scene's grid: ``num.elements`` graded towards x2 and the expected slip start."""
    P = scene.params
    return make_grid(P.L, P.x1, P.x2, num.elements, num.grading,
                     refine_at=expected_slip_start(scene))


def expected_slip_start(scene: Scene) -> tuple:
    """Where the friction jumps to f* at steady state (x1 when the whole contact
    slides), from the analytic solution: the grid is graded towards it as towards x2.
    Empty for stick scenes, periodic drives and scenes without an analytic solution."""
    P = scene.params
    if P.friction != "coulomb" or period_of(scene) is not None:
        return ()
    try:
        x_star = analytic.solve(scene).x_star
    except analytic.NoSolutionError:
        return ()
    return () if x_star is None or x_star >= P.x2 else (float(x_star),)


#: A loop's default elements, and its regularised laws' default v_reg in units of the
#: creep speed (sharper ones stall Newton; the exact law, the default, has none)
LOOP_ELEMENTS = 800
LOOP_REGULARISATION = 0.1
#: a loop's default local error per step: the same norm and scales' rule as an open
#: layout's, and the same path target (a start-up within 1e-3 of a time-refined run).
#: drive_flat's esdirk3 path at 1e-2 is within 6e-5 of a run at 1e-6 (tensions; speeds
#: 8e-6) in 397 steps; at 1e-3, 1e-5 in 1,066; at 1e-1, 3.4e-4 in 131
LOOP_TIME_TOLS = {"esdirk3": 1e-2, "implicit": 1e-3}
#: transits after the drive stops changing before a loop's run ends unsettled: a heavy
#: driven pulley on short spans (random drive 14 of seed 1: J2 = 0.18 kg m^2, 0.15 m
#: between centres) settles after 44 (esdirk3) under the exact law, whose Coulomb
#: friction damps its rotational oscillation weakly
LOOP_END_TRANSITS = 100.0


#: the share of the driver's torque reserve (its capacity less its rated torque) that the
#: pulleys' inertia may take in a default start-up
RAMP_RESERVE = 0.5


@functools.lru_cache(maxsize=64)
def inertial_ramp(scene) -> float:
    """The shortest default start-up (s) whose inertial torque at the driver stays within
    RAMP_RESERVE of its torque reserve at the rated loads: the pulleys' inertia reflected
    to the driver, sum J_i (r_d / r_i)^2, times the smoothstep's steepest acceleration
    15/8 omega_d / t_ramp. A faster start slides over the driver's whole wrap (the
    accessory drive: 26 N m of inertial torque against a 16 N m reserve in 0.31 s, and
    1,295 steps instead of 157). 0 with perfect adhesion or a reserve that cannot be
    found (gross slip: the run reports it)."""
    from ..beltdrive.exact import string_state
    from ..errors import NoSolutionError

    P = scene.params
    if P.mu is None:
        return 0.0
    try:
        sol = string_state(P)
        if P.two_pulley:  # the closed form's capacity
            from ..beltdrive.analytic import capacity

            margin = capacity(P) / P.M2 if P.M2 > 0 else math.inf
        else:
            margin = float(sol.slip_margin(P.driver))
    except NoSolutionError:
        return 0.0
    rd = P.pulleys[P.driver].radius
    torque = sol.driver_torque
    if not math.isfinite(margin) or torque <= 0:
        return 0.0
    reflected = sum(p.inertia * (rd / p.radius) ** 2 for p in P.pulleys)
    reserve = RAMP_RESERVE * (margin - 1.0) * torque
    return 1.875 * P.omega1 * reflected / reserve


def resolve_loop(scene, elements: int | None = None) -> Numerics:
    """A closed drive's numerical settings with their defaults (the same keys and
    meanings as an open layout's; the scales are the loop's: its transit time, the creep
    speed omega_1 R_1 N0 / b1 of the slip velocities)."""
    from ..beltdrive.analytic import creep_speed, transit_time

    P, nm = scene.params, scene.numerics
    if elements is None:
        elements = nm.get("elements", LOOP_ELEMENTS)
    check_memory(elements)
    integrator = nm.get("integrator", DEFAULT_INTEGRATOR)
    reason = registry.applicable(integrator, P.inertia, closed=True)
    if reason:
        raise SceneError(reason)
    transit = transit_time(P)
    ramp_time = nm.get("ramp_time", max(2.0 * transit, inertial_ramp(scene)))
    settle = max([ramp_time, *(v[-1][0] for v in scene_profiles(scene)
                               if isinstance(v, list))])
    dt = nm.get("dt", max(ramp_time, transit) / FIRST_STEPS)
    steady_tol = nm.get("steady_tol", 1e-7)
    # a lightly damped belt rings for longer than the transits allow: its modes decay at
    # d / 2, and ln(1 / steady_tol) / (d / 2) is how long that takes (random drive 18 of
    # seed 1, d = 6.6 1/s at 54 m/s: steady at t = 6.0 s, 230 transits); twice that
    ringing = 4.0 * math.log(1.0 / steady_tol) / P.damping if P.damping > 0 else 0.0
    t_end = nm.get("t_end", settle + max(LOOP_END_TRANSITS * transit, ringing))
    if dt > t_end:
        raise SceneError("numerics.dt", f"must be <= numerics.t_end = {t_end!r}, got {dt!r}")
    if "max_work" in nm and integrator != "explicit":
        raise SceneError("numerics.max_work", 'only for numerics.integrator = "explicit" (the '
                         "other schemes' steps adapt)")
    transient, gyroscopic = transient_of(nm, integrator, closed=True)
    creep = creep_speed(P)
    # the lowest string frequency of the longer free span (pi sqrt(N0 / rho) / l)
    omega1 = math.pi * math.sqrt(P.N0 / P.rho) / max(P.layout.spans) \
        if P.rho > 0.0 else 0.0
    friction_scale = 1.0
    if P.mu is None:
        # adhesion's reaction, scaled as the pretension's pressure on the driver
        law, regularisation = "adhesion", creep
        friction_scale = P.N0 / P.pulleys[P.driver].radius
    else:
        law = nm.get("friction_law", "exact")
        regularisation = (creep if law == "exact" else
                          nm.get("regularisation", LOOP_REGULARISATION * creep))
    return Numerics(
        integrator=integrator, elements=elements, grading=1.0, dt=dt, t_end=t_end,
        ramp_time=ramp_time, friction_law=law, regularisation=regularisation,
        friction_scale=friction_scale,
        acceleration=acceleration_of(nm, integrator, P.inertia, omega1),
        steady_tol=steady_tol,
        snapshot_interval=nm.get("snapshot_interval"),
        newton_tol=nm.get("newton_tol", 1e-9),
        newton_max_iterations=newton_iterations(nm, law),
        time_tol=nm.get("time_tol", LOOP_TIME_TOLS.get(integrator, DEFAULT_TIME_TOL)),
        settle_time=settle, max_work=nm.get("max_work", DEFAULT_MAX_WORK),
        gyroscopic=gyroscopic, transient=transient)
