"""The bundled rotation and polar-motion scenes hold their physics."""

from __future__ import annotations

import astropy.units as u
import pytest

from hamilton_orbits import Scene
from rigid import earth


def test_earth_pole_rigid_wobble_is_euler_period():
    result = Scene.bundled("earth-pole-rigid").with_values({"duration": "5 yr"}).run(
        progress=False)
    measured = result.metrics["simulated wobble period"].to_value(u.day)
    # the pole path's period against the linear triaxial Euler period: the wobble of
    # 0.2 arcsec makes the nonlinear correction ~1e-12 relative; the crossing times
    # are interpolated linearly between daily outputs, off by at most ~(w h)^2 / 6 ~
    # 7e-5 of a day each, so over 6 turns the period is good to ~3e-8 relative
    assert measured == pytest.approx(earth.euler_period(triaxial=True).to_value(u.day),
                                     rel=3e-8)
    assert result.metrics["max attitude error vs exact"].to_value(u.rad) < 1e-9


def test_chandler_wobble_scene_against_published_period():
    result = Scene.bundled("chandler-wobble").run(progress=False)
    period = result.metrics["Chandler period (fit)"].to_value(u.day)
    # published Chandler periods 430-436 d (Wilson & Vicente 1990; Gross 2007)
    assert 430 < period < 436
    annual = result.metrics["annual period (fit)"].to_value(u.day)
    assert abs(annual - 365.25) < 2
    # the effective k2 that lengthens the Euler period to the Chandler period, near
    # 0.28 (REFERENCES.md, Munk & MacDonald 1960)
    assert 0.25 < result.metrics["effective k2 = k_s (1 - T_E / T_C)"] < 0.31
    assert result.metrics["model period"].to_value(u.day) == pytest.approx(period, rel=1e-12)
    # "Q from the line width (see caveat)": the caveat is printed with the summary
    assert "Q from the line width (see caveat)" in result.metrics
    summary = result.summary()
    assert "\ncaveat\nQ from the line width" in summary
    assert "not a measurement of the" in summary and "damping" in summary


def test_polar_scene_refuses_unknown_effect_and_missing_q(tmp_path):
    from hamilton_orbits.scene import SceneError

    path = tmp_path / "bad.toml"
    path.write_text('kind = "polar_motion"\neffects = ["elastik", {name = "damping"}]\n')
    with pytest.raises(SceneError, match=r"bad.toml:2: effects\[0\].*'elastic'"):
        Scene.from_toml(path)
    path.write_text('kind = "polar_motion"\neffects = [{name = "damping"}]\n')
    with pytest.raises(SceneError, match=r"bad.toml:2: effects\[0\].Q"):
        Scene.from_toml(path)
