"""hamilton_orbits.batches: jobs in order, serially, on threads and on Dask."""

from __future__ import annotations

import threading
import time

import pytest

from hamilton_orbits.batches import run_jobs


def _slow_square(offset, job):
    """Later jobs finish first (so the order must be restored), and the thread that
    ran each is recorded."""
    time.sleep(0.02 * (4 - job))
    return job * job + offset, threading.get_ident()


@pytest.mark.parametrize("workers", [None, 1, 3])
def test_results_come_back_in_the_order_of_the_jobs(workers):
    out = run_jobs(_slow_square, 10, [0, 1, 2, 3], workers=workers)
    assert [x for x, _ in out] == [10, 11, 14, 19]
    threads = {t for _, t in out}
    assert (len(threads) > 1) == (workers == 3)  # (three threads really ran them)


def test_an_exception_in_a_job_is_raised_by_the_batch():
    def fails_on_two(_, job):
        if job == 2:
            raise ValueError(f"job {job} failed")
        return job

    for workers in (None, 2):
        with pytest.raises(ValueError, match="job 2 failed"):
            run_jobs(fails_on_two, None, [0, 1, 2, 3], workers=workers)


def test_on_an_in_process_dask_cluster_as_locally():
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(processes=False, n_workers=1, threads_per_worker=2,
                                  dashboard_address=":0") as cluster, \
            distributed.Client(cluster) as client:
        out = run_jobs(_slow_square, 10, [0, 1, 2, 3], client=client)
    assert [x for x, _ in out] == [10, 11, 14, 19]


@pytest.mark.parametrize(("kw", "match"), [
    (dict(workers=0), "`workers` to be a number of threads >= 1, got 0"),
    (dict(workers=True), "`workers`"),
    (dict(client="tcp://127.0.0.1:1"), "`client` .* connect first"),
    (dict(client=object()), "`client` to be a dask.distributed.Client"),
])
def test_bad_arguments_are_refused_naming_them(kw, match):
    with pytest.raises(ValueError, match=match):
        run_jobs(_slow_square, 0, [1], **kw)


def test_a_progress_that_is_not_a_bool_is_refused_by_name():
    """``progress="no"`` drew a bar over the jobs (any non-empty text is true)."""
    with pytest.raises(ValueError, match=r"`progress` to be True or False, got 'no'"):
        run_jobs(_slow_square, 10, [0, 1], progress="no")
