"""Lazy loading of a package's submodules and names, the scientific-Python convention (SPEC 1):
a module-level ``__getattr__`` imports a submodule or the module defining a name on first use,
and ``__dir__`` lists them (and only them), so ``import dumbbell`` stays cheap and ``dumbbell.plot``,
``dumbbell.io.trajectory`` work without an import statement of their own."""

from __future__ import annotations

import importlib

TYPE_CHECKING = False
if TYPE_CHECKING:  # typing and collections.abc are not imported at run time: import cost
    from collections.abc import Callable, Iterable, Mapping
    from typing import Any


def attach(package: str, submodules: Iterable[str] = (),
           names: Mapping[str, str] | None = None
           ) -> tuple[Callable[[str], Any], Callable[[], list[str]], list[str]]:
    """``(__getattr__, __dir__, __all__)`` for ``package``: ``submodules`` are imported when
    first read as attributes; ``names`` maps a public name to the submodule (relative to
    ``package``) that defines it. A name is looked up once, then cached in the package."""
    submodules = tuple(submodules)
    names = dict(names or {})
    public = sorted(set(submodules) | set(names))

    def __getattr__(name: str) -> Any:
        if name in names:
            value = getattr(importlib.import_module(f"{package}.{names[name]}"), name)
        elif name in submodules:
            value = importlib.import_module(f"{package}.{name}")
        else:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        setattr(importlib.import_module(package), name, value)
        return value

    def __dir__() -> list[str]:
        return list(public)

    return __getattr__, __dir__, public
