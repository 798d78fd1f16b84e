"""What the work-precision report is made of: one measured point (:class:`Row`),
how it is timed (:func:`timed`), the progress lines (:func:`log`) and the wall
times' notation (:func:`fmt_time`).

Every problem of the report, its own (:mod:`hamilton_orbits.studies.problems`) and
those other packages add through the entry point group
``hamilton_orbits.report_problems`` (``rigid``'s), returns a list of :class:`Row`;
:mod:`hamilton_orbits.studies.report` re-exports these names for them.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

__all__ = ["Row", "fmt_time", "log", "timed"]


@dataclass
class Row:
    """One measured point of the report."""

    problem: str
    code: str
    method: str
    parameter: str
    error: float
    error_measure: str
    reference: str
    wall_time: float


def timed(fn: Callable[[], Any], repeat: int = 3) -> tuple[float, Any]:
    """The shortest wall time of ``repeat`` calls of ``fn`` (fewer if one takes over
    2 s), and the last call's result.

    Examples
    --------
    >>> seconds, value = timed(lambda: 6 * 7, repeat=2)
    >>> value, seconds >= 0.0
    (42, True)
    """
    best = math.inf
    out = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        dt = time.perf_counter() - t0
        best = min(best, dt)
        if dt > 2.0:
            break
    return best, out


def log(progress: bool, msg: str) -> None:
    """Print ``msg`` as a report progress line when ``progress`` is true.

    Examples
    --------
    >>> log(True, "kepler: 9 rows")
    [report] kepler: 9 rows
    """
    if progress:
        print(f"[report] {msg}", flush=True)


def fmt_time(seconds: float) -> str:
    """A wall time with a readable unit.

    Examples
    --------
    >>> fmt_time(0.5), fmt_time(2.0e-5), fmt_time(12.34)
    ('500 ms', '20 µs', '12.3 s')
    """
    if seconds >= 1:
        return f"{seconds:.3g} s"
    if seconds >= 1e-3:
        return f"{seconds * 1e3:.3g} ms"
    return f"{seconds * 1e6:.3g} µs"
