"""The two-body state ``(r, v, mu)``, checked once for every object built on it, and
the classical elements of checked states as float columns.

:func:`check_state` is used by :class:`~hamilton_orbits.orbit.KeplerOrbit` and
:class:`~hamilton_orbits.conic.Conic` (one compiled pass that checks and copies,
:func:`hamilton_orbits._kernels.elements.check_copy_state`);
:func:`classical_columns` gives the classical elements of checked states
(:func:`hamilton_orbits._kernels.elements.state_to_elements_classical`), and
:func:`refuse_beyond_range` names the state whose elements do not fit in float64.
Quantities are kept in :data:`STATE_UNITS` (km, km/s, km^3/s^2).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from hamilton_orbits import _columns
from hamilton_orbits._lazy import LazyModule
from hamilton_orbits.units import GM, LENGTH, SPEED, as_quantity, is_quantity
from hamilton_orbits.validation import (
    broadcast,
    check_positive,
    check_trailing,
    first_index,
    fmt_index,
)

# numba is imported on first use (hamilton_orbits._lazy)
_el = LazyModule("hamilton_orbits._kernels.elements", globals(), "_el")

__all__ = ["STATE_UNITS", "check_state", "classical_columns", "refuse_beyond_range"]

# the units a two-body state given in Quantities is kept in (KeplerOrbit, Conic)
STATE_UNITS = ("km", "km / s", "km3 / s2")


def _in_quantities(r: Any, v: Any, mu: Any) -> bool:
    """Whether ``r``, ``v``, ``mu`` are Quantities (all of them; a mix is refused)."""
    q = [is_quantity(x) for x in (r, v, mu)]
    if any(q) and not all(q):
        raise ValueError(
            "Expected `r`, `v`, `mu` to be all Quantities or all plain floats, got a mix"
        )
    return all(q)


def _contiguous(x: np.ndarray, shape: tuple[int, ...]) -> np.ndarray:
    """``x`` broadcast to ``shape`` and C-contiguous (a copy only if needed)."""
    return np.ascontiguousarray(x) if x.shape == shape else np.array(np.broadcast_to(x, shape))


def _copy_valid_state(r_in: Any, v_in: Any, mu_in: Any):
    """:func:`check_state`'s result if every value passes the compiled check,
    None if one does not; raises, in no particular order, for a unit mix, a
    conversion or a shape."""
    quantity = _in_quantities(r_in, v_in, mu_in)
    r = check_trailing("r", LENGTH("r", r_in, STATE_UNITS[0], finite=False), 3)
    v = check_trailing("v", SPEED("v", v_in, STATE_UNITS[1], finite=False), 3)
    mu = GM("mu", mu_in, STATE_UNITS[2], finite=False)
    lead = r.shape[:-1]
    if v.shape[:-1] != lead or mu.shape not in (lead, ()):
        lead = np.broadcast_shapes(lead, v.shape[:-1], mu.shape)
    state = np.empty((*lead, 7))
    rows = state.reshape(-1, 7)
    if rows.shape[0] and _el.check_copy_state(
        _contiguous(r, (*lead, 3)).reshape(-1, 3), _contiguous(v, (*lead, 3)).reshape(-1, 3),
        (mu if mu.ndim == 0 else _contiguous(mu, lead)).reshape(-1),
        rows[:, :3], rows[:, 3:6], rows[:, 6],  # (written: views of the state)
    ):
        return None
    return state, quantity


def _refuse_state(r_in: Any, v_in: Any, mu_in: Any) -> None:
    """Check the arguments one at a time, in the order of the parameters, and
    raise for the first bad one (argument, index, value)."""
    _in_quantities(r_in, v_in, mu_in)
    r = check_trailing("r", LENGTH("r", r_in, STATE_UNITS[0]), 3)
    v = check_trailing("v", SPEED("v", v_in, STATE_UNITS[1]), 3)
    mu = check_positive("mu", GM("mu", mu_in, STATE_UNITS[2]))
    lead = broadcast(("r", "v", "mu"), r[..., 0], v[..., 0], mu)[0].shape
    r = np.broadcast_to(r, (*lead, 3))
    bad = ~np.any(r != 0, axis=-1)  # not |r| > 0: |r|^2 underflows at 1e-170
    if np.any(bad):
        index = first_index(np.atleast_1d(bad)) if bad.ndim else ()
        raise ValueError(f"Expected `r` to be nonzero, got {r[index].tolist()}{fmt_index(index)}")
    raise ValueError(  # pragma: no cover - every value the compiled check refuses is named above
        f"Expected a valid state, got r={r.tolist()}, v={np.asarray(v).tolist()}, "
        f"mu={np.asarray(mu).tolist()}"
    )


def check_state(r: Any, v: Any, mu: Any):
    """The two-body state ``(r, v, mu)`` checked once, as the float array an orbit keeps.

    Parameters
    ----------
    r : array_like or Quantity (length), shape (..., 3)
        Position relative to the attracting centre (nonzero).  A list of
        Quantities is joined into one, an astropy representation is its Cartesian
        coordinates (:func:`hamilton_orbits.units.as_quantity`).
    v : array_like or Quantity (length/time), shape (..., 3)
        Velocity (a list of Quantities, or a representation or a
        ``CartesianDifferential``, as ``r``).
    mu : array_like or Quantity (length^3/time^2), shape (...)
        ``G (m1 + m2) > 0`` (Hamilton's M); a list of Quantities is joined.

    Returns
    -------
    state : ndarray, shape (..., 7)
        A fresh C-contiguous float64 array ``[rx, ry, rz, vx, vy, vz, mu]``
        for every state of the leading shape, the broadcast of ``r[..., 0]``,
        ``v[..., 0]`` and ``mu``; Quantities are converted to km, km/s and
        km^3/s^2 (``STATE_UNITS``).
    quantity : bool
        Whether the state came in Quantities.

    Raises
    ------
    ValueError
        NaN / inf, trailing dimension not 3, ``mu <= 0``, ``r = 0``,
        incompatible shapes, or a mix of Quantities and plain floats, naming
        the argument, the index and the value.
    astropy.units.UnitConversionError
        For a Quantity of the wrong kind.

    Notes
    -----
    The values are checked in one compiled pass that also makes the copy
    (:func:`hamilton_orbits._kernels.elements.check_copy_state`, with the rule
    :func:`hamilton_orbits._kernels.elements.state_valid`).  Only when that
    pass or a conversion fails are the arguments checked one at a time, in the
    order of the parameters, to name the first bad one.

    Examples
    --------
    >>> state, quantity = check_state([[1.0, 0, 0], [2.0, 0, 0]], [0, 1.0, 0], 1.0)
    >>> state.tolist(), quantity
    ([[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0], [2.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0]], False)
    >>> check_state([[1.0, 0, 0], [0.0, 0, 0]], [0, 1.0, 0], 1.0)
    Traceback (most recent call last):
    ...
    ValueError: Expected `r` to be nonzero, got [0.0, 0.0, 0.0] at index 1
    """
    r, v = as_quantity("r", r, vector=True), as_quantity("v", v, vector=True)
    mu = as_quantity("mu", mu)
    try:
        checked = _copy_valid_state(r, v, mu)
    except ValueError:
        _refuse_state(r, v, mu)
        raise
    if checked is None:
        _refuse_state(r, v, mu)
    return checked


def refuse_beyond_range(rows: np.ndarray, state: np.ndarray, shape: tuple[int, ...]) -> None:
    """Raise if a row an elements kernel computed is not finite: that state's
    elements do not fit in float64.

    Parameters
    ----------
    rows : ndarray, shape (N, k)
        Kernel output, one row per state.
    state : ndarray, shape (N, 7)
        The states of the rows (:func:`check_state`).
    shape : tuple of int
        Their leading shape (to name the index).

    Raises
    ------
    ValueError
        Naming ``r``, ``v``, ``mu`` and the index of the first such row.

    Examples
    --------
    >>> refuse_beyond_range(np.array([[1.0, np.nan]]), np.ones((1, 7)), ())  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Expected `r`, `v`, `mu` whose elements fit in float64 (...), got r=[1.0, 1.0, 1.0], v=[1.0, 1.0, 1.0], mu=1.0
    """  # noqa: E501
    with np.errstate(over="ignore", invalid="ignore"):
        if np.isfinite(rows.sum()):  # one fast reduction in the common case
            return
    bad = ~np.all(np.isfinite(rows), axis=-1)
    if not np.any(bad):
        return
    i = int(np.flatnonzero(bad)[0])
    where = fmt_index(tuple(int(k) for k in np.unravel_index(i, shape))) if shape else ""
    raise ValueError(
        f"Expected `r`, `v`, `mu` whose elements fit in float64 (|r| |v|^2 / mu ~ e below "
        f"2^450 ~ 3e135, p and a below 1e308), got r={state[i, :3].tolist()}, "
        f"v={state[i, 3:6].tolist()}, mu={float(state[i, 6])!r}{where}"
    )


def classical_columns(state: np.ndarray):
    """The classical elements of checked states (:func:`check_state`) as float columns.

    Parameters
    ----------
    state : ndarray, shape (..., 7)
        Checked states ``[rx, ry, rz, vx, vy, vz, mu]`` (plain floats in one
        consistent unit system).

    Returns
    -------
    columns : ndarray, shape (NCLASSICAL, ...)
        ``columns[i]`` is the element ``hamilton_orbits._columns.CLASSICAL[i]``
        (``p, e, inv_a, inc, lan, argp, nu, a``) of every state: a view, not
        a copy (the kernel writes one row per state).
    a_beyond : int
        The number of states whose ``a`` alone is beyond float64 (NaN there).

    Raises
    ------
    ValueError
        For a state whose other elements do not fit in float64
        (:func:`refuse_beyond_range`).

    Examples
    --------
    >>> c, _ = classical_columns(np.array([1.0, 0, 0, 0, 1.2, 0, 1.0]))
    >>> [round(float(c[_columns.CLASSICAL.index(n)]), 12) for n in ("p", "e", "a")]
    [1.44, 0.44, 1.785714285714]
    """
    lead = state.shape[:-1]
    rows = state.reshape(-1, 7)
    out = np.empty((rows.shape[0], _columns.NCLASSICAL))
    a_beyond = _el.state_to_elements_classical(*_el.row_columns(rows), out)
    if a_beyond:  # a row with a NaN a: refused here if another value is not finite
        refuse_beyond_range(out[:, :-1], rows, lead)
    return out.T.reshape((_columns.NCLASSICAL, *lead)), a_beyond  # a view
