"""One snapshot file: a self-describing netCDF file, written whole or not at all.

A snapshot holds a simulation's state readable by any netCDF reader (``t``,
``r``, ``v``, ``gm`` and the body names, float64 stored exactly, with units) and
what this package needs to continue it bit for bit: the specification (system at
time 0, method and options, effects, events, variational equations) and the
integrator's own state, as JSON in the global attribute ``meta`` and arrays
``state_K``.  ``docs/archive.md`` says why the format is netCDF-3 (64-bit
offset).  This is a snapshot saved alone (``Simulation.save``), and each snapshot
of an archive of format 1; an archive now appends its snapshots to segments
(:mod:`hamilton_orbits.segment`).

Writing is atomic: the file is written under a temporary name in the same folder,
flushed, synced and renamed over its final name, so a process killed at any moment
leaves either the whole snapshot or none (and at most a temporary file, which
:func:`read` never takes for a snapshot).  A SHA-256 of the contents (the
``meta`` text and every variable's name, type, shape and bytes) is stored in the
global attribute ``sha256`` and checked on reading: a truncated file, a flipped
byte or another program's file is a :class:`SnapshotError` naming the path, never
data.

Examples
--------
>>> import tempfile, os
>>> with tempfile.TemporaryDirectory() as tmp:
...     path = os.path.join(tmp, "one.nc")
...     write(path, {"kind": "demo"}, {"r": np.arange(6.0).reshape(2, 3)},
...           dims={"r": ("body", "xyz")})
...     meta, arrays = read(path)
...     meta["kind"], arrays["r"].tolist()
('demo', [[0.0, 1.0, 2.0], [3.0, 4.0, 5.0]])
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from hamilton_orbits._netcdf3 import encode
from hamilton_orbits.integrators._held import held

__all__ = ["FORMAT", "FORMAT_VERSION", "INT_EXACT", "SnapshotError", "beyond_float", "checksum",
           "encode_snapshot", "read", "stored", "strict_json", "variable", "write",
           "write_bytes"]

FORMAT = "hamilton-orbits snapshot"
#: the version of the layout of a snapshot file; every later version reads every
#: earlier one (tests/hamilton_orbits/data/snapshot-v1.nc, -v2.nc).  Format 2: the
#: ``meta`` text is strict JSON, a float JSON has no number for written as
#: ``{"$float": "inf"}`` (format 1 wrote a bare ``Infinity``, which Python's json
#: reads and a strict reader refuses: dop853's ``max_step``)
FORMAT_VERSION = 2
#: the key of a float JSON has no number for (inf, -inf, nan) in a ``meta`` text
NONFINITE = "$float"
#: integers a float64 holds exactly are below this in magnitude
INT_EXACT = 2 ** 53


def beyond_float(a: np.ndarray) -> bool:
    """Whether integer array ``a`` holds a value a float64 would not hold exactly
    (False for other kinds).

    Examples
    --------
    >>> beyond_float(np.array([2**53 - 1])), beyond_float(np.array([-2**53]))
    (False, True)
    """
    return a.dtype.kind in "iu" and bool(a.size) and max(
        map(abs, a.ravel().tolist()) if a.size < 64 else (-int(a.min()), int(a.max()))
    ) >= INT_EXACT


class SnapshotError(ValueError):
    """A snapshot file that cannot be read or written (the message names the path)."""


def _canonical(arr: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(arr, dtype=arr.dtype.newbyteorder("<"))


def checksum(meta_text: str, arrays: Mapping[str, np.ndarray]) -> str:
    """The SHA-256 of a snapshot's contents (see the module notes)."""
    h = hashlib.sha256(meta_text.encode("utf-8"))
    for name in sorted(arrays):
        a = _canonical(np.asarray(arrays[name]))
        h.update(f"\0{name}\0{a.dtype.str}\0{a.shape}\0".encode())
        h.update(a.tobytes())
    return h.hexdigest()


#: the names of the common dtypes (``dtype.name`` builds its string at each call)
_DTYPE_NAMES = {np.dtype(k): np.dtype(k).name for k in (np.float64, np.bool_, np.int8,
                                                       np.int32, np.int64)}


def stored(name: str, arr: np.ndarray) -> tuple[np.ndarray, str]:
    """The array as netCDF-3 stores it (float64, int32 or int8) and its dtype."""
    kind = _DTYPE_NAMES.get(arr.dtype) or arr.dtype.name
    if arr.dtype == np.float64:
        return arr, kind
    if arr.dtype == np.bool_:
        return arr.astype(np.int8), kind
    if arr.dtype == np.int8:
        return arr, kind
    if arr.dtype.kind in "iu":
        if arr.size and np.max(np.abs(arr.astype(np.float64))) >= INT_EXACT:
            raise SnapshotError(f"array {name!r}: integers beyond 2**53 cannot be stored")
        return arr.astype(np.float64), kind
    raise SnapshotError(f"array {name!r}: dtype {arr.dtype} cannot be stored")


def write(path: str | os.PathLike[str], meta: Mapping[str, Any],
          arrays: Mapping[str, np.ndarray], dims: Mapping[str, tuple[str, ...]] | None = None,
          units: Mapping[str, str] | None = None, *, sync: bool = True) -> None:
    """Write a snapshot atomically (see the module notes).

    Parameters
    ----------
    path : path
        The file (replaced if it exists).
    meta : mapping
        JSON-able metadata (floats round-trip exactly).
    arrays : mapping of str to ndarray
        float64, integer (below 2**53) or bool arrays.
    dims, units : mapping, optional
        Dimension names and a ``units`` attribute of some arrays (for readers
        without this package); other arrays get dimensions by their lengths.
    sync : bool
        ``os.fsync`` the file before the rename (survives a power cut, not only a
        killed process).

    Raises
    ------
    SnapshotError
        When the folder cannot be written (a read-only folder, a full disk),
        naming the path.
    """
    write_bytes(path, encode_snapshot(meta, arrays, dims, units), sync=sync)


def encode_snapshot(meta: Mapping[str, Any], arrays: Mapping[str, np.ndarray],
                    dims: Mapping[str, tuple[str, ...]] | None = None,
                    units: Mapping[str, str] | None = None) -> bytes:
    """The bytes of a snapshot file (see :func:`write`): a copy, so the arrays may
    change as soon as it returns."""
    dims, units = dims or {}, units or {}
    meta_text = strict_json(meta)
    variables = [variable(name, np.asarray(value), dims.get(name), units.get(name))
                 for name, value in arrays.items()]
    return encode({"format": FORMAT, "format_version": FORMAT_VERSION, "meta": meta_text,
                   "sha256": checksum(meta_text, arrays)}, variables)


@held
def write_bytes(path: str | os.PathLike[str], data: bytes, *, sync: bool = True,
                keep_open: bool = False) -> int | None:
    """Write ``data`` to ``path`` atomically: under a temporary name in the same
    folder, then renamed over ``path`` (see :func:`write`).  ``keep_open``: return
    the file's descriptor, open for reading and writing (a segment appended to
    next), instead of closing it."""
    folder, name = os.path.split(os.fspath(path))
    # (a name of 255 bytes is legal: the temporary one made of it kept within that)
    tmp = os.path.join(folder, f".{name[:200]}.tmp-{os.getpid()}")
    fd = -1
    try:
        fd = os.open(tmp, os.O_RDWR | os.O_CREAT | os.O_TRUNC, 0o666)
        view = memoryview(data)
        while view:  # (a write may take part of it)
            view = view[os.write(fd, view):]
        if sync:
            os.fsync(fd)
        os.replace(tmp, os.fspath(path))
    except OSError as exc:
        if fd >= 0:
            os.close(fd)
        try:
            os.unlink(tmp)
        except OSError:  # (none made: its folder is not one, or the name too long)
            pass
        raise SnapshotError(f"cannot write the snapshot {path}: "
                            f"{exc.strerror or exc}") from None
    if keep_open:
        return fd
    os.close(fd)
    return None


def variable(name: str, arr: np.ndarray, dims: tuple[str, ...] | None,
              unit: str | None) -> tuple[str, tuple[str, ...], np.ndarray, dict[str, Any]]:
    """A variable of a netCDF file: its dimensions, stored values and attributes
    (``dtype_saved``; an empty array as a marker with its ``empty_shape``)."""
    data, kind = stored(name, arr)
    attrs: dict[str, Any] = {"dtype_saved": kind}
    if arr.size == 0:  # netCDF-3 has no empty fixed dimension: a marker and the shape
        attrs["empty_shape"] = ",".join(str(k) for k in arr.shape) or "0"
        return name, (), np.zeros((), np.int8), attrs
    if unit is not None:
        attrs["units"] = unit
    return name, dims or tuple(f"n{k}" for k in arr.shape), data, attrs


def _array(var: Any) -> np.ndarray:
    kind = var.dtype_saved.decode() if isinstance(var.dtype_saved, bytes) else var.dtype_saved
    shape_attr = getattr(var, "empty_shape", None)
    if shape_attr is not None:
        text = shape_attr.decode() if isinstance(shape_attr, bytes) else shape_attr
        return np.zeros(tuple(int(k) for k in text.split(",")), dtype=kind)
    return np.array(var[...], dtype=kind)


def read(path: str | os.PathLike[str]) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    """The ``meta`` and arrays of a snapshot, its checksum verified.

    Raises
    ------
    SnapshotError
        For a missing, truncated, corrupted or foreign file, naming the path.
    """
    from scipy.io import netcdf_file

    path = Path(path)
    if not path.is_file():
        raise SnapshotError(f"no snapshot file {path}")
    try:
        with netcdf_file(path, "r", mmap=False) as nc:
            fmt = getattr(nc, "format", b"")
            fmt = fmt.decode() if isinstance(fmt, bytes) else fmt
            if fmt != FORMAT:
                hint = ""
                if fmt.startswith("hamilton-orbits archive segment"):  # (segment.SEGMENT_FORMAT)
                    hint = (f"; it is a file of the archive {path.parent}: load the folder "
                            f"instead, Simulation.load({str(path.parent)!r}) (its last "
                            f"snapshot; number=n for another)")
                raise SnapshotError(f"{path} is not a hamilton-orbits snapshot "
                                    f"(format {fmt!r}){hint}")
            version = int(nc.format_version)
            meta_text = nc.meta.decode("utf-8")
            stored = nc.sha256.decode()
            arrays = {name: _array(var) for name, var in nc.variables.items()}
    except SnapshotError:
        raise
    except Exception as exc:  # scipy's parser: any damage surfaces as some error
        raise SnapshotError(f"{path} cannot be read as a snapshot (damaged or not a "
                            f"netCDF file: {type(exc).__name__}: {exc})") from None
    if version > FORMAT_VERSION:
        raise SnapshotError(f"{path} has format version {version}; this version of "
                            f"hamilton-orbits reads up to {FORMAT_VERSION}")
    if checksum(meta_text, arrays) != stored:
        raise SnapshotError(f"{path} is corrupted: its checksum does not match its "
                            f"contents")
    try:
        meta = json.loads(meta_text, object_hook=_untagged if version >= 2 else None)
    except ValueError as exc:  # (a tag that is not a float's: never written by us)
        raise SnapshotError(f"{path} cannot be read as a snapshot ({exc})") from None
    return meta, arrays


def strict_json(meta: Any) -> str:
    """``meta`` as strict JSON text (keys sorted): a float JSON has no number for as
    ``{"$float": "inf"}`` (``"-inf"``, ``"nan"``), read back by :func:`read`.

    Examples
    --------
    >>> strict_json({"max_step": float("inf"), "dt": 0.5})
    '{"dt": 0.5, "max_step": {"$float": "inf"}}'
    """
    try:
        return json.dumps(meta, sort_keys=True, allow_nan=False)
    except ValueError:  # (a float out of JSON's range: tagged, the rest as it was)
        return json.dumps(_tagged(meta), sort_keys=True, allow_nan=False)


def _tagged(x: Any) -> Any:
    if isinstance(x, float) and not math.isfinite(x):
        return {NONFINITE: repr(float(x))}
    if isinstance(x, dict):
        return {k: _tagged(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_tagged(v) for v in x]
    return x


def _untagged(obj: dict[str, Any]) -> Any:
    """A JSON object read back: a tagged float as that float."""
    if len(obj) == 1 and isinstance(obj.get(NONFINITE), str):
        return float(obj[NONFINITE])
    return obj
