"""Test configuration shared by the whole suite.

Hypothesis runs with random examples on developers' machines (that is how it
finds bugs: see the regression tests it left behind) and derandomised under CI
(``CI`` set), so that a submission's CI verdict does not depend on the luck of
one draw; the examples CI uses are still the same full budget per test.

A first test run on a machine compiles the package's numba kernels (minutes on
two cores) before the first tests report anything: the session says so in one
line when numba's cache holds none of the kernels yet (:func:`numba_cache_cold`).
"""

import importlib.util
import os
import signal
import sys
from pathlib import Path

import pytest
from hypothesis import settings

settings.register_profile("ci", derandomize=True, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")

COLD_NOTICE = (
    "hamilton-orbits: numba's cache holds none of the package's kernels yet: the first "
    "tests compile them (a few minutes on 2 cores, once; later runs load them)"
)


def numba_cache_cold() -> bool:
    """True when numba's on-disk cache has no index file of the radau15 kernels
    (numba writes ``<module>.<function>-<line>.pyXY.nbi`` beside the source, in
    ``__pycache__``, or under ``NUMBA_CACHE_DIR``), found without importing numba."""
    spec = importlib.util.find_spec("hamilton_orbits")
    if spec is None or spec.origin is None:
        return False
    kernels = Path(spec.origin).parent / "_kernels"
    custom = os.environ.get("NUMBA_CACHE_DIR")
    if custom:
        return not any(Path(custom).rglob("radau15.*.nbi"))
    return not any((kernels / "__pycache__").glob("radau15.*.nbi"))


def pytest_sessionstart(session):
    if numba_cache_cold():
        reporter = session.config.pluginmanager.get_plugin("terminalreporter")
        if reporter is not None:
            reporter.write_line(COLD_NOTICE)


#: test files sent to one worker process, one after the other (pytest-xdist's
#: ``--dist loadfile`` sends each file whole to one worker): their first tests
#: compile the same event-watching step loops of radau15 and wh (about 25-30 s of a
#: cold cache, measured 2026-11-30 with numba's compile events: test_events.py's
#: first tests compiled them on the other worker at the very moments test_archive.py
#: did), which two workers running them at once each compiled; one after the other,
#: the later files load them from the cache.  The rigid body's RK4 loop (6 s) alike
SHARE_A_WORKER = {
    "tests/hamilton_orbits/test_simulation_legs.py": "tests/hamilton_orbits/test_archive.py",
    "tests/hamilton_orbits/test_events.py": "tests/hamilton_orbits/test_archive.py",
    "tests/rigid/test_reliability.py": "tests/rigid/test_pole_wander.py",
}


@pytest.hookimpl(optionalhook=True)  # (xdist's hook: unknown without xdist, as -p no:xdist)
def pytest_xdist_make_scheduler(config, log):
    """``--dist loadfile`` with the files of :data:`SHARE_A_WORKER` in one unit of work."""
    if config.getvalue("dist") != "loadfile":
        return None
    from xdist.scheduler import LoadFileScheduling

    class SharedCompiles(LoadFileScheduling):
        def _split_scope(self, nodeid: str) -> str:
            scope = super()._split_scope(nodeid)
            return SHARE_A_WORKER.get(scope, scope)

    return SharedCompiles(config, log)


def pytest_collection_finish(session):
    """Once collected, the half-million objects of the imported libraries and the test
    items are moved out of the garbage collector's sight (``gc.freeze``): they live to
    the end anyway, and every full collection of a test (and the five that pytest runs
    at the session's end to find unraisable exceptions) no longer walks them.  What the
    tests create is collected as before."""
    import gc

    gc.collect()
    gc.freeze()


@pytest.fixture(autouse=True)
def _close_figures():
    """Close the figures a test opened and left open (a scene's ``plot()`` returns its
    figures open, for the caller): with more than 20 open, matplotlib warns, and the
    suite turns that warning into an error in whichever later test opens the 21st.
    Figures that existed before the test (a module fixture's, shared by its tests)
    are left alone."""
    pyplot = sys.modules.get("matplotlib.pyplot")
    before = set(pyplot.get_fignums()) if pyplot is not None else set()
    yield
    pyplot = sys.modules.get("matplotlib.pyplot")
    if pyplot is not None:
        for num in set(pyplot.get_fignums()) - before:
            pyplot.close(num)


@pytest.fixture(autouse=True)
def _pythons_ctrl_c():
    """Tests that press Ctrl-C do so where CPython's own SIGINT handler is, as in an
    interactive process; a suite started with SIGINT ignored (a background job of a
    non-interactive shell, some CI runners) has none (``getsignal`` gives
    ``SIG_IGN``, which cannot be called), and is given it for each test, then the
    handler it had back.  Elsewhere nothing is changed."""
    previous = signal.getsignal(signal.SIGINT)
    if callable(previous):
        yield
        return
    signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
