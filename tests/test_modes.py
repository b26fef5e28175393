"""Linear stability of the steady state (physics.modes) and the cells it classifies."""


import numpy as np
import pytest
import scipy.linalg
import scipy.sparse as sp

from beltsim.api import shipped_scene
from beltsim.physics import modes, reference
from beltsim.physics.friction import is_exact
from beltsim.physics.modes import steady_scene
from beltsim.problem.drive import Drive
from beltsim.simulation import trackers
from beltsim.simulation.controller import Simulation
from beltsim.studies import stability
from beltsim.studies.stability import ACCEPTED, Case, CellStatus, stability_cell
from validation import random_scenes as rs

pytestmark = pytest.mark.verification


def _slip(n, *over):
    return shipped_scene("paper_slip", [f"numerics.elements={n}", *over])


def _flutter(n):
    """Random scene 191 of seed 1 (stick, undamped, 0.77 of the critical speed): its
    steady state is unstable from about 300 elements on (+0.27 1/s at 3.9 Hz on 1000)."""
    return rs.draw_scene(1, 191).with_overrides([f"numerics.elements={n}"])


@pytest.mark.parametrize("c", [0.3, 5.0, -0.3])
def test_the_companion_matrix_has_the_oscillators_eigenvalues(c):
    """m x'' + c x' + k x = 0: lambda = (-c +- sqrt(c^2 - 4 m k)) / (2 m), and a negative
    damping grows; two uncoupled oscillators give both pairs."""
    m, k = np.array([2.0, 0.5]), np.array([3.0, 7.0])
    A = modes.companion(sp.diags(m), sp.diags([c, 1.0]), sp.diags(k)).toarray()
    got = np.sort_complex(np.linalg.eigvals(A))
    want = []
    for mi, ci, ki in zip(m, (c, 1.0), k):
        root = np.sqrt(complex(ci * ci - 4 * mi * ki))
        want += [(-ci + root) / (2 * mi), (-ci - root) / (2 * mi)]
    for w in want:  # each once (sorting is fragile where real parts tie)
        assert np.min(np.abs(got - w)) < 1e-12 * (1 + abs(w)), (got, want)
    assert len(got) == len(want)
    assert (max(got.real) > 0) == (c < 0)


@pytest.mark.parametrize("scene", [_slip(40), _slip(40, 'numerics.friction_law="exact"'),
                                   _flutter(40)], ids=["coulomb", "exact", "stick"])
def test_the_kernels_linearisation_is_the_references(scene):
    """(M, C, K) read off the kernel's Jacobian (solvers.linearise) are the vectorised
    reference's (physics.reference.linearisation) on the open layout: each entry within
    1e-10 of its row's largest (measured on paper_slip's 100 elements: M 3e-12, C 2e-14,
    K 2e-13: the quadratic's reading at three rates loses a few digits of M)."""
    disc, st = modes.steady_discretisation(scene)
    got = modes.linearisation(disc, st)
    want = reference.linearisation(st.u, st.theta, np.zeros_like(st.u), np.zeros_like(st.u),
                                   0.0, disc.mesh,
                                   disc.model._replace(damping=disc.params.damping),
                                   Drive.constant(disc.params.v - disc.params.c),
                                   ratios=st.lam if is_exact(disc.model.law) else None)
    for name, g, w in zip("MCK", got, want):
        row = abs(w).max(axis=1).toarray().ravel()
        diff = abs(g - w).max(axis=1).toarray().ravel()
        assert np.all(diff <= 1e-10 * row), (name, np.max(diff / np.maximum(row, 1e-300)))
    assert np.all(got[0].diagonal() > 0) and sp.isspmatrix_csr(got[2])


def _drive(n, *over):
    return shipped_scene("drive_flat", [f"numerics.elements={n}", *over])


def test_a_loops_linearisation_has_its_layouts_masses_and_rows():
    """A loop's M is the lumped masses rho hbar_j, I hbar_j and nothing else (c and the
    driven pulley's speed are first-order unknowns); C holds the belt's c_t in the axial
    rows (rho hbar_j) and the pulley's J2 omega_t; the gauge row is algebraic, sum_j
    hbar_j u_j / Lambda."""
    scene = _drive(60)
    disc, st = modes.steady_discretisation(scene)
    M, C, K = modes.linearisation(disc, st)
    P, hb = disc.params, disc.mesh.hb
    n = 2 * len(hb)
    lumped = np.column_stack([P.rho * hb, P.I * hb]).ravel()
    assert M.shape == (n + 2, n + 2)
    np.testing.assert_allclose(M.diagonal()[:n], lumped, rtol=1e-10)
    assert M.nnz == n  # the lumped masses only
    np.testing.assert_allclose(C[:n:2, n].toarray().ravel(), P.rho * hb, rtol=1e-10)
    assert C[n + 1, n + 1] == pytest.approx(P.J2, rel=1e-10)
    assert C[n].nnz == 0 and M[n].nnz == 0
    L = P.geometry.loop_length
    np.testing.assert_allclose(K[n, :n:2].toarray().ravel(), hb / L, rtol=1e-12)
    assert K[n, 1:n:2].nnz == 0 and K[n, n:].nnz == 0


def _mode_path(scene, scheme, samples=60, periods=5.0, amplitude=1e-5):
    """A transient started on the least stable mode of the scene's linearisation (its
    steady state plus Re(z), rates Re(lambda z), the largest nodal u scaled to amplitude
    times the layout's u scale), against Re(z e^{lambda t}) at that node: the largest
    difference relative to the largest prediction, and lambda."""
    disc, st = modes.steady_discretisation(scene)
    A, B = modes.pencil(*modes.linearisation(disc, st))
    lam, V = scipy.linalg.eig(A.toarray(), None if B is None else B.toarray())
    keep = np.isfinite(lam) & (np.abs(lam) < 1e12)
    lam, V = lam[keep], V[:, keep]
    k = np.argmax(np.where(lam.imag >= 0.0, lam.real, -np.inf))
    lam, x = lam[k], V[:, k]
    n, off = A.shape[0] // 2, disc.mesh.off
    rows = len(st.u) - 2 * off
    node = int(np.argmax(np.abs(x[:2 * rows:2])))
    x *= amplitude * disc.scales.u / abs(x[2 * node])
    over = [("numerics.integrator", scheme), ("numerics.time_tol", 1e-10)]
    sim = Simulation(steady_scene(scene).with_overrides(over))
    if scheme == "explicit":  # a quarter of its default step: its error 16 times smaller
        sim = Simulation(steady_scene(scene).with_overrides(
            [*over, ("numerics.dt", sim.scheme.dt / 4.0)]))
    s = sim.state
    for field, value in zip(s, st):
        field[:] = value
    z, v = x[:n], x[n:]
    inner = slice(off, off + rows)
    s.u[inner] += z[0:2 * rows:2].real
    s.theta[inner] += z[1:2 * rows:2].real
    s.ud[inner], s.td[inner] = v[0:2 * rows:2].real, v[1:2 * rows:2].real
    s.g[:] += z[2 * rows:].real
    s.gd[:] = v[2 * rows:].real
    t0 = sim.t = sim.numerics.settle_time  # the drive's final values from here on
    span = periods * 2.0 * np.pi / abs(lam.imag) if lam.imag else periods / abs(lam.real)
    worst = largest = 0.0
    for t in t0 + np.linspace(0.0, span, samples + 1)[1:]:
        sim.advance(t)
        want = (x[2 * node] * np.exp(lam * (sim.t - t0))).real
        worst = max(worst, abs(s.u[off + node] - st.u[off + node] - want))
        largest = max(largest, abs(want))
    return worst / largest, lam


@pytest.mark.parametrize("scheme", ["esdirk3", "explicit"])
@pytest.mark.parametrize("scene", [_slip(60), _drive(60, 'numerics.friction_law="tanh"')],
                         ids=["straight", "loop"])
def test_a_transient_started_on_a_mode_follows_it(scene, scheme):
    """On either layout, a transient from the steady state displaced along the least
    stable mode z (u at most 1e-5 of its scale) follows Re(z e^{lambda t}) for five
    periods to 1e-3 of its amplitude: the spectrum is the schemes' model's. The
    difference is the time steps' error and the O(amplitude) nonlinearity. Measured on
    60 elements (paper_slip; drive_flat with tanh): esdirk3 at time_tol 1e-10, 4e-5 and
    2e-5; the explicit scheme at a quarter of its default step 7e-5 and 3e-5 (at the
    default step 1.0e-3 and 1.5e-4: the straight belt's falls as dt^2)."""
    err, lam = _mode_path(scene, scheme)
    assert err < 1e-3, (err, lam)


def test_growth_rate_signs_and_the_fine_grid_search():
    """Paper slip (damped, 200 elements): every mode decays; scene 191 (400 elements): a
    3.9 Hz mode grows. On a grid above dense_elements the shift-invert search around the
    coarse grid's least stable modes finds the dense spectrum's largest real part."""
    stable = modes.growth_rate(_slip(200))
    assert stable.rate < -5.0 and stable.method == "dense"
    dense = modes.growth_rate(_flutter(400))
    assert dense.method == "dense" and 0.05 < dense.rate < 0.2
    assert dense.frequency == pytest.approx(3.88, abs=0.01)
    search = modes.growth_rate(_flutter(400), dense_elements=100)
    assert search.method.startswith("shift-invert") and search.elements == 400
    assert search.coarse.rate < 0  # stable on 100 elements: found on the fine grid
    assert search.rate == pytest.approx(dense.rate, rel=1e-6)
    assert search.frequency == pytest.approx(dense.frequency, rel=1e-7)


def test_a_diverged_cell_is_accepted_only_when_its_steady_state_is_unstable(monkeypatch):
    """Any growth counts as divergence here (GROWTH_LIMIT ~ 0): the unstable scene's cell
    becomes "unstable steady state" with its growth rate; the stable one stays diverged,
    a failure, with the stable verdict in its reason."""
    monkeypatch.setattr(trackers, "GROWTH_LIMIT", 1e-12)
    monkeypatch.setattr(stability, "_VERDICTS", {})
    unstable = stability_cell(rs.scene_case(rs.draw_scene(1, 191)), "implicit",
                              extra=[("numerics.elements", 400)])
    assert unstable["status"] is CellStatus.UNSTABLE and unstable["status"] in ACCEPTED
    assert "linearly unstable: a mode at 3.877 Hz grows at 0.129 1/s" in unstable["reason"]
    assert "grew without bound" in unstable["reason"]
    stable = stability_cell(Case("slip", "paper_slip"), "implicit",
                            extra=[("numerics.elements", 200)])
    assert stable["status"] is CellStatus.DIVERGED and stable["status"] not in ACCEPTED
    assert "grew without bound" in stable["reason"] and "linearly stable" in stable["reason"]


def test_an_undamped_scene_runs_a_shorter_span_and_is_judged_by_its_modes():
    """The random study stops an undamped time-accurate run at RINGING_TRANSITS transits
    (the explicit scheme's max_work scaled alike); one still ringing there is bounded when
    its steady state is stable and "unstable steady state" when it is not."""
    scene = rs.draw_scene(1, 191)
    P = scene.params
    over = dict(rs.ringing_span(scene, "explicit"))
    t_end = over["numerics.t_end"]
    assert t_end == pytest.approx(2 * P.L / P.c + rs.RINGING_TRANSITS * P.L / P.c)
    assert over["numerics.max_work"] == pytest.approx(
        2e10 * t_end / (2 * P.L / P.c + 400 * P.L / P.c))
    assert rs.ringing_span(scene, "pseudo") == rs.ringing_span(scene, "steady") == []
    damped = _slip(100)
    assert rs.ringing_span(damped, "implicit") == []
    short = [("numerics.elements", 400), ("numerics.t_end", 1.0)]
    cell = rs.random_cell(scene, 191, "implicit", extra=short)
    assert cell["status"] == CellStatus.UNSTABLE.value and not rs.failed(cell), cell
    assert cell["reason_key"] == "reached t_end"  # what the run stopped on
    ringing = rs.random_cell(_slip(120, "physics.damping=0"), 0, "implicit",
                             extra=[("numerics.t_end", 0.02)])
    assert ringing["status"] == CellStatus.BOUNDED.value
    assert "linearly stable" in ringing["reason"]


def test_the_exact_law_linearises_like_its_regularised_twin():
    # the exact law's stuck nodes enter as the default regularisation's slope; the least
    # stable mode matches the tanh law's (measured on 200 elements: -19.3069 against
    # -19.3066 1/s, 121.28 Hz both)
    base = shipped_scene("paper_slip", ["numerics.elements=120"])
    reg = modes.growth_rate(base)
    exact = modes.growth_rate(base.with_overrides(['numerics.friction_law="exact"']))
    assert reg.rate < 0.0
    assert abs(exact.rate - reg.rate) < 1e-3 * abs(reg.rate)
    assert abs(exact.frequency - reg.frequency) < 1e-3 * reg.frequency


def test_a_damped_run_cut_short_is_bounded_only_when_its_modes_are_too_slow(monkeypatch):
    """Damped paper slip on 120 elements, stopped 0.033 s after the ramp: its least stable
    mode decays at about 20 1/s (test above: -19.3 on 200 elements), so settling to 1e-6
    needs ln(1e6) / 20 ~ 0.7 s: bounded, "stable but slow". With a verdict whose decay
    would have settled it in time (injected), the same cell stays a failure."""
    case = Case("slip", "paper_slip", (("numerics.elements", 120), ("numerics.t_end", 0.05)))
    monkeypatch.setattr(stability, "_VERDICTS", {})
    slow = stability_cell(case, "implicit")
    assert slow["status"] is CellStatus.BOUNDED, slow
    assert slow["reason"].startswith("stable but slow: settling to steady_tol 1e-06 takes")
    fast = {k: (False, "injected", 1e6) for k in stability._VERDICTS}
    monkeypatch.setattr(stability, "_VERDICTS", fast)
    assert stability_cell(case, "implicit")["status"] is CellStatus.NOT_CONVERGED


def test_a_drives_stability_verdict_comes_from_its_modes():
    """The stability matrix's verdict on a drive (a cell that grew) is its modes': the
    drive's least stable mode decays (about 10 1/s at 88 Hz on 100 elements, close to
    half its damping d = 20 1/s), not "no linear stability verdict"."""
    unstable, why, decay = stability._stability_verdict(_drive(100))
    assert not unstable and "linearly stable" in why, why
    assert 5.0 < decay < 20.0


def test_a_heavy_driven_pulleys_rotational_mode_is_the_spring_models():
    """The limit of a belt much lighter than its pulleys in perfect adhesion (Hwang,
    Perkins and Ulsoy 1994): with the driver held, the driven pulley turns on the two
    free spans as springs b1 / l_j, omega^2 = R2^2 b1 (1/l_1 + 1/l_2) / J, J the pulley's
    inertia plus the belt's by Rayleigh (its driven arc at R2, each span a third of it).
    drive_flat in adhesion, string model, no load, no damping, J2 = 2 kg m^2 (the belt's
    share 0.35 %), c = 0.04 m/s: measured 6e-6 from the limit on 100 elements, O(N0 /
    b1)^2 and O(share)^2 terms the spring model leaves out; the bound is 1e-4. (Under the
    rated load the model is 7.5e-4 stiffer: an O((T_tight - T_slack) / b1) = 2.6e-3 term
    of the steady tensions, which the spring model does not have.)"""
    data = _drive(100, "physics.model=\"string\"", "physics.damping=0.0",
                  "drive.driven_inertia=2.0", "drive.driver_speed=0.5",
                  "drive.load_torque=0.0").to_dict()
    data["contact"] = {"friction": "stick"}
    scene = type(_drive(100)).from_dict(data)
    disc, st = modes.steady_discretisation(scene)
    eigs = modes.spectrum(disc, st)
    P, geo = disc.params, disc.params.geometry
    arc, span1, span2 = geo.lengths[2], geo.lengths[1], geo.lengths[3]
    J = P.J2 + P.rho * geo.R2 ** 2 * (arc + (span1 + span2) / 3.0)
    omega = np.sqrt(geo.R2 ** 2 * P.b1 * (1.0 / span1 + 1.0 / span2) / J)
    found = eigs[np.argmin(np.abs(eigs - 1j * omega))]
    assert abs(found.imag - omega) < 1e-4 * omega, (found, omega)
    assert abs(found.real) < 1e-3 * omega  # undamped but for the transport's coupling
