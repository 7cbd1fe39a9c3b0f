"""MkDocs hooks that make the documentation site from the repository as it is (mkdocs.yml).

    mkdocs build --strict        # from the repository's root: the site into site/
    mkdocs serve                 # the same, served at http://127.0.0.1:8000 while you edit

The pages stay plain Markdown that reads on a code host; this file adds what a site needs:

- the README as the page ``readme.html`` (its links into ``docs/`` rewritten to the pages);
- every file outside ``docs/`` that a page links to (``renders/*.png``, ``scenes/*.toml``,
  ``tools/*.py``, ``examples/*.ipynb``, ...) copied to the same path in the site, and the
  pages' links to it rewritten (``../renders/x.png`` from ``docs/physics.md`` is
  ``renders/x.png`` from ``physics.html``), so that every link that works on the code host
  works in the site;
- headings' anchors slugged as code hosts slug them (``tools/doclinks.py``), so that
  ``page.md#some-heading`` keeps pointing at the heading;
- the API reference, ``reference/*.md``: one page per public package, rendering with
  mkdocstrings every name of the ``__all__`` of the package and of its public submodules
  (found as ``tests/test_api_border.py`` finds them, not listed here), each once.
"""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import pkgutil
import posixpath
import re
import sys
import types
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

#: The packages whose ``__all__`` (and their public submodules' ``__all__``) is the public API,
#: one reference page each, in this order after the top-level ``dumbbell``.
PACKAGES = ("dumbbell.model", "dumbbell.solvers", "dumbbell.analysis", "dumbbell.spaces",
            "dumbbell.io", "dumbbell.plot", "dumbbell.animation", "dumbbell.examples")
#: Modules not walked: the compiled loops (numba), called by the solver classes only.
INTERNAL = ("dumbbell.solvers.kernels",)
#: Where the README sits in the site (``README.md`` would collide with ``index.md``).
README = "readme.md"


def _doclinks():
    if "doclinks" not in sys.modules:
        spec = importlib.util.spec_from_file_location("doclinks", ROOT / "tools" / "doclinks.py")
        module = importlib.util.module_from_spec(spec)
        sys.modules["doclinks"] = module
        spec.loader.exec_module(module)
    return sys.modules["doclinks"]


# --- the API reference -------------------------------------------------------------------


def public_modules(package: str) -> list[types.ModuleType]:
    """``package`` and its public submodules (no part of the name starting with ``_``)."""
    module = importlib.import_module(package)
    out = [module]
    if hasattr(module, "__path__"):
        for info in pkgutil.walk_packages(module.__path__, prefix=f"{package}."):
            if info.name.startswith(INTERNAL):
                continue
            if not any(part.startswith("_") for part in info.name.split(".")):
                out.append(importlib.import_module(info.name))
    return out


def canonical(module: types.ModuleType, name: str) -> str | None:
    """The path under which ``module.name`` is defined (None for a submodule)."""
    obj = getattr(module, name)
    if isinstance(obj, types.ModuleType):
        return None
    if inspect.isclass(obj) or inspect.isfunction(obj):
        if "<locals>" in obj.__qualname__:  # made on first use (LazyClasses)
            return f"{obj.__module__}.{name}"
        return f"{obj.__module__}.{obj.__qualname__}"
    return f"{module.__name__}.{name}"


def public_names() -> dict[str, list[str]]:
    """Page -> the public paths it renders, each object once: the top-level ``dumbbell``'s
    names on its page, then each package's own and its submodules' names not rendered yet."""
    pages: dict[str, list[str]] = {}
    done: set[str] = set()
    for page in ("dumbbell", *PACKAGES):
        modules = ([importlib.import_module("dumbbell")] if page == "dumbbell"
                   else public_modules(page))
        paths = []
        for module in modules:
            for name in getattr(module, "__all__", ()):
                path = canonical(module, name)
                if path is not None and path not in done:
                    done.add(path)
                    paths.append(path)
        pages[page] = paths
    return pages


def reference_page(package: str, paths: list[str], others: dict[str, str]) -> str:
    """The Markdown of ``reference/PACKAGE.md``: the package's docstring, then each path,
    grouped by the module that defines it; ``others`` maps a public name of the package
    rendered on another page to that page."""
    lines = [f"# `{package}`", "", f"::: {package}", "    options:", "      members: false",
             "      show_root_heading: false", ""]
    if package == "dumbbell.examples":
        for module in public_modules(package)[1:]:
            lines += [f"## `{module.__name__}`", "", f"::: {module.__name__}", "    options:",
                      "      members: false", "      show_root_heading: false", ""]
    if others:
        lines += ["Also public here, documented with the top-level names: " + ", ".join(
            f"[`{name}`]({page}#{path})" for name, (page, path) in sorted(others.items())) + ".",
            ""]
    section = None
    order = {module: i for i, module in enumerate(dict.fromkeys(map(_module_of, paths)))}
    for path in sorted(paths, key=lambda p: (_module_of(p) != package, order[_module_of(p)])):
        module = _module_of(path)
        if module != section and module != package:
            lines += [f"## `{module}`", ""]
            section = module
        lines += [f"::: {path}", ""]
    return "\n".join(lines)


def _module_of(path: str) -> str:
    """The module part of a path (``dumbbell.spaces.guard.Driver.step`` ->
    ``dumbbell.spaces.guard``)."""
    parts = path.split(".")
    for i in range(len(parts), 0, -1):
        if ".".join(parts[:i]) in sys.modules:
            return ".".join(parts[:i])
    return path.rsplit(".", 1)[0]


def reference_pages() -> dict[str, str]:
    """``reference/NAME.md`` -> its Markdown, and the index page."""
    pages = public_names()
    where = {path: page for page, paths in pages.items() for path in paths}
    out = {}
    for page, paths in pages.items():
        others = {}
        if page != "dumbbell":
            for module in public_modules(page):
                for name in getattr(module, "__all__", ()):
                    path = canonical(module, name)
                    if path and where.get(path) == "dumbbell":
                        others[f"{module.__name__}.{name}"] = ("dumbbell.md", path)
        out[f"reference/{page}.md"] = reference_page(page, paths, others)
    rows = "\n".join(f"| [`{page}`]({page}.md) | {len(paths)} |" for page, paths in pages.items())
    out["reference/index.md"] = (
        "# API reference\n\n"
        "Generated from the docstrings of every name in the `__all__` of `dumbbell` and of its "
        "public packages and their public submodules (a name starting with `_` is private). "
        "A name exported in several places (`dumbbell.simulate` is "
        "`dumbbell.solvers.simulate`) is shown once, on the first page that exports it. The "
        "guide to the API, with examples that run: [The Python API](../api.md) and "
        "[spaces](../spaces.md).\n\n"
        "| page | names |\n|---|---|\n" + rows + "\n")
    return out


def lazy_classes() -> list[tuple[str, str, type]]:
    """(module, name, class) of each public class made on first use, inside a function (as
    ``dumbbell.spaces.PaletteDrawOptions`` subclasses pymunk's class only when asked for)."""
    out = []
    for page in ("dumbbell", *PACKAGES):
        for module in public_modules(page):
            for name in getattr(module, "__all__", ()):
                obj = getattr(module, name)
                if inspect.isclass(obj) and "<locals>" in obj.__qualname__:
                    out.append((obj.__module__, name, obj))
    return out


def dynamic_methods() -> list[tuple[str, str, object]]:
    """(class path, name, method) of each public method that a public class gets when the
    module runs rather than in its source (``Solver.check_work``, made from
    ``Solver._check_work`` by a loop after the class)."""
    import ast

    out = []
    for paths in public_names().values():
        for path in paths:
            module = importlib.import_module(_module_of(path))
            cls = getattr(module, path[len(module.__name__) + 1:].split(".")[0], None)
            if not inspect.isclass(cls) or "<locals>" in cls.__qualname__:
                continue
            try:
                source = inspect.getsource(cls)
            except (OSError, TypeError):
                continue
            tree = ast.parse(inspect.cleandoc("\n" + source) if source[:1].isspace() else source)
            written = {node.name for node in ast.walk(tree)
                       if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)}
            for name, value in vars(cls).items():
                fn = getattr(value, "__func__", value)
                if (not name.startswith("_") and inspect.isfunction(fn)
                        and name not in written):
                    out.append((path, name, fn))
    return out


def run_time_signatures() -> list[tuple[str, object]]:
    """(path, object) of each public function or class whose parameters the source does not
    show: a function given its options' keywords as ``__signature__`` when its module runs
    (``dumbbell.compare(scene, **options)``), a class made by ``__new__`` or a NamedTuple
    (no ``__init__`` in its source)."""
    out = []
    for paths in public_names().values():
        for path in paths:
            module = importlib.import_module(_module_of(path))
            obj = module
            for part in path[len(module.__name__) + 1:].split("."):
                obj = getattr(obj, part, None)
            set_at_run_time = inspect.isfunction(obj) and "__signature__" in vars(obj)
            no_init = (inspect.isclass(obj) and "<locals>" not in obj.__qualname__
                       and not any("__init__" in vars(k) for k in obj.__mro__[:-1]
                                   if k.__module__.startswith("dumbbell"))
                       and ("__new__" in vars(obj) or hasattr(obj, "_fields")))
            if set_at_run_time or no_init:
                out.append((path, obj))
    return out


def private_bases() -> dict[str, set[str]]:
    """Public class path -> the names of its bases defined in a private module (a reader
    of the reference cannot look them up: ``Ledger``'s ``_changes.Changes``)."""
    out = {}
    for paths in public_names().values():
        for path in paths:
            module = importlib.import_module(_module_of(path))
            obj = getattr(module, path[len(module.__name__) + 1:].split(".")[0], None)
            if not inspect.isclass(obj) or path != f"{module.__name__}.{obj.__name__}":
                continue
            names = {b.__name__ for b in obj.__bases__
                     if any(part.startswith("_") for part in b.__module__.split("."))
                     and b.__module__ != "builtins"}
            if names:
                out[path] = names
    return out


def _griffe_parameters(griffe, signature: inspect.Signature):
    """Griffe's parameters for ``signature`` (annotations and defaults as source text)."""
    kinds = {inspect.Parameter.POSITIONAL_ONLY: griffe.ParameterKind.positional_only,
             inspect.Parameter.POSITIONAL_OR_KEYWORD: griffe.ParameterKind.positional_or_keyword,
             inspect.Parameter.VAR_POSITIONAL: griffe.ParameterKind.var_positional,
             inspect.Parameter.KEYWORD_ONLY: griffe.ParameterKind.keyword_only,
             inspect.Parameter.VAR_KEYWORD: griffe.ParameterKind.var_keyword}

    def text(annotation):
        if annotation is inspect.Parameter.empty:
            return None
        if isinstance(annotation, str):
            return annotation
        return getattr(annotation, "__forward_arg__", None) or inspect.formatannotation(annotation)

    return griffe.Parameters(*[
        griffe.Parameter(p.name, annotation=text(p.annotation), kind=kinds[p.kind],
                         default=None if p.default is p.empty else repr(p.default))
        for p in signature.parameters.values()])


def _inspected(griffe, name: str, obj, parts):
    """Griffe's object for ``obj`` inspected at run time under ``name``: the inspector takes
    an object defined elsewhere for an alias, so ``parts`` (the object and its functions)
    say, for the time of the inspection, that they are a shim module's."""
    shim = types.ModuleType(f"_docsite_{name}")
    setattr(shim, name, obj)
    sys.modules[shim.__name__] = shim
    before = [(p.__module__, p.__qualname__) for p in parts]
    for p in parts:
        p.__module__ = shim.__name__
        p.__qualname__ = (p.__qualname__.split("<locals>.", 1)[1]
                          if "<locals>." in p.__qualname__ else name)
    try:
        return griffe.inspect(shim.__name__, docstring_parser="numpy")[name]
    finally:
        for p, (module, qualname) in zip(parts, before, strict=True):
            p.__module__, p.__qualname__ = module, qualname
        del sys.modules[shim.__name__]


def _griffe_extension():
    import griffe

    class LazyClasses(griffe.Extension):
        """Griffe reads the source, and cannot see a class made inside a function or a
        method set on a class after it: inspect each at run time and put it where it is
        found when the package runs."""

        def on_package(self, *, pkg, **kwargs):
            if pkg.name != "dumbbell":
                return
            for module_name, name, cls in lazy_classes():
                parts = [cls] + [getattr(v, "__func__", getattr(v, "fget", v))
                                 for v in vars(cls).values()]
                parts = [p for p in parts if p is cls or (
                    hasattr(p, "__qualname__") and "<locals>" in p.__qualname__)]
                inspected = _inspected(griffe, name, cls, parts)
                module = pkg[module_name.removeprefix("dumbbell.")]
                inspected.parent = module
                module.set_member(name, inspected)
            for path, name, fn in dynamic_methods():
                chain = [fn]
                while hasattr(chain[-1], "__wrapped__"):
                    chain.append(chain[-1].__wrapped__)
                inspected = _inspected(griffe, name, fn, chain)
                if "cls" in inspected.parameters:  # a class method: the class binds cls
                    del inspected.parameters["cls"]
                    inspected.labels.add("classmethod")
                owner = pkg[path.removeprefix("dumbbell.")]
                inspected.parent = owner
                owner.set_member(name, inspected)
            for path, names in private_bases().items():
                found = pkg[path.removeprefix("dumbbell.")]
                found.bases = [b for b in found.bases if str(b).rsplit(".", 1)[-1] not in names]
            for path, obj in run_time_signatures():
                found = pkg[path.removeprefix("dumbbell.")]
                if inspect.isclass(obj):
                    # The class's call as an __init__ (hidden by the filters; its
                    # parameters are the class's, as merge_init_into_class shows them).
                    params = list(inspect.signature(obj).parameters.values())
                    self_ = inspect.Parameter("self", inspect.Parameter.POSITIONAL_ONLY)
                    init = griffe.Function("__init__", parameters=_griffe_parameters(
                        griffe, inspect.Signature([self_, *params])))
                    init.parent = found
                    found.set_member("__init__", init)
                else:
                    found.parameters = _griffe_parameters(griffe, inspect.signature(obj))

    return LazyClasses


def __getattr__(name: str):
    # The extension class is made when griffe asks for it, so that reading this file needs
    # no griffe (the link checks import it).
    if name == "LazyClasses":
        return _griffe_extension()
    raise AttributeError(name)


# --- links -------------------------------------------------------------------------------


def site_path(repo_path: str) -> str:
    """Where a repository file is in the site's source tree: ``docs/X`` is ``X``, the
    README is :data:`README`, anything else keeps its path."""
    if repo_path == "README.md":
        return README
    if repo_path.startswith("docs/"):
        return repo_path[len("docs/"):]
    return repo_path


def rewrite(markdown: str, repo_page: str, site_page: str) -> tuple[str, set[str]]:
    """The page's Markdown with each relative link rewritten from the repository's layout to
    the site's, and the repository paths it links to outside ``docs/``."""
    doclinks = _doclinks()
    outside: set[str] = set()

    def fix(target: str) -> str:
        if doclinks._SCHEME.match(target) or target.startswith(("//", "#")):
            return target
        file_part, sep, anchor = target.partition("#")
        repo = posixpath.normpath(posixpath.join(posixpath.dirname(repo_page), file_part))
        if repo.startswith("../"):
            return target          # outside the repository: doclinks reports it
        if not repo.startswith("docs/") and repo != "README.md":
            outside.add(repo)
        new = posixpath.relpath(site_path(repo), posixpath.dirname(site_page) or ".")
        return new + sep + anchor

    def fix_link(match: re.Match) -> str:
        text = match.group(0)
        start, end = match.span(1)
        start -= match.start()
        end -= match.start()
        return text[:start] + fix(match.group(1)) + text[end:]

    out, fenced = [], False
    for line in markdown.split("\n"):
        if doclinks._FENCE.match(line):
            fenced = not fenced
        elif not fenced:
            # Inline code is left alone: links are rewritten between code spans only.
            pieces = re.split(r"(`+[^`]*`+)", line)
            line = "".join(piece if i % 2 else doclinks._HTML.sub(
                fix_link, doclinks._LINK.sub(fix_link, piece)) for i, piece in enumerate(pieces))
        out.append(line)
    return "\n".join(out), outside


def linked_outside_docs() -> set[str]:
    """Every repository file outside ``docs/`` that README.md or a docs page links to."""
    found: set[str] = set()
    doclinks = _doclinks()
    for path in doclinks.doc_files(ROOT):
        repo_page = path.relative_to(ROOT).as_posix()
        found |= rewrite(path.read_text(encoding="utf-8"), repo_page, site_path(repo_page))[1]
    return {p for p in found if (ROOT / p).is_file()}


# --- the hooks ---------------------------------------------------------------------------


def on_config(config):
    """Headings' anchors as code hosts make them, so that links to them keep working."""
    slug = _doclinks().slug
    config.mdx_configs.setdefault("toc", {})["slugify"] = lambda value, separator: slug(value)
    return config


def on_files(files, config):
    """Add the README, the files the pages link to outside docs/, and the API reference."""
    from mkdocs.structure.files import File

    files.append(File.generated(config, README, abs_src_path=str(ROOT / "README.md")))
    for path in sorted(linked_outside_docs()):
        files.append(File.generated(config, path, abs_src_path=str(ROOT / path)))
    for name, text in reference_pages().items():
        files.append(File.generated(config, name, content=text))
    return files


def on_page_markdown(markdown, page, config, files):
    """Rewrite the links of README.md and docs/*.md from the repository's layout to the
    site's."""
    src = page.file.src_uri
    if src.startswith("reference/"):
        return markdown
    repo_page = "README.md" if src == README else f"docs/{src}"
    if not (ROOT / repo_page).is_file():
        return markdown
    return rewrite(markdown, repo_page, src)[0]


#: A Sphinx role left in a rendered docstring: ``:func:`~dumbbell.compare``` as
#: mkdocstrings renders it (the role's name before the code span).
_ROLE = re.compile(r":(?:class|func|meth|attr|data|exc|mod|obj):<code>(~?)\.?([\w.]+)</code>")


def _targets() -> tuple[dict[str, str], dict[str, list[str]]]:
    """Each rendered path -> its reference page, and each last name -> the paths ending in it."""
    where = {path: page for page, paths in public_names().items() for path in paths}
    by_name: dict[str, list[str]] = {}
    for path in where:
        by_name.setdefault(path.rsplit(".", 1)[-1], []).append(path)
    return where, by_name


def _resolve(target: str, where: dict[str, str], by_name: dict[str, list[str]]) -> str | None:
    """The rendered path a role's target names: the path itself, what ``dumbbell.NAME`` is,
    a method of a rendered class, or the one rendered name ending as the target does."""
    if target in where:
        return target
    if target.startswith("dumbbell."):
        module_name, _, rest = target.partition(".")
        obj = importlib.import_module(module_name)
        try:
            for part in rest.split("."):
                obj = getattr(obj, part)
        except AttributeError:
            obj = None
        if obj is not None and (inspect.isclass(obj) or inspect.isfunction(obj)):
            path = f"{obj.__module__}.{obj.__qualname__}"
            if path in where:
                return path
    ends = [p for p in by_name.get(target.rsplit(".", 1)[-1], ())
            if p == target or p.endswith("." + target)]
    return ends[0] if len(ends) == 1 else None


def on_page_content(html, page, config, files):
    """On the API reference, a Sphinx role of a docstring (``:func:`energy```) becomes a code
    span, linked to the name's entry when the reference renders it (``~`` shows the last
    name only, as Sphinx does)."""
    if not page.file.src_uri.startswith("reference/"):
        return html
    where, by_name = _targets()

    def fix(match: re.Match) -> str:
        tilde, target = match.groups()
        shown = target.rsplit(".", 1)[-1] if tilde else target
        path = _resolve(target, where, by_name)
        if path is None:
            return f"<code>{shown}</code>"
        return f'<a href="{where[path]}.html#{path}"><code>{shown}</code></a>'

    return _ROLE.sub(fix, html)
