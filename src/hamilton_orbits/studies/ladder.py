"""The physics ladder against DE440: each rung adds one piece of JPL's model.

Every rung starts from DE440's own state at J2000 (:meth:`System.from_ephemeris`,
ICRF axes) and integrates with ``radau15``; the residuals are the heliocentric
positions against DE440's (the Moon: geocentric), in km and in arcsec as seen
from the Sun (the Moon: from the Earth).  Nothing is fitted: every constant is
DE440's or a cited paper's (see :mod:`hamilton_orbits.effects`).

Rungs (:data:`RUNGS`), each a name, whether the 16 asteroids are bodies, and the
effect list:

1. ``newtonian``: point masses, Newton only;
2. ``gr``: plus the Sun's first post-Newtonian field (``gr``, one body);
3. ``eih``: the Einstein-Infeld-Hoffmann equations for every body instead;
4. ``sun_j2``: plus the Sun's J2 (``j2`` on the Sun, DE440's J2SUN);
5. ``sun_lt``: plus the Sun's Lense-Thirring field (DE440's MOISUN, OMGSUN);
6. ``figures``: plus the Earth's J2-J4 (``zonal``, about the Earth's pole of each
   time, the IAU 2006 precession) and the Moon's J2, C22 (``moon_figure``);
7. ``tides``: plus the tides raised on the Earth (``earth_tides``, about the same
   pole);
8. ``asteroids``: plus the 16 most massive asteroids as bodies (JPL's sb441-n16;
   72% of the GM of DE440's 343), their own 1PN fields left out;
9. ``ring``: plus DE440's Kuiper-belt ring (``kuiper_ring``).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from hamilton_orbits import ephemeris as de

__all__ = ["BODIES", "RUNGS", "Rung", "RungResult", "residuals", "run_rung"]

# the bodies the ladder reports; "moon" is geocentric, "earth-moon-barycenter" the
# barycentre of the simulated Earth and Moon
BODIES = ("mercury", "venus", "earth-moon-barycenter", "earth", "mars", "jupiter",
          "saturn", "uranus", "neptune", "pluto", "moon")


@dataclass(frozen=True)
class Rung:
    """One rung: its name, whether the 16 asteroids are bodies, the effect list."""

    name: str
    asteroids: bool
    effects: tuple[Any, ...]


_SUN_J2 = {"name": "j2", "body": "sun"}
_SUN = (_SUN_J2, "lense_thirring")
# the Earth's figure and tides about its pole of date (the run starts at J2000)
_ZONAL = {"name": "zonal", "pole": "IAU2006"}
_TIDES = {"name": "earth_tides", "pole": "IAU2006"}
_FIGURES = (_ZONAL, "moon_figure")
# with the asteroids as bodies, their own 1PN fields are left out (each is < 1e-9 of
# the Sun's 1PN field on any planet, far below rounding); every body still feels the
# 1PN fields of the Sun, planets, Moon and Pluto, and the asteroids' Newtonian pull
_EIH_MAJOR = {"name": "eih", "sources": de.DEFAULT_BODIES}
RUNGS: tuple[Rung, ...] = (
    Rung("newtonian", False, ()),
    Rung("gr", False, ("gr",)),
    Rung("eih", False, ("eih",)),
    Rung("sun_j2", False, ("eih", _SUN_J2)),
    Rung("sun_lt", False, ("eih", *_SUN)),
    Rung("figures", False, ("eih", *_SUN, *_FIGURES)),
    Rung("tides", False, ("eih", *_SUN, *_FIGURES, _TIDES)),
    Rung("asteroids", True, (_EIH_MAJOR, *_SUN, *_FIGURES, _TIDES)),
    Rung("ring", True, (_EIH_MAJOR, *_SUN, *_FIGURES, _TIDES, "kuiper_ring")),
)


@dataclass(frozen=True)
class RungResult:
    """Residuals of one rung against DE440.

    Attributes
    ----------
    rung : Rung
    years : ndarray, shape (n_t,)
        Julian years from J2000 (whole years, from the shipped reference).
    names : tuple of str
        :data:`BODIES`.
    km : ndarray, shape (n_t, n)
        Position residual, km (heliocentric; the Moon geocentric).
    arcsec : ndarray, shape (n_t, n)
        The same as an angle seen from the Sun (the Moon: from the Earth).
    wall_time : float
        Seconds in the integrator (compiling the right-hand side excluded).
    steps : int
    """

    rung: Rung
    years: np.ndarray
    names: tuple[str, ...]
    km: np.ndarray
    arcsec: np.ndarray
    wall_time: float
    steps: int


def residuals(names: Sequence[str], r: np.ndarray, years: np.ndarray, frame: str = "icrs",
              start_jd: float = de.J2000_JD) -> tuple[np.ndarray, np.ndarray]:
    """Residuals (km, arcsec) of simulated barycentric positions ``r`` (n_t, n, 3), au,
    on the axes of ``frame`` (:func:`hamilton_orbits.frames.frame_rotation`), at
    ``years`` (Julian years) after the run's start ``start_jd`` (TDB Julian date)
    against DE440 at those dates (turned onto those axes): its shipped table at
    J2000 and whole years after, the ``[ephemeris]`` extra's kernel at any other
    date (a ValueError naming the extra without it).

    Examples
    --------
    >>> from hamilton_orbits import System
    >>> s = System.from_ephemeris()
    >>> km, arcsec = residuals(s.names, s.r.value[None], np.array([0]))
    >>> float(km.max()) < 1e-6
    True
    >>> km, _ = residuals(s.names, s.r.value[None], np.array([10]),  # (started 1990)
    ...                   start_jd=de.J2000_JD - 3652.5)
    >>> float(km.max()) < 1e-6
    True
    """
    _, ref_names, _ = de.reference_table()
    jd = start_jd + 365.25 * np.asarray(years, dtype=np.float64)
    ref = de.heliocentric_positions(jd, ref_names, frame)
    au_km = de.constant("AU")
    idx = {n: k for k, n in enumerate(names)}
    helio = r - r[:, idx["sun"]][:, None, :]
    e, m = helio[:, idx["earth"]], helio[:, idx["moon"]]
    w = de.gm("moon") / (de.gm("earth") + de.gm("moon"))
    km = np.empty((len(years), len(BODIES)))
    arcsec = np.empty_like(km)
    for k, name in enumerate(BODIES):
        if name == "moon":
            ours = m - e
            theirs = ref[:, ref_names.index("moon")] - ref[:, ref_names.index("earth")]
        else:
            ours = e + w * (m - e) if name == "earth-moon-barycenter" else helio[:, idx[name]]
            theirs = ref[:, ref_names.index(name)]
        d = np.linalg.norm(ours - theirs, axis=1)
        km[:, k] = d * au_km
        arcsec[:, k] = np.degrees(d / np.linalg.norm(theirs, axis=1)) * 3600.0
    return km, arcsec


def run_rung(rung: Rung, years: int = 100) -> RungResult:
    """Integrate one rung from DE440's J2000 state for ``years`` (at most 100).

    The right-hand side is compiled by a one-day run first, so that
    ``wall_time`` measures the integration only.

    Examples
    --------
    >>> res = run_rung(RUNGS[0], years=1)
    >>> bool(res.km[-1, BODIES.index("earth")] < 100.0)
    True
    """
    import astropy.units as u

    from hamilton_orbits.nbody import System
    from hamilton_orbits.simulation import integrate

    if not 1 <= years <= 100:
        raise ValueError(f"Expected `years` in 1..100 (the shipped reference), got {years!r}")
    bodies = (*de.DEFAULT_BODIES, *de.ASTEROIDS) if rung.asteroids else de.DEFAULT_BODIES
    system = System.from_ephemeris("J2000", bodies=bodies)
    integrate(system, 1.0 * u.day, effects=list(rung.effects))  # compile
    grid = np.arange(years + 1)
    start = time.perf_counter()
    traj = integrate(system, grid * 365.25 * u.day, effects=list(rung.effects))
    wall = time.perf_counter() - start
    km, arcsec = residuals(system.names, traj.r.to_value(u.au), grid)
    return RungResult(rung, grid.astype(float), BODIES, km, arcsec, wall, int(traj.steps))
