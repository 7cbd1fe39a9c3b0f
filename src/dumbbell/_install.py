"""Running from any install, as any user: numba's cache and matplotlib's folders.

numba caches a compiled function beside its source (``__pycache__``) or, when that folder
cannot be written, under the user's home (``~/.cache``); with neither (a read-only install
run by a user whose HOME is ``/`` or not writable: the usual ``docker --user`` set-up)
``njit(cache=True)`` raises ``RuntimeError: cannot cache function ...: no locator available``
as the module is imported. :func:`njit` here tries numba's own places first, then a private
folder of this user's in the temporary folder (``dumbbell-numba-UID``, mode 0700, used only
if it is a real folder this user owns), and only then compiles without a cache. The user is
told once, in one line on stderr, when the cache is not the usual one and what that costs
(when the private folder is made, and in every process when nothing can be written). Every
module that compiles with numba imports ``njit`` from here (``tests/test_hostile.py``
checks).

matplotlib, in the same set-up, makes a new temporary folder in every process (rebuilding
its font cache each time) and says so in two lines; :func:`matplotlib_folder` gives the
command line a private folder (``dumbbell-matplotlib-UID``) to use instead.

Within :func:`command_line` (the ``dumbbell`` command), two costs of those libraries that the
command does not need are not paid: its figures only go to files, so :mod:`dumbbell.plot`
draws them without pyplot; and its process runs only dumbbell's own compiled kernels, none of
which calls BLAS, so numba's probe for BLAS (an import of ``scipy.linalg``, about 0.1-0.2 s,
made when numba readies itself) is skipped (:func:`_numba_target`).
"""

import contextlib
import os
import stat
import sys
import tempfile
from collections.abc import Callable, Iterator
from contextvars import ContextVar
from typing import Any

__all__: list[str] = []

#: Seconds a solver's first run takes to compile its kernels on the 2-core test machine
#: (0.9 s for exact to 2.2 s for the 2D reference; docs/hardening.md), said when they
#: cannot be cached.
COMPILE_SECONDS = "1-2 s"
#: Set in the environment once the line has been said, so that pool workers stay quiet.
_SAID = "DUMBBELL_NUMBA_CACHE_NOTE"
#: Seconds the first use of a solver's kernels may take before :func:`compiling` says that
#: they compile: loading them from numba's cache takes a tenth of that.
COMPILE_NOTE_AFTER = 0.4
#: What :func:`compiling` has said in this process (each once).
_compiling_said: set[str] = set()

_mode: str | None = None  # "numba" (its own places), "private", "none": decided once


def _private_folder(kind: str) -> tuple[str, bool] | None:
    """This user's own folder ``dumbbell-KIND-UID`` in the temporary folder and whether it
    was just made; None when it cannot be made or is not safely ours (a link, another
    owner, open to others)."""
    try:
        path = os.path.join(tempfile.gettempdir(), f"dumbbell-{kind}-{os.geteuid()}")
        try:
            os.mkdir(path, 0o700)
            made = True
        except FileExistsError:
            made = False
        info = os.lstat(path)
        if not stat.S_ISDIR(info.st_mode) or info.st_uid != os.geteuid() \
                or info.st_mode & 0o077:
            return None
        tempfile.TemporaryFile(dir=path).close()
        return path, made
    except OSError:  # FileNotFoundError too: no usable temporary folder at all
        return None


def _writable(folder: str) -> bool:
    """Whether ``folder`` exists, or can be made, and can be written."""
    try:
        os.makedirs(folder, exist_ok=True)
    except OSError:
        return False
    return os.access(folder, os.W_OK | os.X_OK)


def matplotlib_folder() -> str | None:
    """A folder for MPLCONFIGDIR when matplotlib's own (``$XDG_CONFIG_HOME/matplotlib`` and
    ``$XDG_CACHE_HOME/matplotlib``, under HOME by default) cannot be written and
    MPLCONFIGDIR is not set: this user's private one; else None (matplotlib's own do)."""
    if os.environ.get("MPLCONFIGDIR"):
        return None
    home = os.path.expanduser("~")
    config = os.environ.get("XDG_CONFIG_HOME") or os.path.join(home, ".config")
    cache = os.environ.get("XDG_CACHE_HOME") or os.path.join(home, ".cache")
    if all(_writable(os.path.join(base, "matplotlib")) for base in (config, cache)):
        return None
    found = _private_folder("matplotlib")
    return found[0] if found else None


#: True while the ``dumbbell`` command runs (:func:`command_line`).
COMMAND_LINE: ContextVar[bool] = ContextVar("dumbbell_command_line", default=False)


@contextlib.contextmanager
def command_line(process_ends: bool = False) -> Iterator[None]:
    """Within the block, :mod:`dumbbell.plot` makes bare Figures on the Agg canvas instead of
    pyplot's (no pyplot import, no figure manager; the pixels are the same), and numba is
    readied without its BLAS probe (:func:`_numba_target`): for the ``dumbbell`` command,
    whose figures are only saved and whose process runs only dumbbell's kernels.

    The command also keeps the garbage collector off what it loaded for good (numba,
    matplotlib: hundreds of thousands of objects), with ``gc.freeze()`` at points of its own
    (:func:`dumbbell.cli.run.run_scene`). When the ``process_ends`` with the block, every
    object is frozen at its end: the interpreter's exit then does not look at them all again
    (a quarter to half a second with numba and matplotlib loaded). Otherwise (the command
    called from Python) the block gives them back to the collector, unless something had
    frozen objects before it."""
    import gc

    token = COMMAND_LINE.set(True)
    frozen = gc.get_freeze_count()
    try:
        yield
    finally:
        COMMAND_LINE.reset(token)
        if process_ends:
            gc.freeze()
        elif frozen == 0:
            gc.unfreeze()


#: Whether numba's target has been readied by :func:`_numba_target`.
_target_ready = False
#: The module whose import is numba's BLAS probe.
_BLAS_PROBE = "scipy.linalg.cython_blas"


def _numba_target() -> None:
    """Ready numba's CPU target once per process: the registries numba loads before its first
    compiled function runs or is loaded from the cache (a few tenths of a second, whether it
    then compiles or not). Within :func:`command_line`, without numba's BLAS probe: numba
    imports ``scipy.linalg.cython_blas`` once to learn whether np.dot and friends may call
    BLAS, and that import (all of ``scipy.linalg``) costs more than the rest of loading a
    kernel. With the probe's import failing at once, numba takes its own loops for the few
    functions that would have used BLAS (``np.correlate``, ``np.convolve``); linear algebra
    still imports scipy when compiled. The command's process compiles only dumbbell's
    kernels, none of which calls BLAS; anywhere else numba probes as usual."""
    global _target_ready
    if _target_ready:
        return
    _target_ready = True
    try:
        from numba.core.registry import cpu_target
    except ImportError:  # pragma: no cover - another layout of numba: it readies itself
        return
    skip = (COMMAND_LINE.get() and "scipy.linalg" not in sys.modules
            and _BLAS_PROBE not in sys.modules)
    if skip:
        # Kept on purpose (issue 32): a None in sys.modules makes numba's one import of the
        # probe fail at once, the only way to skip it that numba leaves open. Measured with
        # `python benchmarks/blas_probe.py`: readying numba's target took a median of 1.12 s
        # without the probe against 2.10 s with it (5 rounds interleaved, load average 14 on
        # the shared 2-core machine): about 1 s of every command that runs a compiled solver.
        sys.modules[_BLAS_PROBE] = None  # type: ignore[assignment]  # the import fails at once
    try:
        cpu_target.target_context.refresh()
    finally:
        if skip and sys.modules.get(_BLAS_PROBE, 0) is None:
            del sys.modules[_BLAS_PROBE]


def _say(text: str) -> None:
    if os.environ.get(_SAID):
        return
    os.environ[_SAID] = "1"
    sys.stderr.write(f"dumbbell: {text}\n")


@contextlib.contextmanager
def compiling(what: str, quiet: bool = True) -> Iterator[None]:
    """Around the first use of ``what`` (a solver's compiled kernels) in a process: loaded
    from numba's cache that takes a few hundredths of a second once numba is ready (timed
    from then); compiled (the first run after an install or an upgrade, or an empty cache) a
    second or two. When it takes longer than
    :data:`COMPILE_NOTE_AFTER` s and the user is watching (stderr a terminal, not ``quiet``,
    no CI: as a progress bar), one line on stderr says what is compiling and why, once per
    process; not again after the line about the cache's place (:func:`njit`), which says it.
    """
    from .progress import _progress_wanted

    if what in _compiling_said or not _progress_wanted(quiet) or os.environ.get(_SAID):
        yield
        return
    _numba_target()  # numba's own start-up, compiling or not: not timed
    import threading

    done = threading.Event()

    def note() -> None:
        if not done.wait(COMPILE_NOTE_AFTER):
            _compiling_said.add(what)
            sys.stderr.write(f"dumbbell: compiling {what} with numba (the first run after an "
                             f"install or upgrade, about {COMPILE_SECONDS}; cached for the "
                             "next runs)\n")
            sys.stderr.flush()

    timer = threading.Thread(target=note, name="dumbbell-compiling", daemon=True)
    timer.start()
    try:
        yield
    finally:
        done.set()
        timer.join()


def _cache_error(exc: RuntimeError) -> bool:
    return "no locator available" in str(exc)


def njit(cache: bool = True, **options: Any) -> Callable[[Callable], Any]:
    """``numba.njit(cache=cache, **options)`` (used as ``@njit(cache=True, nogil=True)``),
    cached wherever this user can write (see the module's notes); compiled without a cache
    when nowhere can be written."""
    import numba

    if COMMAND_LINE.get():
        _numba_target()

    def decorate(func: Callable) -> Any:
        global _mode
        if not cache:
            return numba.njit(cache=False, **options)(func)
        if _mode in (None, "numba"):
            compiled = _cached(func, options, None)
            if compiled is not None:
                _mode = "numba"
                return compiled
            _mode = None
        if _mode in (None, "private"):
            found = _private_folder("numba")
            compiled = None if found is None else _cached(func, options, found[0])
            if compiled is not None:
                if _mode is None and found[1]:
                    _say(f"numba cannot cache beside the package or in HOME "
                         f"({os.path.expanduser('~')}): caching the compiled kernels in "
                         f"{found[0]}; this first run compiles them, about "
                         f"{COMPILE_SECONDS} a solver")
                _mode = "private"
                return compiled
        if _mode is None:
            _say(f"numba cannot cache anywhere (the package's folder, HOME "
                 f"{os.path.expanduser('~')} and the temporary folder cannot be written): "
                 f"compiling the kernels in every run, about {COMPILE_SECONDS} a solver")
        _mode = "none"
        return numba.njit(cache=False, **options)(func)

    return decorate


def _cached(func: Callable, options: dict[str, Any], folder: str | None) -> Any:
    """``func`` compiled by numba with a cache, in ``folder`` (None: numba's own places);
    None when numba finds nowhere to write it."""
    import numba
    from numba.core import config

    before = config.CACHE_DIR
    if folder is not None:
        config.CACHE_DIR = folder  # read when the locator is made, right here
    try:
        return numba.njit(cache=True, **options)(func)
    except RuntimeError as exc:
        if not _cache_error(exc):
            raise
        return None
    finally:
        config.CACHE_DIR = before
