"""The pymunk releases dumbbell runs on, checked once at the first use of pymunk (the pymunk
solver's build, the first name read from :mod:`dumbbell.spaces`), never at ``import
dumbbell``; and the one thing dumbbell reads that differs between them: which function a
spring uses for its force.

The range is ``pyproject.toml``'s (a test checks they agree); ``benchmarks/pymunk_versions.py``
runs the whole surface on each release in it.
"""

from __future__ import annotations

import functools
import re

from .errors import PymunkVersionError

TYPE_CHECKING = False
if TYPE_CHECKING:
    from collections.abc import Callable
    from types import ModuleType
    from typing import Any

#: The supported range: at least LOWEST, below BELOW (release numbers), as pip spells it.
LOWEST, BELOW = (7, 0), (8,)
RANGE = "pymunk>=7.0,<8"

#: A PEP 440 version: its release numbers, then an optional pre-release, post-release,
#: development mark and local label (``7.2.0rc1``, ``7.3.1.post1``, ``7.3.1+local``).
_VERSION = re.compile(r"v?(?P<release>\d+(?:\.\d+)*)"
                      r"(?P<pre>[-_.]?(?:a|b|c|rc|alpha|beta|pre|preview)[-_.]?\d*)?"
                      r"(?P<post>[-_.]?(?:post|rev|r)[-_.]?\d*|-\d+)?"
                      r"(?P<dev>[-_.]?dev[-_.]?\d*)?"
                      r"(?:\+[a-z0-9]+(?:[-_.][a-z0-9]+)*)?", re.IGNORECASE)


def release(version: str) -> tuple[tuple[int, ...], bool] | None:
    """``version``'s release numbers and whether it comes before that release (a pre-release
    or development release: ``'7.2.0rc1'`` -> ``((7, 2, 0), True)``), None when it is not a
    version string."""
    if not isinstance(version, str) or len(version) > 100:
        return None
    m = _VERSION.fullmatch(version.strip())
    if m is None:
        return None
    before = m["pre"] is not None or (m["dev"] is not None and m["post"] is None)
    return tuple(int(n) for n in m["release"].split(".")), before


def _pad(numbers: tuple[int, ...], width: int) -> tuple[int, ...]:
    return numbers + (0,) * (width - len(numbers))


def supported(version: str) -> bool:
    """Whether pymunk ``version`` is in :data:`RANGE` (as pip reads it: a pre-release of the
    lowest release is below it, and none of BELOW's pre-releases is below BELOW)."""
    parsed = release(version)
    if parsed is None:
        return False
    numbers, pre = parsed
    width = max(len(numbers), len(LOWEST), len(BELOW))
    numbers, low, high = _pad(numbers, width), _pad(LOWEST, width), _pad(BELOW, width)
    return (numbers > low or (numbers == low and not pre)) and numbers < high


def check(version: str) -> None:
    """Nothing when pymunk ``version`` is supported, else :class:`PymunkVersionError`."""
    if not supported(version):
        shown = version.strip() if release(version) is not None and len(version) <= 40 else (
            repr(version) if len(repr(version)) <= 40 else repr(version)[:37] + "...")
        raise PymunkVersionError(f"pymunk {shown} is installed; dumbbell needs {RANGE}: "
                                 f"pip install '{RANGE}'", version=version, supported=RANGE)


def installed_version(pymunk: Any) -> str:
    """The release of the imported ``pymunk``: its distribution's version when that
    distribution is the package imported (pymunk 7.0.0's own ``pymunk.version`` says
    ``2.0.0``), else ``pymunk.version``."""
    import os
    from importlib import metadata

    try:
        dist = metadata.distribution("pymunk")
        where = os.path.realpath(str(dist.locate_file("pymunk")))
        if where == os.path.realpath(os.path.dirname(pymunk.__file__)):
            return str(dist.version)
    except (metadata.PackageNotFoundError, TypeError, AttributeError, OSError):
        pass
    return str(getattr(pymunk, "version", "unknown"))


@functools.cache
def require() -> ModuleType:
    """pymunk, imported and its release checked (once): :class:`PymunkVersionError` when it
    is outside :data:`RANGE`."""
    import pymunk

    check(installed_version(pymunk))
    return pymunk


def spring_function(c: Any) -> Callable[..., float] | None:
    """The custom force function of the DampedSpring ``c`` (torque function of a
    DampedRotarySpring), None when it uses pymunk's own."""
    import pymunk

    rotary = isinstance(c, pymunk.DampedRotarySpring)
    cls = pymunk.DampedRotarySpring if rotary else pymunk.DampedSpring
    func = _reader(cls, "torque_func" if rotary else "force_func")(c)
    return None if func is None or func is _default(cls) else func


def _default(cls: type) -> Callable[..., float]:
    return cls.spring_torque if hasattr(cls, "spring_torque") else cls.spring_force


@functools.cache
def _reader(cls: type, name: str) -> Callable[[Any], Any]:
    """How to read the spring class ``cls``'s function ``name`` (``force_func`` or
    ``torque_func``), found by trying it on a spring made here. pymunk 7.1 and later read it
    back (the default function unless one was set); 7.0.x's property has only a setter, which
    keeps what it was given as ``_force_func``/``_torque_func`` in the spring's ``__dict__``:
    that entry is read there, once a spring made here shows it absent until the setter runs
    and then holding exactly the function given. Any other behaviour is a PymunkVersionError.
    """
    import pymunk

    probe = _probe(cls, pymunk)
    try:
        if getattr(probe, name) is _default(cls):
            return lambda c: getattr(c, name)
    except AttributeError:
        pass

    def mark(*_: Any) -> float:  # never called: the probe is never stepped
        return 0.0

    key = f"_{name}"
    before = vars(probe).get(key)
    setattr(probe, name, mark)
    if before is None and vars(probe).get(key) is mark:
        return lambda c: vars(c).get(key)
    version = installed_version(pymunk)
    raise PymunkVersionError(f"pymunk {version}: dumbbell cannot tell which {name} a "
                             f"{cls.__name__} uses on this release; it runs on {RANGE}",
                             version=version, supported=RANGE)


def _probe(cls: type, pymunk: Any) -> Any:
    """A spring of class ``cls`` between two free bodies, in no space."""
    a, b = pymunk.Body(1.0, 1.0), pymunk.Body(1.0, 1.0)
    if hasattr(cls, "spring_torque"):
        return cls(a, b, 0.0, 1.0, 0.0)
    return cls(a, b, (0.0, 0.0), (0.0, 0.0), 1.0, 1.0, 0.0)
