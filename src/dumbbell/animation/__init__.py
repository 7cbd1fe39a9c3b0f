"""Layer 4, animation: frames of a trajectory painted with Pillow and written as a GIF."""

#: :mod:`.render` holds the API (``render_gif``); :mod:`.drawing` the painter behind it, put
#: together from :mod:`.layout`, :mod:`.world`, :mod:`.bars`, :mod:`.strip`, :mod:`.palette`,
#: :mod:`.glyphs`, :mod:`.backdrop` and :mod:`.frames`; :mod:`.recording` the painter behind
#: ``dumbbell.spaces.Recorder``, from the same pieces (no public names of their own).
from .._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, ["drawing", "render"])
