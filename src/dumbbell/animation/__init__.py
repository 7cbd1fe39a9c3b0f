"""Layer 4, animation: frames of a trajectory painted with Pillow and written as a GIF."""

#: :mod:`.render` holds the API (``render_gif``); :mod:`.drawing` the painter behind it.
__all__ = ["drawing", "render"]
