"""Output files that appear whole or not at all.

Every output goes through :func:`atomic_output`: a regular file is written beside its final
name as a hidden ``.part`` file and renamed into place; a device, a FIFO (or anything else that
is not a regular file) is written directly, because a rename would replace it.

Inside :func:`output_transaction` (the command line opens one around each command) the renames
wait until the whole command has succeeded, and then happen together: every output is the new
file, or (when one rename fails) every output is what was there before. A failure or a signal
before that leaves nothing behind, not even the outputs that were already complete, and no
output may land on an input or on another output of the same command. Before any work, the
command checks every name it will write (:func:`check_writable`, :meth:`OutputTransaction.plan`).

No temporary file outlives its process: each is registered while it exists and removed at
interpreter exit (``atexit``), and a stop signal whose action is the default one (SIGTERM,
SIGHUP, SIGINT set to ``SIG_DFL``: the process would die without running any Python code) is
given, while a temporary file exists, a handler that removes them, puts the default action
back and sends the signal again, so that the process still ends by that signal. A handler of
the program's own is left alone (an exception it raises removes the files on its way out, as
any exception does), and an ignored signal stays ignored. Not covered: SIGKILL and
``os._exit``, which run no code at all.
"""

from __future__ import annotations

import atexit
import os
import secrets
import signal
import stat
import tempfile
import threading
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from pathlib import Path

from .errors import UsageError
from .parallel import STOP_SIGNALS

#: No public names: the one way every writer of the package writes a file.
__all__: list[str] = []


def _inputs(inputs: object) -> list[tuple[str | Path, str]]:
    """``inputs`` as (path, how the user named it) pairs, else a UsageError."""
    from .model import args

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
    from .model import args

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


def link_refusal(path: str | Path) -> str | None:
    """Why the link at ``path`` (an output's name) may not be written through, or None when
    it is no link or may be followed. Followed only: a link of the user's own (never
    another user's, the rule the kernel's ``fs.protected_symlinks`` applies in sticky
    folders, here everywhere) that names a file inside the folder holding it (a link to
    nothing creates nothing outside it either), or names a device or a FIFO, which are
    written, never created; and a system path the user named (``/dev/stdout``)."""
    from .model.args import show_path

    path = Path(path)
    if not os.path.islink(path) or os.path.abspath(path).startswith(("/dev/", "/proc/")):
        return None
    try:
        owner = os.lstat(path).st_uid
        target = os.readlink(path)
    except OSError as exc:
        return f"is a link that cannot be read ({exc.strerror})"
    if owner != os.geteuid():
        return (f"is a link of another user's (uid {owner}) to {show_path(target)}: never "
                "written through; remove the link or write into another folder")
    if is_special(path):
        return None
    folder = os.path.realpath(path.parent)
    if os.path.commonpath([os.path.realpath(path), folder]) != folder:
        return (f"is a link to {show_path(target)}, outside {show_path(path.parent)}: an "
                "output is written only inside the folder it names; remove the link or write "
                "elsewhere")
    return None


# --- temporary files: registered while they exist, removed at exit or on a stop signal ----

#: Temporary file -> the process that made it (a forked child must not remove its parent's).
_temporary: dict[str, int] = {}
_lock = threading.Lock()
#: Signals given :func:`_remove_and_resend` while temporary files exist.
_armed: set[int] = set()
_STOP = tuple(getattr(signal, n) for n in STOP_SIGNALS if hasattr(signal, n))


def _remove_temporary() -> None:
    """Remove every temporary file this process registered (at exit, or on a stop signal)."""
    with _lock:
        mine = [p for p, pid in _temporary.items() if pid == os.getpid()]
        for p in mine:
            _temporary.pop(p, None)
    for p in mine:
        try:
            os.unlink(p)
        except OSError:
            pass


atexit.register(_remove_temporary)


def _remove_and_resend(signum: int, frame: object) -> None:
    """A stop signal with the default action: remove the temporary files, then die by it."""
    _remove_temporary()
    signal.signal(signum, signal.SIG_DFL)
    _armed.discard(signum)
    os.kill(os.getpid(), signum)


def _in_main_thread() -> bool:
    return threading.current_thread() is threading.main_thread()


def _register(path: Path) -> None:
    with _lock:
        _temporary[str(path)] = os.getpid()
    if not _in_main_thread():
        return
    for signum in _STOP:
        if signum not in _armed and signal.getsignal(signum) is signal.SIG_DFL:
            signal.signal(signum, _remove_and_resend)
            _armed.add(signum)


def _forget(path: Path) -> None:
    with _lock:
        _temporary.pop(str(path), None)
        left = any(pid == os.getpid() for pid in _temporary.values())
    if left or not _in_main_thread():
        return
    for signum in list(_armed):
        if signal.getsignal(signum) is _remove_and_resend:  # still ours: give it back
            signal.signal(signum, signal.SIG_DFL)
        _armed.discard(signum)


def _unlink(path: Path) -> None:
    """Remove the temporary file ``path`` (if still there) and forget it."""
    try:
        path.unlink(missing_ok=True)
    except OSError:
        pass
    _forget(path)


@contextmanager
def _signals_held() -> Iterator[None]:
    """Hold the stop signals back for a block of renames (main thread), so that they all
    happen or none; a signal that arrives meanwhile is delivered right after."""
    held = _in_main_thread() and hasattr(signal, "pthread_sigmask")
    before = signal.pthread_sigmask(signal.SIG_BLOCK, _STOP) if held else None
    try:
        yield
    finally:
        if held:
            signal.pthread_sigmask(signal.SIG_SETMASK, before)


# --- the transaction ------------------------------------------------------------------------


class CommitError(OSError):
    """A rename of the commit failed; every output is back to what it was before."""


class OutputTransaction:
    """The outputs of one command: claimed names, finished ``.part`` files waiting for their
    rename, folders created on the way (removed again if the command fails)."""

    def __init__(self, inputs: Iterable[tuple[str | Path, str]] = ()):
        #: real path -> how the user named it ("the scene x.toml", "-o x.csv").
        self.inputs = {_key(Path(p)): what for p, what in _inputs(inputs)}
        self.claimed: dict[str, str] = {}
        #: Real paths of the outputs checked before the work (:meth:`plan`, claimed flags).
        self.planned: set[str] = set()
        #: Outputs written that were not planned (a command that forgot one: a test finds it).
        self.unplanned: list[Path] = []
        #: Real paths written so far (:func:`atomic_output`): none may be written twice.
        self.written: set[str] = set()
        #: (finished temporary file, final path, the name the user gave): renamed at commit.
        self.pending: list[tuple[Path, Path, str]] = []
        self.created: list[Path] = []
        self.committed = False

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
        from .model import args

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
            self.planned.add(key)
            return
        special = is_special(path) or _under_system(path)
        if key in self.written and not special:
            # Two writes of one file: the commit would rename the second over the first,
            # whichever finished last (an empty one, say).
            raise UsageError(f"{label}: written twice by one command; each output is one "
                             "file")
        self.written.add(key)
        if key not in self.planned and not special:
            self.unplanned.append(path)

    def plan(self, paths: Iterable[str | Path], flag: str) -> list[Path]:
        """Before the work: check every output name a command will write (each can be
        created or replaced, :func:`check_writable`) and reserve it, refusing one that is an
        input or another output. ``flag`` is how the user set them (``'--out r'``): a
        refusal names it, then the file. Returns the paths."""
        from .model import args

        flag = args.text(flag, "flag", "how the user set these outputs (str), e.g. '--out r'")
        if isinstance(paths, str | bytes | os.PathLike) or not isinstance(paths, Iterable):
            raise UsageError(f"paths = {args.show(paths)}: must be a list of paths",
                             param="paths")
        out = [args.path(p, "paths") for p in paths]
        for path in out:
            check_writable(path, f"{flag}:", within=True)
            self.claim(path, f"{flag}: {path}")
        return out

    def commit(self) -> None:
        """Rename every finished output into place, all or none: each existing file is first
        linked (or, where links are not allowed, renamed) to a hidden backup beside it; if a
        rename fails, every earlier one is undone from its backup and the error (a
        :class:`CommitError` naming the output as the user gave it) is raised; else the
        backups are removed. The stop signals wait until it is over."""
        with _signals_held():
            done: list[tuple[Path, Path | None]] = []
            try:
                for tmp, path, shown in self.pending:
                    try:
                        done.append((path, _replace(tmp, path)))
                    except OSError as exc:
                        raise CommitError(exc.errno, exc.strerror or str(exc), shown) from None
            except BaseException:
                self._undo(done)
                raise
            for tmp, _, _ in self.pending:
                _forget(tmp)
            self.pending.clear()
            for _, backup in done:
                if backup is not None:
                    _unlink(backup)
            self.created.clear()
            self.committed = True

    def _undo(self, done: list[tuple[Path, Path | None]]) -> None:
        """Put back what was there before each rename of ``done`` (newest first)."""
        for path, backup in reversed(done):
            try:
                if backup is None:
                    path.unlink(missing_ok=True)
                else:
                    os.replace(backup, path)
                    _forget(backup)
            except OSError:
                pass  # the backup stays (registered), so at least the old content exists

    def rollback(self) -> None:
        """Remove every unfinished or uncommitted ``.part`` file and the folders made for
        them (only if empty)."""
        for tmp, _, _ in self.pending:
            _unlink(tmp)
        self.pending.clear()
        for folder in reversed(self.created):
            try:
                folder.rmdir()
            except OSError:
                pass
        self.created.clear()


def _replace(tmp: Path, path: Path) -> Path | None:
    """Rename ``tmp`` onto ``path``, keeping what was there as a registered hidden backup
    beside it (returned; None when ``path`` did not exist)."""
    if not os.path.lexists(path):
        os.replace(tmp, path)
        return None
    backup = path.parent / f".{path.name}.{secrets.token_hex(4)}.old"
    _register(backup)
    try:
        os.link(path, backup)          # path stays in place meanwhile
        linked = True
    except OSError:
        try:
            os.replace(path, backup)   # no hard links here: move it aside
        except OSError:
            _forget(backup)
            raise
        linked = False
    try:
        os.replace(tmp, path)
    except OSError:
        if linked:
            _unlink(backup)
        else:
            os.replace(backup, path)
            _forget(backup)
        raise
    return backup


_active: ContextVar[OutputTransaction | None] = ContextVar("dumbbell_outputs", default=None)


@contextmanager
def output_transaction(inputs: Iterable[tuple[str | Path, str]] = ()
                       ) -> Iterator[OutputTransaction]:
    """Defer every :func:`atomic_output` rename inside the block to its successful end, then
    make them all or none (:meth:`OutputTransaction.commit`); on any exception (a
    KeyboardInterrupt or a signal too) remove the outputs instead. ``inputs``: (path, how to
    name it) pairs that no output may replace."""
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

    An interrupted or failed write leaves no half-written file behind (nor does a stop
    signal or the end of the interpreter: see the module's notes), and an error names
    ``path``, not the temporary file.

    >>> with atomic_output("out.csv") as tmp:        # doctest: +SKIP
    ...     tmp.write_text("t,x\\n")
    """
    path, transaction = _claimed(path)
    if is_special(path) or _under_system(path):
        with _written_through(path):
            yield path
        return
    shown = path
    if path.is_symlink():
        # Write the file the link names; a rename onto the link would replace the link.
        path = Path(os.path.realpath(path))
    tmp: Path | None = None
    deferred = False
    try:
        tmp = _part_file(path, transaction)
        yield tmp
        if tmp.exists():
            # mkstemp makes private files; outputs get the usual permissions.
            umask = os.umask(0)
            os.umask(umask)
            os.chmod(tmp, 0o666 & ~umask)
        if transaction is not None:
            transaction.pending.append((tmp, path, str(shown)))
            deferred = True
        else:
            os.replace(tmp, path)
    except OSError as exc:
        raise _user_error(exc, shown, tmp) from None
    finally:
        if tmp is not None and not deferred:
            _unlink(tmp)


def _claimed(path: str | Path) -> tuple[Path, OutputTransaction | None]:
    """``path`` checked as an output (no NUL, no link planted since the command checked
    it) and claimed in the running :func:`output_transaction`, if any; with that
    transaction."""
    from .model import args

    path = args.path(path, "path")
    if "\0" in str(path):
        raise UsageError(f"path = {args.show(str(path))}: a path cannot hold a NUL character",
                         param="path")
    refusal = link_refusal(path)
    if refusal is not None:  # planted since the command checked its outputs, say
        raise UsageError(f"{args.show_path(path)}: {refusal}", param="path")
    transaction = _active.get()
    if transaction is not None:
        transaction.claim(path)
    return path, transaction


@contextmanager
def _written_through(path: Path) -> Iterator[None]:
    """The block writes a device, a FIFO or a pipe itself (no temporary file)."""
    try:
        yield
    except BrokenPipeError:
        # A FIFO or a pipe (/dev/stdout) whose reader left: what it did not read is
        # dropped, as for standard output (`| head`); the other outputs are written.
        pass
    except OSError as exc:
        raise _user_error(exc, path, None) from None


def _part_file(path: Path, transaction: OutputTransaction | None) -> Path:
    """A new temporary file beside ``path`` (its folders made, and kept in ``transaction``
    to be removed if it fails), registered to be removed at exit."""
    missing = [p for p in (path.parent, *path.parent.parents) if not p.exists()]
    path.parent.mkdir(parents=True, exist_ok=True)
    if transaction is not None:
        transaction.created.extend(reversed(missing))
    fd, name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part" + path.suffix,
                                dir=path.parent)
    os.close(fd)
    tmp = Path(name)
    _register(tmp)
    return tmp


def _cwd_gone() -> bool:
    try:
        os.getcwd()
    except FileNotFoundError:
        return True
    return False


def _why_not(path: Path, text: str, folder: bool, within: bool) -> str | None:
    """Why ``path`` (spelt ``text`` by the user; a folder if ``folder``) could not be
    created or replaced, or None when it can. ``within``: a name the command chose inside
    the user's folder, so the way out is another folder, not another name."""
    why = _misspelt(path, text, folder) or _unusable(path, folder)
    if why:
        return why
    if not folder and os.path.islink(path):
        why = link_refusal(path)
        if why:
            return why
        if not is_special(path):  # a device or a pipe (/dev/stdout) is written through
            path = Path(os.path.realpath(path))  # the file the link names is written
    if not folder and is_special(path):
        return None if os.access(path, os.W_OK) else "cannot write it (permission denied)"
    if not folder and _under_system(path) and not os.path.exists(path) \
            and not os.path.abspath(path).startswith("/dev/shm/"):
        return ("is no entry of the system's /dev or /proc, where no file can be created; "
                "write elsewhere")
    if folder and path.exists() and not path.is_dir():
        return "exists and is not a folder"
    if not folder and path.is_dir():
        return ("is a folder, where this command writes a file: remove it or write into "
                "another folder") if within else "is a folder; give a file name"
    return _unwritable(path, folder)


def _misspelt(path: Path, text: str, folder: bool) -> str | None:
    """What is wrong with the spelling ``text`` of ``path``, or None."""
    if "\0" in text:
        return "a path cannot hold a NUL character"
    if not folder and text.endswith(("/", os.sep)):
        return "ends in '/', so it names a folder; give a file name"
    if not folder and (path.name in ("", ".", "..") or text.endswith(("/.", "/.."))):
        return "names a folder; give a file name"
    if not path.is_absolute() and _cwd_gone():
        return "the working folder no longer exists; give an absolute path"
    return None


def _unusable(path: Path, folder: bool) -> str | None:
    """Why ``path`` cannot be looked at (a loop of links, a name too long, ...) or, as a
    folder, is a link to nothing; else None."""
    try:
        os.stat(path)
    except (FileNotFoundError, NotADirectoryError):  # the latter: a file on the way, below
        if os.path.islink(path):
            target = os.readlink(path)
            if folder:
                return f"is a link to {target}, which does not exist"
    except OSError as exc:  # a loop of links, a name too long, ...
        return f"cannot be used ({exc.strerror})"
    return None


def _unwritable(path: Path, folder: bool) -> str | None:
    """Why the folder ``path`` (or the one of the file ``path``) cannot be written in, or
    the file not replaced; else None."""
    here = path if folder else path.parent
    here = here if str(here) else Path(".")
    while not here.exists() and here != here.parent:
        if os.path.islink(here):
            return f"{here} is a link to {os.readlink(here)}, which does not exist"
        here = here.parent
    if not here.is_dir():
        return f"{here} is a file, not a folder"
    if not os.access(here, os.W_OK | os.X_OK):
        return f"cannot write in {here} (permission denied)"
    probe = _probe(here)
    if probe:
        return f"cannot write in {here} ({probe})"
    if not folder and path.exists():
        return _sticky(path)
    return None


def _probe(folder: Path) -> str | None:
    """Make and remove a file in ``folder``: the one sure test that a file can be created
    there (a read-only file system, /sys, a folder only root may write pass ``os.access``
    for root). None when it can; else why not."""
    try:
        fd, name = tempfile.mkstemp(prefix=".dumbbell-", suffix=".probe", dir=folder)
    except OSError as exc:
        return exc.strerror or str(exc)
    os.close(fd)
    try:
        os.unlink(name)
    except OSError:
        pass
    return None


def _sticky(path: Path) -> str | None:
    """Why the existing file ``path`` cannot be replaced in its sticky folder (another user
    owns both the folder and the file), or None."""
    try:
        folder, own = os.stat(path.parent), os.stat(path)
    except OSError:
        return None
    me = os.geteuid()
    if folder.st_mode & stat.S_ISVTX and me not in (0, folder.st_uid, own.st_uid):
        return (f"belongs to another user (uid {own.st_uid}) in the sticky folder "
                f"{path.parent}, so it cannot be replaced; give another name")
    return None


def check_writable(path: str | Path, flag: str, folder: bool = False, *,
                   within: bool = False) -> None:
    """Raise UsageError naming ``flag`` unless ``path`` (a folder if ``folder``, else a file)
    could be created or replaced: called before any work, so nothing is half written.

    Refused: a NUL character; a file name ending in '/' (a folder); a relative path when the
    working folder was deleted; a link to nothing (as a folder); a folder given as a file or
    a file as a folder; a missing folder under a file or a dangling link; a folder without
    write permission; an existing file another user owns in a sticky folder that is not ours.
    With ``within``, ``flag`` is a prefix (``'--out r:'``) and the message names ``path``
    after it."""
    from .model import args

    args.text(flag, "flag", "the flag or argument that names the path (str)")
    if not isinstance(path, str | os.PathLike):
        raise UsageError(f"{flag} = {args.show(path)}: must be a path (str or pathlib.Path)",
                         param="path")
    folder = args.flag(folder, "folder")
    within = args.flag(within, "within")
    text = os.fspath(path)
    if not isinstance(text, str):
        text = os.fsdecode(text)
    why = _why_not(Path(text.replace("\0", "")), text, folder, within)
    if why is not None:
        shown = args.show(text) if "\0" in text else args.show_path(text, 200)
        raise UsageError(f"{flag} {shown}: {why}")


def writable_path(value: object, name: str = "path") -> Path:
    """The output path ``value`` a function of the Python API was given, checked before any
    work as the command line checks its outputs (:func:`check_writable`: as spelt, so that
    ``"newdir/"`` is a folder, not a file called ``newdir``), else a UsageError naming
    ``name``; returns it as a Path."""
    from .model import args

    if not isinstance(value, str | os.PathLike) or not os.fspath(value):
        raise UsageError(f"{name} = {args.show(value)}: must be a path (str or "
                         "pathlib.Path)", param=name)
    try:
        check_writable(value, f"{name} =")
    except UsageError as exc:
        raise UsageError(str(exc), param=name) from None
    return Path(os.fsdecode(value))
