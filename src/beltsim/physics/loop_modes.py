"""A closed drive's modes: the eigenvalues and mode shapes of its discrete model linearised
about its steady state (:mod:`beltsim.physics.modes`), read as the drive's rotational and
belt motion.

A mode y = y0 + z e^{lambda t} has its rate Re lambda (1/s; > 0 grows) and its frequency
Im lambda / (2 pi) (Hz); each conjugate pair is kept once (Im lambda > 0). Only the
modes that oscillate are listed, those with a damping ratio -Re lambda / abs(lambda) below
MAX_DAMPING_RATIO: the linearisation also has real and overdamped eigenvalues by the
hundred (the stuck nodes' penalty, a stiff dashpot, and the transport of the strain
frozen on the stuck arcs), with rates down to -1e10 1/s. All of them count for
``DriveModes.least_stable``. A mode's shape:

* each pulley's speed perturbation (a loop's speeds are first-order unknowns) and its
  rotation theta = speed / lambda, in the sense the belt turns the pulley (the driver's
  speed is prescribed: 0); :attr:`PulleyLayout.spin
  <beltsim.beltdrive.pulleys.PulleyLayout.spin>` tells that sense in the plane;
* the belt's axial displacement u along the loop coordinate (from the entry of the first
  pulley's arc, in the belt's direction), sampled at equal steps;
* a tensioner arm's turn beta (rad, into the belt; :mod:`beltsim.physics.arm`);

scaled so that the largest of abs(u), the pulleys' rim displacements abs(r theta) and
the arm's pulley centre's abs(a beta) is 1 and real positive. ``pulley_share`` is the
pulleys' and the arm's part of the mode's kinetic energy, sum J abs(speed)^2 over that
plus the belt's sum rho hbar_j abs(lambda u_j)^2 (the
Eulerian rate of u: the belt's transport of its perturbation is left out of this
measure).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import SceneError, UsageError
from .arm import element_stretches
from .modes import INFINITE, eigenpairs, linearisation, steady_discretisation
from .shift_invert import SWEEP_REACH, ShiftInvert, distinct, one_blas_thread, sweep

#: The grid when the scene sets none
DEFAULT_ELEMENTS = 200
#: The finest grid ``beltsim modes`` accepts (the sparse search's cost grows about as the
#: square of the grid)
MAX_ELEMENTS = 3200
#: Up to this many elements the spectrum is computed whole by the dense QZ algorithm
#: (``method="auto"``); its cost grows as the cube of the grid (6 s on 200 elements)
DENSE_ELEMENTS = 40
#: The dense method refuses grids beyond this (minutes and gigabytes)
MAX_DENSE_ELEMENTS = 800
#: Eigenvalues about 0 the sparse search asks for first when the sweep's disks hold too
#: few of the listed modes (doubled until the listing is complete)
FIRST_NEAREST = 48
#: Modes listed when neither a count nor a frequency bound is given
DEFAULT_COUNT = 10
#: Samples of the belt's displacement along the loop in a mode's shape
SAMPLES = 120
#: A mode more damped than this is not listed (it decays by exp(-3.6) over one period;
#: the penalty's and the transport's overdamped pairs have damping ratios near 1)
MAX_DAMPING_RATIO = 0.5


@dataclass(frozen=True)
class Mode:
    """One mode of the linearised drive: its eigenvalue and shape (see the module)."""

    eigenvalue: complex
    #: each pulley's (rotation (rad), speed perturbation (rad/s)), by name
    pulleys: dict
    #: the belt speed's perturbation (m/s)
    belt_speed: complex
    #: loop coordinate of the belt's samples (m) and u there (m)
    x: np.ndarray
    u: np.ndarray
    pulley_share: float
    #: what moves most: a pulley's name (its rim), "belt" or "arm" (a tensioner arm's
    #: pulley centre)
    largest: str
    #: a tensioner arm's turn (rad, into the belt), None without a moving arm
    arm: complex | None = None

    @property
    def frequency_hz(self) -> float:
        """Im lambda / (2 pi) (Hz)."""
        return self.eigenvalue.imag / (2.0 * math.pi)

    @property
    def rate(self) -> float:
        """Re lambda (1/s): > 0 grows."""
        return self.eigenvalue.real

    @property
    def damping_ratio(self) -> float:
        """-Re lambda / abs(lambda)."""
        return -self.eigenvalue.real / abs(self.eigenvalue)

    def to_dict(self) -> dict:
        """The mode as JSON-ready data (complex numbers as [real, imag])."""
        def pair(z):
            return [float(z.real), float(z.imag)]
        return {
            "frequency_hz": self.frequency_hz, "rate": self.rate,
            "damping_ratio": self.damping_ratio, "pulley_share": self.pulley_share,
            "largest": self.largest,
            "shape": {
                "pulleys": {name: {"rotation": pair(th), "speed": pair(w)}
                            for name, (th, w) in self.pulleys.items()},
                "belt_speed": pair(self.belt_speed),
                "belt": {"x": self.x.tolist(), "u_real": self.u.real.tolist(),
                         "u_imag": self.u.imag.tolist()},
                **({} if self.arm is None else {"arm": pair(self.arm)})}}


@dataclass(frozen=True)
class DriveModes:
    """The lowest modes of a drive linearised about its steady state.

    Attributes
    ----------
    modes : tuple of Mode
        By increasing frequency.
    least_stable : complex
        The eigenvalue with the largest real part among all the finite ones (real ones
        included, and those beyond the listed band); Im >= 0 of a conjugate pair.
    elements : int
        The grid's elements.
    eigenvalues : int
        How many eigenvalues were computed: the dense method's every finite one; the
        sparse method's distinct ones its shifts found.
    method : str
        "dense" or "sparse" (:func:`drive_modes`).
    """

    modes: tuple[Mode, ...]
    least_stable: complex
    elements: int
    eigenvalues: int
    method: str = "dense"

    def to_list(self) -> list[dict]:
        """What ``beltsim modes`` writes to modes.json."""
        return [m.to_dict() for m in self.modes]

    @property
    def frequencies(self) -> np.ndarray:
        """The listed modes' frequencies (Hz)."""
        return np.array([m.frequency_hz for m in self.modes])

    @property
    def rates(self) -> np.ndarray:
        """The listed modes' rates (1/s)."""
        return np.array([m.rate for m in self.modes])

    def growing(self) -> list[Mode]:
        """The listed modes that grow (rate > 0)."""
        return [m for m in self.modes if m.rate > 0.0]

    def table(self) -> str:
        """A short table: frequency, rate, damping ratio, pulley share and what moves
        most (a pulley's rim or the belt), then the least stable eigenvalue."""
        lines = [f"{'#':>3}  {'f [Hz]':>10}  {'rate [1/s]':>11}  {'zeta':>9}  "
                 f"{'pulleys':>7}  moves most"]
        for k, m in enumerate(self.modes):
            lines.append(f"{k:>3}  {m.frequency_hz:>10.4f}  {m.rate:>+11.4g}  "
                         f"{m.damping_ratio:>9.2e}  {m.pulley_share:>7.3f}  {m.largest}")
        lam = self.least_stable
        verdict = "grows" if lam.real > 0.0 else "decays"
        of = (f"of {self.eigenvalues}" if self.method == "dense" else
              f"({self.method}, {self.eigenvalues} found)")
        lines.append(f"least stable eigenvalue {of} ({self.elements} "
                     f"elements): {lam.real:+.4g} 1/s at {abs(lam.imag) / (2 * math.pi):.4g} "
                     f"Hz ({verdict})")
        return "\n".join(lines)


def check_options(count, f_max, elements) -> None:
    """UsageError on a bad count, frequency bound or grid."""
    if count is not None and not (isinstance(count, int) and count >= 1):
        raise UsageError(f"--count: must be an integer >= 1, got {count!r}")
    if f_max is not None and not (math.isfinite(f_max) and f_max > 0):
        raise UsageError(f"--f-max: must be > 0 Hz, got {f_max!r}")
    if elements is not None and not (isinstance(elements, int)
                                     and 8 <= elements <= MAX_ELEMENTS):
        raise UsageError(f"--elements: must be an integer in [8, {MAX_ELEMENTS}], got "
                         f"{elements!r}")


def drive_modes(scene, count: int | None = None, f_max: float | None = None,
                elements: int | None = None, samples: int = SAMPLES,
                method: str = "auto") -> DriveModes:
    """The lowest modes of a closed drive's discrete model about its steady state.

    Two methods give the same modes and least stable eigenvalue (the tests compare them):
    "dense", every eigenvalue by the QZ algorithm (small grids), and "sparse", ARPACK in
    shift-invert mode: a sweep of shifts up the imaginary axis for the least stable
    eigenvalue (:func:`beltsim.physics.shift_invert.sweep`), whose disks also hold the
    listed modes up to a height (a mode missing from the disk of radius r about 0 has
    abs(lambda) > r, so every listed mode with Im lambda below r sqrt(1 -
    MAX_DAMPING_RATIO^2) has been found, and so on for each disk), and when
    that is too low, more eigenvalues about 0, doubling until the listing is complete.

    Parameters
    ----------
    scene : DriveScene
        A drive with inertia (``physics.inertia = true``).
    count : int, optional
        List at most this many modes (the lowest); DEFAULT_COUNT when ``f_max`` is None
        too.
    f_max : float, optional
        List only the modes up to this frequency (Hz).
    elements : int, optional
        The grid; default the scene's ``numerics.elements``, else DEFAULT_ELEMENTS.
    samples : int, optional
        Samples of the belt's displacement in each shape.
    method : {"auto", "dense", "sparse"}, optional
        "auto": dense up to DENSE_ELEMENTS elements, sparse above.

    Returns
    -------
    DriveModes

    Raises
    ------
    UsageError
        A bad count, bound or grid.
    SceneError
        A quasistatic drive (no dynamics to linearise).
    NumericalError
        The steady state could not be solved for.
    """
    check_options(count, f_max, elements)
    P = scene.params
    if not P.inertia:
        raise SceneError("physics.inertia", "a quasistatic drive has no modes (set it true)")
    if elements is None:
        elements = min(scene.numerics.get("elements", DEFAULT_ELEMENTS), MAX_ELEMENTS)
    if count is None and f_max is None:
        count = DEFAULT_COUNT
    if method not in ("auto", "dense", "sparse"):
        raise UsageError(f"method: 'auto', 'dense' or 'sparse', got {method!r}")
    disc, state = steady_discretisation(scene, elements)
    N = disc.grid.n_elements
    if method == "auto":
        method = "dense" if N <= DENSE_ELEMENTS else "sparse"
    if method == "dense" and N > MAX_DENSE_ELEMENTS:
        raise UsageError(f"elements: the dense method stops at {MAX_DENSE_ELEMENTS}, got {N}")
    if method == "sparse":
        lam, Z, least, found = _sparse(disc, state, count, f_max)
    else:
        lam, Z = eigenpairs(disc, state)
        least, found = complex(lam[np.argmax(lam.real)]), len(lam)
    # of a conjugate pair, the one in the upper half plane (as the listed modes)
    least = least.conjugate() if least.imag < 0.0 else least
    order = _listed(lam, count, f_max)
    modes = tuple(_mode(disc, lam[k], Z[:, k], samples) for k in order)
    return DriveModes(modes, least, N, found, method)


def _listed(lam, count, f_max, below=math.inf):
    """Indices of the listed modes among ``lam``, by increasing frequency: oscillating,
    damping ratio below MAX_DAMPING_RATIO, Im lambda up to 2 pi f_max and below
    ``below``, the lowest ``count``."""
    keep = (lam.imag > 0.0) & (-lam.real < MAX_DAMPING_RATIO * np.abs(lam)) & (lam.imag < below)
    if f_max is not None:
        keep &= lam.imag <= 2.0 * math.pi * f_max
    return np.flatnonzero(keep)[np.argsort(lam.imag[keep], kind="stable")][:count]


def _sparse(disc, state, count, f_max):
    """(eigenvalues, their modes z as columns, the least stable eigenvalue, how many
    distinct eigenvalues were found) by shift-invert; see :func:`drive_modes`."""
    from ..solvers.linearise import highest_frequency

    M, C, K = linearisation(disc, state)
    n, size = K.shape[0], 2 * K.shape[0]
    top = highest_frequency(disc)
    with one_blas_thread():
        def listing(disks):
            lam, V = distinct(disks)
            below = _complete(disks)
            return lam, V, below, _listed(lam, count, f_max, below)

        done = []

        def need_modes(disks):
            # once the listing is complete no later disk adds a mode below its frequency
            if not done:
                _, _, below, order = listing(disks)
                if _enough(order, count, f_max, below):
                    done.append(len(disks))
            return not done

        disks = sweep(M, C, K, SWEEP_REACH * top, vectors=need_modes)
        lam, V, below, order = listing(disks)
        k = FIRST_NEAREST
        # the sweep's disks hold too few of the listed modes: more about 0, doubling
        while not _enough(order, count, f_max, below):
            k = min(k, size - 2)
            disks.append(ShiftInvert(M, C, K, 0.0).disk(k, vectors=True))
            lam, V, below, order = listing(disks)
            if k == size - 2 and not _enough(order, count, f_max, below):
                # every eigenvalue ARPACK can give: the dense path's job
                lam, Z = eigenpairs(disc, state)
                return lam, Z, complex(lam[np.argmax(lam.real)]), len(lam)
            k *= 2
    # as the dense path: beyond INFINITE times the grid's highest frequency an eigenvalue
    # is an infinite one's round-off (ARPACK's Ritz values near 0)
    finite = np.abs(lam) < INFINITE * top
    least = complex(lam[finite][np.argmax(lam[finite].real)])
    keep = lam.imag < below
    return lam[keep], V[:n, keep], least, int(np.count_nonzero(finite))


def _enough(order, count, f_max, below) -> bool:
    """Whether the listing is complete: ``count`` modes, or every one up to f_max."""
    return ((count is not None and len(order) == count)
            or (f_max is not None and 2.0 * math.pi * f_max < below))


def _complete(disks) -> float:
    """The frequency (rad/s) below which the disks hold every mode that is listed by its
    damping ratio: the disks about i w of radius r cover the cone
    abs(Re lambda) <= t Im lambda, t = zeta / sqrt(1 - zeta^2) (zeta
    MAX_DAMPING_RATIO), where t^2 y^2 + (y - w)^2 <= r^2, y = Im lambda, and the
    covered heights from 0 up join."""
    t2 = MAX_DAMPING_RATIO ** 2 / (1.0 - MAX_DAMPING_RATIO ** 2)
    spans = []
    for d in disks:
        w, r = d.shift.imag, d.radius
        root = (1.0 + t2) * r * r - t2 * w * w
        if root >= 0.0:
            spans.append(((w - math.sqrt(root)) / (1.0 + t2),
                          (w + math.sqrt(root)) / (1.0 + t2)))
    below = 0.0
    for lo, hi in sorted(spans):
        if lo > below:
            break
        below = max(below, hi)
    return below


def _mode(disc, lam, z, samples) -> Mode:
    P, grid = disc.params, disc.grid
    N = grid.n_elements
    u = z[0:2 * N:2]
    speeds = np.array([0.0 if k < 0 else z[2 * N + k] for k in disc.speed_global],
                      dtype=complex)
    theta = speeds / lam
    radii = np.array([p.radius for p in P.pulleys])
    xs = np.linspace(0.0, grid.loop_length, samples, endpoint=False)
    us = np.interp(xs, grid.x, u, period=grid.loop_length)
    # a moving tensioner arm's turn, and its pulley centre's displacement a beta
    arm = None if disc.arm is None else z[2 * N + disc.mesh.arm_idx[0]]
    centre = [] if arm is None else [P.tensioner.arm(P.layout)[0] * arm]
    # the largest displacement, of the belt, a rim or the arm's pulley, is 1 and real
    cand = np.concatenate([us, radii * theta, centre])
    top = int(np.argmax(np.abs(cand)))
    # a mode of the string's rotary unknowns alone moves neither belt nor rims: unscaled
    scale = cand[top] if cand[top] != 0.0 else 1.0
    inertia = np.array([p.inertia for p in P.pulleys])
    pulley_ke = float(np.sum(inertia * np.abs(speeds) ** 2))
    if arm is not None:
        pulley_ke += P.tensioner.inertia * float(np.abs(lam * arm) ** 2)
    belt_ke = float(P.rho * np.sum(disc.mesh.hb * np.abs(lam * u) ** 2))
    share = pulley_ke / (pulley_ke + belt_ke) if pulley_ke + belt_ke > 0 else 0.0
    names = ["belt"] * samples + [p.name for p in P.pulleys] + ["arm"] * len(centre)
    return Mode(complex(lam), {p.name: (complex(t / scale), complex(w / scale))
                               for p, t, w in zip(P.pulleys, theta, speeds)},
                complex(z[2 * N] / scale), xs, us / scale, share, names[top],
                None if arm is None else complex(arm / scale))


__all__ = ["DEFAULT_COUNT", "DEFAULT_ELEMENTS", "DriveModes", "MAX_DAMPING_RATIO",
           "MAX_ELEMENTS", "Mode",
           "drive_modes"]


@dataclass(frozen=True)
class ForcedResponse:
    """A drive's linear response to a sine on its driver's speed, per rad/s of it.

    ``frequencies`` (Hz); ``tension``: each span's tension amplitude (N per rad/s), by its
    figure key ``tension[A-B]``, at the span's middle; ``speed``: each free pulley's speed
    amplitude (rad/s per rad/s), by ``speed[A]``. Complex: abs() the amplitude, angle()
    the phase against the driver's speed.
    """

    frequencies: np.ndarray
    tension: dict
    speed: dict
    #: a tensioner's arm angle (rad per rad/s), by ``arm_travel``; empty without one
    arm: dict = field(default_factory=dict)

    def amplitudes(self, amplitude: float = 1.0) -> dict:
        """Every figure's amplitude for a driver's speed amplitude (rad/s), by key."""
        return {k: amplitude * np.abs(v)
                for k, v in (self.tension | self.speed | self.arm).items()}


def forced_response(scene, frequencies, elements: int | None = None) -> ForcedResponse:
    """The drive linearised about its steady state, driven by a sine on its driver's
    speed: (-w^2 M + i w C + K) z = f at each frequency (f:
    :func:`beltsim.solvers.linearise.driver_forcing`), read as span tensions and pulley
    speeds. Valid while the sine is small enough that no node changes between stick and
    slip (the runs' periodic states show where that fails).

    Parameters
    ----------
    scene : DriveScene
        A drive with inertia.
    frequencies : array_like
        The driver's fluctuation frequencies (Hz), > 0.
    elements : int, optional
        The grid; default the scene's, else DEFAULT_ELEMENTS.

    Returns
    -------
    ForcedResponse
    """
    import scipy.sparse.linalg as spla

    from ..beltdrive.figures import figure_keys
    from ..solvers.linearise import driver_forcing
    from .modes import linearisation

    f_hz = np.atleast_1d(np.asarray(frequencies, dtype=float))
    if f_hz.size == 0 or not np.all(np.isfinite(f_hz) & (f_hz > 0)):
        raise UsageError("frequencies: must be numbers > 0 (Hz)")
    P = scene.params
    if not P.inertia:
        raise SceneError("physics.inertia", "a quasistatic drive has no forced response "
                         "(set it true)")
    if elements is None:
        elements = scene.numerics.get("elements", DEFAULT_ELEMENTS)
    disc, state = steady_discretisation(scene, elements)
    M, C, K = linearisation(disc, state)
    rhs = driver_forcing(disc, state)
    P, grid = disc.params, disc.grid
    n = grid.n_elements
    b = (len(rhs) - disc.n_globals) // n
    g = P.layout
    names = g.names
    keys = figure_keys(names)
    # each span's middle element: its strain (u_{e+1} - u_e) / h_e
    mids = 0.5 * (g.bounds[1:-1:2] + g.bounds[2::2])
    e = np.searchsorted(grid.x, mids) - 1
    tension = {keys[i]: np.zeros(f_hz.size, complex) for i in range(len(names))}
    speed = {f"speed[{p.name}]": np.zeros(f_hz.size, complex)
             for p, k in zip(P.pulleys, disc.speed_global) if k >= 0}
    he = grid.he
    # a tensioner's arm: its spans' stretch per unit angle (physics.arm), and its angle
    arm_at = disc.mesh.arm_idx[0] if disc.mesh.arm_idx.shape[0] else None
    de = element_stretches(disc.mesh, state.g, slope=True)
    arm = {} if arm_at is None else {"arm_travel": np.zeros(f_hz.size, complex)}
    for m, f in enumerate(f_hz):
        w = 2.0 * math.pi * f
        z = spla.spsolve((-w * w * M + 1j * w * C + K).tocsc(), rhs.astype(complex))
        u = z[0:b * n:b]
        beta = 0.0 if arm_at is None else z[b * n + arm_at]
        for i in range(len(names)):
            j = e[i]
            tension[keys[i]][m] = P.b1 * ((u[(j + 1) % n] - u[j]) / he[j] + de[j] * beta)
        for p, k in zip(P.pulleys, disc.speed_global):
            if k >= 0:
                speed[f"speed[{p.name}]"][m] = z[b * n + k]
        if arm:
            arm["arm_travel"][m] = beta
    return ForcedResponse(f_hz, tension, speed, arm)
