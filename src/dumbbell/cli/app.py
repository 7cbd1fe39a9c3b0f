"""The ``dumbbell`` command. Each subcommand lives in its own module in
:mod:`dumbbell.cli` and provides ``register(subparsers)``.

Exit status: 0 done; 2 bad input (one line naming the file, key or flag and what is allowed;
nothing written); 3 a run ended with a verdict other than ``ok``.
"""

from __future__ import annotations

import argparse
import importlib
import math
import os
import sys
from collections.abc import Sequence

from ..errors import DumbbellError

#: Subcommand modules, in the order ``--help`` lists them.
COMMANDS = ("run", "simulate", "compare", "render", "bench", "stability", "sweep",
            "restitution")

EXIT_USAGE = 2
EXIT_VERDICT = 3


class Parser(argparse.ArgumentParser):
    """An ArgumentParser whose errors are one line and exit status 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        sys.stderr.write(f"{self.prog}: error: {message} (see {self.prog} --help)\n")
        sys.exit(EXIT_USAGE)


def positive_float(unit: str):
    """An argparse type: a finite number > 0, in ``unit``."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not (math.isfinite(value) and value > 0):
            raise argparse.ArgumentTypeError(f"{text!r}: must be a finite number > 0 ({unit})")
        return value

    parse.__name__ = f"number in {unit}"
    return parse


def positive_int(what: str):
    """An argparse type: a whole number >= 1."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = 0
        if value < 1:
            raise argparse.ArgumentTypeError(f"{text!r}: must be a whole number >= 1 ({what})")
        return value

    parse.__name__ = what
    return parse


def add_quiet(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("-q", "--quiet", action="store_true",
                        help="no progress bar (it is also off when stderr is not a terminal "
                             "or CI is set)")


def build_parser() -> Parser:
    parser = Parser(
        prog="dumbbell",
        description="How a body's mechanical energy is shared between centre-of-mass and "
                    "internal motion: the bouncing dumbbell of textbook section 13.5.1.",
        epilog="Exit status: 0 done, 2 bad input, 3 a run ended with a verdict other than ok.",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=Parser)
    sub.required = True
    for name in COMMANDS:
        importlib.import_module(f"dumbbell.cli.{name}").register(sub)
    return parser


def subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    """Command name -> its parser (argparse keeps them in a private list)."""
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(sub.choices)


def arguments(parser: argparse.ArgumentParser) -> list[argparse.Action]:
    """Every argument ``parser`` takes, flags and positionals, without ``--help``."""
    return [a for a in parser._actions if not isinstance(a, argparse._HelpAction)]


#: Output flags every command may have: argparse dest -> (flag, names a folder).
OUTPUT_FLAGS = {"out": ("--out", True), "output": ("--output", False),
                "events": ("--events", False)}


def _check_outputs(args: argparse.Namespace) -> None:
    """Refuse output paths that cannot be written before any work is done (UsageError)."""
    from ..io.files import check_writable

    for dest, (flag, folder) in OUTPUT_FLAGS.items():
        value = getattr(args, dest, None)
        if isinstance(value, str) and value:
            check_writable(value, flag, folder)


def as_flags(exc: DumbbellError) -> str:
    """The error's message as the command line says it: a library error that starts with
    the parameter's name (``UsageError.param``) starts with its flag instead."""
    text = str(exc)
    param = getattr(exc, "param", None)
    if param and text.startswith(param):
        return "--" + param.replace("_", "-") + text[len(param):]
    return text


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``dumbbell`` console script; returns the exit status."""
    # The command only writes files: matplotlib's file-only backend, unless the user chose one.
    os.environ.setdefault("MPLBACKEND", "Agg")
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        _check_outputs(args)
        return int(args.func(args) or 0)
    except DumbbellError as exc:
        sys.stderr.write(f"dumbbell {args.command}: error: {as_flags(exc)}\n")
        return EXIT_USAGE
    except BrokenPipeError:
        # The reader closed the pipe (``dumbbell simulate ... | head``): stop quietly, and keep
        # Python from complaining again when it flushes stdout at exit.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except OSError as exc:
        # Backstop: an output that still cannot be written is one line, not a traceback.
        where = exc.filename or "an output file"
        sys.stderr.write(f"dumbbell {args.command}: error: cannot write {where}: "
                         f"{exc.strerror or exc}\n")
        return EXIT_USAGE
    except KeyboardInterrupt:
        sys.stderr.write(f"dumbbell {args.command}: interrupted; no partial output was kept\n")
        return 130
