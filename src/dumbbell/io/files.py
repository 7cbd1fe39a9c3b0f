"""Output files that appear whole or not at all.

Every output goes through :func:`atomic_output`: a regular file is written beside its final
name as a hidden ``.part`` file and renamed into place; a device, a FIFO (or anything else that
is not a regular file) is written directly, because a rename would replace it.

Inside :func:`output_transaction` (the command line opens one around each command) the renames
wait until the whole command has succeeded: a failure or a signal then leaves nothing behind,
not even the outputs that were already complete, and no output may land on an input or on
another output of the same command.
"""

from __future__ import annotations

import os
import stat
import tempfile
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from pathlib import Path

from ..errors import UsageError

__all__ = ["OutputTransaction", "atomic_output", "check_writable", "is_special",
           "output_transaction"]


def _inputs(inputs: object) -> list[tuple[str | Path, str]]:
    """``inputs`` as (path, how the user named it) pairs, else a UsageError."""
    from ..model import args

    allowed = "must be (path, name) pairs, e.g. [('x.toml', 'the scene x.toml')]"
    if isinstance(inputs, str | bytes) or not isinstance(inputs, Iterable):
        raise UsageError(f"inputs = {args.show(inputs)}: {allowed}", param="inputs")
    pairs = list(inputs)
    if not all(isinstance(p, tuple | list) and len(p) == 2 and isinstance(p[0], str | os.PathLike)
               and str(p[0]) and isinstance(p[1], str) for p in pairs):
        raise UsageError(f"inputs = {args.show(inputs)}: {allowed}", param="inputs")
    return [(p[0], p[1]) for p in pairs]


def _key(path: Path) -> str:
    """One spelling per file: symlinks, '..' and '.' resolved."""
    return os.path.realpath(path)


def is_special(path: str | Path) -> bool:
    """True when ``path`` exists and is neither a regular file nor a folder (a device, a FIFO,
    a socket): such an output is written directly, never replaced."""
    from ..model import args

    path = args.path(path, "path")
    try:
        mode = os.stat(path).st_mode
    except (OSError, ValueError):
        return False
    return not (stat.S_ISREG(mode) or stat.S_ISDIR(mode))


def _under_system(path: Path) -> bool:
    """True for a path in /dev or /proc (also through a link, as /dev/stdout is): written
    directly, since a temporary file and a rename there would replace a system entry."""
    for candidate in (os.path.abspath(path), os.path.realpath(path)):
        if candidate.startswith(("/dev/", "/proc/")):
            return True
    return False


class OutputTransaction:
    """The outputs of one command: claimed names, finished ``.part`` files waiting for their
    rename, folders created on the way (removed again if the command fails)."""

    def __init__(self, inputs: Iterable[tuple[str | Path, str]] = ()):
        #: real path -> how the user named it ("the scene x.toml", "-o x.csv").
        self.inputs = {_key(Path(p)): what for p, what in _inputs(inputs)}
        self.claimed: dict[str, str] = {}
        self.pending: list[tuple[Path, Path]] = []
        self.created: list[Path] = []

    def _same(self, key: str, among: dict[str, str]) -> str | None:
        """How ``among`` names the file ``key`` (same real path, or same inode), or None."""
        if key in among:
            return among[key]
        if os.path.exists(key):
            for other, what in among.items():
                try:
                    if os.path.exists(other) and os.path.samefile(other, key):
                        return what
                except OSError:
                    pass
        return None

    def claim(self, path: str | Path, what: str | None = None) -> None:
        """Check that the output ``path`` is no input; with ``what`` (how the user named it,
        e.g. '-o x.csv') also reserve it, refusing a second output on the same file."""
        from ..model import args

        path = args.path(path, "path")
        if what is not None:
            args.text(what, "what", "how the user named the output (str) or None")
        key = _key(path)
        label = what or str(path)
        clash = self._same(key, self.inputs) or (what and self._same(key, self.claimed))
        if clash:
            raise UsageError(f"{label}: is the same file as {clash}; give another name")
        if what:
            self.claimed[key] = what

    def commit(self) -> None:
        """Rename every finished output into place."""
        while self.pending:
            tmp, path = self.pending.pop(0)
            os.replace(tmp, path)
        self.created.clear()

    def rollback(self) -> None:
        """Remove every unfinished or uncommitted ``.part`` file and the folders made for
        them (only if empty)."""
        for tmp, _ in self.pending:
            tmp.unlink(missing_ok=True)
        self.pending.clear()
        for folder in reversed(self.created):
            try:
                folder.rmdir()
            except OSError:
                pass
        self.created.clear()


_active: ContextVar[OutputTransaction | None] = ContextVar("dumbbell_outputs", default=None)


@contextmanager
def output_transaction(inputs: Iterable[tuple[str | Path, str]] = ()
                       ) -> Iterator[OutputTransaction]:
    """Defer every :func:`atomic_output` rename inside the block to its successful end; on
    any exception (a KeyboardInterrupt or a signal too) remove the outputs instead.
    ``inputs``: (path, how to name it) pairs that no output may replace."""
    transaction = OutputTransaction(_inputs(inputs))
    token = _active.set(transaction)
    try:
        yield transaction
        transaction.commit()
    except BaseException:
        transaction.rollback()
        raise
    finally:
        _active.reset(token)


def _user_error(exc: OSError, path: Path, tmp: Path | None) -> OSError:
    """``exc`` naming ``path`` (the user's name) instead of the temporary file, or naming it
    at all when the write error carried no file name."""
    name = exc.filename
    if name is None or (tmp is not None and Path(os.fsdecode(name)) == tmp) \
            or Path(os.fsdecode(name)).name.startswith(f".{path.name}."):
        new = OSError(exc.errno, exc.strerror or str(exc), str(path))
        return new
    return exc


@contextmanager
def atomic_output(path: str | Path) -> Iterator[Path]:
    """Yield the path to write for the output ``path``: a temporary file beside it, renamed to
    ``path`` only if the block succeeds (and, inside :func:`output_transaction`, only once the
    whole command has); or ``path`` itself when it is a device or a FIFO.

    An interrupted or failed write leaves no half-written file behind, and an error names
    ``path``, not the temporary file.

    >>> with atomic_output("out.csv") as tmp:        # doctest: +SKIP
    ...     tmp.write_text("t,x\\n")
    """
    from ..model import args

    path = args.path(path, "path")
    transaction = _active.get()
    if transaction is not None:
        transaction.claim(path)
    if is_special(path) or _under_system(path):
        try:
            yield path
        except OSError as exc:
            raise _user_error(exc, path, None) from None
        return
    if path.is_symlink():
        # Write the file the link names; a rename onto the link would replace the link.
        path = Path(os.path.realpath(path))
    tmp: Path | None = None
    deferred = False
    try:
        missing = [p for p in (path.parent, *path.parent.parents) if not p.exists()]
        path.parent.mkdir(parents=True, exist_ok=True)
        if transaction is not None:
            transaction.created.extend(reversed(missing))
        fd, name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part" + path.suffix,
                                    dir=path.parent)
        os.close(fd)
        tmp = Path(name)
        yield tmp
        if tmp.exists():
            # mkstemp makes private files; outputs get the usual permissions.
            umask = os.umask(0)
            os.umask(umask)
            os.chmod(tmp, 0o666 & ~umask)
        if transaction is not None:
            transaction.pending.append((tmp, path))
            deferred = True
        else:
            os.replace(tmp, path)
    except OSError as exc:
        raise _user_error(exc, path, tmp) from None
    finally:
        if tmp is not None and not deferred and tmp.exists():
            tmp.unlink()


def check_writable(path: str | Path, flag: str, folder: bool = False) -> None:
    """Raise UsageError naming ``flag`` unless ``path`` (a folder if ``folder``, else a file)
    could be created or replaced: called before any work, so nothing is half written."""
    from ..model import args

    args.text(flag, "flag", "the flag or argument that names the path (str)")
    if not isinstance(path, str | os.PathLike):
        raise UsageError(f"{flag} = {args.show(path)}: must be a path (str or pathlib.Path)",
                         param="path")
    folder = args.flag(folder, "folder")
    text = str(path)
    if "\0" in text:
        raise UsageError(f"{flag} {text!r}: a path cannot hold a NUL character")
    path = Path(path)
    if not folder and is_special(path):
        if not os.access(path, os.W_OK):
            raise UsageError(f"{flag} {path}: cannot write it (permission denied)")
        return
    if folder and path.exists() and not path.is_dir():
        raise UsageError(f"{flag} {path}: exists and is not a folder")
    if not folder and path.is_dir():
        raise UsageError(f"{flag} {path}: is a folder; give a file name")
    here = path if folder else path.parent
    here = here if str(here) else Path(".")
    while not here.exists() and here != here.parent:
        here = here.parent
    if not here.is_dir():
        raise UsageError(f"{flag} {path}: {here} is a file, not a folder")
    if not os.access(here, os.W_OK | os.X_OK):
        raise UsageError(f"{flag} {path}: cannot write in {here} (permission denied)")
