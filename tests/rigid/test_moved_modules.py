"""The old module paths of Earth orientation still work, with a warning (issue 30).

``rigid.c04``, ``rigid.liouville``, ``rigid.wobble``, ``rigid.ar_models``,
``rigid.pole_prediction``, ``rigid.scene_polar`` and ``rigid.scene_prediction`` moved
into :mod:`rigid.earth`.  Importing a name from an old path gives the very object of
the new module and a DeprecationWarning that names the new path; the rest of the suite
(warnings are errors) never goes through them.
"""

from __future__ import annotations

import importlib
import os
import re
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

import rigid
from rigid import earth

# old path -> (new path, a public name, [more names]) checked through the old path
MOVED = {
    "rigid.c04": ("rigid.earth.c04", ["load_c04", "PolarMotionRecord", "iers2010_mean_pole",
                                      "mjd_utc", "decimal_year"]),
    "rigid.liouville": ("rigid.earth.liouville", ["LiouvillePole", "EFFECTS",
                                                  "register_effects", "free_period"]),
    "rigid.wobble": ("rigid.earth.wobble_fit", ["fit_wobble", "WobbleFit", "periodogram",
                                                "free_period"]),
    "rigid.ar_models": ("rigid.earth.ar_models", ["VARModel", "fit_var",
                                                  "accumulate_covariance"]),
    "rigid.pole_prediction": ("rigid.earth.prediction", [
        "predict", "hindcast", "weekly_starts", "PolePrediction", "HindcastScore",
        "PoleRecord", "METHODS", "DEFAULT_HORIZONS", "PAPER_PERIOD", "RECENT_PERIOD",
        "propagate_pole"]),
    "rigid.scene_polar": ("rigid.earth.scene_polar_motion", ["KIND", "SCHEMA", "register"]),
    "rigid.scene_prediction": ("rigid.earth.scene_pole_prediction", [
        "KIND", "SCHEMA", "register", "PUBLISHED", "PUBLISHED_HORIZONS", "TABLE_HORIZONS"]),
}
CASES = [(old, new, name) for old, (new, names) in MOVED.items() for name in names]


@pytest.mark.parametrize(("old", "new", "name"), CASES)
def test_old_path_warns_and_gives_the_same_object(old, new, name):
    module = importlib.import_module(old)
    message = re.escape(f"{old}.{name} moved to {new}.{name}")
    with pytest.warns(DeprecationWarning, match=message) as rec:
        value = getattr(module, name)
    assert value is getattr(importlib.import_module(new), name)
    assert rec[0].filename == __file__  # stacklevel=2: the warning points at the caller


def test_from_import_of_an_old_path_warns():
    with pytest.warns(DeprecationWarning, match=r"rigid\.c04\.load_c04 moved to "
                                                r"rigid\.earth\.c04\.load_c04"):
        from rigid.c04 import load_c04
    from rigid.earth.c04 import load_c04 as new

    assert load_c04 is new


def test_the_tuning_constants_of_pole_prediction_come_from_the_forecasters():
    from rigid.earth import forecasters

    old = importlib.import_module("rigid.pole_prediction")
    for name in ("CHANDLER_PERIOD", "CHANDLER_Q", "LS_SETTINGS", "EXCITATION_WINDOWS"):
        with pytest.warns(DeprecationWarning, match=r"rigid\.earth\.forecasters"):
            assert getattr(old, name) is getattr(forecasters, name)


def test_old_paths_refuse_private_and_unknown_names_without_warning():
    old = importlib.import_module("rigid.pole_prediction")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(AttributeError, match=r"rigid\.pole_prediction.*_history"):
            old._history  # noqa: B018
        with pytest.raises(AttributeError, match="no attribute 'nothing'"):
            old.nothing  # noqa: B018


def test_star_import_names_of_an_old_path_are_the_new_modules():
    old = importlib.import_module("rigid.wobble")
    with pytest.warns(DeprecationWarning, match=r"rigid\.wobble moved to rigid\.earth\.wobble_fit"):
        names = old.__all__
    assert names == importlib.import_module("rigid.earth.wobble_fit").__all__


def test_importing_rigid_touches_no_old_path():
    code = ("import sys, warnings; warnings.simplefilter('error'); import rigid, "
            "rigid.polar_motion, rigid.scene; rigid.scene.register(); "
            "print(sorted(m for m in sys.modules if m in {"
            + ", ".join(repr(m) for m in MOVED) + "}))")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, env=_env())
    assert res.stdout.strip() == "[]"


def _env() -> dict:
    src = str(Path(rigid.__file__).resolve().parents[1])
    return dict(os.environ, PYTHONPATH=src + os.pathsep + os.environ.get("PYTHONPATH", ""))


def test_rigid_earth_keeps_its_documented_names():
    for name in ("GM", "R_EQ", "OMEGA", "J2", "H", "C22_BAR", "S22_BAR", "mass", "moments",
                 "euler_period", "secular_love_number", "chandler_period", "rigid_body",
                 "PolePath", "pole_path", "simulate_wobble"):
        assert name in earth.__all__
        assert callable(getattr(earth, name)) or hasattr(getattr(earth, name), "unit")
