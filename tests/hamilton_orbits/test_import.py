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
