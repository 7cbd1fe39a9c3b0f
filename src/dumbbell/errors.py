"""Errors that the command line turns into one clear line and exit status 2."""

from __future__ import annotations

import string
from collections.abc import Callable, Mapping, Sequence


class DumbbellError(Exception):
    """Base class of the errors that are the user's to fix (exit status 2): catch this one to
    catch them all. Its message is one line naming what to change.

    Examples
    --------
    >>> import dumbbell
    >>> try:
    ...     dumbbell.load_scene("nowhere.toml")
    ... except dumbbell.DumbbellError as error:
    ...     print(type(error).__name__, "-", error)
    SceneError - nowhere.toml: no such scene file
    """


class SceneError(DumbbellError, ValueError):
    """A scene file or value is not valid.

    The message names the file, the dotted key and what is allowed, e.g.
    ``scenes/a.toml: spring.stiffness = -1: must be a finite number >= 0 (N/m)``.

    Examples
    --------
    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "textbook-1d.toml")
    >>> scene.with_values({"spring.stiffnes": 1.0})
    Traceback (most recent call last):
    ...
    dumbbell.errors.SceneError: ...textbook-1d.toml: unknown key 'spring.stiffnes' in [spring]; allowed: rest_length, stiffness
    """


class UsageError(DumbbellError, ValueError):
    """An API argument (or the command-line flag that sets it) is not valid.

    Library code names the parameter and starts the message with it, e.g.
    ``UsageError("window = -1: must be a finite number > 0 (s)", param="window")``; the
    command line shows the flag instead (``--window = -1: ...``).

    ``fixes`` are the ways out, each a phrase naming the parameters to change in braces:
    ``fixes=("keep fewer with a larger {every}", "raise the budget {max_samples}")`` ends the
    message with ``: keep fewer with a larger every or raise the budget max_samples``. The
    command line names its own flags there instead (:meth:`text`), and leaves out a way that
    needs a parameter the command cannot set.

    Parameters
    ----------
    message : str
        What is wrong, starting with the parameter: ``"window = -1: must be ..."``.
    param : str or None, default None
        The parameter's name, kept as :attr:`param`.
    fixes : sequence of str, default ()
        The ways out, parameters in braces.

    Examples
    --------
    >>> from dumbbell import UsageError
    >>> error = UsageError("every = 1: too many samples", param="every",
    ...                    fixes=("keep fewer with a larger {every}", "raise {max_samples}"))
    >>> str(error)
    'every = 1: too many samples: keep fewer with a larger every or raise max_samples'
    >>> error.text({"every": "--every", "max_samples": None}.get)   # as a command says it
    'every = 1: too many samples: keep fewer with a larger --every'
    >>> str(error.named({"every": "run.every"}))                     # as a scene says it
    'every = 1: too many samples: keep fewer with a larger run.every or raise max_samples'
    """

    def __init__(self, message: str, param: str | None = None, fixes: Sequence[str] = ()):
        self.reason = message
        self.param = param
        self.fixes = tuple(fixes)
        super().__init__(self.text())

    def text(self, name: Callable[[str], str | None] = str) -> str:
        """The message with every parameter of :attr:`fixes` spelt ``name(parameter)``; a fix
        with a parameter whose name is None is left out.

        Parameters
        ----------
        name : callable, default str
            Parameter -> how to spell it (a flag), or None to leave out the fixes that need
            it.

        Returns
        -------
        str
            The message and the ways out that remain.
        """
        ways = []
        for fix in self.fixes:
            params = [p for _, p, _, _ in string.Formatter().parse(fix) if p]
            names = {p: name(p) for p in params}
            if all(n is not None for n in names.values()):
                ways.append(fix.format_map(names))
        if not ways:
            return self.reason
        last = ways.pop()
        return f"{self.reason}: {', '.join(ways) + ' or ' if ways else ''}{last}"

    def named(self, names: Mapping[str, str]) -> UsageError:
        """The same error with the parameters in ``names`` spelt as given there, for good:
        a caller that knows where a value came from (a scene key) says so.

        Parameters
        ----------
        names : mapping of str to str
            Parameter -> its spelling.

        Returns
        -------
        UsageError
            A new error; this one is left as it is.
        """
        fixes = [fix.format_map(_Keep(names)) for fix in self.fixes]
        return UsageError(self.reason, self.param, fixes)


class _Keep(dict):
    """format_map's mapping that leaves a placeholder it has no name for as it was."""

    def __missing__(self, key: str) -> str:
        return "{" + key + "}"


class ColumnError(UsageError, KeyError):
    """A trajectory column asked for by a name it does not have (also a ``KeyError``, as
    for a dict): ``traj["nope"]`` names the column and lists the columns there are.

    Parameters
    ----------
    message : str
        What is wrong.
    param : str or None, default None
        The parameter's name.
    fixes : sequence of str, default ()
        The ways out, as :class:`UsageError` takes them.

    Examples
    --------
    A 1D run asked for a column only 2D runs have:

    >>> import dumbbell
    >>> from dumbbell.model.scene import scenes_dir
    >>> scene = dumbbell.load_scene(scenes_dir() / "textbook-1d.toml")
    >>> traj = dumbbell.simulate(scene, solver="exact", t_end=0.1, dt=1e-3)
    >>> try:
    ...     traj["K_rot"]                         # a 1D run has no rotation
    ... except KeyError as error:
    ...     print(error)
    name = 'K_rot': no such column; columns are t, xA, vA, xB, vB, K_cm, K_int, U_g, U_spring, E
    """

    def __str__(self) -> str:  # KeyError's own would quote the message
        return str(self.args[0]) if self.args else ""


class MissingExtraError(DumbbellError, ImportError):
    """An optional dependency is not installed; the message names the extra that brings it,
    e.g. ``to_pandas() needs pandas: pip install 'dumbbell[pandas]'``. It is also an
    ``ImportError``.

    Examples
    --------
    >>> import dumbbell
    >>> issubclass(dumbbell.MissingExtraError, ImportError)
    True
    """


class PymunkVersionError(DumbbellError, ImportError):
    """The installed pymunk is a release dumbbell does not run on. Raised at the first use of
    pymunk (the pymunk solver, the first name read from ``dumbbell.spaces``); the message
    names the installed version and the supported range, e.g. ``pymunk 6.11.1 is installed;
    dumbbell needs pymunk>=7.0,<8: pip install 'pymunk>=7.0,<8'``.

    Parameters
    ----------
    message : str
        The line shown.
    version : str
        The installed pymunk's version, kept as :attr:`version`.
    supported : str
        The range dumbbell runs on, kept as :attr:`supported`.

    Examples
    --------
    >>> from dumbbell import PymunkVersionError
    >>> error = PymunkVersionError("pymunk 6.11.1 is installed; dumbbell needs pymunk>=7.0,<8",
    ...                            "6.11.1", ">=7.0,<8")
    >>> error.version, error.supported, isinstance(error, ImportError)
    ('6.11.1', '>=7.0,<8', True)
    """

    def __init__(self, message: str, version: str, supported: str):
        self.version = version
        self.supported = supported
        super().__init__(message)
