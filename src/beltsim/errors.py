"""Exception types shared by the API and the CLI.

Every user-facing problem is one of these, so the CLI can map it to an exit
status and a one-line message without a traceback. Studies read their structured
parts (``SceneError.key``, ``NumericalError.kind``), never their messages.
"""

from __future__ import annotations

import enum


class BeltsimError(Exception):
    """Base class of beltsim's own errors."""


class SceneError(BeltsimError, ValueError):
    """A scene (file, key or value) breaks a rule; the message names key and rule.

    ``SceneError(key, rule)`` reads ``"key: rule"`` and keeps the key in ``key``
    (a scene key such as ``"numerics.max_work"``, which studies group refusals by);
    ``SceneError(message)`` is an error not about one key (a file that cannot be read),
    whose ``key`` is None.
    """

    def __init__(self, key_or_message: str, rule: str | None = None):
        if rule is None:
            super().__init__(key_or_message)
            self.key = None
        else:
            super().__init__(f"{key_or_message}: {rule}")
            self.key = key_or_message
        self._parts = (key_or_message, rule)

    def __reduce__(self):  # a worker process's error keeps its key
        return type(self), self._parts


class NoSolutionError(BeltsimError, ValueError):
    """The analytic problem has no admissible solution for this scene."""


class FailureKind(enum.Enum):
    """What stopped a run on a numerical failure (``NumericalError.kind``, and a
    failed run's ``RunResult.failure``); the value is what summary.json records."""

    #: a displacement or rotation became NaN or infinite
    NON_FINITE = "non-finite"
    #: the state grew beyond GROWTH_LIMIT times its scale (simulation.trackers)
    GREW = "grew"
    #: a time step's Newton iteration failed with the step cut to its floor
    NEWTON = "newton"
    #: the steady scheme's continuation failed: a stage in the speed mismatch fell below
    #: its floor, or the exact law's last stage from its regularised twin did not converge
    CONTINUATION = "continuation"

    @property
    def diverged(self) -> bool:
        """Whether the state itself ran away (not a solver's failure to take a step)."""
        return self in (FailureKind.NON_FINITE, FailureKind.GREW)


class NumericalError(BeltsimError, RuntimeError):
    """A run stopped on a numerical failure; ``kind`` is its
    :class:`~beltsim.errors.FailureKind`, ``t`` the simulated time and ``quantity`` the
    field concerned, where known."""

    def __init__(self, message: str, *, kind: FailureKind, t: float | None = None,
                 quantity: str | None = None):
        super().__init__(message)
        self.kind = kind
        self.t = t
        self.quantity = quantity

    def __reduce__(self):  # rebuilt with its keywords in another process
        return _numerical_error, (type(self), str(self), self.kind, self.t, self.quantity)


def _numerical_error(cls, message, kind, t, quantity):
    return cls(message, kind=kind, t=t, quantity=quantity)


class UsageError(BeltsimError, ValueError):
    """A command-line option has a bad value."""


class MissingInputError(BeltsimError, FileNotFoundError):
    """An input a command or study needs is not installed or not found (a shipped scene,
    a run directory's file); a study never counts a missing input as a pass."""
