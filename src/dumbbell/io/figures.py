"""Saving a matplotlib figure: atomically (no partial PNG) and then closing it."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..errors import UsageError
from ..model import args
from .files import atomic_output

#: No public names: the commands save the figures that :mod:`dumbbell.plot` draws.
__all__: list[str] = []

#: Resolution of saved figures (dots per inch), and the most allowed (past it the image of a
#: figure of a few inches runs into the renderer's size limit).
DPI = 110
MAX_DPI = 2000


def save_figure(fig: Any, path: str | Path, dpi: float | str = DPI) -> Path:
    """Write ``fig`` to ``path`` (format from its suffix) at ``dpi`` (dots per inch, or
    "figure" for the figure's own) and close it; returns the path."""
    import matplotlib.pyplot as plt

    fig = args.figure(fig)
    path = args.path(path, "path")
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
        fig.savefig(tmp, dpi=dpi)
    plt.close(fig)
    return path
