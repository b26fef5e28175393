"""The top-level API takes either kind of scene the same way: a straight belt (the
paper's slip scene) and a closed drive (drive_flat), by name, path or scene."""

import json

import pytest

import beltsim
from beltsim.beltdrive import DriveScene
from beltsim.errors import MissingInputError, SceneError, UsageError
from helpers import scene_path

pytestmark = pytest.mark.unit

#: name, class, a key to change and two values it may take, a tiny run's overrides
KINDS = {
    "paper_slip": (beltsim.Scene, "contact.max_friction", 2e5, 3e5,
                   {"numerics.elements": 60, "numerics.t_end": 0.005}),
    "drive_flat": (DriveScene, "drive.load_torque", 20.0, 30.0,
                   {"numerics.elements": 40, "numerics.t_end": 0.1}),
}
NAMES = list(KINDS)


def _value(scene, key):
    section, name = key.split(".")
    return scene.to_dict()[section][name]


@pytest.mark.parametrize("name", NAMES)
def test_load_scene_takes_the_file_stem_a_path_a_scene_and_tables(name):
    cls = KINDS[name][0]
    scene = beltsim.load_scene(name)
    assert type(scene) is cls and scene.source == name
    assert beltsim.shipped_scene(name) == scene
    assert beltsim.load_scene(scene_path(name)) == scene
    assert beltsim.load_scene(scene) is scene
    assert beltsim.load_scene(scene.to_dict()) == scene
    assert name in beltsim.scene_names()


@pytest.mark.parametrize("name", NAMES)
def test_a_name_that_is_not_a_stem_is_refused_naming_the_nearest(name):
    short = name.split("_", 1)[1]  # "slip", "flat": not a shipped scene's name
    with pytest.raises(MissingInputError, match=f"did you mean '{name}'"):
        beltsim.load_scene(short)


def test_the_paper_scenes_take_the_short_name_and_the_stem():
    for short in ("quasistatic", "inertia", "slip"):
        assert beltsim.paper_scene(short) == beltsim.paper_scene(f"paper_{short}") \
            == beltsim.load_scene(f"paper_{short}")
    with pytest.raises(SceneError, match="not one of the paper's scenes"):
        beltsim.paper_scene("drive_flat")


@pytest.mark.parametrize("name", NAMES)
def test_with_overrides_takes_a_dict_one_string_and_an_iterable(name):
    _, key, a, b, _ = KINDS[name]
    scene = beltsim.load_scene(name)
    by_dict = scene.with_overrides({key: a})
    assert _value(by_dict, key) == a and type(by_dict) is type(scene)
    assert scene.with_overrides(f"{key}={a}") == by_dict  # one string, one assignment
    assert scene.with_overrides([f"{key}={a}"]) == by_dict
    assert scene.with_overrides([(key, a)]) == by_dict
    assert scene.with_overrides({}) == scene and _value(scene, key) != a  # unchanged
    assert beltsim.load_scene(name, {key: b}) == scene.with_overrides({key: b})


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("bad, match", [
    ("nonsense", "expected SECTION.KEY=VALUE"),
    ([3], "a 'SECTION.KEY=VALUE' string or a \\(key, value\\) pair"),
    (3, "must be a dict"),
    ({"nosuch.key": 1.0}, "unknown section \\[nosuch\\]"),
])
def test_bad_overrides_give_a_one_line_value_error(name, bad, match):
    with pytest.raises(SceneError, match=match) as info:
        beltsim.load_scene(name).with_overrides(bad)
    assert isinstance(info.value, ValueError) and "\n" not in str(info.value)


@pytest.mark.parametrize("name", NAMES)
def test_replace_swaps_a_section_and_the_title(name):
    _, key, a, _, _ = KINDS[name]
    scene = beltsim.load_scene(name)
    section, k = key.split(".")
    table = scene.to_dict()[section] | {k: a}
    assert scene.replace(**{section: table}) == scene.with_overrides({key: a})
    renamed = scene.replace(title="another")
    assert renamed.title == "another" and renamed.replace(title=None).title == ""
    assert scene.replace(numerics=None).to_dict().get("numerics") is None
    with pytest.raises(SceneError, match="unknown section"):
        scene.replace(nosuch={})


def test_a_drive_section_must_be_a_table():
    with pytest.raises(SceneError, match=r"\[drive\]: must be a table"):
        beltsim.load_scene("drive_flat").replace(drive=3.0)


@pytest.mark.parametrize("name", NAMES)
def test_solve_gives_the_exact_steady_state_of_either_kind(name, tmp_path):
    scene = beltsim.load_scene(name)
    exact = beltsim.solve(name)
    assert exact.summary() == beltsim.solve(scene).summary()
    if isinstance(scene, DriveScene):
        # the very solution `beltsim analytic` writes (the beam's, and the creep theory)
        from beltsim.cli import main

        assert main(["analytic", name, "--out", str(tmp_path)]) == 0
        written = json.loads((tmp_path / "summary.json").read_text())
        assert json.loads(json.dumps(exact.summary())) == written["beam"]
        assert json.loads(json.dumps(beltsim.solve(scene, "string").summary())) \
            == written["string"]
        with pytest.raises(UsageError, match="model"):
            beltsim.solve(scene, "slip")
    else:
        from beltsim.problem import analytic

        assert isinstance(exact, beltsim.AnalyticSolution)
        assert exact.summary() == analytic.solve(scene).summary()
        assert beltsim.solve(scene, "stick").summary() == \
            analytic.solve(scene, "stick").summary()
        with pytest.raises(UsageError, match="model"):
            beltsim.solve(scene, "string")


@pytest.mark.parametrize("name", NAMES)
def test_run_takes_a_name_with_overrides(name):
    cls, key, a, _, tiny = KINDS[name]
    result = beltsim.run(name, overrides=tiny | {key: a})
    # one result type for every layout
    assert isinstance(result, beltsim.RunResult)
    assert result.scene == beltsim.load_scene(name, tiny | {key: a})
    assert result.status in (beltsim.RunStatus.CONVERGED, beltsim.RunStatus.REACHED_END)


def test_a_scene_of_neither_kind_is_refused():
    with pytest.raises(SceneError, match="must be a Scene, a DriveScene"):
        beltsim.run(3.0)
