"""Trajectory.plot3d: plotly traces per body, a slider whose steps are the frames,
axes with origin and unit, the bodies at the last output, bad arguments named."""

from __future__ import annotations

import re

import astropy.units as u
import numpy as np
import pytest

from hamilton_orbits import Body, System, integrate

pytest.importorskip("plotly", reason="plotly is in the test extra: pip install -e '.[test]'")


@pytest.fixture(scope="module")
def inner():
    s = System.solar_system("J2000", bodies=["sun", "earth", "mars"])
    return integrate(s, np.linspace(0, 2, 500) * u.yr)


@pytest.fixture(scope="module")
def floats():
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                Body("p", 1e-3, [1.0, 0, 0], [0, 0.6, 0.8]),
                Body("q", 0.0, [2.0, 0, 0], [0, 0.7, 0.0])])
    return integrate(s, np.linspace(0, 6, 37))


def _trace(fig, name):
    (trace,) = [t for t in fig.data if t.name == name]
    return trace


def test_traces_per_body_and_positions_in_the_chosen_unit(inner):
    fig = inner.plot3d(unit="km")
    assert [t.name for t in fig.data] == ["earth", "earth start", "earth now",
                                          "mars", "mars start", "mars now", "sun (origin)"]
    rel = (inner.r - inner.r[:, :1]).to_value(u.km)
    close = {"rtol": 1e-14, "atol": 0.0}  # km: converted before the sun is subtracted
    for k, name in ((1, "earth"), (2, "mars")):
        path = _trace(fig, name)
        np.testing.assert_allclose(np.c_[path.x, path.y, path.z], rel[:, k], **close)
        start, now = _trace(fig, f"{name} start"), _trace(fig, f"{name} now")
        np.testing.assert_allclose(np.c_[start.x, start.y, start.z], rel[:1, k], **close)
        # the body's marker is where the trajectory ends, in km
        np.testing.assert_allclose(np.c_[now.x, now.y, now.z], rel[-1:, k], **close)
        assert abs(now.x[0]) > 1e7  # km, not au
    sun = _trace(fig, "sun (origin)")
    assert (sun.x[0], sun.y[0], sun.z[0]) == (0.0, 0.0, 0.0)


def test_slider_steps_match_the_subsampled_frames(inner):
    fig = inner.plot3d(max_frames=50)
    frames = fig.frames
    assert len(frames) == 50  # 500 outputs subsampled
    (slider,) = fig.layout.sliders
    assert [list(s.args[0]) for s in slider.steps] == [[f.name] for f in frames]
    assert slider.active == len(frames) - 1  # the figure opens at the last output
    idx = [int(f.name) for f in frames]
    assert idx[0] == 0 and idx[-1] == inner.n_outputs - 1 and np.all(np.diff(idx) > 0)
    assert slider.steps[-1].label == f"{inner.t[-1].value:.6g} yr"
    # each frame moves the markers (and only them) to that output
    rel = (inner.r - inner.r[:, :1]).to_value(u.au)
    marker_traces = [i for i, t in enumerate(fig.data) if t.name.endswith(" now")]
    for frame in (frames[0], frames[17], frames[-1]):
        assert list(frame.traces) == marker_traces
        k = int(frame.name)
        for trace, body in zip(frame.data, (1, 2), strict=True):
            np.testing.assert_array_equal([trace.x[0], trace.y[0], trace.z[0]], rel[k, body])
    few = inner.plot3d(max_frames=1000)
    assert len(few.frames) == inner.n_outputs  # never more frames than outputs


def test_axis_titles_carry_origin_and_unit_and_the_aspect_is_the_data(inner, floats):
    scene = inner.plot3d().layout.scene
    assert [scene[f"{c}axis"].title.text for c in "xyz"] == \
        ["x from sun [AU]", "y from sun [AU]", "z from sun [AU]"]
    assert scene.aspectmode == "data"
    assert inner.plot3d(unit=u.km).layout.scene.yaxis.title.text == "y from sun [km]"
    assert inner.plot3d(origin="earth").layout.scene.zaxis.title.text == "z from earth [AU]"
    # the integration frame's origin: no body subtracted
    fig = inner.plot3d(origin="frame")
    assert fig.layout.scene.xaxis.title.text == "x (integration frame) [AU]"
    np.testing.assert_array_equal(_trace(fig, "sun").x, inner.r[:, 0, 0].to_value(u.au))
    assert floats.plot3d().layout.scene.xaxis.title.text == "x from sun [the system's length unit]"


def test_bodies_and_origin_choose_what_is_drawn(floats):
    fig = floats.plot3d(bodies=["q"], origin="p")
    assert [t.name for t in fig.data] == ["q", "q start", "q now", "p (origin)"]
    np.testing.assert_array_equal(_trace(fig, "q").y, floats.r[:, 2, 1] - floats.r[:, 1, 1])


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"bodies": ["p", "pluto"]}, r"`bodies\[1\]` to be one of \['sun', 'p', 'q'\], got 'pluto'"),
    ({"bodies": "p"}, r"`bodies` to be a sequence of body names, got 'p'"),
    ({"bodies": []}, r"`bodies` to name at least one body, got \[\]"),
    ({"origin": "barycentre"}, r"`origin` to be one of \['primary', 'frame'\] or a body's "
                               r"name \['sun', 'p', 'q'\], got 'barycentre'"),
    ({"unit": "km"}, r"`unit` to be None for a trajectory of plain floats .*got 'km'"),
    ({"max_frames": 1}, r"`max_frames` to be an integer >= 2, got 1"),
    ({"max_frames": 2.5}, r"`max_frames` to be an integer >= 2, got 2.5"),
])
def test_bad_arguments_are_named(floats, kwargs, message):
    with pytest.raises(ValueError, match=message):
        floats.plot3d(**kwargs)


def test_a_unit_that_is_not_a_length_is_named(inner):
    with pytest.raises(ValueError, match=r"`unit` to be a unit of length, got 's'"):
        inner.plot3d(unit="s")
    with pytest.raises(ValueError, match=r"`unit` to be a unit of length, got 'parsec-ish'"):
        inner.plot3d(unit="parsec-ish")


def test_without_plotly_the_error_names_the_extra(floats, monkeypatch):
    import builtins

    real_import = builtins.__import__

    def no_plotly(name, *args, **kwargs):
        if name.startswith("plotly"):
            raise ImportError(f"No module named {name!r}")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_plotly)
    with pytest.raises(ImportError, match=r"hamilton-orbits\[plot3d\]"):
        floats.plot3d()


def test_the_html_embeds_plotly_and_holds_the_frames(inner, tmp_path):
    fig = inner.plot3d(max_frames=20)
    path = tmp_path / "orbits.html"
    fig.write_html(path, include_plotlyjs=True)
    html = path.read_text()
    # plotly.js is in the page, no script is fetched from elsewhere: it works offline
    assert re.findall(r"<script[^>]*\ssrc=", html) == []
    assert len(html) > 1_000_000  # plotly.js itself (some MB)
    assert "Plotly.newPlot" in html and html.count('"name":"') >= 20


def test_a_notebook_displays_it_as_a_plotly_figure():
    """In Jupyter the figure displays itself: executed in a real IPython kernel
    (nbclient), a cell ending with ``traj.plot3d()`` outputs plotly's own MIME type,
    which JupyterLab and Notebook 7 render with their built-in plotly renderer."""
    pytest.importorskip("plotly", reason="plotly is in the test extra")
    nbformat = pytest.importorskip("nbformat", reason="nbformat is in the test extra")
    nbclient = pytest.importorskip("nbclient", reason="nbclient is in the test extra")
    pytest.importorskip("ipykernel", reason="ipykernel is in the test extra")
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_code_cell(
        "import numpy as np\n"
        "from hamilton_orbits import Body, System, integrate\n"
        "s = System([Body('sun', 1.0, [0, 0, 0], [0, 0, 0]),\n"
        "            Body('p', 1e-3, [1.0, 0, 0], [0, 1.0, 0])])\n"
        "integrate(s, np.linspace(0, 6.0, 50)).plot3d()")]
    nbclient.NotebookClient(nb, timeout=600, kernel_name="python3").execute()
    # (a kernel that compiles radau15 itself says so on stderr first: a stream output
    # whether there is one depends on numba's cache, not on the figure)
    outputs = [o for o in nb.cells[0].outputs
               if not (o["output_type"] == "stream" and o.get("name") == "stderr")]
    assert [o["output_type"] for o in outputs] == ["display_data"], nb.cells[0].outputs
    figure = outputs[0]["data"]["application/vnd.plotly.v1+json"]
    assert {t["name"] for t in figure["data"]} >= {"p", "p now", "sun (origin)"}  # the bodies
    assert figure["layout"]["sliders"], "the time slider"


def test_a_satellite_s_orbit_is_drawn_in_km_unless_a_unit_is_asked():
    """As ``Trajectory.plot``: paths within 0.01 au of the origin in km."""
    from test_trajectory_plot import _leo

    traj = _leo()
    fig = traj.plot3d()
    assert fig.layout.scene.xaxis.title.text == "x from earth [km]"
    rel = (traj.r[:, 1] - traj.r[:, 0]).to_value(u.km)
    np.testing.assert_allclose(_trace(fig, "sat").x, rel[:, 0], rtol=1e-14)
    assert traj.plot3d(unit="au").layout.scene.xaxis.title.text == "x from earth [AU]"
