"""Ensembles: a grid (or a list) of variations of one scene, run in parallel.

Each member is the scene with some keys replaced (:meth:`Scene.from_values`:
checked once, its system built once, one :class:`~hamilton_orbits.Simulation` run
once; the compiled right-hand side is shared by every member a worker runs), run
in a worker process; its row holds the varied values, the member's headline
metrics (numbers; Quantities as plain numbers in the unit named in the column),
its wall time, and the error if it failed.  A member that fails does not lose
the others.

Locally (the default) members run in a pool of processes on all cores.  With a
``dask.distributed.Client`` (``client=``) they run on that cluster; Dask is the
optional extra ``[dask]``.
"""

from __future__ import annotations

import itertools
import os
import time
import warnings
from collections.abc import Mapping, Sequence
from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits._progress import progress_bar
from hamilton_orbits.batches import check_client, check_workers
from hamilton_orbits.integrals import WARN_UNDER_RESOLVED, UnderResolvedEncounterWarning
from hamilton_orbits.scene import Scene

__all__ = ["UNDER_RESOLVED", "Ensemble", "run_member"]

#: The column of a member's count of close approaches its fixed step was too long for.
UNDER_RESOLVED = "under-resolved encounters"


def run_member(data: Mapping[str, Any], source: str, values: Mapping[str, Any]) -> dict:
    """Run one member (in a worker): the scene ``data`` with ``values``; its row.

    Never raises: a failure is recorded in the row's ``error``.

    Examples
    --------
    >>> from hamilton_orbits import Scene
    >>> s = Scene.bundled("dzhanibekov")
    >>> row = run_member(s.data, s.source, {"duration": "40 s"})
    >>> row["error"] is None, row["simulated flip interval [s]"] > 0
    (True, True)
    """
    row: dict[str, Any] = {key: _plain(v) for key, v in values.items()}
    start = time.perf_counter()
    try:
        scene = Scene.from_values(data, source, dict(values))  # checked once, built once
        quiet = WARN_UNDER_RESOLVED.set(False)  # (counted in the row, and the ensemble
        try:  # warns once for all its members: a map of 64 cells warned 4 times)
            result = scene.run(progress=False)
        finally:
            WARN_UNDER_RESOLVED.reset(quiet)
        if not result.complete or result.interrupted:
            raise KeyboardInterrupt  # (no stop is given: a Ctrl-C cut the member, and
            # it ends the ensemble, as in a pool of workers, not the member alone)
    except Exception as exc:  # a member's failure is data, not the end of the run
        row["wall time [s]"] = time.perf_counter() - start
        row["complete"] = False
        row["error"] = f"{type(exc).__name__}: {exc}"
        return row
    for name, value in result.metrics.items():
        if isinstance(value, u.Quantity) and value.isscalar:
            row[f"{name} [{value.unit.to_string()}]"] = float(value.value)
        elif isinstance(value, (int, np.integer)) and not isinstance(value, bool):
            row[name] = int(value)  # (a count: an integer, in the table and its CSV)
        elif isinstance(value, (float, np.floating)):
            row[name] = float(value)
        elif isinstance(value, str) and name.startswith("first "):
            row[name] = value  # the bodies of a member's first event of a kind
    row["wall time [s]"] = result.wall_time
    row["complete"] = bool(result.complete)
    row["error"] = None
    return row


def _members(members: Any) -> list[dict[str, Any]]:
    """``members`` as a list of dicts, refusing anything else with its index."""
    if members is None:
        return []
    if isinstance(members, (str, bytes, Mapping)) or not isinstance(members, Sequence):
        raise ValueError(f"Expected `members` to be a list of mappings {{key: value}}, got "
                         f"{members!r}")
    for k, m in enumerate(members):
        if not isinstance(m, Mapping):
            raise ValueError(f"Expected `members` to hold mappings {{key: value}}, got {m!r} "
                             f"at index {k}")
    return [dict(m) for m in members]


def _check_run_args(client: Any, workers: Any) -> None:
    """Refuse a ``client`` that is not a Dask client and a ``workers`` that is not a count."""
    check_client(client)
    check_workers(workers, "processes")


def _plain(value: Any) -> Any:
    if isinstance(value, u.Quantity):
        return str(value)
    if isinstance(value, (list, tuple)):
        return str(list(value))
    return value


class Ensemble:
    """Variations of one scene, run in parallel; rows in a pandas DataFrame.

    Parameters
    ----------
    scene : Scene
        The base scene.
    vary : mapping of key -> sequence of values, optional
        The grid: every combination of the values (keys as for ``--set``:
        ``"integrator.tol"``, ``"bodies.mercury.e"``, ``"body.omega"``).
    members : sequence of mappings, optional
        Instead of (or after) the grid: an explicit list of variations.

    Raises
    ------
    ValueError
        For a ``vary`` that is not a mapping of sequences, ``members`` that are
        not mappings, an empty variation, or a member that does not make a valid
        scene (checked before anything runs, naming the member's index).

    Examples
    --------
    >>> from hamilton_orbits import Ensemble, Scene
    >>> ens = Ensemble(Scene.bundled("dzhanibekov"),
    ...                vary={"duration": ["20 s", "40 s"], "integrator.dt": ["1 ms", "2 ms"]})
    >>> len(ens)
    4
    >>> ens.members[1]
    {'duration': '20 s', 'integrator.dt': '2 ms'}
    """

    def __init__(
        self,
        scene: Scene,
        vary: Mapping[str, Sequence[Any]] | None = None,
        members: Sequence[Mapping[str, Any]] | None = None,
    ) -> None:
        if not isinstance(scene, Scene):
            raise ValueError(f"Expected `scene` to be a Scene, got {scene!r}")
        if vary is not None and not isinstance(vary, Mapping):
            raise ValueError(f"Expected `vary` to be a mapping of key -> values, got {vary!r}")
        grid: list[dict[str, Any]] = []
        if vary:
            keys = list(vary)
            for key in keys:
                values = vary[key]
                if isinstance(values, (str, bytes)) or not isinstance(values, Sequence):
                    raise ValueError(
                        f"Expected `vary[{key!r}]` to be a sequence of values, got {values!r}"
                    )
                if len(values) == 0:
                    raise ValueError(f"Expected `vary[{key!r}]` to hold values, got none")
            grid = [dict(zip(keys, combo, strict=True))
                    for combo in itertools.product(*(vary[k] for k in keys))]
        grid += _members(members)
        if not grid:
            raise ValueError("Expected `vary` or `members` to give at least one member")
        for k, member in enumerate(grid):
            try:
                scene.with_values(member)
            except ValueError as exc:  # SceneError: every problem, with the key
                raise ValueError(f"Member {k} ({member}) is not a valid scene: {exc}") from exc
        self.scene = scene
        self.members: list[dict[str, Any]] = grid

    def __len__(self) -> int:
        return len(self.members)

    def __repr__(self) -> str:
        return f"Ensemble({self.scene.name!r}, {len(self)} members)"

    def run(self, client: Any = None, progress: bool = True, workers: int | None = None):
        """Run every member; a DataFrame with one row per member, in member order.

        Parameters
        ----------
        client : dask.distributed.Client, optional
            Run on this cluster; default: a local pool of processes.
        progress : bool
            A progress bar over the whole grid (tqdm, quiet when not a terminal).
        workers : int, optional
            Local processes (default: all cores, at most one per member).  They are
            kept for the next ensemble of as many (their start and compilation paid
            once); another count replaces them, and a pool that lost a worker (killed
            by the system) is replaced.

        Returns
        -------
        pandas.DataFrame
            The varied keys, each member's metrics, ``wall time [s]``, ``complete``
            and ``error`` (None for members that ran).  ``df.attrs["failures"]``
            counts the members that failed.

        Raises
        ------
        ValueError
            For a ``client`` that is not a Dask client (an address must be
            connected first: ``Client("tcp://...")``) or ``workers`` < 1.
        """
        _check_run_args(client, workers)
        try:
            import pandas as pd
        except ImportError as exc:  # pragma: no cover - pandas comes with the extra
            raise ImportError(
                "Ensemble tables need pandas: pip install 'hamilton-orbits[ensemble]'"
            ) from exc
        args = [(self.scene.data, self.scene.source, m) for m in self.members]
        bar = progress_bar(len(args), progress, "member")
        rows: list[dict | None] = [None] * len(args)
        try:
            if client is not None:
                futures = client.map(run_member, *zip(*args, strict=True), pure=False)
                index = {f.key: i for i, f in enumerate(futures)}
                from dask.distributed import as_completed

                for fut in as_completed(futures):
                    rows[index[fut.key]] = fut.result()
                    if bar is not None:
                        bar.update(1)
            else:
                n = workers or min(len(args), os.cpu_count() or 1)
                if n <= 1:
                    for i, a in enumerate(args):
                        rows[i] = run_member(*a)
                        if bar is not None:
                            bar.update(1)
                else:
                    _in_pool(n, args, rows, bar)
        finally:
            if bar is not None:
                bar.close()
        df = pd.DataFrame(rows)
        # (the members' own values: pandas would make None a NaN of a string column
        # where one member failed, and infer the flags' type from them)
        df["error"] = pd.Series([row["error"] for row in rows], index=df.index, dtype=object)
        df["complete"] = pd.Series([row["complete"] for row in rows], index=df.index,
                                   dtype=bool)
        for column in df.columns:  # (counts stay integers where a member failed: 2274,
            values = [row.get(column) for row in rows]  # not 2274.0 in the CSV)
            given = [v for v in values if v is not None]
            if given and all(isinstance(v, int | np.integer) and not isinstance(v, bool)
                             for v in given):
                df[column] = pd.array(values, dtype="Int64")
        df.attrs["failures"] = int(df["error"].notna().sum())
        _warn_under_resolved(df)
        return df


def _warn_under_resolved(df: Any) -> None:
    """One warning for the members whose fixed step was too long for a close approach
    (each member's run would have warned on its own)."""
    if UNDER_RESOLVED not in df.columns:
        return
    hit = df[UNDER_RESOLVED].fillna(0) > 0
    if hit.any():
        warnings.warn(UnderResolvedEncounterWarning(
            f"{int(hit.sum())} of {len(df)} members crossed close approaches their fixed "
            f"step was too long for (column {UNDER_RESOLVED!r}): their results after them "
            "are not to be trusted; shorten the step or use an adaptive method (radau15)"),
            stacklevel=3)


_POOLS: dict[int, Any] = {}
#: the runs going on in each kept pool (another thread's ensemble): a pool in use is
#: not shut down for one of another size (its queued members were cancelled, unseen
#: by its run's wait: that run waited for ever)
_IN_USE: dict[int, int] = {}


def _in_pool(n: int, args: list[tuple], rows: list[dict | None], bar: Any) -> None:
    """Run the members ``args`` on the kept pool of ``n`` processes into ``rows``.  A
    pool found broken before any member of this run has ended (one of its workers
    killed since the last ensemble: the out-of-memory killer) is replaced and the run
    begun again on the new one; one that breaks later fails the run, saying so, and
    is dropped, so that the next ensemble starts a new pool (a broken pool failed
    every later ensemble)."""
    kept = n in _POOLS  # (a pool this run makes and its members break: not run again)
    _IN_USE[n] = _IN_USE.get(n, 0) + 1
    try:
        _runs_in_pool(n, args, rows, bar, kept)
    finally:
        _IN_USE[n] -= 1


def _runs_in_pool(n: int, args: list[tuple], rows: list[dict | None], bar: Any,
                  kept: bool) -> None:
    """:func:`_in_pool`'s attempts: a second on a new pool only where the kept one
    (``kept``) broke before any member of this run ended."""
    from concurrent.futures.process import BrokenProcessPool

    for attempt in (1, 2):
        try:
            futs = _submitted(_pool(n), args)
            _collected(futs, rows, bar)
            return
        except BrokenProcessPool as exc:
            _drop(n)
            if attempt == 1 and kept and all(row is None for row in rows):
                continue  # (the pool was broken before: this run begun again)
            raise BrokenProcessPool(f"a worker process of the ensemble's pool of {n} ended "
                                    f"abruptly ({_likely_cause()}); the members it had "
                                    f"not finished are lost; the next run starts a new "
                                    f"pool") from exc


def _likely_cause() -> str:
    """Why a worker ended abruptly, as likely as can be told: a script's run not under
    ``if __name__ == "__main__":`` (each worker, started by the spawn method, runs the
    script's module-level statements again, this run among them, and dies starting
    a pool of its own: Python's bootstrapping RuntimeError, on stderr), or else the
    memory.  That is told from where this run was called, not guessed."""
    where = _unguarded_call()
    if where is None:
        return "killed: out of memory?"
    return (f"the script calls this run at {where} outside an `if __name__ == "
            f"\"__main__\":` block: each worker, started by the spawn method, runs the "
            f"script again up to there and fails starting its own pool (Python's "
            f"RuntimeError about the bootstrapping phase, above); put the script's run "
            f"under that guard")


def _unguarded_call() -> str | None:
    """``"file:line"`` of the module-level statement of the ``__main__`` script (a
    file: not a notebook or ``python -c``) through which this run was called, when
    it stands outside an ``if __name__ == "__main__":`` block; None otherwise (or
    when the script cannot be read)."""
    import inspect
    import sys
    from pathlib import Path

    main = sys.modules.get("__main__")
    path = getattr(main, "__file__", None)
    frame = inspect.currentframe()
    while frame is not None and not (frame.f_code.co_name == "<module>"
                                     and frame.f_globals is getattr(main, "__dict__", None)):
        frame = frame.f_back
    if path is None or frame is None:
        return None
    try:
        source = Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return None
    line = frame.f_lineno
    return None if _in_main_guard(source, line) else f"{path}:{line}"


def _in_main_guard(source: str, line: int) -> bool:
    r"""True if ``line`` of the module ``source`` lies in an ``if __name__ ==
    "__main__":`` block (or the source cannot be parsed: nothing is claimed).

    Examples
    --------
    >>> code = 'import x\nx.run()\nif __name__ == "__main__":\n    x.run()\n'
    >>> _in_main_guard(code, 2), _in_main_guard(code, 4)
    (False, True)
    """
    import ast

    try:
        tree = ast.parse(source)
    except (SyntaxError, ValueError):
        return True
    guards = ('__name__ == "__main__"', '"__main__" == __name__')
    return any(isinstance(node, ast.If) and ast.unparse(node.test).replace("'", '"') in guards
               and node.lineno <= line <= (node.end_lineno or node.lineno)
               for node in ast.walk(tree))  # (a guard within a try: block too)


def _collected(futs: dict[Any, int], rows: list[dict | None], bar: Any) -> None:
    """The members' rows as their futures end; on any exception (Ctrl-C, a worker
    lost) the members not begun are cancelled, not run for nothing."""
    from concurrent.futures import as_completed

    try:
        for fut in as_completed(futs):
            rows[futs[fut]] = fut.result()
            if bar is not None:
                bar.update(1)
    except BaseException:
        for fut in futs:
            fut.cancel()
        raise


def _submitted(pool: Any, args: list[tuple]) -> dict[Any, int]:
    return {pool.submit(run_member, *a): i for i, a in enumerate(args)}


def _pool(n: int) -> Any:
    """A pool of ``n`` worker processes kept for the session (started once: the
    workers' imports and compiled kernels are paid on the first ensemble only); a
    pool of another size is shut down first, unless a run uses it (one pool's
    processes at a time, but for runs going on at once)."""
    for other in [k for k in _POOLS if k != n and not _IN_USE.get(k)]:
        _drop(other)
    pool = _POOLS.get(n)
    if pool is None:
        import atexit
        import multiprocessing as mp
        from concurrent.futures import ProcessPoolExecutor

        ctx = mp.get_context("spawn")  # safe beside numba's threads
        pool = ProcessPoolExecutor(max_workers=n, mp_context=ctx)
        _POOLS[n] = pool
        atexit.register(pool.shutdown, wait=False, cancel_futures=True)
    return pool


def _drop(n: int) -> None:
    """Shut the kept pool of ``n`` processes down (its workers end)."""
    pool = _POOLS.pop(n, None)
    if pool is not None:
        pool.shutdown(wait=False, cancel_futures=True)
