"""Effects in scene files: parameters with their units, checked at load (issue 32,
classes 3 and 17)."""

from __future__ import annotations

import re

import astropy.units as u
import numpy as np
import pytest
import tomllib

from hamilton_orbits import Scene, System, integrate
from hamilton_orbits import effects as fx
from hamilton_orbits.scene import SceneError
from hamilton_orbits.scenes.nbody.build import build_system


def _scene(effects: str, frame: str = "icrs",
           initial: str = 'solar_system = { epoch = "J2000", bodies = ["sun", "neptune"] }'
           ) -> Scene:
    return Scene.from_dict(tomllib.loads(f"""
kind = "nbody"
duration = "10 d"
effects = {effects}
[integrator]
method = "radau15"
[initial]
frame = "{frame}"
{initial}
"""))


def _params(scene: Scene, k: int = 0) -> np.ndarray:
    """The parameter vector the run gives effect ``k`` of ``scene``."""
    eff = scene.effects[k]
    system = build_system(scene.spec)
    return fx.get("nbody", eff["name"]).params(system, {a: b for a, b in eff.items()
                                                        if a != "name"})


def test_eih_c_is_written_with_its_unit():
    """``eih c = "299792.458 km/s"`` could not be written (its c had no kind)."""
    scene = _scene('[{ name = "eih", c = "299792.458 km/s" }]')
    assert scene.effects[0]["c"] == 299792.458 * u.km / u.s
    assert _params(scene)[0] == pytest.approx(fx.parameters.de440_c_au_per_day(), rel=1e-15)


@pytest.mark.parametrize(("effect", "message"), [
    ('{ name = "eih", c = 173.1 }', 'effects[0].c: expected a speed (m / s) with its unit, e.g. '
                                    '"299792.458 km/s", got the bare number 173.1'),
    ('{ name = "kuiper_ring", radius = 44 }', 'effects[0].radius: expected a length (m) with '
                                              'its unit, e.g. "6378.1366 km", got the bare '
                                              'number 44'),
    ('{ name = "earth_tides", tau = [0.07, 0, 0, 0, 0] }', "effects[0].tau: expected a time"),
    ('{ name = "eih", c = "fast" }', "effects[0].c: cannot read 'fast' as a number with a unit"),
    ('{ name = "lense_thirring", c = "3 km" }', "effects[0].c: expected a speed"),
])
def test_a_bare_number_or_a_wrong_unit_is_a_problem_at_load(effect, message):
    with pytest.raises(SceneError, match=re.escape(message)):
        _scene(f"[{effect}]", initial='ephemeris = { bodies = ["sun", "earth", "moon"] }')


def test_a_list_is_read_value_by_value():
    scene = _scene('[{ name = "earth_tides", tau = ["0.077 d", "-0.01 d", "-0.2 d", '
                   '"1 h", "0 s"] }]', initial='ephemeris = { bodies = ["sun", "earth", "moon"] }')
    assert np.allclose(_params(scene)[-5:], [0.077, -0.01, -0.2, 1 / 24, 0.0], rtol=1e-15)


def test_a_scene_runs_with_quantity_parameters():
    """The run takes the converted parameters: the same Moon as the Python call's."""
    scene = _scene('[{ name = "moon_figure", radius = "1738 km", inclination_deg = 1.5424 }]',
                   initial='ephemeris = { bodies = ["earth", "moon"] }')
    result = scene.run(progress=False)
    s = System.from_ephemeris(bodies=["earth", "moon"])
    tr = integrate(s, result.times, effects=["moon_figure"])
    assert np.array_equal(np.asarray(result.states["r"]), tr.r.to_value(u.au))
