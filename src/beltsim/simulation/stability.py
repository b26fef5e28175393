"""Whether a scene's steady state is stable in the model, and how much a run's scheme
damped its least stable mode.

A run reaches a steady state through the scheme's own damping as well as the model's:
the upwind gyroscopic term damps the span modes by tens to hundreds of 1/s, and
ESDIRK3 and BDF2 damp a mode whose period their steps do not resolve. So a converged
run is no proof that the state is stable (docs/theory/stability.md). Every inertial
run therefore reports the least stable eigenvalue of the model linearised about its
steady state:

* a straight belt with an exact steady state: the exact roots of the continuous
  model's characteristic determinant (:mod:`beltsim.physics.continuum`, no grid) up to
  ``BAND_HZ``; their chains run on above it with rates that do not decay, so the
  band is stated with the answer;
* otherwise (closed drives; straight scenes without an exact state): the discrete
  model's rightmost eigenvalue with the central (second-order, non-dissipative)
  gyroscopic form on the scene's grid, and its error estimated by the same on half
  the grid.

Both cost seconds, and depend only on the scene's data, so they are computed once per
scene and kept in the user's cache (:mod:`beltsim.io.cache`). When the least stable
mode grows, the run's numerical damping of it is estimated: the grid's, from the
run's own discrete model's eigenvalue nearest to it, and the time steps', from the
scheme's amplification factor over the run's last step.
"""

from __future__ import annotations

import math
import os
import sys
from dataclasses import asdict, dataclass

import numpy as np

from ..errors import BeltsimError
from ..io import cache
from ..problem.drive import period_of

#: The exact roots are searched up to this frequency (Hz): several times the paper's
#: slowest span modes, and the band the verification pages list
BAND_HZ = 3000.0
#: The environment variable that turns the check off ("0", "off", "no", "false")
SWITCH = "BELTSIM_STABILITY"
#: The cache entry's format; a change of it recomputes every entry
FORMAT = 2


@dataclass(frozen=True)
class Stability:
    """The least stable eigenvalue of a scene's model about its steady state.

    Attributes
    ----------
    rate : float
        Its real part (1/s): positive grows.
    frequency : float
        Its frequency (Hz).
    method : str
        How it was found: ``"exact"`` (the continuous model's roots up to ``band``) or
        ``"discrete"`` (the central form on ``elements``).
    band : float or None
        The exact search's upper frequency (Hz).
    elements : int or None
        The discrete estimate's grid.
    error : float or None
        The discrete estimate's error (1/s): its difference from the half grid's.
    growing : int
        How many roots in the band grow (exact), or 1 or 0 (discrete).
    modes : tuple of (float, float)
        (rate, frequency) of every growing root in the band, the least stable first; the
        least stable alone when none grows. A physical transient resolves them all.
        How many roots in the band grow (exact), or 1 or 0 (discrete).
    grid_damping, step_damping : float or None
        The run's numerical damping of that mode (1/s): its grid's (the exact rate minus
        the run's discrete eigenvalue's) and its time steps' (the discrete rate minus
        the rate the scheme's amplification over its last step gives). None where not
        estimated (a stable state, or a scheme that does not follow the path).
    """

    rate: float
    frequency: float
    method: str
    band: float | None = None
    elements: int | None = None
    error: float | None = None
    growing: int = 0
    modes: tuple = ()
    grid_damping: float | None = None
    step_damping: float | None = None

    @classmethod
    def from_dict(cls, data: dict) -> Stability:
        """The entry as ``dataclasses.asdict`` wrote it (a cache's JSON)."""
        return cls(**{**data, "modes": tuple(tuple(m) for m in data.get("modes", ()))})

    @property
    def resolved_modes(self) -> tuple:
        """What a physical transient resolves: ``modes``, or the least stable mode alone
        where they are not listed (a discrete estimate)."""
        return self.modes or ((self.rate, self.frequency),)

    @property
    def unstable(self) -> bool:
        """Whether the mode grows by more than the estimate's error."""
        return self.rate > (self.error or 0.0)

    @property
    def verdict(self) -> str:
        """``"unstable"``, ``"stable"``, or ``"undecided"`` (the rate within the estimate's
        error either way)."""
        if self.unstable:
            return "unstable"
        return "stable" if self.rate < -(self.error or 0.0) else "undecided"

    def describe(self) -> str:
        """One line: the verdict, the mode, how it was found."""
        how = (f"exact roots up to {self.band:g} Hz" if self.method == "exact" else
               f"discrete model, central form, {self.elements} elements, "
               f"error about {self.error:.2g} 1/s")
        if self.verdict == "unstable":
            return (f"unstable in the model: a mode at {self.frequency:.4g} Hz grows at "
                    f"{self.rate:.3g} 1/s ({how})")
        if self.verdict == "undecided":
            return (f"undecided: the least stable mode ({self.frequency:.4g} Hz) has rate "
                    f"{self.rate:+.3g} 1/s, within its estimate's error ({how})")
        return (f"stable in the model: the least stable mode ({self.frequency:.4g} Hz) "
                f"decays at {-self.rate:.3g} 1/s ({how})")

    def warning(self) -> str | None:
        """The run's one-line warning when the mode grows, else None."""
        if not self.unstable:
            return None
        text = (f"the steady state is unstable in the model: a mode at "
                f"{self.frequency:.4g} Hz grows at {self.rate:.3g} 1/s")
        parts = [(name, v) for name, v in (("grid", self.grid_damping),
                                           ("time steps", self.step_damping)) if v is not None]
        if parts:
            text += (f"; this run's scheme damps it by about {sum(v for _, v in parts):.3g} "
                     f"1/s ({', '.join(f'{name} {v:.3g}' for name, v in parts)})")
        text += '; numerics.transient = "physical" follows its growth'
        return text

    def to_dict(self) -> dict:
        """The fields, ``stable`` (None when undecided) and ``summary``
        (:meth:`describe`)."""
        stable = {"stable": True, "unstable": False}.get(self.verdict)
        return {**asdict(self), "stable": stable, "summary": self.describe()}


def enabled() -> bool:
    """Whether runs check their steady state's stability (``SWITCH``)."""
    return os.environ.get(SWITCH, "1").strip().lower() not in ("0", "off", "no", "false")


def applies(scene) -> bool:
    """An inertial scene that settles (no sine in its profiles)."""
    return bool(scene.params.inertia) and period_of(scene) is None


def physics_of(scene) -> dict:
    """The scene's data that its stability depends on: all but its title and numerics."""
    data = scene.to_dict()
    data.pop("title", None)
    data.pop("numerics", None)
    return data


def exact_least_stable(scene, notice=None) -> Stability:
    """The least stable exact root of a straight-belt scene with an exact steady state
    (``BAND_HZ``), from the cache or computed (then cached).

    Parameters
    ----------
    scene : Scene
        An inertial straight-belt scene that settles (:func:`applies`).
    notice : callable, optional
        ``notice(text)`` once before a computation of seconds (not for a cached one).

    Raises
    ------
    BeltsimError
        The scene has no exact steady state, or no root was found.
    """
    from ..physics import continuum

    key = cache.key_of("stability", [FORMAT, "exact", physics_of(scene)])
    found = cache.load(key)
    if found is not None:
        return Stability.from_dict(found)
    if notice is not None:
        notice(NOTICE)
    roots = continuum.characteristic(scene).roots(BAND_HZ)
    if roots.size == 0:
        raise BeltsimError(f"no eigenvalue found up to {BAND_HZ:g} Hz")
    lam = roots[0]
    growing = roots[roots.real > 0.0] if roots[0].real > 0.0 else roots[:1]
    out = Stability(rate=float(lam.real), frequency=float(lam.imag / (2 * math.pi)),
                    method="exact", band=BAND_HZ, growing=int(np.sum(roots.real > 0.0)),
                    modes=tuple((float(z.real), float(z.imag / (2 * math.pi)))
                                for z in growing))
    cache.store(key, asdict(out))
    return out


#: What a run prints before it computes a scene's spectrum
NOTICE = "checking whether the steady state is stable in the model (once per scene, a few seconds)"


# -- the schemes' damping of a mode ------------------------------------------------

def amplification(integrator: str, z: complex) -> complex | None:
    """The factor by which ``integrator`` multiplies the mode exp(lambda t) over one step
    h, z = lambda h (None for a scheme without one: explicit, steady, pseudo).

    ESDIRK3: its stability function 1 + z b^T (I - z A)^-1 1 (stiffly accurate: b is
    A's last row). BDF2 at constant steps: the root of largest modulus of
    (3/2 - z) xi^2 - 2 xi + 1/2 = 0.
    """
    if integrator == "esdirk3":
        from ..solvers.esdirk import TABLEAU_A

        A = TABLEAU_A.astype(complex)
        e = np.ones(A.shape[0], complex)
        return complex(1.0 + z * A[-1] @ np.linalg.solve(np.eye(A.shape[0]) - z * A, e))
    if integrator == "implicit":
        xi = np.roots([1.5 - z, -2.0, 0.5])
        return complex(xi[np.argmax(np.abs(xi))])
    return None


#: A physical transient's bound on its steps' damping of the least stable mode: this
#: fraction of the mode's rate (at least of 1 1/s)
PHYSICAL_DAMPING = 0.1


def step_damping(integrator: str, lam: complex, h: float) -> float | None:
    """The damping (1/s) of the mode exp(lambda t) by ``integrator``'s steps of h: the
    exact rate minus ``ln(abs(R(lambda h))) / h`` (None for a scheme without R)."""
    R = amplification(integrator, lam * h)
    if R is None:
        return None
    return lam.real - (math.log(abs(R)) / h if abs(R) > 0.0 else -math.inf)


def physical_step(found: Stability, integrator: str) -> float:
    """The longest step (s) at which ``integrator`` damps (or amplifies) each of
    ``found.modes`` (the growing roots in the band) by at most ``PHYSICAL_DAMPING`` of
    the least stable rate: the step limit of a physical transient
    (``numerics.transient = "physical"``)."""
    bound = PHYSICAL_DAMPING * max(abs(found.rate), 1.0)
    return min(_step_for(complex(r, 2 * math.pi * f), integrator, bound)
               for r, f in found.resolved_modes)


#: A physical transient's checks (its history's rows) per period of the highest growing
#: root of the band
SAMPLES_PER_PERIOD = 8


def physical_sampling(found: Stability) -> float:
    """A physical transient's check interval (s): ``SAMPLES_PER_PERIOD`` checks per period
    of the highest growing root in ``found.modes``, so that its history resolves them."""
    return 1.0 / (SAMPLES_PER_PERIOD * max(f for _, f in found.resolved_modes))


def _step_for(lam: complex, integrator: str, bound: float) -> float:
    """The longest step at which ``integrator`` damps the mode lam by at most ``bound``."""
    h = 1.0 / abs(lam)
    while abs(step_damping(integrator, lam, h)) > bound:  # the error falls as h^p
        h *= 0.5
    lo, hi = h, 2.0 * h
    for _ in range(40):
        mid = math.sqrt(lo * hi)
        lo, hi = (mid, hi) if abs(step_damping(integrator, lam, mid)) <= bound else (lo, mid)
    return lo


def stderr_notice(show: bool):
    """A ``notice`` for :func:`~beltsim.simulation.stability_check.check` that prints to
    stderr, or None when ``show`` is false (nobody watches)."""
    if not show:
        return None
    return lambda text: print(f"beltsim: {text}", file=sys.stderr, flush=True)


