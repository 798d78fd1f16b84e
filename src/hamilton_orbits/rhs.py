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

The variational equations
-------------------------
With ``variational=True`` the same generated module also defines the tangent
right-hand side ``tangent(r, v, gm, dr, dv, da, p)`` (the Jacobian of ``accel``
applied to ``k`` tangent vectors, :mod:`hamilton_orbits._kernels.jacobians`):
the Newtonian Jacobian followed by each listed effect's ``jacobian`` kernel, or,
for an effect registered without one, a compiled loop of central differences of
its own acceleration kernel along each tangent vector.  ``augmented(r, v, gm,
acc, p)`` is ``accel`` and ``tangent`` together on one array of ``n + k n`` rows
(the bodies, then the tangent vectors), the form an integrator of the state
alone integrates the augmented system in.  None of it is written or compiled
unless asked for: the source without ``variational`` is the one above.
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

from hamilton_orbits.effects import EffectSet, get
from hamilton_orbits.firstrun import GENERATED_PREFIX as MODULE_PREFIX

__all__ = ["RHS", "cache_dir", "compile_rhs", "kernels_for", "newtonian_rhs",
           "parameter_vector", "source", "tangent_kernels_for", "tangent_source"]

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
    tangent, tangent_extra : numba dispatcher or None
        With ``variational=True``: ``tangent(r, v, gm, dr, dv, da, p)`` overwrites
        ``da`` (k n, 3) with the Jacobian of ``accel`` times the tangent vectors
        ``(dr, dv)``; ``tangent_extra`` adds that of the listed effects only.
    augmented : numba dispatcher or None
        With ``variational=True``: ``augmented(r, v, gm, acc, p)`` on ``n + k n``
        rows, ``accel`` on the first ``n`` and ``tangent`` on the rest.
    """

    accel: Any
    extra: Any
    p: np.ndarray
    velocity_dependent: bool
    effects: tuple[str, ...]
    tangent: Any = None
    tangent_extra: Any = None
    augmented: Any = None

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


def compile_rhs(system: Any, effects: Any = (), variational: bool = False) -> RHS:
    """The right-hand side of ``system`` with exactly the listed ``effects``.

    Parameters
    ----------
    system : hamilton_orbits.nbody.System
        The system the parameters are for (body indices, radii, ...).
    effects : EffectSet or sequence of str or mapping
        Names (``"gr"``) or mappings with parameters (``{"name": "j2", "body":
        "earth"}``), normalised by :meth:`EffectSet.of`.
    variational : bool
        Also compile the tangent right-hand side (the Jacobians of every listed
        effect; see the module's notes).

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
    >>> compile_rhs(s).tangent is None, compile_rhs(s, variational=True).tangent is None
    (True, False)
    """
    eff = EffectSet.of(effects, "nbody")
    if not eff and not variational:
        return newtonian_rhs()
    specs = [get("nbody", name) for name in eff.names]
    for spec in specs:
        if spec.kernel is None or spec.params is None:
            raise ValueError(f"Effect {spec.name!r} cannot be used in an n-body simulation")
    blocks = [spec.params(system, dict(params))
              for spec, (_, params) in zip(specs, eff.items, strict=True)]
    replaces = any(spec.replaces_newtonian for spec in specs)
    kernels = tuple(spec.kernel for spec in specs)
    p = parameter_vector(blocks)
    names = ("newtonian", *eff.names)
    if not variational:
        accel, extra = kernels_for(kernels, replaces)
        return RHS(accel, extra, p, eff.velocity_dependent, names)
    jacobians = tuple((spec.jacobian, spec.velocity_dependent) for spec in specs)
    accel, extra, tangent, tangent_extra, augmented = tangent_kernels_for(
        kernels, jacobians, replaces)
    return RHS(accel, extra if eff else None, p, eff.velocity_dependent, names, tangent,
               tangent_extra if eff else None, augmented)


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


def _jac_ref(jacobian: Any, velocity_dependent: bool) -> tuple[str, str]:
    """``(module, name)`` of an analytic Jacobian, or ``("fd", parts)`` for central
    differences over positions (and velocities)."""
    if jacobian is None:
        return ("fd", "2" if velocity_dependent else "1")
    return _ref(jacobian)


def tangent_kernels_for(kernels: tuple[Any, ...], jacobians: tuple[tuple[Any, bool], ...],
                        replaces_newtonian: bool = False) -> tuple[Any, ...]:
    """``(accel, extra, tangent, tangent_extra, augmented)`` for ``kernels`` and their
    Jacobians (``(jacobian or None, velocity_dependent)`` each; None: central
    differences), memoised and cached on disk like :func:`kernels_for`.

    Examples
    --------
    >>> from hamilton_orbits._kernels import jacobians, nbody
    >>> fns = tangent_kernels_for((nbody.gr_potential,), ((jacobians.gr_potential_jvp, False),))
    >>> len(fns), tangent_kernels_for((nbody.gr_potential,),
    ...                               ((jacobians.gr_potential_jvp, False),))[2] is fns[2]
    (5, True)
    """
    jac_key = tuple(_jac_ref(j, vd) for j, vd in jacobians)
    key = (tuple(_ref(k) for k in kernels), bool(replaces_newtonian), jac_key)
    with _LOCK:
        found = _MEMO.get(key)
        if found is None:
            found = _build(key, kernels, tuple(j for j, _ in jacobians))
            _MEMO[key] = found
    return found


def source(refs: tuple[tuple[str, str], ...], replaces_newtonian: bool, digest: str,
           jac_refs: tuple[tuple[str, str], ...] | None = None) -> str:
    """The Python source of the module that defines ``accel`` and ``extra`` (and,
    given ``jac_refs``, the tangent right-hand side: see :func:`tangent_source`).

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
    lines += ["    return"] if not refs else []
    lines += ["", "", "@njit(ACCEL_SIGNATURE, cache=CACHE, error_model='numpy')",
              "def accel(r, v, gm, acc, p):  # pragma: no cover - compiled",
              "    base(r, v, gm, acc)", "    extra(r, v, gm, acc, p)", ""]
    if jac_refs is not None:
        lines += tangent_source(replaces_newtonian, jac_refs)
    return "\n".join(lines)


def tangent_source(replaces_newtonian: bool, jac_refs: tuple[tuple[str, str], ...]) -> list[str]:
    """The lines that define ``tangent``, ``tangent_extra`` and ``augmented``:
    effect ``i`` by its Jacobian ``j{i}``, or (``("fd", parts)``) by ``fd{i}``, central
    differences of its kernel ``k{i}`` along each tangent vector, over positions
    (parts 1) or positions and velocities (parts 2).

    Examples
    --------
    >>> print(*tangent_source(False, (("fd", "1"),)), sep=chr(10))  # doctest: +ELLIPSIS
    <BLANKLINE>
    import numpy as np
    ...
    def fd0(r, v, gm, dr, dv, da, p):  # pragma: no cover - compiled
    ...
            for part in range(1):
    ...
    """
    base = "zero_jvp" if replaces_newtonian else "newtonian_jvp"
    lines = ["", "import numpy as np",
             "from hamilton_orbits._kernels.jacobians import TANGENT_SIGNATURE, fd_add, "
             "fd_scales, fd_shift",
             f"from hamilton_orbits._kernels.jacobians import {base} as base_jvp"]
    lines += [f"from {module} import {name} as j{i}"
              for i, (module, name) in enumerate(jac_refs) if module != "fd"]
    sig = "@njit(TANGENT_SIGNATURE, cache=CACHE, error_model='numpy')"
    for i, (module, parts) in enumerate(jac_refs):
        if module != "fd":
            continue
        lines += ["", "", sig,
                  f"def fd{i}(r, v, gm, dr, dv, da, p):  # pragma: no cover - compiled",
                  "    n = r.shape[0]",
                  "    rs, vs = np.empty_like(r), np.empty_like(v)",
                  "    ap, am = np.empty_like(r), np.empty_like(r)",
                  "    length, speed = fd_scales(r, v, gm)",
                  "    for m in range(dr.shape[0] // n):",
                  f"        for part in range({parts}):",
                  "            h = fd_shift(r, v, dr, dv, m, part, length, speed, 1.0, rs, vs, ap)",
                  f"            k{i}(rs, vs, gm, ap, p)",
                  "            fd_shift(r, v, dr, dv, m, part, length, speed, -1.0, rs, vs, am)",
                  f"            k{i}(rs, vs, gm, am, p)",
                  "            fd_add(ap, am, h, da, m)"]
    lines += ["", "", sig,
              "def tangent_extra(r, v, gm, dr, dv, da, p):  # pragma: no cover - compiled"]
    lines += [f"    {'fd' if module == 'fd' else 'j'}{i}(r, v, gm, dr, dv, da, "
              f"p[int(p[{i}]):int(p[{i + 1}])])" for i, (module, _) in enumerate(jac_refs)]
    lines += ["    return"] if not jac_refs else []
    lines += ["", "", sig,
              "def tangent(r, v, gm, dr, dv, da, p):  # pragma: no cover - compiled",
              "    base_jvp(r, v, gm, dr, dv, da)", "    tangent_extra(r, v, gm, dr, dv, da, p)",
              "", "", "@njit(ACCEL_SIGNATURE, cache=CACHE, error_model='numpy')",
              "def augmented(r, v, gm, acc, p):  # pragma: no cover - compiled",
              "    n = gm.shape[0]",
              "    accel(r[:n], v[:n], gm, acc[:n], p)",
              "    tangent(r[:n], v[:n], gm, r[n:], v[n:], acc[n:], p)", ""]
    return lines


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


def _digest(refs: tuple[tuple[str, str], ...], replaces_newtonian: bool,
            jac_refs: tuple[tuple[str, str], ...] | None = None) -> str | None:
    """A digest of the generator and the kernels' source files; None if a kernel's
    module has no importable source file."""
    text = f"{_GENERATOR}|{refs}|{replaces_newtonian}"
    modules = {"hamilton_orbits._kernels.nbody", "hamilton_orbits._kernels.signatures"}
    if jac_refs is not None:
        text += f"|{jac_refs}"
        modules.add("hamilton_orbits._kernels.jacobians")
        modules.update(module for module, _ in jac_refs if module != "fd")
    h = hashlib.sha256(text.encode())
    modules.update(module for module, _ in refs)
    for module in sorted(modules):
        mod = sys.modules.get(module)
        path = getattr(mod, "__file__", None)
        if module == "__main__" or path is None or not Path(path).is_file():
            return None
        h.update(Path(path).read_bytes())
    return h.hexdigest()[:20]


def _build(key: tuple, kernels: tuple[Any, ...],
           jacobians: tuple[Any, ...] | None = None) -> tuple[Any, ...]:
    refs, replaces_newtonian = key[:2]
    jac_refs = key[2] if len(key) > 2 else None
    digest = _digest(refs, replaces_newtonian, jac_refs)
    folder = cache_dir() if digest is not None else None
    if folder is None:
        namespace = _in_memory(refs, replaces_newtonian, kernels, jac_refs, jacobians)
    else:
        path = folder / f"{MODULE_PREFIX}{digest}.py"
        if not path.exists():
            tmp = path.with_suffix(f".{os.getpid()}.tmp")
            tmp.write_text(source(refs, replaces_newtonian, digest, jac_refs)
                           .replace("CACHE", "True"))
            os.replace(tmp, path)
        name = path.stem
        module = sys.modules.get(name)
        if module is None:
            spec = importlib.util.spec_from_file_location(name, path)
            module = importlib.util.module_from_spec(spec)
            sys.modules[name] = module
            spec.loader.exec_module(module)
        namespace = vars(module)
    names = ("accel", "extra") if jac_refs is None else (
        "accel", "extra", "tangent", "tangent_extra", "augmented")
    return tuple(namespace[name] for name in names)


def _in_memory(refs: tuple, replaces_newtonian: bool, kernels: tuple[Any, ...],
               jac_refs: tuple | None = None, jacobians: tuple | None = None) -> dict[str, Any]:
    """The same source compiled for this process only (no disk cache); its namespace."""
    text = source(refs, replaces_newtonian, "in-memory", jac_refs).replace("CACHE", "False")
    lines = [line for line in text.splitlines()
             if not (line.startswith("from ") and (" as k" in line or " as j" in line))]
    namespace: dict[str, Any] = {f"k{i}": k for i, k in enumerate(kernels)}
    namespace.update({f"j{i}": j for i, j in enumerate(jacobians or ()) if j is not None})
    namespace["__name__"] = f"{MODULE_PREFIX}in_memory"
    exec(compile("\n".join(lines), f"<{MODULE_PREFIX}in-memory>", "exec"), namespace)
    return namespace
