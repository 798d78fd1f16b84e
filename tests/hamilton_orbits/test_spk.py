"""spk: DE440's own Chebyshev segments evaluated by a compiled kernel.

References: the shipped yearly table of DE440's heliocentric positions (written
by jplephem from the kernel, tools/make_de440_tables.py), the velocities' own
positions (the derivative of the same series), and jplephem on the kernel itself
where the ``[ephemeris]`` extra is installed.
"""

from __future__ import annotations

import numpy as np
import pytest

from hamilton_orbits import ephemeris as de
from hamilton_orbits.ephemeris import CHAINS
from hamilton_orbits.spk import EXCERPT, Segments

NAMES = [n for n in CHAINS if n != "sun"]


def test_the_excerpt_gives_the_shipped_yearly_positions():
    """At J2000, + 1 yr and + 2 yr: heliocentric positions to 2 ulp of each body's
    distance (Pluto's 30 au: 7e-15 au, 1 mm; the table's km -> au rounding and
    the order of the sums)."""
    seg = Segments.load(EXCERPT)
    _, ref_names, ref = de.reference_table()
    jd = de.J2000_JD + 365.25 * np.arange(3)
    r, _ = seg.states(jd, ["sun", *ref_names])
    helio = r[:, 1:] - r[:, :1]
    ulp = np.spacing(np.linalg.norm(ref[:3], axis=-1, keepdims=True))
    assert np.all(np.abs(helio - ref[:3]) <= 2 * ulp)


def test_velocities_are_the_derivative_of_the_positions():
    """Central differences of the positions over 3e-4 day: truncation h^2 |r'''| / 6,
    at most 5e-12 au/day (Mercury at perihelion, |r'''| ~ (GM / r^2) v / r =
    3.5e-4 au/day^3), rounding about 1e-16 au / h = 3e-13; the step is the one the
    dates hold (their difference is exact)."""
    seg = Segments.load(EXCERPT)
    jd = de.J2000_JD + np.array([0.3, 17.77, 100.5, 400.123, 700.0])
    h = 3e-4
    _, v = seg.states(jd, NAMES)
    rp, _ = seg.states(jd + h, NAMES)
    rm, _ = seg.states(jd - h, NAMES)
    step = ((jd + h) - (jd - h))[:, None, None]  # (jd + h is rounded to 5e-10 day)
    np.testing.assert_allclose(v, (rp - rm) / step, rtol=0, atol=1e-11)


def test_a_date_outside_the_segments_or_an_unknown_body_is_refused():
    seg = Segments.load(EXCERPT)
    with pytest.raises(ValueError, match=r"within JD .* got 2451000.5 at index 1"):
        seg.states([de.J2000_JD, 2451000.5], ["earth"])
    with pytest.raises(ValueError, match=r"`names` among the bodies .* 'ceres' at index 1"):
        seg.states([de.J2000_JD], ["earth", "ceres"])


@pytest.mark.skipif(not de.kernel_available(),
                    reason="needs the DE440 kernel: pip install 'hamilton-orbits[ephemeris]'")
def test_the_segments_are_jplephems_evaluation_of_the_kernel():
    """Any dates of DE440 (here 1850-2150): the compiled sums agree with jplephem's
    to 1e-15 au and 1e-17 au/day relative to the distances (summation order)."""
    rng = np.random.default_rng(440)
    jd = np.sort(rng.uniform(2396758.5, 2506331.5, 200))
    seg = Segments.from_kernel(jd[0], jd[-1])
    r, v = seg.states(jd, NAMES)
    kernel = de.spk_kernel()
    au = de.constant("AU")
    for k, name in enumerate(NAMES):
        want_r, want_v = np.zeros((3, jd.size)), np.zeros((3, jd.size))
        for c, t in CHAINS[name]:
            p, dp = kernel[c, t].compute_and_differentiate(np.floor(jd), jd - np.floor(jd))
            want_r += p
            want_v += dp
        np.testing.assert_allclose(r[:, k], want_r.T / au, rtol=1e-15, atol=1e-15)
        np.testing.assert_allclose(v[:, k], want_v.T / au, rtol=1e-13, atol=1e-17)


def _no_kernel(*args):
    raise AssertionError("the compiled kernel ran before the arguments were checked")


@pytest.mark.parametrize(
    ("jd", "match"),
    [
        (np.full((2, 2), de.J2000_JD), r"`jd` to be one date or a 1-d array .* shape \(2, 2\)"),
        ([de.J2000_JD, np.inf], r"`jd` to be finite, got inf at index 1"),
        ([np.nan], r"`jd` to be finite, got nan at index 0"),
        (["noon"], r"`jd` to be numeric"),
    ],
)
def test_bad_dates_are_refused_naming_jd_before_the_kernel(monkeypatch, jd, match):
    """Dates of shape (2, 2) reached the compiled kernel (a numba TypingError dump,
    after the "compiling" notice), an infinite date a RuntimeWarning from
    ``jd - floor(jd)`` (an error under the suite's warnings filter), a NaN a
    "within JD ..." message that did not say what was wrong, a word numpy's bare
    "could not convert string to float": now a ValueError naming `jd` (the index and
    the value), before any kernel runs."""
    monkeypatch.setattr("hamilton_orbits.spk.add_states", _no_kernel)
    seg = Segments.load(EXCERPT)
    with pytest.raises(ValueError, match=match):
        seg.states(jd, ["earth"])


def test_every_name_is_checked_before_the_kernel(monkeypatch):
    """An unknown body after a known one was refused only after the known one's
    segments had been evaluated (compiling the kernel on a first run)."""
    monkeypatch.setattr("hamilton_orbits.spk.add_states", _no_kernel)
    seg = Segments.load(EXCERPT)
    with pytest.raises(ValueError, match=r"`names` among the bodies .* 'ceres' at index 1"):
        seg.states([de.J2000_JD], ["earth", "ceres"])


def test_one_name_alone_is_a_list_of_one():
    """``names="earth"`` was read letter by letter ("got 'e' at index 0"): one name
    alone is a list of one, as for the package's other ``bodies`` arguments."""
    seg = Segments.load(EXCERPT)
    r, v = seg.states(de.J2000_JD, "Earth")
    want_r, want_v = seg.states([de.J2000_JD], ["earth"])
    assert r.shape == (1, 1, 3)
    np.testing.assert_array_equal(r, want_r)
    np.testing.assert_array_equal(v, want_v)
