"""Polar motion: the linear Liouville pole, the IERS C04 record and its wobble fit.

Conventions (IERS): the pole is ``m = m1 + i m2`` with ``m1 = x_p``,
``m2 = -y_p``; a prograde term is ``exp(+i sigma t)``.  The linearised
Liouville equation (Munk & MacDonald 1960, eq. 6.8.4; Lambeck 1980, eq. 3.2.7;
Gross 2007, Treatise on Geophysics 3, 239, eq. 7)

    m + (i / sigma_c) dm/dt = chi,   sigma_c = (2 pi / T_c)(1 + i / (2 Q))

is solved exactly by :class:`LiouvillePole`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import astropy.units as u
import numpy as np
from astropy.table import QTable
from astropy.time import Time
from scipy.optimize import least_squares

from hamilton_orbits._validation import as_float_array
from hamilton_orbits.units import ANGLE, DIMENSIONLESS, TIME
from rigid._kernels import liouville as _lk

__all__ = [
    "EFFECTS",
    "LiouvillePole",
    "PolarMotionRecord",
    "WobbleFit",
    "fit_wobble",
    "free_period",
    "hindcast",
    "iers2010_mean_pole",
    "load_c04",
    "periodogram",
    "predict",
    "register_effects",
]


def _harmonic_design(t: np.ndarray, freqs: np.ndarray, n_trend: int) -> np.ndarray:
    cols = [t**k for k in range(n_trend)]
    cols += [np.exp(1j * f * t) for f in freqs]
    return np.stack(cols, axis=-1).astype(np.complex128)


def _project(t: np.ndarray, m: np.ndarray, freqs: np.ndarray, n_trend: int):
    """Complex linear least squares at fixed frequencies: (coefficients, residual)."""
    design = _harmonic_design(t, freqs, n_trend)
    coef, *_ = np.linalg.lstsq(design, m, rcond=None)
    return coef, m - design @ coef


def free_period(t: Any, m: Any) -> u.Quantity:
    """The period of a free wobble fitted to a pole path.

    The model is ``m(t) = a exp(i sigma t) + b exp(-i sigma t)`` (the ellipse
    of the triaxial linear theory; ``b = 0`` for an axisymmetric body), fitted by
    nonlinear least squares in ``sigma`` with the amplitudes projected out.  The
    starting value is the mean rate of the unwrapped phase of ``m``.

    Parameters
    ----------
    t : Quantity or array_like, shape (n,)
        Times (days if plain floats).
    m : array_like, complex, shape (n,)
        The pole path ``m1 + i m2`` (any angular unit; only the phase matters).

    Returns
    -------
    Quantity, day
        ``2 pi / sigma``.

    Raises
    ------
    ValueError
        For fewer than 8 points, mismatched shapes or a path without a wobble.

    Examples
    --------
    >>> t = np.arange(0.0, 2000.0)
    >>> print(f"{free_period(t, 1e-6 * np.exp(2j * np.pi * t / 433.0)):.6f}")
    433.000000 d
    """
    tt = TIME("t", t, u.day)
    mm = np.asarray(m.value if isinstance(m, u.Quantity) else m, dtype=np.complex128)
    if tt.ndim != 1 or mm.shape != tt.shape or tt.size < 8:
        raise ValueError(
            f"Expected `t` and `m` of one shape (n,), n >= 8, got {tt.shape} and {mm.shape}"
        )
    if not np.all(np.isfinite(mm)):
        k = int(np.argmin(np.isfinite(mm)))
        raise ValueError(f"Expected `m` to be finite, got {mm[k]!r} at index {k}")
    scale = float(np.max(np.abs(mm)))
    if scale == 0.0:
        raise ValueError("Expected `m` to wobble, got a path identically zero")
    t0 = tt - tt[0]
    phase = np.unwrap(np.angle(mm))
    sigma0 = float(np.polyfit(t0, phase, 1)[0])
    if sigma0 == 0.0:
        raise ValueError("Expected `m` to turn about the figure axis, got no mean rotation")
    mn = mm / scale

    def resid(x):
        _, r = _project(t0, mn, np.array([x[0], -x[0]]), 0)
        return np.concatenate([r.real, r.imag])

    sol = least_squares(resid, [sigma0], x_scale=[abs(sigma0)], xtol=1e-15, ftol=1e-15,
                        gtol=1e-15)
    return (2.0 * np.pi / abs(float(sol.x[0]))) * u.day


# --------------------------------------------------------------------------
# The linearised Liouville equation, solved exactly
# --------------------------------------------------------------------------

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
    """Complex angle -> complex radians; True if it came as a Quantity."""
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
        if isinstance(effects, str):
            effects = (effects,)
        effects = tuple(effects)
        for i, name in enumerate(effects):
            if name not in EFFECTS:
                raise ValueError(
                    f"Expected `effects` from {EFFECTS}, got {name!r} at index {i}"
                )
        self.effects: tuple[str, ...] = effects
        owner = {p: e for e, ps in _PARAMETERS.items() for p in ps}
        for p in params:
            if p not in owner:
                raise ValueError(f"Unknown parameter `{p}`; known: {', '.join(sorted(owner))}")
            if owner[p] not in effects and not (owner[p] == "free"):
                raise ValueError(
                    f"Parameter `{p}` belongs to effect {owner[p]!r}, which is not listed "
                    f"in effects {effects}"
                )
        from rigid import earth

        t_e = params.get("euler_period", earth.euler_period())
        period = float(_positive_scalar("euler_period", TIME("euler_period", t_e, u.day)))
        if "elastic" in effects:
            if ("k2" in params) == ("chandler_period" in params):
                raise ValueError(
                    "Effect 'elastic' needs exactly one of `k2` and `chandler_period`, "
                    f"got {sorted(k for k in ('k2', 'chandler_period') if k in params)}"
                )
            if "k2" in params:
                k2 = float(DIMENSIONLESS("k2", params["k2"]))
                ks = float(earth.secular_love_number())
                if not 0.0 <= k2 < ks:
                    raise ValueError(f"Expected `k2` in [0, k_s = {ks:.6f}), got {k2!r}")
                period = period / (1.0 - k2 / ks)
            else:
                period = float(_positive_scalar(
                    "chandler_period", TIME("chandler_period", params["chandler_period"],
                                            u.day)))
        q_inv = 0.0
        if "damping" in effects:
            if "Q" not in params:
                raise ValueError("Effect 'damping' needs the parameter `Q`")
            q_inv = 1.0 / float(_positive_scalar("Q", DIMENSIONLESS("Q", params["Q"])))
        #: the period T (days) and 1/Q of the free wobble
        self.period: float = period
        self.q_inv: float = q_inv
        #: complex sigma_c (rad / day)
        self.sigma: complex = 2.0 * np.pi / period * (1.0 + 0.5j * q_inv)
        self._sinusoids: list[tuple[complex, float, float]] = []  # (amplitude, omega, epoch)
        if "annual_excitation" in effects:
            if "annual_prograde" not in params:
                raise ValueError("Effect 'annual_excitation' needs `annual_prograde`")
            cp, _ = _complex_angle("annual_prograde", params["annual_prograde"])
            cr, _ = _complex_angle("annual_retrograde", params.get("annual_retrograde", 0.0))
            t_a = float(_positive_scalar("annual_period", TIME(
                "annual_period", params.get("annual_period", 365.2422), u.day)))
            ep = TIME("annual_epoch", params.get("annual_epoch", 0.0), u.day)
            if ep.shape != ():
                raise ValueError(f"Expected `annual_epoch` to be a scalar, got {ep.shape}")
            w_a = 2.0 * np.pi / t_a
            self._sinusoids += [(complex(cp), w_a, float(ep)), (complex(cr), -w_a, float(ep))]
        self._series: tuple[np.ndarray, np.ndarray] | None = None
        if "excitation_series" in effects:
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
            self._series = (st, sc)

    def __repr__(self) -> str:
        return (f"LiouvillePole(effects={self.effects}, period={self.period!r} d, "
                f"Q={'inf' if self.q_inv == 0 else 1 / self.q_inv!r})")

    def excitation(self, t: Any) -> np.ndarray:
        """The model's ``chi(t)`` in radians (zero without forcing effects).

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

    def _series_response(self, tt: np.ndarray, start: float) -> np.ndarray:
        st, sc = self._series  # type: ignore[misc]
        lo, hi = float(st[0]), float(st[-1])
        for name, vals in (("t0", np.array(start)), ("t", tt)):
            out = (vals < lo) | (vals > hi)
            if np.any(out):
                k = np.argwhere(np.atleast_1d(out))[0][0]
                raise ValueError(
                    f"Expected `{name}` within the span of `chi_t` [{lo!r}, {hi!r}] d, got "
                    f"{float(np.atleast_1d(vals)[k])!r}{f' at index {k}' if vals.ndim else ''}"
                )
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


def _positive_scalar(name: str, value: np.ndarray) -> np.ndarray:
    if value.shape != ():
        raise ValueError(f"Expected `{name}` to be a scalar, got shape {value.shape}")
    if not float(value) > 0.0:
        raise ValueError(f"Expected `{name}` > 0, got {float(value)!r}")
    return value


def register_effects() -> None:
    """Register the Liouville effects as ``"rotation"`` effects in hamilton_orbits.effects.

    Idempotent; called on import of :mod:`rigid.polar_motion` and by the
    ``hamilton_orbits.effects`` entry point.

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
        ))


def _builder(name: str):
    def build(**params: Any) -> LiouvillePole:
        """A LiouvillePole with this effect (and "free") only."""
        return LiouvillePole(("free", name) if name != "free" else ("free",), **params)

    return build


register_effects()


# --------------------------------------------------------------------------
# The observed record: IERS 20 C04 from astropy-iers-data, offline
# --------------------------------------------------------------------------

_C04_NAME = "eopc04.1962-now"


@dataclass(frozen=True)
class PolarMotionRecord:
    """Observed polar motion (see :func:`load_c04`).

    Attributes
    ----------
    time : astropy.time.Time, shape (n,)
        Epochs (UTC, 0h of each day).
    x, y : Quantity, shape (n,), arcsec
        The pole coordinates x_p, y_p (IERS).
    source : str
        Where the record was read from.
    """

    time: Time
    x: u.Quantity
    y: u.Quantity
    source: str = ""

    def __post_init__(self) -> None:
        if not isinstance(self.time, Time):
            raise ValueError(f"Expected `time` to be an astropy Time, got {type(self.time)}")
        n = len(self.time)
        for name in ("x", "y"):
            value = getattr(self, name)
            if not isinstance(value, u.Quantity):
                raise u.UnitConversionError(
                    f"Expected `{name}` to be an angle Quantity (e.g. arcsec), got {value!r}"
                )
            arr = ANGLE(name, value, u.arcsec)
            if arr.shape != (n,):
                raise ValueError(f"Expected `{name}` of shape ({n},) like `time`, got {arr.shape}")
            object.__setattr__(self, name, arr * u.arcsec)

    @property
    def m(self) -> u.Quantity:
        """``m = m1 + i m2 = x_p - i y_p`` (IERS convention), complex Quantity (arcsec)."""
        return (self.x.to_value(u.arcsec) - 1j * self.y.to_value(u.arcsec)) * u.arcsec

    def __len__(self) -> int:
        return len(self.x)

    def select(self, start: Any = None, end: Any = None) -> PolarMotionRecord:
        """The part of the record with ``start <= time < end`` (Time, or decimal years).

        Examples
        --------
        >>> print(load_c04().select(2000, 2001).time[0].iso[:10])
        2000-01-01
        """
        yr = _decimal_year(self.time)
        keep = np.ones(yr.shape, dtype=bool)
        if start is not None:
            keep &= yr >= _year("start", start)
        if end is not None:
            keep &= yr < _year("end", end)
        if keep.sum() < 2:
            raise ValueError(
                f"Expected `start`, `end` to select at least 2 epochs of the record "
                f"({yr[0]:.2f}-{yr[-1]:.2f}), got start={start!r}, end={end!r}"
            )
        return PolarMotionRecord(self.time[keep], self.x[keep], self.y[keep], self.source)


def _days(time: Time) -> np.ndarray:
    """UTC MJD: whole days between the 0h UTC epochs of the record (no scale change)."""
    return np.asarray(time.utc.mjd if time.scale != "utc" else time.mjd, dtype=np.float64)


def _decimal_year(time: Time) -> np.ndarray:
    """Years of 365.25 d counted from 2000-01-01 0h UTC (MJD 51544): 0h on 1 January
    falls on or just after the integer year from 1901 to 2099, so ``start=1970`` keeps
    1970-01-01 and ``end=2010`` drops 2010-01-01."""
    return 2000.0 + (_days(time) - 51544.0) / 365.25


def _year(name: str, value: Any) -> float:
    if isinstance(value, Time):
        return float(_decimal_year(value))
    if isinstance(value, u.Quantity):
        return float(TIME(name, value, u.yr))
    v = as_float_array(name, value)
    if v.shape != ():
        raise ValueError(f"Expected `{name}` to be a scalar, got shape {v.shape}")
    return float(v)


def load_c04(path: Any = None) -> PolarMotionRecord:
    """Read the IERS 20 C04 polar motion that ships with ``astropy-iers-data``.

    The file ``eopc04.1962-now`` (daily since 1962-01-01, columns x_p, y_p in
    arcsec; Bizouard et al. 2019, J. Geodesy 93, 621) is found with
    :mod:`importlib.resources` and parsed here; nothing is downloaded.

    Parameters
    ----------
    path : str or Path, optional
        Another file in the same format (default: the bundled one).

    Returns
    -------
    PolarMotionRecord

    Examples
    --------
    >>> rec = load_c04()
    >>> print(rec.time[0].iso[:10], rec.x.unit, len(rec) > 23000)
    1962-01-01 arcsec True
    """
    if path is None:
        from importlib.resources import files

        path = files("astropy_iers_data") / "data" / _C04_NAME
    with open(str(path)) as fh:
        data = np.loadtxt(fh, comments="#", usecols=(4, 5, 6))
    if data.ndim != 2 or data.shape[0] < 2:
        raise ValueError(f"Expected `path` to hold a C04 table, got {data.shape} values")
    time = Time(data[:, 0], format="mjd", scale="utc")
    return PolarMotionRecord(time, data[:, 1] * u.arcsec, data[:, 2] * u.arcsec, str(path))


# IERS Conventions (2010), sec. 7.1.4, eq. (7.25) and Table 7.7: the conventional mean
# pole in mas, cubic before 2010.0 and linear after, tau = t - 2000.0 in years.
_MEAN_POLE_2010 = {
    "x_before": (55.974, 1.8243, 0.18413, 0.007024),
    "y_before": (346.346, 1.7896, -0.10729, -0.000908),
    "x_after": (23.513, 7.6141, 0.0, 0.0),
    "y_after": (358.891, -0.6287, 0.0, 0.0),
}


def iers2010_mean_pole(time: Any) -> tuple[u.Quantity, u.Quantity]:
    """The IERS 2010 conventional mean pole ``(x_bar, y_bar)`` in mas.

    IERS Conventions (2010), eq. (7.25) with Table 7.7 (cubic until 2010.0,
    linear after).

    Examples
    --------
    >>> x, y = iers2010_mean_pole(Time("2000-01-01T12:00:00", scale="tt"))
    >>> print(np.round(x, 3), np.round(y, 3))
    55.974 mas 346.346 mas
    """
    if not isinstance(time, Time):
        raise ValueError(f"Expected `time` to be an astropy Time, got {type(time).__name__}")
    # tau in Julian years from J2000.0 (MJD 51544.5); the UTC-TT offset (~1 min) is
    # irrelevant at the mas level
    tau = (_days(time) - 51544.5) / 365.25
    before = tau < 10.0
    out = []
    for c in ("x", "y"):
        b = np.polynomial.polynomial.polyval(tau, _MEAN_POLE_2010[f"{c}_before"])
        a = np.polynomial.polynomial.polyval(tau, _MEAN_POLE_2010[f"{c}_after"])
        out.append(np.where(before, b, a) * u.mas)
    return out[0], out[1]


@dataclass(frozen=True)
class WobbleFit:
    """The least-squares wobble fit of :func:`fit_wobble`.

    Periods and their errors are in days, amplitudes in mas, phases in degrees
    (the argument of the complex amplitude at ``epoch``; prograde terms are
    ``A exp(i (w (t - epoch) + phase))``, the retrograde annual term
    ``A exp(-i (w (t - epoch)) + i phase)``).

    ``rms_residual`` is per component (x or y) of the residual.  The errors are the
    formal ones scaled by the residual scatter and by an
    AR(1) effective sample size ``n (1 - rho) / (1 + rho)`` (``rho`` the lag-one
    autocorrelation of the residuals, close to 1 for daily data).  The residuals
    remain correlated over months (unmodelled excitation), so even these
    errors are indicative, not rigorous.
    """

    chandler_period: u.Quantity
    chandler_period_error: u.Quantity
    chandler_period_error_formal: u.Quantity
    annual_period: u.Quantity
    annual_period_error: u.Quantity
    chandler_amplitude: u.Quantity
    chandler_phase: u.Quantity
    annual_amplitude: u.Quantity
    annual_phase: u.Quantity
    annual_retrograde_amplitude: u.Quantity
    annual_retrograde_phase: u.Quantity
    mean_pole: u.Quantity
    drift: u.Quantity
    rms_residual: u.Quantity
    residual_autocorrelation: float
    epoch: Time
    start: Time
    end: Time
    n: int
    trend: str
    amplitude_by_decade: QTable
    q_estimate: float
    q_caveat: str

    def model(self, time: Time) -> u.Quantity:
        """The fitted ``m(t)`` (complex, mas) at ``time``, trend included.

        Examples
        --------
        >>> rec = load_c04().select(1980, 2000)
        >>> fit = fit_wobble(rec)
        >>> res = rec.m - fit.model(rec.time)
        >>> bool(np.sqrt(np.mean(np.abs(res) ** 2) / 2) < 1.01 * fit.rms_residual)
        True
        """
        t = _days(time) - float(self.epoch.mjd)
        mean = self.mean_pole.to_value(u.mas) + self.drift.to_value(u.mas / u.yr) * t / 365.25
        if self.trend == "iers2010":
            xb, yb = iers2010_mean_pole(time)
            mean = mean + xb.to_value(u.mas) - 1j * yb.to_value(u.mas)
        wc = 2 * np.pi / self.chandler_period.to_value(u.day)
        wa = 2 * np.pi / self.annual_period.to_value(u.day)

        def c(a, p):
            return a.to_value(u.mas) * np.exp(1j * p.to_value(u.rad))

        return (mean + c(self.chandler_amplitude, self.chandler_phase) * np.exp(1j * wc * t)
                + c(self.annual_amplitude, self.annual_phase) * np.exp(1j * wa * t)
                + c(self.annual_retrograde_amplitude, self.annual_retrograde_phase)
                * np.exp(-1j * wa * t)) * u.mas


def _wobble_resid(x, t, m, n_trend):
    """Residuals and Jacobian of the model for real parameters
    x = [w_c, w_a, Re/Im of (trend..., chandler, annual+, annual-)]."""
    wc, wa = x[0], x[1]
    coef = x[2::2] + 1j * x[3::2]
    design = _harmonic_design(t, np.array([wc, wa, -wa]), n_trend)
    r = m - design @ coef
    n_c = n_trend
    jac_c = np.empty((t.size, x.size), dtype=np.complex128)
    jac_c[:, 0] = -coef[n_c] * 1j * t * design[:, n_c]
    jac_c[:, 1] = -(coef[n_c + 1] * 1j * t * design[:, n_c + 1]
                    - coef[n_c + 2] * 1j * t * design[:, n_c + 2])
    jac_c[:, 2::2] = -design
    jac_c[:, 3::2] = -1j * design
    return r, jac_c


def _fit_core(t: np.ndarray, m: np.ndarray, n_trend: int, t_c0: float, t_a0: float):
    """Nonlinear least squares; returns (x, covariance (scaled), residual, rho, rms)."""
    # start: the highest prograde line within +-10% of the guess, once the trend and the
    # annual terms are removed (one matrix product instead of a nonlinear search)
    _, detrended = _project(t, m, 2 * np.pi / np.array([t_a0, -t_a0]), n_trend)
    grid = np.linspace(0.9 * t_c0, 1.1 * t_c0, 61)  # 0.33% steps; the line is ~2% wide
    amp = np.abs(np.exp(-2j * np.pi * np.outer(1.0 / grid, t)) @ detrended)
    tc = float(grid[int(np.argmax(amp))])
    freqs = 2 * np.pi / np.array([tc, t_a0, -t_a0])
    coef, _ = _project(t, m, freqs, n_trend)
    x0 = np.concatenate([[freqs[0], freqs[1]], np.column_stack([coef.real, coef.imag]).ravel()])

    cache: dict[bytes, tuple[np.ndarray, np.ndarray]] = {}

    def evaluate(x):  # fun and jac at the same x share one evaluation
        key = x.tobytes()
        if key not in cache:
            cache.clear()
            r, j = _wobble_resid(x, t, m, n_trend)
            cache[key] = (np.concatenate([r.real, r.imag]), np.concatenate([j.real, j.imag]))
        return cache[key]

    def fun(x):
        return evaluate(x)[0]

    def jac(x):
        return evaluate(x)[1]

    scale = np.concatenate([[1e-4 * freqs[0], 1e-4 * freqs[1]],
                            np.full(x0.size - 2, max(np.std(np.abs(m)), 1e-300))])
    sol = least_squares(fun, x0, jac=jac, x_scale=scale, xtol=1e-12, ftol=1e-12, gtol=1e-12,
                        method="lm")
    r, jc = _wobble_resid(sol.x, t, m, n_trend)
    jr = np.concatenate([jc.real, jc.imag])
    dof = 2 * t.size - sol.x.size
    s2 = float(np.sum(np.abs(r) ** 2)) / dof
    cov = np.linalg.inv(jr.T @ jr) * s2
    rc = r - r.mean()
    rho = float(np.real(np.vdot(rc[:-1], rc[1:])) / np.real(np.vdot(rc, rc)))
    return sol.x, cov, r, rho, np.sqrt(s2)


def _amp_phase(c: complex) -> tuple[u.Quantity, u.Quantity]:
    return abs(c) * u.mas, (np.degrees(np.angle(c)) * u.deg)


def fit_wobble(
    record: PolarMotionRecord,
    start: Any = None,
    end: Any = None,
    *,
    trend: str = "linear",
    chandler_guess: Any = 433 * u.day,
) -> WobbleFit:
    """Fit the Chandler and annual wobbles to an observed pole path.

    Model (complex, ``m = x_p - i y_p``, mas, ``t`` in days from the window's
    mid epoch)::

        m(t) = mean + drift t + c_C exp(i w_C t) + c_A exp(i w_A t) + c_R exp(-i w_A t)

    with ``mean + drift t`` a linear trend (``trend="linear"``), or the IERS 2010
    mean pole (``trend="iers2010"``, IERS Conventions 2010 eq. 7.25) plus a
    constant offset.  ``w_C`` and ``w_A`` are fitted nonlinearly (Levenberg-
    Marquardt, scipy ``least_squares``, from a grid search of ``w_C`` with the
    linear parameters projected out).

    Parameters
    ----------
    record : PolarMotionRecord
        From :func:`load_c04`.
    start, end : Time, decimal year or None
        The window (default: the whole record).
    trend : {"linear", "iers2010"}
    chandler_guess : Quantity
        Centre of the grid search (+-10%).

    Returns
    -------
    WobbleFit
        Also ``amplitude_by_decade`` (the Chandler and annual amplitudes fitted per
        calendar decade with the periods of the whole window held fixed) and a Q
        estimate with its caveat.

    Examples
    --------
    >>> fit = fit_wobble(load_c04(), 1970, 2010)
    >>> print(round(fit.chandler_period.to_value(u.day)), round(fit.annual_period.to_value(u.day)))
    433 365
    """
    if not isinstance(record, PolarMotionRecord):
        raise ValueError(f"Expected `record` from load_c04(), got {type(record).__name__}")
    if trend not in ("linear", "iers2010"):
        raise ValueError(f"Expected `trend` 'linear' or 'iers2010', got {trend!r}")
    rec = record.select(start, end)
    t_c0 = float(_positive_scalar("chandler_guess", TIME("chandler_guess", chandler_guess,
                                                         u.day)))
    days = _days(rec.time)
    mid = 0.5 * (days[0] + days[-1])
    epoch = Time(mid, format="mjd", scale="utc")
    t = days - mid
    span = float(t[-1] - t[0])
    if span < 3 * t_c0:
        raise ValueError(
            f"Expected a window of at least 3 Chandler periods ({3 * t_c0:.0f} d) to separate "
            f"the Chandler and annual terms, got {span:.0f} d"
        )
    m = rec.m.to_value(u.mas)
    n_trend = 2
    if trend == "iers2010":
        xb, yb = iers2010_mean_pole(rec.time)
        m = m - (xb.to_value(u.mas) - 1j * yb.to_value(u.mas))
        n_trend = 1
    x, cov, _r, rho, rms = _fit_core(t, m, n_trend, t_c0, 365.25)
    wc, wa = x[0], x[1]
    coef = x[2::2] + 1j * x[3::2]
    inflate = np.sqrt((1 + rho) / (1 - rho)) if rho < 1 else np.inf
    err_wc = np.sqrt(cov[0, 0])
    err_wa = np.sqrt(cov[1, 1])
    t_c = 2 * np.pi / wc
    t_a = 2 * np.pi / wa
    ca, cp = _amp_phase(coef[n_trend])
    aa, ap = _amp_phase(coef[n_trend + 1])
    ra, rp = _amp_phase(coef[n_trend + 2])
    drift = (coef[1] * 365.25 if n_trend == 2 else 0j) * u.mas / u.yr
    decades = _amplitude_by_decade(rec, wc, wa)
    q, caveat = _q_estimate(rec, t_c)
    return WobbleFit(
        chandler_period=t_c * u.day,
        chandler_period_error=t_c * err_wc / wc * inflate * u.day,
        chandler_period_error_formal=t_c * err_wc / wc * u.day,
        annual_period=t_a * u.day,
        annual_period_error=t_a * err_wa / wa * inflate * u.day,
        chandler_amplitude=ca, chandler_phase=cp,
        annual_amplitude=aa, annual_phase=ap,
        annual_retrograde_amplitude=ra, annual_retrograde_phase=rp,
        mean_pole=coef[0] * u.mas, drift=drift,
        rms_residual=rms * u.mas,
        residual_autocorrelation=rho,
        epoch=epoch, start=rec.time[0], end=rec.time[-1], n=len(rec), trend=trend,
        amplitude_by_decade=decades, q_estimate=q, q_caveat=caveat,
    )


def _amplitude_by_decade(rec: PolarMotionRecord, wc: float, wa: float) -> QTable:
    """Chandler and annual amplitudes per calendar decade, periods held fixed."""
    yr = _decimal_year(rec.time)
    rows = []
    first = int(np.floor(yr[0] / 10.0) * 10)
    for dec in range(first, int(yr[-1]) + 1, 10):
        sel = (yr >= dec) & (yr < dec + 10)
        if sel.sum() < 2 * 365:  # under two years: the terms cannot be separated
            continue
        sub = PolarMotionRecord(rec.time[sel], rec.x[sel], rec.y[sel])
        days = _days(sub.time)
        t = days - 0.5 * (days[0] + days[-1])
        coef, _ = _project(t, sub.m.to_value(u.mas), np.array([wc, wa, -wa]), 2)
        rows.append((dec, float(yr[sel][0]), float(yr[sel][-1]), abs(coef[2]), abs(coef[3]),
                     abs(coef[4])))
    cols = list(zip(*rows, strict=True)) if rows else [[]] * 6
    return QTable(
        [np.array(cols[0], dtype=int), np.array(cols[1]) * u.yr, np.array(cols[2]) * u.yr,
         np.array(cols[3]) * u.mas, np.array(cols[4]) * u.mas, np.array(cols[5]) * u.mas],
        names=("decade", "from", "to", "chandler_amplitude", "annual_amplitude",
               "annual_retrograde_amplitude"),
    )


def _q_estimate(rec: PolarMotionRecord, t_c: float) -> tuple[float, str]:
    """Q from the half-power width of the Chandler line (resolution limited)."""
    days = _days(rec.time)
    years = (days[-1] - days[0]) / 365.25
    f_c = 365.25 / t_c
    freqs = np.linspace(f_c - 0.04, f_c + 0.04, 81)
    pg = periodogram(rec, freqs / u.yr)
    power = pg["amplitude"].to_value(u.mas) ** 2
    k = int(np.argmax(power))
    half = power[k] / 2
    lo = k
    while lo > 0 and power[lo] > half:
        lo -= 1
    hi = k
    while hi < power.size - 1 and power[hi] > half:
        hi += 1
    fwhm = float(freqs[hi] - freqs[lo])
    q = f_c / fwhm
    caveat = (
        f"Q = f_C / FWHM of the Chandler line = {q:.0f}.  The window's own resolution "
        f"({1 / years:.3f} cycles/yr over {years:.1f} yr) limits the width, so this is of "
        "the order of the largest Q the record can resolve, not a measurement of the "
        "damping: the wobble is re-excited continuously (atmosphere, ocean, hydrology), so a "
        "line width mixes damping and excitation.  Published estimates range from ~50 to "
        "~200 (e.g. Wilson & Vicente 1990, GJI 102, 29: Q ~ 179; Furuya & Chao 1996, GJI "
        "127, 693: Q ~ 49-250)."
    )
    return q, caveat


def periodogram(
    record: PolarMotionRecord, frequency: Any = None, *, trend: str = "linear"
) -> QTable:
    """The complex (two-sided) amplitude spectrum of the pole path.

    ``A(f) = |(1/n) sum_k (m_k - trend_k) exp(-2 pi i f t_k)|`` (mas), ``f`` in
    cycles per year: positive ``f`` is prograde, negative retrograde.  For a pure
    term ``a exp(2 pi i f0 t)``, ``A(f0) = |a|``.

    Parameters
    ----------
    record : PolarMotionRecord
    frequency : Quantity, optional
        Frequencies (1/yr, 1/day ...); default -1.5 .. 1.5 cycles/yr, 1201 points.
    trend : {"linear", "iers2010"}
        What is removed first (a least-squares line, or the IERS 2010 mean pole).

    Returns
    -------
    astropy.table.QTable
        Columns ``frequency`` (1/yr), ``period`` (d, signed) and ``amplitude`` (mas).

    Examples
    --------
    >>> pg = periodogram(load_c04(), np.linspace(0.8, 0.9, 101) / u.yr)
    >>> print(f'{pg["period"][np.argmax(pg["amplitude"])]:.0f}')  # the Chandler line
    432 d
    """
    if not isinstance(record, PolarMotionRecord):
        raise ValueError(f"Expected `record` from load_c04(), got {type(record).__name__}")
    if frequency is None:
        f = np.linspace(-1.5, 1.5, 1201)
    else:
        if not isinstance(frequency, u.Quantity):
            raise u.UnitConversionError(
                f"Expected `frequency` to be a Quantity of 1/time, got {frequency!r}"
            )
        f = as_float_array("frequency", frequency.to_value(1 / u.yr))
    days = _days(record.time)
    t = (days - days[0]) / 365.25
    m = record.m.to_value(u.mas)
    if trend == "iers2010":
        xb, yb = iers2010_mean_pole(record.time)
        m = m - (xb.to_value(u.mas) - 1j * yb.to_value(u.mas))
        m = m - m.mean()
    elif trend == "linear":
        _coef, m = _project(t, m, np.zeros(0), 2)
    else:
        raise ValueError(f"Expected `trend` 'linear' or 'iers2010', got {trend!r}")
    amp = np.empty(f.size)
    chunk = max(1, 2_000_000 // max(t.size, 1))
    for i in range(0, f.size, chunk):  # chunks of frequencies, vectorised over time
        fs = f[i:i + chunk]
        amp[i:i + chunk] = np.abs(np.exp(-2j * np.pi * np.outer(fs, t)) @ m) / t.size
    with np.errstate(divide="ignore"):
        period = np.where(f != 0, 365.25 / np.where(f != 0, f, 1.0), np.inf)
    return QTable([f / u.yr, period * u.day, amp * u.mas],
                 names=("frequency", "period", "amplitude"))


from rigid.pole_prediction import hindcast, predict  # noqa: E402
