"""The stability map (beltsim.studies.stability_map) and its command, ``beltsim
stability-map``: the bisection on d against a rate known in closed form, points without a
steady state recorded as such, bad input refused with one line and exit status 2, and the
critical damping of paper_slip checked by independent root searches either side."""

import csv
import subprocess
import sys

import numpy as np
import pytest

import beltsim
from beltsim.errors import NoSolutionError, UsageError
from beltsim.simulation import stability
from beltsim.simulation.stability import Stability, exact_least_stable
from beltsim.studies import stability_map as study


def _fake_rate(monkeypatch, rate_of_d, calls=None):
    """exact_least_stable replaced by a rate known in closed form (no root search)."""
    def fake(scene, notice=None):
        d = scene.params.damping
        if calls is not None:
            calls.append(d)
        r = rate_of_d(d)
        if r is None:
            raise NoSolutionError("slip solution: no admissible slip start (a test's)")
        return Stability(rate=r, frequency=1000.0, method="exact", band=3000.0,
                         growing=int(r > 0))
    monkeypatch.setattr(stability, "exact_least_stable", fake)


@pytest.mark.unit
@pytest.mark.parametrize("crossing", [7.3, 57.0, 1234.5])
def test_the_bisection_brackets_a_linear_rates_zero_within_the_tolerance(monkeypatch,
                                                                          crossing):
    _fake_rate(monkeypatch, lambda d: 0.1 * (crossing - d))
    crit = study.critical_damping(beltsim.load_scene("paper_slip"), tol=0.5)
    assert crit.lower < crossing <= crit.damping
    assert crit.damping - crit.lower <= 0.5
    rates = {r["value"]: r["rate"] for r in crit.evaluations}
    assert rates[crit.lower] > 0.0 >= rates[crit.damping]
    assert "critical damping d =" in crit.describe()


@pytest.mark.unit
def test_a_stable_undamped_state_needs_no_damping_and_a_hopeless_one_has_none(monkeypatch):
    scene = beltsim.load_scene("paper_slip")
    _fake_rate(monkeypatch, lambda d: -1.0 - d)
    crit = study.critical_damping(scene)
    assert crit.damping == 0.0 and crit.lower is None
    assert [r["value"] for r in crit.evaluations] == [39.0, 0.0]
    _fake_rate(monkeypatch, lambda d: 5.0)
    crit = study.critical_damping(scene, max_damping=1000.0)
    assert crit.damping is None and "still > 0" in crit.reason


@pytest.mark.unit
def test_no_steady_state_is_recorded_as_such_never_as_a_number(monkeypatch):
    scene = beltsim.load_scene("paper_slip")
    _fake_rate(monkeypatch, lambda d: None if d > 50 else 1.0)
    rows = study.sweep(scene, "damping", [10.0, 60.0])
    assert rows[0]["status"] == study.UNSTABLE and rows[0]["rate"] == 1.0
    assert rows[1]["status"] == study.NO_STEADY_STATE
    assert rows[1]["rate"] is rows[1]["frequency"] is rows[1]["growing"] is None
    assert "no admissible slip start" in rows[1]["reason"]
    _fake_rate(monkeypatch, lambda d: None)
    crit = study.critical_damping(scene)
    assert crit.damping is None and crit.reason.startswith(study.NO_STEADY_STATE)


@pytest.mark.unit
def test_the_cli_writes_a_point_without_a_steady_state_as_its_status_and_exits_1(
        monkeypatch, tmp_path, capsys):
    from beltsim.cli import main

    _fake_rate(monkeypatch, lambda d: None if d > 50 else -2.0)
    assert main(["stability-map", "paper_slip", "--values", "10,60", "--out",
                 str(tmp_path)]) == 1
    captured = capsys.readouterr()
    assert "no steady state" in captured.out
    assert "damping = 60: no steady state" in captured.err
    with open(tmp_path / "stability_map.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert [r["status"] for r in rows] == ["stable", "no steady state"]
    assert rows[0]["rate"] == "-2.0" and rows[1]["rate"] == "nan"


@pytest.mark.unit
def test_the_belt_speed_moves_the_surface_speed_at_the_scenes_slip_ratio():
    scene = beltsim.load_scene("paper_slip")
    keys = dict(study.overrides(scene, "belt_speed", 100.0))
    assert keys["motion.belt_speed"] == 100.0
    assert keys["motion.surface_speed"] == pytest.approx(101.0, rel=1e-14)
    assert study.overrides(scene, "max_friction", 3e4) == [("contact.max_friction", 3e4)]


@pytest.mark.unit
@pytest.mark.parametrize("name, param, fragment", [
    ("paper_inertia", "max_friction", "perfect adhesion"),
    ("paper_quasistatic", "damping", "must be inertial"),
    ("drive_flat", "max_friction", "not a parameter of a closed drive's map"),
    ("serpentine_accessory", "belt_speed", "not a parameter of a closed drive's map"),
    ("paper_slip", "friction_coefficient", "not a parameter of a straight belt's map"),
    ("paper_slip", "stiffness", "not a parameter of a straight belt's map"),
])
def test_scenes_and_parameters_a_map_cannot_take_are_refused(name, param, fragment):
    with pytest.raises(UsageError, match=fragment):
        study.check_scene(beltsim.load_scene(name), param)


@pytest.mark.unit
@pytest.mark.parametrize("name, param, key", [
    ("drive_flat", "driver_speed", "drive.driver_speed"),
    ("serpentine_accessory", "driver_speed", "pulley.crankshaft.speed"),
    ("serpentine_accessory", "friction_coefficient", "contact.friction_coefficient"),
    ("serpentine_accessory", "damping", "physics.damping"),
])
def test_a_drives_parameters_set_their_keys(name, param, key):
    scene = beltsim.load_scene(name)
    assert study.overrides(scene, param, 0.45) == [(key, 0.45)]
    assert study.default_values(scene, param) == study.DRIVE_DEFAULT_VALUES[param]


@pytest.mark.unit
@pytest.mark.parametrize("name, key", [("drive_flat", "drive.driver_speed"),
                                       ("serpentine_accessory", "pulley.crankshaft.speed")])
def test_a_drivers_speed_given_as_a_table_is_not_mapped(name, key):
    scene = beltsim.load_scene(name).with_overrides({key: [[0.0, 10.0], [0.2, 150.0]]})
    with pytest.raises(UsageError, match="driver's speed must be a number"):
        study.check_scene(scene, "driver_speed")
    study.check_scene(scene, "damping")


@pytest.mark.verification
@pytest.mark.parametrize("name, param, value", [
    ("drive_flat", "damping", 5.0),
    ("drive_flat", "friction_coefficient", 0.3),
    ("serpentine_machine", "driver_speed", 100.0),
])
def test_a_drives_point_is_the_rightmost_eigenvalue_of_its_band(tmp_path, monkeypatch,
                                                                name, param, value):
    """A drive has no exact spectrum: its point is the sparse sweep's rightmost eigenvalue
    of the central form on the scene's grid, for Im lambda up to SWEEP_REACH times the
    grid's highest axial frequency; here against every eigenvalue of that band by the QZ
    algorithm (dense) on that grid, with the value set by its own key. The two
    eigen-solvers agree to 5e-7 abs(lambda): QZ is backward stable, but on these
    non-normal pencils an eigenvalue's condition number (~1e9) lifts its round-off (2e-16
    of the pencil's norm) to about that; drive_flat's near-neutral mode at 3.3 kHz took
    rates 0.0997 and 0.0969 1/s from QZ in two runs, 0.0991 from the sparse search in
    both. Above the band the central form has grid-scale eigenvalues (their frequency
    doubles with the grid) that the sweep leaves out by design."""
    from beltsim.physics import modes
    from beltsim.physics.shift_invert import SWEEP_REACH
    from beltsim.solvers.linearise import highest_frequency

    monkeypatch.setenv("BELTSIM_CACHE_DIR", str(tmp_path))
    scene = beltsim.load_scene(name).with_overrides({"numerics.elements": 60})
    row = study.point(scene, param, value)
    key = dict(study.overrides(scene, param, value))
    disc, state = modes.steady_discretisation(
        scene.with_overrides({**key, "numerics.gyroscopic": "central"}))
    lam = modes.spectrum(disc, state)
    band = lam[np.abs(lam.imag) <= SWEEP_REACH * highest_frequency(disc)]
    top = band[np.argmax(band.real)]
    assert row["rate"] == pytest.approx(top.real, abs=5e-7 * abs(top))
    assert row["frequency"] == pytest.approx(abs(top.imag) / (2 * np.pi), rel=1e-7)
    assert row["error"] is not None and row["error"] >= 0.0
    if abs(row["rate"]) > row["error"]:
        assert row["status"] == (study.UNSTABLE if row["rate"] > 0 else study.STABLE)
    else:
        assert row["status"] == study.UNDECIDED


@pytest.fixture
def _cli(capsys):
    from beltsim.cli import main

    def call(*args):
        try:
            code = main(["stability-map", *args])
        except SystemExit as exc:
            code = exc.code
        return code, capsys.readouterr().err
    return call


@pytest.mark.unit
@pytest.mark.parametrize("args, fragment", [
    (("paper_slip", "--values", "1,x"), "--values: expected comma-separated numbers"),
    (("paper_slip", "--values", ""), "--values: expected comma-separated finite"),
    (("paper_slip", "--values", "nan"), "--values: expected comma-separated finite"),
    (("paper_slip", "--values", "-5"), "--values: physics.damping: must be >= 0"),
    (("paper_slip", "--param", "belt_speed", "--values", "130"),
     "--values: motion.belt_speed: must stay below both critical speeds"),
    (("paper_slip", "--param", "stiffness"), "argument --param: invalid choice"),
    (("paper_slip", "--param", "driver_speed"), "not a parameter of a straight belt's map"),
    (("drive_flat", "--param", "belt_speed"), "not a parameter of a closed drive's map"),
    (("drive_flat", "--param", "friction_coefficient", "--values", "-0.1"),
     "--values: contact.friction_coefficient: must be > 0"),
    (("paper_inertia", "--param", "max_friction"), "--param max_friction"),
    (("paper_slip", "--tol", "0"), "--tol: must be > 0"),
    (("paper_slip", "--tol", "many"), "argument --tol: invalid float value"),
    (("paper_slip", "--set", "physics.damping=-1"), "physics.damping: must be >= 0"),
])
def test_bad_input_is_one_line_and_exit_2_with_no_outputs(tmp_path, _cli, args, fragment):
    out = tmp_path / "out"
    code, err = _cli(*args, "--out", str(out))
    assert code == 2, err
    assert err.count("\n") == 1 and "Traceback" not in err and fragment in err, err
    assert not out.exists()


@pytest.mark.cli
def test_bad_input_in_a_real_process():
    proc = subprocess.run([sys.executable, "-m", "beltsim", "stability-map", "paper_slip",
                           "--values", "39,,abc"], capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "--values" in proc.stderr


@pytest.mark.verification
def test_a_point_is_the_exact_least_stable_root(tmp_path, monkeypatch):
    """paper_slip at its own d: the root the spectrum page lists (+9.39 1/s, 1302.9 Hz)."""
    monkeypatch.setenv("BELTSIM_CACHE_DIR", str(tmp_path))
    row = study.point(beltsim.load_scene("paper_slip"), "damping", 39.0)
    assert row["status"] == study.UNSTABLE and not row["cached"]
    assert row["rate"] == pytest.approx(9.3875, abs=1e-3)
    assert row["frequency"] == pytest.approx(1302.89, abs=0.01)
    assert study.point(beltsim.load_scene("paper_slip"), "damping", 39.0)["cached"]


@pytest.mark.verification
@pytest.mark.long
def test_the_critical_damping_brackets_a_sign_change(tmp_path, monkeypatch):
    """rate(d_crit - tol) > 0 >= rate(d_crit + tol), each by its own root search in an
    empty cache, not read from the bisection's."""
    scene = beltsim.load_scene("paper_slip")
    monkeypatch.setenv("BELTSIM_CACHE_DIR", str(tmp_path / "bisection"))
    crit = study.critical_damping(scene, tol=study.TOLERANCE)
    assert crit.damping is not None and crit.damping - crit.lower <= study.TOLERANCE
    assert 39.0 < crit.damping < 300.0
    monkeypatch.setenv("BELTSIM_CACHE_DIR", str(tmp_path / "check"))
    tol = study.TOLERANCE
    below = exact_least_stable(scene.with_overrides({"physics.damping": crit.damping - tol}))
    above = exact_least_stable(scene.with_overrides({"physics.damping": crit.damping + tol}))
    assert below.rate > 0.0 > above.rate, (crit.damping, below, above)


@pytest.mark.verification
def test_beltsim_modes_says_how_much_damping_removes_a_growing_mode(tmp_path, monkeypatch,
                                                                    capsys):
    """drive_flat undamped with the central form on 60 elements: its least stable mode
    grows (+2.6 1/s at 3.3 kHz); the damping the command names is checked by the map's
    points either side of it, each from an empty cache."""
    import re

    from beltsim.cli import main

    monkeypatch.setenv("BELTSIM_CACHE_DIR", str(tmp_path / "modes"))
    sets = ["--set", "physics.damping=0", "--set", "numerics.gyroscopic=central"]
    assert main(["modes", "drive_flat", *sets, "--elements", "60",
                 "--out", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    assert "(grows)" in out
    found = re.search(r"physics\.damping = ([0-9.]+) 1/s removes it .* at ([0-9.]+) 1/s it "
                      r"still grows", out)
    assert found, out
    d_crit, d_low = float(found.group(1)), float(found.group(2))
    assert 0.0 < d_crit - d_low <= study.TOLERANCE
    monkeypatch.setenv("BELTSIM_CACHE_DIR", str(tmp_path / "check"))
    scene = beltsim.load_scene("drive_flat").with_overrides(
        {"physics.damping": 0.0, "numerics.gyroscopic": "central", "numerics.elements": 60})
    assert study.point(scene, "damping", d_crit)["rate"] <= 0.0
    assert study.point(scene, "damping", d_low)["rate"] > 0.0
