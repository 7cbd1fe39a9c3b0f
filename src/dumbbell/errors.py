"""Errors that the command line turns into one clear line and exit status 2."""

from __future__ import annotations


class DumbbellError(Exception):
    """Base class of the errors that are the user's to fix (exit status 2)."""


class SceneError(DumbbellError, ValueError):
    """A scene file or value is not valid.

    The message names the file, the dotted key and what is allowed, e.g.
    ``scenes/a.toml: spring.stiffness = -1: must be a finite number >= 0 (N/m)``.
    """


class UsageError(DumbbellError, ValueError):
    """An API argument (or the command-line flag that sets it) is not valid.

    Library code names the parameter and starts the message with it, e.g.
    ``UsageError("window = -1: must be a finite number > 0 (s)", param="window")``; the
    command line shows the flag instead (``--window = -1: ...``)."""

    def __init__(self, message: str, param: str | None = None):
        super().__init__(message)
        self.param = param


class ColumnError(UsageError, KeyError):
    """A trajectory column asked for by a name it does not have (also a ``KeyError``, as
    for a dict): ``traj["nope"]`` names the column and lists the columns there are."""

    def __str__(self) -> str:  # KeyError's own would quote the message
        return str(self.args[0]) if self.args else ""


class MissingExtraError(DumbbellError, ImportError):
    """An optional dependency is not installed; the message names the extra that brings it,
    e.g. ``to_pandas() needs pandas: pip install 'dumbbell[pandas]'``."""
