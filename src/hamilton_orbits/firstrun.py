"""A one-line notice on stderr while the package's kernels compile for the first time.

With no numba cache, the first calls compile kernels for seconds (about 5 s
for the main job on two cores: ``benchmarks/bench_first_run.py``), which otherwise
looks like a hang.  A listener on numba's
``numba:compile`` event (fired only when a function is really compiled, not
when it is loaded from the on-disk cache) prints one line the first time a
function of this package (or of ``rigid``) compiles, at most once per process.
It is a plain line on stderr, not a warning (the test suite turns warnings into
errors), and costs nothing once the cache is warm.

The same listener keeps a clock of compilation (:func:`compile_seconds`,
:func:`compile_count`): the seconds spent in numba's outermost compile events
(a function compiling the functions it calls is one event), so that a run can
report its integration time without the compilation that happened inside it,
and the compilation on its own line.  It also pauses Python's garbage collector
while a kernel of the package compiles (a fifth of a first
run's compilation).

Public: ``rigid``'s kernels and scenes report their compilation through it.
"""

from __future__ import annotations

import gc
import sys
import threading
import time

from numba.core import event

#: No estimate: what a run compiles depends on its method, effects and events (the
#: main job's, measured by ``benchmarks/bench_first_run.py``, is in the README); the
#: summary of a scene's run names what was compiled and how long it took.
NOTICE = (
    "hamilton-orbits: compiling numerical kernels for first use "
    "(once; cached for later runs) ..."
)
PACKAGES = ("hamilton_orbits", "rigid")
#: The modules of the generated right-hand sides (:mod:`hamilton_orbits.rhs`).
GENERATED_PREFIX = "hamilton_orbits_rhs_"

_lock = threading.Lock()
_state = {"printed": False}
_clock = {"seconds": 0.0, "count": 0, "claimed_seconds": 0.0, "claimed_count": 0}
#: ``(function, seconds)`` of every outermost compilation, in order; and those of the
#: last claim (:func:`last_claim`)
_compiled: list[tuple[str, float]] = []
_claimed: dict[str, list[tuple[str, float]]] = {"last": []}
_local = threading.local()


def _ours(dispatcher: object) -> bool:
    func = getattr(dispatcher, "py_func", None)
    module = getattr(func, "__module__", None) or ""
    return module.split(".", 1)[0] in PACKAGES or module.startswith(GENERATED_PREFIX)


def _name(ev: event.Event) -> str:
    """``module.function`` of the function a compile event is about, without the
    package's own prefixes (``hamilton_orbits._kernels.radau15.advance`` ->
    ``radau15.advance``)."""
    data = ev.data if isinstance(ev.data, dict) else {}
    func = getattr(data.get("dispatcher"), "py_func", None)
    module = getattr(func, "__module__", None) or "?"
    for prefix in ("hamilton_orbits._kernels.", "rigid._kernels.", "hamilton_orbits."):
        if module.startswith(prefix):
            module = module[len(prefix):]
            break
    return f"{module}.{getattr(func, '__qualname__', '?')}"


def _pause_gc(ev: event.Event) -> bool:
    """Pause Python's cyclic garbage collector while numba compiles a kernel of this
    package (from its outermost compile event to its end); True if it was running.

    numba's compiler allocates objects by the million, and every collection they
    trigger walks all the objects the process holds (astropy's among them): paused,
    a first ``integrate`` of radau15 or wh compiles in 15-20% less time (3.8 s
    instead of 4.5 s, 4.0 instead of 4.9; ``benchmarks/bench_first_run.py``), for
    40-60 MB more memory at its peak (the garbage of the compilation, freed when the
    collector runs again; 160 MB for the largest kernel, radau15's with events).
    Other packages' compilations are left as they are."""
    data = ev.data if isinstance(ev.data, dict) else {}
    if not (_ours(data.get("dispatcher")) and gc.isenabled()):
        return False
    gc.disable()
    return True


class _CompileNotice(event.Listener):
    def on_start(self, ev: event.Event) -> None:
        depth = getattr(_local, "depth", 0)
        if depth == 0:
            _local.start = time.perf_counter()
            _local.name = _name(ev)
            _local.gc_was_enabled = _pause_gc(ev)
        _local.depth = depth + 1
        if _state["printed"]:
            return
        data = ev.data if isinstance(ev.data, dict) else {}
        if _ours(data.get("dispatcher")):
            notice()

    def on_end(self, ev: event.Event) -> None:
        depth = getattr(_local, "depth", 0) - 1
        _local.depth = max(depth, 0)
        if depth == 0:
            if getattr(_local, "gc_was_enabled", False):
                gc.enable()
            add_compilation(getattr(_local, "name", "?"), time.perf_counter() - _local.start)


def compiling() -> bool:
    """Whether this thread is inside a numba compilation now (of any package's
    function: between its ``numba:compile`` events' start and end).

    Examples
    --------
    >>> compiling()  # (here, between compilations)
    False
    """
    return getattr(_local, "depth", 0) > 0


def compile_seconds() -> float:
    """Seconds spent compiling with numba in this process so far (every package's
    functions; nested compilations counted once).

    Examples
    --------
    >>> before = compile_seconds()
    >>> compile_seconds() >= before >= 0.0
    True
    """
    return _clock["seconds"]


def claim_compilation() -> tuple[float, int]:
    """The compilation not claimed before: ``(seconds, count)`` since the last call
    (or since the process started), then marked as claimed.

    A scene's run claims it at its end, so that its summary reports the
    compilation that its first run in a process really cost, including kernels
    compiled when their module was imported (those with explicit signatures
    compile at import, before the run starts), and a second run reports none.

    Examples
    --------
    >>> _ = claim_compilation()
    >>> claim_compilation()
    (0.0, 0)
    """
    with _lock:
        seconds = _clock["seconds"] - _clock["claimed_seconds"]
        count = _clock["count"] - _clock["claimed_count"]
        _claimed["last"] = _compiled[len(_compiled) - count:] if count else []
        _clock["claimed_seconds"] = _clock["seconds"]
        _clock["claimed_count"] = _clock["count"]
    return seconds, count


def last_claim() -> list[tuple[str, float]]:
    """What the last :func:`claim_compilation` covered: ``(function, seconds)`` of each
    outermost compilation (a kernel with the functions it calls), in order.

    Examples
    --------
    >>> _ = claim_compilation()
    >>> last_claim()
    []
    """
    with _lock:
        return list(_claimed["last"])


def describe(compiled: list[tuple[str, float]], shown: int = 3) -> str:
    """The longest compilations of ``compiled`` by name, the rest counted.

    Examples
    --------
    >>> describe([("radau15.advance", 8.84), ("nbody.newtonian_only", 3.1),
    ...           ("checks.all_finite", 0.1), ("nbody.closest_pair", 0.2)], shown=2)
    'radau15.advance 8.8 s, nbody.newtonian_only 3.1 s, 2 more 0.3 s'
    """
    ranked = sorted(compiled, key=lambda item: -item[1])
    parts = [f"{name} {seconds:.1f} s" for name, seconds in ranked[:shown]]
    rest = ranked[shown:]
    if rest:
        parts.append(f"{len(rest)} more {sum(s for _, s in rest):.1f} s")
    return ", ".join(parts)


def add_compilation(name: str, seconds: float) -> None:
    """Count ``seconds`` of compilation of ``name``: an outermost numba compilation,
    or the wait for ``name`` to compile in another process
    (``hamilton_orbits._kernels.entry.compile_ahead``): the run's summary then
    says what the first run waited for, and its integration time leaves it out.

    Examples
    --------
    >>> before = compile_seconds()
    >>> add_compilation("demo.kernel (a second process)", 0.0)
    >>> compile_seconds() == before
    True
    >>> ("demo.kernel (a second process)", 0.0) in (claim_compilation(), last_claim())[1]
    True
    """
    with _lock:
        _clock["seconds"] += seconds
        _clock["count"] += 1
        _compiled.append((name, seconds))


def notice() -> None:
    """Print the first run's notice (once per process), as a first compilation does."""
    with _lock:
        if _state["printed"]:
            return
        _state["printed"] = True
    try:
        print(NOTICE, file=sys.stderr, flush=True)
    except (OSError, ValueError):  # pragma: no cover - stderr closed
        pass


def compile_count() -> int:
    """How many outermost numba compilations this process has run (0 in a process
    whose kernels all came from the on-disk cache).

    Examples
    --------
    >>> compile_count() >= 0
    True
    """
    return _clock["count"]


def install() -> None:
    """Register the listener (once).

    Examples
    --------
    >>> install()
    >>> install()  # idempotent
    """
    with _lock:
        if _state.get("installed"):
            return
        event.register("numba:compile", _CompileNotice())
        _state["installed"] = True


# Installed when this module is imported: by hamilton_orbits._kernels, before
# any kernel of the package exists (a bare ``import hamilton_orbits`` imports
# neither numba nor this module).
install()
