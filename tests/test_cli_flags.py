"""Every flag of every command, given a bad value, fails the same way: exit status 2, one line
on stderr naming the flag, and nothing written. The flags are read from the parser itself,
so a new flag with a type or choices is covered without editing this file."""

from __future__ import annotations

import argparse
import shutil

import pytest

from dumbbell.cli import main
from dumbbell.cli.app import arguments, build_parser, subcommands
from tests.conftest import SCENES

TEXTBOOK = str(SCENES / "textbook-1d.toml")
STIFF = SCENES / "extreme" / "stiff-wdt-2.1.toml"

#: Bad values for flags whose type argparse cannot check (the command must).
SEMANTIC = {"--solver": "nope", "--solvers": "nope", "--size": "12x", "--scheduler": "nowhere",
            "--cases": "/nonexistent/cases", "--grid": "k=log:1:2", "--dts": "0"}
#: Flags for which 0 is a good value (a tilt of 0 degrees, a perfectly inelastic floor).
ZERO_OK = ("--theta", "--elasticity")
#: Flags that name an output file or folder.
OUTPUTS = ("--out", "-o", "--output", "--events")
#: Small runs, so that a command that would run before it fails stays quick.
CHEAP = {"simulate": ["--t-end", "0.01"], "render": ["--t-end", "0.05"],
         "bench": ["--t-end", "0.01", "--window", "0.01", "--dts", "1e-3", "--repeat", "1"],
         "compare": ["--t-end", "0.01", "--window", "0.01", "--dt", "1e-3"],
         "sweep": ["--grid", "k=1e2,1e3", "--t-end", "0.01", "--workers", "1"],
         "stability": ["--solvers", "exact", "--workers", "1"], "run": []}


def _commands() -> dict[str, argparse.ArgumentParser]:
    return subcommands(build_parser())


def _options(name: str) -> list[argparse.Action]:
    return [a for a in arguments(_commands()[name]) if a.option_strings]


def _base(name: str, skip: str | None = None) -> list[str]:
    """A valid command line for ``name`` without the flag ``skip``."""
    parser = _commands()[name]
    argv = [name]
    if any(a.dest == "scene" and not a.option_strings for a in arguments(parser)):
        argv.append(TEXTBOOK)
    cheap = CHEAP.get(name, [])
    i = 0
    while i < len(cheap):
        flag = cheap[i]
        j = i + 1
        while j < len(cheap) and not cheap[j].startswith("--"):
            j += 1
        if flag != skip:
            argv += cheap[i:j]
        i = j
    return argv


def _cases():
    for name in _commands():
        for action in _options(name):
            flag = action.option_strings[-1]
            if action.nargs == 0:
                continue
            bad = []
            if action.type is not None:
                bad += ["abc", "-1", "nan"] + ([] if flag in ZERO_OK else ["0"])
            if action.choices:
                bad.append("nope")
            for f in action.option_strings:
                if f in SEMANTIC:
                    bad.append(SEMANTIC[f])
            for value in dict.fromkeys(bad):
                yield pytest.param(name, flag, value, id=f"{name} {flag} {value}")


def _run(argv: list[str]) -> int:
    try:
        return main(argv)
    except SystemExit as exc:
        return int(exc.code)


def _check(tmp_path, capsys, argv: list[str], word: str) -> None:
    before = {p for p in tmp_path.rglob("*")}
    code = _run(argv)
    err = capsys.readouterr().err
    assert code == 2, (argv, err)
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert word in err, err
    assert {p for p in tmp_path.rglob("*")} == before, "something was written"


@pytest.mark.parametrize("name,flag,value", list(_cases()))
def test_bad_flag_value(tmp_path, capsys, monkeypatch, name, flag, value):
    monkeypatch.chdir(tmp_path)
    argv = _base(name, skip=flag) + [flag, value]
    if any(a.option_strings and "--out" in a.option_strings for a in _options(name)):
        argv += ["--out", str(tmp_path / "out")]
    # argparse names the long flag; our own checks may name the key behind it instead.
    word = value if flag in ("--solver", "--solvers") else flag.lstrip("-").split("-")[0]
    _check(tmp_path, capsys, argv, word if flag != "--grid" else "--grid")


@pytest.mark.parametrize("name", list(_commands()))
def test_unknown_flag_and_missing_scene(tmp_path, capsys, monkeypatch, name):
    monkeypatch.chdir(tmp_path)
    _check(tmp_path, capsys, _base(name) + ["--no-such-flag"], "--no-such-flag")
    scene_arg = any(a.dest == "scene" and not a.option_strings
                    for a in arguments(_commands()[name]))
    if scene_arg:
        argv = [a if a != TEXTBOOK else str(tmp_path / "missing.toml") for a in _base(name)]
        _check(tmp_path, capsys, argv, "missing.toml")


@pytest.mark.parametrize("name,flag", [
    (name, a.option_strings[-1]) for name in _commands() for a in _options(name)
    if set(a.option_strings) & set(OUTPUTS)
])
def test_output_under_a_file_is_refused(tmp_path, capsys, monkeypatch, name, flag):
    """An output path that cannot be written (its folder is a file) is one line, exit 2."""
    monkeypatch.chdir(tmp_path)
    blocker = tmp_path / "file.txt"
    blocker.write_text("not a folder")
    argv = _base(name)
    if name == "stability":
        cases = tmp_path / "cases"
        cases.mkdir()
        shutil.copy(STIFF, cases)
        argv += ["--cases", str(cases)]
    target = blocker / ("sub" if flag == "--out" else "x.csv")
    argv += [flag, str(target), "-q"]
    _check(tmp_path, capsys, argv, "file.txt")
