"""Trajectory.plot: every body's path about the primary, its start with the direction
of motion, its end; axes with origin and unit; the legend off the data."""

from __future__ import annotations

import astropy.units as u
import matplotlib
import numpy as np
import pytest

from hamilton_orbits import Body, System, integrate

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # (after the backend is chosen)


def _lines(ax, label):
    return [ln for ln in ax.lines if ln.get_label() == label]


def test_paths_about_the_primary_with_units_start_direction_and_end():
    s = System.solar_system("J2000", bodies=["sun", "earth", "mars"])
    traj = integrate(s, np.linspace(0, 2, 200) * u.yr)
    fig = traj.plot()
    ax = fig.axes[0]
    assert ax.get_xlabel() == "x from sun [AU]" and ax.get_ylabel() == "y from sun [AU]"
    rel = (traj.r - traj.r[:, :1]).to_value(u.au)
    for k, name in ((1, "earth"), (2, "mars")):
        (path,) = _lines(ax, name)
        np.testing.assert_array_equal(path.get_xdata(), rel[:, k, 0])  # every output
        np.testing.assert_array_equal(path.get_ydata(), rel[:, k, 1])
    starts = [ln for ln in ax.lines
              if ln.get_marker() == "o" and ln.get_markerfacecolor() == "none"]
    assert sorted((float(ln.get_xdata()[0]), float(ln.get_ydata()[0])) for ln in starts) == \
        sorted((float(rel[0, k, 0]), float(rel[0, k, 1])) for k in (1, 2))
    # the arrows point along each body's velocity relative to the sun at the start
    vel = (traj.v[0] - traj.v[0, 0]).to_value(u.au / u.d)
    arrows = sorted(ax.texts, key=lambda a: a.xyann[0])
    assert len(arrows) == 2
    for arrow in arrows:
        k = 1 if np.isclose(arrow.xyann[0], rel[0, 1, 0]) else 2
        d = np.subtract(arrow.xy, arrow.xyann)
        cos = d @ vel[k, :2] / np.linalg.norm(d) / np.linalg.norm(vel[k, :2])
        assert cos > 1 - 1e-12
    (sun,) = _lines(ax, "sun (primary)")
    assert sun.get_xdata()[0] == sun.get_ydata()[0] == 0.0
    plt.close(fig)


def test_many_bodies_put_the_legend_outside_the_axes():
    s = System.solar_system("J2000")
    fig = integrate(s, np.linspace(0, 1, 50) * u.yr, method="wh", dt=2 * u.day).plot()
    fig.canvas.draw()
    ax = fig.axes[0]
    legend = ax.get_legend().get_window_extent()
    assert legend.x0 >= ax.get_window_extent().x1  # not over the data
    # and within the figure (it was cut off by savefig: x1 = 773 of 650 px)
    assert legend.x1 <= fig.bbox.x1 and legend.y0 >= fig.bbox.y0
    plt.close(fig)


def test_a_plane_is_chosen_and_a_bad_one_named():
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                Body("p", 1e-3, [1.0, 0, 0], [0, 0.6, 0.8])])
    traj = integrate(s, np.linspace(0, 3, 60))
    fig = traj.plot(plane="xz")
    assert fig.axes[0].get_ylabel() == "z from sun [the system's length unit]"
    np.testing.assert_array_equal(_lines(fig.axes[0], "p")[0].get_ydata(),
                                  traj.r[:, 1, 2] - traj.r[:, 0, 2])
    plt.close(fig)
    with pytest.raises(ValueError, match=r"Expected `plane` to be one of \['xy', 'xz', 'yz'\], "
                                         r"got 'xw'"):
        traj.plot(plane="xw")


def test_a_body_an_event_took_out_ends_where_it_left():
    s = System([Body("a", 1.0, [0, 0, 0], [0, 0, 0]),
                Body("b", 1e-3, [2.0, 0, 0], [0, 1.2, 0])])
    traj = integrate(s, np.linspace(0, 20, 200),
                     events=[{"name": "escape", "distance": 4.0, "action": "remove"}])
    fig = traj.plot()
    (path,) = _lines(fig.axes[0], "b")
    assert 0 < len(path.get_xdata()) < 200 and np.isfinite(path.get_xdata()).all()
    plt.close(fig)


def test_a_body_keeps_its_colour_and_a_plain_system_names_its_unit():
    """The start marker took no colour: the cycle moved on by two a body (C0, C2,
    C4), so that a body had another colour beside other figures of the same bodies
    (the Pythagorean example's m4 green in one, orange in the next).  A system of
    plain numbers labelled its axes "x from sun", with no unit."""
    import matplotlib.pyplot as plt

    from hamilton_orbits import Body, System, integrate

    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                Body("a", 1e-3, [1.0, 0, 0], [0, 1.0, 0]),
                Body("b", 1e-3, [0, 2.0, 0], [-0.7, 0, 0]),
                Body("c", 1e-3, [-3.0, 0, 0], [0, -0.58, 0])])
    fig = integrate(s, np.linspace(0.0, 20.0, 200)).plot()
    ax = fig.axes[0]
    paths = [line for line in ax.get_lines() if line.get_label() in ("a", "b", "c")]
    cycle = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    assert [line.get_color() for line in paths] == cycle[:3]
    assert ax.get_xlabel() == "x from sun [the system's length unit]"
    plt.close(fig)


def _leo():
    """A satellite 7000 km from the Earth's centre (e = 0.1), in km and km/s."""
    from hamilton_orbits import KeplerOrbit

    mu = 398600.4418 * u.km**3 / u.s**2
    orb = KeplerOrbit.from_elements(a=7000 * u.km, e=0.1, inc=51.6 * u.deg, lan=0 * u.deg,
                                    argp=0 * u.deg, M=0 * u.deg, mu=mu)
    r, v = orb.state()
    s = System([Body("earth", mu, [0, 0, 0] * u.km, [0, 0, 0] * u.km / u.s),
                Body("sat", 0 * mu, r, v)])
    return integrate(s, np.linspace(0, 2, 121) * u.hour)


def test_a_satellite_s_orbit_is_drawn_in_km():
    """A satellite's orbit was drawn in au: ticks of +-4 under an offset of 1e-5.
    Paths within 0.01 au of the primary are drawn in km (as the scenes' figures)."""
    traj = _leo()
    ax = traj.plot().axes[0]
    assert ax.get_xlabel() == "x from earth [km]"
    (path,) = _lines(ax, "sat")
    rel = (traj.r[:, 1] - traj.r[:, 0]).to_value(u.km)
    np.testing.assert_allclose(path.get_xdata(), rel[:, 0], rtol=1e-14)  # (au -> km)
    # (starts at periapsis, a (1 - e) = 6300 km along x: the node and periapsis there)
    assert path.get_xdata()[0] == pytest.approx(6300.0, rel=1e-12)
    plt.close(ax.figure)


def test_a_merge_breaks_the_kept_body_s_line_and_is_marked():
    """The kept body's line ran from its last output before the merge to the pair's
    centre of mass, a path no body travelled, and nothing marked the merge."""
    s = System([Body("star", 1.0, [0, 0, 0], [0, 0, 0], radius=0.005),
                Body("pa", 1e-3, [1.0, 0, 0], [0, 1.0, 0], radius=0.05),
                Body("pb", 2e-3, [1.0, 0.3, 0], [0, 0.8, 0], radius=0.05)])
    traj = integrate(s, np.linspace(0, 2, 41), events=[{"name": "collision",
                                                         "action": "merge"}])
    (row,) = traj.events
    assert row["bodies"] == "pa-pb" and row["action"] == "merge"
    m = int(np.searchsorted(traj.t, row["time"]))  # the first output after it
    assert np.isnan(traj.r[m, 2]).all() and np.isfinite(traj.r[m - 1, 2]).all()
    fig = traj.plot()
    ax = fig.axes[0]
    rel = traj.r - traj.r[:, :1]
    (pa,) = _lines(ax, "pa")
    x = pa.get_xdata()
    assert len(x) == len(traj.t) + 1 and np.isnan(x[m]) and np.isfinite(np.delete(x, m)).all()
    np.testing.assert_array_equal(np.delete(x, m), rel[:, 1, 0])
    (mark,) = [ln for ln in ax.lines if ln.get_gid() == "merge"]
    assert "merge" in mark.get_label()
    assert (mark.get_xdata()[0], mark.get_ydata()[0]) == (rel[m, 1, 0], rel[m, 1, 1])
    ends = [(float(ln.get_xdata()[0]), float(ln.get_ydata()[0])) for ln in ax.lines
            if ln.get_marker() == "o" and ln.get_markerfacecolor() != "none"]
    assert (rel[m - 1, 2, 0], rel[m - 1, 2, 1]) not in ends  # pb: no ordinary end
    assert (rel[-1, 1, 0], rel[-1, 1, 1]) in ends
    plt.close(fig)


def test_a_backward_run_s_arrow_follows_the_drawn_motion_and_the_title_says_so():
    """The arrow (the "first motion") followed v at t = 0 while the path was drawn
    the other way, and the title did not say time ran backwards."""
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                Body("earth", 3e-6, [1.0, 0, 0], [0, 1.0, 0])])
    traj = integrate(s, np.linspace(0, -3.0, 31))
    fig = traj.plot()
    ax = fig.axes[0]
    (arrow,) = ax.texts
    d = np.subtract(arrow.xy, arrow.xyann)
    drawn = (traj.r[1, 1] - traj.r[0, 1])[:2]  # from the first output to the second
    assert d @ drawn > 0 and d[1] < 0  # along -v (v = +y at the start)
    assert "t = 0 \N{RIGHTWARDS ARROW} -3 (the system's time unit) (backwards)" in \
        ax.get_title()
    plt.close(fig)
    q = System.solar_system("J2000", bodies=["sun", "earth"])
    fig = integrate(q, np.linspace(0, -0.25, 11) * u.yr).plot()
    assert "t = 0 \N{RIGHTWARDS ARROW} -0.25 yr (backwards)" in fig.axes[0].get_title()
    plt.close(fig)
