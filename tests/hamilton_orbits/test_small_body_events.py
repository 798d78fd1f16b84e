"""Close encounters of small bodies with the ephemeris's bodies (issue 35 item 2:
``small_bodies.propagate(events=...)``), on the shipped excerpt of DE440."""

from __future__ import annotations

import astropy.units as u
import numpy as np
import pytest
from astropy.time import Time
from numba import njit

from hamilton_orbits import engine
from hamilton_orbits._kernels import chebyshev
from hamilton_orbits.perturber_field import field_rhs
from hamilton_orbits.small_bodies import propagate
from hamilton_orbits.spk import EXCERPT, Segments

JD0 = 2451545.0
EPOCH = Time(JD0, format="jd", scale="tdb")
T = 40.0  # days: the encounter built below


@pytest.fixture(scope="module")
def excerpt() -> Segments:
    return Segments.load(EXCERPT)


@pytest.fixture(scope="module")
def flyby(excerpt):
    """A rock 0.002 au from the Earth at day 40, moving 0.004 au/day relative to it,
    across the line between them: its closest approach is there and then.  Its
    start is found by integrating back from that state (no event watched)."""
    at, speed = excerpt.states(np.array([JD0 + T]), ["earth"])
    r_t = at[0, 0] + [0.0, 0.002, 0.0]
    v_t = speed[0, 0] + [0.004, 0.0, 0.0]
    back = propagate(r_t * u.au, v_t * u.au / u.day, Time(JD0 + T, format="jd", scale="tdb"),
                     -T * u.day, ephemeris=excerpt, asteroids=False, names=["rock"])
    return back.r[-1, 0], back.v[-1, 0]


def _watch(excerpt, flyby, **kw):
    r0, v0 = flyby
    return propagate(r0, v0, EPOCH, 80 * u.day, ephemeris=excerpt, asteroids=False,
                     names=["rock"], **kw)


# radau15 finds an event on its own step polynomial; dop853 on the cubic Hermite
# interpolant of its steps' ends (the events' generic case, hamilton_orbits._kernels.events),
# whose error at this 0.002 au flyby is 0.2 s and 80 m: so its bounds are 1e-5 day, 1e-9 au
@pytest.mark.parametrize(("method", "t_tol", "d_tol"), [("radau15", 1e-9, 1e-13),
                                                        ("dop853", 1e-5, 1e-9)])
def test_the_closest_approach_is_found_where_a_dense_search_finds_it(excerpt, flyby, method,
                                                                      t_tol, d_tol):
    """Against the rock's own dense outputs (10 s apart) and the ephemeris's Earth:
    the root of ``d . w`` (relative position and velocity) between two outputs by
    linear interpolation, and the straight-line closest distance from the nearest
    output: with radau15 the time to 1e-9 day (0.1 ms) and the distance to 1e-13
    au (15 mm); and the built encounter's (day 40, 0.002 au, 0.004 au/day)."""
    traj = _watch(excerpt, flyby, method=method,
                  events=[{"name": "close_encounter", "bodies": "earth",
                           "distance": 0.01 * u.au}])
    assert len(traj.events) == 1
    row = traj.events[0]
    assert row["bodies"] == "rock-earth" and row["action"] == "record"
    t_ev, d_ev = row["time"].to_value(u.day), row["distance"].to_value(u.au)
    r0, v0 = flyby
    grid = T + np.arange(-200, 201) * (10.0 / 86400)
    dense = propagate(r0, v0, EPOCH, grid * u.day, ephemeris=excerpt, asteroids=False,
                      method=method)
    at, speed = excerpt.states(JD0 + grid, ["earth"])
    d = dense.r[1:, 0].to_value(u.au) - at[:, 0]  # ([0]: the epoch, the first output)
    w = dense.v[1:, 0].to_value(u.au / u.day) - speed[:, 0]
    f = (d * w).sum(axis=-1)
    k = int(np.flatnonzero((f[:-1] < 0) & (f[1:] >= 0))[0])
    t_min = grid[k] + (grid[k + 1] - grid[k]) * f[k] / (f[k] - f[k + 1])
    near = k if t_min - grid[k] < grid[k + 1] - t_min else k + 1
    d_min = np.sqrt(d[near] @ d[near] - f[near] ** 2 / (w[near] @ w[near]))
    assert abs(t_ev - t_min) < t_tol and abs(d_ev - d_min) < d_tol, (t_ev - t_min,
                                                                     d_ev - d_min)
    assert abs(t_ev - T) < t_tol + 1e-9 and abs(d_ev - 0.002) < d_tol + 1e-12
    assert row["speed"].to_value(u.au / u.day) == pytest.approx(0.004, rel=1e-5)


def test_a_shadow_row_follows_the_ephemeris(excerpt):
    """The Earth's and the Moon's shadows, started on their states and driven by
    their ephemeris's second derivatives, are the ephemeris's after 200 days to
    1e-11 au (1.5 m; measured 0.5 m, the Moon's, whose month radau15's default
    tolerance resolves to that: an encounter's distance is found to it)."""
    rhs = field_rhs(excerpt, ["rock"], (JD0, 0.0), (), shadows=("earth", "moon"))
    at, speed = excerpt.states(np.array([JD0, JD0 + 200.0]), ["earth", "moon"])
    r = np.vstack([[[2.0, 0.0, 0.0]], [[0.0, 0.0, 0.0]], at[0]])
    v = np.vstack([[[0.0, 0.01, 0.0]], [[1.0, 0.0, 0.0]], speed[0]])
    out = engine.run(r, v, np.zeros(4), np.array([0.0, 200.0]), rhs, "radau15")
    assert np.abs(out.r[-1, 2:] - at[1]).max() < 1e-11
    assert np.abs(out.v[-1, 2:] - speed[1]).max() < 1e-12


def test_the_acceleration_of_a_segment_is_the_second_derivative_of_its_series():
    """Against numpy's own Chebyshev algebra (``chebder`` twice), to 1e-12."""
    rng = np.random.default_rng(3)
    coef = rng.normal(size=(3, 4, 13))
    init, intlen = 1000.0, 8.0

    @njit
    def acceleration(jd2):  # pragma: no cover - compiled
        out, uu, du = np.zeros(3), np.empty(13), np.empty(13)
        k = chebyshev.acceleration_basis(init, intlen, 4, init, jd2, 13, uu, du)
        chebyshev.add_record_acceleration(coef, k, intlen, du, out)
        return k, out

    for jd2 in (0.3, 9.7, 17.0, 31.99):
        k, got = acceleration(jd2)
        s = 2.0 * (jd2 - k * intlen) / intlen - 1.0
        want = [np.polynomial.chebyshev.chebval(s, np.polynomial.chebyshev.chebder(
            coef[c, k], 2)) * (2.0 / intlen) ** 2 for c in range(3)]
        assert np.allclose(got, want, rtol=1e-12, atol=1e-12 * np.abs(want).max())


def test_chunks_find_the_same_encounters_with_their_bodies_names(excerpt, flyby):
    """Two rocks (one 1e-4 au further out), in one chunk or one each: the same
    encounters, named, in order of time, to the shared steps' rounding."""
    r0, v0 = flyby
    r = np.stack([r0.to_value(u.au), r0.to_value(u.au) + [0.0, 1e-4, 0.0]]) * u.au
    v = np.stack([v0.to_value(u.au / u.day)] * 2) * u.au / u.day
    events = [{"name": "close_encounter", "bodies": ["earth", "moon"], "distance": 0.05}]
    tables = [propagate(r, v, EPOCH, 80 * u.day, ephemeris=excerpt, asteroids=False,
                        names=["a", "b"], events=events, chunk=chunk).events
              for chunk in (1, 2)]
    for table in tables:
        assert sorted(table["bodies"]) == ["a-earth", "a-moon", "b-earth", "b-moon"]
        assert np.all(np.diff(table["time"].to_value(u.day)) >= 0)
    one, two = ({b: (row["time"].to_value(u.day), row["distance"].to_value(u.au))
                 for b, row in zip(t["bodies"], t, strict=True)} for t in tables)
    for key in one:
        assert np.allclose(one[key], two[key], rtol=0, atol=1e-9), key


def test_only_the_named_small_bodies_are_watched(excerpt, flyby):
    r0, v0 = flyby
    r = np.stack([r0.to_value(u.au)] * 2) * u.au
    v = np.stack([v0.to_value(u.au / u.day)] * 2) * u.au / u.day
    traj = propagate(r, v, EPOCH, 80 * u.day, ephemeris=excerpt, asteroids=False,
                     names=["a", "b"], events=[{"name": "close_encounter",
                                                "bodies": ["b", "earth"], "distance": 0.01}])
    assert list(traj.events["bodies"]) == ["b-earth"]


@pytest.mark.parametrize(("events", "kw", "message"), [
    ([{"name": "collision", "bodies": "earth"}], {},
     "Event at index 0: small_bodies.propagate watches 'close_encounter'"),
    ([{"name": "close_encounter", "bodies": "earth", "distance": 0.1, "action": "stop"}], {},
     "Event at index 0: the action is 'record' here"),
    ([{"name": "close_encounter", "bodies": "rock", "distance": 0.1}], {},
     "Event at index 0: `bodies` names no perturber"),
    ([{"name": "close_encounter", "bodies": "vulcan", "distance": 0.1}], {},
     "Event at index 0: `bodies` names 'vulcan', neither a small body nor a perturber"),
    ([{"name": "close_encounter", "bodies": "earth"}], {},
     r"Event at index 0: needs `distance`"),
    ([{"name": "close_encounter", "bodies": "earth", "distance": -1.0}], {},
     r"Event at index 0: expected `distance` > 0"),
    ([{"name": "close_encounter", "bodies": "earth", "distance": 0.1, "when": 3}], {},
     r"Event at index 0: unknown keys \['when'\]"),
    ({"name": "close_encounter"}, {}, "Expected `events` to be a list of mappings"),
    ([{"name": "close_encounter", "bodies": "earth", "distance": 0.1}], {"stm": True},
     "`events` are watched without `stm` or `variational`"),
    # (the same watch twice recorded each encounter twice; the n-body events refuse it)
    ([{"name": "close_encounter", "bodies": "earth", "distance": 0.1},
      {"name": "close_encounter", "bodies": ["earth", "rock"], "distance": 0.1}], {},
     r"Event at index 1 watches rock-earth within 0.1 au as an earlier event does; list "
     r"each event of a pair once"),
])
def test_bad_events_are_refused_by_name(excerpt, flyby, events, kw, message):
    with pytest.raises(ValueError, match=message):
        _watch(excerpt, flyby, events=events, **kw)


def test_a_backward_run_finds_the_encounter_it_came_through(excerpt, flyby):
    """From the rock's state at day 80, back to day 0 (the shadow row of the Earth on
    the ephemeris's second derivative, which time reversal leaves alone; the
    events' times turned back): the one encounter, at day 40 and 0.002 au, where
    the forward run finds it, to 1e-9 day and 1e-13 au (the forward run's own
    bounds against a dense search; measured 2.1e-11 day and 3.6e-14 au)."""
    events = [{"name": "close_encounter", "bodies": "earth", "distance": 0.01 * u.au}]
    there = _watch(excerpt, flyby, events=events)
    back = propagate(there.r[-1], there.v[-1], EPOCH + 80 * u.day, -80 * u.day,
                     ephemeris=excerpt, asteroids=False, names=["rock"], events=events)
    assert len(back.events) == 1 and back.events[0]["bodies"] == "rock-earth"
    t_fwd, t_back = (tr.events[0]["time"].to_value(u.day) for tr in (there, back))
    d_fwd, d_back = (tr.events[0]["distance"].to_value(u.au) for tr in (there, back))
    assert abs((t_back + 80.0) - t_fwd) < 1e-9, (t_back + 80.0) - t_fwd
    assert abs(d_back - d_fwd) < 1e-13, d_back - d_fwd
    assert back.events[0]["speed"].to_value(u.au / u.day) == pytest.approx(0.004, rel=1e-5)
