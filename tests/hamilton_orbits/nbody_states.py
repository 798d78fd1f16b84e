"""Initial states shared by the integrator tests (plain floats, au and day).

The solar system at J2000 is built here independently of the package under
test: positions and velocities from astropy's built-in ephemeris (ERFA's
``epv00`` for the Earth and ``plan94``, Simon et al. 1994, for the planets;
offline), barycentric ICRS, and GM from the DE430 planetary ephemeris (Folkner
et al. 2014, IPN Progress Report 42-196, table 8; the Earth-Moon barycentre and
the planetary systems as single bodies).  The built-in ephemeris is accurate to
about 1e-6 au, which does not matter here: ours and rebound start from the same
floats.
"""

from __future__ import annotations

import numpy as np

__all__ = ["GM_DE430_KM3_S2", "solar_system", "to_rebound"]

AU_KM = 149597870.7  # IAU 2012 Resolution B2
DAY_S = 86400.0

GM_DE430_KM3_S2 = {
    "sun": 132712440041.939400,
    "mercury": 22031.780000,
    "venus": 324858.592000,
    "earth-moon-barycenter": 403503.235502,
    "mars": 42828.375214,
    "jupiter": 126712764.800000,
    "saturn": 37940585.200000,
    "uranus": 5794548.600000,
    "neptune": 6836527.100580,
}


def solar_system() -> tuple[list[str], np.ndarray, np.ndarray, np.ndarray]:
    """Names, r (au), v (au/day) and GM (au^3/day^2) of the Sun and 8 planets at J2000 TDB."""
    import astropy.units as u
    from astropy.coordinates import get_body_barycentric_posvel, solar_system_ephemeris
    from astropy.time import Time

    t = Time("2000-01-01T12:00:00", scale="tdb")
    names = list(GM_DE430_KM3_S2)
    r = np.empty((len(names), 3))
    v = np.empty((len(names), 3))
    with solar_system_ephemeris.set("builtin"):
        for i, name in enumerate(names):
            p, w = get_body_barycentric_posvel(name, t)
            r[i] = p.xyz.to_value(u.au)
            v[i] = w.xyz.to_value(u.au / u.day)
    gm = np.array([GM_DE430_KM3_S2[n] for n in names]) * DAY_S**2 / AU_KM**3
    return names, r, v, gm


def to_rebound(r: np.ndarray, v: np.ndarray, gm: np.ndarray, integrator: str = "ias15"):
    """A rebound simulation (G = 1, so m = GM) of the same floats."""
    import rebound

    sim = rebound.Simulation()
    sim.G = 1.0
    sim.integrator = integrator
    for k in range(len(gm)):
        sim.add(
            m=float(gm[k]),
            x=float(r[k, 0]),
            y=float(r[k, 1]),
            z=float(r[k, 2]),
            vx=float(v[k, 0]),
            vy=float(v[k, 1]),
            vz=float(v[k, 2]),
        )
    n_active = int(np.count_nonzero(gm))
    if n_active < len(gm):
        # massless bodies must come last for rebound's N_active
        assert np.all(gm[:n_active] > 0.0)
        sim.N_active = n_active
    return sim


def rebound_state(sim) -> tuple[np.ndarray, np.ndarray]:
    """Positions and velocities of all particles of ``sim``."""
    r = np.array([p.xyz for p in sim.particles])
    v = np.array([p.vxyz for p in sim.particles])
    return r, v
