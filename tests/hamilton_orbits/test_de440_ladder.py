"""The physics ladder against DE440: each rung brings its bodies closer.

10 years in the default suite (what 10 years can show: the tide's quadratic
signature is below the Moon's other residuals there, so its rung is checked over
100 years only), the whole century under ``-m slow``.  The bounds are the measured
residuals (benchmarks/results/de440_ladder.md) with a factor 1.5 margin for the
step sequence, which differs across machines only by rounding.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest

from hamilton_orbits.studies import ladder


@functools.cache
def _run(name: str, years: int) -> ladder.RungResult:
    rung = next(r for r in ladder.RUNGS if r.name == name)
    return ladder.run_rung(rung, years)


def _km(name: str, years: int, body: str) -> float:
    res = _run(name, years)
    return float(res.km[years, res.names.index(body)])


# (rung, the rung below it, bodies it must bring closer)
STEPS_10 = [
    ("gr", "newtonian", ("mercury", "venus", "earth-moon-barycenter", "mars", "jupiter")),
    ("eih", "gr", ("venus", "earth-moon-barycenter")),
    ("sun_j2", "eih", ("mercury", "venus")),
    ("sun_lt", "sun_j2", ("mercury",)),
    ("figures", "sun_lt", ("moon", "earth")),
    ("asteroids", "tides", ("mercury", "earth-moon-barycenter", "saturn")),
    ("ring", "asteroids", ("uranus", "neptune", "pluto")),
]


@pytest.mark.parametrize(("rung", "below", "bodies"), STEPS_10)
def test_ladder_10_years(rung, below, bodies):
    for body in bodies:
        assert _km(rung, 10, body) < _km(below, 10, body), body


def test_ladder_10_years_top_rung():
    """The top rung after 10 years (measured: Mercury 0.032, Venus 0.089, EMB 0.19,
    Mars 0.84, Jupiter 4.9, Saturn 1.75, Uranus 0.37, Neptune 0.35, Moon 0.59 km)."""
    bounds = {"mercury": 0.05, "venus": 0.14, "earth-moon-barycenter": 0.3, "mars": 1.3,
              "jupiter": 7.4, "saturn": 2.7, "uranus": 0.55, "neptune": 0.53, "moon": 0.9}
    for body, bound in bounds.items():
        assert _km("ring", 10, body) < bound, body


STEPS_100 = [
    *STEPS_10[:2],
    ("sun_j2", "eih", ("mercury",)),  # Venus moves away over the century: docs/de440_ladder.md
    *STEPS_10[3:5],
    ("tides", "figures", ("moon",)),
    ("asteroids", "tides", ("mercury", "earth-moon-barycenter", "mars", "saturn", "uranus")),
    ("ring", "asteroids", ("uranus", "neptune", "pluto")),
]


@pytest.mark.slow
@pytest.mark.parametrize(("rung", "below", "bodies"), STEPS_100)
def test_ladder_100_years(rung, below, bodies):
    for body in bodies:
        assert _km(rung, 100, body) < _km(below, 100, body), body


@pytest.mark.slow
def test_ladder_100_years_goals_reached():
    """The issue's goals that the top rung reaches after 100 years (EMB 3, Mars 3,
    Saturn 20, Uranus 20, Neptune 100, Moon 20 km; measured 2.72, 2.45, 19.96, 1.88,
    73, 3.1).  Saturn meets its goal by 40 m: its bound carries 1% for a change in
    the step sequence, which moves it by far less."""
    goals = {"earth-moon-barycenter": 3.0, "mars": 3.0, "saturn": 20.2, "uranus": 20.0,
             "neptune": 100.0, "moon": 20.0}
    for body, goal in goals.items():
        assert _km("ring", 100, body) < goal, body


def test_the_bundled_scene_is_the_top_rung():
    """``de440-century`` is the ladder's top rung as a scene: over 10 years its table
    holds the rung's residuals (same state, same effects, same integrator)."""
    import astropy.units as u

    from hamilton_orbits import Scene
    from hamilton_orbits.studies.ladder import BODIES, RUNGS, run_rung

    result = Scene.bundled("de440-century").with_values({"duration": "10 yr"}).run(
        progress=False)
    rung = run_rung(RUNGS[-1], years=10)
    assert RUNGS[-1].name == "ring"
    km = result.diagnostics["de440_km"]
    np.testing.assert_allclose(km[-1], rung.km[-1], rtol=1e-6)
    assert result.diagnostics["de440_years"][-1] == 10
    assert km[-1, BODIES.index("mercury")] < 0.1 and km[-1, BODIES.index("moon")] < 2.0
    assert result.times[-1].to_value(u.yr) == 10.0


def test_a_short_runs_table_shows_its_last_year():
    """The scene's residual table had a column at 10, 50 and 100 years only: a
    2-year run printed the bodies' names and no number.  It now ends with the last
    whole year, whose values are the diagnostics' own."""
    from hamilton_orbits import Scene
    from hamilton_orbits.studies.ladder import BODIES

    result = Scene.bundled("de440-century").with_values({"duration": "2 yr"}).run(
        progress=False)
    rows = result.tables["residuals against DE440 (heliocentric; the Moon geocentric)"]
    km = result.diagnostics["de440_km"]
    assert [list(row) for row in rows] == [["body", "2 yr"]] * len(BODIES)
    moon = BODIES.index("moon")
    assert rows[moon]["2 yr"].startswith(f"{km[-1, moon]:.3g} km")


def test_residuals_are_taken_at_the_runs_own_dates():
    """Positions are compared with DE440 at the start's epoch plus the years (issue
    35 item 7: a run started in 1950 was compared with the J2000 table).  DE440's
    own J2000 states, as a run started ten years before J2000 would hold them ten
    years on, have no residual; the same states as year 10 of a run started at
    J2000 have residuals of the size of the orbits."""
    from hamilton_orbits import System
    from hamilton_orbits import ephemeris as de

    s = System.from_ephemeris()
    r = s.r.value[None]
    km, _ = ladder.residuals(s.names, r, np.array([10]), start_jd=de.J2000_JD - 3652.5)
    assert float(km.max()) < 1e-6
    km, _ = ladder.residuals(s.names, r, np.array([10]))
    assert float(km[0, ladder.BODIES.index("mars")]) > 1e7


def test_residuals_at_dates_the_package_does_not_ship_need_the_extra():
    from hamilton_orbits import System
    from hamilton_orbits import ephemeris as de

    s = System.from_ephemeris()
    start = de.J2000_JD - 18262.5  # 1950, as the run
    if de.kernel_available():  # (the extra installed: DE440's kernel at those dates)
        from astropy.time import Time

        then = System.from_ephemeris(epoch=Time(start + 365.25, format="jd", scale="tdb"))
        km, _ = ladder.residuals(then.names, then.r.value[None], np.array([1]),
                                 start_jd=start)
        assert float(km.max()) < 1e-6
    else:
        with pytest.raises(ValueError, match=r"needs the kernel: .*hamilton-orbits\[ephemeris\]"):
            ladder.residuals(s.names, s.r.value[None], np.array([1]), start_jd=start)


def test_the_scene_analysis_compares_at_the_runs_own_dates():
    """The de440_residuals analysis takes the start's epoch from the scene: a run
    started ten years before J2000 whose outputs at years 10 and 11 hold DE440's own
    positions at J2000 and J2000 + 1 yr has no residual (the shipped table; it read
    against years 10 and 11 after J2000 before)."""
    from types import SimpleNamespace

    import astropy.units as u

    from hamilton_orbits import System
    from hamilton_orbits import ephemeris as de
    from hamilton_orbits.scenes.nbody.analyses import ANALYSIS_FUNCTIONS

    s = System.from_ephemeris()
    _, ref_names, ref = de.reference_table()
    r = np.zeros((2, len(s.names), 3))  # barycentric: the Sun at 0, the rest from it
    for k, name in enumerate(s.names):
        if name in ref_names:
            r[:, k] = ref[[0, 1], ref_names.index(name)]
    result = SimpleNamespace(
        times=[10.0, 11.0] * u.yr, states={"r": r * u.au}, metrics={}, tables={},
        diagnostics={}, plotters=[],
        scene=SimpleNamespace(name="t", spec={"initial": {
            "ephemeris": {"epoch": "1990-01-01T00:00:00"}, "frame": "icrs"}}))  # (J2000 - 3652.5 d)
    ANALYSIS_FUNCTIONS["de440_residuals"](result, s, {"name": "de440_residuals"})
    assert np.max(result.diagnostics["de440_km"]) < 1e-6, result.metrics
