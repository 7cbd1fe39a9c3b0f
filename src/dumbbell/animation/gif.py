"""The GIF encoder that ``render_gif`` and the pymunk-space recorder share.

One global palette (:func:`dumbbell.animation.palette.palette`), 'loop forever', and each frame
after the first holding only the rectangle that changed, with unchanged pixels in it marked
transparent (disposal 'leave in place'); Pillow's C encoder compresses each rectangle (LZW).
Frames are arrays of palette indices (uint8, height x width); delays are in 10 ms units.
Same frames, same bytes.

The names here serve the animation's modules and :mod:`dumbbell.spaces.recorder`; the
public API is ``render_gif`` and ``Recorder``.
"""

from __future__ import annotations

import io
import time
from collections.abc import Callable, Sequence
from typing import BinaryIO

import numpy as np

from .palette import palette

__all__: list[str] = []

#: The byte that ends a GIF file.
TRAILER = b"\x3b"


def write_frames(fh: BinaryIO, size: tuple[int, int], frame: Callable[[int], np.ndarray],
                 delays: Sequence[int], on_frame: Callable[[], object] | None = None,
                 region: Callable[[int], tuple[int, int, int, int] | None] | None = None
                 ) -> tuple[float, float]:
    """Write a whole GIF of ``size`` (width, height px) to the binary file ``fh``: frame k is
    ``frame(k)`` (palette indices), shown for ``delays[k]`` x 10 ms, for every k in
    ``delays``. ``on_frame`` is called after each frame (a progress bar). ``region(k)``, if
    given, is a box (px: left, top, right, bottom) outside which frame k is known to equal
    frame k - 1 (None: anywhere), so only it is compared. Returns the seconds spent in
    ``frame`` (drawing) and in encoding."""
    pal, clear = palette()
    fh.write(header(*size, pal))
    previous: np.ndarray | None = None
    draw = encode = 0.0
    for k, delay in enumerate(delays):
        t1 = time.perf_counter()
        current = np.asarray(frame(k))
        t2 = time.perf_counter()
        within = region(k) if region is not None else None
        fh.write(encode_frame(*delta(previous, current, clear, within), delay, clear))
        draw += t2 - t1
        encode += time.perf_counter() - t2
        previous = current
        if on_frame is not None:
            on_frame()
    fh.write(TRAILER)
    return draw, encode


def header(width: int, height: int, pal: bytes) -> bytes:
    """GIF89a header, the global palette (256 colours) and 'loop forever'."""
    lsd = width.to_bytes(2, "little") + height.to_bytes(2, "little") + bytes([0xF7, 0, 0])
    loop = b"\x21\xff\x0bNETSCAPE2.0\x03\x01" + (0).to_bytes(2, "little") + b"\x00"
    return b"GIF89a" + lsd + pal + loop


def delta(previous: np.ndarray | None, current: np.ndarray, clear: int,
          within: tuple[int, int, int, int] | None = None
          ) -> tuple[np.ndarray, int, int, bool]:
    """The rectangle of ``current`` that differs from ``previous``, unchanged pixels set to
    ``clear``; with its left and top (px) and whether it uses transparency. ``within`` (px:
    left, top, right, bottom): the frames are known to be equal outside it, so only it is
    compared (the same result, sooner)."""
    if previous is None:
        return current, 0, 0, False
    left = top = 0
    if within is not None:
        left, top = max(0, within[0]), max(0, within[1])
        previous = previous[top:max(top, within[3]), left:max(left, within[2])]
        current = current[top:max(top, within[3]), left:max(left, within[2])]
    changed = previous != current
    rows = np.flatnonzero(changed.any(axis=1))
    if len(rows) == 0:
        return np.full((1, 1), clear, dtype=np.uint8), 0, 0, True
    cols = np.flatnonzero(changed.any(axis=0))
    y0, y1, x0, x1 = rows[0], rows[-1] + 1, cols[0], cols[-1] + 1
    sub = current[y0:y1, x0:x1].copy()
    sub[~changed[y0:y1, x0:x1]] = clear
    return sub, int(x0) + left, int(y0) + top, True


def encode_frame(pixels: np.ndarray, left: int, top: int, transparent: bool, delay: int,
                 clear: int) -> bytes:
    """One frame: graphic control extension (delay in 10 ms units, 'leave in place',
    transparency) and the image, LZW-compressed by Pillow."""
    h, w = pixels.shape
    gce = bytes([0x21, 0xF9, 4, (1 << 2) | int(transparent)]) + delay.to_bytes(2, "little") \
        + bytes([clear if transparent else 0, 0])
    desc = b"\x2c" + b"".join(v.to_bytes(2, "little") for v in (left, top, w, h)) + b"\x00"
    return gce + desc + _lzw(pixels)


def _lzw(pixels: np.ndarray) -> bytes:
    """The LZW image data (code size byte, sub-blocks, terminator) of palette indices, by
    Pillow's GIF encoder (C; it keeps indices as given): called as Pillow's GIF writer calls
    it for a one-frame GIF (code size 8, not interlaced), which is what
    :func:`_lzw_of_a_gif` takes from such a file, byte for byte, without the file's headers
    and palette around it."""
    from PIL import Image, ImageFile

    im = Image.frombuffer("L", (pixels.shape[1], pixels.shape[0]), np.ascontiguousarray(pixels),
                          "raw", "L", 0, 1)
    tile = getattr(ImageFile, "_Tile", None)
    if tile is None:  # an older Pillow: through a whole one-frame GIF
        return _lzw_of_a_gif(im)
    buf = io.BytesIO()
    im.encoderconfig = (8, False)
    ImageFile._save(im, buf, [tile("gif", (0, 0, *im.size), 0, "L")])
    return b"\x08" + buf.getvalue() + b"\x00"


def _lzw_of_a_gif(im: object) -> bytes:
    """The first image's LZW data of a one-frame GIF that Pillow writes of the "L" image
    ``im``."""
    buf = io.BytesIO()
    im.save(buf, "GIF", optimize=False, interlace=False)  # type: ignore[attr-defined]
    return _image_data(buf.getvalue())


def _image_data(gif: bytes) -> bytes:
    """The first image's LZW data block of a GIF file, terminator included."""
    pos = 13
    if gif[10] & 0x80:
        pos += 3 << ((gif[10] & 7) + 1)
    while True:
        marker = gif[pos]
        if marker == 0x21:  # extension: label, then sub-blocks
            pos += 2
            pos = _skip_blocks(gif, pos)
        elif marker == 0x2C:
            flags = gif[pos + 9]
            pos += 10
            if flags & 0x80:
                pos += 3 << ((flags & 7) + 1)
            start = pos
            return gif[start:_skip_blocks(gif, pos + 1)]
        else:
            raise ValueError(f"unexpected GIF block 0x{marker:02x}")


def _skip_blocks(data: bytes, pos: int) -> int:
    while data[pos]:
        pos += data[pos] + 1
    return pos + 1
