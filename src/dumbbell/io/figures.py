"""Saving a matplotlib figure: atomically (no partial PNG) and then closing it."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from .files import atomic_output

#: Resolution of saved figures (dots per inch).
DPI = 110


def save_figure(fig: Any, path: str | Path, dpi: float | str = DPI) -> Path:
    """Write ``fig`` to ``path`` (format from its suffix) at ``dpi`` (dots per inch, or
    "figure" for the figure's own) and close it; returns the path."""
    import matplotlib.pyplot as plt

    path = Path(path)
    with atomic_output(path) as tmp:
        fig.savefig(tmp, dpi=dpi)
    plt.close(fig)
    return path
