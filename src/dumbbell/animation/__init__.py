"""Layer 4, animation: frames of a trajectory painted with Pillow and written as a GIF, and
the interactive player page drawn from the same description of a frame."""

#: :mod:`.render` holds the API (``render_gif``); :mod:`.painter` the one painter of every
#: animation's frames, a scene's (its panel in :mod:`.world`, drawing what :mod:`.picture`
#: describes, laid out by :mod:`.layout`) and a recorded space's (its panel in
#: :mod:`.recording`, behind ``dumbbell.spaces.Recorder``), with the same :mod:`.bars`,
#: :mod:`.strip`, :mod:`.palette` and :mod:`.glyphs`; :mod:`.player` (``player``) the
#: interactive page drawn from that same description (no public names of their own).
from .._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, ["painter", "player", "render"])
