"""Colour of each particle, the centre of mass and each energy term: the figures'
(:mod:`dumbbell.plot.style`, where every other colour, label and line style is) and the
animations' (:mod:`dumbbell.animation.palette`, whose GIF palette is built from these). Kept
apart from both so that drawing a GIF does not import the figures' package."""

from __future__ import annotations

#: No public names.
__all__: list[str] = []

COLOURS = {"A": "#1f77b4", "B": "#d62728", "cm": "black", "K_cm": "#1f77b4", "K_int": "#d62728",
           "K_rot": "#2ca02c", "K_vib": "#d62728", "K_spin": "#9467bd", "U_g": "#8c564b",
           "U_spring": "#e6a700", "E": "black", "E_lost": "#7f7f7f"}
