"""The pole of a deformable Earth from the linearised Liouville equation, solved exactly.

Conventions (IERS): the pole is ``m = m1 + i m2`` with ``m1 = x_p``,
``m2 = -y_p``; a prograde term is ``exp(+i sigma t)``.  The linearised
Liouville equation (Munk & MacDonald 1960, eq. 6.8.4; Lambeck 1980, eq. 3.2.7;
Gross 2007, Treatise on Geophysics 3, 239, eq. 7)

    m + (i / sigma_c) dm/dt = chi,   sigma_c = (2 pi / T_c)(1 + i / (2 Q))

is solved exactly by :class:`LiouvillePole`, whose effects are registered as
``"rotation"`` effects in :mod:`hamilton_orbits.effects` (``register_effects``,
called on import).  ``free_period``, the period of a free wobble fitted to a
pole path (the measure of a model's period), lives with the fits in
``rigid.earth.wobble_fit`` and is re-exported here.  The public facade is
:mod:`rigid.polar_motion`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits.units import ANGLE, DIMENSIONLESS, TIME
from hamilton_orbits.validation import check_unmasked
from rigid._kernels import liouville as _lk
from rigid._shared import positive_scalar
from rigid.earth.constants import euler_period, secular_love_number
from rigid.earth.wobble_fit import free_period

__all__ = ["EFFECTS", "LiouvillePole", "free_period", "register_effects"]

EFFECTS = ("free", "elastic", "damping", "annual_excitation", "excitation_series")

_PARAMETERS: dict[str, dict[str, str]] = {
    "free": {"euler_period": "rigid-Earth (Euler) period (default rigid.earth.euler_period())"},
    "elastic": {
        "k2": "effective Love number; T_c = T_E / (1 - k2/k_s)",
        "chandler_period": "the lengthened period directly (instead of k2)",
    },
    "damping": {"Q": "quality factor; sigma_c = sigma_0 (1 + i/(2Q))"},
    "annual_excitation": {
        "annual_prograde": "complex chi amplitude of exp(+i w_a t) (angle)",
        "annual_retrograde": "complex chi amplitude of exp(-i w_a t) (angle), default 0",
        "annual_period": "period of the seasonal forcing (default 365.2422 d)",
        "annual_epoch": "time origin of the annual phases (default t = 0)",
    },
    "excitation_series": {
        "chi_t": "times of the user excitation series (increasing)",
        "chi": "complex chi at chi_t (angle), piecewise linear in between",
    },
}

# the scalar parameters with a dimension (a scene reads "433 d" into a Quantity, and
# "5 mas" into an angle: a real amplitude there, TOML having no complex numbers; a bare
# number stays radians)
_KINDS = {"euler_period": TIME, "k2": DIMENSIONLESS, "chandler_period": TIME,
          "Q": DIMENSIONLESS, "annual_period": TIME, "annual_epoch": TIME,
          "annual_prograde": ANGLE, "annual_retrograde": ANGLE}

_REFERENCES = {
    "free": "Euler (1765); Lambeck 1980, The Earth's Variable Rotation, sec. 3.1",
    "elastic": "Munk & MacDonald 1960, eq. 6.2.11; Smith & Dahlen 1981, GJRAS 64, 223",
    "damping": "Munk & MacDonald 1960, sec. 10.3; Wilson & Vicente 1990, GJI 102, 29",
    "annual_excitation": "Gross 2007, Treatise on Geophysics 3, 239, sec. 3.09.4",
    "excitation_series": "Gross 2007, Treatise on Geophysics 3, 239, eq. 7",
}

_SUMMARY = {
    "free": "the free Euler wobble of the rigid Earth (always the homogeneous part)",
    "elastic": "lengthening of the free period by the effective Love number k2",
    "damping": "anelastic damping of the wobble with quality factor Q",
    "annual_excitation": "seasonal forcing chi(t): prograde and retrograde annual terms",
    "excitation_series": "a user excitation chi(t), piecewise linear, integrated exactly",
}


def _complex_angle(name: str, value: Any) -> tuple[np.ndarray, bool]:
    """Complex angle -> complex radians; True if it came as a Quantity.  A masked
    value is refused (``np.asarray`` would read under the mask)."""
    check_unmasked(name, value)  # (complex values: not through a unit kind's check)
    if isinstance(value, u.Quantity):
        re = ANGLE(name, value.real)
        im = ANGLE(name, value.imag)
        return re + 1j * im, True
    arr = np.asarray(value)
    if np.iscomplexobj(arr):
        re = ANGLE(name, arr.real)
        im = ANGLE(name, arr.imag)
        return re + 1j * im, False
    return ANGLE(name, arr).astype(np.complex128), False


def _cexpm1(w: np.ndarray) -> np.ndarray:
    """``exp(w) - 1`` for complex ``w`` without cancellation near 0."""
    a, b = w.real, w.imag
    s = np.sin(0.5 * b)
    return np.expm1(a) * np.cos(b) - 2.0 * s * s + 1j * np.exp(a) * np.sin(b)


def _phi1(w: np.ndarray) -> np.ndarray:
    """``(exp(w) - 1) / w`` (1 at w = 0)."""
    w = np.asarray(w, dtype=np.complex128)
    small = np.abs(w) < 1e-5  # series: the next term w^3/24 is below one ulp
    ws = w[small]
    out = np.empty_like(w)
    out[small] = 1.0 + ws * (0.5 + ws / 6.0)
    wl = w[~small]
    out[~small] = _cexpm1(wl) / wl
    return out


def _phi2(w: np.ndarray) -> np.ndarray:
    """``((w - 1) exp(w) + 1) / w^2 = sum_n w^n / (n! (n + 2))`` (1/2 at w = 0)."""
    out = np.empty_like(w)
    small = np.abs(w) < 0.5
    ws = w[small]
    term = np.ones_like(ws)
    acc = term / 2.0
    for n in range(1, 25):  # |w| < 0.5: 0.5^25 / 25! is far below one ulp
        term = term * ws / n
        acc = acc + term / (n + 2)
    out[small] = acc
    wl = w[~small]
    out[~small] = (wl * np.exp(wl) - _cexpm1(wl)) / (wl * wl)
    return out


class LiouvillePole:
    """The pole of a deformable Earth from the linearised Liouville equation.

    ``m + (i / sigma_c) dm/dt = chi(t)``, i.e. ``dm/dt = i sigma_c (m - chi)``,
    with ``m = m1 + i m2`` (IERS: ``m1 = x_p``, ``m2 = -y_p``) and

        sigma_c = (2 pi / T) (1 + i / (2 Q)).

    Only the listed effects enter the model:

    ``"free"``
        The homogeneous part, the Euler wobble, ``T = T_E`` (parameter
        ``euler_period``, default :func:`rigid.earth.euler_period`).  It is the
        equation itself and is always present; listing it is optional.
    ``"elastic"``
        ``T = T_E / (1 - k2 / k_s)`` (parameter ``k2``) or ``T`` given as
        ``chandler_period``.
    ``"damping"``
        A finite ``Q`` (otherwise ``Q`` is infinite).
    ``"annual_excitation"``
        ``chi(t) = chi_p exp(i w_a (t - t_a)) + chi_r exp(-i w_a (t - t_a))``
        (``annual_prograde``, ``annual_retrograde``, ``annual_period``,
        ``annual_epoch``).
    ``"excitation_series"``
        A user ``chi(t)`` given at times ``chi_t``, linear in between.

    A parameter of an effect that is not listed is refused.

    Parameters
    ----------
    effects : sequence of str
        Names from :data:`EFFECTS` (registered as ``"rotation"`` effects in
        :mod:`hamilton_orbits.effects`).
    **params
        The parameters of the listed effects (see above); times as Quantities
        or plain floats in days, angles as Quantities or plain radians.

    Notes
    -----
    :meth:`solve` is exact (no ODE solver): the homogeneous part is
    ``exp(i sigma_c (t - t0)) m0``; a sinusoidal forcing ``c exp(i w t)`` adds
    ``sigma_c c / (sigma_c - w) [exp(i w t) - exp(i sigma_c (t - t0)) exp(i w t0)]``
    (evaluated with a cancellation-free ``(exp(x) - 1)/x``, so also at
    resonance); a piecewise-linear ``chi`` is integrated exactly over each
    interval, ``int_0^h exp(i sigma u) (chi_1 - s u) du = h chi_1 phi1(w) - s h^2
    phi2(w)``, ``w = i sigma h``, and the intervals are chained by the linear
    recursion ``m_{k+1} = exp(w) m_k - i sigma I_k`` (a compiled loop).

    Examples
    --------
    >>> import astropy.units as u
    >>> model = LiouvillePole(("elastic", "damping"), chandler_period=433 * u.day, Q=100)
    >>> m = model.solve([0.0, 433.0] * u.day, 0.2 * u.arcsec)
    >>> print(np.round(m.real, 6), round(0.2 * np.exp(-np.pi / 100), 6))  # exp(-pi/Q) per turn
    [0.2      0.193814] arcsec 0.193814
    >>> LiouvillePole(("free",), Q=100)
    Traceback (most recent call last):
    ...
    ValueError: Parameter `Q` belongs to effect 'damping', which is not listed in effects ('free',)
    """

    def __init__(self, effects: Any = ("free",), **params: Any) -> None:
        effects = _check_effects(effects, params)
        self.effects: tuple[str, ...] = effects
        period = _wobble_period(effects, params)
        q_inv = 0.0
        if "damping" in effects:
            if "Q" not in params:
                raise ValueError("Effect 'damping' needs the parameter `Q`")
            q_inv = 1.0 / float(positive_scalar("Q", DIMENSIONLESS("Q", params["Q"])))
        #: the period T (days) and 1/Q of the free wobble
        self.period: float = period
        self.q_inv: float = q_inv
        #: complex sigma_c (rad / day)
        self.sigma: complex = 2.0 * np.pi / period * (1.0 + 0.5j * q_inv)
        # (amplitude, omega, epoch) of each sinusoidal forcing term
        self._sinusoids: list[tuple[complex, float, float]] = _annual_terms(effects, params)
        self._series: tuple[np.ndarray, np.ndarray] | None = _series(effects, params)

    def __repr__(self) -> str:
        return (f"LiouvillePole(effects={self.effects}, period={self.period!r} d, "
                f"Q={'inf' if self.q_inv == 0 else 1 / self.q_inv!r})")

    def excitation(self, t: Any) -> np.ndarray:
        """The model's ``chi(t)`` in radians (zero without forcing effects); with an
        excitation series, ``t`` within its span (as :meth:`solve` takes it).

        Examples
        --------
        >>> LiouvillePole(("annual_excitation",), annual_prograde=1e-7).excitation([0.0])
        array([1.e-07+0.j])
        """
        tt = TIME("t", t, u.day)
        chi = np.zeros(tt.shape, dtype=np.complex128)
        for c, w, ep in self._sinusoids:
            chi += c * np.exp(1j * w * (tt - ep))
        if self._series is not None:
            self._within_series("t", tt)
            st, sc = self._series
            chi += np.interp(tt, st, sc.real) + 1j * np.interp(tt, st, sc.imag)
        return chi

    def rhs(self, t: float, m: complex) -> complex:
        """``dm/dt = i sigma_c (m - chi(t))`` (rad/day; for checks with an ODE solver).

        Examples
        --------
        >>> model = LiouvillePole(("elastic",), chandler_period=433.0)
        >>> bool(abs(model.rhs(0.0, 1e-6) - 2j * np.pi / 433.0 * 1e-6) < 1e-22)
        True
        """
        return 1j * self.sigma * (m - complex(self.excitation(t)))

    def solve(self, t: Any, m0: Any, t0: Any = None) -> Any:
        """The exact pole path ``m(t)`` from ``m(t0) = m0``.

        Parameters
        ----------
        t : Quantity or array_like
            Output times (days if plain floats).
        m0 : complex, or complex Quantity (angle)
            The pole at ``t0`` (``m1 + i m2``; radians if plain).
        t0 : Quantity or float, optional
            Initial time (default the first of ``t``).  With
            ``"excitation_series"``, ``t0`` and ``t`` must lie in the span of
            ``chi_t``.

        Returns
        -------
        ndarray (complex) or complex Quantity, shape t.shape
            In the unit of ``m0`` if it was a Quantity, else radians.

        Raises
        ------
        ValueError
            For a non-scalar ``m0`` or ``t0``, times outside an excitation series,
            or a backward run of a damped model so long that the pole overflows.

        Examples
        --------
        >>> model = LiouvillePole(("elastic",), chandler_period=400 * u.day)
        >>> m = model.solve([0, 100, 200] * u.day, 0.1 * u.arcsec)  # quarter turns
        >>> print(np.round(m.real, 12) + 0.0, np.round(m.imag, 12) + 0.0)
        [ 0.1  0.  -0.1] arcsec [0.  0.1 0. ] arcsec
        """
        tt = TIME("t", t, u.day)
        m0c, quantity = _complex_angle("m0", m0)
        if m0c.shape != ():
            raise ValueError(f"Expected `m0` to be a scalar, got shape {m0c.shape}")
        if t0 is None:
            if tt.size == 0:
                raise ValueError("Expected `t` to hold at least one time, got none")
            start = float(tt.flat[0])
        else:
            t0a = TIME("t0", t0, u.day)
            if t0a.shape != ():
                raise ValueError(f"Expected `t0` to be a scalar, got shape {t0a.shape}")
            start = float(t0a)
        sig = self.sigma
        tau = tt - start
        with np.errstate(over="ignore", invalid="ignore"):
            decay = np.exp(1j * sig * tau)
            m = decay * complex(m0c)
            for c, w, ep in self._sinusoids:
                if c == 0:
                    continue
                # -i sig c int_t0^t exp(i sig (t - s)) exp(i w (s - ep)) ds
                #   = -i sig c exp(i w (t - ep)) tau phi1(i (sig - w) tau)
                z = 1j * (sig - w) * tau
                m = m - 1j * sig * c * np.exp(1j * w * (tt - ep)) * tau * _phi1(z)
            if self._series is not None:
                m = m + self._series_response(tt, start)
        bad = ~np.isfinite(m)
        if np.any(bad):
            k = np.argwhere(np.atleast_1d(bad))[0][0]
            raise ValueError(
                f"Expected `t` within reach of t0 = {start!r} d (a damped wobble run "
                f"backwards grows as exp(|t - t0| / tau)), got {float(np.atleast_1d(tt)[k])!r}"
                f"{f' at index {k}' if tt.ndim else ''}: the pole overflows"
            )
        if quantity:
            return u.Quantity(m, u.rad).to(m0.unit)
        return m

    def _within_series(self, name: str, vals: np.ndarray) -> None:
        """Refuse times ``vals`` beyond the excitation series' span (``chi`` is not
        known there: an interpolation would hold its end value)."""
        st, _ = self._series  # type: ignore[misc]
        lo, hi = float(st[0]), float(st[-1])
        out = (vals < lo) | (vals > hi)
        if np.any(out):
            k = np.argwhere(np.atleast_1d(out))[0][0]
            raise ValueError(
                f"Expected `{name}` within the span of `chi_t` [{lo!r}, {hi!r}] d, got "
                f"{float(np.atleast_1d(vals)[k])!r}{f' at index {k}' if vals.ndim else ''}"
            )

    def _series_response(self, tt: np.ndarray, start: float) -> np.ndarray:
        st, sc = self._series  # type: ignore[misc]
        for name, vals in (("t0", np.array(start)), ("t", tt)):
            self._within_series(name, vals)
        if np.any(tt < start):
            k = int(np.argmax(np.atleast_1d(tt < start)))
            raise ValueError(
                f"Expected `t` >= t0 = {start!r} with an excitation series, got "
                f"{float(np.atleast_1d(tt)[k])!r} at index {k}"
            )
        # knots: the series' own knots after t0, plus t0 and the output times (inserting a
        # point on a linear piece leaves chi unchanged, so the integral stays exact)
        grid = np.unique(np.concatenate([[start], st[st > start], tt.ravel()]))
        chi = np.interp(grid, st, sc.real) + 1j * np.interp(grid, st, sc.imag)
        h = np.diff(grid)
        sig = self.sigma
        w = 1j * sig * h
        slope = np.diff(chi) / h
        integral = h * chi[1:] * _phi1(w) - slope * h * h * _phi2(w)
        a = np.exp(w)
        b = -1j * sig * integral
        out = np.empty(grid.size, dtype=np.complex128)
        _lk.linear_recurrence(a, b, 0j, out)
        return out[np.searchsorted(grid, tt.ravel())].reshape(tt.shape)




def _check_effects(effects: Any, params: dict[str, Any]) -> tuple[str, ...]:
    """The effects as a tuple of known names; every parameter belongs to a listed one."""
    if isinstance(effects, str):
        effects = (effects,)
    if not isinstance(effects, Sequence):
        raise ValueError(f"Expected `effects` to be a list of names from {EFFECTS}, got "
                         f"{effects!r}")
    effects = tuple(effects)
    for i, name in enumerate(effects):
        if not isinstance(name, str) or name not in EFFECTS:
            raise ValueError(
                f"Expected `effects` from {EFFECTS}, got {name!r} at index {i}"
            )
        if name in effects[:i]:  # as hamilton_orbits.effects.normalize_effects refuses it
            raise ValueError(f"Effect {name!r} is listed twice (at indices "
                             f"{effects.index(name)} and {i})")
    owner = {p: e for e, ps in _PARAMETERS.items() for p in ps}
    for p in params:
        if p not in owner:
            raise ValueError(f"Unknown parameter `{p}`; known: {', '.join(sorted(owner))}")
        if owner[p] not in effects and not (owner[p] == "free"):
            raise ValueError(
                f"Parameter `{p}` belongs to effect {owner[p]!r}, which is not listed "
                f"in effects {effects}"
            )
    return effects


def _wobble_period(effects: tuple[str, ...], params: dict[str, Any]) -> float:
    """The free period T in days: Euler's, lengthened by ``"elastic"``."""
    t_e = params.get("euler_period", euler_period())
    period = float(positive_scalar("euler_period", TIME("euler_period", t_e, u.day)))
    if "elastic" not in effects:
        return period
    if ("k2" in params) == ("chandler_period" in params):
        raise ValueError(
            "Effect 'elastic' needs exactly one of `k2` and `chandler_period`, "
            f"got {sorted(k for k in ('k2', 'chandler_period') if k in params)}"
        )
    if "k2" in params:
        k2 = DIMENSIONLESS.scalar("k2", params["k2"])
        ks = float(secular_love_number())
        if not 0.0 <= k2 < ks:
            raise ValueError(f"Expected `k2` in [0, k_s = {ks:.6f}), got {k2!r}")
        return period / (1.0 - k2 / ks)
    return float(positive_scalar(
        "chandler_period", TIME("chandler_period", params["chandler_period"], u.day)))


def _annual_terms(
    effects: tuple[str, ...], params: dict[str, Any]
) -> list[tuple[complex, float, float]]:
    """``(amplitude, omega, epoch)`` of the prograde and retrograde annual terms."""
    if "annual_excitation" not in effects:
        return []
    if "annual_prograde" not in params:
        raise ValueError("Effect 'annual_excitation' needs `annual_prograde`")
    cp, _ = _complex_angle("annual_prograde", params["annual_prograde"])
    cr, _ = _complex_angle("annual_retrograde", params.get("annual_retrograde", 0.0))
    for name, value in (("annual_prograde", cp), ("annual_retrograde", cr)):
        if value.shape != ():
            raise ValueError(f"Expected `{name}` to be one (complex) angle, got shape "
                             f"{value.shape}")
    t_a = float(positive_scalar("annual_period", TIME(
        "annual_period", params.get("annual_period", 365.2422), u.day)))
    ep = TIME("annual_epoch", params.get("annual_epoch", 0.0), u.day)
    if ep.shape != ():
        raise ValueError(f"Expected `annual_epoch` to be a scalar, got {ep.shape}")
    w_a = 2.0 * np.pi / t_a
    return [(complex(cp), w_a, float(ep)), (complex(cr), -w_a, float(ep))]


def _series(
    effects: tuple[str, ...], params: dict[str, Any]
) -> tuple[np.ndarray, np.ndarray] | None:
    """``(chi_t in days, chi in radians)`` of ``"excitation_series"``, validated."""
    if "excitation_series" not in effects:
        return None
    if "chi_t" not in params or "chi" not in params:
        raise ValueError("Effect 'excitation_series' needs `chi_t` and `chi`")
    st = TIME("chi_t", params["chi_t"], u.day)
    sc, _ = _complex_angle("chi", params["chi"])
    if st.ndim != 1 or sc.shape != st.shape or st.size < 2:
        raise ValueError(
            f"Expected `chi_t` and `chi` of one shape (n,), n >= 2, got {st.shape} "
            f"and {sc.shape}"
        )
    bad = np.nonzero(np.diff(st) <= 0)[0]
    if bad.size:
        k = int(bad[0]) + 1
        raise ValueError(f"Expected `chi_t` increasing, got {st[k]!r} at index {k}")
    return st, sc


def register_effects() -> None:
    """Register the Liouville effects as ``"rotation"`` effects in hamilton_orbits.effects.

    Idempotent; called on import of :mod:`rigid.earth.liouville` (so of
    :mod:`rigid.polar_motion`) and by the ``hamilton_orbits.effects`` entry point
    ``rigid.polar_motion:register_effects``.

    Examples
    --------
    >>> from hamilton_orbits import effects
    >>> register_effects()
    >>> effects.get("rotation", "damping").parameters["Q"][:15]
    'quality factor;'
    """
    from hamilton_orbits.effects import EffectSpec, register

    for name in EFFECTS:
        register(EffectSpec(
            name=name,
            kind="rotation",
            summary=_SUMMARY[name],
            parameters=dict(_PARAMETERS[name]),
            build=_builder(name),
            reference=_REFERENCES[name],
            parameter_kinds={p: _KINDS[p] for p in _PARAMETERS[name] if p in _KINDS},
        ))


def _builder(name: str):
    def build(**params: Any) -> LiouvillePole:
        """A LiouvillePole with this effect (and "free") only."""
        return LiouvillePole(("free", name) if name != "free" else ("free",), **params)

    return build


register_effects()
