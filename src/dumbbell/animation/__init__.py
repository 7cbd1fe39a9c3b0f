"""Layer 4, animation: frames of a trajectory painted with Pillow and written as a GIF, and
the interactive player page drawn from the same description of a frame."""

#: :mod:`.render` holds the API (``render_gif``); :mod:`.drawing` the painter behind it, put
#: together from :mod:`.layout`, :mod:`.world`, :mod:`.bars`, :mod:`.strip`, :mod:`.palette`,
#: :mod:`.glyphs`, :mod:`.backdrop` and :mod:`.frames`, drawing what :mod:`.picture`
#: describes; :mod:`.player` (``player``) the interactive page drawn from that same
#: description; :mod:`.recording` the painter behind ``dumbbell.spaces.Recorder``, from the
#: same pieces (no public names of their own).
from .._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, ["drawing", "player", "render"])
