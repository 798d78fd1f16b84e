"""What the drivers share: their input checks, the starting step, the addresses of a
right-hand side for the stepping kernels, and :func:`runner`, which makes each
driver's one-call ``run`` from its ``start``."""

from __future__ import annotations

import math
import weakref
from collections.abc import Callable
from typing import Any

import numpy as np

from hamilton_orbits._kernels import checks as _checks
from hamilton_orbits._kernels import nbody as _nbody
from hamilton_orbits._kernels.signatures import ACCEL_SIGNATURE
from hamilton_orbits.validation import ConvergenceError, as_float_array, check_positive

_ADDRESSES: weakref.WeakKeyDictionary[Any, dict[int, np.ndarray]] = weakref.WeakKeyDictionary()
#: the ids of the address arrays handed out (they live as long as their dispatcher)
_ADDRESS_IDS: set[int] = set()


def addresses(fn: Any, signature: Any = ACCEL_SIGNATURE) -> np.ndarray:
    """The addresses ``[C wrapper, entry point]`` (int64) of the compiled function
    ``fn`` (a numba dispatcher) for ``signature``, the form in which a stepping
    kernel takes a right-hand side (:mod:`hamilton_orbits._kernels.signatures`),
    found once per dispatcher and signature.

    Examples
    --------
    >>> from hamilton_orbits._kernels import nbody
    >>> accel_arg(nbody.newtonian_only) is accel_arg(nbody.newtonian_only)
    True
    >>> bool(np.all(accel_arg(nbody.newtonian_only) > 0))
    True
    """
    known = _ADDRESSES.get(fn)
    if known is None:
        known = _ADDRESSES[fn] = {}
    found = known.get(id(signature))  # the signatures are module constants (hashing one: us)
    if found is None:
        cres = fn.get_compile_result(signature)
        lib, names = cres.library, cres.fndesc
        found = np.array([lib.get_pointer_to_function(names.llvm_cfunc_wrapper_name),
                          lib.get_pointer_to_function(names.llvm_func_name)], dtype=np.int64)
        known[id(signature)] = found
        _ADDRESS_IDS.add(id(found))
        # (forgotten with the array: a later array given the freed id is not one)
        weakref.finalize(found, _ADDRESS_IDS.discard, id(found))
    return found


def is_address(arr: np.ndarray) -> bool:
    """True if ``arr`` is an array of compiled-function addresses (:func:`addresses`):
    a value of this process that a saved state must not carry.

    Examples
    --------
    >>> from hamilton_orbits._kernels import nbody
    >>> is_address(accel_arg(nbody.newtonian_only)), is_address(np.zeros(2, np.int64))
    (True, False)
    """
    return id(arr) in _ADDRESS_IDS and arr.dtype == np.int64 and arr.shape == (2,)


def force_arg(rhs: Any, gm: np.ndarray, watch: np.ndarray) -> np.ndarray:
    """:func:`accel_arg` of ``rhs``'s right-hand side, or, for the right-hand side of
    no effect with fewer than :data:`~hamilton_orbits._kernels.nbody.SIMD_FROM`
    bodies, all massive, watching no event (the masses then never change), of
    :func:`~hamilton_orbits._kernels.nbody.newtonian_few`: the same bits, and a first
    run of a few bodies compiles neither the SIMD form nor the test particles'.

    Examples
    --------
    >>> from hamilton_orbits._kernels import nbody
    >>> from hamilton_orbits.rhs import newtonian_rhs
    >>> few = force_arg(newtonian_rhs(), np.array([1.0, 1e-3]), np.zeros((0, 5)))
    >>> few is accel_arg(nbody.newtonian_few)
    True
    >>> force_arg(newtonian_rhs(), np.array([1.0, 0.0]), np.zeros((0, 5))) is few
    False
    """
    fn = rhs.accel
    if (fn is _nbody.newtonian_only and watch.shape[0] == 0 and gm.shape[0] < _nbody.SIMD_FROM
            and bool((gm > 0.0).all())):
        fn = _nbody.newtonian_few
    return accel_arg(fn)


def accel_arg(fn: Any) -> np.ndarray:
    """The addresses of a right-hand side ``fn`` (:data:`ACCEL_SIGNATURE`) for a
    stepping kernel (:func:`addresses`)."""
    return addresses(fn, ACCEL_SIGNATURE)


def check_inputs(
    r0: Any, v0: Any, gm: Any, t_out: Any
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Float64 copies of the state and output times, checked.

    Raises
    ------
    ValueError
        Naming the argument, index and value: non-finite values, shapes other
        than (n, 3), (n, 3), (n,), (n_t,), negative ``gm`` or ``t_out`` not
        strictly increasing.

    Examples
    --------
    >>> check_inputs([[0.0, 0, 0]], [[0.0, 0, 0]], [-1.0], [0.0, 1.0])
    Traceback (most recent call last):
    ...
    ValueError: Expected `gm` >= 0, got -1.0 at index 0
    """
    if _fast_ok(r0, v0, gm, t_out):  # float64 arrays of the right shapes, all valid
        check_apart(r0, gm)
        return r0, v0, gm, t_out
    r0 = np.ascontiguousarray(as_float_array("r0", r0), dtype=np.float64)
    v0 = np.ascontiguousarray(as_float_array("v0", v0), dtype=np.float64)
    gm = np.ascontiguousarray(as_float_array("gm", gm), dtype=np.float64)
    t_out = np.ascontiguousarray(as_float_array("t_out", t_out), dtype=np.float64)
    if r0.ndim != 2 or r0.shape[1] != 3:
        raise ValueError(f"Expected `r0` to have shape (n, 3), got {r0.shape}")
    if v0.shape != r0.shape:
        raise ValueError(f"Expected `v0` to have shape {r0.shape}, got {v0.shape}")
    if gm.shape != (r0.shape[0],):
        raise ValueError(f"Expected `gm` to have shape ({r0.shape[0]},), got {gm.shape}")
    check_positive("gm", gm, strict=False)
    if t_out.ndim != 1 or t_out.shape[0] < 1:
        raise ValueError(f"Expected `t_out` to be a non-empty 1-d array, got shape {t_out.shape}")
    bad = np.nonzero(np.diff(t_out) <= 0.0)[0]
    if bad.size:
        i = int(bad[0]) + 1
        raise ValueError(
            f"Expected `t_out` to be strictly increasing, got {float(t_out[i])!r} at index {i} "
            f"after {float(t_out[i - 1])!r}"
        )
    check_apart(r0, gm)
    return r0, v0, gm, t_out


_TINY = float(np.finfo(np.float64).tiny)  # the smallest normal float64


def check_apart(r: np.ndarray, gm: np.ndarray, names: Any = None, arg: str = "r0") -> None:
    """Refuse two bodies (one of them massive) at one position, or so close that the
    cube of their separation underflows float64 (the force between them would be
    infinite or undefined); ``r`` (n, 3) and ``gm`` (n,) float64, the bodies named
    by ``names`` or else by their indices in ``arg``.

    Examples
    --------
    >>> check_apart(np.array([[1.0, 0, 0], [1.0, 0, 0]]), np.array([0.0, 1.0]))
    Traceback (most recent call last):
    ...
    ValueError: Bodies at indices 0 and 1 of `r0` are at one position [1.0, 0.0, 0.0]
    """
    d2, i, j = _nbody.closest_pair(np.ascontiguousarray(r), np.ascontiguousarray(gm))
    if i < 0 or d2 * math.sqrt(d2) >= _TINY:
        return
    who = (f"Bodies {names[i]!r} and {names[j]!r}" if names is not None
           else f"Bodies at indices {i} and {j} of `{arg}`")
    if np.array_equal(r[i], r[j]):
        raise ValueError(f"{who} are at one position {r[i].tolist()}")
    apart = float(np.max(np.abs(r[i] - r[j])))  # d2 may underflow to 0
    raise ValueError(
        f"{who} are {apart:.3g} apart: the cube of their separation underflows float64 "
        f"(below {_TINY ** (1 / 3):.3g} in the system's length unit); use a smaller length "
        "unit or merge them"
    )


def _fast_ok(r0: Any, v0: Any, gm: Any, t_out: Any) -> bool:
    """True for C-contiguous float64 arrays of the right shapes whose values pass
    every check (one compiled pass, :func:`hamilton_orbits._kernels.checks.state_ok`)."""
    for x in (r0, v0, gm, t_out):
        if type(x) is not np.ndarray or x.dtype != np.float64 or not x.flags.c_contiguous:
            return False
    n = r0.shape[0] if r0.ndim == 2 else -1
    if r0.shape != (n, 3) or v0.shape != (n, 3) or gm.shape != (n,) or t_out.ndim != 1 \
            or t_out.shape[0] < 1:
        return False
    return bool(_checks.state_ok(r0, v0, gm, t_out))


def check_finite(acc: np.ndarray, t: float, method: str) -> None:
    """Raise ``ConvergenceError`` for a non-finite acceleration ``acc`` (C-contiguous)
    at time ``t`` (two bodies at one point), naming ``method`` and the time.  (scipy's
    solver would take a NaN derivative at the start of an interval into a NaN first
    step and loop on it for ever.)

    Examples
    --------
    >>> check_finite(np.array([[0.0, np.inf, 0.0]]), 0.5, "dop853")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    hamilton_orbits.validation.ConvergenceError: dop853 stopped at t = 0.5: the acceleration...
    """
    if not _checks.all_finite(acc.reshape(-1)):
        raise ConvergenceError(f"{method} stopped at t = {float(t)!r}: the acceleration "
                               "became non-finite (two bodies at one point: a collision?)")


def check_dt_tol(dt: Any, tol: Any) -> tuple[float | None, float | None]:
    """``dt`` and ``tol`` as positive finite floats (or None).

    Examples
    --------
    >>> check_dt_tol(0.5, None)
    (0.5, None)
    >>> check_dt_tol(0.0, None)
    Traceback (most recent call last):
    ...
    ValueError: Expected `dt` > 0, got 0.0
    """
    out: list[float | None] = []
    for name, value in (("dt", dt), ("tol", tol)):
        if value is None:
            out.append(None)
            continue
        if type(value) is float and 0.0 < value < math.inf:  # the common case, fast
            out.append(value)
            continue
        arr = as_float_array(name, value)
        if arr.ndim != 0:
            raise ValueError(f"Expected `{name}` to be a scalar, got shape {arr.shape}")
        check_positive(name, arr)
        out.append(float(arr))
    return out[0], out[1]


def initial_step(r0: np.ndarray, v0: np.ndarray, gm: np.ndarray) -> float:
    """A first trial step: 1/100 of the shortest pair free-fall time
    ``sqrt(d^3 / (G m_i + G m_j))`` over pairs with a massive member.

    Examples
    --------
    >>> initial_step(np.array([[0.0, 0, 0], [1.0, 0, 0]]), np.zeros((2, 3)),
    ...              np.array([1.0, 0.0]))
    0.01
    """
    best = _nbody.min_pair_time(np.ascontiguousarray(r0), np.ascontiguousarray(gm))
    if not math.isfinite(best):
        return 1.0
    return 0.01 * best


#: Default limit on the steps of one run of a fixed-step method (refused up front).
MAX_FIXED_STEPS = 1_000_000_000


_HINT = ("pass max_steps=... to go on (a scene's integrator.max_steps), or a shorter "
         "span")


def check_pace(total: int, max_steps: int, t: float, t_out: np.ndarray, method: str,
               hint: str | None = None) -> None:
    """Stop a run of an adaptive method that cannot finish within ``max_steps``: at
    the budget, or early when the pace so far (``total`` steps to reach ``t``)
    projects more than 100 times the budget over the span of ``t_out``; ``hint``
    says what to do about it.

    Examples
    --------
    >>> check_pace(1000, 10**6, 0.5, np.array([0.0, 1.0]), "dop853")  # 2000 projected
    >>> check_pace(1000, 10**6, 1e-6, np.array([0.0, 1e3]), "dop853")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    hamilton_orbits.validation.ConvergenceError: dop853 reached t = 1e-06 of 1000.0 in 1000 ...
    """
    covered = abs(t - t_out[0])
    projected = total * abs(t_out[-1] - t_out[0]) / covered if covered > 0 else math.inf
    if total >= max_steps or projected > 100.0 * max_steps:
        raise ConvergenceError(
            f"{method} reached t = {float(t)!r} of {float(t_out[-1])!r} in {total} steps; at this "
            f"pace the run needs about {projected:.3g} steps, more than max_steps = "
            f"{max_steps} (a step far shorter than the span: {hint or _HINT})"
        )


class StepBudget:
    """A right-hand side ``f(t, y)`` that counts its evaluations and stops a run
    whose steps exceed ``max_steps`` (:func:`check_pace`), for a solver that takes
    no step budget of its own (scipy's ``solve_ivp``).  DOP853 evaluates ``f`` 12
    times a step, rejected steps included: the steps counted are never fewer than
    the solver's.

    Examples
    --------
    >>> f = StepBudget(lambda t, y: -y, np.array([0.0, 1.0]), 10**6, "dop853")
    >>> f(0.0, np.ones(2)).tolist(), f.calls
    ([-1.0, -1.0], 1)
    """

    #: evaluations of a DOP853 step; the pace is checked every 100 steps
    PER_STEP, EVERY = 12, 1200

    def __init__(self, f: Callable[[float, np.ndarray], np.ndarray], t_out: np.ndarray,
                 max_steps: int, method: str, hint: str | None = None) -> None:
        self.f, self.t_out, self.max_steps, self.method = f, t_out, max_steps, method
        self.hint, self.calls = hint, 0

    def __call__(self, t: float, y: np.ndarray) -> np.ndarray:
        self.calls += 1
        if self.calls % self.EVERY == 0:
            check_pace(self.calls // self.PER_STEP, self.max_steps, float(t), self.t_out,
                       self.method, self.hint)
        return self.f(t, y)


def check_step_count(span: float, dt: float, max_steps: int, method: str) -> int:
    """The steps a fixed-step method needs for ``span`` at ``dt``, refused up front
    above ``max_steps`` (a run of hours, or an integer overflow, caught before it
    starts).

    Examples
    --------
    >>> check_step_count(1.0, 0.25, 100, "leapfrog")
    4
    >>> check_step_count(1.0, 1e-12, 10**9, "leapfrog")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: leapfrog would take about 1e+12 steps of dt = 1e-12 over 1 (max_steps = ...
    """
    steps = abs(span) / dt
    if not steps <= max_steps:
        raise ValueError(
            f"{method} would take about {steps:.3g} steps of dt = {dt:.6g} over "
            f"{abs(span):.6g} (max_steps = {max_steps}); choose a longer `dt` or pass "
            "max_steps=... to allow it"
        )
    return max(1, math.ceil(steps * (1.0 - 1e-12)))




def fixed_steps(span: float, dt: float) -> tuple[int, float]:
    """The steps of a fixed-step method over an output interval ``span``: ``n`` steps of
    ``dt``, the last shortened to ``span - (n - 1) dt`` to land on the output (``n``
    rounded up; a remainder within 1e-12 of a step is not a step of its own).

    Examples
    --------
    >>> fixed_steps(1.0, 0.3)
    (4, 0.10000000000000009)
    >>> fixed_steps(0.9, 0.3)
    (3, 0.30000000000000004)
    """
    n = max(1, math.ceil(span / dt * (1.0 - 1e-12)))
    return n, span - (n - 1) * dt


def interval_origin(cut: tuple[float, int] | None, i: int, times: Any,
                    dt: float) -> tuple[float, int]:
    """Where a fixed-step method lays the steps to ``times[i]`` from, and how many
    are taken: from ``times[i - 1]``, none; but for a leg's first interval going on
    from where a Ctrl-C or ``stop()`` cut one (``cut``: that interval's start and
    its steps taken, the leg's start ``times[0]`` their end), from that interval's
    start, its steps taken, so that the last step is the one the run never cut
    takes (laid from the time reached, it is rounded otherwise).

    Examples
    --------
    >>> interval_origin((0.0, 3), 1, [0.30000000000000004, 1.0], 0.1)
    (0.0, 3)
    >>> interval_origin(None, 1, [0.3, 1.0], 0.1)
    (0.3, 0)
    """
    if cut is not None and i == 1 and cut[0] + cut[1] * dt == times[0]:
        if fixed_steps(float(times[1]) - cut[0], dt)[0] > cut[1]:
            return cut
    return float(times[i - 1]), 0

def run_once(start: Callable[..., Any], method: type, rhs: Any, r0: Any, v0: Any, gm: Any,
             t_out: Any, *, dt: Any = None, tol: Any = None,
             on_output: Callable[[int, int], None] | None = None,
             out: tuple[np.ndarray, np.ndarray] | None = None, events: Any = None,
             variational: Any = None, stop: Callable[[], bool] | None = None,
             **options: Any) -> tuple[np.ndarray, np.ndarray, int]:
    """What every driver's ``run`` is (the protocol of :mod:`hamilton_orbits.integrators`):
    one run through ``t_out``, its input checked (:func:`check_inputs`,
    :func:`check_dt_tol`), its ``options`` made the typed ``method`` (a
    :class:`~hamilton_orbits.integrators.methods.Method` class; an option it does not
    take is refused, naming those it takes), then the driver's ``start`` and one
    ``advance``; returns ``(r, v, steps)``."""
    from hamilton_orbits.integrators import output_arrays
    from hamilton_orbits.integrators.methods import method_of

    r0, v0, gm, t_out = check_inputs(r0, v0, gm, t_out)
    typed = method_of(method.name, options)
    dt_f, tol_f = check_dt_tol(dt, tol)
    state = start(rhs, r0, v0, gm, float(t_out[0]), typed, dt=dt_f, tol=tol_f, events=events,
                  variational=variational)
    r_out, v_out = output_arrays(out, t_out.shape[0], r0, v0)
    state.advance(t_out, r_out, v_out, on_output, stop)
    return r_out, v_out, state.steps
