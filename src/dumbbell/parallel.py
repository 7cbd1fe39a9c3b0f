"""One ordered map over three backends: this process, a local process pool, or Dask.

>>> ordered_map(evaluate, [(values, "verlet") for values in grid], shared=scene,
...             workers=2)                                                # doctest: +SKIP

``func(shared, *job)`` (or ``func(*job)`` without ``shared``) runs for every job; the results
come back in job order whatever order they finish in, so the same jobs give the same result
on any backend. Jobs travel in interleaved batches, a few per worker, so that cheap and
costly jobs mix and small jobs are not drowned in overhead. Dask is imported only when a
scheduler is given; it is the analysis layer's only way to run work in parallel.
"""

from __future__ import annotations

import contextlib
import math
import os
from collections.abc import Callable, Iterable, Sequence
from typing import Any

from .errors import UsageError

#: Marks "no shared argument".
_NOTHING = object()


def batches(n: int, workers: int) -> list[list[int]]:
    """Job indices 0..n-1 in interleaved batches: a few per worker, at most 64 jobs each."""
    size = max(1, min(64, n // (8 * max(1, workers))))
    count = math.ceil(n / size) if n else 0
    return [list(range(i, n, count)) for i in range(count)]


def _run_batch(func: Callable[..., Any], shared: tuple, batch: list[tuple[int, tuple]]
               ) -> list[tuple[int, Any]]:
    """Run one batch in a worker: (index, result) pairs. ``shared`` is () or (value,)."""
    return [(i, func(*shared, *job)) for i, job in batch]


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


def ordered_map(
    func: Callable[..., Any], jobs: Sequence[tuple], *, shared: Any = _NOTHING,
    workers: int = 1, scheduler: str | None = None, processes: bool = True,
    initializer: Callable[..., None] | None = None, initargs: tuple = (),
    quiet: bool = True, desc: str = "", unit: str = "run",
) -> list[Any]:
    """``[func(shared, *job) for job in jobs]`` in job order.

    ``workers`` 1 (or a single job): in this process. More: a local process pool of that
    many processes, each first calling ``initializer(*initargs)``. ``scheduler``: a Dask
    cluster at that address, or 'local' for a new LocalCluster of ``workers``
    single-threaded workers (threads instead of processes with ``processes`` False);
    ``shared`` is then sent to every worker once. ``func`` must be a module-level function
    (it is pickled). A progress bar counts the jobs on a terminal unless ``quiet``."""
    from .progress import bar

    results: list[Any] = [None] * len(jobs)
    indexed = list(enumerate(jobs))
    lead = () if shared is _NOTHING else (shared,)
    with bar(len(jobs), desc, unit, quiet=quiet) as pb:
        if scheduler is not None:
            _on_dask(func, indexed, lead, scheduler, workers, processes, results, pb)
        elif workers <= 1 or len(jobs) <= 1:
            for i, job in indexed:
                results[i] = func(*lead, *job)
                pb.update(1)
        else:
            from concurrent.futures import ProcessPoolExecutor, as_completed

            with ProcessPoolExecutor(max_workers=workers, initializer=initializer,
                                     initargs=initargs) as pool:
                futures = [pool.submit(_run_batch, func, lead, [indexed[i] for i in b])
                           for b in batches(len(jobs), workers)]
                try:
                    _collect(futures, as_completed, results, pb)
                except BaseException:
                    for fut in futures:
                        fut.cancel()
                    raise
    return results


def _on_dask(func: Callable[..., Any], indexed: list[tuple[int, tuple]], lead: tuple,
             scheduler: str, workers: int, processes: bool, results: list[Any], pb: Any
             ) -> None:
    try:
        from dask.distributed import Client, LocalCluster, as_completed
    except ImportError:
        raise UsageError("scheduler needs dask.distributed: pip install 'dumbbell[dask]'",
                         param="scheduler") from None
    with contextlib.ExitStack() as stack:
        if scheduler == "local":
            cluster = stack.enter_context(LocalCluster(
                n_workers=workers or os.cpu_count() or 1, threads_per_worker=1,
                processes=processes, dashboard_address=None, silence_logs=50))
            client = stack.enter_context(Client(cluster))
        else:
            try:
                client = stack.enter_context(Client(scheduler, timeout="10s"))
            except (OSError, TimeoutError, ValueError) as exc:
                text = " ".join(str(exc).split())[:200]
                raise UsageError(f"scheduler {scheduler}: cannot connect to a Dask "
                                 f"scheduler there ({text})", param="scheduler") from None
        n_workers = max(1, len(client.scheduler_info().get("workers", {})))
        # The shared value goes to every worker once; each batch names it by its future.
        sent = [client.scatter(value, broadcast=True) for value in lead]
        futures = [client.submit(_run_dask_batch, func, *sent, batch=[indexed[i] for i in b],
                                 pure=False)
                   for b in batches(len(indexed), n_workers)]
        try:
            _collect(futures, as_completed, results, pb)
        except BaseException:
            client.cancel(futures)
            raise
