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
