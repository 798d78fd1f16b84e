"""Every bundled n-body scene runs in a quick variant and its summary holds its physics."""

from __future__ import annotations

import astropy.units as u
import numpy as np
import pytest

from hamilton_orbits import Scene
from hamilton_orbits.rhs import compile_rhs


def test_mercury_gr_quick_holds_the_advance():
    """42.98 arcsec/century within 0.1 (REFERENCES.md), from 10 years of the scene."""
    result = Scene.bundled("mercury-gr").with_values({"duration": "10 yr"}).run(progress=False)
    rate = result.metrics["perihelion advance of mercury"]
    assert rate.to_value(u.arcsec / u.yr) * 100 == pytest.approx(42.98, abs=0.1)


def test_leo_j2_quick_holds_the_regression():
    """The nodal regression within 1% of the first-order formula (Vallado eq. 9-41)."""
    result = Scene.bundled("leo-j2").with_values({"duration": "2 d"}).run(progress=False)
    assert result.metrics["ratio simulated / formula"] == pytest.approx(1.0, abs=0.01)


def test_comet_encounter_against_ias15():
    result = Scene.bundled("comet-encounter").run(progress=False)
    closest = result.metrics["closest approach comet-jupiter"].to_value(u.au)
    assert 0.02 < closest < 0.04  # aimed at 0.03 au off Jupiter (see the scene file)
    # the encounter raises the comet's semi-major axis from 100 au
    assert result.metrics["comet orbit after: a"].to_value(u.au) > 110
    # two machine-precision integrators through perihelion and the encounter
    assert result.metrics["max relative position difference"] < 1e-9
    assert result.metrics["max |relative energy error|"] < 1e-13


def test_solar_system_quick_against_ias15():
    result = Scene.bundled("solar-system").with_values(
        {"duration": "20 yr", "cadence": "1 yr"}).run(progress=False)
    assert result.metrics["max relative position difference"] < 1e-9
    assert np.max(np.abs(result.diagnostics["energy_error"])) < 1e-14
    assert np.max(np.abs(result.diagnostics["rebound_energy_error"])) < 1e-14
    rows = result.tables["cross-check against rebound: final position difference"]
    assert [r["body"] for r in rows][3] == "earth-moon-barycenter"


def test_scene_effects_are_exactly_what_is_compiled():
    """`scene.effects` is what runs: the compiled right-hand side holds just those."""
    from hamilton_orbits.scenes.nbody.build import build_system

    for name, expected in (("solar-system", ("newtonian",)),
                           ("mercury-gr", ("newtonian", "gr")),
                           ("leo-j2", ("newtonian", "j2"))):
        scene = Scene.bundled(name)
        system = build_system(scene.spec)
        rhs = compile_rhs(system, list(scene.effects))
        assert rhs.effects == expected
    # no effect: the bare Newtonian kernel itself, nothing composed around it
    from hamilton_orbits._kernels.nbody import newtonian_only

    system = build_system(Scene.bundled("solar-system").spec)
    assert compile_rhs(system, []).accel is newtonian_only
