"""Linear stability of the steady state (physics.modes) and the cells it classifies."""


import numpy as np
import pytest
import scipy.sparse as sp

from beltsim.api import shipped_scene
from beltsim.physics import modes
from beltsim.physics.friction import is_exact
from beltsim.physics.model import (
    Loads,
    State,
    add_stick_penalty,
    assemble,
    blocks_to_dense,
    model_params,
)
from beltsim.problem.drive import Drive
from beltsim.simulation import trackers
from beltsim.solvers.newton import Workspace
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


def _kernel_jacobian(disc, state, s):
    """P(s) = M s^2 + C s + K from the kernel: assemble's Jacobian at inv_dt = s, the old
    state the steady state at rest (and, for an exact law, its stick penalty)."""
    P, num = disc.params, disc.numerics
    p = model_params(P, P.damping, num.friction_scale, num.regularisation, num.law_code)
    N = disc.grid.n_elements
    w = Workspace.allocate(N)
    zero = np.zeros(N + 1)
    old = State(state.u, state.theta, state.lam, zero, zero, zero)
    assemble(state.u.copy(), state.theta.copy(), state.lam.copy(), np.zeros(0), zero.copy(),
             old, s, 0.0,
             disc.mesh, p, Drive.constant(P.v - P.c), Loads.none(N + 1), w, True)
    if is_exact(p.law):
        add_stick_penalty(w, s, p.friction_scale, p.speed, disc.mesh, p)
    return blocks_to_dense(w.Lb, w.Db, w.Ub, w.L2)


@pytest.mark.parametrize("scene", [_slip(40), _slip(40, 'numerics.friction_law="exact"'),
                                   _flutter(40)], ids=["coulomb", "exact", "stick"])
def test_the_linearisation_is_the_kernels_jacobian(scene):
    """(M, C, K) from the reference give the kernel's Jacobian at the steady state (the
    primal-dual form, as the steady scheme solved it) at s = 0 and s = +-s1: P(s) =
    M s^2 + C s + K. The two differ by the friction ratios' convergence (Newton's update
    tolerance 1e-9; measured 9e-11 of the largest entry on the Coulomb scene, 2e-16 for
    the exact and linear laws, whose slopes do not depend on the ratios' last digits)."""
    disc, st = modes.steady_discretisation(scene)
    M, C, K = modes.linearisation(disc, st)
    s1 = 50.0
    for s in (0.0, s1, -s1):
        kernel = _kernel_jacobian(disc, st, s)
        scale = np.abs(kernel).max()
        diff = np.abs((M * s * s + C * s + K).toarray() - kernel).max() / scale
        assert diff < 1e-9, (s, diff)
    assert np.all(M.diagonal() > 0) and sp.isspmatrix_csr(K)


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
