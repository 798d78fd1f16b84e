"""An archive's snapshot written from inside a compiled run (radau15's
``every_steps`` schedule), without returning to Python.

The record is the one :meth:`hamilton_orbits.segment.SegmentWriter.refill` appends
at a pause between two steps (``docs/archive.md``): its float64 part (``t``, ``r``,
``v``, ``gm``, the integrator's state, the state's numbers, ``steps``, ``leg``,
``leg_span``, ``rows``) big-endian, then ``active`` (int8, padded), then ``check``,
the CRC-32 of the bytes before it as a big-endian float64.  It is appended as the
Python writer appends it: the record after the last one, then the count of
records in the header (each by ``pwrite``, called through its address: the kernels
stay cached), so the count never runs ahead of a record and a kill loses at most
the snapshot being written.

What changes from one snapshot to the next is named by a *plan*: rows
``(place, source, length)``, ``place`` in the float64 part, ``source`` one of the
``SRC_*`` codes (the run's arrays and numbers); everything else was filled once,
from the record Python wrote last (``template``: the float64 part, native; ``rec``:
the whole record's bytes, ``active`` included).

The CRC-32 is that of zlib and the netCDF writer (the reflected polynomial
0xEDB88320; ISO 3309, ITU-T V.42), by eight tables of 256 entries, eight bytes a
round ("slicing-by-8": Kounavis & Berry 2005, "A systematic approach to building
high performance software-based CRC generators").
"""

from __future__ import annotations

import ctypes
import functools

import numpy as np
from numba import njit, types

from hamilton_orbits._kernels.signatures import function_at

#: where a netCDF-3 file keeps its number of records (big-endian int32)
NUMRECS_AT = 4

__all__ = ["CRC_TABLES", "IO_SIZE", "PWRITE_TYPE", "SRC_BR", "SRC_CSV", "SRC_CSX", "SRC_D",
           "SRC_DRIVER_STEPS", "SRC_GM", "SRC_P", "SRC_ST", "SRC_STEPS", "SRC_T", "SRC_V",
           "SRC_X", "crc32", "pwrite_address", "write_snapshot"]

#: the sources of a plan's row: the run's positions, velocities, ``G m``, the last
#: step's ``br`` and ``d``, the Kahan compensations, the state ``st`` and the
#: parameters ``p`` (arrays, flattened); its time, the driver's step count and the
#: propagation's (numbers)
SRC_X, SRC_V, SRC_GM, SRC_BR, SRC_D, SRC_CSX, SRC_CSV, SRC_ST, SRC_P = range(9)
SRC_T, SRC_DRIVER_STEPS, SRC_STEPS = 9, 10, 11

#: ``io``, the numbers the kernel and Python share: the steps between snapshots,
#: the run's step (counted in this call) of the next one, the file's descriptor,
#: where the next record goes, the records in the file, the snapshots written in
#: this call, the address of ``pwrite``, the driver's and the propagation's step
#: counts before this call, the run's step of the last snapshot written
(IO_EVERY, IO_NEXT, IO_FD, IO_END, IO_COUNT, IO_WRITTEN, IO_PWRITE, IO_DRIVER0, IO_STEPS0,
 IO_LAST) = range(10)
IO_SIZE = 10

#: ``ssize_t pwrite(int fd, const void *buf, size_t count, off_t offset)``
PWRITE_TYPE = types.FunctionType(types.intp(types.intp, types.intp, types.intp, types.intp))
_pwrite_at = function_at(PWRITE_TYPE)


@functools.lru_cache(maxsize=1)
def pwrite_address() -> int | None:
    """The address of the C library's ``pwrite`` (None where there is none: the
    snapshots are then written by Python)."""
    try:
        return ctypes.cast(ctypes.CDLL(None).pwrite, ctypes.c_void_p).value
    except (AttributeError, OSError, TypeError):  # pragma: no cover - no such libc
        return None


def _crc_tables() -> np.ndarray:
    """The eight tables of slicing-by-8 for the reflected CRC-32 polynomial."""
    out = np.zeros((8, 256), np.uint32)
    for i in range(256):
        c = i
        for _ in range(8):
            c = (c >> 1) ^ 0xEDB88320 if c & 1 else c >> 1
        out[0, i] = c
    for k in range(1, 8):
        out[k] = (out[k - 1] >> 8) ^ out[0, out[k - 1] & 0xFF]
    return out


#: the tables of :func:`crc32`
CRC_TABLES = _crc_tables()


@njit(cache=True)
def crc32(buf, n, tab):  # pragma: no cover - compiled
    """The CRC-32 of ``buf[:n]`` (bytes), as :func:`zlib.crc32` gives it.

    Examples
    --------
    >>> import zlib
    >>> data = np.frombuffer(b"hamilton-orbits archive segment", np.uint8)
    >>> int(crc32(data, data.size, CRC_TABLES)) == zlib.crc32(data.tobytes())
    True
    """
    c = np.uint32(0xFFFFFFFF)
    i = 0
    while i + 8 <= n:
        c ^= (np.uint32(buf[i]) | (np.uint32(buf[i + 1]) << 8) | (np.uint32(buf[i + 2]) << 16)
              | (np.uint32(buf[i + 3]) << 24))
        c = (tab[7, c & 0xFF] ^ tab[6, (c >> 8) & 0xFF] ^ tab[5, (c >> 16) & 0xFF]
             ^ tab[4, c >> 24] ^ tab[3, buf[i + 4]] ^ tab[2, buf[i + 5]] ^ tab[1, buf[i + 6]]
             ^ tab[0, buf[i + 7]])
        i += 8
    while i < n:
        c = tab[0, (c ^ buf[i]) & 0xFF] ^ (c >> 8)
        i += 1
    return c ^ np.uint32(0xFFFFFFFF)


@njit(cache=True, inline="always")
def _big_endian(x):  # pragma: no cover - compiled
    """The bytes of ``x`` (uint64) reversed (compiled to one byte swap)."""
    return (((x & 0xFF) << 56) | ((x & 0xFF00) << 40) | ((x & 0xFF0000) << 24)
            | ((x & 0xFF000000) << 8) | ((x >> 8) & 0xFF000000) | ((x >> 24) & 0xFF0000)
            | ((x >> 40) & 0xFF00) | (x >> 56))


@njit(cache=True, inline="always")
def _put(tpl, at, a):  # pragma: no cover - compiled
    for k in range(a.size):
        tpl[at + k] = a[k]


@njit(cache=True)
def _pwrite_all(io, buf, size, at):  # pragma: no cover - compiled
    """``buf[:size]`` written at offset ``at`` of the file ``io`` names (a write may
    take part of it); False when the file refuses it."""
    pwrite = _pwrite_at(io[IO_PWRITE], 0)
    done = 0
    while done < size:
        n = pwrite(io[IO_FD], np.intp(buf.ctypes.data) + done, size - done, at + done)
        if n <= 0:
            return False
        done += n
    return True


@njit(cache=True)
def write_snapshot(arch, r, v, gm, st, br, d, csx, csv, p, steps,
                   t_slot):  # pragma: no cover - compiled
    """Append the snapshot of the run at its ``steps``-th step of this call (``st``
    saved: its time in ``st[t_slot]``) to the segment ``arch`` describes
    (``(plan, template, rec, io, tables)``, see the module notes); False,
    nothing counted, when the file refuses the record (Python writes it again,
    which says why)."""
    plan, tpl, rec, io, tab = arch
    for k in range(plan.shape[0]):
        at, src = plan[k, 0], plan[k, 1]
        if src == SRC_X:
            _put(tpl, at, r.reshape(r.size))
        elif src == SRC_V:
            _put(tpl, at, v.reshape(v.size))
        elif src == SRC_GM:
            _put(tpl, at, gm)
        elif src == SRC_BR:
            _put(tpl, at, br.reshape(br.size))
        elif src == SRC_D:
            _put(tpl, at, d.reshape(d.size))
        elif src == SRC_CSX:
            _put(tpl, at, csx)
        elif src == SRC_CSV:
            _put(tpl, at, csv)
        elif src == SRC_ST:
            _put(tpl, at, st)
        elif src == SRC_P:
            _put(tpl, at, p)
        elif src == SRC_T:
            tpl[at] = st[t_slot]
        elif src == SRC_DRIVER_STEPS:
            tpl[at] = float(io[IO_DRIVER0] + steps)
        else:  # SRC_STEPS
            tpl[at] = float(io[IO_STEPS0] + steps)
    words = rec[:8 * tpl.size].view(np.uint64)
    bits = tpl.view(np.uint64)
    for k in range(tpl.size):
        words[k] = _big_endian(bits[k])
    size = rec.size
    check = _big_endian(np.array([float(crc32(rec, size - 8, tab))]).view(np.uint64)[0])
    for k in range(8):
        rec[size - 8 + k] = (check >> (8 * k)) & 0xFF
    if not _pwrite_all(io, rec, size, io[IO_END]):
        return False
    n_records = io[IO_COUNT] + 1  # (after the record: the count never runs ahead)
    count = np.empty(4, np.uint8)
    for k in range(4):
        count[k] = (n_records >> (8 * (3 - k))) & 0xFF
    if not _pwrite_all(io, count, 4, NUMRECS_AT):
        return False
    io[IO_COUNT] = n_records
    io[IO_END] += size
    io[IO_WRITTEN] += 1
    io[IO_LAST] = steps
    io[IO_NEXT] += io[IO_EVERY]
    return True
