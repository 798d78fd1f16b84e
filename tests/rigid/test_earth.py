"""rigid.earth: the cited constants, the moments and the Euler / Chandler periods."""

import astropy.units as u
import numpy as np
import pytest

from rigid import earth


def test_constants_are_the_iers_2010_values():
    """IERS Conventions (2010), TN 36, Table 1.1."""
    assert earth.GM.to_value(u.m**3 / u.s**2) == 3.986004418e14
    assert earth.R_EQ.to_value(u.m) == 6378136.6
    assert earth.OMEGA.to_value(u.rad / u.s) == 7.292115e-5
    assert float(earth.J2) == 1.0826359e-3
    assert float(earth.H) == 3273795e-9


def test_moments_reproduce_j2_and_h():
    """The definitions the moments are built from hold to rounding."""
    a, b, c = earth.moments()
    mr2 = earth.mass() * earth.R_EQ**2
    abar = 0.5 * (a + b)
    assert abs(float(((c - abar) / mr2).decompose()) / float(earth.J2) - 1) < 1e-13
    assert abs(float((c - abar) / c) / float(earth.H) - 1) < 1e-12
    assert a < b < c
    # C/(M R^2) = 0.3307 (IERS 2010 H and J2; e.g. Lambeck 1980 Table 2.1: 0.3308)
    assert abs(float((c / mr2).decompose()) - 0.3307) < 1e-4
    # (B - A)/C = 2.2e-5 (Liu & Chao 1991, Geophys. J. Int. 106, 699)
    assert 2.15e-5 < float((b - a) / c) < 2.25e-5


def test_euler_period_is_304_sidereal_days():
    """A/(C - A) = (1 - H)/H sidereal days: 304.45 (e.g. Lambeck 1980, sec. 3.1: ~305 d)."""
    sidereal = (2 * np.pi * u.rad / earth.OMEGA).to(u.day)
    h = float(earth.H)
    t_e = earth.euler_period()
    assert abs(float(t_e / sidereal) - (1 - h) / h) < 1e-11 * (1 - h) / h
    assert abs(float(t_e / sidereal) - 304.45) < 0.01
    assert abs(t_e.to_value(u.day) - 303.6) < 0.05  # REFERENCES: ~303.6 solar days
    # the triaxial period differs at the (B - A)/(C - A) ~ 7e-3 level squared, not more
    rel = abs(float(earth.euler_period(triaxial=True) / t_e) - 1)
    assert 0 < rel < 1e-4


def test_secular_love_number_and_chandler_period():
    """k_s ~ 0.94 and k2 = 0.28 gives ~433 d (Munk & MacDonald 1960; Lambeck 1980)."""
    ks = float(earth.secular_love_number())
    assert abs(ks - 0.938) < 0.002
    t_c = earth.chandler_period(0.28)
    assert abs(t_c.to_value(u.day) - 433) < 1.0
    t_e = earth.euler_period()
    assert abs(float(earth.chandler_period(0.3 * u.one) * (1 - 0.3 / ks) / t_e) - 1) < 1e-14
    with pytest.raises(ValueError, match="k2"):
        earth.chandler_period(1.0)
    with pytest.raises(ValueError, match="k2"):
        earth.chandler_period(-0.1)
    with pytest.raises(u.UnitConversionError, match="k2"):
        earth.chandler_period(0.28 * u.deg)


def test_rigid_body_wobble_angle_and_units():
    w_deg = earth.rigid_body((0.2 / 3600) * u.deg)
    w_as = earth.rigid_body(0.2 * u.arcsec)
    om = np.asarray(u.Quantity(w_as.omega, u.rad / u.s).value if hasattr(w_as.omega, "unit")
                    else w_as.omega)
    om_deg = np.asarray(w_deg.omega.value if hasattr(w_deg.omega, "unit") else w_deg.omega)
    assert np.allclose(om, om_deg, rtol=1e-15, atol=0)
    angle = np.arctan2(om[0], om[2])
    assert abs(angle - (0.2 * u.arcsec).to_value(u.rad)) < 1e-15 * angle + 1e-24
    assert abs(np.linalg.norm(om) / earth.OMEGA.to_value(u.rad / u.s) - 1) < 1e-15
    with pytest.raises(u.UnitConversionError, match="wobble"):
        earth.rigid_body(1.0 * u.m)
    with pytest.raises(ValueError, match="wobble"):
        earth.rigid_body(-1.0 * u.arcsec)
