"""What the scenes' figures show, tested on the data they draw (issue 21).

A figure a scientist cannot trust at a glance is a bug even when the numbers in
the table are right: ``mercury-gr`` drew the Sun as a 0.3 au line and Mercury's
orbit as a smeared band, because the pair started with its barycentric velocity
from the whole solar system.  These tests read the lines back from the figures.
"""

import re

import astropy.units as u
import matplotlib
import numpy as np
import pytest

from hamilton_orbits import KeplerOrbit, Scene, System

matplotlib.use("Agg")


@pytest.fixture(scope="module")
def mercury():
    # 10 years (41 orbits) is as telling as the bundled 100
    return Scene.bundled("mercury-gr").with_values({"duration": "10 yr"}).run(progress=False)


def _figure(result, name):
    figs = result.plot()
    found = [f for f in figs if f.get_label() == name]
    assert len(found) == 1
    return found[0]


def test_a_subset_starts_at_rest_in_its_own_barycentre(mercury):
    """The Sun of the Sun-Mercury pair stays within the pair's barycentric wobble,
    m / (M + m) times Mercury's aphelion distance (6.8e-8 au), instead of drifting
    0.03 au in 10 years with the solar-system barycentre's frame."""
    names = mercury.states["names"]
    r = mercury.states["r"].to_value(u.au)
    sun, merc = names.index("sun"), names.index("mercury")
    gm = System.solar_system("J2000", bodies=["sun", "mercury"]).gm.value
    wobble = gm[1] / gm.sum() * np.linalg.norm(r[:, merc] - r[:, sun], axis=1).max()
    # 1 + 1e-6: the wobble bound is exact for the two-body motion; rounding only
    assert np.linalg.norm(r[:, sun], axis=1).max() <= wobble * (1 + 1e-6)


def test_orbit_figure_is_drawn_about_the_primary(mercury):
    fig = _figure(mercury, "orbits")
    ax = fig.axes[0]
    lines = {line.get_label(): line.get_xydata() for line in ax.get_lines()}
    sun = lines["sun (origin)"]
    assert sun.tolist() == [[0.0, 0.0]]
    merc = next(xy for label, xy in lines.items() if label.startswith("mercury"))
    # Mercury about the Sun: between perihelion 0.3075 and aphelion 0.4667 au
    # (projected on the ecliptic, inclination 7 degrees shortens by cos 7 at most)
    dist = np.hypot(merc[:, 0], merc[:, 1])
    assert 0.3075 * np.cos(np.radians(7.1)) < dist.min() and dist.max() < 0.4668


@pytest.mark.parametrize("scene", ["mercury-gr", "leo-j2", "comet-encounter"])
def test_every_position_axis_names_a_frame_and_a_unit(scene):
    result = Scene.bundled(scene).with_values({"duration": "3 d", "cadence": "1 h"}).run(
        progress=False)
    fig = _figure(result, "orbits")
    labels = [a.get_xlabel() for a in fig.axes] + [a.get_ylabel() for a in fig.axes]
    assert labels
    for label in labels:
        assert re.search(r"(ICRS axes|J2000 mean ecliptic)", label), label
        assert re.search(r"\[(au|km)\]$", label), label
    assert "frame: " in result.summary()


def test_low_orbit_is_drawn_in_km():
    result = Scene.bundled("leo-j2").with_values({"duration": "0.2 d"}).run(progress=False)
    ax = _figure(result, "orbits").axes[0]
    assert ax.get_xlabel().endswith("[km]")
    sat = next(line.get_xydata() for line in ax.get_lines()
               if line.get_label().startswith("satellite"))
    # a = 7000 km, e = 0.001: the projected distance never exceeds a (1 + e)
    assert 6000 < np.abs(sat).max() <= 7007.0 + 1e-6


def test_inner_planets_get_their_own_panel():
    result = Scene.bundled("solar-system").with_values(
        {"duration": "20 yr", "crosscheck": "false"}).run(progress=False)
    fig = _figure(result, "orbits")
    assert len(fig.axes) == 2
    inner = {line.get_label().split(" (")[0] for line in fig.axes[1].get_lines()}
    assert {"mercury", "venus", "earth-moon-barycenter", "mars"} <= inner
    assert "jupiter" not in inner
    assert fig.axes[1].get_xlim()[1] < 2.0  # au: the inner panel is zoomed


def test_ecliptic_frame_gives_table_inclinations():
    """Mars's heliocentric inclination: 1.85 degrees to the J2000 ecliptic (JPL's
    approximate elements, Standish: 1.849726 deg), 24.7 to the ICRS x-y plane."""
    incs = {}
    for frame in ("ecliptic", "icrs"):
        s = System.solar_system("J2000", bodies=["sun", "mars"], frame=frame)
        orbit = KeplerOrbit.from_state(s.r[1] - s.r[0], s.v[1] - s.v[0], s.gm.sum())
        incs[frame] = orbit.inc.to_value(u.deg)
    # 0.005 deg: the built-in ephemeris's osculating elements against a mean fit
    assert incs["ecliptic"] == pytest.approx(1.849726, abs=0.005)
    assert incs["icrs"] == pytest.approx(24.68, abs=0.01)


def test_scene_frame_key_rotates_the_solar_system():
    base = {"kind": "nbody", "duration": "1 d",
            "initial": {"solar_system": {"bodies": ["sun", "mars"]}}}
    from hamilton_orbits.scenes.nbody.build import build_system

    ecl = build_system(Scene.from_dict({**base, "initial": {**base["initial"],
                                                             "frame": "ecliptic"}}).spec)
    icrs = build_system(Scene.from_dict(base).spec)
    # the same vectors, rotated about x by the obliquity 84381.406"
    eps = np.radians(84381.406 / 3600)
    y, z = icrs.r[1, 1].value, icrs.r[1, 2].value
    assert ecl.r[1, 1].value == pytest.approx(np.cos(eps) * y + np.sin(eps) * z, rel=1e-14)
    assert ecl.r[1, 0].value == icrs.r[1, 0].value


def test_solar_system_bad_arguments_name_the_argument():
    with pytest.raises(ValueError, match=r"`frame`.*'galactic'"):
        System.solar_system("J2000", frame="galactic")
    with pytest.raises(ValueError, match=r"`origin`.*'sun'"):
        System.solar_system("J2000", origin="sun")
    with pytest.raises(ValueError, match=r"`epoch`.*'tomorrow': the string did not parse"):
        System.solar_system("tomorrow")
    assert System.solar_system("now").names[0] == "sun"


def test_ssb_origin_keeps_the_ephemeris_states():
    ssb = System.solar_system("J2000", bodies=["sun", "mercury"], origin="ssb")
    own = System.solar_system("J2000", bodies=["sun", "mercury"])
    # the Sun moves at ~13 m/s about the solar-system barycentre at J2000
    speed = np.linalg.norm(ssb["sun"].v.to_value(u.m / u.s))
    assert 5 < speed < 20
    assert np.linalg.norm(own.barycentre()[1].to_value(u.m / u.s)) < 1e-12
    # the relative state is the same
    np.testing.assert_allclose((ssb.r[1] - ssb.r[0]).value, (own.r[1] - own.r[0]).value,
                               rtol=1e-13)


def test_barycenter_origin_is_spelled_either_way():
    """``barycenter`` as astropy and JPL write it (the default); ``barycentre`` accepted."""
    default = System.solar_system("J2000", bodies=["sun", "mercury"])
    for spelling in ("barycenter", "barycentre"):
        other = System.solar_system("J2000", bodies=["sun", "mercury"], origin=spelling)
        np.testing.assert_array_equal(other.r.value, default.r.value)
        np.testing.assert_array_equal(other.v.value, default.v.value)
    with pytest.raises(ValueError, match=r"'barycenter' or 'ssb'"):
        System.solar_system("J2000", origin="centre")


def test_energy_of_a_lone_test_particle_is_its_specific_energy():
    """One massive body and a massless one: Hamilton's E does not see the particle,
    so its error was 0 whatever the integrator did.  The test particle's specific
    orbital energy shows a coarse leapfrog's error and radau15's rounding."""
    from hamilton_orbits import Body, integrate

    mu = 398600.4418 * u.km**3 / u.s**2
    orbit = KeplerOrbit.from_elements(a=7000 * u.km, e=0.1, inc=0 * u.deg, lan=0 * u.deg,
                                      argp=0 * u.deg, M=0 * u.deg, mu=mu)
    r, v = orbit.state()
    s = System([Body("earth", mu, [0, 0, 0] * u.km, [0, 0, 0] * u.km / u.s),
                Body("sat", 0 * mu, r, v)])
    coarse = integrate(s, 1 * u.d, method="leapfrog", dt=60 * u.s)
    assert 1e-6 < np.abs(coarse.energy_error).max() < 1e-2
    fine = integrate(s, 1 * u.d, method="radau15")
    # 1e-13: rounding over 15 orbits (~1e-15 per orbit, as the other radau15 tests)
    assert 0 < np.abs(fine.energy_error).max() < 1e-13


def test_gr_energy_is_the_conserved_1pn_quantity(mercury):
    """With gr the Newtonian energy changes by 1e-7 over an orbit; the energy with
    the 1PN terms is kept to rounding (1e-13: 41 orbits of ~1e-15 each)."""
    assert "1PN" in mercury.metrics["energy"]
    assert mercury.metrics["max |relative energy error|"] < 1e-13
    from hamilton_orbits.integrals import integral_errors

    r = mercury.states["r"].to_value(u.au)
    v = mercury.states["v"].to_value(u.au / u.d)
    gm = System.solar_system("J2000", bodies=["sun", "mercury"]).as_arrays().gm
    newtonian = integral_errors(r, v, gm, mercury.times.to_value(u.d))[0]
    assert np.abs(newtonian).max() > 1e-8


def test_energy_figure_draws_no_invented_floor_and_names_its_lines(mercury):
    ax = _figure(mercury, "energy_error").axes[0]
    ys = np.concatenate([line.get_ydata() for line in ax.get_lines()
                         if line.get_linestyle() == "None"])
    assert ys.min() > 1e-17  # exact zeros are counted, not drawn at 1e-18
    labels = [line.get_label() for line in ax.get_lines()]
    assert any(label.startswith("machine epsilon") for label in labels)
    assert "gr (1PN)" in ax.get_title()


def test_rigid_earth_figure_shows_the_wobble_in_mas_and_years():
    """The spin about the figure axis is 1e6 times the wobble: drawn in rad/s the
    wobble was a flat line at 0, on an axis of seconds times 1e8."""
    result = Scene.bundled("earth-pole-rigid").with_values({"duration": "3 yr"}).run(
        progress=False)
    top, bottom = _figure(result, "spin").axes
    assert top.get_ylabel().endswith("[mas]") and "body" in top.get_ylabel()
    assert bottom.get_xlabel().endswith("[yr]")
    amplitude = max(np.abs(line.get_ydata()).max() for line in top.get_lines())
    # the scene's 0.2 arcsec offset of the rotation axis from the figure axis
    assert amplitude == pytest.approx(200.0, rel=0.01)
    assert "principal axes" in result.summary()


def test_a_removed_body_leaves_the_orbit_figure_in_au():
    """A body removed or merged is NaN after it left: the largest distance was NaN,
    "above 0.01 au" false, and a 6 au orbit was drawn in km with 1e9 offsets."""
    from hamilton_orbits.scenes.nbody.figures import orbit_view

    r = np.zeros((3, 3, 3))
    r[:, 1, 0] = 5.2
    r[:, 2, 0] = [1.0, 2.0, np.nan]
    view = orbit_view(["sun", "jupiter", "comet"], np.array([1.0, 1e-3, 0.0]), r)
    assert view["unit"] == "au" and view["reach"].tolist() == [0.0, 5.2, 2.0]


def test_a_distance_still_closing_at_a_removal_is_not_called_the_closest_approach():
    """The comet is removed at 5 au from the Sun still closing on Jupiter: its last
    distance is no closest approach (the figure said "the closest approach (0.046 au)")."""
    comet = {"name": "comet", "gm": "0 km3 / s2", "primary": "sun", "q": "0.01 au",
             "e": 0.9999, "inc": "36.003522070993 deg", "lan": "32.42821444595107 deg",
             "argp": "222.42981967246678 deg", "M": "-0.016637268139259004 deg"}
    result = Scene.from_dict({
        "kind": "nbody", "description": "comet removed", "duration": "1 yr",
        "cadence": "1 d", "crosscheck": False, "effects": [],
        "events": [{"name": "escape", "distance": "5 au", "bodies": ["comet"],
                    "action": "remove"}],
        "integrator": {"method": "radau15"},
        "initial": {"solar_system": {"epoch": "J2000", "bodies": ["sun", "jupiter"]}},
        "bodies": [comet],
        "analysis": [{"name": "close_approach", "body": "comet", "other": "jupiter"}],
    }).run(progress=False)
    assert result.metrics["closest approach comet-jupiter"].startswith(
        "not reached: ") and "comet was removed" in result.metrics[
        "closest approach comet-jupiter"]
    fig = _figure(result, "orbits")
    for ax in fig.axes:
        assert ax.get_xlabel().endswith("[au]") and ax.get_ylabel().endswith("[au]")
        fig.canvas.draw()
        assert ax.xaxis.get_offset_text().get_text() == ""
        assert ax.yaxis.get_offset_text().get_text() == ""
        labels = [h.get_label() for h in ax.get_legend().legend_handles]
        assert not any("closest approach (" in t for t in labels)
        assert any(t.startswith("comet at the last output before comet was removed") or
                   t.startswith("the last output before comet was removed") for t in labels)


def test_perihelion_outputs_are_points_under_the_fit_and_two_points_make_no_fit(mercury):
    """The lower panel joined thousands of osculating samples swinging +-0.08" within
    each orbit: a solid block over the fit and GR lines.  Two outputs were "a
    least-squares fit of 43.01"/century"."""
    fig = _figure(mercury, "perihelion")
    for ax in fig.axes:
        (samples,) = [ln for ln in ax.get_lines() if ln.get_label().startswith("mercury")
                      or ln.get_linestyle() == "None"]
        assert samples.get_linestyle() == "None" and samples.get_marker() == "."
        over = [ln for ln in ax.get_lines() if ln is not samples]
        assert len(over) == 2 and all(ln.get_zorder() > samples.get_zorder() for ln in over)
    assert any(t.startswith("least-squares fit") for t in
               fig.axes[0].get_legend_handles_labels()[1])
    short = Scene.bundled("mercury-gr").with_values(
        {"duration": "88 d", "cadence": "88 d"}).run(progress=False)
    fig = _figure(short, "perihelion")
    ax, ax2 = fig.axes
    labels = ax.get_legend_handles_labels()[1]
    assert not any("fit" in t for t in labels) and not ax2.get_lines()
    assert "too few orbits run for a fit" in ax2.texts[0].get_text()


def _fake_result(n=101, **diagnostics):
    from types import SimpleNamespace

    return SimpleNamespace(times=np.linspace(0.0, 100.0, n) * u.yr, diagnostics=diagnostics,
                           scene=SimpleNamespace(name="fake"))


def test_an_energy_change_names_its_scale_in_the_label_not_an_offset():
    """de440-century: a "1e-9" above the y axis, apart from its label."""
    import matplotlib.pyplot as plt

    from hamilton_orbits.scenes.nbody.figures import plot_energy

    change = 2e-9 * np.sin(np.arange(101.0))
    fig = plot_energy(_fake_result(energy_error=change), "the total energy", conserved=False)
    ax = fig.axes[0]
    fig.canvas.draw()
    assert ax.yaxis.get_offset_text().get_text() == ""
    assert "[$10^{-9}$]" in ax.get_ylabel() and "dimensionless" in ax.get_ylabel()
    (points,) = [ln for ln in ax.get_lines() if ln.get_label() == "hamilton-orbits"]
    np.testing.assert_allclose(points.get_ydata(), change[1:] * 1e9, rtol=1e-12)
    plt.close(fig)


def test_megno_is_drawn_from_the_first_output_after_the_start():
    """MEGNO's value at t = 0 (0 by definition) was drawn: a spike from 0."""
    import matplotlib.pyplot as plt

    from hamilton_orbits.scenes.nbody.figures import plot_megno

    megno = np.concatenate([[0.0], 2.0 + 1.0 / np.arange(1.0, 11.0)])
    fig = plot_megno(_fake_result(11, megno=megno))
    (line,) = [ln for ln in fig.axes[0].get_lines() if ln.get_label().startswith("MEGNO")]
    assert line.get_xdata()[0] > 0 and line.get_ydata().min() > 2.0
    np.testing.assert_array_equal(line.get_ydata(), megno[1:])
    plt.close(fig)


def test_a_merge_breaks_the_kept_body_s_track_in_the_scene_s_orbit_figure():
    """pa's line ran from its last output before the merge to the pair's centre of
    mass, a path no body travelled, with nothing marking the merge."""
    def planet(name, gm, y, vy):
        return {"name": name, "gm": f"{gm} km3 / s2", "radius": "0.05 au",
                "r": ["1.0 au", f"{y} au", "0 au"], "v": ["0 au / d", f"{vy} au / d", "0 au / d"]}

    result = Scene.from_dict({
        "kind": "nbody", "description": "two planets merging", "duration": "0.3 yr",
        "cadence": "2 d", "crosscheck": False, "effects": [],
        "events": [{"name": "collision", "action": "merge"}],
        "integrator": {"method": "radau15"},
        "bodies": [{"name": "sun", "gm": "1.32712440018e11 km3 / s2", "radius": "0.005 au",
                    "r": ["0 au", "0 au", "0 au"], "v": ["0 au / d", "0 au / d", "0 au / d"]},
                   planet("pa", 1.32712440018e8, 0, 0.01720209895),
                   planet("pb", 2.65424880036e8, 0.3, 0.01376167916)],
    }).run(progress=False)
    (event,) = result.tables["events"]
    assert event["bodies"] == "pa-pb" and event["action"] == "merge"
    r = result.states["r"].to_value(u.au)
    m = int(np.argmax(~np.isfinite(r[:, 2, 0])))  # pb's first NaN: the first output after
    rel = r[:, 1] - r[:, 0]
    ax = _figure(result, "orbits").axes[0]
    (pa,) = [ln for ln in ax.get_lines() if ln.get_label() == "pa"]
    xy = pa.get_xydata()
    gap = np.flatnonzero(np.isnan(xy[:, 0]))
    assert gap.size == 1  # one break, between the last output before and the first after
    assert xy[gap[0] - 1].tolist() == rel[m - 1, :2].tolist()
    assert xy[gap[0] + 1].tolist() == rel[m, :2].tolist()
    (mark,) = [ln for ln in ax.get_lines() if ln.get_gid() == "merge"]
    assert mark.get_xydata()[0].tolist() == rel[m, :2].tolist()
    assert mark.get_label().startswith("merge: pb into pa")
    assert mark in ax.get_legend().legend_handles or any(
        t.get_text() == mark.get_label() for t in ax.get_legend().get_texts())
