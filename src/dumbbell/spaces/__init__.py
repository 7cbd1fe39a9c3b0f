"""Tools for any pymunk space the user built: energy and momentum accounting, a step-size
guard, a heat counter for contacts, and offline GIF/MP4 recording.

>>> from dumbbell import spaces                                     # doctest: +SKIP
>>> e = spaces.energy(space, about=(0.0, 0.0))                      # doctest: +SKIP
>>> e.E, e.K_int, e.momentum, e.L_cm                                # doctest: +SKIP
>>> for f in spaces.check(space, dt=1 / 60):                        # doctest: +SKIP
...     print(f)
>>> heat = spaces.HeatCounter(space)                                # doctest: +SKIP
>>> with spaces.Recorder(space, "out.gif", fps=25) as rec:          # doctest: +SKIP
...     for frame in range(100):
...         spaces.step(space, 1 / 25, substeps=10)
...         rec.capture()

Each name is imported when first used: ``import dumbbell.spaces`` loads neither pymunk nor
matplotlib nor imageio (the recorder loads Pillow and, for MP4, imageio).
"""

from __future__ import annotations

import importlib
from typing import Any

#: Public name -> submodule that defines it.
_WHERE = {
    "energy": "accounting", "SpaceEnergy": "accounting", "BodyEnergy": "accounting",
    "SpringEnergy": "accounting", "Skipped": "accounting",
    "check": "guard", "survey": "guard", "suggest_dt": "guard", "substeps": "guard",
    "report": "guard", "Finding": "guard", "step": "stepping", "Driver": "stepping",
    "spring_omega": "guard", "shape_size": "guard", "energy_swing": "guard",
    "reach": "estimates", "Reach": "estimates",
    "HeatCounter": "heat",
    "Ledger": "ledger", "Balance": "balance", "Term": "balance",
    "Recorder": "recorder", "PaletteDrawOptions": "recorder", "draw_options": "recorder",
}

__all__ = list(_WHERE)


def __getattr__(name: str) -> Any:
    if name in _WHERE:
        value = getattr(importlib.import_module(f"{__name__}.{_WHERE[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_WHERE))
