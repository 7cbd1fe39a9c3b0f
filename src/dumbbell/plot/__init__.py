"""Static figures, drawn with matplotlib (imported only when a figure is drawn).

Every function draws on the axes ``ax`` it is given, or makes its own figure when given none,
and returns the axes (``ax.figure`` is the figure). None chooses a matplotlib backend and none
saves: :func:`dumbbell.io.figures.save_figure` does. Colours are in :mod:`.style`. A figure of
its own fits its canvas whatever the number of panels and the length of its texts (legends
outside the axes); on the user's axes a figure stays inside them (its legend in a band above
the data), so that several share a grid without squeezing each other.

>>> ax = dumbbell.plot.kinetic(traj)                                    # doctest: +SKIP
>>> dumbbell.plot.compare(dumbbell.analysis.compare.compare(scene), ax=my_axes)  # doctest: +SKIP

Of a trajectory: :func:`positions`, :func:`kinetic`, :func:`potential`, :func:`energy`.
Of analysis results: :func:`rotation` (a rotation preview), :func:`compare`,
:func:`compare_positions`, :func:`compare_energy` (a comparison), :func:`work_precision`,
:func:`convergence` (a benchmark), :func:`sweep_map`, :func:`stability_map`,
:func:`restitution`, :func:`topple` and :func:`contact_momentum` (the rotation chapter).
"""

from __future__ import annotations

from .bench import convergence, work_precision
from .compare import compare, compare_energy, compare_positions
from .maps import stability_map, sweep_map
from .rotation import rotation
from .rotation_chapter import contact_momentum, restitution, topple
from .trajectory import energy, kinetic, positions, potential

__all__ = [
    "compare", "compare_energy", "compare_positions", "contact_momentum", "convergence", "energy", "kinetic",
    "positions", "potential", "restitution", "rotation", "stability_map", "sweep_map", "topple",
    "work_precision",
]
