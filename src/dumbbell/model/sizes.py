"""A GIF's size in pixels: the rule and its parser, shared by the scene reader
(``outputs.gif.size``) and the animations (``--size``, the recorder's ``size``); apart from
both, so that neither imports the other."""

from __future__ import annotations

from typing import Any

#: No public names.
__all__: list[str] = []

#: What a GIF size must be (the scene's ``outputs.gif.size``, ``--size``, the recorder's).
SIZE_RULE = "must be WIDTHxHEIGHT in pixels, each between 64 and 4096"


def pixel_size(text: Any) -> tuple[int, int] | None:
    """'640x360' -> (640, 360); None when not a valid size (:data:`SIZE_RULE`)."""
    if not isinstance(text, str):
        return None
    parts = text.lower().split("x")
    # ASCII digits only, and few: int() rejects other Unicode digits and huge strings.
    if len(parts) != 2 or not all(p.isascii() and p.isdigit() and len(p) <= 6 for p in parts):
        return None
    w, h = int(parts[0]), int(parts[1])
    return (w, h) if 64 <= w <= 4096 and 64 <= h <= 4096 else None
