"""The scene files shipped with beltsim, by name: the file's stem.

They live in ``runs/`` at the top of the repository, one copy each, which the build
installs as the package ``beltsim.scenes`` (pyproject.toml); this module finds them the
same way in a wheel and in an editable install. Which kind of scene a file holds is for
:func:`beltsim.load_scene` to decide: this module reads text.
"""

from __future__ import annotations

import difflib

from ..errors import MissingInputError, SceneError

#: The package the shipped scene files are installed as.
SCENES_PACKAGE = "beltsim.scenes"

#: The paper's three scenes, by the short name :func:`beltsim.paper_scene` also takes
#: (each is the shipped scene ``paper_<name>``).
PAPER_SCENES = ("quasistatic", "inertia", "slip")


def scenes_dir():
    """The folder of the shipped scene files, or None where the package was installed
    without them.

    Returns
    -------
    importlib.resources.abc.Traversable or None
    """
    from importlib.resources import files

    try:
        folder = files(SCENES_PACKAGE)
    except ModuleNotFoundError:
        return None  # installed without its scenes (or the folder removed)
    return folder if folder.is_dir() else None


def scene_names() -> tuple[str, ...]:
    """The names of the scenes shipped with beltsim, sorted.

    ``beltsim run NAME`` runs one, ``beltsim.load_scene(NAME)`` reads one; a name is its
    file's stem (``paper_slip``). None where the package was installed without them.

    Returns
    -------
    tuple of str
    """
    folder = scenes_dir()
    if folder is None:
        return ()
    return tuple(sorted(f.name[:-5] for f in folder.iterdir() if f.name.endswith(".toml")))


def shipped_text(name: str) -> str:
    """The text of the shipped scene file ``NAME.toml``.

    Parameters
    ----------
    name : str
        The scene's name, its file's stem (see :func:`beltsim.scene_names`).

    Returns
    -------
    str

    Raises
    ------
    MissingInputError
        No shipped scene has that name (or none is installed); the message lists the
        names that are, and the nearest one.
    """
    folder = scenes_dir()
    resource = None if folder is None else folder / f"{name}.toml"
    if resource is None or not resource.is_file():
        names = scene_names()
        near = difflib.get_close_matches(name, names, n=1, cutoff=0.5) or [
            n for n in names if n.endswith(f"_{name}")][:1]
        hint = f"; did you mean {near[0]!r}?" if near else ""
        raise MissingInputError(f"{name}: no scene of that name ships with beltsim "
                                f"(shipped: {', '.join(names) or 'none installed'}){hint}")
    return resource.read_text(encoding="utf-8")


def paper_scene_name(name: str) -> str:
    """The shipped scene's name of one of the paper's scenes.

    Parameters
    ----------
    name : str
        "quasistatic", "inertia" or "slip", or the shipped name itself
        ("paper_slip").

    Returns
    -------
    str
        The shipped name, ``paper_<name>``.

    Raises
    ------
    SceneError
        Not one of the paper's scenes.
    """
    short = name.removeprefix("paper_")
    if short not in PAPER_SCENES:
        known = ", ".join(f"{s} (paper_{s})" for s in PAPER_SCENES)
        raise SceneError(f"{name}: not one of the paper's scenes ({known})")
    return f"paper_{short}"
