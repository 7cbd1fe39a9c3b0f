"""Layer 4, static figures drawn with matplotlib (imported only when a figure is drawn)."""
