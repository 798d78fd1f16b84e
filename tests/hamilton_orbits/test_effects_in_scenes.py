"""Effects in scene files: parameters with their units, the scene's frame, and the
effects that exclude each other, all checked at load (issue 32, classes 3 and 17)."""

from __future__ import annotations

import re
import tomllib

import astropy.units as u
import numpy as np
import pytest

from hamilton_orbits import Scene, System, integrate
from hamilton_orbits import effects as fx
from hamilton_orbits import ephemeris as de
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


def test_eih_and_gr_together_are_refused_at_load():
    with pytest.raises(SceneError, match=re.escape(
            "effects[2]: effect 'gr' (at index 2) is refused beside 'eih' (at index 0): 'eih' "
            "already computes the first post-Newtonian terms")):
        _scene('["eih", "kuiper_ring", "gr"]')


def test_j2_and_zonal_on_the_same_body_are_refused_at_load():
    """The Earth's J2 counted twice by ``j2`` on the Earth and ``zonal`` is a problem
    of the scene at load, at the later effect; ``j2`` on the Sun beside it is not."""
    moon = 'ephemeris = { bodies = ["sun", "earth", "moon"] }'
    with pytest.raises(SceneError, match=re.escape(
            "effects[1]: effect 'j2' (at index 1) is refused beside 'zonal' (at index 0) on "
            "body 'earth': 'zonal' already computes its body's J2")):
        _scene('["zonal", { name = "j2", body = "earth" }]', initial=moon)
    _scene('["zonal", { name = "j2", body = "sun", j2 = 2.2e-7, radius = "696000 km" }]',
           initial=moon)


def test_the_scene_frame_reaches_kuiper_ring():
    """``[initial] frame = "ecliptic"`` was not passed to ``kuiper_ring``: the ring's
    normal was the ICRS's ecliptic pole on ecliptic axes, 23.4 deg off.  The ring's
    field in the ecliptic scene is the ICRS scene's rotated."""
    out = {}
    for frame in ("icrs", "ecliptic"):
        scene = _scene('["kuiper_ring"]', frame=frame)
        assert scene.effects[0]["frame"] == frame
        p = _params(scene)
        assert np.allclose(p[3:], de.ecliptic_pole(frame), rtol=0, atol=1e-15)
        system = build_system(scene.spec)
        r = np.ascontiguousarray(system.r.to_value(u.au))
        acc = np.zeros_like(r)
        fx.get("nbody", "kuiper_ring").kernel(
            r, np.zeros_like(r), system.gm.to_value(u.au**3 / u.day**2), acc, p)
        out[frame] = acc
    rot = de.frame_rotation("ecliptic")
    assert np.abs(out["ecliptic"] - out["icrs"] @ rot.T).max() < 1e-12 * np.abs(out["icrs"]).max()


def test_an_effect_frame_against_the_scene_frame_is_a_problem():
    with pytest.raises(SceneError, match=re.escape(
            "effects[0].frame: 'icrs', but the scene's states are in 'ecliptic' axes "
            "([initial] frame)")):
        _scene('[{ name = "kuiper_ring", frame = "icrs" }]', frame="ecliptic")


def test_a_scene_runs_with_quantity_parameters():
    """The run takes the converted parameters: the same Moon as the Python call's."""
    scene = _scene('[{ name = "moon_figure", radius = "1738 km", inclination_deg = 1.5424 }]',
                   initial='ephemeris = { bodies = ["earth", "moon"] }')
    result = scene.run(progress=False)
    s = System.from_ephemeris(bodies=["earth", "moon"])
    tr = integrate(s, result.times, effects=["moon_figure"])
    assert np.array_equal(np.asarray(result.states["r"]), tr.r.to_value(u.au))


def test_the_pole_of_date_takes_the_scenes_epoch():
    """``pole = "IAU2006"`` in a scene: its ``epoch`` is the scene's start, filled in
    (another is a problem at load, with the key path)."""
    from hamilton_orbits._kernels.figures import OF_DATE

    scene = _scene('[{ name = "zonal", pole = "IAU2006" }]',
                   initial='ephemeris = { epoch = "J2000", bodies = ["sun", "earth", "moon"] }')
    assert scene.effects[0]["epoch"] == "J2000"
    lead = _params(scene)[:OF_DATE]
    assert lead[0] == 1.0 and lead[1] == 0.0  # (of date; 0 days from J2000 at the start)
    with pytest.raises(SceneError, match=re.escape(
            "effects[0].epoch: '1950-01-01', but the scene starts at 'J2000' ([initial] "
            "epoch)")):
        _scene('[{ name = "zonal", pole = "IAU2006", epoch = "1950-01-01" }]',
               initial='ephemeris = { epoch = "J2000", bodies = ["sun", "earth", "moon"] }')


def test_the_pole_of_date_needs_an_epoch_when_the_scene_has_none():
    with pytest.raises(SceneError, match=re.escape(
            "effects[0].epoch: the pole of date needs the TDB of the scene's start")):
        Scene.from_dict(tomllib.loads('''
kind = "nbody"
duration = "10 d"
effects = [{ name = "zonal", pole = "IAU2006" }]
[integrator]
method = "radau15"
[initial]
frame = "icrs"
[[bodies]]
name = "earth"
gm = "398600.4418 km3/s2"
r = ["0 km", "0 km", "0 km"]
v = ["0 km/s", "0 km/s", "0 km/s"]
[[bodies]]
name = "moon"
gm = "4902.8 km3/s2"
r = ["384400 km", "0 km", "0 km"]
v = ["0 km/s", "1.02 km/s", "0 km/s"]
'''))
