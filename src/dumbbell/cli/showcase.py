"""The showcase: every file tracked in the repository's ``renders/``, and the one command that
writes it. ``dumbbell run --all`` runs them all into one folder (``renders/`` by default), so
the README's pictures and tables come from one source and regenerate byte for byte, except
the files that hold run times (:attr:`Piece.measured`): those are a fresh measurement of the
machine they run on.

The shipped scenes are read from the package and named ``scenes/NAME.toml`` in what the
commands print and write, as the repository names them (never by a path inside the
installation)."""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass
from pathlib import Path

__all__: list[str] = []


@dataclass(frozen=True)
class Piece:
    """One command of the showcase: ``argv`` as typed after ``dumbbell`` (the scene, where
    there is one, by the name of a shipped scene), without ``--out``; ``writes``, the files
    it leaves in the folder that ``renders/`` tracks; ``measured``, those of them that hold
    run times."""

    argv: tuple[str, ...]
    writes: tuple[str, ...]
    measured: tuple[str, ...] = ()

    @property
    def command(self) -> str:
        """The command as a user types it from a clone of the repository."""
        words = [f"scenes/{w}.toml" if i == 1 and self.scene else w
                 for i, w in enumerate(self.argv)]
        return "dumbbell " + " ".join(words)

    @property
    def scene(self) -> str | None:
        """The shipped scene the command runs, or None (``stability`` runs a catalogue)."""
        return self.argv[1] if len(self.argv) > 1 and not self.argv[1].startswith("-") \
            else None


#: Work-precision steps of the showcase's benchmark: half-decades from 1e-3 to 3.16e-6 s
#: (the default grid goes on to 1e-6 s, where pymunk alone takes a minute and a half).
BENCH_DTS = ("1e-3", "3.16e-4", "1e-4", "3.16e-5", "1e-5", "3.16e-6")

#: The showcase, in the order ``run --all`` makes it.
PIECES = (
    Piece(("run", "textbook-1d"), ("textbook-1d-positions.png", "textbook-1d-kinetic.png",
                                   "textbook-1d-potential.png", "textbook-1d.gif")),
    Piece(("run", "tilted-2d"), ("tilted-2d-energy.png", "tilted-2d-rotation.png",
                                 "tilted-2d.gif")),
    Piece(("run", "rigid-2d"), ("rigid-2d-energy.png", "rigid-2d-contact.png", "rigid-2d.gif")),
    Piece(("run", "topple-2d"), ("topple-2d-topple.png", "topple-2d.gif")),
    Piece(("compare", "textbook-1d"), ("textbook-1d-compare-positions.png",
                                       "textbook-1d-compare-error.png",
                                       "textbook-1d-compare-energy.png")),
    Piece(("restitution", "tilted-2d", "--elasticity", "0.5"), ("tilted-2d-restitution.png",)),
    Piece(("sweep", "textbook-1d", "--grid", "k=log:1e2:1e7:50", "dt=log:1e-6:1e-2:50",
           "--t-end", "1"), ("textbook-1d-sweep.png",)),
    Piece(("stability",), ("stability-map.png",)),
    # The budget is an hour: the default two minutes skip pymunk's 3.16e-6 s step on a
    # machine loaded enough to make it look slower, and the table must not depend on load.
    Piece(("bench", "textbook-1d", "--dts", *BENCH_DTS, "--repeat", "3", "--budget", "3600"),
          ("bench-textbook-1d.md", "bench-textbook-1d-work-precision.png",
           "bench-textbook-1d-convergence.png"),
          measured=("bench-textbook-1d.md", "bench-textbook-1d-work-precision.png")),
)


def tracked() -> set[str]:
    """Every file name the showcase writes into ``renders/``."""
    return {name for piece in PIECES for name in piece.writes}


def measured() -> set[str]:
    """The showcase's files that hold run times: rewritten by ``run --all``, never the same
    bytes twice."""
    return {name for piece in PIECES for name in piece.measured}


def load_packaged(name: str):
    """The shipped scene ``name``, read from the package and named ``scenes/NAME.toml``."""
    from ..model.scene import load_scene_file, packaged_scene

    # Read as any scene file is: no more than the size limit, whatever the file has become.
    return load_scene_file(packaged_scene(name), f"scenes/{name}.toml")


def parse(piece: Piece, out: Path, quiet: bool) -> argparse.Namespace:
    """``piece``'s command line as the parser reads it, writing into ``out``, with its scene
    loaded from the package."""
    from .app import build_parser

    args = build_parser().parse_args([*piece.argv, "--out", str(out),
                                      *(["-q"] if quiet else [])])
    if piece.scene is not None:
        args.scene = load_packaged(piece.scene)
    return args


def run_pieces(out: Path, quiet: bool = False, max_samples: int | None = None,
               max_frames: int | None = None) -> int:
    """Run every piece into ``out``; returns the worst exit status. Every piece's command
    line and scene are read before the first one runs. ``max_samples`` and ``max_frames``
    are the budgets of the ``run`` pieces (their defaults when None)."""
    from ..files import check_writable
    from .app import worst_status

    pieces = [(piece, parse(piece, out, quiet)) for piece in PIECES]
    # Every showcase file can be written, before the first piece runs (each piece then
    # checks and reserves all of its own outputs, as its command does).
    for piece in PIECES:
        for name in piece.writes:
            check_writable(out / name, f"--out {out}:", within=True)
    status = 0
    for piece, args in pieces:
        if piece.argv[0] == "run":
            if max_samples is not None:
                args.max_samples = max_samples
            if max_frames is not None:
                args.max_frames = max_frames
        if not quiet:
            sys.stderr.write(f"dumbbell run --all: {piece.command}\n")
        status = worst_status(status, int(args.func(args) or 0))
    return status
