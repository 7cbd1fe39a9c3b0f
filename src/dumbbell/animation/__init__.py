"""Layer 4, animation: frames of a trajectory painted with Pillow and written as a GIF."""
