"""The one place colours, labels and line styles are defined, for figures and animations
(the particles' and energy terms' colours in :mod:`dumbbell.colours`, re-exported here).

Also :func:`pyplot`, the lazy import of matplotlib's pyplot, and how the package's figures are
made (:func:`_figure`, :func:`_subplots`): through pyplot, so that a notebook shows them and
``plt.show()`` opens them; but within :func:`dumbbell._install.command_line` (the ``dumbbell``
command, which only writes files), as a bare ``matplotlib.figure.Figure`` on the Agg canvas,
without importing pyplot. The pixels are the same either way. None of this chooses
a backend: a notebook keeps its own.
"""

from __future__ import annotations

from typing import Any

# Colour of each particle, the centre of mass and each energy term: defined apart, because the
# animations' palette is built from them without importing this package.
from ..colours import COLOURS  # noqa: F401  (re-exported)

#: No public names: the colours every figure shares.
__all__: list[str] = []

def plain(text: str) -> str:
    """``text`` of the user's (a scene's title or name) as matplotlib shows it letter for
    letter: it reads text between two ``$`` as mathtext, which a title such as ``"price
    $\\frac{ and $ end"`` breaks when the figure is drawn. The package's own labels use no
    mathtext; tick labels (which do, on log axes) are not touched."""
    return str(text).replace("$", r"\$")


#: Colour of the angular momentum L_cm (kept out of COLOURS: the GIF's palette is built from
#: those, and L_cm is text there, drawn in ink).
MOMENTUM_COLOUR = "#17becf"
#: Colour of E_heat, the energy the contacts dissipated (figures only, like L_cm).
HEAT_COLOUR = "#ff7f0e"

#: Legend text of each energy term.
LABELS = {"K_cm": "K_cm, centre of mass", "K_int": "K_int, relative to the centre of mass",
          "K_rot": "K_rot, rotation", "K_vib": "K_vib, vibration", "K_spin": "K_spin, own spin",
          "U_g": "U_g = M g X, external", "U_spring": "U_spring, internal", "E": "E, total",
          "E_lost": "E_lost", "E_heat": "E_heat, dissipated by contacts"}

#: Colour and marker of each solver in the benchmark figures.
SOLVER_STYLES = {"euler-cromer": ("#d62728", "o"), "verlet": ("#1f77b4", "s"),
                 "pymunk": ("#2ca02c", "^"), "euler-cromer-2d": ("#ff7f0e", "v"),
                 "exact": ("black", "*"), "reference": ("#9467bd", "P")}

#: Colours of the compared runs, in row order.
ROW_COLOURS = ["#d62728", "#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2"]
#: Line styles by row: runs that agree to rounding (pymunk and euler-cromer-2d) stay visible.
ROW_DASHES = ["-", (0, (4, 3)), (0, (1, 2)), "-.", "-", (0, (4, 3)), (0, (1, 2))]

#: Colours of the ways a run can fail, in the stability and sweep maps.
FAIL_COLOURS = {"unstable": "#bdbdbd", "tunnelled": "#f4a582", "failed": "#4d4d4d"}



def solver_style(name: str, i: int) -> tuple[str, str]:
    """Colour and marker of solver ``name``; the ``i``-th default for one without a style."""
    from ..model import args

    name = args.text(name, "name", "a solver name (str)")
    i = args.whole(i, "i", "index", lo=0)
    return SOLVER_STYLES.get(name, (f"C{i % 10}", "D"))


def legend_outside(ax: Any, *args: Any, **kwargs: Any) -> Any:
    """``ax.legend(*args, **kwargs)`` outside the axes, on the right, its top level with the
    axes' top: no curve of the axes can run through it, whatever the data (the figures are
    checked for that). ``fontsize`` is 8 unless given. Returns the legend. For the package's
    figures (not exported): ``ax`` is theirs."""
    kwargs.setdefault("fontsize", 8)
    return ax.legend(*args, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0,
                     **kwargs)


def pyplot() -> Any:
    """matplotlib.pyplot, imported on first use (whatever backend is configured)."""
    import matplotlib.pyplot as plt

    return plt


def _figure(**kwargs: Any) -> Any:
    """A new figure (``kwargs`` as ``Figure`` takes them): pyplot's, or within
    :func:`dumbbell._install.command_line` a bare one on the Agg canvas."""
    from .._install import COMMAND_LINE

    if not COMMAND_LINE.get():
        return pyplot().figure(**kwargs)
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(**kwargs)
    FigureCanvasAgg(fig)
    return fig


#: The keywords of ``pyplot.subplots`` that go to ``Figure.subplots`` (the rest make the figure).
_GRID_KEYWORDS = ("sharex", "sharey", "squeeze", "gridspec_kw")


def _subplots(nrows: int = 1, ncols: int = 1, **kw: Any) -> tuple[Any, Any]:
    """``pyplot.subplots`` by way of :func:`_figure`: the figure and its grid of axes."""
    grid = {k: kw.pop(k) for k in _GRID_KEYWORDS if k in kw}
    fig = _figure(**kw)
    return fig, fig.subplots(nrows, ncols, **grid)
