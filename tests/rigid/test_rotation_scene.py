"""The rotation scene kind (registered by rigid) and its bundled scenes."""

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
