"""Input validation shared by every public entry point.

Every check raises :class:`ValueError` naming the argument, the (first) offending
index and the value, as the project's conventions require.

Public: ``rigid`` stands on it as ``hamilton_orbits`` does (the core both packages share).
"""

from __future__ import annotations

import sys
from typing import Any

import numpy as np


class ConvergenceError(ValueError):
    """An iterative solver did not reach its tolerance (never a silent NaN)."""


def as_flag(name: str, value: object) -> bool:
    """``value`` as a bool, refused unless it is one (``"no"`` or ``"False"`` would be
    true, as any non-empty text is).

    Examples
    --------
    >>> as_flag("triaxial", False)
    False
    >>> as_flag("triaxial", "no")
    Traceback (most recent call last):
    ...
    ValueError: Expected `triaxial` to be True or False, got 'no'
    """
    if not isinstance(value, bool | np.bool_):
        raise ValueError(f"Expected `{name}` to be True or False, got {value!r}")
    return bool(value)


def first_index(mask: np.ndarray) -> tuple[int, ...]:
    idx = np.argwhere(mask)[0]
    return tuple(int(i) for i in idx)


def fmt_index(index: tuple[int, ...]) -> str:
    if len(index) == 0:
        return ""
    return " at index " + (str(index[0]) if len(index) == 1 else str(index))


def as_float_array(name: str, value, *, finite: bool = True) -> np.ndarray:
    """Convert ``value`` to a float64 array and reject NaN / inf.

    Parameters
    ----------
    name : str
        The argument's name, used in the error message.
    value : array_like
        Anything :func:`numpy.asarray` takes (plain numbers; Quantities must be
        converted to floats at the unit boundary before this call).
    finite : bool, optional
        If True (default), NaN and inf raise.

    Raises
    ------
    ValueError
        If a value is NaN or infinite, naming the argument, index and value.

    Examples
    --------
    >>> as_float_array("x", [1.0, 2.0])
    array([1., 2.])
    >>> as_float_array("x", [1.0, float("nan")])
    Traceback (most recent call last):
    ...
    ValueError: Expected `x` to be finite, got nan at index 1
    """
    if value is None:  # np.asarray(None, dtype=float) would be a silent NaN
        raise ValueError(f"Expected `{name}` to be numeric, got None")
    if type(value) is list or type(value) is tuple:
        _check_listed(name, value, ())
    elif isinstance(value, np.ndarray) and value.dtype == object:  # (None in it: nan)
        if value.ndim:
            _check_listed(name, value.tolist(), ())
        elif value.item() is None or isinstance(value.item(), bool | np.bool_):
            raise ValueError(f"Expected `{name}` to be numeric, got {value.item()!r}")
    if np.iscomplexobj(value):
        raise ValueError(f"Expected `{name}` to be real, got complex {value!r}")
    check_unmasked(name, value)
    try:
        arr = np.asarray(value, dtype=np.float64)
    except OverflowError as exc:  # a Python int beyond the float64 range
        shown = repr(value) if len(repr(value)) <= 40 else repr(value)[:37] + "..."
        raise ValueError(
            f"Expected `{name}` to be finite (within the float64 range), got {shown}"
        ) from exc
    except (TypeError, ValueError) as exc:
        raise ValueError(f"Expected `{name}` to be numeric, got {value!r}") from exc
    kind = value.dtype.kind if isinstance(value, np.ndarray) else np.asarray(value).dtype.kind
    if kind in "USb":  # (numeric strings and bools convert, silently: "1" and True)
        raise ValueError(f"Expected `{name}` to be numeric, got {value!r}")
    if kind in "mMV":  # (numpy's durations, dates and records convert, silently, to
        # their counts or fields: a minute as 1)
        what = {"m": "a numpy timedelta64 (a duration: give it as a time Quantity, or "
                     "in this argument's unit)",
                "M": "a numpy datetime64 (a date, not a number)",
                "V": "a structured array (records, not numbers)"}[kind]
        raise ValueError(f"Expected `{name}` to be numeric, got {what}: {value!r}")
    if finite:
        bad = ~np.isfinite(arr)
        if bad.any():
            index = first_index(bad) if arr.ndim else ()
            raise ValueError(
                f"Expected `{name}` to be finite, got {float(arr[index])!r}{fmt_index(index)}"
            )
    return arr


#: Types never masked (:func:`check_unmasked`'s quick answer; a Quantity's masked
#: form is a subclass of its own)
_NEVER_MASKED = frozenset({float, int, np.float64, np.ndarray, list, tuple})


def check_unmasked(name: str, value: object) -> None:
    """Refuse a masked value: a numpy masked array or an astropy ``Masked`` one (a
    masked Quantity included) with any element masked, naming ``name`` and the index
    of the first masked element (``numpy.asarray`` and ``Quantity.to_value`` read
    the values under the mask, silently).

    Examples
    --------
    >>> check_unmasked("x", np.ma.array([1.0, 2.0]))  # nothing masked: taken
    >>> check_unmasked("x", np.ma.array([1.0, 2.0], mask=[0, 1]))
    Traceback (most recent call last):
    ...
    ValueError: Expected `x` to be numbers, got a masked value at index 1
    """
    if type(value) in _NEVER_MASKED:  # (the common types at once: two isinstance
        return  # tests cost 0.1-0.3 us of every conversion)
    if isinstance(value, np.ma.MaskedArray):
        mask = np.ma.getmaskarray(value)
    else:
        module = sys.modules.get("astropy.utils.masked")  # (not imported: none was made)
        if module is None or not isinstance(value, module.Masked):
            return
        mask = np.asarray(value.mask, dtype=bool)
    if mask.any():
        index = first_index(mask) if mask.ndim else ()
        raise ValueError(f"Expected `{name}` to be numbers, got a masked value"
                         f"{fmt_index(index)}")


def _check_listed(name: str, values: list | tuple, at: tuple[int, ...]) -> None:
    """Refuse what a list (nested or not) holds that ``numpy.asarray`` would take
    wrongly: a bool (read as 1.0 or 0.0, silently), None (read as nan) or a
    Quantity (a TypeError deep in numpy), naming the index."""
    units = sys.modules.get("astropy.units")
    first = None  # the first entry's length (-1: a number), which every entry must have
    for k, x in enumerate(values):
        kind = type(x)
        if kind is float or kind is int:
            if first is None:
                first = -1
            elif first != -1:
                _refuse_ragged(name, x, (*at, k), -1, first)
            continue
        if kind is list or kind is tuple:
            if first is None:
                first = len(x)
            elif first != len(x):
                _refuse_ragged(name, x, (*at, k), len(x), first)
            _check_listed(name, x, (*at, k))
        elif kind is bool or kind is np.bool_ or x is None:  # (None: read as nan)
            raise ValueError(f"Expected `{name}` to be numeric, got {x!r}{fmt_index((*at, k))}")
        elif units is not None and isinstance(x, units.Quantity):
            raise ValueError(
                f"Expected `{name}` to be plain numbers or one Quantity array, got the "
                f"Quantity {x}{fmt_index((*at, k))} in a list (u.Quantity(...) joins a list of "
                f"Quantities into one)")


def _refuse_ragged(name: str, x: Any, at: tuple[int, ...], length: int, first: int) -> None:
    """Refuse a ragged list (numpy's "inhomogeneous shape"): entry ``x`` at index ``at``
    of ``length`` entries (-1: a number) where the first of its row has ``first``."""
    def entries(n: int) -> str:
        return "is a number" if n == -1 else "has 1 entry" if n == 1 else f"has {n} entries"

    shown = repr(x) if len(repr(x)) <= 60 else repr(x)[:57] + "..."
    raise ValueError(
        f"Expected `{name}` to be a regular array (rows of one length), got {shown}"
        f"{fmt_index(at)}, which {entries(length)}, where index "
        f"{fmt_index((*at[:-1], 0))[10:]} {entries(first)}")


def check_finite(name: str, arr: np.ndarray, where: np.ndarray | None = None) -> None:
    """Refuse a NaN or infinite entry of the 1-d ``arr``, naming ``name``, the index
    (``where[k]`` for entry ``k`` when given: ``arr`` a selection of a longer array)
    and the value.

    Examples
    --------
    >>> check_finite("gm", np.array([1.0, 2.0]))
    >>> check_finite("radius", np.array([1.0, np.inf]), where=np.array([0, 3]))
    Traceback (most recent call last):
    ...
    ValueError: Expected `radius` to be finite, got inf at index 3
    """
    bad = np.flatnonzero(~np.isfinite(arr))
    if bad.size:
        k = int(bad[0])
        index = k if where is None else int(where[k])
        raise ValueError(f"Expected `{name}` to be finite, got {float(arr[k])!r} at index "
                         f"{index}")


def check_trailing(name: str, arr: np.ndarray, size: int) -> np.ndarray:
    """Require ``arr.shape == (..., size)``.

    Examples
    --------
    >>> check_trailing("v", np.zeros(2), 3)
    Traceback (most recent call last):
    ...
    ValueError: Expected `v` to have shape (..., 3), got (2,)
    """
    if arr.ndim == 0 or arr.shape[-1] != size:
        raise ValueError(f"Expected `{name}` to have shape (..., {size}), got {arr.shape}")
    return arr


def check_positive(name: str, arr: np.ndarray, *, strict: bool = True) -> np.ndarray:
    """Require ``arr > 0`` (or ``>= 0`` with ``strict=False``) elementwise.

    Examples
    --------
    >>> check_positive("mu", np.array([1.0, -2.0]))
    Traceback (most recent call last):
    ...
    ValueError: Expected `mu` > 0, got -2.0 at index 1
    """
    bad = ~(arr > 0) if strict else ~(arr >= 0)
    if np.any(bad):
        index = first_index(np.atleast_1d(bad)) if arr.ndim else ()
        value = arr[index] if arr.ndim else arr
        op = ">" if strict else ">="
        raise ValueError(f"Expected `{name}` {op} 0, got {float(value)!r}{fmt_index(index)}")
    return arr


def broadcast(names: tuple[str, ...], *arrays: np.ndarray) -> list[np.ndarray]:
    """Broadcast arrays together, naming them if their shapes are incompatible.

    Examples
    --------
    >>> broadcast(("a", "b"), np.zeros(2), np.zeros(3))
    Traceback (most recent call last):
    ...
    ValueError: Expected `a`, `b` to broadcast together, got shapes (2,), (3,)
    """
    try:
        return list(np.broadcast_arrays(*arrays))
    except ValueError as exc:
        shapes = ", ".join(str(a.shape) for a in arrays)
        names_s = ", ".join(f"`{n}`" for n in names)
        raise ValueError(
            f"Expected {names_s} to broadcast together, got shapes {shapes}"
        ) from exc


def broadcast_shapes(names: tuple[str, ...], *shapes: tuple[int, ...]) -> tuple[int, ...]:
    """The broadcast shape of ``shapes``, naming the arguments if they do not broadcast.

    Like :func:`broadcast` but on shapes only (no arrays are built), for calls
    into generalised ufuncs whose own message would be numpy's.

    Examples
    --------
    >>> broadcast_shapes(("axis", "angle"), (2,), ())
    (2,)
    >>> broadcast_shapes(("axis", "angle"), (2,), (3,))
    Traceback (most recent call last):
    ...
    ValueError: Expected `axis`, `angle` to broadcast together, got shapes (2,), (3,)
    """
    try:
        return tuple(np.broadcast_shapes(*shapes))
    except ValueError as exc:
        names_s = ", ".join(f"`{n}`" for n in names)
        shapes_s = ", ".join(str(tuple(s)) for s in shapes)
        raise ValueError(
            f"Expected {names_s} to broadcast together, got shapes {shapes_s}"
        ) from exc


def check_finite_result(
    name: str, result: np.ndarray, what: str, value: np.ndarray | None = None
) -> np.ndarray:
    """Refuse a result that overflowed: inf or NaN out of finite input.

    Parameters
    ----------
    name : str
        The argument whose value makes the result unrepresentable.
    result : ndarray, shape (..., k)
        The computed result, components on the last axis.
    what : str
        What overflowed, e.g. ``"the product"``.
    value : ndarray, optional
        The values of ``name``, of shape (...) or (..., j) with the leading
        shape of ``result``, quoted at the first bad index.

    Raises
    ------
    ValueError
        Naming ``name``, the first bad index (leading dimensions) and the value.

    Examples
    --------
    >>> check_finite_result("t", np.array([[1.0, 2.0], [1.0, np.inf]]), "the power",
    ...                     np.array([1.0, 1e300]))
    Traceback (most recent call last):
    ...
    ValueError: Expected `t` to keep the power finite, got 1e+300 at index 1: it overflows
    """
    bad = ~np.isfinite(result)
    if not bad.any():
        return result
    lead = np.any(bad, axis=-1)
    index = first_index(lead) if lead.ndim else ()
    got = ""
    if value is not None:
        v = np.asarray(value, dtype=np.float64)[index]
        shown = repr(float(v)) if v.ndim == 0 else np.array2string(v, separator=", ")
        got = f", got {shown}"
    raise ValueError(
        f"Expected `{name}` to keep {what} finite{got}{fmt_index(index)}: it overflows"
    )


def read_only(x: Any) -> Any:
    """A read-only view of array ``x`` (a Quantity stays one; ``x`` itself where it is
    read-only already); anything else as it is.

    For arrays a caller must not change through what it is given (a trajectory's
    ``t``, ``r``, ``v``) and for a kernel's inputs, which numba compiles again for
    each mix of read-only and writable arrays (a type of its own).

    Examples
    --------
    >>> a = np.zeros(3)
    >>> b = read_only(a)
    >>> b.flags.writeable, a.flags.writeable, b.base is a
    (False, True, True)
    """
    if not isinstance(x, np.ndarray) or not x.flags.writeable:
        return x
    view = x.view()
    view.flags.writeable = False
    return view
