"""Output files that appear whole or not at all."""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path


@contextmanager
def atomic_output(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; rename it to ``path`` only if the block succeeds.

    An interrupted or failed write leaves no half-written file behind.

    >>> with atomic_output("out.csv") as tmp:        # doctest: +SKIP
    ...     tmp.write_text("t,x\\n")
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part" + path.suffix,
                                dir=path.parent)
    os.close(fd)
    tmp = Path(name)
    try:
        yield tmp
        if tmp.exists():
            # mkstemp makes private files; outputs get the usual permissions.
            umask = os.umask(0)
            os.umask(umask)
            os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def check_writable(path: str | Path, flag: str, folder: bool = False) -> None:
    """Raise UsageError naming ``flag`` unless ``path`` (a folder if ``folder``, else a file)
    could be created or replaced: called before any work, so nothing is half written."""
    from ..errors import UsageError

    path = Path(path)
    if folder and path.exists() and not path.is_dir():
        raise UsageError(f"{flag} {path}: exists and is not a folder")
    if not folder and path.is_dir():
        raise UsageError(f"{flag} {path}: is a folder; give a file name")
    here = path if folder else path.parent
    here = here if str(here) else Path(".")
    while not here.exists() and here != here.parent:
        here = here.parent
    if not here.is_dir():
        raise UsageError(f"{flag} {path}: {here} is a file, not a folder")
    if not os.access(here, os.W_OK | os.X_OK):
        raise UsageError(f"{flag} {path}: cannot write in {here} (permission denied)")
