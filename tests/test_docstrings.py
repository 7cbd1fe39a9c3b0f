"""Every public callable's docstring has the numpydoc sections that apply (Parameters,
Returns, Raises, Examples: tests/docstrings.py says which apply when), and every Examples
section runs as a doctest, in a fresh folder, against the installed package."""

from __future__ import annotations

import doctest
import inspect
import io
import sys

import pytest

from tests.docstrings import problems, public_callables, sections

CALLABLES = public_callables()


def _owner(path: str):
    owner = path.rsplit(".", 1)[0]
    obj = CALLABLES.get(owner)
    return obj if inspect.isclass(obj) else None


def test_every_public_callable_has_its_sections():
    found = [line for path, obj in CALLABLES.items()
             for line in problems(path, obj, _owner(path))]
    complete = len({line.split(":")[0] for line in found})
    print(f"{len(CALLABLES) - complete} of {len(CALLABLES)} public callables have every "
          "section that applies")
    assert len(CALLABLES) >= 150
    assert found == [], "\n".join(found)


def _doctests():
    finder = doctest.DocTestFinder(recurse=False)
    out = []
    for path, obj in CALLABLES.items():
        target = getattr(obj, "__func__", obj)
        for test in finder.find(target, path, globs={}):
            if test.examples:
                out.append(test)
    return out


DOCTESTS = _doctests()


@pytest.mark.parametrize("test", DOCTESTS, ids=[t.name for t in DOCTESTS])
def test_examples_run(test, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    out = io.StringIO()
    try:
        runner.run(test, out=out.write)
    finally:
        if "matplotlib.pyplot" in sys.modules:
            sys.modules["matplotlib.pyplot"].close("all")
    assert runner.failures == 0, out.getvalue()


def test_few_examples_are_skipped_and_each_says_why():
    skipped = [(t.name, e.source) for t in DOCTESTS for e in t.examples
               if e.options.get(doctest.SKIP)]
    assert len(skipped) <= 10, skipped
    # A skipped example says why on the line (a comment after the directive).
    assert [s for s in skipped if "# doctest: +SKIP" in s[1]
            and not s[1].split("+SKIP", 1)[1].strip(" -:,")] == []


def test_the_check_finds_what_is_missing():
    from dumbbell import UsageError

    def bare(x, y=1, **options):
        """Add."""
        if x is None:
            raise UsageError("x")
        return x + y

    def good(x: float) -> float:
        """Twice ``x``.

        Parameters
        ----------
        x : float
            A number.

        Returns
        -------
        float
            ``2 x``.

        Raises
        ------
        UsageError
            When ``x`` is None.

        Examples
        --------
        >>> good(2.0)
        4.0
        """
        if x is None:
            raise UsageError("x")
        return 2 * x

    def stray(x: float) -> None:
        """Nothing.

        Parameters
        ----------
        x : float
            A number.
        z : int
            Not a parameter.
        """

    assert problems("m.bare", bare) == [
        "m.bare: Parameters lacks x, y, **options", "m.bare: no Returns",
        "m.bare: Raises lacks UsageError", "m.bare: no Examples"]
    assert problems("m.good", good) == []
    assert problems("m.stray", stray) == ["m.stray: Parameters names z, not parameters",
                                          "m.stray: no Examples"]
    assert sections(good).raises == ["UsageError"]
    assert problems("m.nothing", lambda: None) == ["m.nothing: no docstring"]
