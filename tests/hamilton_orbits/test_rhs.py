"""The compiled right-hand side: exactly the listed effects, compiled once across processes."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import astropy.units as u
import numpy as np
import pytest

from hamilton_orbits import Body, System
from hamilton_orbits._kernels import nbody as kernels
from hamilton_orbits.effects import EffectSet
from hamilton_orbits.firstrun import NOTICE
from hamilton_orbits.rhs import compile_rhs, kernels_for, parameter_vector, source

SRC = Path(__file__).resolve().parents[2] / "src"


def _system() -> System:
    return System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0], radius=0.01, j2=0.1),
                   Body("p", 1e-3, [1.0, 0.1, 0.2], [0, 1.0, 0.1]),
                   Body("q", 0.0, [-1.5, 0.3, -0.1], [0.1, -0.8, 0])])


def test_the_composed_rhs_is_newton_plus_each_kernel_in_order():
    """accel = newtonian + gr + j2, each kernel given its own parameters: bit for bit."""
    s = _system()
    rhs = compile_rhs(s, [{"name": "gr", "c": 50.0}, {"name": "j2", "body": "sun"}])
    assert rhs.effects == ("newtonian", "gr", "j2")
    a = s.as_arrays()
    r, v, gm = a.r.copy(), a.v.copy(), a.gm.copy()
    expected = np.empty((3, 3))
    kernels.newtonian(r, v, gm, expected)
    kernels.gr_anderson(r, v, gm, expected, np.array([0.0, 50.0]))
    kernels.j2_field(r, v, gm, expected, np.array([0.0, 0.1, 0.01, 0.0, 0.0, 1.0]))
    np.testing.assert_array_equal(rhs.acceleration(r, v, gm), expected)
    extra = np.zeros((3, 3))
    rhs.extra(r, v, gm, extra, rhs.p)  # the effects alone (what wh's kick adds)
    alone = np.zeros((3, 3))
    kernels.gr_anderson(r, v, gm, alone, np.array([0.0, 50.0]))
    kernels.j2_field(r, v, gm, alone, np.array([0.0, 0.1, 0.01, 0.0, 0.0, 1.0]))
    np.testing.assert_array_equal(extra, alone)


def test_one_compiled_function_per_list_of_kernels():
    """The key is the kernels, not the parameters: another c, another system, same code."""
    first = compile_rhs(_system(), [{"name": "gr", "c": 50.0}])
    other = compile_rhs(System([Body("a", 2.0, [0, 0, 0], [0, 0, 0])]), [{"name": "gr", "c": 9.0}])
    assert first.accel is other.accel
    # p = [offsets..., parameters]: gr takes (source index, c)
    assert first.p.tolist() == [2.0, 4.0, 0.0, 50.0]
    assert other.p.tolist() == [2.0, 4.0, 0.0, 9.0]
    assert compile_rhs(_system(), [{"name": "gr_potential", "c": 50.0}]).accel is not first.accel


def test_the_generated_source_names_exactly_the_listed_kernels():
    text = source((("hamilton_orbits._kernels.nbody", "j2_field"),), False, "d")
    assert "import j2_field as k0" in text and "gr_anderson" not in text
    assert "k0(r, v, gm, acc, p[int(p[0]):int(p[1])])" in text
    assert "from hamilton_orbits._kernels.nbody import newtonian as base" in text
    eih_like = source((("hamilton_orbits._kernels.nbody", "j2_field"),), True, "d")
    assert "import zero as base" in eih_like


def test_a_kernel_from_an_unimportable_module_is_compiled_in_memory():
    from numba import njit

    @njit
    def push(r, v, gm, acc, p):  # pragma: no cover - compiled
        for i in range(r.shape[0]):
            acc[i, 0] += p[0]

    push.py_func.__module__ = "__main__"
    accel, _ = kernels_for((push,))
    r = np.array([[0.0, 0, 0], [2.0, 0, 0]])
    acc = np.empty((2, 3))
    accel(r, np.zeros((2, 3)), np.array([1.0, 0.0]), acc, parameter_vector([np.array([3.0])]))
    np.testing.assert_array_equal(acc[:, 0], [3.0, 3.0 - 0.25])


def test_effect_sets_are_equal_and_hashable_with_quantities_and_lists():
    a = EffectSet.of([{"name": "gr", "c": 10065.32 * u.au / u.d}])
    b = EffectSet.of([{"name": "gr", "c": 10065.32 * u.au / u.d}])
    assert a == b and hash(a) == hash(b)
    assert a != EffectSet.of([{"name": "gr", "c": 10065.33 * u.au / u.d}])
    assert EffectSet.of(a) is a
    assert EffectSet.of(["gr", "newtonian"]).names == ("gr",)
    with pytest.raises(ValueError, match=r"rotation effects, got an EffectSet of 'nbody'"):
        EffectSet.of(a, "rotation")


def _run_twice(tmp_path: Path, code: str) -> list[str]:
    env = {**os.environ, "HAMILTON_ORBITS_CACHE_DIR": str(tmp_path), "NUMBA_DEBUG_CACHE": "1"}
    env["PYTHONPATH"] = str(SRC) + os.pathsep + env.get("PYTHONPATH", "")
    outs = []
    for _ in range(2):
        res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             env=env, check=True, timeout=600)
        outs.append(res.stdout + res.stderr)
    return outs


def test_an_effect_rhs_is_compiled_once_across_processes(tmp_path):
    """Issue 21: the notice's promise ("once; cached") holds for effect-specialised kernels:
    the second process loads the generated right-hand side from numba's cache and
    compiles nothing (no notice, nothing saved)."""
    code = (
        "import astropy.units as u\n"
        "from hamilton_orbits import System, integrate\n"
        "s = System.solar_system('J2000', bodies=['sun', 'mercury'])\n"
        "integrate(s, 10 * u.day, effects=['gr'])\n"
    )
    first, second = _run_twice(tmp_path, code)
    generated = [p.name for p in tmp_path.joinpath("rhs").glob("*.py")]
    assert len(generated) == 1, generated
    assert "data saved" in first and "hamilton_orbits_rhs_" in first
    assert NOTICE not in second, second[-2000:]
    loaded = [ln for ln in second.splitlines()
              if "data loaded" in ln and "hamilton_orbits_rhs_" in ln]
    saved = [ln for ln in second.splitlines() if "data saved" in ln]
    assert loaded and saved == [], second[-2000:]
