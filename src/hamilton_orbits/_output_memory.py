"""How much memory a run's outputs may take, refused by name before the run.

:data:`OUTPUT_LIMIT` bounds a scene's outputs (checked at loading,
:mod:`hamilton_orbits.scenes.base`); :func:`memory_limit` bounds those of a call of
:meth:`Simulation.integrate <hamilton_orbits.Simulation.integrate>`, which
:func:`check_output_memory` checks before anything is integrated (numpy's own
``MemoryError`` came after the setting up, or, for a request a little under the
machine's memory, not at all: the machine ran out of memory instead).
:func:`format_size` and :func:`beyond_limit` word both refusals.
"""

from __future__ import annotations

import functools
import os

__all__ = ["OUTPUT_LIMIT", "beyond_limit", "check_output_memory", "format_size",
           "memory_limit", "output_bytes"]

OUTPUT_LIMIT = 2**30
"""The most memory (bytes) a scene's outputs may take: 1 GiB of float64 values
kept at the output times (the states, and as much again in ``states.nc``).  A
scene asking for more is refused at loading, not after hours of running."""


def format_size(nbytes: float) -> str:
    """``nbytes`` in the binary unit that reads best, to 3 significant digits.

    Examples
    --------
    >>> format_size(512), format_size(26_000_000_000)
    ('512 bytes', '24.2 GiB')
    """
    for unit in ("bytes", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if nbytes < 1024 or unit == "PiB":
            return f"{nbytes:.3g} {unit}"
        nbytes /= 1024
    return ""  # pragma: no cover


def beyond_limit(nbytes: float, limit: float = OUTPUT_LIMIT) -> str:
    """``"X, beyond the limit of Y"``, in bytes where the two would read the same.

    Examples
    --------
    >>> beyond_limit(2**30 + 1)
    '1073741825 bytes, beyond the limit of 1073741824 bytes'
    """
    size, most = format_size(nbytes), format_size(limit)
    if size == most:  # (just beyond it: "1 GiB, beyond the limit of 1 GiB")
        size, most = f"{nbytes:.0f} bytes", f"{limit:.0f} bytes"
    return f"{size}, beyond the limit of {most}"


@functools.cache
def memory_limit() -> int:
    """The most memory (bytes) the outputs of one ``Simulation.integrate`` call may
    take: half the machine's physical memory, at least :data:`OUTPUT_LIMIT`.

    Half, not all: the run holds more than its outputs (the integrator's state, the
    trajectory's integrals, whatever else the process and the machine hold), and an
    allocation a little under the memory is granted by the system and then runs the
    machine out of memory as it is filled.  A fixed size would refuse on a large
    machine what fits there, or let through on a small one what does not; the
    scenes' fixed :data:`OUTPUT_LIMIT` is the least, where the memory is not known.
    """
    try:
        physical = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (AttributeError, ValueError, OSError):  # pragma: no cover - not POSIX
        return OUTPUT_LIMIT
    return max(OUTPUT_LIMIT, physical // 2)


def output_bytes(n_outputs: int, n_bodies: int, stm: bool,
                 copies: float = 2.0) -> tuple[float, float]:
    """The bytes of ``n_outputs`` outputs of ``n_bodies`` bodies: the positions and
    velocities (and MEGNO's three columns), and the STM's (``6n x 6n`` a row,
    counted ``copies`` times: twice for a Simulation, the integrator's rows and the
    trajectory's copy; 0 without it).

    Examples
    --------
    >>> round(output_bytes(1001, 300, True)[1] / 2**30, 1)  # GiB
    48.3
    """
    states = n_outputs * (6.0 * n_bodies + 4.0) * 8.0
    matrices = copies * n_outputs * (6.0 * n_bodies) ** 2 * 8.0 if stm else 0.0
    return states, matrices


def _times(copies: float) -> str:
    """``copies`` as words: "once", "twice", "1.3 times"."""
    return {1.0: "once", 2.0: "twice"}.get(copies, f"{copies:.3g} times")


def check_output_memory(n_outputs: int, n_bodies: int, stm: bool,
                        copies: float = 2.0) -> None:
    """Refuse, before a run, outputs beyond :func:`memory_limit`: naming ``stm``
    when the STM takes them beyond it, ``t`` (the output times) otherwise (the STM
    counted ``copies`` times, as :func:`output_bytes`).

    Raises
    ------
    ValueError
        With the outputs' count, the bodies', the size and the limit.

    Examples
    --------
    >>> check_output_memory(1001, 300, False)
    >>> check_output_memory(10**9, 300, False)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Expected `t` to ask for outputs that fit in memory: 1e+09 outputs of 300 ...
    """
    states, matrices = output_bytes(n_outputs, n_bodies, stm, copies)
    limit = memory_limit()
    if states + matrices <= limit:
        return
    fit = int(limit // ((states + matrices) / n_outputs))
    advice = (f": ask for at most {fit} outputs, or" if fit >= 2
              else "; not even the start and the end fit:")
    size = (f"{n_outputs:.4g} outputs of {n_bodies} bodies would take "
            f"{beyond_limit(states + matrices, limit)} (half this machine's memory, at "
            f"least 1 GiB)")
    if stm and states <= limit:  # (the STM's rows take the outputs beyond it)
        raise ValueError(
            f"Expected the STM's outputs (`stm` = True) to fit in memory: {size} with "
            f"the STM ({6 * n_bodies} x {6 * n_bodies} an output, kept {_times(copies)})"
            f"{advice} "
            f"fewer bodies, or stm=False (MEGNO and the Lyapunov exponent need no STM)")
    raise ValueError(f"Expected `t` to ask for outputs that fit in memory: {size} for the "
                     f"positions and velocities{' and the STM' if stm else ''}{advice} "
                     f"fewer bodies (an end time alone keeps two outputs)")
