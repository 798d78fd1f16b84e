"""Hamilton's integrals (C), (D), (E): of a system, and how well a run keeps them.

From his n-body equation (B) Hamilton (1845) deduces the laws of the centre of
gravity (C), of areas (D) and of vis viva (E); a
:class:`~hamilton_orbits.nbody.System` gives them for its state
(``barycentre()``, ``angular_momentum()``, ``energy()``).  This module measures
how well the states of a run keep them (:func:`integral_errors`, one compiled
pass of ``hamilton_orbits._kernels.integrals``; :class:`LostStateError` for a
state that became non-finite), gives (E) on plain arrays (:func:`energy_gm`,
:func:`energy_gm_many`), and evaluates (B) itself with quaternion products
(:func:`accelerations_quaternion`), a reference for the compiled kernel.

Test particles (massless bodies) do not enter Hamilton's integrals; each gets
its own check (:func:`particle_errors`: its Jacobi constant, or its two-body
energy about its primary), and a fixed step too long for a close approach (a
particle's to a massive body, a massive body's to a heavier one) is found at the outputs
(:func:`under_resolved_encounters`, :class:`UnderResolvedEncounterWarning`).

References
----------
W. R. Hamilton, "On the application of the method of quaternions to some dynamical
questions", Proc. R. Irish Acad. 3 (1847), Appendix, pp. xxxvi-l: equations (A)-(E).
"""

from __future__ import annotations

from contextvars import ContextVar
from typing import Any, NamedTuple

import numpy as np

__all__ = [
    "ENCOUNTER_STEP_FRACTION",
    "LIGHT",
    "NEAR_ZERO",
    "WARN_UNDER_RESOLVED",
    "Encounter",
    "LostStateError",
    "UnderResolvedEncounterWarning",
    "accelerations_quaternion",
    "energy_gm",
    "energy_gm_many",
    "integral_errors",
    "light_as_massless",
    "particle_errors",
    "prepare",
    "primaries",
    "relative_change",
    "under_resolved_encounters",
]

#: A fixed step of a second-order map (``wh``, ``leapfrog``) is too long for a close
#: approach when it exceeds this fraction of the approach's time scale
#: (:func:`under_resolved_encounters`): the comet of the ``comet-encounter`` scene
#: past Jupiter (time scale 2.1 d) ends with ``wh`` at 0.1 d on ``1/a`` off by twice
#: what the encounter changed, at 0.05 d by 1% of it, at 0.02 d by 3e-6.
ENCOUNTER_STEP_FRACTION = 1.0 / 30.0
#: A body whose GM is at most this fraction of the largest (a comet, a small
#: asteroid) is checked as a test particle (:func:`under_resolved_encounters`): its
#: own pull does not matter to whether its approaches are resolved (a comet of GM
#: 1e-12 through a sungrazing passage went unwarned where GM 0 was warned of).
LIGHT = 1e-10
#: The largest eccentricity of the two massive bodies' mutual orbit for which a test
#: particle's Jacobi constant is its check (it varies by about that much).
JACOBI_MAX_ECCENTRICITY = 1e-6


def _checked_states(r: Any, v: Any, gm: Any, *, many: bool, finite: bool = True
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``r``, ``v`` and ``gm`` as float64 arrays, checked at once (vectorised, before any
    kernel reads them): ``r`` of shape (n_t, n, 3) with ``n_t >= 1`` (``many``) or (n,
    3), ``v`` of r's shape, ``gm`` (n,) (or (n_t, n), or (1, n), with ``many``), finite
    and ``>= 0``; ``r`` and ``v`` finite where ``finite``.

    Raises
    ------
    ValueError
        Naming the argument and its shape, or the index and the value.
    """
    from hamilton_orbits.validation import as_float_array, check_positive

    r = as_float_array("r", r, finite=finite)
    v = as_float_array("v", v, finite=finite)
    gm = as_float_array("gm", gm)
    if r.ndim != (3 if many else 2) or r.shape[-1] != 3 or (many and r.shape[0] == 0):
        want = "(n_t, n, 3) with n_t >= 1" if many else "(n, 3)"
        raise ValueError(f"Expected `r` to have shape {want}, got {r.shape}")
    if v.shape != r.shape:
        raise ValueError(f"Expected `v` to have the shape of `r`, {r.shape}, got {v.shape}")
    n = r.shape[-2]
    shapes = [(n,), (r.shape[0], n), (1, n)] if many else [(n,)]
    if gm.shape not in shapes:
        raise ValueError(f"Expected `gm` to have shape {' or '.join(map(str, shapes[:2]))} "
                         f"for `r` of shape {r.shape}, got {gm.shape}")
    check_positive("gm", gm, strict=False)
    return r, v, gm


def _refuse_coinciding(r: np.ndarray, i: np.ndarray, j: np.ndarray, zero: np.ndarray,
                       where: str = "") -> None:
    """Refuse the first pair ``(i[k], j[k])`` of bodies at one position (``zero[k]``),
    naming their indices in ``r`` (the potential between them is infinite)."""
    if zero.any():
        k = int(np.argmax(zero))
        a, b = int(i[k]), int(j[k])
        raise ValueError(f"Bodies at indices {a} and {b} of `r` are at one position "
                         f"{r[a].tolist()}{where}: their potential energy is infinite")


def energy_gm(r: Any, v: Any, gm: Any) -> float:
    """Hamilton's (E) in gm units; pairs with at least one massless body add nothing.

    Parameters
    ----------
    r, v : array_like, shape (n, 3)
        Finite positions and velocities, in the caller's consistent units.
    gm : array_like, shape (n,)
        ``G m >= 0``, finite.

    Returns
    -------
    float
        ``sum gm v^2 / 2 - sum_{pairs} gm gm' / d``.

    Raises
    ------
    ValueError
        Naming the argument and its shape, or the index and the value: shapes that do
        not match, a non-finite value, a negative ``gm``, two massive bodies at one
        position (both indices in ``r``).

    Examples
    --------
    >>> energy_gm([[0.0, 0, 0], [2.0, 0, 0]], [[0.0, 0, 0], [0, 1.0, 0]], [1.0, 1.0])
    0.0
    """
    r, v, gm = _checked_states(r, v, gm, many=False)
    kinetic = 0.5 * float(gm @ np.einsum("ij,ij->i", v, v))
    idx = np.flatnonzero(gm > 0)
    rm = r[idx]
    gmm = gm[idx]
    if len(idx) < 2:
        return kinetic
    i, j = np.triu_indices(len(idx), 1)
    d = np.sqrt(np.einsum("ij,ij->i", rm[i] - rm[j], rm[i] - rm[j]))
    _refuse_coinciding(r, idx[i], idx[j], d == 0)
    return kinetic - float(np.sum(gmm[i] * gmm[j] / d))


def energy_gm_many(r: Any, v: Any, gm: Any) -> np.ndarray:
    """Hamilton's (E) in gm units for many states.

    Parameters
    ----------
    r, v : array_like, shape (n_t, n, 3)
        Finite positions and velocities, in the caller's consistent units.
    gm : array_like, shape (n,), or (n_t, n) where masses change between states
        ``G m >= 0``, finite.

    Returns
    -------
    ndarray, shape (n_t,)

    Raises
    ------
    ValueError
        As :func:`energy_gm`, two massive bodies at one position named with the output.

    Examples
    --------
    >>> r = np.array([[[0.0, 0, 0], [2.0, 0, 0]]] * 2); v = np.zeros((2, 2, 3))
    >>> energy_gm_many(r, v, np.array([[1.0, 1.0], [1.0, 0.0]])).tolist()
    [-0.5, 0.0]
    """
    r, v, gm = _checked_states(r, v, gm, many=True)
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
    zero = (pair != 0.0) & (dist == 0.0)
    if zero.any():
        out, p = np.unravel_index(int(np.argmax(zero)), zero.shape)
        _refuse_coinciding(r[out], idx[i[p:p + 1]], idx[j[p:p + 1]], np.ones(1, bool),
                           f" at output {int(out)}")
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
    pass over the states (``hamilton_orbits._kernels.integrals.integral_sums``,
    the energy's sums compensated).

    Parameters
    ----------
    r, v : ndarray, shape (n_t, n, 3)
    gm : ndarray, shape (n,) or (n_t, n)
    t : ndarray, shape (n_t,)
    extra_energy : ndarray, shape (n_t, n), optional
        The effects' part of each body's specific energy
        (``hamilton_orbits.effects.effect_energy``), added so that the energy
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
        start (to the size of its terms where that start is near 0,
        :data:`NEAR_ZERO`): at each time the one of largest magnitude among the
        particles still in the run, 0 where none is left.
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
    from hamilton_orbits.validation import as_float_array, read_only

    # (checked before the kernel, which reads ``v``, ``gm`` and ``t`` by r's shape; r and
    # v may hold NaN: the bodies taken out of the run)
    r, v, gm = _checked_states(r, v, gm, many=True, finite=False)
    k, n = r.shape[0], r.shape[1]
    t = as_float_array("t", t)
    for name, value, shape in (("t", t, (k,)), ("extra_energy", extra_energy, (k, n)),
                               ("gone", gone, (n,))):
        if value is not None and np.shape(value) != shape:
            raise ValueError(f"Expected `{name}` to have shape {shape} for `r` of shape "
                             f"{r.shape}, got {np.shape(value)}")
    # the kernel's inputs as read-only views, whatever they came as (a trajectory's
    # are read-only, a run's own states and a merged run's G m writable: each mix was
    # another type, compiled again, 1.3-1.7 s a time)
    r, v, gm2, t, gone_b = (read_only(np.ascontiguousarray(a)) for a in (
        r, v, np.atleast_2d(gm), np.asarray(t, dtype=np.float64),
        np.zeros(n, np.bool_) if gone is None else np.asarray(gone, np.bool_)))
    out = np.empty((3, k))
    lost = integrals.integral_errors(r, v, gm2, t, gone_b, out[0], out[1], out[2])
    if gone is not None and lost >= 0:
        raise LostStateError(divmod(int(lost), n))
    if _one_centre(gm2):  # (the particles' own energies; one removed is NaN from then
        out[0] = _energy_error(r, v, gm2[0], extra_energy)  # on, passed over)
    elif extra_energy is not None:
        out[0] = _energy_error(*_present(r, v, gm), extra_energy)
    else:
        out[0] = _near_zero_scaled(out[0], r[0], v[0], gm2[0])
    return out[0], out[1], out[2]


#: where ``|E(0)|`` is below this fraction of the size of its terms (the kinetic
#: energy plus the magnitude of the potential), it is known to fewer than half its
#: digits (a parabola, a pair at escape speed: E(0) is their rounding residue, 1e-19
#: beside terms of 1e-4), and a change relative to it reads O(1) for a perfect run:
#: the energy error is then relative to the size of the terms
NEAR_ZERO = 2.0**-26


def _terms(r: np.ndarray, v: np.ndarray, gm: np.ndarray) -> tuple[float, float]:
    """Hamilton's E of one state (gm units) and the size of its terms, ``T + |U|``
    (the bodies of a non-finite state left out)."""
    ok = np.isfinite(r).all(axis=1) & np.isfinite(v).all(axis=1)
    r, v, gm = r[ok], v[ok], gm[ok]
    kinetic = 0.5 * float(np.einsum("j,jk,jk->", gm, v, v))
    potential = kinetic - energy_gm(r, v, gm)
    return kinetic - potential, kinetic + abs(potential)


def _near_zero_scaled(error: np.ndarray, r0: np.ndarray, v0: np.ndarray,
                      gm0: np.ndarray) -> np.ndarray:
    """The energy error ``(E - E0) / |E0|`` (absolute where ``E0 = 0``) relative to
    the size of E's terms instead, where ``|E0|`` is below :data:`NEAR_ZERO` of it."""
    e0, size = _terms(r0, v0, gm0)
    if not (size > 0 and abs(e0) < NEAR_ZERO * size):
        return error
    return error * (abs(e0) / size) if e0 != 0 else error / size


def prepare() -> None:
    """Compile the kernel of :func:`integral_errors` for the types a run gives it
    (``G m`` read-only, as a system's are), by a call on two states of two bodies:
    a first run that has a core to spare compiles it while it waits for another
    (``hamilton_orbits._kernels.entry.compile_ahead``).

    Examples
    --------
    >>> prepare()  # (compiled, or loaded from numba's cache)
    """
    r = np.zeros((2, 2, 3))
    r[:, 1, 0] = 1.0
    gm = np.array([1.0, 1e-3])
    gm.flags.writeable = False
    integral_errors(r, np.zeros((2, 2, 3)), gm, np.array([0.0, 1.0]))


def _one_centre(gm: np.ndarray) -> bool:
    """One massive body and test particles, its mass unchanged (``gm`` (1, n), or (n_t,
    n) where events took test particles out of the run, or merged them into it)."""
    massive = gm[0] > 0
    return (gm.shape[1] > 1 and int(np.count_nonzero(massive)) == 1
            and bool(np.all((gm > 0) == massive))
            and bool(np.all(gm[:, massive] == gm[0, massive])))


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
    # (a body taken out, G m = 0, adds no effect energy: its NaN times 0 was NaN)
    if np.ndim(gm) == 2:  # masses changed (a merge, a removal): Hamilton's E as it is
        energy = energy_gm_many(r, v, gm)
        effect = 0.0 if extra is None else np.einsum("tj,tj->t", np.where(gm > 0, extra, 0.0),
                                                      gm)
        return _near_zero_scaled(relative_change(energy + effect), r[0], v[0], gm[0])
    massive = np.flatnonzero(gm > 0)
    if len(massive) != 1 or len(gm) == 1:
        energy = energy_gm_many(r, v, gm)
        effect = 0.0 if extra is None else np.where(gm > 0, extra, 0.0) @ gm
        return _near_zero_scaled(relative_change(energy + effect), r[0], v[0], gm)
    s = int(massive[0])
    tp = np.flatnonzero(gm == 0)
    d = r[:, tp] - r[:, s:s + 1]
    w = v[:, tp] - v[:, s:s + 1]
    kinetic = 0.5 * np.einsum("tij,tij->ti", w, w)
    potential = gm[s] / np.sqrt(np.einsum("tij,tij->ti", d, d))
    eps = kinetic - potential
    size = kinetic[0] + potential[0]
    if extra is not None:
        eps = eps + extra[:, tp]
        size = size + np.abs(extra[0, tp])
    # (each relative to its own start, or to the size of its terms where the start
    # is near 0: NEAR_ZERO)
    scale = np.where(np.abs(eps[0]) >= NEAR_ZERO * size, np.abs(eps[0]), size)
    change = (eps - eps[0]) / np.where(scale > 0, scale, 1.0)
    # (the largest over the particles still in the run: a removed one's is NaN; where
    # none is left, 0: the one body alone keeps its energy)
    finite = np.isfinite(change)
    pick = np.argmax(np.where(finite, np.abs(change), -1.0), axis=1)
    return np.where(finite.any(axis=1), change[np.arange(len(change)), pick], 0.0)


def accelerations_quaternion(r: Any, gm: Any) -> Any:
    """Equation (B) evaluated with :class:`~hamilton_orbits.quaternion.Quaternion` products.

    Exactly as Hamilton writes it: for each body alpha and each other body alpha' of
    mass m', the term ``m' / ((alpha - alpha') sqrt(-(alpha - alpha')^2))``, where
    ``alpha - alpha'`` is a pure quaternion (a vector), its square
    ``(alpha - alpha')^2 = -|alpha - alpha'|^2`` is a negative real number, and the
    quotient is a quaternion product with the inverse.  A reference for the compiled
    kernel (O(n^2) memory; for tests).

    Parameters
    ----------
    r : Quantity or array_like, shape (n, 3)
        Positions (a Quantity: any length unit).
    gm : Quantity or array_like, shape (n,)
        ``G m >= 0`` (a Quantity: any unit of a gravitational parameter); both
        Quantities or both plain floats in the caller's consistent units.

    Returns
    -------
    ndarray or Quantity, shape (n, 3)
        In au/day^2 for Quantities (as ``System.accelerations``);
        else in the caller's units.

    Raises
    ------
    ValueError
        Naming the argument, the index and the value: a non-finite ``r`` or ``gm``, a
        negative ``gm``, two bodies (one of them massive) at one position (both indices
        in ``r``), shapes that do not match (both shapes), a Quantity beside a plain
        number (astropy's ``UnitConversionError``, a ``ValueError``, for a wrong unit).

    Examples
    --------
    >>> accelerations_quaternion([[0.0, 0, 0], [2.0, 0, 0]], [1.0, 0.0])
    array([[ 0.  ,  0.  ,  0.  ],
           [-0.25,  0.  ,  0.  ]])
    >>> import astropy.units as u
    >>> accelerations_quaternion([[0.0, 0, 0], [2.0, 0, 0]] * u.au,
    ...                          [1.0, 0.0] * u.au**3 / u.day**2)[1]
    <Quantity [-0.25,  0.  ,  0.  ] AU / d2>
    """
    from hamilton_orbits._body import A_UNIT, GM_UNIT, L_UNIT
    from hamilton_orbits.integrators._setup import check_apart
    from hamilton_orbits.quaternion import Quaternion
    from hamilton_orbits.units import GM, LENGTH, require_consistent
    from hamilton_orbits.validation import check_positive

    quantity = require_consistent(("r", "gm"), (r, gm))
    r = LENGTH("r", r, L_UNIT if quantity else None)
    gm = GM("gm", gm, GM_UNIT if quantity else None)
    n = len(gm) if gm.ndim == 1 else -1
    if r.shape != (n, 3):
        raise ValueError(f"Expected `gm` of shape (n,) and `r` of shape (n, 3), got `gm` of "
                         f"shape {gm.shape} and `r` of shape {r.shape}")
    check_positive("gm", gm, strict=False)
    check_apart(r, gm, arg="r")
    i, j = np.nonzero(~np.eye(n, dtype=bool) & (gm[None, :] != 0))
    alpha = Quaternion.from_vector(r[i] - r[j])  # alpha - alpha'
    square = (alpha * alpha).scalar  # (alpha - alpha')^2 = -T^2, a real number
    denominator = alpha * np.sqrt(-square)  # (alpha - alpha') sqrt(-(alpha - alpha')^2)
    term = denominator.inverse() * gm[j]  # m' / (...)
    acc = np.zeros((n, 4))
    np.add.at(acc, i, term.as_array())
    return acc[:, 1:] * A_UNIT if quantity else acc[:, 1:]


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


class UnderResolvedEncounterWarning(UserWarning):
    """A fixed step was too long for a close approach the run crossed (a test
    particle's to a massive body, a massive body's to a heavier one): the lighter
    body's orbit after it is not to be trusted (see
    :func:`under_resolved_encounters`)."""


#: Whether a run warns of the approaches its fixed step was too long for
#: (:class:`UnderResolvedEncounterWarning`; ``Trajectory.under_resolved`` lists them
#: either way).  An ensemble's member sets it False while it runs (its row counts
#: them, and the ensemble warns once): a context variable, so that members run in
#: threads (Dask's) change no other thread's, where ``warnings.catch_warnings`` left
#: the process's filters ignoring the warning for good.
WARN_UNDER_RESOLVED: ContextVar[bool] = ContextVar("WARN_UNDER_RESOLVED", default=True)


class Encounter(NamedTuple):
    """A close approach crossed with too long a step (``particle``: a test particle,
    or the lighter body of a massive pair; internal units:
    days, au, au/day); ``before`` and ``after`` the outputs around it, and the
    particle's osculating ``1/a`` and ``e`` about its primary there."""

    particle: int
    body: int
    primary: int
    time: float
    distance: float
    timescale: float
    step: float
    before: int
    after: int
    inv_a: tuple[float, float]
    e: tuple[float, float]


def primaries(r: np.ndarray, v: np.ndarray, gm: np.ndarray) -> np.ndarray:
    """Each test particle's primary in the state ``r``, ``v`` (n, 3): the massive body
    it is bound to on the smallest orbit (two-body energy about it negative, the
    semi-major axis least), else the most massive body; -1 for a massive body.

    Examples
    --------
    >>> r = np.array([[0.0, 0, 0], [1.0, 0, 0], [1.001, 0, 0], [3.0, 0, 0]])
    >>> v = np.array([[0.0, 0, 0], [0, 1.0, 0], [0, 1.03, 0], [0, 0.5, 0]])
    >>> primaries(r, v, np.array([1.0, 3e-6, 0.0, 0.0])).tolist()  # a moon, a planet
    [-1, -1, 1, 0]
    """
    gm = np.asarray(gm, dtype=np.float64)
    out = np.full(len(gm), -1)
    tp, m = np.flatnonzero(gm == 0), np.flatnonzero(gm > 0)
    if not len(tp) or not len(m):
        return out
    d = np.linalg.norm(r[tp, None] - r[None, m], axis=2)
    w2 = np.sum((v[tp, None] - v[None, m]) ** 2, axis=2)
    inv_a = 2.0 / d - w2 / gm[m]  # > 0: bound, the orbit the smaller the larger
    best = np.argmax(np.where(inv_a > 0, inv_a, -np.inf), axis=1)
    bound = (inv_a > 0).any(axis=1)
    out[tp] = np.where(bound, m[best], m[np.argmax(gm[m])])
    return out


def particle_errors(r: np.ndarray, v: np.ndarray, gm: np.ndarray,
                    extra: np.ndarray | None = None) -> tuple[np.ndarray, tuple[str, ...]]:
    """Each test particle's own check over states ``r``, ``v`` (n_t, n, 3), relative
    to the first state, and what it is.

    With two massive bodies on a circular mutual orbit (eccentricity at most
    ``JACOBI_MAX_ECCENTRICITY``) the particle's Jacobi constant ``2 U + 2 w . (x
    cross u) - u^2`` (``x``, ``u`` about the pair's centre of mass, ``w`` the pair's
    angular velocity; conserved, so its change is an error); otherwise its
    two-body energy ``u^2 / 2 - mu / d`` about its primary (:func:`primaries`):
    conserved with one massive body, and with several a measure of how much the
    others changed its orbit (an encounter's change is real where the steps
    resolved it: see :func:`under_resolved_encounters`).  ``extra`` (n_t, n) adds
    the effects' specific energies (``-2 extra`` to the Jacobi constant).

    Returns
    -------
    errors : ndarray, shape (n_t, n)
        ``(X(t) - X(0)) / |X(0)|`` for each test particle (absolute where
        ``X(0) = 0``), NaN for the massive bodies (and after a particle is taken
        out of the run).
    checks : tuple of str
        Per body: ``"jacobi"``, ``"energy about <index>"``, or ``""`` (massive).

    Examples
    --------
    >>> r = np.array([[[0.0, 0, 0], [1.0, 0, 0]]] * 2); v = np.zeros((2, 2, 3))
    >>> v[:, 1, 1] = 1.0; v[1, 1, 1] = 1.0 + 2.0**-20
    >>> errors, checks = particle_errors(r, v, np.array([1.0, 0.0]))
    >>> errors[:, 1].tolist(), checks
    ([0.0, 1.9073495423072018e-06], ('', 'energy about 0'))
    """
    gm0 = np.atleast_2d(np.asarray(gm, dtype=np.float64))[0]
    n_t, n = r.shape[:2]
    errors = np.full((n_t, n), np.nan)
    checks = [""] * n
    tp, m = np.flatnonzero(gm0 == 0), np.flatnonzero(gm0 > 0)
    if not len(tp) or not len(m):
        return errors, tuple(checks)
    if len(m) == 2 and _circular(r[0, m], v[0, m], gm0[m]):
        x, jac = _jacobi(r, v, gm0, m, tp), True
        size = np.abs(x[0])
    else:
        prim = primaries(r[0], v[0], gm0)[tp]
        d = r[:, tp] - r[:, prim]
        w = v[:, tp] - v[:, prim]
        kinetic = 0.5 * np.einsum("tij,tij->ti", w, w)
        potential = gm0[prim] / np.sqrt(np.einsum("tij,tij->ti", d, d))
        x, size, jac = kinetic - potential, kinetic[0] + potential[0], False
    if extra is not None:
        x = x + (-2.0 if jac else 1.0) * extra[:, tp]
        size = size + np.abs(extra[0, tp]) * (2.0 if jac else 1.0)
    # (relative to the start, or to the size of the energy's terms where the start is
    # near 0, a parabolic comet's: NEAR_ZERO)
    scale = np.where(np.abs(x[0]) >= NEAR_ZERO * size, np.abs(x[0]), size)
    errors[:, tp] = (x - x[0]) / np.where(scale > 0, scale, 1.0)
    for k, i in enumerate(tp):
        checks[i] = "jacobi" if jac else f"energy about {int(prim[k])}"
    return errors, tuple(checks)


def _circular(r: np.ndarray, v: np.ndarray, gm: np.ndarray) -> bool:
    """Whether two bodies' mutual orbit is circular (to ``JACOBI_MAX_ECCENTRICITY``)."""
    d, w = r[1] - r[0], v[1] - v[0]
    mu = float(gm.sum())
    e = (np.dot(w, w) / mu - 1.0 / np.linalg.norm(d)) * d - np.dot(d, w) / mu * w
    return bool(np.linalg.norm(e) <= JACOBI_MAX_ECCENTRICITY)


def _jacobi(r: np.ndarray, v: np.ndarray, gm: np.ndarray, m: np.ndarray,
            tp: np.ndarray) -> np.ndarray:
    """The test particles' Jacobi constants (n_t, n_tp) about the massive pair ``m``."""
    g = gm[m]
    rc = np.einsum("j,tjk->tk", g, r[:, m]) / g.sum()
    vc = np.einsum("j,tjk->tk", g, v[:, m]) / g.sum()
    d, w = r[:, m[1]] - r[:, m[0]], v[:, m[1]] - v[:, m[0]]
    omega = np.cross(d, w) / np.einsum("tk,tk->t", d, d)[:, None]
    x, u = r[:, tp] - rc[:, None], v[:, tp] - vc[:, None]
    pot = sum(g[k] / np.linalg.norm(r[:, tp] - r[:, m[k], None], axis=2) for k in (0, 1))
    spin = np.einsum("tk,tik->ti", omega, np.cross(x, u))
    return 2.0 * pot + 2.0 * spin - np.einsum("tik,tik->ti", u, u)


def light_as_massless(gm: np.ndarray) -> np.ndarray:
    """``gm`` with the bodies of at most :data:`LIGHT` of the largest GM made 0 (test
    particles, for the check of their approaches).

    Examples
    --------
    >>> light_as_massless(np.array([1.0, 1e-3, 1e-12, 0.0])).tolist()
    [1.0, 0.001, 0.0, 0.0]
    """
    top = float(np.max(gm)) if gm.size else 0.0
    return np.where(gm <= LIGHT * top, 0.0, gm) if top > 0 else gm


def under_resolved_encounters(r: np.ndarray, v: np.ndarray, gm: np.ndarray, t: np.ndarray,
                              step: float, exempt: tuple[int, float] | None = None,
                              fraction: float = ENCOUNTER_STEP_FRACTION) -> list[Encounter]:
    """The close approaches of test particles to massive bodies, and of massive
    bodies to heavier ones, seen at the output states ``r``, ``v`` (n_t, n, 3) at
    times ``t``, that a fixed ``step`` was too long for (bodies of at most
    :data:`LIGHT` of the largest GM checked as test particles,
    :func:`light_as_massless`).  A pair of massive bodies is checked once, from
    its lighter body (of two equal, the later one) as "the particle", with the
    pair's summed GM, in systems of at most 32 massive bodies
    (``hamilton_orbits._kernels.integrals.MASSIVE_PAIRS_MAX``: beyond, checking
    every pair at every output would cost about a force evaluation per output); a
    massive body's primary is the heavier body it is bound to on the smallest
    orbit, else the most massive body, and its approaches to it are not checked
    (its own orbit, which the energy's error measures).

    An approach is a pericentre passage about the particle's primary
    (:func:`primaries`) whose time scale is under a tenth of the orbit's own pace
    ``1 / n`` (any, on an unbound orbit: a step too long for a bound orbit's pace
    is what the particle's own check shows), or one within three Hill radii
    (about that primary) of another massive body.  The time
    scale of an approach at distance ``d`` and relative speed ``u`` to a body of
    ``mu`` is ``min(d / u, sqrt(d^3 / mu))`` (the time to cross the distance,
    or to fall through it): the time over which that body's pull turns.  It is
    taken at each output, and between two outputs where the particle passed its
    closest point to the body (its radial velocity from approaching to receding in
    the run's direction: from negative to positive forwards, from positive to
    negative in a run backwards, ``t`` decreasing) at the two-body periapsis
    about that body (the larger of those from the two outputs; the speed there
    from the vis-viva law).  A step (``step``, or the
    output interval where shorter: steps land on the outputs) longer than
    ``fraction`` of it does not resolve the approach; each run of
    consecutive such outputs is one encounter, reported at its closest point,
    with the particle's osculating ``1/a`` and ``e`` about its primary before and
    after it in the run (backwards: at the later time, then the earlier; at the
    outputs around it, beyond three Hill radii of the body where the leg has
    them).  ``exempt = (body, distance)``: a body whose approaches
    beyond that distance the method integrates exactly (``wh``'s central body:
    at any distance in democratic-heliocentric coordinates; in Jacobi
    coordinates, whose Kepler motions are about the inner bodies' centre of mass,
    beyond ten times the central body's distance from it).  Approaches between
    outputs that do not pass a closest point (the outputs too sparse) are not seen.

    Examples
    --------
    >>> t = np.array([0.0, 1.0]); gm = np.array([1.0, 0.0])
    >>> r = np.array([[[0.0, 0, 0], [0.01, 0, 0]]] * 2); v = np.zeros((2, 2, 3))
    >>> v[:, 1, 1] = 20.0  # unbound: twice the speed of a circular orbit
    >>> [(e.particle, e.body, e.timescale) for e in under_resolved_encounters(r, v, gm, t, 0.1)]
    [(1, 0, 0.0005)]
    >>> under_resolved_encounters(r, v, gm, t, 0.00001)
    []
    """
    from hamilton_orbits._kernels import integrals
    from hamilton_orbits._screening import output_steps, screen

    r = np.ascontiguousarray(r, dtype=np.float64)
    v = np.ascontiguousarray(v, dtype=np.float64)
    t = np.ascontiguousarray(t, dtype=np.float64)
    gm = np.ascontiguousarray(np.atleast_2d(gm)[0], dtype=np.float64)
    ex, ex_dist = (-1, 0.0) if exempt is None else (int(exempt[0]), float(exempt[1]))
    if not screen(r, v, gm, t, float(step), ex, ex_dist, float(fraction), LIGHT):
        return []  # (all resolved: nearly every run, found in one compiled call)
    gm0 = light_as_massless(gm)
    m = np.flatnonzero(gm0 > 0)
    tp = np.delete(np.arange(len(gm0)), m[np.argmax(gm0[m])])  # all but the most massive
    if len(m) > integrals.MASSIVE_PAIRS_MAX:  # (massive pairs: only in smaller systems)
        tp = tp[gm0[tp] == 0]
    h = output_steps(t, step)
    prim = integrals.primaries(r[0], v[0], gm0, np.empty(len(gm0), np.int64), True)
    bad = np.zeros((1, len(tp), len(m)), np.bool_)
    none = np.empty((0, 0, 0))
    integrals.approaches(r, v, gm0, t, tp, m, prim, ex, ex_dist, h, float(fraction), bad,
                         none, none)
    found: list[Encounter] = []
    for p, j in zip(*np.nonzero(bad[0]), strict=True):
        dist, tau = np.empty((len(t), 1, 1)), np.empty((len(t), 1, 1))
        at = np.zeros((len(t), 1, 1), np.bool_)  # (the outputs this pair was flagged at)
        integrals.approaches(r, v, gm0, t, tp[p:p + 1], m[j:j + 1], prim, ex, ex_dist, h,
                             float(fraction), at, dist, tau)
        found += _runs(r, v, gm0, t, h, int(tp[p]), int(m[j]), (int(prim[tp[p]]),
                       int(prim[m[j]])), at[:, 0, 0], dist[:, 0, 0], tau[:, 0, 0])
    return sorted(found, key=lambda enc: (enc.time, enc.particle))


def _runs(r: np.ndarray, v: np.ndarray, gm: np.ndarray, t: np.ndarray, h: np.ndarray,
          i: int, b: int, primaries: tuple[int, int], bad: np.ndarray, dist: np.ndarray,
          tau: np.ndarray) -> list[Encounter]:
    """The encounters of particle ``i`` with body ``b`` (``primaries``: ``i``'s and
    ``b``'s, -1 for the most massive body): one per run of consecutive outputs
    ``bad``."""
    c = primaries[0]
    far = _far(r, gm, i, b, primaries)
    edges = np.diff(np.concatenate(([0], bad.astype(np.int8), [0])))
    found = []
    for start, end in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1),
                          strict=True):
        k = start + int(np.argmin(dist[start:end]))
        before = max([x for x in np.flatnonzero(far[:start])[-1:]] or [max(start - 1, 0)])
        after = min([x for x in end + np.flatnonzero(far[end:])[:1]] or [len(t) - 1])
        inv_a, e = _osculating(r, v, gm, i, c, (int(before), int(after)))
        found.append(Encounter(i, b, c, _closest_time(r, v, gm, t, k, i, b), float(dist[k]),
                               float(tau[k]), float(h[k]), int(before), int(after), inv_a, e))
    return found


def _closest_time(r: np.ndarray, v: np.ndarray, gm: np.ndarray, t: np.ndarray, k: int,
                  i: int, b: int) -> float:
    """When body ``i`` passed closest to body ``b`` about output ``k``: its two-body
    periapsis time about ``b`` where that falls between the outputs on either side
    of ``k`` (the approach seen between them: output 10 was reported for a
    periapsis at 1.56), else the output's time."""
    from hamilton_orbits._kernels import elements

    d = (r[k, i] - r[k, b])[None]
    w = (v[k, i] - v[k, b])[None]
    since = np.empty(1)
    elements.state_to_time_since_periapsis(d, w, np.array([gm[b] + gm[i]]), since)
    when = float(t[k] - since[0])
    near = (float(t[max(k - 1, 0)]), float(t[min(k + 1, len(t) - 1)]))  # (either side:
    return when if min(near) <= when <= max(near) else float(t[k])  # a backward run's too)


def _far(r: np.ndarray, gm: np.ndarray, i: int, b: int, primaries: tuple[int, int]
         ) -> np.ndarray:
    """At which outputs body ``i`` is beyond three Hill radii of body ``b`` about
    ``b``'s own primary (``primaries``: ``i``'s and ``b``'s): everywhere when ``b`` is
    ``i``'s primary, nowhere when ``b`` is the most massive body (no primary)."""
    c, cb = primaries
    if b == c:
        return np.ones(len(r), bool)
    if cb < 0:
        return np.zeros(len(r), bool)
    hill = np.linalg.norm(r[:, b] - r[:, cb], axis=1) * (gm[b] / (3.0 * gm[cb])) ** (1.0 / 3.0)
    return np.linalg.norm(r[:, i] - r[:, b], axis=1) > 3.0 * hill


def _osculating(r: np.ndarray, v: np.ndarray, gm: np.ndarray, i: int, c: int,
                rows: tuple[int, int]) -> tuple[tuple[float, float], tuple[float, float]]:
    """Body ``i``'s osculating ``1/a`` and ``e`` about body ``c`` at outputs ``rows``."""
    inv_a, ecc = [], []
    for k in rows:
        d, w = r[k, i] - r[k, c], v[k, i] - v[k, c]
        mu, dist = float(gm[c] + gm[i]), float(np.linalg.norm(d))
        inv_a.append(2.0 / dist - float(np.dot(w, w)) / mu)
        e = (np.dot(w, w) / mu - 1.0 / dist) * d - np.dot(d, w) / mu * w
        ecc.append(float(np.linalg.norm(e)))
    return (inv_a[0], inv_a[1]), (ecc[0], ecc[1])
