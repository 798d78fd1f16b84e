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


@pytest.mark.parametrize("elastic", [
    {"name": "elastic", "chandler_period": 446.3 * u.day},
    {"name": "elastic", "k2": 0.3},  # (Chandler period 446.3 d from it)
    None,  # (the rigid Earth: Euler's period, 303.6 d)
])
def test_polar_scenes_annual_excitation_reproduces_the_fitted_annual_term(elastic):
    """The annual excitation a ``polar_motion`` scene derives from the fit is the
    one whose forced response, under the model's own free wobble, is the fitted
    annual term.  It took the fit's Chandler period instead: with ``k2`` (446.3 d)
    the forced term came out 72.3 mas against the fit's 84.2, without "elastic"
    94.1 mas and opposite in phase.  The forced term is read from the model's
    exact solution (least squares on the two annual terms and the free wobble)."""
    import numpy as np

    from rigid.earth.scene_polar_motion import _model
    from rigid.polar_motion import fit_wobble, load_c04

    fit = fit_wobble(load_c04(), 1980, 2010)
    effects = [{"name": "annual_excitation"}] + ([elastic] if elastic else [])
    model = _model({"effects": effects}, fit)
    t = np.linspace(0.0, 20 * 365.25, 2001)
    m = model.solve(t * u.day, 0j * u.mas).to_value(u.mas)
    w = 2 * np.pi / fit.annual_period.to_value(u.day)
    basis = np.exp(1j * np.outer(t, [w, -w, model.sigma]))
    coef = np.linalg.lstsq(basis, m, rcond=None)[0]
    want = fit.annual_amplitude.to_value(u.mas) * np.exp(1j * fit.annual_phase.to_value(u.rad))
    assert abs(coef[0] - want) < 1e-9 * abs(want)
