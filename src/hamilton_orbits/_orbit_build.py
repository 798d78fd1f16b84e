"""The pieces of :meth:`hamilton_orbits.orbit.KeplerOrbit.from_elements`: the elements
checked and as floats (:func:`element_inputs`), ``p`` and ``1/a``
(:func:`p_and_inv_a`), the anomaly (:func:`anomaly_of`) and the state they give
(:func:`state_of`); and :func:`raise_at`, the error naming an argument's first bad
index, which Hamilton's products (:mod:`hamilton_orbits._hamilton_products`) share.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from hamilton_orbits._columns import NCLASSICAL
from hamilton_orbits._lazy import LazyModule
from hamilton_orbits.twobody import STATE_UNITS
from hamilton_orbits.units import ANGLE, DIMENSIONLESS, GM, LENGTH, as_quantity, is_quantity
from hamilton_orbits.validation import (
    ConvergenceError,
    broadcast,
    first_index,
    fmt_index,
)

# numba is imported on first use (hamilton_orbits._lazy)
_el = LazyModule("hamilton_orbits._kernels.elements", globals(), "_el")
_kk = LazyModule("hamilton_orbits._kernels.kepler", globals(), "_kk")

__all__ = ["anomaly_of", "clamp_inc", "element_inputs", "p_and_inv_a", "raise_at",
           "refuse_unreadable", "state_of"]

# two ulp above the float pi: an inclination of 180 degrees in another unit converts to
# up to this (648 000 000 mas is one ulp above pi in astropy's conversion)
_PI_PLUS_2ULP = float(np.nextafter(np.nextafter(np.pi, 4.0), 4.0))

# |r| |v|^2 / mu (max-norm) of a state above which :func:`refuse_unreadable` asks the
# elements kernel whether it reads the state back (its range: below 2^450, the constant
# MAX_E_EXPONENT of hamilton_orbits._kernels.kepler)
_SUSPECT = 2.0**440

# internal units when Quantities come in
_L, _MU = STATE_UNITS[0], STATE_UNITS[2]


def raise_at(name: str, mask: np.ndarray, values: np.ndarray, what: str,
             given: Any = None) -> None:
    """Raise ValueError naming ``name``, the first index where ``mask`` and its value:
    as ``given`` (the argument as the caller wrote it) has it when that is a Quantity
    (``values`` are in the internal units: "got -3.0 AU", not "-448793612.1")."""
    if np.any(mask):
        mask = np.atleast_1d(mask)
        values = np.broadcast_to(np.atleast_1d(values), mask.shape)
        index = first_index(mask)
        shown = index if np.ndim(mask) and mask.size > 1 else ()
        value = repr(float(values[index]))
        if is_quantity(given):
            number = np.broadcast_to(np.atleast_1d(given.value), mask.shape)[index]
            value = f"{float(number)!r} {given.unit.to_string()}".rstrip()  # (dimensionless)
        raise ValueError(f"Expected `{name}` {what}, got {value}{fmt_index(shown)}")


def clamp_inc(inc: np.ndarray) -> np.ndarray:
    """``inc`` with an excess of at most two ulp over the float pi taken as pi: the
    conversion of exactly 180 degrees from another unit rounds there (648 000 000 mas
    gives one ulp above pi), an inclination no element set can mean otherwise; the
    rest, beyond, is refused by the caller."""
    inc = np.asarray(inc, dtype=np.float64)
    return np.where((inc > np.pi) & (inc <= _PI_PLUS_2ULP), np.pi, inc)


def element_inputs(lengths: dict, anomalies: dict, e, inc, lan, argp, mu):
    """The arguments of :meth:`KeplerOrbit.from_elements` checked and as floats.

    ``lengths`` maps ``a``, ``p``, ``q`` and ``anomalies`` ``nu``, ``M`` to the
    values given (None if not); exactly one of each must be given.  Returns
    ``(lname, length, aname, angle, e, inc, lan, argp, mu, quantity)``: the
    name and value of the length and of the anomaly given, and every value as
    float arrays broadcast together (km and km^3/s^2 if ``quantity``), with
    ``e >= 0``, ``mu > 0`` and ``inc`` in [0, pi] checked.  A list of Quantities
    is one Quantity (:func:`hamilton_orbits.units.as_quantity`)."""
    if sum(x is not None for x in lengths.values()) != 1:
        raise ValueError("Expected exactly one of `a`, `p`, `q`")
    if sum(x is not None for x in anomalies.values()) != 1:
        raise ValueError("Expected exactly one of `nu`, `M`")
    lname, lval = next((k, x) for k, x in lengths.items() if x is not None)
    aname, aval = next((k, x) for k, x in anomalies.items() if x is not None)
    lval, aval, mu = as_quantity(lname, lval), as_quantity(aname, aval), as_quantity("mu", mu)
    e, inc, lan, argp = (as_quantity(n, x) for n, x in
                         (("e", e), ("inc", inc), ("lan", lan), ("argp", argp)))
    quantity = is_quantity(lval) or is_quantity(mu)
    if quantity and not (is_quantity(lval) and is_quantity(mu)):
        raise ValueError(
            f"Expected `{lname}` and `mu` to be both Quantities or both plain floats"
        )
    values = broadcast(
        ("e", "inc", "lan", "argp", "mu", lname, aname),
        DIMENSIONLESS("e", e), ANGLE("inc", inc), ANGLE("lan", lan), ANGLE("argp", argp),
        GM("mu", mu, _MU), LENGTH(lname, lval, _L), ANGLE(aname, aval),
    )
    e_, inc_, lan_, argp_, mu_, length, angle = values
    raise_at("e", ~(e_ >= 0), e_, ">= 0", e)
    raise_at("mu", ~(mu_ > 0), mu_, "> 0", mu)
    inc_ = clamp_inc(inc_)
    raise_at("inc", ~((inc_ >= 0) & (inc_ <= np.pi)), inc_, "in [0, pi] rad", inc)
    return lname, length, aname, angle, e_, inc_, lan_, argp_, mu_, quantity


def p_and_inv_a(lname: str, length: np.ndarray, e: np.ndarray, given: Any = None):
    """``(p, 1/a, radial)`` from ``a``, ``p`` or ``q`` (``lname``) and ``e``;
    ``radial`` where ``e == 1`` with ``a`` given (the rectilinear orbit of that
    energy).  Refuses ``a`` and ``e`` inconsistent, ``p`` or ``q`` <= 0 (``given``:
    the length as written, for the message), and ``p`` or ``1/a`` beyond float64
    (:func:`_refuse_beyond`)."""
    if lname != "a":
        raise_at(lname, ~(length > 0), length, "> 0", given)
        with np.errstate(over="ignore", invalid="ignore"):
            p = length if lname == "p" else length * (1.0 + e)
            inv_a = (1.0 - e) * (1.0 + e) / p
        _refuse_beyond(lname, length, e, p, inv_a, given)
        return p, inv_a, np.zeros(e.shape, dtype=bool)
    raise_at("a", length == 0, length, "nonzero", given)
    raise_at("a", (length > 0) & (e > 1), length, "< 0 for e > 1 (a and e inconsistent)", given)
    raise_at("a", (length < 0) & (e < 1), length, "> 0 for e < 1 (a and e inconsistent)", given)
    radial = e == 1.0
    with np.errstate(over="ignore", invalid="ignore"):
        p = length * (1.0 - e) * (1.0 + e)
        inv_a = np.where(radial, 1.0 / length, (1.0 - e) * (1.0 + e) / np.where(radial, 1, p))
    _refuse_beyond("a", length, e, p, inv_a, given)
    return p, inv_a, radial


def _refuse_beyond(lname: str, length: np.ndarray, e: np.ndarray, p: np.ndarray,
                   inv_a: np.ndarray, given: Any) -> None:
    """Refuse ``1 - e^2`` beyond float64, naming ``e`` (e ~ 1e200: the length was
    named, after a RuntimeWarning), and ``p`` beyond it, naming the length ``lname``
    (as the caller refuses a state beyond float64).  A ``1/a`` beyond float64 alone
    (``inv_a`` inf: a length below 1/1.8e308, subnormal) is no refusal: the state
    of such an orbit is built, and its elements refuse what does not fit, by name."""
    with np.errstate(over="ignore"):
        e_bad = ~np.isfinite((1.0 - e) * (1.0 + e))
    raise_at("e", e_bad, e, "for which 1 - e^2 fits in float64")
    raise_at(lname, ~np.isfinite(p), length, "to give a finite state (check the elements)",
             given)


def anomaly_of(aname: str, angle: np.ndarray, e: np.ndarray, radial: np.ndarray,
               inv_a: np.ndarray, given: Any = None):
    """The anomaly (E, D or F by ``e``) from ``nu`` or ``M`` (``aname``); NaN
    for a radial orbit (its M is solved by :func:`_radial_from_mean`).
    Refuses ``nu`` for a radial orbit or beyond the asymptote, a radial orbit's
    ``M`` at its collision with the centre (0: r = 0 at infinite speed) or, bound
    (``inv_a > 0``), outside (-pi, pi], and a Kepler equation not solved
    (ConvergenceError)."""
    if aname == "nu":
        raise_at(
            "nu", radial, angle, "to be replaced by `M` for a radial orbit (e == 1, a given)",
            given)
        anom = np.asarray(_kk.anomaly_from_nu_ufunc(angle, e))
        raise_at("nu", ~np.isfinite(anom), angle, "inside the asymptotes (1 + e cos nu > 0)",
                 given)
        return anom
    raise_at("M", radial & (angle == 0), angle, "!= 0 for a radial orbit (M = 0 is its "
             "collision with the centre: r = 0 at infinite speed)", given)
    raise_at("M", radial & (inv_a > 0) & ~((angle > -np.pi) & (angle <= np.pi)), angle,
             "in (-pi, pi] for a radial orbit", given)
    with np.errstate(invalid="ignore"):
        anom = np.asarray(_kk.solve_ufunc(angle, np.where(radial, 0.0, e)))
    bad = ~np.isfinite(anom) & ~radial
    if np.any(bad):
        index = first_index(np.atleast_1d(bad))
        raise ConvergenceError(
            f"Kepler's equation not solved for `M` = "
            f"{float(np.atleast_1d(angle)[index])!r}{fmt_index(index if bad.ndim else ())}"
        )
    return anom


def refuse_unreadable(state: np.ndarray, e: np.ndarray, inv_a: np.ndarray, aname: str,
                      angle: np.ndarray, given_e: Any = None, given_angle: Any = None) -> None:
    """Refuse elements whose state the elements kernel cannot read back although every
    element fits in float64: ``|r| |v|^2 / mu`` beyond its range, 2^450 ~ 3e135 (far
    out on a hyperbola it is ~ ``|M|``, at periapsis ~ ``e``).  The orbit keeps its state
    only, so that its ``e``, ``M`` ... would be refused when read, naming `r`, `v`, `mu`
    the caller never passed; named here instead: ``M`` (``aname``) where ``|M| >= e``,
    else ``e``.  A state whose ``1/a`` itself is beyond float64 (a subnormal length) is
    built, as before: its elements do not fit, and are refused by name when read.

    Parameters
    ----------
    state : ndarray, shape (..., 7)
        The state built (:func:`state_of`).
    e, inv_a, angle : ndarray, shape (...)
        The eccentricity, ``1/a`` and the anomaly given (radians).
    aname : str
        ``"nu"`` or ``"M"``.
    given_e, given_angle : optional
        ``e`` and the anomaly as the caller wrote them (for the message).

    Raises
    ------
    ValueError
        Naming the argument, its first such index and its value.
    """
    rows = state.reshape(-1, 7)
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        vm = np.max(np.abs(rows[:, 3:6]), axis=-1)
        x = np.max(np.abs(rows[:, :3]), axis=-1) * vm * vm / rows[:, 6]
    suspect = ~(x < _SUSPECT) & np.isfinite(inv_a).reshape(-1)
    if not np.any(suspect):
        return
    idx = np.flatnonzero(suspect)
    sub = np.ascontiguousarray(rows[idx])
    out = np.empty((idx.size, NCLASSICAL))
    _el.state_to_elements_classical(*_el.row_columns(sub), out)
    bad = np.zeros(rows.shape[0], dtype=bool)
    bad[idx] = ~np.all(np.isfinite(out[:, :-1]), axis=-1)  # (a, the last, NaN with them)
    bad = bad.reshape(e.shape)
    if not np.any(bad):
        return
    index = first_index(np.atleast_1d(bad))
    use_m = aname == "M" and abs(np.atleast_1d(angle)[index]) >= np.atleast_1d(e)[index]
    name, values, given = (aname, angle, given_angle) if use_m else ("e", e, given_e)
    raise_at(name, bad, values,
             "for which the state's elements can be read back (|r| |v|^2 / mu, ~ |M| far "
             "out on a hyperbola and ~ e at periapsis, below 2^450 ~ 3e135)", given)


def state_of(p, e, inv_a, inc, lan, argp, anom, radial, mu, m):
    """The state (..., 7) of the elements (one compiled pass; radial orbits
    from their mean anomaly ``m``)."""
    shape = e.shape
    el = np.stack(
        [p * 1.0, e * 1.0, inv_a * 1.0, inc, lan, argp, np.where(radial, 0.0, anom)],
        axis=-1,
    ).reshape(-1, 7)
    flat_mu = np.ascontiguousarray(mu.reshape(-1), dtype=np.float64)
    state = np.empty((*shape, 7))
    rows = state.reshape(-1, 7)
    rows[:, 6] = flat_mu
    r_out, v_out = rows[:, :3], rows[:, 3:6]
    el[:, 0] = np.where(radial.reshape(-1), 0.0, el[:, 0])
    _el.elements_to_state(np.ascontiguousarray(el), flat_mu, r_out, v_out)
    if np.any(radial):
        _radial_from_mean(el, flat_mu, m.reshape(-1), radial.reshape(-1), r_out, v_out)
    return state


def _radial_from_mean(el, mu, m, radial, r_out, v_out) -> None:
    """States of radial orbits from their mean anomaly (in place).

    Kepler's equation of the rectilinear orbit (e = 1, a finite),
    ``E - sin E = M`` or ``sinh F - F = M``, is solved directly
    (:func:`hamilton_orbits._kernels.kepler.solve_radial`), and the state is
    ``r = a (1 - cos E) = 2 a sin^2(E/2)`` (``|a| (cosh F - 1)``) on the line, so
    that a tiny M keeps full relative precision (E ~ (6 M)^(1/3)).
    """
    idx = np.flatnonzero(radial)
    mm = m[idx]
    rows = np.ascontiguousarray(el[idx])
    rows[:, 0] = 0.0
    rows[:, 6] = _kk.solve_radial_ufunc(mm, rows[:, 2])
    r1 = np.empty((idx.size, 3))
    v1 = np.empty((idx.size, 3))
    _el.elements_to_state(rows, np.ascontiguousarray(mu[idx]), r1, v1)
    r_out[idx] = r1
    v_out[idx] = v1
