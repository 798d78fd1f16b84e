"""Names that moved keep working at their old paths, with a DeprecationWarning naming
the new one, and give the very same object (issue 30: a house by concept)."""

from __future__ import annotations

import importlib

import pytest

# (old module, name, new module)
MOVED = [
    *[("hamilton_orbits.nbody", name, "hamilton_orbits.initial_states")
      for name in ("DEFAULT_BODIES", "SOLAR_SYSTEM_GM", "SOLAR_SYSTEM_SPAN",
                   "solar_system_bodies", "solar_system_epoch")],
    *[("hamilton_orbits.nbody", name, "hamilton_orbits.integrals")
      for name in ("LostStateError", "accelerations_quaternion", "energy_gm_many",
                   "integral_errors")],
    *[("hamilton_orbits.kepler", name, "hamilton_orbits.twobody")
      for name in ("STATE_UNITS", "check_state", "classical_columns", "refuse_beyond_range")],
    *[(f"hamilton_orbits.{module}", name, f"hamilton_orbits.studies.{module}")
      for module, names in (
          ("report", ("SETTINGS", "Row", "build_report", "fmt_time", "log", "timed")),
          ("ladder", ("BODIES", "RUNGS", "Rung", "RungResult", "residuals", "run_rung")),
          ("reference", ("Reference", "reference")))
      for name in names],
]


@pytest.mark.parametrize(("old", "name", "new"), MOVED, ids=lambda x: x.rsplit(".")[-1])
def test_old_path_warns_and_gives_the_same_object(old, name, new):
    module = importlib.import_module(old)
    with pytest.warns(DeprecationWarning, match=rf"{old}\.{name} moved to {new}\.{name}"):
        value = getattr(module, name)
    assert value is getattr(importlib.import_module(new), name)


@pytest.mark.parametrize(("old", "name", "new"), MOVED[:1])
def test_from_import_of_an_old_path_warns(old, name, new):
    with pytest.warns(DeprecationWarning, match=new):
        exec(f"from {old} import {name}", {})


@pytest.mark.parametrize("module", ["report", "ladder", "reference"])
def test_a_moved_module_still_imports_and_lists_its_names(module):
    old = importlib.import_module(f"hamilton_orbits.{module}")
    new = importlib.import_module(f"hamilton_orbits.studies.{module}")
    assert old.__all__ == new.__all__
    with pytest.warns(DeprecationWarning, match=f"hamilton_orbits.studies.{module}"):
        star: dict = {}
        exec(f"from hamilton_orbits.{module} import *", star)
    assert all(star[name] is getattr(new, name) for name in new.__all__)


def test_the_report_problems_plug_in_keeps_its_contract():
    """rigid's problems (entry point group ``hamilton_orbits.report_problems``) build
    the report's Row, from the report module's public names."""
    from importlib.metadata import entry_points

    from hamilton_orbits.studies import report, rows

    assert report.Row is rows.Row and report.timed is rows.timed and report.log is rows.log
    eps = list(entry_points(group="hamilton_orbits.report_problems"))
    assert [ep.value for ep in eps] == ["rigid.report_problems:problems"]
    slugs = [slug for slug, fn in eps[0].load()() if callable(fn)]
    assert slugs == ["rigid_body", "pole_wander"]


def test_unknown_names_still_raise_attribute_error():
    import hamilton_orbits.nbody as nbody

    with pytest.raises(AttributeError, match="no attribute 'no_such_name'"):
        nbody.no_such_name  # noqa: B018


def test_public_names_that_stayed_do_not_warn():
    import warnings

    from hamilton_orbits import nbody

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert nbody.Body is importlib.import_module("hamilton_orbits").Body
        assert nbody.System.solar_system.__func__ is not None
        assert nbody.SystemArrays is not None and nbody.DAY is not None
