"""The compiled right-hand side: exactly the listed effects, compiled once across processes."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import astropy.units as u
import numpy as np
import pytest

from hamilton_orbits import Body, System
from hamilton_orbits._kernels import nbody as kernels
from hamilton_orbits.effects import EffectSet
from hamilton_orbits.firstrun import NOTICE
from hamilton_orbits.rhs import (
    compile_rhs,
    diskcache,
    kernels_for,
    parameter_vector,
    remove_stale,
    source,
    tangent_source,
)

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
    # p = [offsets..., parameters, the clock]: gr takes (source index, c)
    assert first.p.tolist() == [2.0, 4.0, 0.0, 50.0, 0.0]
    assert other.p.tolist() == [2.0, 4.0, 0.0, 9.0, 0.0]
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
    # issue 32, class 16: an unknown kind was blamed on the effect
    with pytest.raises(ValueError, match=r"^Unknown effect `kind` 'bogus-kind'; known: nbody, "
                                         r"rotation$"):
        EffectSet.of(["gr"], "bogus-kind")


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


def test_the_template_fills_its_fields_only():
    """Issue 30: the source is filled field by field; a kernel whose name contains the
    old placeholder ``CACHE`` is written as it is, and ``cache=`` is only the flag."""
    text = source((("plugin.CACHE_mod", "CACHE_push"),), False, "d", (("fd", "1"),),
                  cache=False)
    assert "from plugin.CACHE_mod import CACHE_push as k0" in text
    assert "# The right-hand side newtonian + CACHE_push" in text
    flags = [line for line in text.splitlines() if line.startswith("@njit")]
    assert len(flags) == 6 and all("cache=False, error_model='numpy')" in f for f in flags)
    assert "True" not in text and "$" not in text
    assert all("cache=True" in line for line in tangent_source(False, (("fd", "2"),))
               if line.startswith("@njit"))


@pytest.mark.parametrize(("module", "name", "match"), [
    ("plugin", "push; import os", r"Effect 'bad_push': the kernel's name 'push; import os' is "
                                  r"not a Python identifier"),
    ("plugin", "class", r"the kernel's name 'class' is not a Python identifier"),
    ("plugin\nimport os", "push", r"Effect 'bad_push': the kernel's module "
                                   r"'plugin\\nimport os' \(of 'push'\) is not a dotted"),
    ("plugin..x", "push", r"module 'plugin..x' .*is not a dotted Python module path"),
])
def test_a_plugin_kernel_with_a_bad_name_is_refused(module, name, match):
    """A kernel's module and name come from a plugin (an entry point): they are checked
    as Python names before anything is written, the error naming the effect."""
    from numba import njit

    from hamilton_orbits import effects

    @njit
    def push(r, v, gm, acc, p):  # pragma: no cover - compiled
        acc[0, 0] += p[0]

    push.py_func.__module__, push.py_func.__name__ = module, name
    effects.register(effects.EffectSpec("bad_push", "nbody", "a kernel of a bad name (test)",
                                        kernel=push, params=lambda s, p: np.array([1.0])))
    try:
        with pytest.raises(ValueError, match=match):
            compile_rhs(_system(), ["bad_push"])
        with pytest.raises(ValueError, match=r"^The kernel's"):
            kernels_for((push,))
        with pytest.raises(ValueError, match=r"^The kernel's"):
            source(((module, name),), False, "d")
    finally:
        effects.registry._REGISTRY["nbody"].pop("bad_push")


def _written(folder: Path, name: str, text: str, age: float) -> Path:
    path = folder / name
    path.write_text(text)
    os.utime(path, (time.time() - age, time.time() - age))
    return path


def test_stale_generated_files_are_removed_and_current_ones_kept(tmp_path):
    """Removed: an older generator's files, files whose kernel sources changed or are
    gone, unfinished writes, numba's cache of removed modules; kept: current files,
    files too young to judge, files of a newer generator, and anything not ours."""
    from hamilton_orbits.rhs.diskcache import MODULE_PREFIX, digest

    kernel = tmp_path / "kernel.py"
    kernel.write_text("def push(): pass\n")
    refs = (("plugin", "push"),)
    now = digest(refs, False, None, {"plugin": str(kernel)})
    old = 2 * diskcache.STALE_AGE_SECONDS

    def generated(name: str, sources: dict, age: float = old) -> Path:
        text = source(refs, False, name, sources=sources)
        return _written(tmp_path, f"{MODULE_PREFIX}{name}.py", text, age)

    def header(version: int, name: str) -> str:
        return f"# Generated by hamilton-orbits rhs v{version} (do not edit); digest {name}\n"

    current = generated(now, {"plugin": str(kernel)})
    changed = generated("0" * 20, {"plugin": str(kernel)})
    vanished = generated("1" * 20, {"plugin": str(tmp_path / "gone.py")})
    young = generated("7" * 20, {"plugin": str(kernel)}, age=10.0)
    older = _written(tmp_path, f"{MODULE_PREFIX}{'2' * 20}.py", header(2, "2" * 20), old)
    newer = _written(tmp_path, f"{MODULE_PREFIX}{'3' * 20}.py", header(99, "3" * 20), old)
    young_older = _written(tmp_path, f"{MODULE_PREFIX}{'4' * 20}.py", header(2, "4" * 20), 10.0)
    partial = _written(tmp_path, f"{MODULE_PREFIX}{'5' * 20}.123.tmp", "", old)
    foreign = _written(tmp_path, f"{MODULE_PREFIX}notes.py", "# mine\n", old)
    other = _written(tmp_path, "other.py", header(2, "6" * 20), old)
    (tmp_path / "__pycache__").mkdir()
    orphan = _written(tmp_path / "__pycache__", f"{older.stem}.accel-19.py311.nbi", "", 0.0)
    numba_cache = _written(tmp_path / "__pycache__", f"{current.stem}.accel-19.py311.nbi", "",
                           old)

    removed = remove_stale(tmp_path)
    assert sorted(removed) == sorted([changed, vanished, older, partial, orphan])
    for path in (current, young, newer, young_older, foreign, other, numba_cache, kernel):
        assert path.exists(), path
    assert remove_stale(tmp_path) == []  # nothing left to remove
    kernel.write_text("def push(): return 1\n")  # the kernel changed: its file is stale
    assert remove_stale(tmp_path) == [current, numba_cache]
    assert remove_stale(tmp_path / "no such folder") == []


def test_removing_stale_files_never_fails_a_run(tmp_path, monkeypatch):
    from hamilton_orbits.rhs.diskcache import MODULE_PREFIX

    old = 2 * diskcache.STALE_AGE_SECONDS
    stale = _written(tmp_path, f"{MODULE_PREFIX}{'2' * 20}.py",
                     f"# Generated by hamilton-orbits rhs v1 (do not edit); digest {'2' * 20}\n",
                     old)
    undecodable = tmp_path / f"{MODULE_PREFIX}{'6' * 20}.py"
    undecodable.write_bytes(b"\xff\xfe not text")
    os.utime(undecodable, (time.time() - old, time.time() - old))

    def refuse(self, *args, **kwargs):
        raise PermissionError(f"cannot remove {self}")

    monkeypatch.setattr(Path, "unlink", refuse)
    assert remove_stale(tmp_path) == []
    assert stale.exists() and undecodable.exists()
