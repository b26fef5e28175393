"""The runs' stability check (beltsim.simulation.stability): the schemes' amplification
factors against exp(z), the verdicts on the paper's damped and undamped states, the
warning, the cache, and the physical transient's step limit."""

import json
import math
import subprocess
import sys

import numpy as np
import pytest

import beltsim
from beltsim.errors import SceneError
from beltsim.simulation import stability as st
from beltsim.simulation import stability_check as sc


@pytest.fixture
def checking(monkeypatch, tmp_path_factory):
    """The check on, with a cache shared by this module's tests."""
    folder = tmp_path_factory.getbasetemp() / "stability-cache"
    monkeypatch.setenv(st.SWITCH, "1")
    monkeypatch.setenv("BELTSIM_CACHE_DIR", str(folder))
    return folder


@pytest.mark.unit
@pytest.mark.parametrize("integrator, order", [("esdirk3", 3), ("implicit", 2)])
def test_the_amplification_factor_is_exp_z_to_the_schemes_order(integrator, order):
    # one step's error is O(z^(p+1)): halving z divides it by 2^(p+1) (within 10 % at
    # |z| = 0.02, where the next term is |z| times smaller)
    errs = [abs(st.amplification(integrator, z) - np.exp(z))
            for z in (0.02 * (0.3 + 1j), 0.01 * (0.3 + 1j))]
    assert errs[0] / errs[1] == pytest.approx(2.0 ** (order + 1), rel=0.1)
    # L-stable (ESDIRK3) and BDF2's root -> 0 far in the left half plane
    assert abs(st.amplification(integrator, -1e8)) < 1e-4


@pytest.mark.unit
def test_the_explicit_and_steady_schemes_have_no_factor():
    assert st.amplification("explicit", 0.1j) is None
    assert st.step_damping("steady", 1j, 1.0) is None


@pytest.mark.unit
@pytest.mark.parametrize("integrator", ["esdirk3", "implicit"])
def test_the_physical_step_bounds_the_steps_damping(integrator):
    found = st.Stability(rate=9.4, frequency=1303.0, method="exact", band=3000.0)
    lam = complex(found.rate, 2 * math.pi * found.frequency)
    h = st.physical_step(found, integrator)
    bound = st.PHYSICAL_DAMPING * found.rate
    assert abs(st.step_damping(integrator, lam, h)) == pytest.approx(bound, rel=1e-6)
    # the damping grows with the step (as h^p): twice the step damps more than the bound
    assert abs(st.step_damping(integrator, lam, 2 * h)) > 2 * bound


@pytest.mark.unit
def test_the_physical_step_resolves_every_growing_mode():
    # the step is set by the mode it damps most: the highest growing frequency
    low = st.Stability(rate=9.4, frequency=1303.0, method="exact", band=3000.0)
    both = st.Stability(rate=9.4, frequency=1303.0, method="exact", band=3000.0,
                        modes=((9.4, 1303.0), (9.4, 2879.0)))
    high = st.Stability(rate=9.4, frequency=2879.0, method="exact", band=3000.0)
    assert st.physical_step(both, "esdirk3") == pytest.approx(
        st.physical_step(high, "esdirk3"), rel=1e-9)
    assert st.physical_step(both, "esdirk3") < 0.5 * st.physical_step(low, "esdirk3")


@pytest.mark.unit
def test_verdicts_and_the_warning_text():
    grows = st.Stability(rate=9.39, frequency=1302.9, method="exact", band=3000.0,
                         growing=32, grid_damping=650.5, step_damping=-178.6)
    assert grows.verdict == "unstable" and grows.to_dict()["stable"] is False
    text = grows.warning()
    assert text.startswith("the steady state is unstable in the model: a mode at 1303 Hz "
                           "grows at 9.39 1/s; this run's scheme damps it by about 472 1/s")
    assert "\n" not in text
    unsure = st.Stability(rate=4.6, frequency=3912.0, method="discrete", elements=201,
                          error=9.8)
    assert unsure.verdict == "undecided" and unsure.warning() is None
    assert unsure.to_dict()["stable"] is None
    decays = st.Stability(rate=-8.2, frequency=1613.0, method="exact", band=3000.0)
    assert decays.verdict == "stable" and decays.warning() is None
    assert "decays at 8.2 1/s" in decays.describe()


@pytest.mark.unit
@pytest.mark.parametrize("key, value, rule", [
    ("numerics.transient", "slow", "one of"),
    ("numerics.gyroscopic", "upwind", 'must be "central"'),
])
def test_a_physical_transient_refuses_what_would_damp_it(key, value, rule):
    over = {"numerics.transient": "physical", key: value}
    with pytest.raises(SceneError, match=rule):
        _discretise("paper_slip", over)


def _discretise(name, over):
    from beltsim import solvers

    return solvers.discretise(beltsim.load_scene(name, over))


@pytest.mark.unit
@pytest.mark.parametrize("name, over", [
    ("paper_slip", {"numerics.integrator": "pseudo"}),
    ("paper_slip", {"numerics.integrator": "explicit"}),
    ("drive_flat", {}),
])
def test_a_physical_transient_needs_an_implicit_scheme_and_an_exact_spectrum(name, over):
    with pytest.raises(SceneError, match="numerics.transient"):
        _discretise(name, {"numerics.transient": "physical", **over})


@pytest.mark.verification
def test_the_paper_states_grow_and_damping_200_is_stable(checking, monkeypatch):
    # The exact roots (tests/test_continuum.py checks the determinant against the moving
    # string and the discrete spectra's second-order convergence) at the paper's d = 39 1/s
    # grow, and d = 200 1/s makes the state stable (docs/verification/spectrum.md: the
    # least stable root +9.39 1/s at 1302.9 Hz, and -8.2 1/s at d = 200)
    grows = sc.least_stable(beltsim.load_scene("paper_slip"))
    assert grows.verdict == "unstable" and grows.method == "exact"
    assert grows.rate == pytest.approx(9.388, abs=0.01)
    assert grows.frequency == pytest.approx(1302.89, abs=0.05)
    decays = sc.least_stable(beltsim.load_scene("paper_slip", {"physics.damping": 200.0}))
    assert decays.verdict == "stable"
    # the second call is the cache's: computing again would fail here
    from beltsim.physics import continuum

    def fail(scene):
        raise AssertionError("computed again")

    monkeypatch.setattr(continuum, "characteristic", fail)
    assert sc.least_stable(beltsim.load_scene("paper_slip")) == grows


@pytest.mark.verification
def test_a_run_reports_the_grids_and_the_steps_damping(checking):
    # the default upwind form damps the 1.3 kHz mode by hundreds of 1/s on the default grid
    # (the spectrum page: 327 1/s on 600 elements, more on coarser grids); the central form
    # by a few (its error falls at second order)
    upwind = beltsim.run("paper_slip").stability
    central = beltsim.run("paper_slip", overrides={"numerics.gyroscopic": "central"}).stability
    assert upwind.grid_damping > 100.0
    assert abs(central.grid_damping) < 10.0
    assert upwind.step_damping is not None and central.step_damping is not None
    off = beltsim.run("paper_slip", stability=False)
    assert off.stability is None and off.summary()["stability"] is None
    assert beltsim.run("paper_quasistatic").stability is None


@pytest.mark.cli
@pytest.mark.verification
def test_the_cli_warns_once_and_writes_the_verdict(checking, tmp_path):
    env = {**__import__("os").environ, st.SWITCH: "1", "BELTSIM_CACHE_DIR": str(checking)}
    res = subprocess.run([sys.executable, "-m", "beltsim", "run", "paper_slip", "--out",
                          str(tmp_path)], capture_output=True, text=True, env=env, timeout=600)
    assert res.returncode == 0, res.stderr
    warnings = [ln for ln in res.stderr.splitlines() if "unstable in the model" in ln]
    assert len(warnings) == 1 and warnings[0].startswith("beltsim: warning: ")
    assert "stability       unstable in the model" in res.stdout
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["stability"]["stable"] is False
    assert summary["stability"]["grid_damping"] > 0.0


@pytest.mark.unit
@pytest.mark.parametrize("elements, expected", [(300, (300, 150)), (6400, (800, 400))])
def test_a_drives_estimate_is_made_on_its_grid_up_to_the_checks_finest(tmp_path, monkeypatch,
                                                                      elements, expected):
    # the estimate's sweep costs about the square of the grid: a fine grid's run is
    # checked on CHECK_ELEMENTS, and its half for the error
    monkeypatch.setenv("BELTSIM_CACHE_DIR", str(tmp_path))
    grids = []

    def fake(scene, n=None):
        grids.append(n)
        return complex(-1.0 - 1e-3 * n, 2e4), n
    monkeypatch.setattr(sc, "_rightmost", fake)
    assert sc.CHECK_ELEMENTS == 800
    scene = beltsim.load_scene("drive_flat").with_overrides({"numerics.elements": elements})
    found = sc.discrete_least_stable(scene)
    assert tuple(grids) == expected
    assert found.elements == expected[0]
    assert found.error == pytest.approx(1e-3 * (expected[0] - expected[1]))
