"""Typed sections of a scene, for building one in Python.

Each class is one table of a scene file, with the file's key names and SI units::

    import dataclasses

    import beltsim
    from beltsim import Beam, Contact, Motion, NumericsSection, Physics

    scene = beltsim.Scene.build(
        beam=Beam(length=1.0, height=0.1, width=0.1, youngs_modulus=5e7,
                  poisson_ratio=0.45, density=1500.0, shear_factor=1.1),
        motion=Motion(belt_speed=120.0, surface_speed=121.2),
        contact=Contact(start=1 / 3, end=2 / 3, friction="coulomb", max_friction=1e5),
        physics=Physics(inertia=True, damping=39.0),
        numerics=NumericsSection(elements=300),
    )
    stiffer = scene.replace(contact=dataclasses.replace(scene.contact, max_friction=2e5))

A field left at ``None`` is a key the scene does not set: the scene file would not
name it and its default applies. The sections do not check their values; a scene
does, when it is built (:meth:`beltsim.Scene.build`, :meth:`beltsim.Scene.replace`),
with the same rules and one-line :class:`~beltsim.errors.SceneError` messages as a
file, because it hands the same dictionary to the one validator
(:func:`beltsim.problem.validation.validate`).

The drive's quantities (``Motion.surface_speed``, ``Contact.max_friction``) are
profiles: a number, a table of ``(time, value)`` rows (linear between rows, held
outside them) or a :class:`Sine`.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

SINE_FIELDS = ("mean", "amplitude", "period")


@dataclass(frozen=True)
class Sine:
    """A periodic profile, ``mean + amplitude sin(2 pi t / period)``.

    Parameters
    ----------
    mean : float
        The mean value (the unit of the quantity it drives).
    amplitude : float
        The amplitude; ``mean - |amplitude|`` must stay > 0.
    period : float
        The period (s), > 0. Two sines in one scene share it.

    Examples
    --------
    >>> Motion(belt_speed=120.0, surface_speed=Sine(mean=121.2, amplitude=0.6, period=0.02))
    Motion(belt_speed=120.0, surface_speed=Sine(mean=121.2, amplitude=0.6, period=0.02))
    """

    mean: float
    amplitude: float
    period: float


#: A number, rows ``((t0, v0), (t1, v1), ...)`` with increasing times, or a sine.
Profile = float | tuple[tuple[float, float], ...] | Sine


def _profile(value):
    """A profile in the sections' form: rows as a tuple of tuples, a sine table as a Sine.

    Anything else is left as it is, for the validator to name what is wrong with it.
    """
    if getattr(value, "ndim", 0) == 2:  # a numpy table of rows
        value = value.tolist()
    if isinstance(value, (list, tuple)):
        return tuple(tuple(row) if isinstance(row, (list, tuple)) else row for row in value)
    if isinstance(value, dict) and set(value) == set(SINE_FIELDS):
        return Sine(**value)
    return value


def _plain(value):
    """A value as the scene dictionary holds it: lists for rows, a table for a sine,
    Python numbers for numpy scalars."""
    if isinstance(value, Sine):
        return {k: _plain(getattr(value, k)) for k in SINE_FIELDS}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if hasattr(value, "item") and getattr(value, "shape", None) == ():
        return value.item()  # a numpy scalar, e.g. from np.linspace
    return value


class Section:
    """What every section shares: its table, and dictionary-style reads of the keys set."""

    #: the section's name in a scene file, ``[name]``
    section = ""

    def to_dict(self) -> dict:
        """The keys this section sets (fields not None), as a scene file's table.

        Returns
        -------
        dict
            ``{key: value}`` with profiles as lists of ``[time, value]`` rows or
            ``{mean, amplitude, period}`` tables.
        """
        return {f.name: _plain(getattr(self, f.name)) for f in dataclasses.fields(self)
                if getattr(self, f.name) is not None}

    def get(self, key: str, default=None):
        """The value of ``key`` if this section sets it, else ``default`` (as ``dict.get``).

        Parameters
        ----------
        key : str
            A key of the section, e.g. ``"elements"``.
        default
            What to return when the key is not set.
        """
        value = getattr(self, key) if key in self.__dataclass_fields__ else None
        return default if value is None else value

    def __contains__(self, key: str) -> bool:
        """True when the section sets ``key`` (a field that is not None)."""
        return self.get(key) is not None

    def __repr__(self):
        # the keys set, as a scene file would show them
        keys = ", ".join(f"{f.name}={getattr(self, f.name)!r}" for f in dataclasses.fields(self)
                         if getattr(self, f.name) is not None)
        return f"{type(self).__name__}({keys})"


@dataclass(frozen=True, repr=False)
class Beam(Section):
    """The belt's geometry and material, ``[beam]``.

    Parameters
    ----------
    length : float
        L (m), the length of the span.
    height : float
        h (m), the belt's thickness; the bottom fibre at -h/2 touches the surface.
    width : float
        w (m).
    youngs_modulus : float
        E (Pa).
    poisson_ratio : float
        nu, in the open interval (-1, 0.5).
    shear_factor : float
        k, the shear correction factor of b2 = k E w h / (2 (1 + nu)).
    density : float, optional
        (kg/m^3); needed with inertia unless [stiffness] gives mass and rotary_inertia.
    """

    section = "beam"
    length: float
    height: float
    width: float
    youngs_modulus: float
    poisson_ratio: float
    shear_factor: float
    density: float | None = None


@dataclass(frozen=True, repr=False)
class Motion(Section):
    """The belt's speed and the surface's, ``[motion]``.

    Parameters
    ----------
    belt_speed : float
        c (m/s), the axial speed of the belt; with inertia below both critical speeds.
    surface_speed : Profile
        v (m/s), the speed of the surface in contact: a number, ``(time, value)`` rows
        or a :class:`Sine`. Lists of lists are stored as tuples of tuples.
    """

    section = "motion"
    belt_speed: float
    surface_speed: Profile

    def __post_init__(self):
        object.__setattr__(self, "surface_speed", _profile(self.surface_speed))


@dataclass(frozen=True, repr=False)
class Contact(Section):
    """The contact zone and its friction, ``[contact]``.

    Parameters
    ----------
    start : float
        x1 (m), with 0 < x1 < x2.
    end : float
        x2 (m), with x2 < L.
    friction : str
        ``"stick"`` (perfect adhesion) or ``"coulomb"`` (stick and slip).
    max_friction : Profile, optional
        f* (N/m), the friction limit of a ``"coulomb"`` contact (required there, refused
        in a ``"stick"`` one): a number, ``(time, value)`` rows or a :class:`Sine`.
    """

    section = "contact"
    start: float
    end: float
    friction: str
    max_friction: Profile | None = None

    def __post_init__(self):
        object.__setattr__(self, "max_friction", _profile(self.max_friction))


@dataclass(frozen=True, repr=False)
class Physics(Section):
    """Which terms the model has, ``[physics]``.

    Parameters
    ----------
    inertia : bool
        True for the dynamic model, False for the quasistatic one.
    damping : float, optional
        d (1/s), viscous damping d rho u_t, d I theta_t of the local rates (default 0;
        ignored without inertia).
    """

    section = "physics"
    inertia: bool
    damping: float | None = None


@dataclass(frozen=True, repr=False)
class Stiffness(Section):
    """Stiffness and inertia per unit length, overriding those derived from [beam],
    ``[stiffness]`` (optional).

    Parameters
    ----------
    bending : float, optional
        a (N m^2), default E w h^3 / 12.
    tension : float, optional
        b1 (N), default E w h.
    shear : float, optional
        b2 (N), default k E w h / (2 (1 + nu)).
    mass : float, optional
        rho (kg/m), default density h w (with inertia only).
    rotary_inertia : float, optional
        I (kg m), default density h w (h^2 + w^2) / 12 (with inertia only).
    """

    section = "stiffness"
    bending: float | None = None
    tension: float | None = None
    shear: float | None = None
    mass: float | None = None
    rotary_inertia: float | None = None


@dataclass(frozen=True, repr=False)
class NumericsSection(Section):
    """The numerical keys a scene sets, ``[numerics]`` (optional; every key has a default).

    This is the scene's table, with only what the user chose (None: the default
    applies). It is not :class:`beltsim.solvers.settings.Numerics`, the settings a run
    uses, resolved from this section with every default filled in
    (:func:`beltsim.solvers.settings.resolve`, ``RunResult.numerics``); the two names
    differ so that neither is taken for the other.

    Parameters
    ----------
    integrator : str, optional
        A registered scheme: ``"esdirk3"`` (default), ``"implicit"``, ``"explicit"``,
        ``"pseudo"``, ``"steady"``.
    elements : int, optional
        Number of elements (at least 6).
    grading : float, optional
        Largest over smallest element (>= 1).
    dt : float, optional
        Time step (s): the first (implicit), nominal (pseudo) or requested (explicit).
    t_end : float, optional
        Simulated time (s) at which a run that is not steady stops.
    ramp_time : float, optional
        Duration (s) of the smooth start-up from v = c.
    regularisation : float, optional
        v_reg (m/s) of a regularised coulomb law.
    friction_law : str, optional
        ``"tanh"``, ``"sqrt"``, ``"ramp"`` or ``"exact"``.
    adhesion_layer : float, optional
        delta (m) of a stick scene's regularised adhesion.
    acceleration : float, optional
        Numerical damping (1/s) of the pseudo-transient scheme (with inertia).
    time_tol : float, optional
        Local error per step of the implicit scheme (relative).
    steady_tol : float, optional
        Relative tolerance of the steady-state test.
    snapshot_interval : float, optional
        Simulated seconds between stored states.
    newton_tol : float, optional
        Newton's tolerance (scaled max norm of the update).
    newton_max_iterations : int, optional
        Newton iterations per step before the step is cut.
    max_work : float, optional
        The explicit scheme's most node-steps before it refuses a run.
    gyroscopic : str, optional
        The gyroscopic term's form: ``"upwind"`` (default; first order, damps the spans'
        modes numerically) or ``"central"`` (second order, no numerical damping;
        implicit schemes only).
    transient : str, optional
        ``"fast"`` (default: the quickest way to the steady state) or ``"physical"``
        (the central form and a step limit from the spectrum, so that the scheme damps
        the least stable mode by at most a tenth of its rate; esdirk3 or implicit).
    """

    section = "numerics"
    integrator: str | None = None
    elements: int | None = None
    grading: float | None = None
    dt: float | None = None
    t_end: float | None = None
    ramp_time: float | None = None
    regularisation: float | None = None
    friction_law: str | None = None
    adhesion_layer: float | None = None
    acceleration: float | None = None
    time_tol: float | None = None
    steady_tol: float | None = None
    snapshot_interval: float | None = None
    newton_tol: float | None = None
    newton_max_iterations: int | None = None
    max_work: float | None = None
    gyroscopic: str | None = None
    transient: str | None = None


#: The section classes by their names in a scene file, in the file's order.
SECTIONS: dict[str, type[Section]] = {cls.section: cls for cls in (
    Beam, Motion, Contact, Physics, Stiffness, NumericsSection)}
