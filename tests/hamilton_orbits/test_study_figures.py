"""studies.figures: the work-precision diagrams' axes and styles."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # (after the backend is chosen)

from hamilton_orbits.studies.figures import _draw
from hamilton_orbits.studies.rows import Row


def _row(code, method, error, wall):
    return Row("fidelity", code, method, "", error, "|dr|/r", "DE440", wall)


def _labels(axis):
    lo, hi = sorted(axis.get_view_interval())
    ticks = axis.get_major_ticks() + axis.get_minor_ticks()
    return [t.label1.get_text() for t in ticks
            if t.label1.get_text() and lo <= t.get_loc() <= hi]


def test_a_log_axis_under_a_decade_has_labels_and_our_codes_our_style():
    """Minor labels were switched off: 0.5 to 0.7 s showed one label (or none); the
    package's rows were recognised only as code "hamilton-orbits", so "hamilton-orbits
    radau15" was drawn in the other codes' dashed squares."""
    fig, ax = plt.subplots()
    _draw(ax, [_row("hamilton-orbits radau15", "newtonian", 1e-4, 0.5),
               _row("hamilton-orbits radau15", "gr", 2e-7, 0.7),
               _row("scipy", "dop853", 3e-5, 0.6)])
    fig.canvas.draw()
    assert len(_labels(ax.xaxis)) >= 2
    assert len(_labels(ax.yaxis)) >= 2
    styles = {ln.get_label(): (ln.get_linestyle(), ln.get_marker()) for ln in ax.get_lines()}
    assert styles["newtonian (hamilton-orbits radau15)"] == ("-", "o")
    assert styles["dop853 (scipy)"] == ("--", "s")
    plt.close(fig)


def test_a_log_axis_over_decades_labels_its_powers_only():
    fig, ax = plt.subplots()
    _draw(ax, [_row("hamilton-orbits", "wh", e, w) for e, w in ((1e-3, 1e-3), (1e-9, 10.0))])
    fig.canvas.draw()
    labels = _labels(ax.xaxis)
    assert len(labels) >= 2 and not any("times" in t for t in labels)
    plt.close(fig)
