"""Polar motion: the linear Liouville pole, the IERS C04 record and its wobble fit.

Conventions (IERS): the pole is ``m = m1 + i m2`` with ``m1 = x_p``,
``m2 = -y_p``; a prograde term is ``exp(+i sigma t)``.  The linearised
Liouville equation (Munk & MacDonald 1960, eq. 6.8.4; Lambeck 1980, eq. 3.2.7;
Gross 2007, Treatise on Geophysics 3, 239, eq. 7)

    m + (i / sigma_c) dm/dt = chi,   sigma_c = (2 pi / T_c)(1 + i / (2 Q))

is solved exactly by :class:`LiouvillePole`.
"""

from __future__ import annotations

from typing import Any

import astropy.units as u
import numpy as np
from scipy.optimize import least_squares

from hamilton_orbits.units import TIME

__all__ = ["free_period"]


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
