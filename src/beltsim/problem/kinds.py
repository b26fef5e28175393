"""The two kinds of scene, told apart: a straight belt's
(:class:`~beltsim.problem.scene.Scene`) and a closed drive's
(:class:`~beltsim.beltdrive.scene.DriveScene`), from their tables or as objects.

Below :mod:`beltsim.api` (its entry points take either kind) and below the readers that
meet both kinds (a checkpoint holds a scene of either), this module loads the drive's
modules only for a drive.
"""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING

from .scene import Scene

if TYPE_CHECKING:
    from ..beltdrive.scene import DriveScene


def is_drive_data(data) -> bool:
    """Whether scene tables (a dict) describe a closed drive: they have a ``[drive]`` table."""
    return isinstance(data, dict) and "drive" in data


def is_drive_scene(scene) -> bool:
    """Whether a scene is a closed drive (a :class:`~beltsim.beltdrive.scene.DriveScene`)."""
    # A DriveScene exists only once its module is loaded; importing it for a straight
    # belt would cost numpy and scipy.
    drive = sys.modules.get("beltsim.beltdrive.scene")
    return drive is not None and isinstance(scene, drive.DriveScene)


def scene_from_tables(data: dict, source: str | None = None) -> Scene | DriveScene:
    """A scene from its tables: a closed drive where they have a ``[drive]`` section, a
    straight belt otherwise.

    Parameters
    ----------
    data : dict
        The scene as nested tables, as a scene file holds them (left unchanged).
    source : str, optional
        Where it came from, for messages.

    Returns
    -------
    Scene or DriveScene

    Raises
    ------
    SceneError
        On the first broken rule, naming the key and the rule.
    """
    if is_drive_data(data):
        from ..beltdrive.scene import DriveScene

        return DriveScene(data, source=source)
    return Scene(data, source=source)
