"""The ``dumbbell`` command. Each subcommand lives in its own module in
:mod:`dumbbell.cli` and provides ``register(subparsers)``.

Exit status: 0 done; 2 bad input (one line naming the file, key or flag and what is allowed;
nothing written); 3 a run ended early (a verdict unstable, tunnelled or failed); 4 a run
reached its end but is ``inaccurate`` (its energy error passed ``run.inaccurate_energy``;
every output written); 128+N stopped by signal N (SIGINT, SIGTERM, SIGHUP; nothing
written, pool workers stopped).
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import importlib
import math
import os
import signal
import sys
import threading
from collections.abc import Iterator, Sequence
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


def add_scene(parser: argparse.ArgumentParser) -> None:
    """The SCENE argument: a scene file, or - for standard input."""
    parser.add_argument("scene", metavar="SCENE",
                        help="scene file (TOML); - reads it from standard input")


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


def _stop(signum: int, frame: object) -> None:
    # Once is enough: a second signal must not break the cleanup the first one started.
    for name in STOP_SIGNALS:
        signal.signal(getattr(signal, name), signal.SIG_IGN)
    raise Stopped(signum)


@contextlib.contextmanager
def _stop_signals() -> Iterator[None]:
    """Turn SIGINT, SIGTERM and SIGHUP into :class:`Stopped` for the block (main thread only),
    then give back the caller's handlers."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    numbers = [getattr(signal, n) for n in STOP_SIGNALS if hasattr(signal, n)]
    before = {n: signal.getsignal(n) for n in numbers}
    for n in numbers:
        if before[n] is not signal.SIG_IGN:  # nohup's ignored SIGHUP stays ignored
            signal.signal(n, _stop)
    try:
        yield
    finally:
        for n, handler in before.items():
            signal.signal(n, handler if handler is not None else signal.SIG_DFL)


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
    with _stop_signals(), _file_backend(process_ends=argv is None):
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


def _run(args: argparse.Namespace, command: str, state: dict[str, object]) -> int:
    from ..files import output_transaction

    def error(text: str) -> int:
        sys.stderr.write(one_line(f"{command}: error: {text}") + "\n")
        return EXIT_USAGE

    try:
        with output_transaction() as transaction:
            state["outputs"] = args.outputs = transaction
            _check_paths(args, transaction)
            return int(args.func(args) or 0)
    except DumbbellError as exc:
        return error(as_flags(exc, args))
    except BrokenPipeError:
        # The reader closed the pipe (``dumbbell simulate ... | head``): stop quietly, and keep
        # Python from complaining again when it flushes stdout at exit.
        with contextlib.suppress(OSError, ValueError):
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
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
