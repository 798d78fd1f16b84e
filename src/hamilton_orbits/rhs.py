"""The compiled right-hand side: exactly the listed effects, compiled once, cached on disk.

A right-hand side is ``accel(r, v, gm, acc, p)`` (see
:mod:`hamilton_orbits._kernels.signatures`).  For a list of effects it is the
Newtonian kernel followed by each listed effect's kernel, and nothing else: an
effect that is not listed is not in the compiled function at all.  What the
function is depends only on which kernels it calls, in which order; the
numbers (which body is the source, J2, c, ...) are the parameter vector ``p``,
passed at run time.  So the key of the compiled function is the tuple of kernel
names, and one compilation serves every system and every parameter value.

Compiled once, across processes
-------------------------------
numba caches a function on disk only when it is defined in a source file.  For
each key this module writes a small Python source file that imports the
kernels and calls them in order (:func:`source`), into the user's cache folder
(``$HAMILTON_ORBITS_CACHE_DIR``, else ``$XDG_CACHE_HOME/hamilton-orbits``, else
``~/.cache/hamilton-orbits``), and imports it; its functions are compiled with
``cache=True``, so a second process loads them instead of compiling.  The file's
name carries a digest of the kernels' own source files, so editing a kernel
makes a new file (numba does not track changes in the functions a cached
function calls).  Where no cache folder can be written, or a kernel cannot be
imported by name (one defined in ``__main__``), the same source is compiled in
memory for the process.

The parameter vector
--------------------
``p = [o_0, o_1, ..., o_m, params_0..., params_1..., ...]`` for ``m`` effects:
effect ``i`` receives ``p[o_i:o_(i+1)]`` (its own parameters, as its
``params`` builder returned them).
"""

from __future__ import annotations

import hashlib
import importlib.util
import os
import sys
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from hamilton_orbits._firstrun import GENERATED_PREFIX as MODULE_PREFIX
from hamilton_orbits.effects import EffectSet, get

__all__ = ["RHS", "cache_dir", "compile_rhs", "kernels_for", "newtonian_rhs",
           "parameter_vector", "source"]

_GENERATOR = "hamilton-orbits rhs v2"


@dataclass(frozen=True, eq=False)
class RHS:
    """A compiled right-hand side and its parameters for one system.

    Attributes
    ----------
    accel : numba dispatcher
        ``accel(r, v, gm, acc, p)``: overwrites ``acc`` with the total acceleration.
    extra : numba dispatcher or None
        ``extra(r, v, gm, acc, p)``: adds the listed effects only; None if none.
    p : ndarray, shape (k,)
        The parameter vector (see the module's notes).
    velocity_dependent : bool
        True if any listed effect depends on velocities.
    effects : tuple of str
        The names of what is computed, ``"newtonian"`` first.
    """

    accel: Any
    extra: Any
    p: np.ndarray
    velocity_dependent: bool
    effects: tuple[str, ...]

    def acceleration(self, r: np.ndarray, v: np.ndarray, gm: np.ndarray) -> np.ndarray:
        """The acceleration of every body, shape (n, 3) (float64, internal units).

        Examples
        --------
        >>> acc = newtonian_rhs().acceleration(np.array([[0.0, 0, 0], [2.0, 0, 0]]),
        ...                              np.zeros((2, 3)), np.array([1.0, 0.0]))
        >>> acc[1].tolist()
        [-0.25, 0.0, 0.0]
        """
        r, v, gm = (np.require(x, np.float64, ["C", "W"]) for x in (r, v, gm))
        acc = np.empty_like(r)
        self.accel(r, v, gm, acc, self.p)
        return acc


def _newtonian() -> RHS:
    from hamilton_orbits._kernels import nbody

    return RHS(nbody.newtonian_only, None, np.zeros(1), False, ("newtonian",))


class _Lazy:
    """The Newtonian right-hand side, built on first use (it imports numba)."""

    value: RHS | None = None


def newtonian_rhs() -> RHS:
    """The right-hand side of Newtonian gravity alone (Hamilton's equation (B)).

    Examples
    --------
    >>> newtonian_rhs().effects
    ('newtonian',)
    """
    if _Lazy.value is None:
        _Lazy.value = _newtonian()
    return _Lazy.value


def parameter_vector(blocks: list[np.ndarray]) -> np.ndarray:
    """``p`` from the effects' own parameter vectors, offsets first.

    Examples
    --------
    >>> parameter_vector([np.array([0.0, 173.1]), np.array([1.0])]).tolist()
    [3.0, 5.0, 6.0, 0.0, 173.1, 1.0]
    """
    m = len(blocks)
    offsets = np.cumsum([m + 1] + [len(b) for b in blocks]).astype(np.float64)
    parts = [offsets] + [np.asarray(b, dtype=np.float64).ravel() for b in blocks]
    return np.ascontiguousarray(np.concatenate(parts))


def compile_rhs(system: Any, effects: Any = ()) -> RHS:
    """The right-hand side of ``system`` with exactly the listed ``effects``.

    Parameters
    ----------
    system : hamilton_orbits.nbody.System
        The system the parameters are for (body indices, radii, ...).
    effects : EffectSet or sequence of str or mapping
        Names (``"gr"``) or mappings with parameters (``{"name": "j2", "body":
        "earth"}``), normalised by :meth:`EffectSet.of`.

    Raises
    ------
    ValueError
        For an unknown effect or bad parameters (from the effect's builder).

    Examples
    --------
    >>> from hamilton_orbits import Body, System
    >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0])])
    >>> compile_rhs(s).effects
    ('newtonian',)
    """
    eff = EffectSet.of(effects, "nbody")
    if not eff:
        return newtonian_rhs()
    specs = [get("nbody", name) for name in eff.names]
    for spec in specs:
        if spec.kernel is None or spec.params is None:
            raise ValueError(f"Effect {spec.name!r} cannot be used in an n-body simulation")
    blocks = [spec.params(system, dict(params))
              for spec, (_, params) in zip(specs, eff.items, strict=True)]
    accel, extra = kernels_for(tuple(spec.kernel for spec in specs),
                               any(spec.replaces_newtonian for spec in specs))
    return RHS(accel, extra, parameter_vector(blocks), eff.velocity_dependent,
               ("newtonian", *eff.names))


_MEMO: dict[tuple, tuple[Any, Any]] = {}
_LOCK = threading.Lock()


def _ref(kernel: Any) -> tuple[str, str]:
    func = getattr(kernel, "py_func", kernel)
    return func.__module__, func.__name__


def kernels_for(kernels: tuple[Any, ...], replaces_newtonian: bool = False) -> tuple[Any, Any]:
    """The compiled ``(accel, extra)`` calling ``kernels`` in order (memoised per
    process; cached on disk across processes, see the module's notes).

    Examples
    --------
    >>> from hamilton_orbits._kernels import nbody
    >>> accel, extra = kernels_for((nbody.gr_potential,))
    >>> kernels_for((nbody.gr_potential,))[0] is accel
    True
    """
    key = (tuple(_ref(k) for k in kernels), bool(replaces_newtonian))
    with _LOCK:
        found = _MEMO.get(key)
        if found is None:
            found = _build(key, kernels)
            _MEMO[key] = found
    return found


def source(refs: tuple[tuple[str, str], ...], replaces_newtonian: bool, digest: str) -> str:
    """The Python source of the module that defines ``accel`` and ``extra``.

    Examples
    --------
    >>> print(source((("hamilton_orbits._kernels.nbody", "gr_potential"),), False, "x"))
    ... # doctest: +ELLIPSIS
    # Generated by hamilton-orbits rhs v2 (do not edit); digest x
    ...
    def extra(r, v, gm, acc, p):  # pragma: no cover - compiled
        k0(r, v, gm, acc, p[int(p[0]):int(p[1])])
    ...
    """
    base = "zero" if replaces_newtonian else "newtonian"
    lines = [
        f"# Generated by {_GENERATOR} (do not edit); digest {digest}",
        "# The right-hand side " + " + ".join([base] + [name for _, name in refs]),
        "from numba import njit",
        "",
        "from hamilton_orbits._kernels.signatures import ACCEL_SIGNATURE",
        f"from hamilton_orbits._kernels.nbody import {base} as base",
    ]
    lines += [f"from {module} import {name} as k{i}" for i, (module, name) in enumerate(refs)]
    lines += ["", "", "@njit(ACCEL_SIGNATURE, cache=CACHE, error_model='numpy')",
              "def extra(r, v, gm, acc, p):  # pragma: no cover - compiled"]
    lines += [f"    k{i}(r, v, gm, acc, p[int(p[{i}]):int(p[{i + 1}])])" for i in range(len(refs))]
    lines += ["", "", "@njit(ACCEL_SIGNATURE, cache=CACHE, error_model='numpy')",
              "def accel(r, v, gm, acc, p):  # pragma: no cover - compiled",
              "    base(r, v, gm, acc)", "    extra(r, v, gm, acc, p)", ""]
    return "\n".join(lines)


def cache_dir(name: str = "rhs") -> Path | None:
    """The folder ``name`` in the user's cache folder (default: the generated
    right-hand sides), created if needed; None if it cannot be written.

    Examples
    --------
    >>> cache_dir() is None or cache_dir().name == "rhs"
    True
    """
    env = os.environ.get("HAMILTON_ORBITS_CACHE_DIR")
    if env:
        base = Path(env)
    else:
        base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "hamilton-orbits"
    folder = base / name
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError:
        return None
    return folder if os.access(folder, os.W_OK) else None


def _digest(refs: tuple[tuple[str, str], ...], replaces_newtonian: bool) -> str | None:
    """A digest of the generator and the kernels' source files; None if a kernel's
    module has no importable source file."""
    h = hashlib.sha256(f"{_GENERATOR}|{refs}|{replaces_newtonian}".encode())
    modules = {"hamilton_orbits._kernels.nbody", "hamilton_orbits._kernels.signatures"}
    modules.update(module for module, _ in refs)
    for module in sorted(modules):
        mod = sys.modules.get(module)
        path = getattr(mod, "__file__", None)
        if module == "__main__" or path is None or not Path(path).is_file():
            return None
        h.update(Path(path).read_bytes())
    return h.hexdigest()[:20]


def _build(key: tuple, kernels: tuple[Any, ...]) -> tuple[Any, Any]:
    refs, replaces_newtonian = key
    digest = _digest(refs, replaces_newtonian)
    folder = cache_dir() if digest is not None else None
    if folder is None:
        return _in_memory(refs, replaces_newtonian, kernels)
    path = folder / f"{MODULE_PREFIX}{digest}.py"
    if not path.exists():
        tmp = path.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(source(refs, replaces_newtonian, digest).replace("CACHE", "True"))
        os.replace(tmp, path)
    name = path.stem
    module = sys.modules.get(name)
    if module is None:
        spec = importlib.util.spec_from_file_location(name, path)
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    return module.accel, module.extra


def _in_memory(refs: tuple, replaces_newtonian: bool, kernels: tuple[Any, ...]) -> tuple[Any, Any]:
    """The same source compiled for this process only (no disk cache)."""
    text = source(refs, replaces_newtonian, "in-memory").replace("CACHE", "False")
    lines = [line for line in text.splitlines()
             if not (line.startswith("from ") and " as k" in line)]
    namespace: dict[str, Any] = {f"k{i}": k for i, k in enumerate(kernels)}
    namespace["__name__"] = f"{MODULE_PREFIX}in_memory"
    exec(compile("\n".join(lines), f"<{MODULE_PREFIX}in-memory>", "exec"), namespace)
    return namespace["accel"], namespace["extra"]
