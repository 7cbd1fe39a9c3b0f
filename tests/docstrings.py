"""The public callables and their numpydoc sections, read with griffe's numpy parser (the
parser the documentation site renders them with): what tests/test_docstrings.py checks and
tests/test_api_border.py reads to check that each error a callable raises is in its
``Raises`` section."""

from __future__ import annotations

import ast
import functools
import importlib
import inspect
import logging
import textwrap
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from tests.conftest import load_tool

docsite = load_tool("docsite")


@dataclass
class Sections:
    """A docstring's sections: its summary, the parameter names, the returned and yielded
    names (or types), the raised exception names, and the Examples' text."""

    summary: str = ""
    parameters: list[str] = field(default_factory=list)
    returns: list[str] = field(default_factory=list)
    raises: list[str] = field(default_factory=list)
    examples: str = ""
    kinds: list[str] = field(default_factory=list)


@functools.cache
def _parse(text: str) -> Sections:
    import griffe

    logging.getLogger("griffe").setLevel(logging.ERROR)  # missing types are no concern here
    out = Sections()
    for section in griffe.Docstring(text, parser="numpy").parse():
        kind = section.kind.value
        out.kinds.append(kind)
        if kind == "text" and not out.summary:
            out.summary = section.value.strip().split("\n\n")[0]
        elif kind in ("parameters", "other parameters"):
            out.parameters += [p.name for p in section.value]
        elif kind in ("returns", "yields"):
            out.returns += [r.name or str(r.annotation) for r in section.value]
        elif kind == "raises":
            out.raises += [str(r.annotation).rsplit(".", 1)[-1] for r in section.value]
        elif kind == "examples":
            out.examples += "\n".join(v for k, v in section.value if k.value == "examples")
    return out


def sections(obj: Any) -> Sections:
    """The numpydoc sections of ``obj``'s own docstring (a class's is its constructor's too)."""
    doc = inspect.getdoc(obj) if inspect.isclass(obj) else getattr(obj, "__doc__", None)
    return _parse(inspect.cleandoc(doc)) if doc else Sections()


def _resolve(path: str) -> Any:
    module = importlib.import_module(docsite._module_of(path))
    obj = module
    for part in path[len(module.__name__) + 1:].split("."):
        obj = getattr(obj, part)
    return obj


def own_methods(cls: type) -> dict[str, Callable[..., Any]]:
    """The public methods a class defines itself (``__getitem__`` counts), not overrides of a
    base class's from outside the package (a protocol others call, as pymunk calls a debug
    draw options' ``draw_circle``); properties are attributes, not callables."""
    out = {}
    for name, value in vars(cls).items():
        if name.startswith("_") and name != "__getitem__":
            continue
        fn = value.__func__ if isinstance(value, staticmethod | classmethod) else value
        if not inspect.isfunction(fn):
            continue
        if any(hasattr(base, name) for base in cls.__mro__[1:]
               if not base.__module__.startswith("dumbbell")):
            continue
        out[name] = getattr(cls, name)
    return out


@functools.cache
def public_callables() -> dict[str, Any]:
    """Path -> each public function, class and public method, as the site's reference shows
    them: every callable of a public module's ``__all__`` (tools/docsite.py) and the methods
    its classes define."""
    out: dict[str, Any] = {}
    for paths in docsite.public_names().values():
        for path in paths:
            obj = _resolve(path)
            if not callable(obj):
                continue
            out[path] = obj
            if inspect.isclass(obj):
                for name, method in own_methods(obj).items():
                    out[f"{path}.{name}"] = method
    return out


def parameters(obj: Any) -> list[str]:
    """The parameters a docstring must document: a function's, a method's without
    ``self``/``cls``, a class's constructor's; ``*args`` and ``**kwargs`` spelt so."""
    try:
        signature = inspect.signature(obj)
        if inspect.isclass(obj):
            # A class whose own __new__ passes *args, **kwargs on to its __init__ (a ledger
            # that is one per space) is made with the __init__'s parameters.
            init = next((c.__init__ for c in obj.__mro__ if "__init__" in vars(c)
                         and c.__module__.startswith("dumbbell")), None)
            kinds = {p.kind for p in signature.parameters.values()}
            if init is not None and inspect.Parameter.VAR_POSITIONAL in kinds:
                signature = inspect.signature(init)
    except (TypeError, ValueError):
        return []
    out = []
    for p in signature.parameters.values():
        if p.name in ("self", "cls"):
            continue
        prefix = {p.VAR_POSITIONAL: "*", p.VAR_KEYWORD: "**"}.get(p.kind, "")
        out.append(prefix + p.name)
    return out


def _function(obj: Any) -> Any:
    fn = inspect.unwrap(getattr(obj, "__func__", obj))
    return fn if inspect.isfunction(fn) else None


def _tree(fn: Any) -> ast.AST | None:
    try:
        return ast.parse(textwrap.dedent(inspect.getsource(fn)))
    except (OSError, TypeError, SyntaxError):
        return None


def returns_value(obj: Any) -> bool:
    """Whether a function or method gives its caller something: its return annotation is not
    None, or (without one) a ``return`` in its own body has a value."""
    fn = _function(obj)
    if fn is None or inspect.isclass(obj):
        return False
    annotation = inspect.signature(obj).return_annotation
    if annotation is not inspect.Signature.empty:
        return annotation not in (None, "None", "NoReturn", "Never")
    tree = _tree(fn)
    if tree is None:
        return False
    body = tree.body[0]
    nested = {id(n) for d in ast.walk(body) if d is not body
              and isinstance(d, ast.FunctionDef | ast.AsyncFunctionDef | ast.Lambda)
              for n in ast.walk(d)}
    return any(isinstance(n, ast.Return | ast.Yield) and n.value is not None
               and not (isinstance(n.value, ast.Constant) and n.value.value is None)
               for n in ast.walk(body) if id(n) not in nested)


def raised_here(obj: Any) -> set[str]:
    """The DumbbellError subclasses a function's own body raises by name
    (``raise UsageError(...)``); for a class, its ``__init__`` and ``__post_init__``'s."""
    from dumbbell import errors

    if inspect.isclass(obj):
        fns = [vars(obj)[n] for n in ("__init__", "__post_init__") if n in vars(obj)]
    else:
        fns = [obj]
    found = set()
    for fn in fns:
        fn = _function(fn)
        tree = _tree(fn) if fn is not None else None
        if tree is None:
            continue
        for node in ast.walk(tree):
            if not isinstance(node, ast.Raise) or node.exc is None:
                continue
            target = node.exc.func if isinstance(node.exc, ast.Call) else node.exc
            name = target.attr if isinstance(target, ast.Attribute) else getattr(
                target, "id", None)
            kind = getattr(errors, name, None) or fn.__globals__.get(name)
            if (inspect.isclass(kind) and issubclass(kind, errors.DumbbellError)
                    and kind is not errors.DumbbellError):
                found.add(kind.__name__)
    return found


def names_error(doc: Sections, kind: type) -> bool:
    """Whether ``doc``'s Raises section names ``kind`` or one of its bases below
    DumbbellError (a ColumnError is a UsageError)."""
    from dumbbell import DumbbellError

    return any(base.__name__ in doc.raises for base in kind.__mro__
               if issubclass(base, DumbbellError) and base is not DumbbellError)


def problems(path: str, obj: Any, owner: Any = None) -> list[str]:
    """What ``obj``'s docstring lacks, one line each: a summary; every parameter in
    Parameters (and nothing else there, unless it takes ``**kwargs``); Returns (or Yields)
    when it gives something; each DumbbellError subclass its body raises in Raises; Examples
    with a ``>>>`` line (a method may be shown in its class's, ``owner``'s, instead)."""
    doc = sections(obj)
    out = []
    if not doc.summary:
        return [f"{path}: no docstring"]
    wanted = parameters(obj)
    missing = [p for p in wanted if p not in doc.parameters]
    if missing:
        out.append(f"{path}: Parameters lacks {', '.join(missing)}")
    if not any(p.startswith("**") for p in wanted):
        extra = [p for p in doc.parameters if p not in wanted]
        if extra:
            out.append(f"{path}: Parameters names {', '.join(extra)}, not parameters")
    if returns_value(obj) and not doc.returns:
        out.append(f"{path}: no Returns")
    from dumbbell import errors

    unnamed = sorted(n for n in raised_here(obj) if not names_error(doc, getattr(errors, n)))
    if unnamed:
        out.append(f"{path}: Raises lacks {', '.join(unnamed)}")
    if ">>>" not in doc.examples:
        name = path.rsplit(".", 1)[1]
        shown = owner is not None and (
            f".{name}(" in sections(owner).examples
            or (name == "__getitem__" and "[" in sections(owner).examples))
        if not shown:
            out.append(f"{path}: no Examples")
    return out
