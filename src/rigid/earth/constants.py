"""The Earth as a rigid body: cited constants, moments, the Euler and Chandler periods.

Re-exported by :mod:`rigid.earth` (``rigid.earth.moments()``, ``rigid.earth.OMEGA``, ...).

Constants (astropy Quantities) follow the IERS Conventions (2010), G. Petit &
B. Luzum (eds.), IERS Technical Note 36, Table 1.1 (numerical standards):

* ``GM``: the geocentric gravitational constant, 3.986004418e14 m^3 s^-2;
* ``R_EQ``: the equatorial radius, 6378136.6 m;
* ``OMEGA``: the nominal mean angular velocity, 7.292115e-5 rad s^-1;
* ``J2``: the dynamical form factor, 1.0826359e-3;
* ``H``: the dynamical flattening (C - (A + B)/2) / C, 3273795e-9.

The triaxiality comes from the degree-2 order-2 Stokes coefficients of EGM2008
(Pavlis et al. 2012, J. Geophys. Res. 117, B04406), the model adopted in IERS
Conventions (2010), ch. 6, Table 6.2: normalised ``C22_BAR = 2.43938357328313e-6``,
``S22_BAR = -1.40027370385934e-6``.  Unnormalised (Heiskanen & Moritz 1967,
eq. 2-80), ``C22 = sqrt(5/12) C22_BAR``, and in the principal frame
``sqrt(C22^2 + S22^2) = (B - A) / (4 M R^2)`` (Lambeck 1980, *The Earth's
Variable Rotation*, eq. 2.4.2), which gives (B - A)/C ~ 2.2e-5 (Liu & Chao 1991,
Geophys. J. Int. 106, 699).

The mass is ``M = GM / G`` with the CODATA 2018 G (astropy).

Sign convention of the pole (IERS): the rotation pole in the body frame is
``m = m1 + i m2`` with ``m1 = x_p`` and ``m2 = -y_p`` in the terrestrial frame
(:func:`simulate_wobble` turns the principal frame's pole by ``A_AXIS_LONGITUDE``;
x_p towards Greenwich,
y_p towards 90 degrees west).  A free wobble of an axisymmetric rigid Earth is
``m(t) = m0 exp(i sigma_E t)``: prograde (anticlockwise seen from above the
North pole), with ``sigma_E = OMEGA (C - A) / A`` (Euler 1765).

Sylvester (1866, last paragraph) names exactly this use of the free rigid body:
"the evagation of the pole of the earth regarded as a body of irregular form".
"""

from __future__ import annotations

from typing import Any

import astropy.constants as const
import astropy.units as u
import numpy as np

from hamilton_orbits.units import ANGLE, DIMENSIONLESS
from hamilton_orbits.validation import as_flag
from rigid.body import RigidBody

__all__ = [
    "A_AXIS_LONGITUDE",
    "C22_BAR",
    "GM",
    "J2",
    "OMEGA",
    "R_EQ",
    "S22_BAR",
    "H",
    "chandler_period",
    "euler_period",
    "mass",
    "moments",
    "rigid_body",
    "secular_love_number",
]

#: Geocentric gravitational constant (IERS Conventions 2010, Table 1.1).
GM = 3.986004418e14 * u.m**3 / u.s**2
#: Equatorial radius (IERS Conventions 2010, Table 1.1).
R_EQ = 6378136.6 * u.m
#: Nominal mean angular velocity of the Earth (IERS Conventions 2010, Table 1.1).
OMEGA = 7.292115e-5 * u.rad / u.s
#: Dynamical form factor J2 (IERS Conventions 2010, Table 1.1).
J2 = 1.0826359e-3 * u.dimensionless_unscaled
#: Dynamical flattening H = (C - (A+B)/2) / C (IERS Conventions 2010, Table 1.1).
H = 3273795e-9 * u.dimensionless_unscaled
#: Normalised C22 of EGM2008 (IERS Conventions 2010, Table 6.2).
C22_BAR = 2.43938357328313e-6 * u.dimensionless_unscaled
#: Normalised S22 of EGM2008 (IERS Conventions 2010, Table 6.2).
S22_BAR = -1.40027370385934e-6 * u.dimensionless_unscaled
#: The longitude of the least moment's axis A, ``atan2(S22, C22) / 2`` (Lambeck 1980,
#: eq. 2.4.2; the normalisation cancels): about 14.93 deg west of Greenwich.  The
#: body frame of :func:`rigid_body` has x along it; :func:`simulate_wobble` turns its
#: pole into the IERS ``x_p`` (towards Greenwich) and ``y_p`` (towards 90 deg west).
A_AXIS_LONGITUDE = (0.5 * np.arctan2(float(S22_BAR), float(C22_BAR)) * u.rad).to(u.deg)

_SIDEREAL_DAY = (2.0 * np.pi * u.rad / OMEGA).to(u.s)


def mass() -> u.Quantity:
    """The Earth's mass ``GM / G`` (CODATA 2018 G).

    Examples
    --------
    >>> print(f"{mass():.4e}")
    5.9722e+24 kg
    """
    return (GM / const.G).to(u.kg)


def moments() -> u.Quantity:
    """The principal moments ``(A, B, C)`` of the Earth, kg m^2.

    ``C - (A + B)/2 = J2 M R^2`` (definition of J2 for principal axes) and
    ``H = (C - (A + B)/2) / C`` give ``C = J2 M R^2 / H``; the triaxiality is
    ``B - A = 4 M R^2 sqrt(C22^2 + S22^2)`` with the unnormalised EGM2008
    coefficients (see the module docstring).

    Returns
    -------
    Quantity, shape (3,), kg m^2
        ``A < B < C``.

    Examples
    --------
    >>> A, B, C = moments()
    >>> print(f"{C:.4e}")
    8.0343e+37 m2 kg
    >>> print(round(float((C / (mass() * R_EQ**2)).decompose()), 4))   # C/(M R^2)
    0.3307
    >>> print(round(float((B - A) / C * 1e5), 3))   # (B - A)/C ~ 2.2e-5 (Liu & Chao 1991)
    2.196
    """
    mr2 = mass() * R_EQ**2
    c = J2 * mr2 / H
    norm = np.sqrt(5.0 / 12.0)  # N_22 = sqrt(2 (2n+1) (n-m)!/(n+m)!) at n = m = 2
    b_minus_a = 4.0 * mr2 * np.hypot(norm * C22_BAR, norm * S22_BAR)
    a_bar = c - J2 * mr2
    a = a_bar - 0.5 * b_minus_a
    b = a_bar + 0.5 * b_minus_a
    return u.Quantity([a, b, c]).to(u.kg * u.m**2)


def euler_period(triaxial: bool = False) -> u.Quantity:
    """The Euler (rigid-Earth free-nutation) period, in days of 86400 s.

    Axisymmetric (``A = B = (A + B)/2``): ``sigma_E = OMEGA (C - A) / A``, i.e.
    ``A / (C - A) = (1 - H)/H ~ 304.45`` sidereal days.  Triaxial:
    ``sigma_E = OMEGA sqrt((C - A)(C - B) / (A B))``, the frequency of the
    linearised Euler equations about the figure axis (Lambeck 1980, sec. 3.1).

    Examples
    --------
    >>> print(f"{euler_period():.2f}")
    303.62 d
    >>> print(round(float(euler_period() / _SIDEREAL_DAY), 2))     # sidereal days
    304.46
    >>> print(f"{euler_period(triaxial=True):.2f}")
    303.63 d
    """
    a, b, c = moments()
    if as_flag("triaxial", triaxial):
        ratio = np.sqrt((c - a) * (c - b) / (a * b))
    else:
        a_bar = 0.5 * (a + b)
        ratio = (c - a_bar) / a_bar
    return (_SIDEREAL_DAY / ratio.decompose()).to(u.day)


def secular_love_number() -> u.Quantity:
    """The secular (fluid) Love number ``k_s = 3 G (C - A) / (OMEGA^2 R^5)``.

    With ``C - A = J2 M R^2`` this is ``3 GM J2 / (OMEGA^2 R^3)`` (Munk &
    MacDonald 1960, *The Rotation of the Earth*, sec. 6.2; Lambeck 1980, eq. 3.3.8).

    Examples
    --------
    >>> print(round(float(secular_love_number()), 4))
    0.9383
    """
    ks = 3.0 * GM * J2 / (OMEGA.to_value(u.rad / u.s) ** 2 / u.s**2 * R_EQ**3)
    return ks.to(u.dimensionless_unscaled)


def chandler_period(k2: Any, *, triaxial: bool = False) -> u.Quantity:
    """The Chandler period of an elastic Earth with effective Love number ``k2``.

    ``sigma_c = sigma_E (1 - k2 / k_s)`` (Munk & MacDonald 1960, eq. 6.2.11;
    Lambeck 1980, eq. 3.3.12; Smith & Dahlen 1981, Geophys. J. R. astr. Soc.
    64, 223, whose full theory adds the ocean and the fluid core): the rotational
    bulge that follows the pole lengthens the Euler period.  An effective k2 near
    0.28 lumps mantle elasticity, anelasticity, the ocean pole tide and the
    decoupled core, and reproduces the observed ~433 days.

    Parameters
    ----------
    k2 : float or dimensionless Quantity
        Effective Love number, ``0 <= k2 < k_s``.
    triaxial : bool, optional
        Use the triaxial Euler frequency (default False).

    Raises
    ------
    ValueError
        If ``k2`` is negative, not below ``k_s`` or not finite.

    Examples
    --------
    >>> print(f"{chandler_period(0.0):.2f}")
    303.62 d
    >>> print(f"{chandler_period(0.28):.1f}")
    432.8 d
    """
    k = DIMENSIONLESS("k2", k2)
    if k.shape != ():
        raise ValueError(f"Expected `k2` to be a scalar, got shape {k.shape}")
    ks = float(secular_love_number())
    if not 0.0 <= float(k) < ks:
        raise ValueError(f"Expected `k2` in [0, k_s = {ks:.6f}), got {float(k)!r}")
    return euler_period(triaxial=triaxial) / (1.0 - float(k) / ks)


def rigid_body(wobble: Any = 0.2 * u.arcsec, *, triaxial: bool = True) -> RigidBody:
    """The rigid Earth spinning at OMEGA with its rotation axis off the figure axis.

    The body frame is the principal frame (x towards the A axis, at
    ``A_AXIS_LONGITUDE`` (14.93 deg west), not Greenwich; z the figure axis C);
    the attitude is the identity and the angular velocity is
    ``OMEGA (sin w, 0, cos w)``, ``w`` the wobble angle.

    Parameters
    ----------
    wobble : Quantity or float
        Angle between the rotation and figure axes (radians if a float).
    triaxial : bool, optional
        Use the triaxial moments (default); False takes ``A = B = (A + B)/2``.

    Raises
    ------
    ValueError
        If ``wobble`` is negative, not finite or not below 90 degrees.

    Examples
    --------
    >>> body = rigid_body(0.2 * u.arcsec)
    >>> w = body.omega.to_value(u.rad / u.s) if hasattr(body.omega, "unit") else body.omega
    >>> print(f"{np.degrees(np.arctan2(w[0], w[2])) * 3600:.4f}")
    0.2000
    """
    w = ANGLE("wobble", wobble)
    if w.shape != ():
        raise ValueError(f"Expected `wobble` to be a scalar, got shape {w.shape}")
    if not 0.0 <= float(w) < np.pi / 2:
        raise ValueError(f"Expected `wobble` in [0, 90 deg), got {wobble!r}")
    mom = moments()
    if not as_flag("triaxial", triaxial):
        a_bar = 0.5 * (mom[0] + mom[1])
        mom = u.Quantity([a_bar, a_bar, mom[2]])
    om = OMEGA.to_value(u.rad / u.s)
    omega = om * np.array([np.sin(float(w)), 0.0, np.cos(float(w))]) * u.rad / u.s
    return RigidBody(mom, omega=omega)
