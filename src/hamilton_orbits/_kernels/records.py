"""An archive record written from inside a stepping kernel, between two of its steps.

An archive's ``every_steps`` snapshot of a radau15 run without events used to end
the compiled call at the snapshot, refill the record in Python and write it: about
0.1 ms a snapshot on a busy machine (the interpreter's caches cold after the
steps), 5-6% of the 100 steps of ten bodies between two snapshots.  Once the
Python path has written two such snapshots in a row (so that it is known which of
the record's values the steps change, and from which of the kernel's arrays:
:meth:`hamilton_orbits.segment.SegmentWriter.compiled_plan`), the kernel writes the
next ones itself: it puts those values into the record (the rest of it, the same
from one snapshot to the next, stays as the Python path left it), computes the
record's CRC-32 and appends it with ``pwrite``, then writes the segment's count of
records, in that order (the order the Python path keeps: a process killed between
the two loses that snapshot, never reads a torn one).  ``pwrite`` and the CRC-32
are the C library's and zlib's own functions, called at their addresses
(:func:`c_functions`).  An ``every`` snapshot (a simulation time) is written the
same way: the kernel, given the snapshot times up to the next output, lands on
each as a call ending there would have, and writes its record there, where the
Python path ended the call, wrote the snapshot and called again (40-100 us a
snapshot).

The plan (an int64 array) holds, from :data:`P_RUNS` on, runs of four integers:
the source (its number in :data:`SOURCES`), the first element read, the record's
float64 slot written first (the record's float64 values come first), the length.
A source ``SRC_STEPS`` is the kernel's count of steps: the value written is the
run's "first element" plus :data:`P_BASE` plus the steps of the call (a step count
the record holds).  An ``every`` schedule's snapshot times follow the runs (each
float64's bits as an int64, from ``plan[P_LAND]``, the next, to
``plan[P_LAND_END]``): the kernel lands on each by its own step control, as a call
ending there would, and writes its record there.

A ``pwrite`` that fails (a full disk) writes nothing more: the kernel stops at the
snapshot with :data:`P_FAILED` set, and the Python path writes it again, which
meets the failure and says why.
"""

from __future__ import annotations

import ctypes
import functools
import sys

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

from hamilton_orbits._kernels.signatures import function_at
from hamilton_orbits._netcdf3 import NUMRECS_AT

__all__ = ["P_ADDRESSES", "P_BASE", "P_COUNT", "P_CRC", "P_END", "P_EVERY",
           "P_FAILED", "P_FD", "P_LAND", "P_LAND_END", "P_LAST", "P_NEXT", "P_PWRITE",
           "P_REC", "P_RUNS", "P_SIZE", "P_WRITER", "P_WRITTEN", "RECORD_SIGNATURE", "SOURCES",
           "SRC_STEPS", "c_functions", "next_landing", "record_at", "write_record"]

#: the plan's entries: the snapshot interval in steps (0: none), the steps of the call
#: at which the next is due, the file's descriptor, where the next record goes (its
#: bytes written so far), the records counted in the file, the addresses of
#: ``pwrite`` and of zlib's ``crc32``, the records written by the call, the step (of
#: the call) of the last, a failed write (1), the step count at the call's start, the
#: number of runs, the address and size of the record's buffer (its float64 values
#: first), 8 bytes of working space, where the next snapshot time to land on is kept
#: and where those times end (:func:`next_landing`), and the addresses of :func:`write_record`
#: (:data:`RECORD_SIGNATURE`; two: its C wrapper and entry point, as a right-hand
#: side's, :mod:`hamilton_orbits._kernels.signatures`)
(P_EVERY, P_NEXT, P_FD, P_END, P_COUNT, P_PWRITE, P_CRC, P_WRITTEN, P_LAST, P_FAILED, P_BASE,
 P_NRUNS, P_REC, P_SIZE, P_SCRATCH, P_LAND, P_LAND_END, P_WRITER) = range(18)
#: the kernel's arrays a record's values are read from, by number (their addresses
#: from :data:`P_ADDRESSES` on: C-contiguous float64 arrays the plan's holder keeps)
SOURCES = ("r", "v", "gm", "p", "st", "br", "d", "csx", "csv")
SRC_STEPS = len(SOURCES)
P_ADDRESSES = P_WRITER + 2
#: where the runs begin
P_RUNS = P_ADDRESSES + len(SOURCES)

#: ``ssize_t pwrite(int fd, const void *buf, size_t count, off_t offset)``
_PWRITE = function_at(types.FunctionType(types.int64(types.int64, types.int64, types.int64,
                                                     types.int64)))
#: ``uLong crc32(uLong crc, const Bytef *buf, uInt len)``
_CRC32 = function_at(types.FunctionType(types.int64(types.int64, types.int64, types.int64)))

#: ``write_record(plan, steps) -> bool``: a stepping kernel calls it at its
#: addresses (:func:`record_at`), so that it is compiled only where an archive is
#: written, not into the kernel (where it added a second to a first run)
RECORD_SIGNATURE = types.boolean(types.int64[::1], types.int64)
#: ``record_at(c_addr, jit_addr)``: :func:`write_record` at those addresses
record_at = function_at(types.FunctionType(RECORD_SIGNATURE))


@functools.cache
def c_functions() -> tuple[int, int]:
    """The addresses of the C library's ``pwrite`` and of zlib's ``crc32`` (the CRC
    of :func:`zlib.crc32`), found once; ``(0, 0)`` where either is missing (the
    Python path then writes every record)."""
    if sys.platform == "win32":
        return 0, 0
    names = ("libz.dylib",) if sys.platform == "darwin" else ("libz.so.1", "libz.so")
    try:
        pwrite = ctypes.cast(ctypes.CDLL(None).pwrite, ctypes.c_void_p).value or 0
    except (OSError, AttributeError):
        return 0, 0
    for name in names:
        try:
            crc = ctypes.cast(ctypes.CDLL(name).crc32, ctypes.c_void_p).value or 0
        except (OSError, AttributeError):
            continue
        return (int(pwrite), int(crc)) if pwrite and crc else (0, 0)
    return 0, 0


@intrinsic
def _load(typingctx, address):  # pragma: no cover - compiled
    """The 8 bytes at ``address`` (int64) as a uint64."""
    def codegen(context, builder, signature, args):
        ptr = builder.inttoptr(args[0], ir.PointerType(ir.IntType(64)))
        return builder.load(ptr, align=1)
    return types.uint64(types.int64), codegen


@intrinsic
def _store(typingctx, address, value):  # pragma: no cover - compiled
    """``value`` (uint64) as the 8 bytes at ``address`` (int64)."""
    def codegen(context, builder, signature, args):
        ptr = builder.inttoptr(args[0], ir.PointerType(ir.IntType(64)))
        builder.store(args[1], ptr, align=1)
        return context.get_dummy_value()
    return types.void(types.int64, types.uint64), codegen


@intrinsic
def _bits(typingctx, x):  # pragma: no cover - compiled
    """The bits of ``x`` (float64) as a uint64."""
    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.IntType(64))
    return types.uint64(types.float64), codegen


@intrinsic
def _float(typingctx, bits):  # pragma: no cover - compiled
    """The float64 whose bits are ``bits`` (int64)."""
    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.DoubleType())
    return types.float64(types.int64), codegen


@njit(cache=True, inline="always")
def next_landing(plan, t_end):  # pragma: no cover - compiled
    """The next snapshot time the kernel lands on (the float64 whose bits are
    ``plan[plan[P_LAND]]``, the times being kept from there to ``plan[P_LAND_END]``:
    an ``every`` schedule's), or ``t_end`` where none is left."""
    k = plan[P_LAND]
    return _float(plan[k]) if k < plan[P_LAND_END] else t_end


@njit(cache=True)
def _swapped(x):  # pragma: no cover - compiled
    """The 8 bytes of ``x`` (uint64) in the other order."""
    y = np.uint64(0)
    for _ in range(8):
        y = (y << np.uint64(8)) | (x & np.uint64(0xFF))
        x >>= np.uint64(8)
    return y


@njit(cache=True)
def _written(plan, address, n, at):  # pragma: no cover - compiled
    """``n`` bytes from ``address`` written at offset ``at`` of the plan's file
    (``pwrite``, again for the rest where it took part); False where it fails."""
    write = _PWRITE(plan[P_PWRITE], 0)
    done = 0
    while done < n:
        k = write(plan[P_FD], address + done, n - done, at + done)
        if k <= 0:
            return False
        done += k
    return True


@njit(cache=True)
def write_record(plan, steps):  # pragma: no cover - compiled
    """Append the record of the state after ``steps`` steps of the call: its values
    filled from the kernel's arrays (at the plan's addresses, :data:`P_ADDRESSES`),
    its CRC-32 in its last eight bytes, written after the last record, then counted
    in the file's header.  False, nothing counted, where a write fails
    (:data:`P_FAILED` set)."""
    out, n = plan[P_REC], plan[P_SIZE]
    for k in range(plan[P_NRUNS]):
        at = P_RUNS + 4 * k
        src, first, slot, length = plan[at], plan[at + 1], plan[at + 2], plan[at + 3]
        if src == SRC_STEPS:
            _store(out + 8 * slot, _swapped(_bits(float(first + plan[P_BASE] + steps))))
            continue
        a = plan[P_ADDRESSES + src] + 8 * first
        for j in range(length):
            _store(out + 8 * (slot + j), _swapped(_load(a + 8 * j)))
    crc = _CRC32(plan[P_CRC], 0)(0, out, n - 8)
    _store(out + n - 8, _swapped(_bits(float(crc))))  # (the check: a big-endian float64)
    count = plan[P_COUNT] + 1
    scratch = np.int64(plan.ctypes.data) + 8 * P_SCRATCH
    _store(scratch, _swapped(np.uint64(count)) >> np.uint64(32))  # (4 bytes big-endian)
    if not (_written(plan, out, n, plan[P_END]) and _written(plan, scratch, 4, NUMRECS_AT)):
        plan[P_FAILED] = 1
        return False
    plan[P_END] += n
    plan[P_COUNT] = count
    plan[P_WRITTEN] += 1
    plan[P_LAST] = steps
    return True
