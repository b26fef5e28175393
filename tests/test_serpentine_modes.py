"""Rotational modes of belt drives: the discrete rotational model (Hwang, Perkins and Ulsoy
1994; beltsim.beltdrive.rotational) against hand-derived closed forms, the belt model's
modes (beltsim.physics.loop_modes) against it in the limit of a light belt in perfect
adhesion, and ``beltsim modes``."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import beltsim
from beltsim import load_scene
from beltsim.beltdrive.exact import string_state
from beltsim.beltdrive.rotational import adhesion_limit, rotational_model, stiffness_matrix
from beltsim.errors import SceneError, UsageError
from beltsim.physics import modes as linear
from beltsim.physics.loop_modes import drive_modes
from helpers import BACK_IDLER, cli, serpentine_scene

#: The limit's grid (the stuck arcs' belt moves with the pulleys whatever the grid: 200
#: elements give the same frequencies within 2.5e-4)
LIMIT_ELEMENTS = 100


def limit_scene(scene):
    """``scene`` in the rotational model's limit (beltdrive.rotational.adhesion_limit)."""
    return adhesion_limit(scene, elements=LIMIT_ELEMENTS)


def _rotational(found, n):
    """The n lowest lightly damped modes (damping ratio < 0.01: the rotational ones; the
    stuck arcs' transport and penalty modes have ratios above 0.1)."""
    light = [m for m in found.modes if m.damping_ratio < 0.01]
    return light[:n]


# -- the discrete model -----------------------------------------------------------------


@pytest.mark.unit
def test_every_rim_moving_alike_stretches_no_span():
    """The free-free stiffness matrix is singular on theta_i = 1 / q_i (every rim moves
    the belt by the same length: no span stretches), with signed radii q = s r: a
    back-side idler turns the other way."""
    P = serpentine_scene(BACK_IDLER, model="string").params
    q = P.layout.sides * P.layout.radii
    assert q[2] < 0.0 < q[0]
    K = stiffness_matrix(q, P.b1 / P.layout.spans)
    np.testing.assert_allclose(K @ (1.0 / q), 0.0, atol=1e-12 * np.abs(K).max() / np.abs(q).min())
    np.testing.assert_allclose(K, K.T)
    assert np.all(np.linalg.eigvalsh(K)[1:] > 0.0)


@pytest.mark.unit
def test_two_pulleys_turn_on_the_two_spans_in_parallel():
    """Driver held, the driven pulley on both spans: omega^2 = r^2 (k1 + k2) / J."""
    P = load_scene("drive_flat").params
    model = rotational_model(P)
    r, J = P.pulleys[1].radius, P.pulleys[1].inertia
    k1, k2 = P.b1 / P.layout.spans
    omega, X = model.solve()
    assert model.names == ("driven",) and model.stiffness.shape == (1, 1)
    assert omega[0] == pytest.approx(math.sqrt(r * r * (k1 + k2) / J), rel=1e-13)
    # both spans of one length here: the driven pulley's arcs are half the loop apart
    assert k1 == pytest.approx(k2, rel=1e-12)


@pytest.mark.unit
def test_three_pulleys_with_a_back_side_idler_solve_the_quadratic():
    """Motor held; mill (1) and back-side idler (2): by hand, with q = s r and spans
    k0 (motor -> mill), k1 (mill -> idler), k2 (idler -> motor),
    K = [[q1^2 (k0 + k1), -q1 q2 k1], [-q1 q2 k1, q2^2 (k1 + k2)]], and
    J1 J2 w^4 - (J1 K22 + J2 K11) w^2 + K11 K22 - K12^2 = 0."""
    P = serpentine_scene(BACK_IDLER, model="string").params
    k0, k1, k2 = P.b1 / P.layout.spans
    q1, q2 = P.pulleys[1].radius, -P.pulleys[2].radius
    J1, J2 = P.pulleys[1].inertia, P.pulleys[2].inertia
    K11, K22, K12 = q1 * q1 * (k0 + k1), q2 * q2 * (k1 + k2), -q1 * q2 * k1
    model = rotational_model(P)
    np.testing.assert_allclose(model.stiffness, [[K11, K12], [K12, K22]], rtol=1e-13)
    b, c = J1 * K22 + J2 * K11, K11 * K22 - K12 * K12
    disc = math.sqrt(b * b - 4.0 * J1 * J2 * c)
    w2 = np.array([(b - disc), (b + disc)]) / (2.0 * J1 * J2)
    np.testing.assert_allclose(model.solve()[0], np.sqrt(w2), rtol=1e-10)


# -- the belt model's limit ---------------------------------------------------------------


def _compare(scene):
    """(model frequencies, reference frequencies, model modes, reference) in the limit."""
    lim = limit_scene(scene)
    ref = rotational_model(lim.params)
    n = len(ref.names)
    # dense: the limit's belt, 1e-4 as dense, spreads the spectrum over 1e-1 to 1e10
    # 1/s and the sparse search loses the 114 Hz mode's damping (4e-3 for 5e-5)
    found = drive_modes(lim, count=4 * n + 40, method="dense")
    got = _rotational(found, n)
    assert len(got) == n
    return np.array([m.frequency_hz for m in got]), ref.frequencies, got, ref, lim


@pytest.mark.verification
@pytest.mark.parametrize("name", ["drive_flat", "serpentine_accessory"])
def test_a_light_belt_in_adhesion_turns_the_pulleys_as_the_spring_model(name):
    """In perfect adhesion with no loads and a belt 1e-4 as dense, the belt model's
    lowest N - 1 rotational frequencies are the discrete model's (spans b1 / l_j, arcs
    stuck to their pulleys). Bound 1 %, the issue's; measured on 100 elements: drive_flat
    7.9e-5, the accessory drive (seven pulleys, two back-side idlers) 5.9e-5 at most (the
    belt's remaining inertia share, the stick penalty's round-off). The shapes: each
    pulley's rotation in the belt's sense is s_i times the spring model's, counted
    counterclockwise with signed radii (cosine of the angle between them > 0.999)."""
    f, f_ref, got, ref, lim = _compare(load_scene(name))
    np.testing.assert_allclose(f, f_ref, rtol=1e-2)
    assert np.max(np.abs(f / f_ref - 1.0)) < 2e-4  # the measurement, with margin
    _, X = ref.solve()
    sides = {p.name: p.side for p in lim.params.pulleys}
    for k, mode in enumerate(got):
        theta = np.array([mode.pulleys[nm][0].real for nm in ref.names])
        ccw = theta * np.array([sides[nm] for nm in ref.names])
        cos = abs(ccw @ X[:, k]) / (np.linalg.norm(ccw) * np.linalg.norm(X[:, k]))
        assert cos > 0.999, (k, cos)
        assert mode.rate <= 0.0


@pytest.mark.verification
def test_a_tensioners_arm_turns_as_in_the_spring_model_with_its_arm():
    """The accessory drive with its tensioner in the same limit (the arm undamped): the
    arm's angle is one more degree of freedom of the discrete model (Beikmann, Perkins
    and Ulsoy), coupled to its two spans by their length's slopes in the angle and
    stiffened by the spring and the spans' geometric stiffness. The belt model moves the
    arm through its spans' stretch (physics.arm): its seven lowest rotational
    frequencies are the discrete model's, about the creep theory's rest angle. Bound 1 %,
    the issue's; measured on 100 elements 2.1e-4 at most (1.1e-3 on 200: the discrete
    rest angle's difference from the creep theory's, which moves the arm's geometric
    stiffness)."""
    lim = limit_scene(load_scene("serpentine_tensioner"))
    P = lim.params
    sol = string_state(P)
    rest = P.at_arm(sol.arm_travel - P.arm_turn)
    ref = rotational_model(rest, tension=rest.N0 - rest.rho * sol.c ** 2)
    assert ref.names[-1] == "arm" and len(ref.names) == 7
    found = drive_modes(lim, count=60, method="dense")  # the limit's spread spectrum
    got = _rotational(found, len(ref.names))
    f = np.array([m.frequency_hz for m in got])
    np.testing.assert_allclose(f, ref.frequencies, rtol=1e-2)
    assert np.max(np.abs(f / ref.frequencies - 1.0)) < 5e-4  # the measurement, with margin
    # the shapes, the arm's turn among them (cosine > 0.999, as the pulleys' alone above)
    _, X = ref.solve()
    sides = {p.name: p.side for p in P.pulleys}
    for k, mode in enumerate(got):
        shape = np.array([mode.pulleys[nm][0].real * sides[nm] for nm in ref.names[:-1]]
                         + [mode.arm.real])
        cos = abs(shape @ X[:, k]) / (np.linalg.norm(shape) * np.linalg.norm(X[:, k]))
        assert cos > 0.999, (k, cos)
    assert "arm" in got[0].to_dict()["shape"]


@pytest.mark.verification
def test_the_stick_penalty_does_not_set_the_arcs_stiffness():
    """The stuck nodes' linearisation is a stiff dashpot (physics.model.add_stick_penalty),
    not a spring: ten and a hundred times softer, the two-pulley frequency moves by
    less than 2e-4 (measured 9e-5; the accessory drive's six, 7e-5): the arcs' belt is
    stuck to the pulleys and the span spring is b1 / l_span."""
    lim = limit_scene(load_scene("drive_flat"))
    f_ref = rotational_model(lim.params).frequencies[0]
    disc, st = linear.steady_discretisation(lim)
    base = disc.model
    found = []
    for softer in (1.0, 10.0, 100.0):
        disc.model = base._replace(regularisation=base.regularisation * softer)
        eigs = linear.spectrum(disc, st)
        light = eigs[(eigs.imag > 0) & (-eigs.real < 0.01 * np.abs(eigs))]
        found.append(np.min(light.imag) / (2.0 * math.pi))
    assert np.ptp(found) < 2e-4 * f_ref, found
    assert abs(found[0] / f_ref - 1.0) < 2e-4


@pytest.mark.verification
def test_the_accessory_drive_under_its_rated_loads_is_stable():
    """With creep zones (the rated loads, Coulomb friction, 12 m/s): every mode decays.
    Measured on 200 elements: the least stable eigenvalue -10.0 1/s at 15.4 kHz (a belt
    mode at half the belt's damping 20 1/s); the lowest rotational mode at 47.9 Hz decays
    at 31.7 1/s (the slip arcs' friction slope damps it)."""
    found = beltsim.modes("serpentine_accessory", count=8)
    assert found.least_stable.real < 0.0
    assert not found.growing()
    assert found.modes[0].frequency_hz == pytest.approx(47.92, rel=1e-2)
    assert found.modes[0].largest == "alternator"


# -- the API and the command --------------------------------------------------------------


@pytest.mark.unit
def test_modes_refuses_what_has_none():
    with pytest.raises(UsageError, match="closed drive"):
        beltsim.modes("paper_slip")
    with pytest.raises(SceneError, match="physics.inertia"):
        beltsim.modes("drive_flat", overrides={"physics.inertia": False})
    for kw, key in (({"count": 0}, "--count"), ({"f_max": -1.0}, "--f-max"),
                    ({"elements": 5000}, "--elements")):
        with pytest.raises(UsageError, match=key):
            beltsim.modes("drive_flat", **kw)


@pytest.mark.unit
def test_modes_lists_the_lowest_by_frequency_with_their_shapes():
    found = beltsim.modes("drive_flat", f_max=400.0, elements=60)
    f = found.frequencies
    assert len(f) >= 1 and np.all(np.diff(f) >= 0.0) and f[-1] <= 400.0
    data = found.to_list()
    mode = data[0]
    assert set(mode) >= {"frequency_hz", "rate", "shape"}
    shape = mode["shape"]
    assert set(shape["pulleys"]) == {"driver", "driven"}
    assert shape["pulleys"]["driver"]["rotation"] == [0.0, 0.0]
    u = np.array(shape["belt"]["u_real"]) + 1j * np.array(shape["belt"]["u_imag"])
    rim = [abs(complex(*p["rotation"])) * r for p, r in
           zip(shape["pulleys"].values(), (0.08, 0.16))]
    assert max(np.max(np.abs(u)), *rim) == pytest.approx(1.0, rel=1e-12)
    json.dumps(data)
    assert "least stable eigenvalue" in found.table()


@pytest.mark.cli
def test_the_modes_command_writes_modes_json(tmp_path):
    out = tmp_path / "m"
    res = cli("modes", "drive_flat", "--out", out, "--count", "3", "--elements", "60")
    assert res.returncode == 0, res.stderr
    data = json.loads((out / "modes.json").read_text())
    assert len(data) == 3
    assert [d["frequency_hz"] for d in data] == sorted(d["frequency_hz"] for d in data)
    assert "f [Hz]" in res.stdout and "wrote" in res.stdout
    bad = cli("modes", "drive_flat", "--out", out, "--count", "0")
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1 and "--count" in bad.stderr
    straight = cli("modes", "paper_slip", "--out", out)
    assert straight.returncode == 2 and "closed drive" in straight.stderr


# forced response ------------------------------------------------------------------

def _tanh_accessory(**over):
    return load_scene("serpentine_accessory", {"numerics.friction_law": "tanh",
                                               "numerics.elements": 200, **over})


@pytest.mark.unit
def test_the_drivers_forcing_is_the_residuals_derivative():
    """driver_forcing against central differences of the kernel's residual in the
    driver's rim speed, with a step 1e-4 of the tanh law's regularisation speed (the
    truncation (h / v_reg)^2 ~ 1e-8 relative; round-off ~1e-16 R / h ~ 1e-9 of it)."""
    from beltsim.physics.model import assemble
    from beltsim.problem.drive import Profile
    from beltsim.solvers.linearise import _assembled, driver_forcing

    disc, st = linear.steady_discretisation(_tanh_accessory(), 200)
    f = driver_forcing(disc, st)
    P = disc.params
    base = disc.steady_drive()
    old = st._replace(ud=np.zeros_like(st.ud), td=np.zeros_like(st.td),
                      gd=np.zeros_like(st.gd))

    def residual(rim):
        w, p = _assembled(disc, st, 1.0)
        assemble(st.u.copy(), st.theta.copy(), st.lam.copy(), st.g.copy(),
                 np.zeros_like(st.u), old, 1.0, 0.0, disc.mesh, p,
                 base._replace(speed=Profile.constant(rim)), disc.loads, w, False)
        return np.concatenate([w.R.ravel(), w.Rg])

    rim, r = P.driver_rim_speed, P.pulleys[P.driver].radius
    h = 1e-4 * disc.model.regularisation
    fd = -(residual(rim + h) - residual(rim - h)) / (2 * h) * r
    assert np.abs(fd - f).max() < 1e-7 * np.abs(f).max()
    assert np.count_nonzero(f) >= 10


@pytest.mark.unit
def test_the_linear_forced_response_is_the_periodic_runs():
    """A sine of 0.5 rad/s at 20 Hz on the crankshaft's speed (below the first mode,
    48 Hz): the periodic state's span tension and alternator speed amplitudes (half of
    max - min over the last period) are the linearised drive's to 1 % (measured 0.3 % on
    800 elements, 2026-12-03; near the resonance, 45 Hz, the run's slip arcs move and the
    two part by 13 %)."""
    from beltsim.physics.loop_modes import forced_response

    sine = {"mean": 150.0, "amplitude": 0.5, "period": 1.0 / 20.0}
    scene = _tanh_accessory(**{"pulley.crankshaft.speed": sine})
    res = beltsim.run(scene, raise_on_failure=False)
    assert res.status.name == "CONVERGED"
    lin = forced_response(_tanh_accessory(), [20.0]).amplitudes(0.5)
    for key in ("tension[crankshaft-compressor]", "tension[pump-crankshaft]",
                "speed[alternator]"):
        per = res.periodic[key]
        assert 0.5 * (per["max"] - per["min"]) == pytest.approx(lin[key][0], rel=1e-2), key
