"""Every bundled scene's figures carry their result (issue 34, item 6), checked
with matplotlib's own geometry on shortened runs of the scenes:

(a) every data line is drawn from enough points: an orbit turns by at most a
    50th of a revolution about the primary between drawn points, any other line
    has 50 points or marks each point it has;
(b) no legend's box covers a drawn data point (display coordinates);
(c) every axis that is labelled at all names its unit (or says it has none);
(d) every orbit plot marks each body's start and the direction of its motion.

(``pole-prediction``, ~30 s, is left out to keep the suite fast.)
"""

from __future__ import annotations

import re

import matplotlib
import numpy as np
import pytest

from hamilton_orbits import Scene

matplotlib.use("Agg")

SHORT = {  # the same scenes, fewer years: what the figures draw is the same kind
    "solar-system": {"duration": "20 yr", "crosscheck": "false"},
    "mercury-gr": {"duration": "5 yr"},
    "comet-encounter": {"crosscheck": "false"},
    "de440-century": {"duration": "3 yr"},
    "leo-j2": {"duration": "0.5 d"},
    "stability-map": {"duration": "1185.6 yr"},
    "dzhanibekov": {"duration": "10 s"},
    "earth-pole-rigid": {"duration": "3 yr"},
    "chandler-wobble": {},  # the whole record: under a second
}
UNIT = re.compile(r"\[[^\]]+\]|\(dimensionless\)|\(mas\b|fraction")
STEP = 2 * np.pi / 50  # an orbit line's largest turn between drawn points


@pytest.fixture(scope="module", params=sorted(SHORT))
def figures(request):
    import matplotlib.pyplot as plt

    result = Scene.bundled(request.param).with_values(SHORT[request.param]).run(
        progress=False)
    figs = result.plot()
    for fig in figs:
        fig.canvas.draw()
    yield request.param, figs
    for fig in figs:
        plt.close(fig)


def _data_lines(ax):
    """The lines that carry data: visible, with data, not a proxy of the legend."""
    return [line for line in ax.get_lines()
            if line.get_visible() and len(line.get_xdata()) > 0]


def _turns(xy: np.ndarray) -> np.ndarray:
    """The angles (rad) by which a line turns about the origin between its points."""
    ang = np.arctan2(xy[:, 1], xy[:, 0])
    step = np.abs(np.angle(np.exp(1j * np.diff(ang))))
    return step[np.isfinite(step)]


def test_every_data_line_is_drawn_from_enough_points(figures):
    scene, figs = figures
    for fig in figs:
        for ax in fig.axes:
            for line in _data_lines(ax):
                xy = np.asarray(line.get_xydata(), dtype=float)
                if line.get_linestyle() in ("None", "") or line.get_transform() \
                        is not ax.transData:
                    continue  # dots, or a reference line across the axes
                what = f"{scene}/{fig.get_label()}: {line.get_label()!r}"
                if fig.get_label() == "orbits":
                    assert _turns(xy).max(initial=0.0) <= STEP * 1.0001, what
                elif line.get_marker() in ("None", "", None):
                    assert len(xy) >= 50, f"{what}: {len(xy)} points"


def test_no_legend_covers_a_data_point(figures):
    scene, figs = figures
    for fig in figs:
        renderer = fig.canvas.get_renderer()
        legends = [ax.get_legend() for ax in fig.axes if ax.get_legend()] + fig.legends
        for legend in legends:
            box = legend.get_window_extent(renderer)
            for ax in fig.axes:
                clip = ax.get_window_extent(renderer)
                for line in _data_lines(ax):
                    pts = line.get_transform().transform(
                        np.asarray(line.get_xydata(), dtype=float))
                    pts = pts[np.all(np.isfinite(pts), axis=1)]
                    shown = ((pts[:, 0] >= clip.x0) & (pts[:, 0] <= clip.x1)
                             & (pts[:, 1] >= clip.y0) & (pts[:, 1] <= clip.y1))
                    inside = ((pts[:, 0] > box.x0) & (pts[:, 0] < box.x1)
                              & (pts[:, 1] > box.y0) & (pts[:, 1] < box.y1) & shown)
                    assert not inside.any(), (
                        f"{scene}/{fig.get_label()}: the legend covers "
                        f"{int(inside.sum())} point(s) of {line.get_label()!r}")


def test_every_axis_names_its_unit(figures):
    scene, figs = figures
    for fig in figs:
        for ax in fig.axes:
            if not _data_lines(ax):
                continue
            ticks = any(t.get_visible() and t.get_text() for t in ax.get_xticklabels())
            labels = [ax.get_ylabel()] + ([ax.get_xlabel()] if ticks else [])
            for label in labels:
                assert UNIT.search(label), f"{scene}/{fig.get_label()}: {label!r}"


def test_orbit_plots_mark_start_and_direction(figures):
    scene, figs = figures
    for fig in figs:
        if fig.get_label() != "orbits":
            continue
        for ax in fig.axes:
            starts = [line for line in ax.get_lines() if line.get_gid() == "start"]
            arrows = [t for t in ax.texts if t.get_gid() == "direction"]
            tracks = [line for line in _data_lines(ax) if line.get_gid() is None
                      and line.get_linestyle() not in ("None", "")]
            assert len(starts) >= len(tracks) >= 1, scene  # a moon is drawn as dots
            assert len(arrows) == len(starts), scene
            assert any("start" in t.get_text() for t in ax.get_legend().get_texts())


def test_an_energy_the_effects_change_is_drawn_signed_and_a_peers_apart(figures):
    """An energy the effects change was drawn as |change| on a log axis, each change
    of sign a deep dip that looked like structure; it is signed, on a linear axis.
    rebound's errors were drawn over ours on one axis (both on the same few levels
    of rounding: ours hidden); they have a panel of their own, on the same scales.
    The DE440 residuals, sampled yearly, are points: joined, the orbits' periods
    aliased into slow wiggles."""
    scene, figs = figures
    by_label = {fig.get_label(): fig for fig in figs}
    energy = by_label.get("energy_error")
    if energy is None:
        pytest.skip(f"{scene} draws no energy figure")
    axes = [ax for ax in energy.axes if _data_lines(ax)]
    if scene == "de440-century":
        (ax,) = axes
        assert ax.get_yscale() == "linear" and "signed" in ax.get_ylabel()
        assert any(list(line.get_ydata()) == [0, 0] for line in _data_lines(ax))  # (zero)
        residuals = by_label["de440_residuals"].axes[0]
        assert all(line.get_linestyle() == "None" for line in _data_lines(residuals))
    else:
        assert all(ax.get_yscale() == "log" for ax in axes)
        if scene in ("solar-system", "comet-encounter") and len(axes) > 1:
            assert axes[0].get_shared_y_axes().joined(axes[0], axes[1])


def test_a_panel_of_exact_zeros_does_not_hide_the_other_panels_errors():
    """The two energy panels shared their y axis: rebound's errors all exactly 0 set
    the limits eps/100 .. eps*100 for both, and none of ours (1e-10) was in view."""
    import astropy.units as u
    import matplotlib.pyplot as plt

    from hamilton_orbits.scenes.nbody.figures import plot_energy
    from hamilton_orbits.scenes.result import Result

    t = np.linspace(0.0, 10.0, 200) * u.yr
    ours = np.linspace(0.0, 1e-10, 200)
    result = Result(scene=Scene.bundled("solar-system"), times=t,
                    diagnostics={"energy_error": ours, "rebound_energy_error": 0 * ours})
    fig = plot_energy(result, "the total energy", True)
    fig.canvas.draw()
    top = fig.axes[0]
    low, high = top.get_ylim()
    drawn = np.concatenate([line.get_ydata() for line in top.get_lines()
                            if line.get_linestyle() == "None"])
    assert np.all((drawn >= low) & (drawn <= high)) and len(drawn) == 199
    plt.close(fig)
