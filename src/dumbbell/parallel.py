"""One ordered map over three backends: this process, a local process pool, or Dask.

>>> ordered_map(evaluate, [(values, Verlet) for values in grid], Backend(workers=2),
...             shared=scene)                                             # doctest: +SKIP

``func(shared, *job)`` (or ``func(*job)`` without ``shared``) runs for every job; the results
come back in job order whatever order they finish in, so the same jobs give the same result
on any backend. Jobs travel in interleaved batches, a few per worker, so that cheap and
costly jobs mix and small jobs are not drowned in overhead. Dask is imported only when a
scheduler is given; it is the analysis layer's only way to run work in parallel.
"""

from __future__ import annotations

import contextlib
import math
import numbers
import os
import signal
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple

from .errors import UsageError

#: No public names: the analyses run their work through :func:`ordered_map`.
__all__: list[str] = []

def _check(ok: bool, name: str, value: Any, allowed: str) -> None:
    """UsageError naming ``name`` unless ``ok``. (This module sits below the model, so it
    checks with the errors module alone, not with :mod:`dumbbell.model.args`.)"""
    if not ok:
        text = " ".join(repr(value).split())
        raise UsageError(f"{name} = {text if len(text) <= 60 else text[:57] + '...'}: must be "
                         f"{allowed}", param=name)


def _whole(value: Any, name: str, unit: str, lo: int) -> int:
    """``value`` (an int or a numpy integer, not a bool) as an int >= ``lo``."""
    _check(not isinstance(value, bool) and isinstance(value, numbers.Integral)
           and value >= lo, name, value, f"a whole number >= {lo} ({unit})")
    return int(value)


#: Marks "no shared argument".
_NOTHING = object()


def cap_workers(workers: int | None, jobs: int) -> tuple[int, bool]:
    """(processes to start, whether that is fewer than ``workers``): min(workers, CPUs,
    jobs), at least 1; ``workers`` None means the number of CPUs."""
    if workers is not None:
        workers = _whole(workers, "workers", "processes", 1)
    jobs = _whole(jobs, "jobs", "jobs", 0)
    cpus = os.cpu_count() or 1
    n = max(1, min(workers or cpus, cpus, jobs))
    return n, workers is not None and n < workers


def cap_note(flag: str, workers: int | None, jobs: int, what: str = "runs") -> str | None:
    """The one line saying that ``flag`` was capped, or None when it was not."""
    _check(isinstance(flag, str), "flag", flag, "the flag's name (str)")
    _check(isinstance(what, str), "what", what, "what the jobs are called (str)")
    n, capped = cap_workers(workers, jobs)
    if not capped:
        return None
    cpus = os.cpu_count() or 1
    why = f"there are {cpus} CPUs" if n == cpus and cpus <= jobs else f"there are {jobs} {what}"
    return f"{flag} {workers}: starting {n} processes, as {why}"


#: Signals that end a command the way Ctrl-C does: workers stopped, no output kept. The
#: CLI turns them into a clean exit; a pool forks with them blocked (see _on_pool).
STOP_SIGNALS = ("SIGINT", "SIGTERM", "SIGHUP")
_STOP_NUMBERS = {getattr(signal, name) for name in STOP_SIGNALS if hasattr(signal, name)}


def worker_init(initializer: Callable[..., Any] | None = None, *initargs: Any) -> None:
    """Run first in each pool worker. The parent's stop handlers (inherited through fork)
    would turn the pool's own SIGTERM into an exception inside the worker instead of ending
    it, so SIGTERM and SIGHUP get their default back (end the process); SIGINT is ignored,
    because a Ctrl-C reaches the whole process group and the parent stops the workers."""
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if hasattr(signal, "SIGHUP"):
        signal.signal(signal.SIGHUP, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    # The parent forked us with these signals blocked (see _on_pool); now they are safe.
    signal.pthread_sigmask(signal.SIG_UNBLOCK, _STOP_NUMBERS)
    if initializer is not None:
        initializer(*initargs)


def _batches(n: int, workers: int) -> list[list[int]]:
    """Job indices 0..n-1 in interleaved batches: a few per worker, at most 64 jobs each."""
    size = max(1, min(64, n // (8 * max(1, workers))))
    count = math.ceil(n / size) if n else 0
    return [list(range(i, n, count)) for i in range(count)]


def _run_batch(func: Callable[..., Any], shared: tuple, batch: list[tuple[int, tuple]]
               ) -> list[tuple[int, Any]]:
    """Run one batch in a worker: (index, result) pairs. ``shared`` is () or (value,)."""
    return [(i, func(*shared, *job)) for i, job in batch]


def _run_pool_batch(item: tuple[Callable[..., Any], tuple, list[tuple[int, tuple]]]
                    ) -> list[tuple[int, Any]]:
    return _run_batch(*item)


def _run_dask_batch(func: Callable[..., Any], *shared: Any, batch: list[tuple[int, tuple]]
                    ) -> list[tuple[int, Any]]:
    """:func:`_run_batch` for Dask, which resolves futures only among the direct arguments."""
    return _run_batch(func, shared, batch)


def _collect(futures: Iterable[Any], as_completed: Callable[[Any], Iterable[Any]],
             results: list[Any], pb: Any) -> None:
    for fut in as_completed(futures):
        part = fut.result()
        for i, value in part:
            results[i] = value
        pb.update(len(part))


@dataclass(frozen=True)
class Backend:
    """Where and how :func:`ordered_map` runs its jobs.

    ``workers`` 1 (or a single job): in this process. More: a local process pool of that
    many processes (capped at one per CPU and per job, :func:`cap_workers`), each first
    calling ``initializer(*initargs)``. ``scheduler``: a Dask cluster at that address, or
    'local' for a new LocalCluster of ``workers`` single-threaded workers (threads instead of
    processes with ``processes`` False); a scheduler that does not answer within
    ``connect_timeout`` s is a UsageError naming its address. A progress bar counts the jobs
    (``unit``, described by ``desc``) on a terminal unless ``quiet``."""

    workers: int = 1
    scheduler: str | None = None
    processes: bool = True
    initializer: Callable[..., None] | None = None
    initargs: tuple = ()
    quiet: bool = True
    desc: str = ""
    unit: str = "run"
    connect_timeout: float = 10.0

    def __post_init__(self) -> None:
        if self.scheduler is not None:
            _check(isinstance(self.scheduler, str), "scheduler", self.scheduler,
                   "a Dask scheduler's address (str), 'local' or None")
        _whole(self.workers, "workers", "processes", 0 if self.scheduler is not None else 1)
        for name in ("processes", "quiet"):
            value = getattr(self, name)
            _check(isinstance(value, bool) or type(value).__name__ == "bool_", name, value,
                   "True or False")
        _check(self.initializer is None or callable(self.initializer), "initializer",
               self.initializer, "a function or None")
        _check(isinstance(self.initargs, tuple | list), "initargs", self.initargs,
               "a tuple of arguments")
        for name in ("desc", "unit"):
            _check(isinstance(getattr(self, name), str), name, getattr(self, name), "a str")
        _check(not isinstance(self.connect_timeout, bool)
               and isinstance(self.connect_timeout, numbers.Real)
               and 0 < self.connect_timeout < math.inf, "connect_timeout",
               self.connect_timeout, "a finite number > 0 (s)")


class _Work(NamedTuple):
    """The jobs of one :func:`ordered_map`: ``func``, the jobs with their indices, and the
    leading argument every job gets (``()`` or ``(shared,)``)."""

    func: Callable[..., Any]
    indexed: list[tuple[int, tuple]]
    lead: tuple


def ordered_map(func: Callable[..., Any], jobs: Sequence[tuple], backend: Backend | None = None,
                *, shared: Any = _NOTHING) -> list[Any]:
    """``[func(shared, *job) for job in jobs]`` in job order, run where ``backend`` says (by
    default in this process); ``shared`` is sent to every worker once. ``func`` must be a
    module-level function (it is pickled).

    If anything goes wrong here (an exception from a job, Ctrl-C, SIGTERM, SIGHUP) the pool's
    workers are terminated before the exception goes on: none outlives the call."""
    from .progress import bar

    _check(callable(func), "func", func, "a function")
    _check(not isinstance(jobs, str) and isinstance(jobs, Sequence)
           and all(isinstance(job, tuple | list) for job in jobs),
           "jobs", jobs, "a list of argument tuples")
    backend = Backend() if backend is None else backend
    _check(isinstance(backend, Backend), "backend", backend, "a Backend or None")
    workers = backend.workers
    if backend.scheduler is None or backend.scheduler == "local":
        workers, _ = cap_workers(workers, len(jobs))
    results: list[Any] = [None] * len(jobs)
    work = _Work(func, list(enumerate(jobs)), () if shared is _NOTHING else (shared,))
    with bar(len(jobs), backend.desc, backend.unit, quiet=backend.quiet) as pb:
        if backend.scheduler is not None:
            _on_dask(work, backend, workers, results, pb)
        elif workers <= 1 or len(jobs) <= 1:
            for i, job in work.indexed:
                results[i] = func(*work.lead, *job)
                pb.update(1)
        else:
            _on_pool(work, backend, workers, results, pb)
    return results


def _on_pool(work: _Work, backend: Backend, workers: int, results: list[Any], pb: Any) -> None:
    import multiprocessing

    items = [(work.func, work.lead, [work.indexed[i] for i in b])
             for b in _batches(len(work.indexed), workers)]
    # A signal that lands between a worker's fork and its worker_init would run the parent's
    # stop handler inside the worker and print a traceback. So the stop signals stay blocked
    # while the pool forks (its helper threads, which fork replacements, inherit the mask);
    # a signal sent meanwhile waits, and is raised once the pool can be terminated.
    before = signal.pthread_sigmask(signal.SIG_BLOCK, _STOP_NUMBERS)
    try:
        pool = multiprocessing.get_context().Pool(
            workers, initializer=worker_init,
            initargs=(backend.initializer, *backend.initargs))
    except BaseException:
        signal.pthread_sigmask(signal.SIG_SETMASK, before)
        raise
    try:
        signal.pthread_sigmask(signal.SIG_SETMASK, before)
        for part in pool.imap_unordered(_run_pool_batch, items):
            for i, value in part:
                results[i] = value
            pb.update(len(part))
        pool.close()
    except BaseException:
        pool.terminate()
        raise
    finally:
        pool.join()


def _on_dask(work: _Work, backend: Backend, workers: int, results: list[Any], pb: Any
             ) -> None:
    scheduler = backend.scheduler
    try:
        from dask.distributed import Client, LocalCluster, as_completed
    except ImportError:
        raise UsageError("scheduler needs dask.distributed: pip install 'dumbbell[dask]'",
                         param="scheduler") from None
    with contextlib.ExitStack() as stack:
        if scheduler == "local":
            cluster = stack.enter_context(LocalCluster(
                n_workers=workers or os.cpu_count() or 1, threads_per_worker=1,
                processes=backend.processes, dashboard_address=None, silence_logs=50))
            client = stack.enter_context(Client(cluster))
        else:
            client = stack.enter_context(_connect(Client, scheduler, backend.connect_timeout))
        n_workers = max(1, len(client.scheduler_info().get("workers", {})))
        # The shared value goes to every worker once; each batch names it by its future.
        sent = [client.scatter(value, broadcast=True) for value in work.lead]
        futures = [client.submit(_run_dask_batch, work.func, *sent,
                                 batch=[work.indexed[i] for i in b], pure=False)
                   for b in _batches(len(work.indexed), n_workers)]
        try:
            _collect(futures, as_completed, results, pb)
        except BaseException:
            client.cancel(futures)
            raise


class _NotDask(Exception):
    """The peer at a scheduler address is not a Dask scheduler."""


def _probe(scheduler: str, timeout: float) -> None:
    """Raise unless something at the ``tcp://`` address ``scheduler`` speaks first within
    ``timeout`` s, as a Dask scheduler does (it sends its handshake on accept): Dask's own
    timeout bounds the TCP connect but not a peer that accepts and then stays silent, such
    as an HTTP server. Other schemes are left to Dask."""
    import socket
    from urllib.parse import urlsplit

    parts = urlsplit(scheduler)
    if parts.scheme != "tcp":
        return
    try:
        host, port = parts.hostname, parts.port
    except ValueError as exc:
        raise _NotDask(f"not an address: {exc}") from None
    if not host or port is None:
        raise _NotDask("not an address: give tcp://HOST:PORT")
    with socket.create_connection((host, port), timeout=timeout) as sock:
        try:
            first = sock.recv(1)
        except TimeoutError:
            raise _NotDask("it accepted the connection but did not answer as one") from None
    if not first:
        raise _NotDask("it closed the connection without answering")


#: The way out of an unreachable scheduler; each command spells {connect_timeout} its way.
_SCHEDULER_FIX = "check the address, or wait longer with a larger {connect_timeout}"


def _connect(client_class: Any, scheduler: str, timeout: float) -> Any:
    """A Dask client of ``scheduler``, or one UsageError naming the address when nothing there
    answers as a Dask scheduler within ``timeout`` s (a closed port, an HTTP server, ...)."""
    import logging

    # distributed logs each failed attempt; the one line below says it all.
    loggers = [logging.getLogger(n) for n in ("distributed", "tornado")]
    levels = [lg.level for lg in loggers]
    for lg in loggers:
        lg.setLevel(logging.CRITICAL + 1)
    try:
        _probe(scheduler, timeout)
        return client_class(scheduler, timeout=f"{timeout}s")
    except Exception as exc:  # noqa: BLE001 - any failure to connect is the same one line
        text = exc.args[0] if isinstance(exc, _NotDask) else " ".join(
            f"{type(exc).__name__}: {exc}".split())[:160]
        raise UsageError(f"scheduler {scheduler}: no Dask scheduler answered there within "
                         f"{timeout:g} s: {text}", param="scheduler",
                         fixes=[_SCHEDULER_FIX]) from None
    finally:
        for lg, level in zip(loggers, levels, strict=True):
            lg.setLevel(level)
