"""Hamilton's integrals (C), (D), (E): of a system, and how well a run keeps them.

From his n-body equation (B) Hamilton (1845) deduces the laws of the centre of
gravity (C), of areas (D) and of vis viva (E); a
:class:`~hamilton_orbits.nbody.System` gives them for its state
(``barycentre()``, ``angular_momentum()``, ``energy()``).  This module measures
how well the states of a run keep them (:func:`integral_errors`, one compiled
pass of :mod:`hamilton_orbits._kernels.integrals`; :class:`LostStateError` for a
state that became non-finite), gives (E) on plain arrays (:func:`energy_gm`,
:func:`energy_gm_many`), and evaluates (B) itself with quaternion products
(:func:`accelerations_quaternion`), a reference for the compiled kernel.

References
----------
W. R. Hamilton, "On the application of the method of quaternions to some dynamical
questions", Proc. R. Irish Acad. 3 (1847), Appendix, pp. xxxvi-l: equations (A)-(E).
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["LostStateError", "accelerations_quaternion", "energy_gm",
           "energy_gm_many", "integral_errors", "relative_change"]


def energy_gm(r: np.ndarray, v: np.ndarray, gm: np.ndarray) -> float:
    """Hamilton's (E) in gm units; pairs with at least one massless body add nothing."""
    kinetic = 0.5 * float(gm @ np.einsum("ij,ij->i", v, v))
    idx = np.flatnonzero(gm > 0)
    rm = r[idx]
    gmm = gm[idx]
    if len(idx) < 2:
        return kinetic
    i, j = np.triu_indices(len(idx), 1)
    d = np.sqrt(np.einsum("ij,ij->i", rm[i] - rm[j], rm[i] - rm[j]))
    return kinetic - float(np.sum(gmm[i] * gmm[j] / d))


def energy_gm_many(r: np.ndarray, v: np.ndarray, gm: np.ndarray) -> np.ndarray:
    """Hamilton's (E) in gm units for states ``r``, ``v`` of shape (n_t, n, 3);
    ``gm`` (n,), or (n_t, n) where masses change between states."""
    gm_t = np.broadcast_to(gm, r.shape[:2])
    kinetic = 0.5 * np.einsum("tj,tjk,tjk->t", gm_t, v, v)
    idx = np.flatnonzero((gm_t > 0).any(axis=0))
    if len(idx) < 2:
        return kinetic
    i, j = np.triu_indices(len(idx), 1)
    rm = r[:, idx]
    d = rm[:, i] - rm[:, j]
    dist = np.sqrt(np.einsum("tpk,tpk->tp", d, d))
    g = gm_t[:, idx]
    pair = g[:, i] * g[:, j]
    return kinetic - np.where(pair != 0.0, pair / np.where(dist > 0, dist, 1.0), 0.0).sum(axis=1)


def integral_errors(
    r: np.ndarray, v: np.ndarray, gm: np.ndarray, t: np.ndarray,
    extra_energy: np.ndarray | None = None,
    gone: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """How well states ``r``, ``v`` (n_t, n, 3) at times ``t`` (n_t,) keep Hamilton's
    integrals, relative to the first state.

    ``gm`` is (n,), or (n_t, n) where masses changed during the run (merges);
    bodies with NaN states (taken out of the run) count as absent.  One compiled
    pass over the states (:func:`hamilton_orbits._kernels.integrals.integral_sums`,
    the energy's sums compensated).

    Parameters
    ----------
    r, v : ndarray, shape (n_t, n, 3)
    gm : ndarray, shape (n,) or (n_t, n)
    t : ndarray, shape (n_t,)
    extra_energy : ndarray, shape (n_t, n), optional
        The effects' part of each body's specific energy
        (:func:`hamilton_orbits.effects.effect_energy`), added so that the energy
        compared is the one the equations of motion keep.
    gone : ndarray of bool, shape (n,), optional
        The bodies an event took out of the run.  When given, a non-finite state
        of any other body raises ``LostStateError`` (a ``ValueError``) with the
        output and body index in ``index``.

    Returns
    -------
    energy_error : ndarray, (n_t,)
        ``(E(t) - E(0)) / |E(0)|``, vis viva (E); absolute where ``E(0) = 0``.
        With one massive body and test particles, whose masses do not enter
        Hamilton's E (it would be constant, and its error a meaningless 0), the
        specific orbital energies of the test particles about the massive body,
        ``w^2 / 2 - mu / d`` (plus ``extra_energy``), each relative to its own
        start: at each time the one of largest magnitude.
    angular_momentum_error : ndarray, (n_t,)
        ``|L(t) - L(0)| / |L(0)|``, areas (D); absolute where ``L(0) = 0``.
    barycentre_drift : ndarray, (n_t,)
        ``|R(t) - R(0) - V(0) t| / s`` with ``s`` the largest distance from the
        initial centre of mass, centre of gravity (C).

    Examples
    --------
    >>> r = np.array([[[0.0, 0, 0], [1.0, 0, 0]]] * 2); v = np.zeros((2, 2, 3))
    >>> [x.tolist() for x in integral_errors(r, v, np.array([1.0, 1.0]), np.array([0.0, 1.0]))]
    [[0.0, 0.0], [0.0, 0.0], [0.0, 0.0]]
    >>> v[1, 1, 1] = 2.0**-10  # a test particle that gained speed: its energy changed
    >>> integral_errors(r, v, np.array([1.0, 0.0]), np.array([0.0, 1.0]))[0].tolist()
    [0.0, 4.76837158203125e-07]
    """
    from hamilton_orbits._kernels import integrals

    r = np.ascontiguousarray(r, dtype=np.float64)
    v = np.ascontiguousarray(v, dtype=np.float64)
    gm2 = np.ascontiguousarray(np.atleast_2d(np.asarray(gm, dtype=np.float64)))
    t = np.ascontiguousarray(t, dtype=np.float64)
    k, n = r.shape[0], r.shape[1]
    out = np.empty((3, k))
    gone_b = np.zeros(n, np.bool_) if gone is None else np.ascontiguousarray(gone, np.bool_)
    lost = integrals.integral_errors(r, v, gm2, t, gone_b, out[0], out[1], out[2])
    if gone is not None and lost >= 0:
        raise LostStateError(divmod(int(lost), n))
    if extra_energy is not None or _one_centre(gm2):
        out[0] = _energy_error(*_present(r, v, gm), extra_energy)
    return out[0], out[1], out[2]


def _one_centre(gm: np.ndarray) -> bool:
    """One massive body and test particles, masses unchanged (``gm`` (1, n))."""
    return gm.shape[0] == 1 and gm.shape[1] > 1 and int(np.count_nonzero(gm[0] > 0)) == 1


def _present(r: np.ndarray, v: np.ndarray, gm: np.ndarray
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The states with the bodies taken out of the run (non-finite) set to zero
    mass at the origin; ``gm`` (n,) when nothing was taken out and it was (n,)."""
    present = np.isfinite(r).all(axis=2) & np.isfinite(v).all(axis=2)
    if present.all():
        return r, v, gm
    gm_t = np.where(present, np.broadcast_to(gm, r.shape[:2]), 0.0)
    return (np.where(present[..., None], r, 0.0), np.where(present[..., None], v, 0.0), gm_t)


class LostStateError(ValueError):
    """A body's state became non-finite during a run; ``index`` is ``(output, body)``."""

    def __init__(self, index: tuple[int, int]) -> None:
        super().__init__(f"non-finite state at output {index[0]}, body {index[1]}")
        self.index = index


def _energy_error(r: np.ndarray, v: np.ndarray, gm: np.ndarray,
                  extra: np.ndarray | None) -> np.ndarray:
    """The energy part of :func:`integral_errors`."""
    if np.ndim(gm) == 2:  # masses changed (a merge, a removal): Hamilton's E as it is
        energy = energy_gm_many(r, v, gm)
        if extra is not None:
            energy = energy + np.einsum("tj,tj->t", extra, gm)
        return relative_change(energy)
    massive = np.flatnonzero(gm > 0)
    if len(massive) != 1 or len(gm) == 1:
        energy = energy_gm_many(r, v, gm)
        if extra is not None:
            energy = energy + extra @ gm
        return relative_change(energy)
    s = int(massive[0])
    tp = np.flatnonzero(gm == 0)
    d = r[:, tp] - r[:, s:s + 1]
    w = v[:, tp] - v[:, s:s + 1]
    eps = 0.5 * np.einsum("tij,tij->ti", w, w) - gm[s] / np.sqrt(np.einsum("tij,tij->ti", d, d))
    if extra is not None:
        eps = eps + extra[:, tp]
    scale = np.abs(eps[0])
    change = (eps - eps[0]) / np.where(scale > 0, scale, 1.0)
    pick = np.argmax(np.abs(change), axis=1)
    return change[np.arange(len(change)), pick]


def accelerations_quaternion(r: Any, gm: Any) -> np.ndarray:
    """Equation (B) evaluated with :class:`~hamilton_orbits.quaternion.Quaternion` products.

    Exactly as Hamilton writes it: for each body alpha and each other body alpha' of
    mass m', the term ``m' / ((alpha - alpha') sqrt(-(alpha - alpha')^2))``, where
    ``alpha - alpha'`` is a pure quaternion (a vector), its square
    ``(alpha - alpha')^2 = -|alpha - alpha'|^2`` is a negative real number, and the
    quotient is a quaternion product with the inverse.  A reference for the compiled
    kernel (O(n^2) memory; for tests).

    Parameters
    ----------
    r : array_like, shape (n, 3)
    gm : array_like, shape (n,)

    Returns
    -------
    ndarray, shape (n, 3)

    Examples
    --------
    >>> accelerations_quaternion([[0.0, 0, 0], [2.0, 0, 0]], [1.0, 0.0])
    array([[ 0.  ,  0.  ,  0.  ],
           [-0.25,  0.  ,  0.  ]])
    """
    from hamilton_orbits.quaternion import Quaternion

    r = np.asarray(r, dtype=float)
    gm = np.asarray(gm, dtype=float)
    n = len(gm)
    i, j = np.nonzero(~np.eye(n, dtype=bool) & (gm[None, :] != 0))
    alpha = Quaternion.from_vector(r[i] - r[j])  # alpha - alpha'
    square = (alpha * alpha).scalar  # (alpha - alpha')^2 = -T^2, a real number
    denominator = alpha * np.sqrt(-square)  # (alpha - alpha') sqrt(-(alpha - alpha')^2)
    term = denominator.inverse() * gm[j]  # m' / (...)
    acc = np.zeros((n, 4))
    np.add.at(acc, i, term.as_array())
    return acc[:, 1:]


def relative_change(values: np.ndarray) -> np.ndarray:
    """``(x(t) - x(0)) / |x(0)|`` for scalars, ``|x(t) - x(0)| / |x(0)|`` for
    vectors (last axis), and the absolute change where ``x(0) = 0``.

    Parameters
    ----------
    values : ndarray, shape (n_t,) or (n_t, k)

    Examples
    --------
    >>> relative_change(np.array([2.0, 2.0, 3.0])).tolist()
    [0.0, 0.0, 0.5]
    >>> relative_change(np.array([[0.0, 2.0], [0.0, 2.0], [2.0, 2.0]])).tolist()
    [0.0, 0.0, 1.0]
    >>> relative_change(np.zeros(2)).tolist()
    [0.0, 0.0]
    """
    x = np.asarray(values, dtype=np.float64)
    if x.ndim == 1:
        scale = abs(x[0])
        d = x - x[0]
    else:
        scale = float(np.linalg.norm(x[0]))
        d = np.linalg.norm(x - x[0], axis=-1)
    return d / scale if scale > 0 else d
