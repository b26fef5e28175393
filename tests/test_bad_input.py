"""Bad input through the CLI: one line naming what is wrong, exit 2, no traceback, and no
partial outputs. Hypothesis drives valid scenes through the simulator at a coarse grid."""

import math
import subprocess
import sys

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import beltsim
from beltsim.api import paper_scene
from beltsim.simulation.result import RunStatus
from beltsim.studies.stability import steady_state_stability
from helpers import scene_path

PAPER = open(scene_path("paper_slip")).read()
DRIVE = open(scene_path("drive_flat")).read()

CORPUS = {
    "malformed": ("[beam\nlength = 1", "malformed TOML"),
    "wrong type": (PAPER.replace("length = 1.0", 'length = "one"'),
                   "beam.length: must be a number"),
    "nan": (PAPER.replace("height = 0.1", "height = nan"), "beam.height: must be finite"),
    "inf": (PAPER.replace("width = 0.1", "width = inf"), "beam.width: must be finite"),
    "unknown section": (PAPER + "\n[extras]\na = 1\n", "extras: unknown section"),
    "unknown key": (PAPER.replace("[motion]", "[motion]\nspeed = 3"), "motion.speed: unknown key"),
    "negative": (PAPER.replace("density = 1500.0", "density = -1500.0"),
                 "beam.density: must be > 0"),
    "poisson": (PAPER.replace("poisson_ratio = 0.45", "poisson_ratio = 0.5"), "beam.poisson_ratio"),
    "order": (PAPER.replace("start = 0.3333333333333333", "start = 0.9"),
              "contact.start: must be <"),
    "critical": (PAPER.replace("belt_speed = 120.0", "belt_speed = 150.0"), "critical speeds"),
    "stick with limit": (PAPER.replace('"coulomb"', '"stick"'), "contact.max_friction: only"),
    "missing key": (PAPER.replace("max_friction = 1.0e5", ""), "contact.max_friction: missing"),
    "empty": ("", "[beam]: missing section"),
    "table order": (PAPER.replace("surface_speed = 121.2",
                                  "surface_speed = [[0, 120], [0.1, 121], [0.1, 122]]"),
                    "motion.surface_speed row 3: times must increase strictly"),
    "table row": (PAPER.replace("surface_speed = 121.2", "surface_speed = [[0, 120, 1]]"),
                  "motion.surface_speed row 1: must be a [time, value] pair"),
    "table value": (PAPER.replace("max_friction = 1.0e5", "max_friction = [[0, 1e5], [1, 0]]"),
                    "contact.max_friction row 2 value: must be > 0"),
    "table nan": (PAPER.replace("max_friction = 1.0e5", "max_friction = [[nan, 1e5]]"),
                  "contact.max_friction row 1 time: must be finite"),
    "table critical": (PAPER.replace("surface_speed = 121.2",
                                     "surface_speed = [[0, 120], [1, 190]]"),
                       "motion.surface_speed: every speed of the profile must stay below"),
    "sine key": (PAPER.replace("surface_speed = 121.2",
                               "surface_speed = { mean = 121, amplitude = 1 }"),
                 "motion.surface_speed.period: missing key of a sine"),
    "sine sign": (PAPER.replace("max_friction = 1.0e5",
                                "max_friction = { mean = 1e5, amplitude = 2e5, period = 1 }"),
                  "contact.max_friction: must stay > 0"),
    "stick regularised law": (PAPER.replace('"coulomb"', '"stick"').replace(
        "max_friction = 1.0e5", "") + '\n[numerics]\nfriction_law = "tanh"\n',
        'numerics.friction_law: a "stick" scene takes only "exact"'),
    "exact with v_reg": (PAPER + '\n[numerics]\nfriction_law = "exact"\nregularisation = 1e-3\n',
                         'numerics.regularisation: not with numerics.friction_law = "exact"'),
    "unknown gyroscopic form": (PAPER + '\n[numerics]\ngyroscopic = "skew"\n',
                                'numerics.gyroscopic: must be one of "upwind" | "central"'),
    "explicit central": (PAPER + '\n[numerics]\ngyroscopic = "central"\n'
                         'integrator = "explicit"\n',
                         'numerics.gyroscopic: "central" is for the implicit schemes'),
    # the closed drive's layout, through the same command line
    "drive wrong type": (DRIVE.replace("driver_radius = 0.08", 'driver_radius = "small"'),
                         "drive.driver_radius: must be a number"),
    "drive overlap": (DRIVE.replace("centre_distance = 0.6", "centre_distance = 0.2"),
                      "drive.centre_distance"),
    "drive unknown key": (DRIVE.replace("[drive]", "[drive]\npulleys = 3"),
                          "drive.pulleys: unknown key"),
    "drive lift-off": (DRIVE.replace("installation_tension = 600.0",
                                     "installation_tension = 5.0"),
                       "drive.installation_tension"),
    "drive table order": (DRIVE.replace("load_torque = 50.0",
                                        "load_torque = [[0, 1], [0, 2]]"),
                          "drive.load_torque row 2"),
    "drive nan": (DRIVE.replace("density = 1200.0", "density = nan"),
                  "belt.density: must be finite"),
}


class _Proc:
    def __init__(self, returncode, stderr):
        self.returncode, self.stderr = returncode, stderr


@pytest.fixture
def _cli(capsys):
    """The CLI in-process (main() returns the exit status; argparse errors exit)."""
    from beltsim.cli import main

    def call(*args):
        try:
            code = main(list(args))
        except SystemExit as exc:
            code = exc.code
        return _Proc(code, capsys.readouterr().err)
    return call


def _subprocess(*args):
    return subprocess.run([sys.executable, "-m", "beltsim.cli", *args], capture_output=True,
                          text=True, timeout=300)


def _assert_clean_error(proc, fragment, out_dir=None):
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.count("\n") == 1, proc.stderr
    assert "Traceback" not in proc.stderr and fragment in proc.stderr
    if out_dir is not None:
        assert not out_dir.exists() or not any(out_dir.iterdir())


@pytest.mark.cli
@pytest.mark.parametrize("case", ["malformed", "critical"])
def test_corpus_in_a_real_process(tmp_path, case):
    """Exit status and stderr as a shell sees them."""
    text, fragment = CORPUS[case]
    scene = tmp_path / "scene.toml"
    scene.write_text(text)
    out = tmp_path / "out"
    _assert_clean_error(_subprocess("run", str(scene), "--out", str(out)), fragment, out)


@pytest.mark.unit
@pytest.mark.parametrize("case", sorted(CORPUS))
@pytest.mark.parametrize("command", ["run", "analytic"])
def test_corpus(tmp_path, _cli, case, command):
    text, fragment = CORPUS[case]
    scene = tmp_path / "scene.toml"
    scene.write_text(text)
    out = tmp_path / "out"
    _assert_clean_error(_cli(command, str(scene), "--out", str(out)), fragment, out)


@pytest.mark.unit
def test_missing_and_unreadable_files(tmp_path, _cli):
    out = tmp_path / "out"
    _assert_clean_error(_cli("run", str(tmp_path / "nope.toml"), "--out", str(out)),
                        "not found", out)
    _assert_clean_error(_cli("run", str(tmp_path), "--out", str(out)), "is a directory", out)
    link = tmp_path / "dangling.toml"
    link.symlink_to(tmp_path / "gone.toml")
    _assert_clean_error(_cli("analytic", str(link), "--out", str(out)), "not found", out)


@pytest.mark.unit
@pytest.mark.parametrize("assignment, fragment", [
    ("contact.nope=1", "contact.nope: unknown key"),
    ("nope.x=1", "unknown section"),
    ("beam.length=-2", "beam.length: must be > 0"),
    ("beam.length=1..2", "cannot parse"),
    ("numerics.elements=3", "numerics.elements: must be >= 6"),
    ("numerics.integrator=rk4", "numerics.integrator: must be one of"),
    ("contact.max_friction", "expected SECTION.KEY=VALUE"),
    ("motion.surface_speed=120.000000000001", "motion.surface_speed: |v/c - 1|"),
    ("numerics.regularisation=1e-14", "numerics.regularisation: must be >="),
])
def test_bad_set(tmp_path, _cli, assignment, fragment):
    out = tmp_path / "out"
    _assert_clean_error(_cli("run", scene_path("paper_slip"), "--set", assignment, "--out",
                             str(out)), fragment, out)


@pytest.mark.unit
def test_output_directory_that_cannot_be_written(tmp_path, _cli):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    _assert_clean_error(_cli("run", scene_path("paper_slip"), "--out", str(blocker / "sub")),
                        "--out")
    _assert_clean_error(_cli("analytic", scene_path("paper_slip"), "--out", str(blocker)),
                        "exists and is not a directory")


@pytest.mark.cli
def test_bad_options(tmp_path, _cli):
    _assert_clean_error(_cli("convergence", scene_path("paper_slip"), "--ladder", "10,x"),
                        "--ladder")
    _assert_clean_error(_cli("sweep", scene_path("paper_slip"), "--vary", "beam.length"),
                        "--vary")
    _assert_clean_error(_cli("run"), "give a SCENE")
    _assert_clean_error(_cli("run", "--resume", str(tmp_path)), "cannot read checkpoint")
    proc = _subprocess("frobnicate")
    assert proc.returncode == 2 and "Traceback" not in proc.stderr


@pytest.mark.verification
@settings(max_examples=15, deadline=None)
@given(L=st.floats(0.6, 2.0), x1f=st.floats(0.15, 0.4), x2f=st.floats(0.55, 0.85),
       cfrac=st.floats(0.1, 0.9), e0=st.floats(-0.02, 0.02), logf=st.floats(4.3, 6.5),
       inertia=st.booleans())
def test_valid_scenes_converge_within_bounds_unless_they_flutter(L, x1f, x2f, cfrac, e0, logf,
                                                                inertia):
    """Across the valid ranges every scene runs: converged within the bounds for a coarse
    grid, with an analytic state to compare with; never NaN, never a silent wrong number.
    A valid scene may flutter (e.g. L = 0.625 m, contact over [0.25, 0.625] L, c at 0.75
    of the critical speed, e0 = 1/64, f* = 1e6: a 206 Hz mode grows at 5.4 1/s): a run
    that does not settle must reach t_end and have a linearly unstable steady state.
    A mismatch below 1e-8 is refused by rule (round-off of v - c), so it is not drawn."""
    assume(abs(e0) >= 1e-6)
    P0 = paper_scene("slip").params
    c = cfrac * min(math.sqrt(P0.b1 / P0.rho), math.sqrt(P0.a / P0.I))
    scene = paper_scene("slip", [
        ("beam.length", L), ("contact.start", x1f * L), ("contact.end", x2f * L),
        ("motion.belt_speed", c), ("motion.surface_speed", c * (1 + e0)),
        ("contact.max_friction", 10 ** logf), ("physics.inertia", inertia),
        ("numerics.elements", 400)])
    result = beltsim.run(scene, raise_on_failure=False)
    if not result.converged:
        unstable, why, _ = steady_state_stability(scene)
        assert result.status is RunStatus.REACHED_END and unstable, (result.reason, why)
        return
    err = result.errors()
    # scenes drawn across the valid ranges, so no one measurement: the acceptance bounds
    # of the simulator (0.5% friction, 2% u) widened 2.5x for 400 elements, about
    # (600 / 400)^2 times the default grid's second-order error
    assert err["total_friction"] < 0.0125 and err["u"] < 0.05
    assert err["slip_start"] < 0.0125 * L


@pytest.mark.cli
def test_python_dash_m_beltsim_is_the_command():
    proc = subprocess.run([sys.executable, "-m", "beltsim", "run", "missing.toml"],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2
    assert proc.stderr.startswith("beltsim: error:") and "Traceback" not in proc.stderr
