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
the alias.  A class may name attributes that are working space, not state, in
``RESTART_SCRATCH`` (the events log's buffer, empty after a drain): they are left
out, and the fresh build's are kept (a layout that holds them is still restored).
A class with a ``restarted`` method has it called once its attributes are
restored (to make again what it derives from them, as scratch it left out).

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

import keyword
import types
from typing import Any

import numpy as np

from hamilton_orbits.integrators import Method
from hamilton_orbits.integrators._setup import is_address
from hamilton_orbits.rhs import RHS
from hamilton_orbits.snapshot import INT_EXACT

__all__ = ["Capture", "LayoutMismatch", "flatten", "inline", "restore"]

_SCALARS = (bool, int, float, str, type(None))
_NUMPY_SCALARS = {np.float64: "float64", np.bool_: "bool", np.int64: "int64"}
_NUMBERS = frozenset((bool, int, float))
_TYPES = {"float64": "float", "bool": "bool", "int64": "int"}


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


def flatten(obj: Any, scalars: list[Any] | None = None) -> tuple[dict[str, Any],
                                                                 list[np.ndarray]]:
    """The layout of ``obj``'s state and its arrays (see the module notes).

    ``scalars``: a list that takes the numbers of the state (times, step counts,
    flags), each leaf then ``{"scalar": k, "type": ...}`` instead of its value, so
    that the layout stays the same from one snapshot to the next (an archive
    segment shares it); :func:`inline` puts the values back.

    Examples
    --------
    >>> class Leaf:
    ...     def __init__(self):
    ...         self.t, self.name, self.x = 2.5, "a", np.zeros(1)
    >>> numbers = []
    >>> layout, _ = flatten(Leaf(), numbers)
    >>> layout["attrs"]["t"], layout["attrs"]["name"], numbers
    ({'scalar': 0, 'type': 'float'}, {'value': 'a'}, [2.5])
    >>> inline(layout, np.array(numbers)) == flatten(Leaf())[0]
    True
    """
    arrays: list[np.ndarray] = []
    seen: dict[int, int] = {}
    return _node(obj, arrays, seen, scalars), arrays


def inline(layout: dict[str, Any], values: np.ndarray) -> dict[str, Any]:
    """The layout :func:`flatten` gives without ``scalars``, from the one it gives
    with them and their ``values``."""
    if "scalar" in layout:
        x = values[layout["scalar"]]
        kind = layout["type"]
        out = {"value": float(x) if kind == "float" else int(x) if kind == "int" else bool(x)}
        if "numpy" in layout:
            out["numpy"] = layout["numpy"]
        return out
    if "attrs" in layout:
        return {**layout, "attrs": {k: inline(x, values) for k, x in layout["attrs"].items()}}
    if "items" in layout:
        return {**layout, "items": [inline(x, values) for x in layout["items"]]}
    if "dict" in layout:
        return {"dict": {k: inline(x, values) for k, x in layout["dict"].items()}}
    return layout


_PLAIN = frozenset(_SCALARS)


def _scalar(obj: Any, kind: str, scalars: list[Any] | None,
            numpy: str | None = None) -> dict[str, Any] | None:
    """``obj`` as an entry of ``scalars`` (None: keep it inline)."""
    if scalars is None or (kind == "int" and abs(obj) >= INT_EXACT):
        return None
    scalars.append(obj)
    node = {"scalar": len(scalars) - 1, "type": kind}
    if numpy is not None:
        node["numpy"] = numpy
    return node


#: how a value of each type is flattened (what _built decides for a non-array type
#: depends on its type alone): filled as types are met
_PLAN: dict[type, str] = {}


def _plan(kind: type, obj: Any) -> str:
    if kind in _PLAIN:
        return "number" if kind in _NUMBERS else "plain"
    if kind is np.ndarray:
        return "array"
    if _built(obj):
        return "built"
    if kind in _NUMPY_SCALARS:
        return "numpy"
    if issubclass(kind, _SCALARS):
        return "plain"
    if issubclass(kind, np.ndarray):
        return "array"
    if issubclass(kind, (list, tuple)):
        return "sequence"
    if issubclass(kind, dict):
        return "dict"
    if hasattr(obj, "__dict__") or hasattr(kind, "__slots__"):
        return "object"
    raise TypeError(f"cannot flatten a {kind.__name__}")


def _node(obj: Any, arrays: list[np.ndarray], seen: dict[int, int],
          scalars: list[Any] | None = None) -> dict[str, Any]:
    kind = type(obj)
    how = _PLAN.get(kind)
    if how is None:
        how = _PLAN.setdefault(kind, _plan(kind, obj))
    if how == "number":
        node = _scalar(obj, kind.__name__, scalars)
        return node if node is not None else {"value": obj}
    if how == "plain":
        return {"value": obj}
    if how == "array":
        if is_address(obj):
            return {"built": True}
        if id(obj) in seen:
            return {"alias": seen[id(obj)]}
        seen[id(obj)] = len(arrays)
        arrays.append(obj)
        return {"array": len(arrays) - 1}
    if how == "built":
        return {"built": True}
    if how == "numpy":
        name = _NUMPY_SCALARS[kind]
        node = _scalar(obj.item(), _TYPES[name], scalars, name)
        return node if node is not None else {"value": obj.item(), "numpy": name}
    if how == "sequence":
        return {"tuple" if isinstance(obj, tuple) else "list":
                True, "items": [_node(x, arrays, seen, scalars) for x in obj]}
    if how == "dict":
        if not all(isinstance(k, str) for k in obj):
            raise TypeError(f"cannot flatten a dict with keys {list(obj)!r}")
        return {"dict": {k: _node(x, arrays, seen, scalars) for k, x in obj.items()}}
    fields = obj.__dict__ if hasattr(obj, "__dict__") else _fields(obj)
    scratch = getattr(kind, "RESTART_SCRATCH", ())
    if scratch:  # working space the object's own state does not depend on
        fields = {k: x for k, x in fields.items() if k not in scratch}
    return {"class": f"{kind.__module__}.{kind.__qualname__}",
            "attrs": {k: _node(x, arrays, seen, scalars) for k, x in fields.items()}}


#: the compiled text of Capture.take's functions, by text (the values it compares
#: against are bound by name when it is run)
_CODE: dict[str, types.CodeType] = {}
# the steps of a Capture: what each node of the layout is
_OBJ, _SEQ, _DICT, _ARR, _ALIAS, _NUM, _NPNUM, _VAL, _BUILT = range(9)


class Capture:
    """What :func:`flatten` gives with ``scalars`` for a graph of the shape it had once,
    found again without walking it anew (an archive takes many snapshots of one
    propagation, whose layout changes seldom).

    Made from ``obj`` and the layout :func:`flatten` gave for it, :meth:`take` reads
    the same attributes, items, arrays and numbers again, checking at each node that
    the graph still has the layout's shape: the same classes and attribute names,
    the same lengths and keys, arrays of the same shapes and types reached by the
    same aliases, the same plain values.  Where anything differs it returns None,
    and the caller flattens afresh: what it returns is then always what ``flatten``
    would give.

    Examples
    --------
    >>> class Leaf:
    ...     def __init__(self):
    ...         self.t, self.x = 2.5, np.zeros(2); self.pair = (self.x, 3)
    >>> leaf, numbers = Leaf(), []
    >>> layout, arrays = flatten(leaf, numbers)
    >>> capture = Capture(leaf, layout)
    >>> leaf.t = 3.0
    >>> capture.take(leaf)[1] == [3.0, 3]
    True
    >>> leaf.pair = (np.zeros(2), 3)   # no longer the alias of x: flatten afresh
    >>> capture.take(leaf) is None
    True
    """

    def __init__(self, obj: Any, layout: dict[str, Any]) -> None:
        self.root = (type(obj), obj.__dict__.keys() | set())
        self.ops: list[tuple[int, int, Any, bool, Any]] = []
        self.usable = True
        self._compile(obj, layout, 0)
        self._take: Any = None  # (written out at the first take: a layout met once
        # costs nothing more)
        self._reread: Any = None
        #: the positions of the integer arrays among those :meth:`take` returns
        self.ints = [k for k, (code, expect, *_) in enumerate(
            op for op in self.ops if op[0] == _ARR) if expect[2].kind in "iu"]

    def _compile(self, obj: Any, layout: dict[str, Any], slot: int) -> None:
        if "attrs" in layout:
            if not hasattr(obj, "__dict__"):
                self.usable = False  # (a class with __slots__: always flattened)
                return
            children = [(k, True, getattr(obj, k), x) for k, x in layout["attrs"].items()]
        elif "items" in layout:
            children = [(i, False, x, n) for i, (x, n) in enumerate(zip(obj, layout["items"],
                                                                         strict=True))]
        else:
            children = [(k, False, obj[k], n) for k, n in layout["dict"].items()]
        for key, attr, x, node in children:
            self.ops.append((*_step(x, node), slot, key, attr))
            if "attrs" in node or "items" in node or "dict" in node:
                self._compile(x, node, len(self.ops))

    def take(self, obj: Any) -> tuple[list[np.ndarray], list[Any]] | None:
        """The arrays and numbers ``flatten(obj, scalars)`` would give (its layout the
        one this capture was made from), or None where the graph's shape differs."""
        if not self.usable:
            return None
        if self._take is None:
            self._take = self._function(checked=True)
        return self._take(obj)

    def reread(self, obj: Any) -> tuple[list[np.ndarray], list[Any]] | None:
        """What :meth:`take` returns, read along the same paths without checking the
        graph: only for a caller that knows the graph's shape is unchanged since a
        :meth:`take` of ``obj`` that succeeded (arrays changed in place, numbers and
        arrays of the same shape put in their places), as between two pauses of one
        compiled run; None where :meth:`take` would always be."""
        if not self.usable:
            return None
        if self._reread is None:
            self._reread = self._function(checked=False)
        return self._reread(obj)

    def _function(self, checked: bool) -> Any:
        """:meth:`take`'s function (``checked``) or :meth:`reread`'s, compiled once per
        text (the same shape of graph in another leg is not compiled again)."""
        source, known = self._source(checked)
        code = _CODE.get(source)
        if code is None:
            code = _CODE[source] = compile(source, "<restart.Capture>", "exec")
            if len(_CODE) > 64:
                del _CODE[next(iter(_CODE))]
        exec(code, known)
        return known["take"]

    def _source(self, checked: bool = True) -> tuple[str, dict[str, Any]]:
        """The text of :meth:`take`'s function, written out from :attr:`ops` (one
        line per read and per check: several times faster than interpreting the
        steps), and the values it compares against (by name, never as text);
        without the checks (``checked`` False), :meth:`reread`'s."""
        known: dict[str, Any] = {"np": np, "is_address": is_address, "E": INT_EXACT,
                                 "T0": self.root[0], "K0": self.root[1]}
        lines = ["def take(x0):",
                 "    if type(x0) is not T0 or x0.__dict__.keys() != K0: return None"]
        arrays, numbers = [], []
        for i, (code, expect, parent, key, attr) in enumerate(self.ops, start=1):
            x, at = f"x{i}", f"x{parent}"
            if attr and key.isidentifier() and not keyword.iskeyword(key):
                lines.append(f"    {x} = {at}.{key}")
            elif type(key) is int:
                lines.append(f"    {x} = {at}[{key}]")
            else:
                known[f"A{i}"] = key
                lines.append(f"    {x} = getattr({at}, A{i})" if attr else f"    {x} = {at}[A{i}]")
            if code == _ALIAS:
                lines.append(f"    if {x} is not {arrays[expect]}: return None")
                continue
            known[f"T{i}"] = expect[0]
            lines.append(f"    if type({x}) is not T{i}: return None")
            lines += _checks(code, expect, x, i, known)
            if code == _ARR:
                arrays.append(x)
            elif code == _NUM:
                numbers.append(x)
            elif code == _NPNUM:
                numbers.append(f"{x}.item()")
        lines.append(f"    arrays = [{', '.join(arrays)}]")
        lines.append(f"    if len(set(map(id, arrays))) != {len(arrays)}: return None")
        lines.append(f"    return arrays, [{', '.join(numbers)}]")
        if not checked:  # (the reads alone: a check is the only line that returns None)
            lines = [line for line in lines if not line.endswith(": return None")]
        return "\n".join(lines) + "\n", known


def _checks(code: int, expect: Any, x: str, i: int, known: dict[str, Any]) -> list[str]:
    """The lines of :meth:`Capture._source` that check value ``x`` of step ``i``
    beyond its type (what they compare against put in ``known``)."""
    known[f"V{i}"] = expect[1] if len(expect) > 1 else None
    if code == _ARR:
        known[f"D{i}"] = expect[2]
        out = [f"    if {x}.shape != V{i} or {x}.dtype != D{i}: return None"]
        if expect[2] == np.int64:
            out.append(f"    if is_address({x}): return None")
        return out
    if code in (_NUM, _NPNUM):
        value = x if code == _NUM else f"{x}.item()"
        return [f"    if not -E < {value} < E: return None"] if expect[1] else []
    if code == _OBJ:
        return [f"    if {x}.__dict__.keys() != V{i}: return None"]
    if code == _DICT:
        return [f"    if {x}.keys() != V{i}: return None"]
    if code == _SEQ:
        return [f"    if len({x}) != V{i}: return None"]
    if code == _VAL:  # (None: its type said it all)
        return [] if expect[1] is None else [
            f"    if not ({x} is V{i} or {x} == V{i}): return None"]
    if expect[0] is np.ndarray:  # (built: an array of compiled functions' addresses)
        return [f"    if not is_address({x}): return None"]
    return []


def _step(x: Any, node: dict[str, Any]) -> tuple[int, Any]:
    """The code of a :class:`Capture` step for value ``x`` at layout ``node``, and
    what it expects to find there."""
    kind = type(x)
    if "alias" in node:
        return _ALIAS, node["alias"]
    if "array" in node:
        return _ARR, (kind, x.shape, x.dtype)
    if "scalar" in node:
        return (_NPNUM if "numpy" in node else _NUM), (kind, node["type"] == "int")
    if "attrs" in node:
        return _OBJ, (kind, x.__dict__.keys() | set())
    if "items" in node:
        return _SEQ, (kind, len(x))
    if "dict" in node:
        return _DICT, (kind, x.keys() | set())
    if "built" in node:
        return _BUILT, (kind,)
    return _VAL, (kind, x)


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
    scratch = set(getattr(cls, "RESTART_SCRATCH", ()))
    if set(saved) - scratch != set(fresh) - scratch:
        raise LayoutMismatch(f"{where}: saved attributes {sorted(saved)}, this version has "
                             f"{sorted(fresh)}")
    for key, node in saved.items():
        setattr(obj, key, _value(fresh[key], node, arrays, restored, f"{where}.{key}"))
    hook = getattr(cls, "restarted", None)
    if hook is not None:  # (what the object makes of its restored state)
        hook(obj)


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
