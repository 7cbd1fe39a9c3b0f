"""The one fixed 256-colour palette every GIF frame is drawn in, and its inks.

Why a fixed palette: quantizing every RGB frame to 256 colours costs more than drawing it.
The palette holds each ink blended with white in 15 steps (so smooth edges drawn in RGB map
back exactly), a grey ramp and the floor colour; one index is kept free for 'unchanged' (GIF
transparency).
"""

from __future__ import annotations

from functools import lru_cache

from PIL import Image

from ..colours import COLOURS

#: No public names: a piece of the painter behind :func:`dumbbell.animation.render.render_gif`
#: and :class:`dumbbell.spaces.Recorder`.
__all__: list[str] = []

WHITE = (255, 255, 255)
BLACK = (0, 0, 0)
INK = (34, 34, 34)
GREY = (110, 110, 110)
LIGHT = (200, 200, 200)
FLOOR = (232, 232, 232)
SPRING = (70, 70, 70)
#: Levels of each ink's blend with white.
BLEND_LEVELS = 15


def _hex(colour: str) -> tuple[int, int, int]:
    named = {"black": "#000000"}
    colour = named.get(colour, colour)
    return int(colour[1:3], 16), int(colour[3:5], 16), int(colour[5:7], 16)


#: Colours of the energy terms and particles, the same as the figures'.
TERM_RGB = {name: _hex(c) for name, c in COLOURS.items()}
TERM_RGB["E"] = BLACK
#: Opacity of the pale version of a term's colour (what a bar reached since the last frame).
TINT = 0.33


@lru_cache(maxsize=1)
def palette() -> tuple[bytes, int]:
    """The fixed palette as 768 RGB bytes, and the index kept free for 'unchanged' (GIF
    transparency): each ink blended with white in 15 steps, a grey ramp, the floor colour."""
    inks = [BLACK, INK, GREY, SPRING, *sorted(set(TERM_RGB.values()))]
    colours: list[tuple[int, int, int]] = [WHITE, FLOOR, LIGHT]
    for ink in inks:
        for level in range(1, BLEND_LEVELS + 1):
            a = level / BLEND_LEVELS
            c = tuple(round(255 + (v - 255) * a) for v in ink)
            colours.append(c)  # type: ignore[arg-type]
    for v in range(0, 256, 8):
        colours.append((v, v, v))
    unique: list[tuple[int, int, int]] = []
    for c in colours:
        if c not in unique:
            unique.append(c)
    if len(unique) > 255:  # a GIF palette holds 256 colours, one kept for padding
        raise RuntimeError(f"the GIF palette needs {len(unique)} colours, more than 255")
    # Pad with white: ties go to the lowest index, so padding is never chosen.
    unique += [WHITE] * (256 - len(unique))
    return bytes(v for c in unique for v in c), 255


@lru_cache(maxsize=1)
def _palette_image() -> Image.Image:
    pal = Image.new("P", (1, 1))
    pal.putpalette(palette()[0])
    return pal


def to_palette(rgb: Image.Image) -> Image.Image:
    """Map an RGB image to the fixed palette (nearest colour, no dithering)."""
    return rgb.quantize(palette=_palette_image(), dither=Image.Dither.NONE)


def blend(rgb: tuple[int, int, int], a: float) -> tuple[int, int, int]:
    """``rgb`` at opacity ``a`` over white, snapped to the palette's blend levels."""
    level = max(1, min(BLEND_LEVELS, round(a * BLEND_LEVELS))) / BLEND_LEVELS
    return tuple(round(255 + (v - 255) * level) for v in rgb)  # type: ignore[return-value]


def ink_index(rgb: tuple[int, int, int]) -> int:
    """The palette index of the colour ``rgb`` (KeyError if the palette lacks it)."""
    pal = palette()[0]
    for i in range(256):
        if tuple(pal[3 * i:3 * i + 3]) == rgb:
            return i
    raise KeyError(rgb)


@lru_cache(maxsize=1)
def term_inks() -> dict[str, int]:
    """Palette index of each term's colour by name, and of "ink" and "grey"."""
    out = {name: ink_index(rgb) for name, rgb in TERM_RGB.items()}
    out.update({"ink": ink_index(INK), "grey": ink_index(GREY)})
    return out

