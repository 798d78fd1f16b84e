"""A warm ``import hamilton_orbits`` stays light: no heavy module until it is used.

Checked in a fresh interpreter through ``sys.modules`` (not a timing test):
the n-body, scene and plotting stacks, and compiled kernels, load on first use.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

SRC = str(Path(__file__).resolve().parents[2] / "src")

# modules that a plain import must not load (each costs 0.05-1 s)
HEAVY = (
    "matplotlib",
    "scipy.integrate",
    "scipy.optimize",
    "scipy.interpolate",
    "astropy.coordinates",
    "astropy.time",
    "rebound",
    "reboundx",
    "rigid",
    "tomllib",
    "hamilton_orbits.nbody",
    "hamilton_orbits._body",
    "hamilton_orbits.initial_states",
    "hamilton_orbits.integrals",
    "hamilton_orbits.studies",
    "hamilton_orbits.scene",
    "hamilton_orbits.simulation",
    "hamilton_orbits.rebound_bridge",
    "hamilton_orbits.integrators",
)


def _modules_after(code: str) -> dict:
    probe = (
        "import sys, json\n"
        f"{code}\n"
        "from hamilton_orbits._kernels import _dispatch, kepler, quaternion\n"
        "built = [k.__name__ for k in (kepler.solve_ufunc, kepler.anomaly_from_nu_ufunc,\n"
        "         quaternion.qmul_gufunc, quaternion.qrot_gufunc) if k._ufunc is not None]\n"
        "print(json.dumps({'modules': sorted(sys.modules), 'built': built}))\n"
    )
    env = dict(os.environ, PYTHONPATH=SRC)
    proc = subprocess.run(
        [sys.executable, "-c", probe], env=env, capture_output=True, text=True, timeout=300
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    return json.loads(proc.stdout.splitlines()[-1])


def _heavy(modules: list[str]) -> list[str]:
    return [m for m in modules if m in HEAVY or m.startswith(tuple(h + "." for h in HEAVY))]


def test_import_is_light():
    got = _modules_after("import hamilton_orbits")
    assert _heavy(got["modules"]) == []
    assert got["built"] == []  # no ufunc compiled or loaded at import


def _bare_modules(code: str) -> list[str]:
    """``sys.modules`` right after ``code`` in a fresh interpreter."""
    probe = f"import sys, json\n{code}\nprint(json.dumps(sorted(sys.modules)))\n"
    env = dict(os.environ, PYTHONPATH=SRC)
    proc = subprocess.run(
        [sys.executable, "-c", probe], env=env, capture_output=True, text=True, timeout=300
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    return json.loads(proc.stdout.splitlines()[-1])


# what a bare import must not load: numba with the kernels (~0.5 s) is imported
# when a kernel is first called, astropy (~0.5 s) when a Quantity comes in
NOT_AT_IMPORT = ("numba", "llvmlite", "astropy", "scipy", "hamilton_orbits._kernels")


def _loaded(modules: list[str], roots: tuple[str, ...]) -> list[str]:
    return [m for m in modules if m in roots or m.startswith(tuple(r + "." for r in roots))]


@pytest.mark.parametrize(
    "code", ["import hamilton_orbits", "from hamilton_orbits import KeplerOrbit, Quaternion"]
)
def test_bare_import_loads_no_numba_no_astropy(code):
    assert _loaded(_bare_modules(code), NOT_AT_IMPORT) == []


def test_plain_float_calls_never_import_astropy():
    """A caller that never imported astropy cannot pass a Quantity: the unit
    boundary does not import it for plain floats (numba comes with the kernels).
    The values are smoke checks only (precision is tested in test_orbit etc.)."""
    got = _bare_modules(
        "from hamilton_orbits import KeplerOrbit, Quaternion, solve_kepler\n"
        "o = KeplerOrbit.from_state([1.0, 0.0, 0.0], [0.0, 1.2, 0.0], 1.0)\n"
        "assert abs(o.e - 0.44) < 1e-15 and o.propagate(0.5).e == o.e\n"
        "o = KeplerOrbit.from_elements(a=1.0, e=0.5, inc=0.1, lan=0.2, argp=0.3, M=0.4, mu=1.0)\n"
        "assert abs(o.M - 0.4) < 1e-14 and o.conic.p > 0 and solve_kepler(0.5, 0.1) > 0\n"
        "q = Quaternion.from_axis_angle([0.0, 0.0, 1.0], 0.5)\n"
        "assert abs(q.rotate([1.0, 0.0, 0.0])[1] - 0.479425538604203) < 1e-15\n"
        "repr(o), repr(q)\n"
    )
    assert _loaded(got, ("astropy",)) == []
    assert "numba" in got  # the kernels did run


def test_public_names_still_import():
    got = _modules_after(
        "from hamilton_orbits import *\n"
        "import hamilton_orbits\n"
        "assert all(getattr(hamilton_orbits, n) is not None for n in hamilton_orbits.__all__)"
    )
    assert "hamilton_orbits.scene" in got["modules"]  # the lazy names did resolve


def test_lazy_attribute_errors():
    import hamilton_orbits

    try:
        hamilton_orbits.no_such_name  # noqa: B018
    except AttributeError as exc:
        assert "no_such_name" in str(exc)
    else:  # pragma: no cover
        raise AssertionError("expected AttributeError")
    assert set(hamilton_orbits.__all__) <= set(dir(hamilton_orbits))


# what looking up the scene kinds (every command line's first step) must not load:
# the Earth's record, fit and predictions of rigid (0.6-0.8 s of a command)
NOT_FOR_SCENE_KINDS = ("scipy.signal", "scipy.optimize", "astropy.table", "rigid.polar_motion",
                       "rigid.earth.prediction")


def test_rigid_polar_motion_resolves_on_first_use_after_the_scene_kinds():
    got = _bare_modules(
        "from hamilton_orbits.scenes.base import registered_kinds\n"
        "kinds = registered_kinds()\n"
        "assert {'nbody', 'rotation', 'polar_motion', 'pole_prediction'} <= set(kinds), kinds\n"
        "import rigid\n"
        "assert callable(rigid.polar_motion.predict)\n"  # on first use
    )
    # (the probe imported rigid.polar_motion last, on purpose: it resolves lazily)
    assert "rigid.polar_motion" in got


def test_the_scene_kinds_alone_import_no_earth_module():
    got = _bare_modules(
        "from hamilton_orbits.scenes.base import registered_kinds\n"
        "registered_kinds()\n"
    )
    assert _loaded(got, NOT_FOR_SCENE_KINDS) == []
