"""The exact spectrum of the linearised continuous model (physics.continuum) against
closed forms and against the discrete model's spectrum under refinement."""

import math

import pytest

from beltsim.api import shipped_scene
from beltsim.physics import continuum, modes
from beltsim.physics.continuum import Characteristic, Zone


def _params(name="paper_slip"):
    return shipped_scene(name).params


@pytest.mark.unit
def test_a_free_span_has_the_moving_strings_frequencies():
    """Without contact and damping the axial modes of the moving string with fixed ends are
    omega_n = n pi (b1 - rho c^2) / (L sqrt(rho b1)) (e.g. Wickert and Mote 1990), purely
    imaginary; the root finder's tolerance is 1e-12 relative."""
    P = _params()
    ch = Characteristic(P, [Zone(0.0, P.L, "free")], 0.0)
    w1 = math.pi * P.B / (P.L * math.sqrt(P.rho * P.b1))
    for n in (1, 2, 5):
        lam = ch.root(complex(0.0, 1.0005 * n * w1))
        assert lam is not None
        assert abs(lam.imag - n * w1) < 1e-9 * n * w1, (lam, n * w1)
        assert abs(lam.real) < 1e-9 * n * w1


@pytest.mark.unit
def test_splitting_a_free_zone_changes_nothing():
    """Interfaces between free zones carry continuity of z, phi, z', phi' only: the roots
    of one zone and of three are the same."""
    P = _params()
    one = Characteristic(P, [Zone(0.0, P.L, "free")], 39.0)
    three = Characteristic(P, [Zone(0.0, 0.3, "free"), Zone(0.3, 0.7, "free"),
                               Zone(0.7, P.L, "free")], 39.0)
    roots = one.roots(600.0)
    assert len(roots) >= 10
    for lam in roots:  # each is a root of the other determinant too
        other = three.root(lam)
        assert other is not None and abs(other - lam) < 1e-9 * abs(lam)


@pytest.mark.unit
def test_zones_follow_the_exact_steady_state():
    """paper_slip: free up to x1, stick to the slip start x*, then free (sliding) to L;
    paper_inertia (perfect adhesion): stick over the whole contact."""
    ch = continuum.characteristic(shipped_scene("paper_slip"))
    P = ch.P
    assert [z.kind for z in ch.zones] == ["free", "stick", "free"]
    assert ch.zones[1].a == pytest.approx(P.x1) and P.x1 < ch.zones[1].b < P.x2
    ch = continuum.characteristic(shipped_scene("paper_inertia"))
    assert [(z.kind, z.a, z.b) for z in ch.zones][1] == ("stick", ch.P.x1, ch.P.x2)
    with pytest.raises(ValueError, match="quasistatic"):
        continuum.characteristic(shipped_scene("paper_quasistatic"))


@pytest.mark.verification
def test_the_central_discrete_spectrum_converges_to_the_exact_roots_at_second_order():
    """paper_slip's growing mode near 531 Hz: the discrete model with the central
    gyroscopic term, at a fixed regularisation (the linearisation held fixed), reaches the
    exact root at second order in h (error ratio 4 per halving; >= 3 asked); the upwind
    form is first order and damps the mode by far more than its own rate."""
    scene = shipped_scene("paper_slip", [("numerics.regularisation", 1.2e-4)])
    roots = continuum.characteristic(scene).roots(560.0, 500.0)
    exact = roots[0]
    assert exact.real > 0.0 and abs(exact.imag / (2 * math.pi) - 531.36) < 0.05
    central = scene.with_overrides([("numerics.gyroscopic", "central")])
    errors = [abs(modes.nearest_eigenvalue(central, exact, N) - exact)
              for N in (1200, 2400, 4800)]
    assert errors[0] / errors[1] >= 3.0 and errors[1] / errors[2] >= 3.0, errors
    upwind = modes.nearest_eigenvalue(scene, exact, 2400)
    assert upwind.real < exact.real - 20.0, upwind


@pytest.mark.verification
@pytest.mark.long  # 15 to 23 s a case
@pytest.mark.parametrize("name, factor", [("paper_slip", 1), ("paper_slip", 8),
                                          ("paper_inertia", 1)])
def test_the_default_form_settles_the_damped_paper_scenes(name, factor):
    """The upwind form's numerical damping exceeds the exact spectrum's growth (about 5 to
    10 1/s at d = 39 1/s) on the default grid and on one 8 times finer: no discrete mode
    grows, so time-accurate runs reach the steady state the paper's solutions describe."""
    scene = shipped_scene(name)
    if factor > 1:
        from beltsim.solvers.settings import default_elements

        scene = scene.with_overrides([("numerics.elements",
                                       factor * default_elements(scene.params))])
    growth = modes.growth_rate(scene)
    assert growth.rate < 0.0, growth.describe()
