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
scenes (``[initial] frame``) and the figures' axis labels read it.

References
----------
J. L. Hilton et al., "Report of the IAU Division I Working Group on Precession and
the Ecliptic", Celest. Mech. Dyn. Astr. 94, 351 (2006).
G. Petit, B. Luzum (eds.), IERS Conventions (2010), IERS Technical Note 36.
"""

from __future__ import annotations

import numpy as np

__all__ = ["FRAMES", "OBLIQUITY_J2000_ARCSEC", "check_frame", "frame_label",
           "frame_rotation"]

#: IAU 2006 mean obliquity of the ecliptic at J2000 (Hilton et al. 2006), arcseconds.
OBLIQUITY_J2000_ARCSEC = 84381.406

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
