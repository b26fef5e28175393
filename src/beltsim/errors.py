"""Exception types shared by the API and the CLI.

Every user-facing problem is one of these, so the CLI can map it to an exit
status and a one-line message without a traceback.
"""


class BeltsimError(Exception):
    """Base class of beltsim's own errors."""


class SceneError(BeltsimError, ValueError):
    """A scene (file, key or value) breaks a rule; the message names key and rule."""


class NoSolutionError(BeltsimError, ValueError):
    """The analytic problem has no admissible solution for this scene."""


class NumericalError(BeltsimError, RuntimeError):
    """A run stopped on a numerical failure (non-finite values, divergence, Newton failure)."""

    def __init__(self, message, t=None, quantity=None):
        super().__init__(message)
        self.t = t
        self.quantity = quantity


class UsageError(BeltsimError, ValueError):
    """A command-line option has a bad value."""


class MissingInputError(BeltsimError, FileNotFoundError):
    """An input a command or study needs is not installed or not found (a shipped scene,
    a run directory's file); a study never counts a missing input as a pass."""
