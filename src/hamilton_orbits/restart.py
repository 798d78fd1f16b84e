"""The restart state of a propagation: its object graph as named arrays and a layout.

A :class:`~hamilton_orbits.engine.Propagation` carries, beside the positions and
velocities, everything its integrator needs to continue bit for bit: radau15's
predictor values, last step and compensated sums, the Wisdom-Holman coordinates and
corrector state, dop853's step, the events found, the MEGNO sums and tangent
vectors.  :func:`flatten` walks that graph and returns a JSON-able *layout* (the
attribute tree, with plain values inline and each array by its number) and the
list of arrays; :func:`restore` puts them back into a propagation built afresh
from the same specification, so the driver's own objects and its compiled
functions are the new process's, and only the values are the saved ones.

What is not state is kept from the fresh build, never read from a file: the
compiled right-hand side, the method value, modules, compiled functions and
callables, and the addresses of compiled functions (int64 arrays that differ
from one process to the next; :func:`hamilton_orbits.integrators._setup.is_address`).
An array reached twice (a tuple of kernel arguments holding the same arrays as the
driver's attributes) is restored as one array reached twice: the layout records
the alias.

The layout names classes; :func:`restore` refuses a layout whose classes or
attributes differ from the fresh build's (:class:`LayoutMismatch`), which is what
a snapshot written by a version with other integrator internals meets.

Examples
--------
>>> class Leaf:
...     def __init__(self):
...         self.x = np.zeros(2); self.pair = (self.x, 3); self.f = len
>>> layout, arrays = flatten(Leaf())
>>> layout["attrs"]["pair"]["items"][0], layout["attrs"]["f"]
({'alias': 0}, {'built': True})
>>> new = Leaf(); arrays[0][:] = 7.0
>>> restore(new, layout, arrays)
>>> new.x.tolist(), new.pair[0] is new.x
([7.0, 7.0], True)
"""

from __future__ import annotations

import types
from typing import Any

import numpy as np

from hamilton_orbits.integrators import Method
from hamilton_orbits.integrators._setup import is_address
from hamilton_orbits.rhs import RHS

__all__ = ["LayoutMismatch", "flatten", "restore"]

_SCALARS = (bool, int, float, str, type(None))
_NUMPY_SCALARS = {np.float64: "float64", np.bool_: "bool", np.int64: "int64"}


class LayoutMismatch(ValueError):
    """A saved layout that does not fit the fresh build (another version's integrator
    internals): the exact state cannot be restored."""


def _built(obj: Any) -> bool:
    """True for what a build makes and a restart must not read back."""
    if isinstance(obj, (RHS, Method, types.ModuleType, type)) or callable(obj):
        return True
    if (type(obj).__module__ or "").startswith("numba"):
        return True
    return isinstance(obj, np.ndarray) and is_address(obj)


def _fields(obj: Any) -> dict[str, Any]:
    if hasattr(obj, "__dict__"):
        return dict(vars(obj))
    return {k: getattr(obj, k) for k in type(obj).__slots__ if hasattr(obj, k)}


def flatten(obj: Any) -> tuple[dict[str, Any], list[np.ndarray]]:
    """The layout of ``obj``'s state and its arrays (see the module notes)."""
    arrays: list[np.ndarray] = []
    seen: dict[int, int] = {}
    return _node(obj, arrays, seen), arrays


_PLAIN = frozenset(_SCALARS)


def _node(obj: Any, arrays: list[np.ndarray], seen: dict[int, int]) -> dict[str, Any]:
    kind = type(obj)
    if kind in _PLAIN:  # the common leaves first (what _built decides for them: not built)
        return {"value": obj}
    if kind is np.ndarray and not is_address(obj):
        if id(obj) in seen:
            return {"alias": seen[id(obj)]}
        seen[id(obj)] = len(arrays)
        arrays.append(obj)
        return {"array": len(arrays) - 1}
    if _built(obj):
        return {"built": True}
    if isinstance(obj, _SCALARS):
        return {"value": obj}
    kind = _NUMPY_SCALARS.get(type(obj))
    if kind is not None:
        return {"value": obj.item(), "numpy": kind}
    if isinstance(obj, np.ndarray):
        if id(obj) in seen:
            return {"alias": seen[id(obj)]}
        seen[id(obj)] = len(arrays)
        arrays.append(obj)
        return {"array": len(arrays) - 1}
    if isinstance(obj, (list, tuple)):
        return {"tuple" if isinstance(obj, tuple) else "list":
                True, "items": [_node(x, arrays, seen) for x in obj]}
    if isinstance(obj, dict):
        if not all(isinstance(k, str) for k in obj):
            raise TypeError(f"cannot flatten a dict with keys {list(obj)!r}")
        return {"dict": {k: _node(x, arrays, seen) for k, x in obj.items()}}
    if hasattr(obj, "__dict__") or hasattr(type(obj), "__slots__"):
        cls = type(obj)
        return {"class": f"{cls.__module__}.{cls.__qualname__}",
                "attrs": {k: _node(x, arrays, seen) for k, x in _fields(obj).items()}}
    raise TypeError(f"cannot flatten a {type(obj).__name__}")


def restore(obj: Any, layout: dict[str, Any], arrays: list[np.ndarray]) -> None:
    """Put the state of ``layout``/``arrays`` (from :func:`flatten`) into ``obj``, a
    fresh object of the same classes (in place).

    Raises
    ------
    LayoutMismatch
        When a class or an attribute of the layout is not the fresh object's.
    """
    restored: dict[int, np.ndarray] = {}
    _fill(obj, layout, arrays, restored, "state")


def _fill(obj: Any, layout: dict[str, Any], arrays: list[np.ndarray],
          restored: dict[int, np.ndarray], where: str) -> None:
    cls = type(obj)
    name = f"{cls.__module__}.{cls.__qualname__}"
    if layout.get("class") != name:
        raise LayoutMismatch(f"{where}: saved {layout.get('class')!r}, this version has "
                             f"{name!r}")
    fresh = _fields(obj)
    saved = layout["attrs"]
    if set(saved) != set(fresh):
        raise LayoutMismatch(f"{where}: saved attributes {sorted(saved)}, this version has "
                             f"{sorted(fresh)}")
    for key, node in saved.items():
        setattr(obj, key, _value(fresh[key], node, arrays, restored, f"{where}.{key}"))


def _value(fresh: Any, node: dict[str, Any], arrays: list[np.ndarray],
           restored: dict[int, np.ndarray], where: str) -> Any:
    if "built" in node:
        return fresh
    if "value" in node:
        kind = node.get("numpy")
        return node["value"] if kind is None else np.dtype(kind).type(node["value"])
    if "array" in node or "alias" in node:
        k = node.get("array", node.get("alias"))
        if k not in restored:
            restored[k] = np.array(arrays[k], copy=True)
        return restored[k]
    if "items" in node:
        old = list(fresh) if isinstance(fresh, (list, tuple)) else []
        items = [_value(old[i] if i < len(old) else None, x, arrays, restored,
                        f"{where}[{i}]") for i, x in enumerate(node["items"])]
        return tuple(items) if "tuple" in node else items
    if "dict" in node:
        old = fresh if isinstance(fresh, dict) else {}
        return {k: _value(old.get(k), x, arrays, restored, f"{where}[{k!r}]")
                for k, x in node["dict"].items()}
    if fresh is None:
        raise LayoutMismatch(f"{where}: saved an object, this version has none")
    _fill(fresh, node, arrays, restored, where)
    return fresh
