"""The shipped scenes live in runs/, one copy each, and the build installs them as the
package beltsim.scenes; pyproject.toml lists the packages, which must match src/."""

import tomllib
from importlib.resources import files

import pytest

import beltsim
from helpers import ROOT

pytestmark = pytest.mark.unit


def _pyproject():
    with open(ROOT / "pyproject.toml", "rb") as fh:
        return tomllib.load(fh)


def test_the_listed_packages_are_the_packages_in_src():
    """A package-dir mapping outside src/ needs the packages listed: a new subpackage
    left out of the list would be missing from the wheel."""
    listed = set(_pyproject()["tool"]["setuptools"]["packages"])
    found = {".".join(p.parent.relative_to(ROOT / "src").parts)
             for p in (ROOT / "src").rglob("__init__.py")}
    assert listed == found | {"beltsim.scenes"}


def test_the_scenes_package_maps_to_runs():
    config = _pyproject()["tool"]["setuptools"]
    assert config["package-dir"]["beltsim.scenes"] == "runs"
    assert config["package-data"]["beltsim.scenes"] == ["*.toml"]


def test_every_scene_in_runs_ships_and_only_once():
    stems = sorted(p.stem for p in (ROOT / "runs").glob("*.toml"))
    assert stems and list(beltsim.scene_names()) == stems
    for name in stems:  # the installed copy (a wheel's) or the file itself (editable)
        installed = files("beltsim.scenes") / f"{name}.toml"
        assert installed.read_bytes() == (ROOT / "runs" / f"{name}.toml").read_bytes()
    # no second copy in the package's sources
    assert not list((ROOT / "src").rglob("*.toml"))


def test_run_outputs_are_ignored_but_the_scenes_are_not():
    ignore = (ROOT / ".gitignore").read_text().split("\n")
    assert "runs/out/" in ignore and "runs/" not in ignore
