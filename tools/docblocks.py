"""Run every code block of README.md and docs/*.md as a reader would, and report the ones that
fail.

    python tools/docblocks.py              # from the repository's root: every file
    python tools/docblocks.py docs/api.md  # one file; exit 1 when a block fails
    python tools/docblocks.py -v           # also each block's time

The pages are shared between two processes (forked); each Markdown file is one session, in
a fresh temporary folder holding a copy of the
repository's ``scenes/`` (what a reader who cloned the repository has beside them), run
against the installed ``dumbbell``. A ``dumbbell`` command line that two blocks run (on two
pages: README.md's compare and solvers.md's) runs once, in one process, on the same inputs:
the second block gets its status, output and files, and checks them as its own.

- ```` ```python ```` blocks run in order in one namespace per file, as in a notebook; a
  line that is an expression followed by a comment showing a result's repr
  (``traj.events[0]  # Impact(t=0.45..., body='B', ...)``: a name and an opening
  parenthesis) must have that repr, by doctest's rules (``...`` stands for any text): the
  page shows what the reader will see;
- ```` ```sh ```` and ```` ```bash ```` blocks run line by line (``\\`` continues a line,
  ``#`` starts a comment, ``&&`` and ``;`` join commands); ``dumbbell ARGS`` runs in this
  process (``dumbbell.cli.main``, exit status 0 expected), ``python ...`` with this Python,
  anything else in ``bash``;
- ```` ```console ```` blocks are transcripts: ``$ COMMAND`` lines run as above and the lines
  after one are the output it must print (doctest's rules: ``...`` stands for any text,
  white space is normalised; ``$ echo $?`` prints the last exit status);
- ```` ```toml ```` and ```` ```text ```` blocks are data and output listings, not run; a
  fence without a language is an error, so that nothing is left unlabelled.

A block that is not meant to run says so on the line before its fence:
``<!-- illustrative: why -->``. Those are counted and listed, with their reasons.

After a file's blocks, whatever they left in ``renders/`` must be a file the repository
tracks there, with the same bytes (the showcase's timed files excepted), or one that git
ignores: the docs' commands write outside ``renders/`` unless they are the showcase's.
"""

from __future__ import annotations

import ast
import contextlib
import doctest
import io
import itertools
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
import tokenize
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

#: Languages that run, and those that are data or output listings.
RUN = {"python", "sh", "bash", "console"}
DATA = {"toml", "text"}
_FENCE = re.compile(r"^(?P<indent> {0,3})(?P<fence>```+|~~~+)\s*(?P<lang>[\w+-]*)\s*$")
_MARK = re.compile(r"^\s*<!--\s*illustrative\b:?\s*(?P<why>.*?)\s*-->\s*$")
#: Shell syntax this runner leaves to bash (pipes, redirections, background jobs).
_SHELL = {"|", "||", ">", ">>", "<", "&", "2>", "2>&1", "(", ")"}
#: Seconds a command run in a subprocess may take.
TIMEOUT = 300


@dataclass
class Block:
    """One fenced code block: the file (relative to the root), the line of its opening
    fence, its language, its text, and why it is illustrative (None: it runs)."""

    path: str
    line: int
    lang: str
    code: str
    illustrative: str | None = None

    @property
    def runs(self) -> bool:
        return self.lang in RUN and self.illustrative is None

    def __str__(self) -> str:
        return f"{self.path}:{self.line} ({self.lang or 'no language'})"


@dataclass
class Result:
    """What running one block gave: its time (s) and the error, if any."""

    block: Block
    seconds: float = 0.0
    error: str | None = None


def doc_files(root: Path = ROOT) -> list[Path]:
    """README.md and every Markdown file directly under docs/."""
    files = [root / "README.md"] if (root / "README.md").exists() else []
    return files + sorted((root / "docs").glob("*.md"))


def blocks(path: Path, root: Path = ROOT) -> list[Block]:
    """The fenced code blocks of one Markdown file, in order."""
    out: list[Block] = []
    lines = path.read_text(encoding="utf-8").splitlines()
    name = str(path.relative_to(root)) if path.is_relative_to(root) else str(path)
    i = 0
    while i < len(lines):
        m = _FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        fence, start = m.group("fence"), i
        i += 1
        body = []
        while i < len(lines) and not lines[i].strip().startswith(fence):
            body.append(lines[i])
            i += 1
        prev = next((lines[j] for j in range(start - 1, -1, -1) if lines[j].strip()), "")
        mark = _MARK.match(prev)
        out.append(Block(name, start + 1, m.group("lang"), "\n".join(body) + "\n",
                         (mark.group("why") or "illustrative") if mark else None))
        i += 1
    return out


class Failed(Exception):
    """A block did not do what it says; the message says where and why."""


@dataclass
class Session:
    """One Markdown file's blocks, run in ``folder`` (which holds a copy of scenes/)."""

    folder: Path
    namespace: dict = field(default_factory=lambda: {"__name__": "__docs__"})
    status: int = 0
    #: ``dumbbell`` command lines that more than one block of the docs runs (:func:`repeated`).
    repeats: frozenset = frozenset()

    # -- Python ---------------------------------------------------------------------------

    def python(self, block: Block) -> None:
        name = f"{block.path}:{block.line}"
        tree = ast.parse(block.code, name)
        shown = _shown_reprs(block.code)
        printed = io.StringIO()
        with _in(self.folder), contextlib.redirect_stdout(printed), \
                contextlib.redirect_stderr(printed):
            try:
                # One statement at a time, as the module would run, so that an expression
                # whose repr the page shows is checked where it stands.
                for node in tree.body:
                    want = shown.get(node.end_lineno) if isinstance(node, ast.Expr) else None
                    if want is None:
                        exec(compile(ast.Module([node], []), name, "exec"), self.namespace)  # noqa: S102
                        continue
                    value = eval(compile(ast.Expression(node.value), name, "eval"),
                                 self.namespace)
                    _check_repr(value, want, f"{name}, line {node.end_lineno}")
            except Failed:
                raise
            except Exception as exc:
                raise Failed(f"{type(exc).__name__}: {exc}\n(it printed: "
                             f"{printed.getvalue()[-2000:]})") from exc
            finally:
                _close_figures()

    # -- shell ----------------------------------------------------------------------------

    def command(self, line: str) -> tuple[int, str]:
        """Run one shell line; returns its exit status and what it printed."""
        if line.strip() == "echo $?":
            return 0, f"{self.status}\n"
        try:
            tokens = list(_lexer(line))
        except ValueError as exc:
            raise Failed(f"cannot read the shell line {line!r}: {exc}") from None
        if not tokens:
            return self.status, ""
        if any(t in _SHELL for t in tokens) or "$" in line:
            return self._bash(line)
        printed, status = "", 0
        for argv in _split(tokens, {"&&", ";"}):
            status, text = self._one(argv)
            printed += text
            if status != 0 and "&&" in tokens:
                break
        return status, printed

    def _one(self, argv: list[str]) -> tuple[int, str]:
        if argv[0] == "dumbbell":
            return self._dumbbell(argv)
        if argv[0] in ("python", "python3", "python3.11"):
            argv = [sys.executable, *argv[1:]]
        return self._process(argv)

    def _dumbbell(self, argv: list[str]) -> tuple[int, str]:
        """``dumbbell ARGV`` in this process: its status and what it printed. A command line
        another page already ran on the same inputs (:func:`_inputs`) is not run again: the
        package's outputs are reproducible, so this session gets that run's status, printed
        text and files (written into its own folder), and the page checks them as its own."""
        key = _inputs(self.folder, argv) if " ".join(argv) in self.repeats else None
        if key in _RAN:
            status, printed, files = _RAN[key]
            for name, data in files.items():
                (self.folder / name).parent.mkdir(parents=True, exist_ok=True)
                (self.folder / name).write_bytes(data)
            return status, printed
        from dumbbell.cli import main

        before = _stamps(self.folder) if key is not None else None
        out, err = io.StringIO(), io.StringIO()
        with _in(self.folder), contextlib.redirect_stdout(out), \
                contextlib.redirect_stderr(err):
            try:
                status = main(argv[1:])
            except SystemExit as exc:  # --help, --version and argparse's errors
                status = exc.code if isinstance(exc.code, int) else 1
            finally:
                _close_figures()
        printed = out.getvalue() + err.getvalue()
        if key is not None:  # a shared run: the files it wrote or changed, for the other page
            _RAN[key] = (status, printed, {name: (self.folder / name).read_bytes()
                                           for name, stamp in _stamps(self.folder).items()
                                           if before.get(name) != stamp})
        return status, printed

    def _bash(self, line: str) -> tuple[int, str]:
        return self._process(["bash", "-c", line])

    def _process(self, argv: list[str]) -> tuple[int, str]:
        env = dict(os.environ, MPLBACKEND="Agg",
                   PATH=os.pathsep.join([str(Path(sys.executable).parent),
                                         os.environ.get("PATH", "")]))
        done = subprocess.run(argv, cwd=self.folder, capture_output=True, text=True, env=env,
                              timeout=TIMEOUT, check=False)
        return done.returncode, done.stdout + done.stderr

    def shell(self, block: Block) -> None:
        for line in _lines(block.code):
            self.status, printed = self.command(line)
            if self.status != 0:
                raise Failed(f"`{line}` exited {self.status}:\n{printed[-2000:]}")

    def console(self, block: Block) -> None:
        checker = doctest.OutputChecker()
        flags = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE
        for line, want in _transcript(block.code):
            self.status, got = self.command(line)
            if not checker.check_output(want, got, flags):
                raise Failed(f"`{line}` printed (exit {self.status}):\n{got}\nnot:\n{want}")

    def run(self, block: Block) -> None:
        {"python": self.python, "sh": self.shell, "bash": self.shell,
         "console": self.console}[block.lang](block)


#: ``dumbbell`` commands run in this process, by their inputs (:func:`_inputs`): (exit
#: status, what they printed, the files they wrote or changed, relative name -> bytes).
_RAN: dict[tuple, tuple[int, str, dict[str, bytes]]] = {}


def _stamps(folder: Path) -> dict[str, tuple[int, int]]:
    """Every file under ``folder`` (relative name) with its size and modification time."""
    out = {}
    for path in folder.rglob("*"):
        if path.is_file():
            st = path.stat()
            out[str(path.relative_to(folder))] = (st.st_size, st.st_mtime_ns)
    return out


def _digest(path: Path) -> str:
    import hashlib

    h = hashlib.sha256()
    for item in sorted(path.rglob("*")) if path.is_dir() else [path]:
        if item.is_file():
            h.update(str(item.relative_to(path) if path.is_dir() else item.name).encode())
            h.update(item.read_bytes())
    return h.hexdigest()


def _inputs(folder: Path, argv: list[str]) -> tuple:
    """What a ``dumbbell ARGV`` run in ``folder`` reads: the command line, the session's
    scenes/ (each page starts from the same copy; a block may change it), every argument
    that names a file or folder there, and standard input's absence (a page cannot give
    one)."""
    named = []
    for arg in argv[1:]:
        path = folder / arg
        try:
            exists = path.exists()
        except OSError:  # a name too long for the file system
            exists = False
        if exists:
            named.append((arg, _digest(path)))
    return (tuple(argv), _digest(folder / "scenes"), tuple(named))


#: A comment that shows a repr: a name and an opening parenthesis (``# Impact(t=...``).
_REPR_COMMENT = re.compile(r"#\s*(?P<repr>[A-Z]\w*\(.*)$")


def _shown_reprs(code: str) -> dict[int, str]:
    """The reprs the comments of a Python block show, by line (1-based): the comment's text
    from the name to the parenthesis that closes the one after it."""
    out = {}
    for tok in _tokens(code):
        m = _REPR_COMMENT.match(tok.string) if tok.type == tokenize.COMMENT else None
        if m is None:
            continue
        text, depth = m.group("repr"), 0
        for i, ch in enumerate(text):
            depth += {"(": 1, ")": -1}.get(ch, 0)
            if depth == 0 and ch == ")":
                out[tok.start[0]] = text[: i + 1]
                break
    return out


def _tokens(code: str) -> list[tokenize.TokenInfo]:
    return list(tokenize.generate_tokens(io.StringIO(code).readline))


def _check_repr(value: object, want: str, where: str) -> None:
    """Failed unless ``repr(value)`` is what the page shows (``want``): ``...`` after a
    digit stands for a number's further digits (``-4.427...``), anywhere else for any text
    (``Verdict(status='ok', ...)``), so a cut number cannot hide a field the page left out."""
    got = repr(value)
    pieces = want.split("...")
    pattern = re.escape(pieces[0])
    for before, piece in itertools.pairwise(pieces):
        pattern += (r"[0-9]*(?:e[-+]?[0-9]+)?" if before[-1:].isdigit() else ".*")
        pattern += re.escape(piece)
    if not re.fullmatch(pattern, got, re.DOTALL):
        raise Failed(f"{where}: the page shows {want!r}, the code gives {got!r}")


@contextlib.contextmanager
def _in(folder: Path):
    before = Path.cwd()
    os.chdir(folder)
    try:
        yield
    finally:
        os.chdir(before)


def _close_figures() -> None:
    if "matplotlib.pyplot" in sys.modules:
        sys.modules["matplotlib.pyplot"].close("all")


def _lexer(line: str):
    lexer = shlex.shlex(line, posix=True, punctuation_chars=True)
    lexer.whitespace_split = True
    lexer.commenters = "#"
    return lexer


def _split(tokens: list[str], separators: set[str]) -> list[list[str]]:
    out: list[list[str]] = [[]]
    for token in tokens:
        if token in separators:
            out.append([])
        else:
            out[-1].append(token)
    return [argv for argv in out if argv]


def _lines(code: str) -> list[str]:
    """Shell lines, a trailing backslash joining a line to the next."""
    out, held = [], ""
    for raw in code.splitlines():
        if raw.rstrip().endswith("\\"):
            held += raw.rstrip()[:-1] + " "
            continue
        out.append(held + raw)
        held = ""
    if held:
        out.append(held)
    return [line for line in out if line.strip()]


def _transcript(code: str) -> list[tuple[str, str]]:
    """(command, expected output) pairs of a console block."""
    pairs: list[tuple[str, str]] = []
    for raw in code.splitlines():
        if raw.startswith("$ "):
            pairs.append((raw[2:], ""))
        elif pairs:
            pairs[-1] = (pairs[-1][0], pairs[-1][1] + raw + "\n")
    return pairs


def check_renders(folder: Path, root: Path = ROOT) -> list[str]:
    """What the blocks left in ``folder/renders`` that they should not have: a file the
    repository neither tracks nor ignores there, or a tracked one with other bytes."""
    out = folder / "renders"
    if not out.is_dir():
        return []
    from dumbbell.cli.showcase import measured, tracked

    problems = []
    for path in sorted(out.iterdir()):
        name = path.name
        if name in tracked():
            if name not in measured() and path.read_bytes() != (root / "renders" /
                                                                name).read_bytes():
                problems.append(f"renders/{name}: written with other bytes than the tracked "
                                "file (only the showcase's own command may write it)")
        elif not _ignored(name, root):
            problems.append(f"renders/{name}: not a showcase file, and git would see it")
    return problems


def _ignored(name: str, root: Path) -> bool:
    """Whether .gitignore keeps renders/NAME out of git (its renders/ rules only)."""
    ignored = False
    for line in (root / ".gitignore").read_text(encoding="utf-8").splitlines():
        line = line.strip()
        negate = line.startswith("!")
        pattern = line[1:] if negate else line
        if not pattern.startswith("renders/"):
            continue
        regex = re.escape(pattern[len("renders/"):]).replace(r"\*", "[^/]*")
        if re.fullmatch(regex, name):
            ignored = not negate
    return ignored


def commands(root: Path = ROOT, paths: list[Path] | None = None) -> set[str]:
    """Every command line the runnable shell and console blocks of ``paths`` (default: every
    doc file) run, comments dropped and white space normalised (what the showcase's test
    leaves to the docs' run)."""
    return set(_command_lines(root, paths))


def repeated(root: Path = ROOT) -> frozenset[str]:
    """The ``dumbbell`` command lines that more than one runnable block of the docs runs:
    the one run of each is shared (:meth:`Session._dumbbell`)."""
    from collections import Counter

    counts = Counter(_command_lines(root, None))
    return frozenset(c for c, n in counts.items() if n > 1 and c.startswith("dumbbell "))


def _command_lines(root: Path, paths: list[Path] | None) -> list[str]:
    """:func:`commands`, each as often as a block runs it."""
    out = []
    for path in doc_files(root) if paths is None else paths:
        for block in blocks(path, root):
            if not block.runs or block.lang == "python":
                continue
            lines = (_lines(block.code) if block.lang != "console"
                     else [c for c, _ in _transcript(block.code)])
            for line in lines:
                try:
                    tokens = list(_lexer(line))
                except ValueError:
                    continue
                out.extend(" ".join(argv) for argv in _split(tokens, {"&&", ";"}))
    return out


def run_file(path: Path, root: Path = ROOT) -> tuple[list[Result], list[str], set[str]]:
    """Run one file's blocks in a fresh folder; the results, what they left in renders/ that
    they should not have, and the names of every file they left there."""
    results = []
    with tempfile.TemporaryDirectory(prefix="docblocks-") as tmp:
        folder = Path(tmp)
        shutil.copytree(root / "scenes", folder / "scenes")
        session = Session(folder, repeats=repeated(root))
        for block in blocks(path, root):
            result = Result(block)
            if block.lang not in RUN | DATA:
                result.error = (f"a fence without a known language ({block.lang!r}): label it "
                                f"with one of {', '.join(sorted(RUN | DATA))}")
            elif block.runs:
                t0 = time.perf_counter()
                try:
                    session.run(block)
                except Failed as exc:
                    result.error = str(exc)
                except Exception as exc:  # noqa: BLE001 - report it as the block's failure
                    result.error = f"{type(exc).__name__}: {exc}"
                result.seconds = time.perf_counter() - t0
            results.append(result)
        left = check_renders(folder, root)
        renders = folder / "renders"
        written = {p.name for p in renders.iterdir()} if renders.is_dir() else set()
    return results, left, written


#: Rough seconds each page's blocks take (``python tools/docblocks.py -v``, a quiet 2-core
#: machine; solvers.md without the compare that README.md runs), to share the pages between
#: processes.
COST = {"rotation.md": 19, "physics.md": 12, "README.md": 11, "solvers.md": 10, "cli.md": 10,
        "measurements.md": 7, "api.md": 5, "spaces-reference.md": 4, "stability.md": 3,
        "rendering.md": 2, "scenes.md": 2, "player.md": 1}


def run_files(paths: list[Path], root: Path = ROOT, processes: int = 2
              ) -> dict[Path, tuple[list[Result], list[str], set[str]]]:
    """:func:`run_file` for every path, the pages shared between this process and
    ``processes - 1`` forked ones (each page a session of its own either way); where fork
    is not available, one after another here."""
    import multiprocessing

    if processes < 2 or "fork" not in multiprocessing.get_all_start_methods():
        return {path: run_file(path, root) for path in paths}
    groups: list[list[Path]] = [[] for _ in range(processes)]
    loads = [0.0] * processes
    for unit in sorted(_sharing(paths, root), key=lambda u: -sum(COST.get(q.name, 0.5)
                                                                 for q in u)):
        i = loads.index(min(loads))
        groups[i] += unit
        loads[i] += sum(COST.get(q.name, 0.5) for q in unit)
    context = multiprocessing.get_context("fork")
    children = []
    for group in groups[1:]:
        receive, send = context.Pipe(duplex=False)
        child = context.Process(target=_run_group, args=(send, group, root))
        child.start()
        send.close()
        children.append((child, receive, group))
    out = {path: run_file(path, root) for path in groups[0]}
    for child, receive, group in children:
        try:
            out.update(receive.recv())
        except EOFError:  # the child died: run its pages here
            out.update({path: run_file(path, root) for path in group})
        child.join()
    return {path: out[path] for path in paths}


def _sharing(paths: list[Path], root: Path) -> list[list[Path]]:
    """``paths`` in groups that run in one process: pages that run a :func:`repeated`
    command together (its one run is shared within a process), each page alone otherwise."""
    repeats = repeated(root)
    units: list[tuple[set[str], list[Path]]] = []
    for path in paths:
        mine = commands(root, [path]) & repeats
        joined = [u for u in units if u[0] & mine]
        for u in joined:
            units.remove(u)
        units.append((mine.union(*(u[0] for u in joined)),
                      [q for u in joined for q in u[1]] + [path]))
    return [unit for _, unit in units]


def _run_group(send, paths: list[Path], root: Path) -> None:
    send.send({path: run_file(path, root) for path in paths})
    send.close()


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    verbose = "-v" in argv
    paths = [Path(a).resolve() for a in argv if a != "-v"] or doc_files()
    ran = skipped = failed = 0
    for path, (results, left, _) in run_files(paths).items():
        for r in results:
            if r.block.illustrative is not None and r.block.lang in RUN:
                skipped += 1
                print(f"illustrative {r.block}: {r.block.illustrative}")
            elif r.block.runs:
                ran += 1
                if verbose:
                    print(f"{r.seconds:6.1f} s  {r.block}")
            if r.error:
                failed += 1
                print(f"FAILED {r.block} after {r.seconds:.1f} s: {r.error}")
        for problem in left:
            failed += 1
            print(f"FAILED {path.name}: {problem}")
    print(f"{ran} blocks run, {skipped} illustrative, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
