"""What a saved simulation holds: its parts as a snapshot's ``meta`` and arrays.

:func:`record` turns a simulation's parts (the system at time 0, the method, the
effects, the events, the propagation's whole state) into a snapshot's ``meta``
and arrays (:mod:`hamilton_orbits.snapshot`, and the records of an archive's
segments, :mod:`hamilton_orbits.segment`); :func:`spec` reads them back into the
arguments that rebuild it.  Values that may be Quantities (effect and event
parameters) go through a JSON form that keeps their unit and every bit of their
value.

Examples
--------
>>> import astropy.units as u
>>> import json
>>> text = json.dumps(to_json({"c": 299792.458 * u.km / u.s, "body": "sun"}))
>>> from_json(json.loads(text))["c"]
<Quantity 299792.458 km / s>
"""

from __future__ import annotations

import functools
import math
import sys
from collections.abc import Mapping
from typing import Any

import numpy as np

from hamilton_orbits._netcdf3 import Parts
from hamilton_orbits.restart import Capture, flatten
from hamilton_orbits.snapshot import SnapshotError, beyond_float
from hamilton_orbits.units import is_quantity

__all__ = ["all_active", "from_json", "pack", "record", "spec", "state_values", "to_json", "unpack"]

_SYSTEM_FIELDS = ("gm", "r", "v", "radius", "j2", "pole")
_DTYPE_NAMES: dict[np.dtype, str] = {}  # (dtype.name is slow to compute)
_JSON_PLAIN = frozenset((str, int, float, bool, type(None)))


def to_json(value: Any) -> Any:
    """``value`` in a JSON form that keeps Quantities (value and unit) and arrays."""
    if type(value) in _JSON_PLAIN:
        return value
    if is_quantity(value):
        return {"__quantity__": np.asarray(value.value).tolist(),
                "unit": value.unit.to_string()}
    if isinstance(value, np.ndarray):
        if value.dtype == np.float64:
            return {"__array__": value.tolist()}
        return {"__array__": value.tolist(), "dtype": value.dtype.str}  # (names, ints:
        # read back as what they were, not as floats)
    time = sys.modules.get("astropy.time")  # (a Time can only come from a loaded module)
    if time is not None and isinstance(value, time.Time):  # (an epoch: its two-part JD)
        return {"__time__": [np.asarray(value.jd1).tolist(), np.asarray(value.jd2).tolist()],
                "scale": value.scale,
                "format": value.format}
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, Mapping):
        return {str(k): to_json(x) for k, x in value.items()}
    if isinstance(value, (list, tuple)):
        return [to_json(x) for x in value]
    return value


def from_json(value: Any) -> Any:
    """The inverse of :func:`to_json`."""
    if isinstance(value, dict):
        if "__quantity__" in value:
            import astropy.units as u

            return u.Quantity(value["__quantity__"], u.Unit(value["unit"]), dtype=np.float64)
        if "__array__" in value:
            if "dtype" in value:
                return np.array(value["__array__"], dtype=np.dtype(value["dtype"]))
            try:  # (written without a dtype: floats, or, by a version that lost the
                return np.array(value["__array__"], dtype=np.float64)  # dtype, names)
            except (TypeError, ValueError):
                return np.array(value["__array__"])
        if "__time__" in value:
            from astropy.time import Time

            jd1, jd2 = value["__time__"]
            out = Time(jd1, jd2, format="jd", scale=value["scale"])
            out.format = value["format"]
            return out
        return {k: from_json(x) for k, x in value.items()}
    if isinstance(value, list):
        return [from_json(x) for x in value]
    return value


def record(system: Any, method: Any, dt: float | None, tol: float | None, effects: list,
           events: list, variational: bool, stm: bool, prop: Any,
           extra: Mapping[str, Any], cache: dict[str, Any] | None = None,
           split: bool = False) -> tuple[dict[str, Any], dict[str, np.ndarray],
                                         dict[str, tuple[str, ...]], dict[str, str]]:
    """The ``meta``, arrays, dimensions and units of a snapshot of a simulation whose
    system at time 0 is ``system`` and whose propagation is ``prop``; ``cache``: a
    dict kept by the simulation, where the parts that never change (the system at
    time 0, the method, the effects and events as JSON) are made once; ``split``:
    the numbers of the state in an array ``scalars``, out of the layout, and the
    state's arrays as the propagation's own, :class:`~hamilton_orbits._netcdf3.Parts`
    packed only into the record (for an archive segment, whose snapshots share their
    layout, and whose next record can then be refilled from the same arrays)."""
    scalars: list[Any] | None = [] if split else None
    if prop.events is not None:
        prop.events.drain()  # (its buffer is then empty: not saved)
    layout, state, index = _state(prop, scalars, cache if split else None)
    fixed = None if cache is None else cache.get("fixed")
    if fixed is None:
        fixed = _fixed(system, method, dt, tol, effects, events, variational, stm)
        if cache is not None:
            cache["fixed"] = fixed
    head, sa = fixed
    quantity = bool(sa.quantity)
    meta = {**head, "t": float(prop.t), "steps": int(prop.steps), "layout": layout,
            **to_json(dict(extra))}
    arrays: dict[str, np.ndarray] = {f"initial_{k}": getattr(sa, k) for k in _SYSTEM_FIELDS}
    if split and cache is not None:  # (the capture and the index of its layout: _state's)
        capture, _, index = cache["capture"]
        arrays.update(state_values(prop, state, index, scalars, capture.ints))
        meta["state_arrays"] = index
    else:
        arrays.update(state_values(prop, state, index, scalars))
        meta["state_arrays"] = arrays.pop("state_arrays")
    dims = {"r": ("body", "xyz"), "v": ("body", "xyz"), "gm": ("body",),
            "active": ("body",), "initial_r": ("body", "xyz"), "initial_v": ("body", "xyz"),
            "initial_gm": ("body",), "initial_radius": ("body",), "initial_j2": ("body",),
            "initial_pole": ("body", "xyz")}
    units = {}
    if quantity:
        units = {"t": "day", "r": "au", "v": "au/day", "gm": "au3/day2",
                 "initial_r": "au", "initial_v": "au/day", "initial_gm": "au3/day2",
                 "initial_radius": "au"}
    return meta, arrays, dims, units


def state_values(prop: Any, state: list[np.ndarray], index: list[list[Any]] | None,
                 scalars: list[Any] | None, ints: list[int] | None = None) -> dict[str, Any]:
    """What a snapshot of propagation ``prop`` holds that changes from one snapshot
    to the next: ``t``, ``r``, ``v``, ``gm``, ``active``, the packed ``state`` (of the
    arrays of its layout) and its ``state_arrays`` index, ``scalars`` when given.

    ``ints``: the positions of the integer arrays of ``state``, when known (an
    archive's record, whose index its segment holds): ``state`` is then given as
    :class:`~hamilton_orbits._netcdf3.Parts`, packed only into the record."""
    if prop.events is not None:
        active = ~prop.events.inactive
    else:
        active = all_active(prop.r.shape[0])
    out = {"t": np.float64(prop.t), "r": prop.r, "v": prop.v, "gm": prop.gm, "active": active}
    if ints is None:
        out["state"], out["state_arrays"] = pack(state, index)
    else:
        _exact_integers([state[k] for k in ints])
        out["state"] = Parts(state)
    if scalars is not None:
        out["scalars"] = np.array(scalars, dtype=np.float64)
    return out


@functools.lru_cache(maxsize=8)
def all_active(n: int) -> np.ndarray:
    """``n`` bodies all active (read-only: one array for every snapshot of them)."""
    out = np.ones(n, dtype=bool)
    out.flags.writeable = False
    return out


def _exact_integers(arrays: list[np.ndarray]) -> None:
    """Refuse integer arrays a float64 would not hold exactly."""
    for a in arrays:
        if beyond_float(a):
            raise SnapshotError(f"a state array holds integers beyond 2**53: {a!r}")


def _state(prop: Any, scalars: list[Any] | None, cache: dict[str, Any] | None) -> tuple[
        dict[str, Any], list[np.ndarray], list[list[Any]] | None]:
    """The layout and arrays of ``prop``'s state, its numbers put in ``scalars``
    (:func:`~hamilton_orbits.restart.flatten`), and the index of the packed arrays
    when it is known; with a ``cache`` (an archive's snapshots, which share their
    layout), the graph is walked afresh only when its shape changed
    (:class:`~hamilton_orbits.restart.Capture`)."""
    known = None if cache is None else cache.get("capture")
    if known is None and cache is not None and scalars is not None:
        known = _RECENT.get(type(prop))  # (another simulation's of the same kind)
    if known is not None and scalars is not None:
        taken = known[0].take(prop)
        if taken is not None:
            scalars += taken[1]
            cache["capture"] = known
            return known[1], taken[0], known[2]
    layout, state = flatten(prop, scalars)
    if cache is not None:
        cache["capture"] = _RECENT[type(prop)] = (Capture(prop, layout), layout,
                                                   pack(state)[1])
    return layout, state, None


#: the last capture made, per class of propagation: a simulation's first archived
#: snapshot tries it before walking its graph (a new simulation of the same kind,
#: as in a loop of runs, whose layout is then the same: the capture checks it, and
#: its compiled reading is reused; it holds no array)
_RECENT: dict[type, tuple[Capture, dict[str, Any], list[list[Any]]]] = {}


def _fixed(system: Any, method: Any, dt: float | None, tol: float | None, effects: list,
           events: list, variational: bool, stm: bool) -> tuple[dict[str, Any], Any]:
    """The part of a snapshot's ``meta`` that a simulation never changes, and its
    system's arrays at time 0."""
    from hamilton_orbits import __version__

    sa = system.as_arrays()
    head = {"kind": "simulation", "version": __version__,
            "system": {"names": list(sa.names), "quantity": bool(sa.quantity),
                       "G": float(sa.G)},
            "method": {"name": method.name, "options": to_json(method.options())},
            "dt": dt, "tol": tol, "effects": to_json(effects), "events": to_json(events),
            "variational": variational, "stm": stm}
    return head, sa


def spec(meta: Mapping[str, Any], arrays: Mapping[str, np.ndarray]) -> dict[str, Any]:
    """The parts that rebuild a recorded simulation: ``system`` (a SystemArrays),
    ``method``/``options``, ``dt``, ``tol``, ``effects``, ``events``,
    ``variational``, ``stm``, ``layout`` and ``state`` (the propagation's arrays)."""
    from hamilton_orbits.nbody import SystemArrays

    s = meta["system"]
    system = SystemArrays(tuple(s["names"]), *(arrays[f"initial_{k}"] for k in ("gm", "r", "v",
                                                                                "radius", "j2",
                                                                                "pole")),
                          bool(s["quantity"]), float(s["G"]))
    return {"system": system, "method": meta["method"]["name"],
            "options": from_json(meta["method"]["options"]), "dt": meta["dt"],
            "tol": meta["tol"], "effects": from_json(meta["effects"]),
            "events": from_json(meta["events"]), "variational": meta["variational"],
            "stm": meta["stm"], "layout": meta["layout"],
            "state": unpack(arrays["state"], meta["state_arrays"])}


def pack(arrays: list[np.ndarray], index: list[list[Any]] | None = None) -> tuple[
        np.ndarray, list[list[Any]]]:
    """The arrays of a propagation's state as one float64 vector (integers below
    2**53 and booleans exactly) and each one's ``[offset, shape, dtype]`` (``index``:
    those, when known)."""
    _exact_integers(arrays)
    if index is None:
        index, start = [], 0
        for a in arrays:
            name = _DTYPE_NAMES.get(a.dtype)
            if name is None:
                name = _DTYPE_NAMES.setdefault(a.dtype, a.dtype.name)
            index.append([start, list(a.shape), name])
            start += a.size
    if not arrays:
        return np.empty(0), index
    return np.concatenate([a.reshape(-1) for a in arrays], dtype=np.float64), index


def unpack(flat: np.ndarray, index: list[list[Any]]) -> list[np.ndarray]:
    """The arrays :func:`pack` packed."""
    return [flat[offset:offset + math.prod(shape)].astype(kind).reshape(shape)
            for offset, shape, kind in index]
