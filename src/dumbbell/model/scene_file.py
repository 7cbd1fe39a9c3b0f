"""Scene files on disk: a file read safely (a regular file, at most :data:`MAX_SCENE_BYTES`,
never waiting on a FIFO)."""

from __future__ import annotations

import os
import stat
from pathlib import Path

from ..errors import SceneError

#: No public names: ``load_scene`` is :mod:`dumbbell.model.scene`'s.
__all__: list[str] = []

#: Largest scene file read (bytes).
MAX_SCENE_BYTES = 1_000_000


def _read_scene_file(path: Path) -> bytes:
    """The bytes of ``path`` if it is a regular file of at most MAX_SCENE_BYTES; SceneError
    for a device, a FIFO, a socket or a larger file. Opened without blocking, so that a FIFO
    with no writer is refused rather than waited on."""
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    try:
        info = os.fstat(fd)
        if stat.S_ISDIR(info.st_mode):
            raise IsADirectoryError
        if not stat.S_ISREG(info.st_mode):
            raise SceneError(f"{path}: is {_file_kind(info.st_mode)}, not a regular file; a "
                             "scene is a TOML file")
        if info.st_size > MAX_SCENE_BYTES:
            raise SceneError(f"{path}: is {info.st_size:,} bytes; a scene file may be at most "
                             f"{MAX_SCENE_BYTES:,} bytes (1 MB)")
        with os.fdopen(fd, "rb", closefd=False) as fh:
            data = fh.read(MAX_SCENE_BYTES + 1)
    finally:
        os.close(fd)
    if len(data) > MAX_SCENE_BYTES:  # it grew while we read it
        raise SceneError(f"{path}: more than {MAX_SCENE_BYTES:,} bytes; a scene file may be at "
                         "most 1 MB")
    return data


def _file_kind(mode: int) -> str:
    """'a character device', 'a FIFO', ... for an ``st_mode``."""
    for test, kind in ((stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
                       (stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return kind
    return "not a regular file"
