"""The frames a state's axes can be given in: the ICRS and the J2000 mean ecliptic.

States from astropy's ephemeris (and JPL's) come on the axes of the ICRS, whose
x-y plane is (within 0.02") the mean equator of J2000: Mars's orbit is then
inclined 24.7 degrees to it, not the 1.85 degrees that tables of ecliptic
elements give.  ``"ecliptic"`` is the mean ecliptic and equinox of J2000: x the
equinox, z the ecliptic pole, reached from the ICRS by a rotation about x by the
IAU 2006 mean obliquity at J2000, 84381.406" (Hilton et al. 2006; IERS
Conventions 2010, eq. 5.40 at t = 0).  The 0.02" frame bias between the ICRS
and the dynamical equator of J2000 is not applied, as JPL Horizons' ecliptic
frame does not apply it either.

This is the one place the rotation is written; ``System.solar_system``, the
scenes (``[initial] frame``) and the figures' axis labels read it.  The poles that
orient the effects' bodies are here too, in either frame: the J2000 mean ecliptic's
(:func:`ecliptic_pole`), the Sun's (:func:`sun_pole`) and the Earth's and the
Moon's (:func:`pole`); :mod:`hamilton_orbits.ephemeris` gives them under its name
as well.

References
----------
J. L. Hilton et al., "Report of the IAU Division I Working Group on Precession and
the Ecliptic", Celest. Mech. Dyn. Astr. 94, 351 (2006).
G. Petit, B. Luzum (eds.), IERS Conventions (2010), IERS Technical Note 36.
B. A. Archinal et al., "Report of the IAU Working Group on Cartographic
Coordinates and Rotational Elements: 2015", Celest. Mech. Dyn. Astr. 130, 22 (2018).
"""

from __future__ import annotations

import numpy as np

__all__ = ["FRAMES", "OBLIQUITY_J2000_ARCSEC", "SUN_POLE_DEC_DEG", "SUN_POLE_RA_DEG",
           "check_frame", "ecliptic_pole", "frame_label", "frame_rotation", "pole",
           "sun_pole"]

#: IAU 2006 mean obliquity of the ecliptic at J2000 (Hilton et al. 2006), arcseconds.
OBLIQUITY_J2000_ARCSEC = 84381.406

#: The Sun's north pole, IAU WGCCRE 2015 (Archinal et al. 2018, table 1): fixed in
#: the ICRF, degrees.
SUN_POLE_RA_DEG = 286.13
SUN_POLE_DEC_DEG = 63.87

#: The frames a state can be given in, and what each one's axes are.
FRAMES = {
    "icrs": "ICRS axes (equatorial)",
    "ecliptic": "J2000 mean ecliptic and equinox",
}


def check_frame(frame: object, name: str = "frame") -> str:
    """``frame`` if it is one of :data:`FRAMES`, else a ValueError naming ``name``.

    Examples
    --------
    >>> check_frame("ecliptic")
    'ecliptic'
    >>> check_frame("galactic")
    Traceback (most recent call last):
    ...
    ValueError: Expected `frame` to be 'icrs' or 'ecliptic', got 'galactic'
    """
    if not isinstance(frame, str) or frame not in FRAMES:
        raise ValueError(f"Expected `{name}` to be 'icrs' or 'ecliptic', got {frame!r}")
    return frame


def frame_rotation(frame: str) -> np.ndarray:
    """The 3x3 matrix taking ICRS vectors to ``frame`` (``"icrs"`` or ``"ecliptic"``).

    Parameters
    ----------
    frame : {"icrs", "ecliptic"}

    Returns
    -------
    ndarray, shape (3, 3)
        ``v_frame = M @ v_icrs``; for ``"ecliptic"`` a rotation about x by the
        obliquity epsilon: rows ``[1, 0, 0]``, ``[0, cos e, sin e]``,
        ``[0, -sin e, cos e]``.

    Raises
    ------
    ValueError
        For another frame, naming it.

    Examples
    --------
    >>> m = frame_rotation("ecliptic")
    >>> bool(np.allclose(m @ [0.0, 0.0, 1.0], [0.0, 0.3977771559, 0.9174820621]))
    True
    >>> frame_rotation("icrs").tolist()[0]
    [1.0, 0.0, 0.0]
    """
    if check_frame(frame) == "icrs":
        return np.eye(3)
    eps = np.deg2rad(OBLIQUITY_J2000_ARCSEC / 3600.0)
    c, s = np.cos(eps), np.sin(eps)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, s], [0.0, -s, c]])


def frame_label(frame: str) -> str:
    """What the axes of ``frame`` are, for axis labels and summaries.

    Examples
    --------
    >>> frame_label("icrs")
    'ICRS axes (equatorial)'
    """
    return FRAMES[check_frame(frame)]


def ecliptic_pole(frame: str = "icrs") -> np.ndarray:
    """The unit normal of the J2000 mean ecliptic in ``frame``.

    Examples
    --------
    >>> ecliptic_pole("ecliptic")
    array([0., 0., 1.])
    >>> bool(np.allclose(ecliptic_pole("icrs"), [0.0, -0.3977771559, 0.9174820621]))
    True
    """
    if frame == "ecliptic":
        return np.array([0.0, 0.0, 1.0])
    # the third row of the ICRS -> ecliptic rotation: the ecliptic z axis in ICRS
    return frame_rotation(frame) @ frame_rotation("ecliptic")[2]


def sun_pole(frame: str = "icrs") -> np.ndarray:
    """The Sun's north pole (IAU WGCCRE 2015: RA 286.13 deg, Dec 63.87 deg) in ``frame``.

    Examples
    --------
    >>> bool(abs(np.degrees(np.arccos(sun_pole("ecliptic")[2])) - 7.25) < 0.01)
    True
    """
    return frame_rotation(frame) @ _radec(SUN_POLE_RA_DEG, SUN_POLE_DEC_DEG)


def pole(name: str, frame: str = "icrs") -> np.ndarray:
    """The pole :func:`hamilton_orbits.ephemeris.body_specs` gives body ``name``
    (``"sun"``, ``"earth"``, ``"moon"``), in ``frame``: the Sun's IAU pole
    (:func:`sun_pole`), the Earth's mean pole of J2000 (the ICRF z axis to 0.02"),
    the Moon's mean pole (IAU WGCCRE 2015, Archinal et al. 2018: the constant terms
    RA 269.9949 deg, Dec 66.5392 deg).  The Moon's is the centre about which its
    pole turns in 18.6 years (Cassini's laws), 0.02 deg from the ecliptic's pole;
    its pole at any date is 1.54 deg from there (at J2000, with the WGCCRE's
    periodic terms, RA 266.86 deg, Dec 65.64 deg: 1.56 deg from this one).  A
    ``j2`` of the Moon about it is therefore an average over that cycle; the
    ``moon_figure`` effect follows the Moon's pole as it turns.

    Examples
    --------
    >>> pole("earth", "icrs").tolist()
    [0.0, 0.0, 1.0]
    >>> bool(np.allclose(pole("earth", "ecliptic"), [0.0, 0.3977771559, 0.9174820621]))
    True
    """
    if name == "sun":
        return sun_pole(frame)
    rot = frame_rotation(frame)
    if name == "earth":
        return rot @ np.array([0.0, 0.0, 1.0])
    if name == "moon":
        return rot @ _radec(269.9949, 66.5392)
    raise ValueError(f"Expected `name` to be 'sun', 'earth' or 'moon', got {name!r}")


def _radec(ra_deg: float, dec_deg: float) -> np.ndarray:
    """The unit vector of right ascension ``ra_deg`` and declination ``dec_deg``."""
    ra, dec = np.deg2rad(ra_deg), np.deg2rad(dec_deg)
    return np.array([np.cos(dec) * np.cos(ra), np.cos(dec) * np.sin(ra), np.sin(dec)])
