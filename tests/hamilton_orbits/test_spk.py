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


@pytest.mark.parametrize(("args", "match"), [
    # (two components were read past the array's end: a z from whatever lay after it)
    ((2451545.0, 10.0, np.zeros((2, 1, 2))), r"`coef` .* shape \(3, n records, m "
                                             r"coefficients\), got shape \(2, 1, 2\)"),
    ((2451545.0, 10.0, np.zeros((3, 0, 2))), r"`coef` .* got shape \(3, 0, 2\)"),
    ((2451545.0, 10.0, [[[0.0]]] * 3), r"`coef` .* got \[\["),
    ((2451545.0, 10.0, np.full((3, 1, 2), np.nan)), r"`coef` .* finite, .* index \(0, 0, 0\)"),
    ((2451545.0, 0.0, np.zeros((3, 1, 2))), r"`intlen` .* days > 0 .* got 0.0"),  # (was a
    ((2451545.0, -10.0, np.zeros((3, 1, 2))), r"`intlen` .* got -10.0"),  # ZeroDivisionError;
    ((np.nan, 10.0, np.zeros((3, 1, 2))), r"`init` .* got nan"),  # a negative one was taken)
])
def test_a_segment_of_the_wrong_shape_or_span_is_refused(args, match):
    from hamilton_orbits.spk import Segment

    with pytest.raises(ValueError, match=match):
        Segment(*args)


def test_segments_hold_segments_by_pair_and_a_segments_coef_is_the_kernels_typing():
    from hamilton_orbits.spk import Segment

    seg = Segment(2451545, 10, np.zeros((3, 1, 2), dtype=np.float32)[:, :, ::-1])
    assert seg.coef.dtype == np.float64 and seg.coef.flags.c_contiguous
    assert seg.init == 2451545.0 and isinstance(seg.init, float)
    with pytest.raises(ValueError, match=r"`segments` of Segment values, got tuple for \(0, 10\)"):
        Segments({(0, 10): (2451545.0, 10.0, np.zeros((3, 1, 2)))})
    with pytest.raises(ValueError, match=r"`segments` keyed by \(center, target\)"):
        Segments({"sun": seg})


def test_the_excerpts_documented_span_is_the_one_its_segments_cover():
    """spk.py said the excerpt covers JD 2451504.5 to 2452320.5: the Earth and the
    Moon end at 2452316.5 (a date between was refused for them)."""
    import inspect

    import hamilton_orbits.spk as spk

    segments = Segments.load(EXCERPT)
    ends = {name: min(segments.segments[p].init + segments.segments[p].intlen
                      * segments.segments[p].coef.shape[1] for p in chain)
            for name, chain in CHAINS.items()}
    lo = max(segments.segments[p].init for chain in CHAINS.values() for p in chain)
    assert (lo, ends["earth"], ends["moon"], min(ends.values())) == (2451504.5, 2452316.5,
                                                                     2452316.5, 2452316.5)
    text = " ".join(line.lstrip("#: ").strip() for line in inspect.getsource(spk).splitlines()
                    if line.startswith("#:"))
    assert "from JD 2451504.5; the Earth and the Moon to 2452316.5, the common span" in text
    assert "2452320.5" not in text.split("Venus")[0]
    with pytest.raises(ValueError, match=r"2451504\.5\.\.2452316\.5"):
        segments.states([2452318.0], "earth")
