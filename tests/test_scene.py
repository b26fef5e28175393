"""Scene validation: every rule gives its own one-line error naming the key and the rule,
a ValueError from the API and exit status 2 without a traceback from the CLI."""

import copy
import math
import tomllib

import pytest

from beltsim.api import load_scene
from beltsim.errors import SceneError
from beltsim.problem.scene import SCHEMA, Scene
from beltsim.solvers.settings import resolve
from helpers import scene_path

pytestmark = pytest.mark.unit

with open(scene_path("paper_slip"), "rb") as fh:
    BASE = tomllib.load(fh)  # coulomb, inertia


def _with(path, value, base=BASE):
    d = copy.deepcopy(base)
    section, key = path.split(".")
    if value is _DELETE:
        del d[section][key]
    else:
        d.setdefault(section, {})[key] = value
    return d


_DELETE = object()


def _error(data):
    with pytest.raises(SceneError) as info:
        Scene.from_dict(data)
    msg = str(info.value)
    assert "\n" not in msg
    assert isinstance(info.value, ValueError)
    return msg


def test_paper_scenes_are_valid():
    for name in ("quasistatic", "inertia", "slip"):
        load_scene(scene_path(f"paper_{name}"))
    assert BASE["contact"]["start"] == 1 / 3 and BASE["contact"]["end"] == 2 / 3


def test_unknown_section_and_key():
    assert _error({**BASE, "extra": {"a": 1}}).startswith("extra: unknown section")
    assert _error(_with("beam.colour", 1.0)).startswith("beam.colour: unknown key")
    assert _error({**BASE, "title": 3}).startswith("title: must be a string")


@pytest.mark.parametrize("section", ["beam", "motion", "contact", "physics"])
def test_missing_section(section):
    d = copy.deepcopy(BASE)
    del d[section]
    assert _error(d) == f"[{section}]: missing section"


@pytest.mark.parametrize("key", [f"beam.{k}" for k in SCHEMA["beam"]]
                         + ["motion.belt_speed", "motion.surface_speed", "contact.start",
                            "contact.end", "contact.friction", "contact.max_friction",
                            "physics.inertia"])
def test_missing_key(key):
    assert _error(_with(key, _DELETE)).startswith(f"{key}: missing key")


POSITIVE = ([f"beam.{k}" for k in ("length", "height", "width", "youngs_modulus", "density",
                                    "shear_factor")]
            + ["motion.belt_speed", "motion.surface_speed", "contact.max_friction"]
            + [f"stiffness.{k}" for k in SCHEMA["stiffness"]])


@pytest.mark.parametrize("key", POSITIVE)
@pytest.mark.parametrize("value", [0.0, -1.0])
def test_non_positive(key, value):
    assert _error(_with(key, value)) == f"{key}: must be > 0, got {value!r}"


@pytest.mark.parametrize("key", POSITIVE + ["beam.poisson_ratio", "contact.start"])
@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf])
def test_non_finite(key, value):
    assert _error(_with(key, value)).startswith(f"{key}: must be finite")


@pytest.mark.parametrize("key, value, rule", [
    ("beam.length", "1 m", "must be a number"),
    ("beam.height", True, "must be a number"),
    ("physics.inertia", 1, "must be true or false"),
    ("contact.friction", "sticky", 'must be one of "stick" | "coulomb"'),
    ("contact.friction", 1.0, "must be a string"),
    ("numerics.elements", 10.5, "must be a whole number"),
])
def test_wrong_types(key, value, rule):
    assert rule in _error(_with(key, value))


@pytest.mark.parametrize("nu", [-1.0, 0.5, -1.5, 0.7])
def test_poisson_ratio_open_interval(nu):
    assert _error(_with("beam.poisson_ratio", nu)).startswith(
        "beam.poisson_ratio: must lie in the open interval (-1.0, 0.5)")


def test_contact_order_and_inside():
    msg = _error(_with("contact.start", 0.7))
    assert msg.startswith("contact.start: must be < contact.end")
    assert _error(_with("contact.start", 0.0)).startswith("contact.start/end: the contact "
                                                          "must lie inside the beam")
    assert _error(_with("contact.end", 1.0)).startswith("contact.start/end")


@pytest.mark.parametrize("speed, which", [(182.6, "tension"), (130.0, "bending"),
                                          (129.1, "bending")])
def test_critical_speeds(speed, which):
    """Both critical speeds quoted: sqrt(b1/rho) = 182.574, sqrt(a/I) = 129.099 m/s."""
    d = _with("motion.belt_speed", speed)
    b1, rho = 5e7 * 0.1 * 0.1, 1500 * 0.01
    a, inertia = 5e7 * 0.1 * 1e-3 / 12, 1500 * 0.01 * 0.02 / 12
    msg = _error(d)
    assert msg.startswith("motion.belt_speed: must stay below both critical speeds")
    assert f"{math.sqrt(b1 / rho):.6g}" in msg and f"{math.sqrt(a / inertia):.6g}" in msg
    # a quasistatic scene has no inertia terms, hence no critical speed
    Scene.from_dict(_with("physics.inertia", False, d))


def test_keys_a_scene_does_not_need():
    stick = _with("contact.friction", "stick")
    assert _error(stick).startswith('contact.max_friction: only for contact.friction = '
                                    '"coulomb"')
    assert _error(_with("contact.max_friction", _DELETE)).startswith(
        "contact.max_friction: missing key")
    qs = _with("physics.inertia", False)
    assert _error(_with("stiffness.mass", 10.0, qs)).startswith(
        "stiffness.mass: only for physics.inertia = true")
    assert _error(_with("numerics.adhesion_layer", 1e-6)).startswith(
        "numerics.adhesion_layer: only for contact.friction = \"stick\"")
    # the schemes' registry decides what a scheme needs, when the numerics are resolved
    with pytest.raises(SceneError, match='^numerics.integrator: "explicit" needs physics'):
        resolve(Scene.from_dict(_with("numerics.integrator", "explicit", qs)))
    # a quasistatic scene needs no density
    Scene.from_dict(_with("beam.density", _DELETE, qs))


def test_stiffness_overrides_take_effect():
    s = Scene.from_dict(_with("stiffness.shear", 1234.0))
    assert s.params.b2 == 1234.0
    assert s.params.b1 == 5e7 * 0.1 * 0.1


def test_set_overrides():
    s = load_scene(scene_path("paper_slip"), ["contact.max_friction=2e5",
                                             "contact.friction=coulomb"])
    assert s.params.fstar == 2e5


@pytest.mark.parametrize("assignment, message", [
    ("contact.nope=1", r"^contact\.nope: unknown key"),
    ("nope.x=1", r"^nope\.x: unknown section"),
    ("contact.max_friction=-5", r"^contact\.max_friction: must be > 0"),
    ("contact.max_friction=nan", r"^contact\.max_friction: must be finite"),
    ("contact.max_friction", r"expected SECTION\.KEY=VALUE"),
    ("beam.length=1..2", r"cannot parse value"),
])
def test_bad_set_overrides(assignment, message):
    with pytest.raises(SceneError, match=message):
        load_scene(scene_path("paper_slip"), [assignment])


def test_files(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[beam\nlength = 1\n")
    with pytest.raises(SceneError, match="malformed TOML"):
        load_scene(bad)
    with pytest.raises(SceneError, match="scene file not found"):
        load_scene(tmp_path / "missing.toml")
    with pytest.raises(SceneError, match="is a directory"):
        load_scene(tmp_path)
    binary = tmp_path / "bin.toml"
    binary.write_bytes(b"\xff\xfe\x00")
    with pytest.raises(SceneError, match="not a UTF-8"):
        load_scene(binary)


def test_round_trip_through_toml():
    s = load_scene(scene_path("paper_slip"), ["numerics.elements=300"])
    again = Scene(tomllib.loads(s.to_toml()))
    assert again.to_dict() == s.to_dict()


def test_shipped_scenes_load_by_name_and_match_their_files():
    import beltsim
    from helpers import scene_path
    names = beltsim.scene_names()
    assert {"paper_slip", "paper_inertia", "paper_quasistatic"} <= set(names)
    from beltsim.beltdrive import DriveScene
    for name in names:
        cls = DriveScene if name.startswith(("drive_", "serpentine_")) else beltsim.Scene
        assert (beltsim.load_scene(name).to_dict()
                == cls.load(scene_path(name)).to_dict())
    assert beltsim.paper_scene("slip").to_dict() == beltsim.load_scene("paper_slip").to_dict()
    with pytest.raises(beltsim.SceneError, match="not one of the paper's scenes"):
        beltsim.paper_scene("sliding")
    with pytest.raises(beltsim.MissingInputError, match="no scene of that name"):
        beltsim.load_scene("paper_slipp")


def test_a_study_whose_scenes_are_missing_fails(tmp_path, monkeypatch, capsys):
    """With the scene files hidden, the stability matrix stops with a one-line error and
    a non-zero exit instead of counting every cell as refused."""
    from beltsim.cli import main
    from beltsim.problem import shipped
    monkeypatch.setattr(shipped, "scenes_dir", lambda: None)
    assert main(["stability", "--elements", "60", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "no scene of that name" in err
    assert not (tmp_path / "o" / "stability.csv").exists()


@pytest.mark.cli  # and unit: a 60-element run
def test_the_cli_runs_a_shipped_scene_by_name(tmp_path):
    from helpers import cli
    proc = cli("run", "paper_quasistatic", "--set", "numerics.elements=60", "--quiet",
               "--out", tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "summary.json").is_file() and "converged       true" in proc.stdout


def test_a_drive_title_that_sizes_its_pulleys_says_radius_and_matches_the_file():
    """A pulley's size in a shipped drive's title reads as its radius (an engineer reads
    a bare "80 mm pulley" as a diameter), and the numbers are the scene's own."""
    import re

    import beltsim
    for name in beltsim.scene_names():
        data = beltsim.load_scene(name).to_dict()
        title = data.get("title", "")
        sizes = re.search(r"(\d+(?:\.\d+)?) / (\d+(?:\.\d+)?) mm", title)
        if "drive" not in data or sizes is None:
            continue
        assert re.search(r"radi(us|i) " + re.escape(sizes.group(0)), title), title
        radii = (data["drive"]["driver_radius"], data["drive"]["driven_radius"])
        assert tuple(float(s) / 1000 for s in sizes.groups()) == pytest.approx(radii), title
