"""Saving a matplotlib figure: atomically (no partial PNG) and then closing it."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

from ..errors import UsageError
from ..files import atomic_output, writable_path
from ..model import args

#: No public names: the commands save the figures that :mod:`dumbbell.plot` draws.
__all__: list[str] = []

#: Resolution of saved figures (dots per inch), and the most allowed (past it the image of a
#: figure of a few inches runs into the renderer's size limit).
DPI = 110
MAX_DPI = 2000


def save_figure(fig: Any, path: str | Path, dpi: float | str = DPI) -> Path:
    """Write ``fig`` to ``path`` (format from its suffix) at ``dpi`` (dots per inch, or
    "figure" for the figure's own) and close it; returns the path."""
    fig = args.figure(fig)
    path = writable_path(path)
    formats = fig.canvas.get_supported_filetypes()
    if path.suffix[1:].lower() not in formats:
        raise UsageError(f"path = {args.show(str(path))}: must end in a figure format: "
                         f"{', '.join('.' + f for f in sorted(formats))}", param="path")
    if dpi != "figure":
        if isinstance(dpi, str):
            raise UsageError(f"dpi = {args.show(dpi)}: must be a number > 0 (dots per inch) or "
                             "'figure'", param="dpi")
        args.real(dpi, "dpi", "dots per inch", lo=1, hi=MAX_DPI)
    with atomic_output(path) as tmp:
        write_figure(fig, tmp, dpi)
    return path


def write_figure(fig: Any, path: str | Path, dpi: float | str = DPI) -> None:
    """Write the checked figure ``fig`` to the file ``path`` itself (format from its suffix),
    then close it: :func:`save_figure` past its checks, for a caller that already holds the
    file to write (a temporary file of :func:`~dumbbell.files.atomic_output`)."""
    from matplotlib.layout_engine import ConstrainedLayoutEngine, PlaceHolderLayoutEngine

    engine = fig.get_layout_engine()
    if isinstance(engine, PlaceHolderLayoutEngine) or (
            isinstance(engine, ConstrainedLayoutEngine) and not fig.stale):
        # What tight_layout() leaves behind lays nothing out, and a constrained layout done
        # since the figure last changed (dumbbell.plot's figures are laid out when drawn) is
        # done: its places are fractions of the figure, the same at the dpi written. Either
        # way savefig would draw the whole figure once more for it, without rendering (and
        # lay it out again), before drawing it for real.
        fig.set_layout_engine(None)
    fig.savefig(path, dpi=dpi)
    # Only pyplot keeps figures open (a bare Figure is freed with its last reference); its
    # import is not paid for a figure it never made.
    plt = sys.modules.get("matplotlib.pyplot")
    if plt is not None:
        plt.close(fig)
