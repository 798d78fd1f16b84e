"""The bytes of a netCDF-3 file (64-bit offset format, "CDF-2"), and its header read.

The classic format (Unidata, "The NetCDF Classic Format Specification", netCDF
User's Guide, appendix "File Format Specifications") is a header (the number of
records, dimensions, global attributes, variables with their attributes, types,
sizes and offsets) followed by each fixed-size variable's values, then the
records: record ``k`` holds every record variable's values at index ``k`` of the
unlimited dimension, one after the other, big-endian, each padded to four bytes.

:func:`encode` builds a whole file (the header, the fixed variables, no record
yet) as one ``bytes`` with :mod:`struct` and ``ndarray.tobytes``: a tenth of the
time of a general writer; :func:`record` the bytes of one record, to append;
:data:`NUMRECS_AT` is where the number of records is kept, to update after an
append; :func:`parse` reads a header back.  Any netCDF reader reads the files (the
tests read them with ``scipy.io.netcdf_file`` and xarray).

Examples
--------
>>> import io
>>> from scipy.io import netcdf_file
>>> data = encode({"title": "demo"}, [("r", ("body", "xyz"), np.eye(2, 3), {"units": "au"})])
>>> with netcdf_file(io.BytesIO(data), "r", mmap=False) as nc:
...     nc.title, nc.variables["r"][:].tolist(), nc.variables["r"].units
(b'demo', [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], b'au')
"""

from __future__ import annotations

import functools
import math
import struct
from collections.abc import Mapping, Sequence
from typing import Any, NamedTuple

import numpy as np

__all__ = ["NUMRECS_AT", "Header", "Parts", "RecordBuffer", "Variable", "encode", "parse",
           "record"]

_ABSENT = b"\0" * 8
_DIMENSION, _VARIABLE, _ATTRIBUTE = 10, 11, 12
_TYPES = {np.dtype(np.int8): 1, np.dtype(np.int32): 4, np.dtype(np.float64): 6}
_DTYPES = {1: np.dtype(">i1"), 2: np.dtype("S1"), 4: np.dtype(">i4"), 6: np.dtype(">f8")}
#: the offset of the number of records (a big-endian int32) in the file
NUMRECS_AT = 4


def _pad(n: int) -> int:
    return -n % 4


def _name(text: str) -> bytes:
    raw = text.encode("utf-8")
    return struct.pack(">i", len(raw)) + raw + b"\0" * _pad(len(raw))


def _attributes(attrs: Mapping[str, Any]) -> bytes:
    if not attrs:
        return _ABSENT
    out = [struct.pack(">ii", _ATTRIBUTE, len(attrs))]
    for key, value in attrs.items():
        if isinstance(value, str):
            raw = value.encode("utf-8")
            out.append(_name(key) + struct.pack(">ii", 2, len(raw)) + raw + b"\0" * _pad(len(raw)))
        else:
            out.append(_name(key) + struct.pack(">iii", 4, 1, int(value)))
    return b"".join(out)


def encode(global_attrs: Mapping[str, Any],
           variables: Sequence[tuple[str, tuple[str, ...], np.ndarray, Mapping[str, Any]]],
           records: Sequence[tuple[str, tuple[str, ...], np.ndarray, Mapping[str, Any]]] = (),
           record_dim: str = "record") -> bytes:
    """The file of ``variables`` — ``(name, dimension names, values, attributes)``,
    values float64, int32 or int8, each dimension name one length throughout — and
    the global attributes (str or int), with no record yet.

    ``records``: the record variables, each given as the values of one record (the
    dimensions after ``record_dim``, the unlimited dimension); append records with
    :func:`record` and count them at :data:`NUMRECS_AT`.  Give two or more: with
    one, the format packs its records without padding.
    """
    if len(records) == 1:
        raise ValueError("give two or more record variables (or none)")
    dims: dict[str, int] = {record_dim: 0} if records else {}
    for name, names, values, _ in (*variables, *records):
        if values.dtype not in _TYPES or len(names) != values.ndim:
            raise ValueError(f"variable {name!r}: {values.dtype} with dimensions {names}")
        for dim, k in zip(names, values.shape, strict=True):
            if dims.setdefault(dim, k) != k or k == 0:
                raise ValueError(f"dimension {dim!r}: lengths {dims[dim]} and {k}")
    ids = {dim: k for k, dim in enumerate(dims)}
    head = [b"CDF\x02", struct.pack(">i", 0)]
    head.append(b"".join([struct.pack(">ii", _DIMENSION, len(dims))]
                         + [_name(d) + struct.pack(">i", k) for d, k in dims.items()])
                if dims else _ABSENT)
    head.append(_attributes(global_attrs))
    blocks, sizes = [], []
    for name, names, values, attrs in variables:
        data = _bytes(values)
        sizes.append(len(data))
        blocks.append(data)
        head.append(_entry(name, [ids[d] for d in names], values, attrs, len(data)))
    for name, names, values, attrs in records:
        n = values.size * values.dtype.itemsize
        sizes.append(n + _pad(n))
        head.append(_entry(name, [ids[record_dim]] + [ids[d] for d in names], values, attrs,
                           sizes[-1]))
    count = len(variables) + len(records)
    var_head = struct.pack(">ii", _VARIABLE, count) if count else _ABSENT
    begin = sum(map(len, head)) + len(var_head) + 8 * count
    offsets = []
    for size in sizes:  # the fixed variables, then the parts of a record
        offsets.append(struct.pack(">q", begin))
        begin += size
    parts = head[:4] + [var_head] + [h + o for h, o in zip(head[4:], offsets, strict=True)]
    return b"".join(parts + blocks)


def _bytes(values: np.ndarray) -> bytes:
    """The values big-endian, padded to four bytes."""
    data = np.ascontiguousarray(values, dtype=values.dtype.newbyteorder(">")).tobytes()
    return data + b"\0" * _pad(len(data))


def _entry(name: str, dim_ids: list[int], values: np.ndarray, attrs: Mapping[str, Any],
           size: int) -> bytes:
    """A variable's header entry, without its offset (the same variables' entries
    are made once: an archive writes a header of the same variables per segment)."""
    key = (name, tuple(dim_ids), _TYPES[values.dtype], tuple(attrs.items()), size)
    try:
        return _entry_of(*key)
    except TypeError:  # (an attribute that is not hashable: made afresh)
        return _entry_of.__wrapped__(*key)


@functools.lru_cache(maxsize=512)
def _entry_of(name: str, dim_ids: tuple[int, ...], kind: int,
              attrs: tuple[tuple[str, Any], ...], size: int) -> bytes:
    return (_name(name) + struct.pack(f">i{len(dim_ids)}i", len(dim_ids), *dim_ids)
            + _attributes(dict(attrs)) + struct.pack(">ii", kind, size))


def record(values: Sequence[np.ndarray]) -> bytes:
    """The bytes of one record: the record variables' values in the order given to
    :func:`encode`, each padded to four bytes."""
    return b"".join(_bytes(v) for v in values)


class Parts(tuple):
    """A record variable's values given as arrays to be concatenated, flattened, into
    it (:meth:`RecordBuffer.fill`), which saves building the whole first."""

    __slots__ = ()


class RecordBuffer:
    """One record's bytes kept for reuse: :meth:`fill` writes each record variable's
    values into its big-endian view, giving the bytes :func:`record` gives for the
    same values, without building them anew (an archive appends many records of one
    layout).

    Examples
    --------
    >>> like = [np.zeros(2), np.zeros(3, np.int8)]
    >>> buf = RecordBuffer(like)
    >>> values = [np.array([1.5, -2.0]), np.array([1, 0, 1], np.int8)]
    >>> bytes(buf.fill(values)) == record(values)
    True
    >>> bytes(buf.fill([Parts([np.array([1.5]), np.array([-2.0])]), values[1]])) == record(values)
    True
    """

    def __init__(self, like: Sequence[np.ndarray]) -> None:
        sizes = [v.size * v.dtype.itemsize for v in like]
        self.data = bytearray(sum(n + _pad(n) for n in sizes))
        self.views: list[np.ndarray] = []
        starts, at = [], 0
        for v, n in zip(like, sizes, strict=True):
            self.views.append(np.frombuffer(self.data, v.dtype.newbyteorder(">"), v.size,
                                            at).reshape(v.shape))
            starts.append(at)
            at += n + _pad(n)
        #: consecutive float64 variables, each run filled by one concatenation:
        #: (first, end, the run's values as one flat view), or (k, k + 1, None)
        self.runs: list[tuple[int, int, np.ndarray | None]] = []
        k = 0
        while k < len(like):
            end = k
            while end < len(like) and like[end].dtype == np.float64:
                end += 1
            if end - k > 1:
                self.runs.append((k, end, np.frombuffer(self.data, ">f8",
                                                        sum(sizes[k:end]) // 8, starts[k])))
            else:
                end = k + 1
                self.runs.append((k, end, None))
            k = end

    def fill(self, values: Sequence[Any]) -> bytearray:
        """The record of ``values`` (each of its variable's shape, or :class:`Parts`
        of its size, cast to its type).

        Raises
        ------
        ValueError
            When a value's shape (the size of :class:`Parts`) is not its variable's.
        """
        if len(values) != len(self.views):
            raise ValueError(f"{len(values)} values for a record of {len(self.views)}")
        for first, end, flat in self.runs:
            if flat is None and type(values[first]) is not Parts:  # a variable alone
                self.views[first][...] = self._shaped(first, values[first])
                continue
            parts: list[Any] = []
            given = 0  # (Parts in this run: one is checked by the run's size)
            for k in range(first, end):
                x = values[k]
                if type(x) is Parts:
                    given += 1
                    if given > 1:
                        self._sized(k, x)
                    parts += [a.reshape(-1) for a in x]
                else:
                    x = self._shaped(k, x)
                    parts.append(x.reshape(-1) if type(x) is np.ndarray or type(x) is np.float64
                                 else np.ravel(x))
            try:  # (the other values' shapes checked, parts of a wrong size change the run's)
                np.concatenate(parts, out=self.views[first].reshape(-1) if flat is None
                               else flat, casting="unsafe")
            except ValueError:
                for k in range(first, end):
                    if type(values[k]) is Parts:
                        self._sized(k, values[k])
                raise
        return self.data

    def _shaped(self, k: int, x: Any) -> Any:
        """Value ``x`` of variable ``k``, its shape checked."""
        kind = type(x)
        shape = x.shape if kind is np.ndarray or kind is np.float64 else () if (
            kind is float or kind is int) else np.shape(x)
        if shape != self.views[k].shape:
            raise ValueError(f"record variable {k}: shape {shape}, the record holds "
                             f"{self.views[k].shape}")
        return x

    def _sized(self, k: int, x: Parts) -> None:
        """The parts ``x`` of variable ``k``, their size checked."""
        size = sum(a.size for a in x)
        if size != self.views[k].size:
            raise ValueError(f"record variable {k}: parts of {size} values, the record "
                             f"holds {self.views[k].size}")


class Variable(NamedTuple):
    """A variable of a parsed header."""

    shape: tuple[int, ...]  # without the record dimension for a record variable
    dtype: np.dtype
    attrs: dict[str, Any]
    begin: int
    size: int  # bytes of its values (one record's, for a record variable)
    is_record: bool


class Header(NamedTuple):
    """A parsed netCDF-3 header: what :func:`parse` returns."""

    numrecs: int
    attrs: dict[str, Any]
    variables: dict[str, Variable]
    record_begin: int  # the offset of the first record (0 without record variables)
    record_size: int  # the bytes of one record

    def values(self, data: bytes | memoryview, name: str, k: int | None = None) -> np.ndarray:
        """Variable ``name``'s values (of record ``k`` for a record variable) as a
        native-endian array."""
        var = self.variables[name]
        begin = var.begin + (0 if k is None else k * self.record_size)
        count = math.prod(var.shape)
        out = np.frombuffer(data, var.dtype, count, begin).reshape(var.shape)
        return out.astype(var.dtype.newbyteorder("="))


class _Reader:
    def __init__(self, data: bytes) -> None:
        self.data, self.at = data, 0

    def ints(self, fmt: str) -> tuple[int, ...]:
        out = struct.unpack_from(fmt, self.data, self.at)
        self.at += struct.calcsize(fmt)
        return out

    def name(self) -> str:
        (n,) = self.ints(">i")
        raw = self.data[self.at:self.at + n]
        if len(raw) != n:
            raise ValueError("the header ends inside a name")
        self.at += n + _pad(n)
        return raw.decode("utf-8")

    def attrs(self) -> dict[str, Any]:
        tag, count = self.ints(">ii")
        if tag not in (0, _ATTRIBUTE):
            raise ValueError(f"expected an attribute list, found tag {tag}")
        out: dict[str, Any] = {}
        for _ in range(count):
            key = self.name()
            kind, n = self.ints(">ii")
            if kind not in _DTYPES:
                raise ValueError(f"attribute {key!r} of unknown type {kind}")
            size = _DTYPES[kind].itemsize * n
            raw = self.data[self.at:self.at + size]
            self.at += size + _pad(size)
            out[key] = (raw.decode("utf-8") if kind == 2
                        else np.frombuffer(raw, _DTYPES[kind]).tolist())
            if kind != 2 and n == 1:
                out[key] = out[key][0]
        return out


def parse(data: bytes) -> Header:
    """The header of a netCDF-3 file of 64-bit offsets (what :func:`encode` writes).

    Raises
    ------
    ValueError
        When ``data`` does not begin with such a header (also ``struct.error``).
    """
    if data[:4] != b"CDF\x02":
        raise ValueError(f"not a netCDF-3 64-bit offset file (begins {data[:4]!r})")
    rd = _Reader(data)
    rd.at = 4
    (numrecs,) = rd.ints(">i")
    tag, count = rd.ints(">ii")
    dims = []
    for _ in range(count if tag == _DIMENSION else 0):
        dims.append((rd.name(), rd.ints(">i")[0]))
    attrs = rd.attrs()
    tag, count = rd.ints(">ii")
    variables: dict[str, Variable] = {}
    for _ in range(count if tag == _VARIABLE else 0):
        name = rd.name()
        (ndim,) = rd.ints(">i")
        ids = rd.ints(f">{ndim}i")
        var_attrs = rd.attrs()
        kind, size = rd.ints(">ii")
        (begin,) = rd.ints(">q")
        is_record = bool(ids) and dims[ids[0]][1] == 0
        shape = tuple(dims[i][1] for i in ids[1 if is_record else 0:])
        nbytes = math.prod(shape) * _DTYPES[kind].itemsize
        if size != nbytes + _pad(nbytes) or begin < 0:
            raise ValueError(f"variable {name!r}: {size} bytes for shape {shape}")
        variables[name] = Variable(shape, _DTYPES[kind], var_attrs, begin, size, is_record)
    records = [v for v in variables.values() if v.is_record]
    record_begin = min((v.begin for v in records), default=0)
    return Header(numrecs, attrs, variables, record_begin, sum(v.size for v in records))
