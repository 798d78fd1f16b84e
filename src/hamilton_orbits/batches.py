"""Independent jobs run one after another, on threads, or on a Dask cluster.

:func:`run_jobs` is the executor of batches whose jobs spend their time in the
compiled kernels, which release the GIL (``nogil``): on ``workers`` threads of
this process they run on as many cores with nothing copied or pickled; with a
``dask.distributed.Client`` the shared argument is sent to every worker once
(``scatter``, broadcast) and the jobs are its tasks.  Results come back in the
order of the jobs, whichever finishes first.
"""

from __future__ import annotations

import numbers
from collections.abc import Callable, Sequence
from typing import Any

from hamilton_orbits._progress import progress_bar
from hamilton_orbits.validation import as_flag

__all__ = ["check_client", "check_workers", "run_jobs"]


def check_client(client: Any) -> None:
    """Refuse a ``client`` that is not None or a ``dask.distributed.Client``.

    Raises
    ------
    ValueError
        Naming ``client`` (an address string: how to connect first).

    Examples
    --------
    >>> check_client(None)
    >>> check_client("tcp://127.0.0.1:8786")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Expected `client` ... connect first: dask.distributed.Client('tcp://...')
    """
    if client is not None and not (callable(getattr(client, "map", None))
                                   and callable(getattr(client, "submit", None))):
        hint = (f"; connect first: dask.distributed.Client({client!r})"
                if isinstance(client, str) else "")
        raise ValueError(f"Expected `client` to be a dask.distributed.Client, got {client!r}"
                         + hint)


def check_workers(workers: Any, what: str) -> None:
    """Refuse a ``workers`` that is not None or a count ``>= 1`` of ``what``.

    Examples
    --------
    >>> check_workers(2, "threads")
    >>> check_workers(0, "threads")
    Traceback (most recent call last):
    ...
    ValueError: Expected `workers` to be a number of threads >= 1, got 0
    """
    if workers is not None and (isinstance(workers, bool)
                                or not isinstance(workers, numbers.Integral) or workers < 1):
        raise ValueError(f"Expected `workers` to be a number of {what} >= 1, got {workers!r}")


def run_jobs(fn: Callable[[Any, Any], Any], shared: Any, jobs: Sequence[Any], *,
             workers: int | None = None, client: Any = None, progress: bool = False,
             unit: str = "job") -> list[Any]:
    """``[fn(shared, job) for job in jobs]``, serially, on ``workers`` threads, or as
    tasks of the Dask ``client`` (``fn`` must then be importable by name).

    Parameters
    ----------
    fn : callable
        ``fn(shared, job)``; an exception in any job is raised here.
    shared : object
        The argument every job shares (sent to a cluster's workers once).
    jobs : sequence
        One argument per job.
    workers : int, optional
        Threads of this process (default: one, the caller's).
    client : dask.distributed.Client, optional
        Run on that cluster instead.
    progress : bool
        A progress bar over the jobs (tqdm, on stderr; none for a single job).
    unit : str
        What a job is called on the bar.

    Returns
    -------
    list
        The results, in the order of ``jobs``.

    Examples
    --------
    >>> run_jobs(lambda k, x: k * x, 10, [1, 2, 3], workers=2)
    [10, 20, 30]
    """
    check_client(client)
    check_workers(workers, "threads")
    bar = progress_bar(len(jobs), as_flag("progress", progress) and len(jobs) > 1, unit)
    out: list[Any] = [None] * len(jobs)
    try:
        for k, result in _completed(fn, shared, jobs, workers, client):
            out[k] = result
            if bar is not None:
                bar.update(1)
    finally:
        if bar is not None:
            bar.close()
    return out


def _completed(fn: Callable[[Any, Any], Any], shared: Any, jobs: Sequence[Any],
               workers: int | None, client: Any) -> Any:
    """``(index, result)`` of each job as it completes."""
    if client is not None:
        from dask.distributed import as_completed

        there = client.scatter(shared, broadcast=True)
        futures = [client.submit(fn, there, job, pure=False) for job in jobs]
        index = {f.key: k for k, f in enumerate(futures)}
        for fut in as_completed(futures):
            yield index[fut.key], fut.result()
    elif workers is None or workers == 1 or len(jobs) <= 1:
        for k, job in enumerate(jobs):
            yield k, fn(shared, job)
    else:
        from concurrent.futures import ThreadPoolExecutor, as_completed

        with ThreadPoolExecutor(max_workers=min(workers, len(jobs))) as pool:
            futs = {pool.submit(fn, shared, job): k for k, job in enumerate(jobs)}
            try:
                for fut in as_completed(futs):
                    yield futs[fut], fut.result()
            finally:
                for fut in futs:
                    fut.cancel()
