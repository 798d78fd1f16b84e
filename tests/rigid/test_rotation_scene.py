"""The rotation scene kind (registered by rigid) and its bundled scenes."""

import re

import astropy.units as u
import numpy as np
import pytest

import rigid.scene
from hamilton_orbits import Scene
from hamilton_orbits.scene import SceneError

rigid.scene.register()  # what the entry point does in an installed package


def test_dzhanibekov_scene_flips_at_the_exact_interval():
    scene = Scene.bundled("dzhanibekov").with_values({"duration": "30 s"})
    result = scene.run(progress=False)
    exact = result.metrics["exact flip interval 2K(m)/lambda"]
    simulated = result.metrics["simulated flip interval"]
    # splitting4 at 1 ms against the exact 2K(m)/lambda: the crossings are
    # interpolated linearly between 10 ms outputs, whose error (~1e-6 s) bounds this
    assert abs((simulated / exact).to_value(u.one) - 1) < 1e-5
    assert result.metrics["max attitude error vs exact"] < 1e-8 * u.rad
    assert "flip interval" in result.summary()


def test_rotation_scene_validation_names_the_keys(tmp_path):
    path = tmp_path / "spin.toml"
    path.write_text(
        'kind = "rotation"\nduration = "1 s"\n[body]\nmoments = ["1 kg m2", "2 kg m2", "3 m"]\n'
        'omga = ["1 rad/s", "0 rad/s", "0 rad/s"]\n[integrator]\nmethod = "splitting"\n'
    )
    with pytest.raises(SceneError) as info:
        Scene.from_toml(path)
    text = str(info.value)
    assert f"{path}:4: body.moments[2]: expected a moment of inertia" in text  # file:LINE
    assert "body.omga: unknown key (did you mean 'omega'" in text
    assert "integrator.method: unknown value 'splitting' (did you mean 'splitting4'" in text
    assert np.all([p.startswith(str(path)) for p in info.value.problems])


@pytest.mark.parametrize(("scene", "values", "pattern"), [
    ("dzhanibekov", {"body.moments": '["1 kg m2", "-2 kg m2", "3 kg m2"]'},
     r"body: Expected `inertia` > 0"),
    ("dzhanibekov", {"body.attitude": "[0, 0, 0, 0]"}, r"body: .*nonzero quaternion"),
    ("earth-pole-rigid", {"body.wobble": '"-1 arcsec"'}, r"body: Expected `wobble`"),
    ("chandler-wobble", {"effects": '["free", {name = "damping", Q = -5}]'},
     r"effects: Expected `Q` > 0"),
    ("chandler-wobble", {"effects": '["free", {name = "elastic", chandler_period = "433 d", '
                                    'k2 = 0.3}]'}, r"effects: .*exactly one of `k2`"),
])
def test_a_body_or_effects_the_run_would_refuse_fail_at_loading(scene, values, pattern):
    """docs/scenes.md: a scene that loads does not fail at run time for a reason its
    file holds.  These loaded and failed in the run (exit 1): the body, and the
    polar motion's model, are now built when the scene loads."""
    from hamilton_orbits import Scene
    from hamilton_orbits.scene import SceneError

    with pytest.raises(SceneError, match=pattern):
        Scene.bundled(scene).with_values(values)


def test_a_rotation_scene_stops_when_asked_and_keeps_what_it_reached():
    """The command line's first Ctrl-C asks the run to stop (``stop()``); a rotation
    scene ignored it, said it was stopping, ran to its end and exited 0."""
    scene = Scene.bundled("dzhanibekov").with_values({"duration": "30 s"})
    looks = []
    result = scene.run(progress=False, stop=lambda: len(looks.append(1) or looks) >= 20)
    whole = scene.run(progress=False)
    n = len(result.times)
    assert not result.complete and whole.complete and 2 <= n < len(whole.times)
    np.testing.assert_array_equal(result.states["omega"], whole.states["omega"][:n])


def test_a_flip_interval_the_outputs_cannot_resolve_is_said_so():
    """Outputs 20 s apart for flips 15 s apart: the zero crossings alias, and the
    summary gave a flip interval 101% off (880% with 100 s) for a run right to
    1e-7 rad, without a word."""
    scene = Scene.bundled("dzhanibekov").with_values({"duration": "400 s", "cadence": "20 s"})
    said = scene.run(progress=False).metrics["simulated flip interval"]
    assert isinstance(said, str) and re.match(
        r"outputs 20 s apart cannot time flips 14.966 s apart", said), said


def test_the_analyses_time_the_axes_the_motion_turns_about_wherever_they_are():
    """``flip_time`` timed ``omega[:, 1]`` and ``wobble_period`` the crossings of
    ``omega[:, 0]`` whatever the body: moments (1, 3, 2), the middle axis third, gave
    "fewer than two flips" for a run of four; a wobble about the first axis "less
    than one full turn" for 22.  Each now times the middle axis, and an axis the
    spin's path circles, against the exact 2K(m)/lambda and free-motion period."""
    flip = Scene.bundled("dzhanibekov").with_values({
        "duration": "60 s", "body.moments": ["1 kg m2", "3 kg m2", "2 kg m2"],
        "body.omega": ["0.001 rad/s", "0.001 rad/s", "2 rad/s"]}).run(progress=False)
    assert abs((flip.metrics["simulated flip interval"]
                / flip.metrics["exact flip interval 2K(m)/lambda"]).to_value(u.one) - 1) < 1e-5
    wobble = Scene.bundled("dzhanibekov").with_values({
        "duration": "200 s", "cadence": "0.05 s", "body.moments": ["3 kg m2", "2 kg m2",
                                                                   "1.5 kg m2"],
        "body.omega": ["1 rad/s", "0.05 rad/s", "0.05 rad/s"],
        "analysis": [{"name": "wobble_period"}]}).run(progress=False)
    # (crossings interpolated between outputs 0.05 s apart, over 22 turns: 1e-5)
    assert abs((wobble.metrics["simulated wobble period"]
                / wobble.metrics["exact free-motion period"]).to_value(u.one) - 1) < 1e-5


def test_a_body_at_rest_gives_its_changes_not_nan(tmp_path):
    """A body at rest: the omega and energy errors relative to zero printed ``nan``
    (and wrote it to summary.json).  Its changes themselves are given, in rad/s and
    J, named as such; the figure says the attitude error is 0 throughout."""

    result = Scene.bundled("dzhanibekov").with_values(
        {"body.omega": ["0 rad/s", "0 rad/s", "0 rad/s"]}).run(progress=False)
    m = result.metrics
    assert m["max |omega error| (a body at rest)"] == 0 * u.rad / u.s
    assert m["max |energy change| (a body at rest)"] == 0 * u.J
    assert "max |relative energy error|" not in m
    result.save(tmp_path)
    assert "nan" not in (tmp_path / "summary.json").read_text().lower()
    fig = result.plot()[0]
    assert [t.get_text() for t in fig.axes[1].texts] == ["0 at every output"]
