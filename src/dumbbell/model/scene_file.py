"""Scene files on disk: a file read safely (a regular file, at most :data:`MAX_SCENE_BYTES`,
never waiting on a FIFO) and its TOML parsed, integers too long for Python kept to be named."""

from __future__ import annotations

import os
import stat
import tomllib
from pathlib import Path
from typing import Any

from ..errors import SceneError
from .checker import _LongInteger, _printable

#: No public names: ``load_scene`` is :mod:`dumbbell.model.scene`'s.
__all__: list[str] = []

#: Largest scene file read (bytes).
MAX_SCENE_BYTES = 1_000_000


#: A decimal integer of more digits than Python converts from text (sys.int_info's default
#: limit, 4,300 digits), in a TOML document: a number's sign and digits, '_' between them.
_LONG_INTEGER = r"(?<![\w.+-])([+-]?)([0-9](?:_?[0-9]){4300,})(?![\w.])"


def _toml(text: str) -> dict[str, Any]:
    """``tomllib.loads(text)``, except that a decimal integer too long for Python to read
    ('Exceeds the limit (4300 digits) for integer string conversion', naming no key) is
    read as a :class:`_LongInteger` at its key, which the scene's checks then name."""
    import re

    try:
        return tomllib.loads(text)
    except ValueError as exc:
        if isinstance(exc, tomllib.TOMLDecodeError) or "integer string" not in str(exc):
            raise
    longs: dict[int, _LongInteger] = {}

    def stand_in(match: re.Match[str]) -> str:
        # A hexadecimal integer (no limit on those) marks the place.
        marker = 0x5CE7E << 64 | len(longs)
        longs[marker] = _LongInteger(match[1], len(match[2].replace("_", "")))
        return hex(marker)

    data = tomllib.loads(re.sub(_LONG_INTEGER, stand_in, text))

    def swap(node: Any) -> Any:
        if isinstance(node, dict):
            return {k: swap(v) for k, v in node.items()}
        if isinstance(node, list):
            return [swap(v) for v in node]
        return longs.get(node, node) if type(node) is int else node

    return swap(data)


def _read_scene_file(path: Path, source: str) -> bytes:
    """The bytes of ``path`` (named ``source``) if it is a regular file of at most
    MAX_SCENE_BYTES; SceneError for a device, a FIFO, a socket or a larger file, before
    reading (a 3 GB sparse file is refused from its size). Opened without blocking, so that
    a FIFO with no writer is refused rather than waited on."""
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    try:
        info = os.fstat(fd)
        if stat.S_ISDIR(info.st_mode):
            raise IsADirectoryError
        if not stat.S_ISREG(info.st_mode):
            raise SceneError(f"{_printable(source)}: "
                             f"is {_file_kind(info.st_mode)}, not a regular file; a "
                             "scene is a TOML file")
        if info.st_size > MAX_SCENE_BYTES:
            raise SceneError(f"{_printable(source)}: "
                             f"is {info.st_size:,} bytes; a scene file may be at most "
                             f"{MAX_SCENE_BYTES:,} bytes (1 MB)")
        with os.fdopen(fd, "rb", closefd=False) as fh:
            data = fh.read(MAX_SCENE_BYTES + 1)
    finally:
        os.close(fd)
    if len(data) > MAX_SCENE_BYTES:  # it grew while we read it
        raise SceneError(f"{_printable(source)}: "
                         f"more than {MAX_SCENE_BYTES:,} bytes; a scene file may be at "
                         "most 1 MB")
    return data


def _file_kind(mode: int) -> str:
    """'a character device', 'a FIFO', ... for an ``st_mode``."""
    for test, kind in ((stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
                       (stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return kind
    return "not a regular file"
