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

The source is written from templates with named fields (``string.Template``):
only a field is ever filled, never text searched and replaced, and the names
that fill them (kernel modules and functions, which plugins supply through
entry points) are checked as Python names first (:func:`check_ref`).  The
first lines of a file record the generator's version, the key and the kernels'
source files, so that a file no run will use again (an older generator's, or
one whose kernel sources changed or are gone) is recognised and removed, once
per process and only when old enough that no other process can be importing it
(:func:`remove_stale`).

Where things are: this module compiles (:func:`compile_rhs`, :func:`kernels_for`,
:func:`tangent_kernels_for`); :mod:`hamilton_orbits.rhs.codegen` writes the
source (the templates, :func:`check_ref`); :mod:`hamilton_orbits.rhs.diskcache`
keeps the files (:func:`cache_dir`, the digest, :func:`remove_stale`).

The parameter vector
--------------------
``p = [o_0, o_1, ..., o_m, params_0..., params_1..., ..., clock]`` for ``m``
effects: effect ``i`` receives ``p[o_i:o_(i+1)]`` (its own parameters, as its
``params`` builder returned them).  The last element is the clock: before every
evaluation, the integrator writes there the time of the state it passes
(:mod:`hamilton_orbits._kernels.signatures`).

Effects that know the time
--------------------------
A kernel of six arguments, ``kernel(r, v, gm, acc, p, t)``, receives the time
``t`` of the state (the simulation's time, in its unit: days for a Quantity
system; the true time also in a time-reversed run) read from the clock; a
Jacobian of eight, ``jacobian(r, v, gm, dr, dv, da, p, t)``, likewise.  Kernels
of five (seven) arguments are compiled as before, without it.

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

import threading
from dataclasses import dataclass
from typing import Any

import numpy as np

from hamilton_orbits.effects import EffectSet, get
from hamilton_orbits.rhs.codegen import check_ref, kernel_ref, source, tangent_source
from hamilton_orbits.rhs.diskcache import (
    MODULE_PREFIX,
    STALE_AGE_SECONDS,
    cache_dir,
    digest,
    load_module,
    module_sources,
    remove_stale,
)

__all__ = ["RHS", "STALE_AGE_SECONDS", "cache_dir", "check_ref", "compile_rhs", "kernel_ref",
           "kernels_for", "newtonian_rhs", "parameter_vector", "refuse_nonfinite",
           "remove_stale", "run_parameters", "source", "takes_time", "tangent_kernels_for",
           "tangent_source", "time_reversed"]


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
    reversed : RHS or None
        The right-hand side of the time-reversed motion, for one made outside the
        list of effects (:func:`time_reversed` returns it; None: made from the
        effects).
    timed : bool
        True if a kernel reads the time (the clock, ``p``'s last element).
    per_run : bool
        True if ``p`` was made for one run (the small bodies' field, made per
        chunk, whose ``p`` also holds its ephemeris tables and cache): the run uses
        it in place instead of a copy (:func:`run_parameters`).
    """

    accel: Any
    extra: Any
    p: np.ndarray
    velocity_dependent: bool
    effects: tuple[str, ...]
    tangent: Any = None
    tangent_extra: Any = None
    augmented: Any = None
    reversed: Any = None
    timed: bool = False
    per_run: bool = False

    def __post_init__(self) -> None:
        p = self.p
        if not (isinstance(p, np.ndarray) and p.dtype == np.float64 and p.ndim == 1
                and p.size >= 1 and p.flags.c_contiguous and p.flags.writeable):
            # (the integrators write the clock into p's last element: one must exist)
            raise ValueError("Expected `p` to be a writable C-contiguous float64 vector of at "
                             f"least one element (its last the clock), got {p!r}")

    def acceleration(self, r: np.ndarray, v: np.ndarray, gm: np.ndarray,
                     t: float = 0.0) -> np.ndarray:
        """The acceleration of every body at time ``t`` (for the effects that know
        it), shape (n, 3) (float64, internal units).

        Examples
        --------
        >>> acc = newtonian_rhs().acceleration(np.array([[0.0, 0, 0], [2.0, 0, 0]]),
        ...                              np.zeros((2, 3)), np.array([1.0, 0.0]))
        >>> acc[1].tolist()
        [-0.25, 0.0, 0.0]
        """
        r, v, gm = (np.require(x, np.float64, ["C", "W"]) for x in (r, v, gm))
        acc = np.empty_like(r)
        p = self.p.copy()  # (its own clock: this p may be a running integrator's)
        p[-1] = t
        try:
            self.accel(r, v, gm, acc, p)
        except ZeroDivisionError:  # (called from Python, a compiled division by zero
            acc[...] = np.nan  # raises where a run gets inf or NaN: the run's value)
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
    """``p`` from the effects' own parameter vectors, offsets first, the clock last.

    Examples
    --------
    >>> parameter_vector([np.array([0.0, 173.1]), np.array([1.0])]).tolist()
    [3.0, 5.0, 6.0, 0.0, 173.1, 1.0, 0.0]
    """
    m = len(blocks)
    offsets = np.cumsum([m + 1] + [len(b) for b in blocks]).astype(np.float64)
    parts = [offsets] + [np.asarray(b, dtype=np.float64).ravel() for b in blocks]
    return np.ascontiguousarray(np.concatenate([*parts, np.zeros(1)]))


def run_parameters(rhs: RHS) -> np.ndarray:
    """The parameter vector a run of ``rhs`` passes its kernels, which write its
    clock: its own copy (two runs of one right-hand side, on two threads, share no
    clock; and what a snapshot of a run holds is that run's alone), or ``rhs.p``
    itself when it was made for the one run (``per_run``: no copy of the small
    bodies' ephemeris tables).

    Examples
    --------
    >>> rhs = newtonian_rhs()
    >>> run_parameters(rhs) is rhs.p, bool((run_parameters(rhs) == rhs.p).all())
    (False, True)
    """
    return rhs.p if rhs.per_run else rhs.p.copy()


def takes_time(kernel: Any, plain: int) -> bool:
    """Whether compiled ``kernel`` takes the time: ``plain + 1`` arguments, not
    ``plain`` (5 for an acceleration kernel, 7 for a Jacobian).

    Raises
    ------
    ValueError
        For another number of arguments.

    Examples
    --------
    >>> from hamilton_orbits._kernels import figures, nbody
    >>> takes_time(nbody.gr_potential, 5), takes_time(figures.zonal_of_date, 5)
    (False, True)
    """
    func = getattr(kernel, "py_func", kernel)
    count = func.__code__.co_argcount
    if count not in (plain, plain + 1):
        raise ValueError(f"Expected the kernel {func.__name__!r} to take {plain} arguments, or "
                         f"{plain + 1} with the time last, got {count}")
    return count == plain + 1


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
        kernel_ref(spec.kernel, spec.name)  # a plugin's names, checked before they are written
        if variational and spec.jacobian is not None:
            kernel_ref(spec.jacobian, spec.name)
    blocks = eff.parameters(system)
    replaces = any(spec.replaces_newtonian for spec in specs)
    kernels = tuple(spec.kernel for spec in specs)
    p = parameter_vector(blocks)
    names = ("newtonian", *eff.names)
    timed = any(takes_time(k, 5) for k in kernels)
    if not variational:
        accel, extra = kernels_for(kernels, replaces)
        return RHS(accel, extra, p, eff.velocity_dependent, names, timed=timed)
    jacobians = tuple((spec.jacobian, spec.velocity_dependent) for spec in specs)
    accel, extra, tangent, tangent_extra, augmented = tangent_kernels_for(
        kernels, jacobians, replaces)
    return RHS(accel, extra if eff else None, p, eff.velocity_dependent, names, tangent,
               tangent_extra if eff else None, augmented, timed=timed)


def refuse_nonfinite(system: Any, effects: Any, acc: np.ndarray, r: np.ndarray,
                     v: np.ndarray, gm: np.ndarray, t: float = 0.0) -> None:
    """Refuse a state whose acceleration ``acc`` is not finite through one of the
    listed ``effects``, naming the effect, its index in the list, the body and the
    cause (the effect's ``EffectSpec.singular``): the run would stop at its first
    step saying only "the acceleration became non-finite (a collision?)", and
    :meth:`System.accelerations <hamilton_orbits.nbody.System.accelerations>` would
    return NaN.  Each effect's kernel is evaluated alone (on this path only); a
    non-finite acceleration no effect makes (two bodies at one point) is left to
    the integrators' own refusal.

    Parameters
    ----------
    system : hamilton_orbits.nbody.System
    effects : EffectSet or sequence of str or mapping
    acc : ndarray, shape (n, 3)
        The acceleration of the state with every effect.
    r, v : ndarray, shape (n, 3)
    gm : ndarray, shape (n,)
    t : float
        The time of the state (for the effects that know it).

    Raises
    ------
    ValueError
        For an effect whose acceleration alone is not finite.

    Examples
    --------
    >>> from hamilton_orbits import Body, System
    >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("b", 0.0, [1, 0, 0], [0, 1, 0])])
    >>> refuse_nonfinite(s, [], np.zeros((2, 3)), s.r, s.v, s.gm)  # finite: nothing to say
    """
    if np.isfinite(acc).all():
        return
    eff = EffectSet.of(effects, "nbody")
    if not eff:
        return
    indices = eff.indices or range(len(eff.names))
    for k, name, p in zip(indices, eff.names, eff.parameters(system), strict=True):
        spec = get("nbody", name)
        alone = np.zeros((len(gm), 3))
        q = np.array(p, dtype=np.float64)
        args = (r, v, gm, alone, q) + ((float(t),) if takes_time(spec.kernel, 5) else ())
        try:  # (called from Python, a kernel raises where its run gives inf or NaN)
            with np.errstate(all="ignore"):
                spec.kernel(*args)
            bad = np.flatnonzero(~np.isfinite(alone).all(axis=1))
            what = " is not finite"
        except ZeroDivisionError:
            bad, what = np.arange(len(gm)), " is not finite (a division by zero)"
        if bad.size:
            why = spec.singular(system, r, q) if spec.singular is not None else None
            where = why or "the acceleration of " + ", ".join(
                f"body {system.names[i]!r} (index {i})" for i in bad) + what
            raise ValueError(f"Effect {name!r} (effects[{k}]) at t = {float(t)!r}: {where}")


def time_reversed(rhs: RHS) -> RHS:
    """The right-hand side of the time-reversed motion of ``rhs`` (the same effects
    and parameters), which a backward run integrates forwards in ``s = -t`` on the
    velocities ``w = -v``: ``d2r/ds2 = a(r, -w, t = -s)``, the effects evaluated at
    the true velocity and the true time (:func:`~hamilton_orbits.rhs.codegen.source`,
    ``reverse``).  ``rhs`` itself when no effect depends on velocities or on the
    time (``a(r, -w) = a(r, w)``).  Of ``rhs`` compiled with ``variational=True``,
    its variational equations too, on the tangent vectors ``(dr, dw) = (dr, -dv)``:
    the effects' Jacobians applied at the true velocity and time to ``(dr, -dw)``.

    Examples
    --------
    >>> from hamilton_orbits import Body, System
    >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("b", 0.0, [1, 0, 0], [0, 1, 0])])
    >>> rhs = compile_rhs(s, [{"name": "nongrav", "body": "b", "A2": 1e-3}])
    >>> r, v, gm = np.array(s.r), np.array(s.v), np.array(s.gm)
    >>> back = time_reversed(rhs).acceleration(r, -v, gm)  # (at w = -v)
    >>> bool(np.array_equal(back, rhs.acceleration(r, v, gm)))
    True
    """
    if rhs.reversed is not None:
        return rhs.reversed
    if not rhs.velocity_dependent and not rhs.timed:
        return rhs
    specs = [get("nbody", name) for name in rhs.effects[1:]]
    kernels = tuple(spec.kernel for spec in specs)
    refs, replaces = tuple(kernel_ref(k) for k in kernels), any(
        spec.replaces_newtonian for spec in specs)
    if rhs.tangent is None:
        return RHS(*_memoised((refs, replaces, None, "reversed"), kernels), rhs.p,
                   rhs.velocity_dependent, rhs.effects, timed=rhs.timed)
    jacobians = tuple((spec.jacobian, spec.velocity_dependent) for spec in specs)
    key = (refs, replaces, tuple(_jac_ref(j, vd) for j, vd in jacobians), "reversed")
    accel, extra, tangent, tangent_extra, augmented = _memoised(
        key, kernels, tuple(j for j, _ in jacobians))
    return RHS(accel, extra, rhs.p, rhs.velocity_dependent, rhs.effects, tangent,
               tangent_extra, augmented, timed=rhs.timed)


_MEMO: dict[tuple, tuple[Any, Any]] = {}
_LOCK = threading.Lock()
_SWEPT: set[str] = set()  # the cache folders this process has removed stale files from


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
    key = (tuple(kernel_ref(k) for k in kernels), bool(replaces_newtonian))
    return _memoised(key, kernels)


def _memoised(key: tuple, kernels: tuple[Any, ...],
              jacobians: tuple[Any, ...] | None = None) -> tuple[Any, ...]:
    """The compiled functions of ``key``, built once per process (:func:`_build`)."""
    with _LOCK:
        found = _MEMO.get(key)
        if found is None:
            found = _build(key, kernels, jacobians)
            _MEMO[key] = found
    return found


def _jac_ref(jacobian: Any, velocity_dependent: bool) -> tuple[str, str]:
    """``(module, name)`` of an analytic Jacobian, or ``("fd", parts)`` for central
    differences over positions (and velocities)."""
    if jacobian is None:
        return ("fd", "2" if velocity_dependent else "1")
    return kernel_ref(jacobian)


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
    key = (tuple(kernel_ref(k) for k in kernels), bool(replaces_newtonian), jac_key)
    return _memoised(key, kernels, tuple(j for j, _ in jacobians))


def _build(key: tuple, kernels: tuple[Any, ...],
           jacobians: tuple[Any, ...] | None = None) -> tuple[Any, ...]:
    refs, replaces_newtonian = key[:2]
    jac_refs = key[2] if len(key) > 2 else None
    reverse = key[3:] == ("reversed",)
    timed = {"timed": tuple(takes_time(k, 5) for k in kernels),
             "jac_timed": tuple(j is not None and takes_time(j, 7) for j in jacobians or ())}
    sources = module_sources(refs, replaces_newtonian, jac_refs)
    folder = cache_dir() if sources is not None else None
    if folder is None:
        namespace = _in_memory(refs, replaces_newtonian, kernels, jac_refs, jacobians,
                               reverse, timed)
    else:
        name = digest(refs, replaces_newtonian, jac_refs, sources, reverse)
        text = source(refs, replaces_newtonian, name, jac_refs, sources=sources,
                      reverse=reverse, **timed)
        namespace = vars(load_module(folder / f"{MODULE_PREFIX}{name}.py", text))
        if str(folder) not in _SWEPT:
            _SWEPT.add(str(folder))
            remove_stale(folder)
    names = ("accel", "extra") if jac_refs is None else (
        "accel", "extra", "tangent", "tangent_extra", "augmented")
    return tuple(namespace[name] for name in names)


def _in_memory(refs: tuple, replaces_newtonian: bool, kernels: tuple[Any, ...],
               jac_refs: tuple | None = None, jacobians: tuple | None = None,
               reverse: bool = False, timed: dict[str, tuple] | None = None) -> dict[str, Any]:
    """The same source compiled for this process only (no disk cache); its namespace."""
    text = source(refs, replaces_newtonian, "in-memory", jac_refs, cache=False, imports=False,
                  reverse=reverse, **(timed or {}))
    namespace: dict[str, Any] = {f"k{i}": k for i, k in enumerate(kernels)}
    namespace.update({f"j{i}": j for i, j in enumerate(jacobians or ()) if j is not None})
    namespace["__name__"] = f"{MODULE_PREFIX}in_memory"
    exec(compile(text, f"<{MODULE_PREFIX}in-memory>", "exec"), namespace)
    return namespace

