"""The ``dumbbell`` command. Each subcommand lives in its own module in
:mod:`dumbbell.cli` and provides ``register(subparsers)``.

Exit status: 0 done; 2 bad input (one line naming the file, key or flag and what is allowed;
nothing written); 3 a run ended early (a verdict unstable, tunnelled or failed); 4 a run
reached its end but is ``inaccurate`` (its energy error passed ``run.inaccurate_energy``;
every output written); 128+N stopped by signal N (SIGINT, SIGTERM, SIGHUP; nothing
written, pool workers stopped).
"""

from __future__ import annotations

import _thread
import argparse
import contextlib
import dataclasses
import importlib
import math
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator, Sequence
from typing import Any

from ..errors import DumbbellError, UsageError
from ..parallel import STOP_SIGNALS

#: Subcommand modules, in the order ``--help`` lists them.
COMMANDS = ("run", "simulate", "compare", "render", "play", "bench", "stability", "sweep",
            "restitution")

EXIT_USAGE = 2
EXIT_VERDICT = 3
EXIT_INACCURATE = 4
#: The exit statuses of runs, from best to worst: a command that makes several runs exits
#: with the worst (an early end is worse than an inaccurate run).
RUN_STATUSES = (0, EXIT_INACCURATE, EXIT_VERDICT)


def verdict_status(verdict: Any) -> int:
    """The exit status of a run's verdict: 0 ``ok``, :data:`EXIT_INACCURATE` for a run that
    reached its end but is ``inaccurate``, :data:`EXIT_VERDICT` for one that ended early."""
    if verdict.ok:
        return 0
    return EXIT_INACCURATE if verdict.complete else EXIT_VERDICT


def worst_status(*statuses: int) -> int:
    """The worst of exit statuses: a status outside :data:`RUN_STATUSES` (a usage error,
    a signal) first, then by that order."""
    return max(statuses, key=lambda s: RUN_STATUSES.index(s) if s in RUN_STATUSES
               else len(RUN_STATUSES) + s, default=0)


#: Longest run of characters without a space a message may echo (a value, a path): longer
#: ones keep their start and end around '...'.
MAX_ECHO = 200


def clip(text: str, limit: int = MAX_ECHO) -> str:
    """``text`` with every word (a run without spaces) longer than ``limit`` characters cut
    to its first ``limit - 23`` and last 20 around '...', and the whole at most ``5 *
    limit`` characters (its first ``3 * limit - 3`` and last ``2 * limit`` around '...'): a
    message echoing a huge value (10,000 tilts, a 5,000-digit number, a 4,000-character
    path, a key of many words) stays short, and keeps its end, which says what is allowed."""
    out = " ".join(w if len(w) <= limit else f"{w[:limit - 23]}...{w[-20:]}"
                   for w in str(text).split(" "))
    return out if len(out) <= 5 * limit else f"{out[:3 * limit - 3]}...{out[-2 * limit:]}"


def one_line(text: str) -> str:
    """``text`` with every character that is not printable (newlines, control characters,
    line and record separators) escaped, so that a message echoing user input stays one line,
    and no word longer than :data:`MAX_ECHO` characters, nor the whole longer than five
    times that (:func:`clip`)."""
    return clip("".join(c if c.isprintable() else repr(c)[1:-1] for c in str(text)))


class Parser(argparse.ArgumentParser):
    """An ArgumentParser whose errors are one line and exit status 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        sys.stderr.write(one_line(f"{self.prog}: error: {message} (see {self.prog} --help)")
                         + "\n")
        sys.exit(EXIT_USAGE)

    def _get_value(self, action: argparse.Action, arg_string: str) -> Any:
        """A flag's value; an empty one (`-o ''`, `--out ''`, `--size ''`) is refused for
        every flag that takes a word: taken as 'not given', it wrote to standard output, into
        the working folder or with the scene's size instead of what the user asked for."""
        if arg_string == "" and action.option_strings and action.type is None:
            what = action.metavar if isinstance(action.metavar, str) else "value"
            raise argparse.ArgumentError(action, f"'': must be a {what}, not empty")
        return super()._get_value(action, arg_string)


def _shown(text: str) -> str:
    """A flag's value for an error message: quoted, one line, at most 40 characters."""
    text = repr(text)
    return text if len(text) <= 40 else text[:36] + "...'"


def positive_float(unit: str):
    """An argparse type: a finite number > 0, in ``unit``."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not (math.isfinite(value) and value > 0):
            raise argparse.ArgumentTypeError(f"{_shown(text)}: must be a finite number > 0 "
                                             f"({unit})")
        return value

    parse.__name__ = f"number in {unit}"
    return parse


#: Largest value of a count flag (--repeat, --workers, ...) unless the flag says otherwise.
MAX_COUNT = 10**9


def positive_int(what: str, hi: int = MAX_COUNT):
    """An argparse type: a whole number from 1 to ``hi`` (ASCII digits: int() would also read
    other scripts' digits, and reads huge strings slowly)."""

    def parse(text: str) -> int:
        digits = text.strip().lstrip("+")
        value = int(digits) if digits.isascii() and digits.isdigit() and len(digits) <= 20 \
            else 0
        if not 1 <= value <= hi:
            raise argparse.ArgumentTypeError(f"{_shown(text)}: must be a whole number from 1 "
                                             f"to {hi:,} ({what})")
        return value

    parse.__name__ = what
    return parse


#: The one default output folder of every command (``--out``; ``render -o`` and ``simulate``'s
#: CSV, which goes to standard output, name files).
DEFAULT_OUT = "renders"


def add_scene(parser: argparse.ArgumentParser, solver: str | None = None) -> None:
    """The SCENE argument: a scene file, or - for standard input; with ``solver`` (its help
    text), the ``--solver NAME`` flag after it (None: the scene's ``run.solver``)."""
    parser.add_argument("scene", metavar="SCENE",
                        help="scene file (TOML); - reads it from standard input")
    if solver is not None:
        parser.add_argument("--solver", metavar="NAME", help=solver)


def add_out(parser: argparse.ArgumentParser, what: str) -> None:
    """The ``--out DIR`` flag: the folder for ``what``, :data:`DEFAULT_OUT` by default."""
    parser.add_argument("--out", metavar="DIR", default=DEFAULT_OUT,
                        help=f"folder for {what} (default: {DEFAULT_OUT}, for every command)")


def add_quiet(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("-q", "--quiet", action="store_true",
                        help="no progress bar (it is also off when stderr is not a terminal "
                             "or CI is set)")


class _Version(argparse._VersionAction):
    """``--version``: the installed version, looked up only when asked for (reading the
    package's metadata costs more than the rest of a parser)."""

    @property
    def version(self) -> str:
        from .. import __version__

        return f"dumbbell {__version__}"

    @version.setter
    def version(self, value: object) -> None:
        pass


def build_parser(commands: Sequence[str] = COMMANDS) -> Parser:
    """The ``dumbbell`` parser with the subcommands ``commands`` (default: all of them)."""
    parser = Parser(
        prog="dumbbell",
        description="How a body's mechanical energy is shared between centre-of-mass and "
                    "internal motion: the bouncing dumbbell of textbook section 13.5.1.",
        epilog="Exit status: 0 done, 2 bad input, 3 a run ended early (unstable, tunnelled or "
               "failed), 4 a run reached its end but is inaccurate (its energy error passed "
               "run.inaccurate_energy; every output written).",
    )
    parser.add_argument("--version", action=_Version, help="print the installed version and exit")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=Parser)
    sub.required = True
    for name in commands:
        importlib.import_module(f"dumbbell.cli.{name}").register(sub)
    return parser


def _parser_for(argv: Sequence[str]) -> Parser:
    """The parser that parses ``argv``: with only the subcommand ``argv`` starts with, when it
    names one (its modules alone are imported: ``dumbbell run`` does not wait for the others);
    else with every subcommand (``--help``, ``--version``, a misspelt command)."""
    if argv and argv[0] in COMMANDS:
        return build_parser((argv[0],))
    return build_parser()


def subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    """Command name -> its parser (argparse keeps them in a private list)."""
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(sub.choices)


def arguments(parser: argparse.ArgumentParser) -> list[argparse.Action]:
    """Every argument ``parser`` takes, flags and positionals, without ``--help``."""
    return [a for a in parser._actions if not isinstance(a, argparse._HelpAction)]


#: Output flags every command may have: argparse dest -> (flag, names a folder).
OUTPUT_FLAGS = {"out": ("--out", True), "output": ("-o", False), "events": ("--events", False)}
#: Input flags: argparse dest -> how a message names the input.
INPUT_FLAGS = {"scene": "the scene"}


class Stopped(KeyboardInterrupt):
    """A stop signal arrived; every ``except KeyboardInterrupt`` cleanup runs for it too."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


class _StopState:
    """The stop signals of the running command: the first one (``signum``, None before any),
    kept until the command ends whatever swallowed the exception it raised."""

    signum: int | None = None
    #: The command is over (its handlers are being given back): a late signal is ignored.
    closing = False
    #: Inside :func:`_unraisable`'s hook, where an exception would only be printed.
    in_hook = False
    #: The timer that delivers a swallowed stop again.
    retry: threading.Timer | None = None


_stopping = _StopState()

#: How soon (s) a stop that C code swallowed is delivered again.
RETRY_STOP = 0.005


def _handling_a_stop() -> bool:
    """True while a :class:`Stopped` is being handled (an ``except`` or ``finally`` on its
    way out, the command's own handler): its cleanup must not be broken by a second one."""
    exc = sys.exc_info()[1]
    seen = 0
    while exc is not None and seen < 100:
        if isinstance(exc, Stopped):
            return True
        exc, seen = exc.__context__, seen + 1
    return False


def _stop(signum: int, frame: object) -> None:
    """A stop signal: raise :class:`Stopped` for the first one. Another one while the first
    one's cleanup runs is ignored; any other time (the first one's exception was swallowed)
    it raises again, for the first signal."""
    if _stopping.closing or _handling_a_stop():
        return
    if _stopping.signum is None:
        _stopping.signum = signum
    if _stopping.in_hook:
        _retry_stop()
        return
    raise Stopped(_stopping.signum)


def _retry_stop() -> None:
    """Deliver the stop again in :data:`RETRY_STOP` s (a thread simulates the signal: the
    main thread runs :func:`_stop` at its next Python instruction), unless that is planned."""
    if _stopping.retry is None or not _stopping.retry.is_alive():
        _stopping.retry = threading.Timer(RETRY_STOP, _thread.interrupt_main,
                                          (_stopping.signum,))
        _stopping.retry.daemon = True
        _stopping.retry.start()


def _unraisable(previous: Callable[[Any], object]) -> Callable[[Any], object]:
    """A ``sys.unraisablehook`` that takes back a :class:`Stopped` that C code swallowed: an
    exception raised in a pymunk collision callback is printed by cffi ('Exception ignored
    from cffi callback') and the step goes on. No message then, and the stop is delivered
    again a moment later (:func:`_retry_stop`): in a later callback (swallowed again, and
    retried) or, at the latest, once ``Space.step`` has returned. Anything else goes to
    ``previous``."""

    def hook(unraisable: Any) -> None:
        if isinstance(unraisable.exc_value, Stopped) and _stopping.signum is not None \
                and threading.current_thread() is threading.main_thread():
            _stopping.in_hook = True
            try:
                _retry_stop()
            finally:
                _stopping.in_hook = False
            return
        previous(unraisable)

    return hook


@contextlib.contextmanager
def _stop_signals() -> Iterator[None]:
    """Turn SIGINT, SIGTERM and SIGHUP into :class:`Stopped` for the block (main thread only),
    then give back the caller's handlers."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    numbers = [getattr(signal, n) for n in STOP_SIGNALS if hasattr(signal, n)]
    before = {n: signal.getsignal(n) for n in numbers}
    hook = sys.unraisablehook
    _stopping.signum, _stopping.closing = None, False
    for n in numbers:
        if before[n] is not signal.SIG_IGN:  # nohup's ignored SIGHUP stays ignored
            signal.signal(n, _stop)
    sys.unraisablehook = _unraisable(hook)
    try:
        yield
    finally:
        _stopping.closing = True
        if _stopping.retry is not None:
            _stopping.retry.cancel()
            _stopping.retry.join()  # a stop it simulated is ignored now (closing)
            _stopping.retry = None
        for n, handler in before.items():
            signal.signal(n, handler if handler is not None else signal.SIG_DFL)
        sys.unraisablehook = hook
        _stopping.signum, _stopping.closing = None, False


#: How a scene read from standard input (SCENE ``-``) is named in messages and outputs.
STDIN_SCENE = "stdin"


def read_scene(path, stdin: bool = True):
    """The scene at ``path``, or read from standard input when ``path`` is ``-`` and the
    command takes ``stdin`` (at most 1 MB, the cap of a scene file; named
    :data:`STDIN_SCENE`, so ``render`` writes ``renders/stdin.gif``). A :class:`Scene`
    already loaded (the showcase's shipped scenes) is taken as it is."""
    from ..errors import SceneError
    from ..model.scene import MAX_SCENE_BYTES, Scene, load_scene, load_scene_bytes

    if isinstance(path, Scene):
        return path
    if path != "-" or not stdin:
        return load_scene(path)
    if sys.stdin is None:  # started with standard input closed (<&-)
        raise SceneError(f"{STDIN_SCENE}: standard input is closed, so SCENE - has nothing "
                         "to read; give the scene file's path instead")
    try:
        data = sys.stdin.buffer.read(MAX_SCENE_BYTES + 1)
    except (OSError, AttributeError, ValueError) as exc:
        raise SceneError(f"{STDIN_SCENE}: cannot read a scene from standard input: "
                         f"{getattr(exc, 'strerror', None) or exc}") from None
    return load_scene_bytes(data, STDIN_SCENE)


def plan_outputs(args: argparse.Namespace, paths, flag: str | None = None) -> list:
    """Before the work: check and reserve every output ``paths`` the command will write
    (each can be created or replaced, none is an input or another output), else a
    UsageError naming ``flag`` (default ``--out DIR``) and the file. Returns the paths."""
    from ..files import OutputTransaction

    flag = flag or f"--out {args.out}"
    transaction = getattr(args, "outputs", None) or OutputTransaction()
    return transaction.plan(paths, flag)


def _check_paths(args: argparse.Namespace, transaction) -> None:
    """Before any work: every output can be written, none is an input or another output
    (UsageError naming the flags)."""
    from ..files import check_writable

    for dest, what in INPUT_FLAGS.items():
        value = getattr(args, dest, None)
        if isinstance(value, str) and value and os.path.exists(value):
            transaction.inputs[os.path.realpath(value)] = f"{what} {value}"
    for dest, (flag, folder) in OUTPUT_FLAGS.items():
        value = getattr(args, dest, None)
        if not isinstance(value, str) or not value or value == "-":
            continue
        check_writable(value, flag, folder)
        if not folder:
            transaction.claim(value, f"{flag} {value}")


def options(kind: type, args: argparse.Namespace, **flags: str) -> Any:
    """The options record ``kind`` (a frozen dataclass of an analysis) from the flags of
    ``args``: each field from the flag of its name, or of the name ``flags`` gives it; a flag
    left unset (None) leaves the field's default."""
    given = {f.name: getattr(args, flags.get(f.name, f.name), None)
             for f in dataclasses.fields(kind)}
    return kind(**{name: value for name, value in given.items() if value is not None})


def flag_for(param: str, args: argparse.Namespace | None) -> str | None:
    """How command ``args`` sets the library parameter ``param``: the name the command
    declares for it (``set_defaults(names={...})``: a flag of another name, a scene key),
    else ``--param`` when the command has that option, else None (it cannot)."""
    if args is None:
        return None
    names = getattr(args, "names", {})
    if param in names:
        return names[param]
    if param not in ("func", "command", "names") and hasattr(args, param):
        return "--" + param.replace("_", "-")
    return None


def as_flags(exc: DumbbellError, args: argparse.Namespace | None = None) -> str:
    """The error's message as the command line says it: a library error that starts with
    the parameter's name (``UsageError.param``) starts with how command ``args`` sets it
    (:func:`flag_for`; unchanged when it cannot), and the ways out it names
    (``UsageError.fixes``) name this command's flags, leaving out those it has none for."""
    def spell(param: str) -> str | None:
        return "--" + param.replace("_", "-") if args is None else flag_for(param, args)

    text = exc.text(spell) if isinstance(exc, UsageError) and args is not None else str(exc)
    param = getattr(exc, "param", None)
    flag = spell(param) if param and text.startswith(param) else None
    return flag + text[len(param):] if flag else text


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``dumbbell`` console script; returns the exit status: 0 done, 2 bad
    input, 3 a run ended early, 4 a run is inaccurate, 128+N stopped by signal N (SIGINT 130,
    SIGTERM 143, SIGHUP 129)."""
    command = "dumbbell"
    state: dict[str, object] = {}
    # Without argv, this is the process's own command (the console script, python -m):
    # it ends with the command.
    with _stop_signals(), _standard_streams(process_ends=argv is None), \
            _file_backend(process_ends=argv is None):
        try:
            argv = sys.argv[1:] if argv is None else list(argv)
            parser = _parser_for(argv)
            args = parser.parse_args(argv)
            command = f"dumbbell {args.command}"
            return _run(args, command, state)
        except KeyboardInterrupt as exc:
            signum = getattr(exc, "signum", signal.SIGINT)
            kept = getattr(state.get("outputs"), "committed", False)
            sys.stderr.write(f"{command}: stopped by {signal.Signals(signum).name}; "
                             + ("its outputs were already written\n" if kept
                                else "no output was kept\n"))
            return 128 + signum
        finally:
            # The command is over: a signal from now on (a second Ctrl-C) changes nothing.
            if threading.current_thread() is threading.main_thread():
                _stopping.closing = True


class _Sturdy:
    """A standard stream that cannot stop the command: a write or flush that fails because
    the stream is gone (closed when the process started, ``>&-``, or a pipe whose reader
    left) is dropped, and so is everything after it, so that the command still writes its
    files and its exit status says how they went; text the stream's encoding cannot hold
    (``PYTHONIOENCODING=ascii``) is written with backslash escapes instead of failing."""

    def __init__(self, stream: Any):
        self.stream = stream
        #: The stream is gone: nothing more is written to it.
        self.lost = stream is None

    def write(self, text: str) -> int:
        if not self.lost:
            try:
                return self.stream.write(text)
            except UnicodeEncodeError:
                encoding = getattr(self.stream, "encoding", None) or "ascii"
                return self.write(text.encode(encoding, "backslashreplace").decode(encoding))
            except (OSError, ValueError):  # EPIPE, EBADF; ValueError: a closed file
                self._lose()
        return len(text)

    def flush(self) -> None:
        if not self.lost:
            try:
                self.stream.flush()
            except (OSError, ValueError):
                self._lose()

    def isatty(self) -> bool:
        try:
            return not self.lost and self.stream.isatty()
        except (OSError, ValueError):
            return False

    def __getattr__(self, name: str) -> Any:  # encoding, errors, fileno, buffer, ...
        if self.stream is None:
            raise AttributeError(name)
        return getattr(self.stream, name)

    def _lose(self) -> None:
        self.lost = True
        # Python flushes the stream once more at exit: let that land in /dev/null rather
        # than complain about the pipe (or end the process with status 120).
        with contextlib.suppress(OSError, ValueError, AttributeError):
            null = os.open(os.devnull, os.O_WRONLY)
            os.dup2(null, self.stream.fileno())
            os.close(null)


@contextlib.contextmanager
def _standard_streams(process_ends: bool = False) -> Iterator[None]:
    """Standard output and error as :class:`_Sturdy` streams for the command, given back
    afterwards. ``process_ends`` (the process's own command): descriptors 0, 1 and 2 that
    were closed when it started are opened on /dev/null first, so that no file the command
    opens takes their number (a message to descriptor 2 would land in an output)."""
    if process_ends:
        for fd in (0, 1, 2):
            try:
                os.fstat(fd)
            except OSError:
                null = os.open(os.devnull, os.O_RDONLY if fd == 0 else os.O_WRONLY)
                if null != fd:  # pragma: no cover - lower descriptors are open
                    os.dup2(null, fd)
                    os.close(null)
    before = sys.stdout, sys.stderr
    sys.stdout, sys.stderr = _Sturdy(before[0]), _Sturdy(before[1])
    try:
        yield
    finally:
        for stream in (sys.stdout, sys.stderr):
            stream.flush()
        sys.stdout, sys.stderr = before


def stdout_closed() -> bool:
    """Whether standard output was closed when the command started (``>&-``): a command
    that writes its result there refuses before the work."""
    return isinstance(sys.stdout, _Sturdy) and sys.stdout.stream is None


@contextlib.contextmanager
def _file_backend(process_ends: bool = False) -> Iterator[None]:
    """The command only writes files: matplotlib's file-only backend (Agg) whatever
    MPLBACKEND says (a backend that does not exist, or needs a display, would fail); and a
    private MPLCONFIGDIR when matplotlib's own folders cannot be written (HOME = /); figures
    drawn without pyplot, numba without its BLAS probe, the garbage collector's work
    (:func:`dumbbell._install.command_line`; ``process_ends``: the process ends with the
    command). The environment is given back afterwards."""
    from .._install import command_line, matplotlib_folder

    settings = {"MPLBACKEND": "Agg"}
    folder = matplotlib_folder()
    if folder is not None:
        settings["MPLCONFIGDIR"] = folder
    before = {name: os.environ.get(name) for name in settings}
    os.environ.update(settings)
    try:
        with command_line(process_ends):
            yield
    finally:
        for name, value in before.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value


def solver_names(values: Any) -> list[str]:
    """The solver names a ``--solvers`` flag gives (``values``: its words, or None); commas
    also separate names."""
    return [s.strip() for item in values or () for s in str(item).split(",") if s.strip()]


def _check_solvers(args: argparse.Namespace) -> None:
    """Every command's ``--solvers`` names each solver once (commas also separate names):
    a name given twice is refused, not run once without a word."""
    from ..errors import UsageError

    names = solver_names(getattr(args, "solvers", None))
    twice = next((name for i, name in enumerate(names) if name in names[:i]), None)
    if twice is not None:
        raise UsageError(f"--solvers: {_shown(twice)} named twice; give each solver once")


def _run(args: argparse.Namespace, command: str, state: dict[str, object]) -> int:
    from ..files import output_transaction

    def error(text: str) -> int:
        sys.stderr.write(one_line(f"{command}: error: {text}") + "\n")
        return EXIT_USAGE

    try:
        with output_transaction() as transaction:
            state["outputs"] = args.outputs = transaction
            _check_paths(args, transaction)
            _check_solvers(args)
            status = int(args.func(args) or 0)
            if _stopping.signum is not None:  # a stop something swallowed: keep nothing
                raise Stopped(_stopping.signum)
            return status
    except DumbbellError as exc:
        return error(as_flags(exc, args))
    except OSError as exc:
        # Backstop: a file that still cannot be written or read is one line, not a traceback.
        if exc.filename:
            return error(f"{exc.filename}: {exc.strerror or exc}; nothing was written")
        return error(f"{exc.strerror or exc}; nothing was written")
    except MemoryError:
        return error("ran out of memory; nothing was written: ask for less (a shorter "
                     "--t-end, a smaller --size, fewer values) or allow the process more "
                     "memory")
    except RecursionError:
        return error("an input is nested too deeply")
