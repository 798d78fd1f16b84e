"""restart.Capture: the state flatten would give, found again without a new walk.

The invariant tested: whenever ``Capture.take`` returns a result, ``flatten`` of
the same object gives the layout the capture was made from, the same arrays (the
same objects, in the same order) and the same numbers; whenever the graph's shape
differs from that layout in any way flatten would record, ``take`` returns None.
"""

from __future__ import annotations

import numpy as np
import pytest

from hamilton_orbits import Simulation
from hamilton_orbits.integrators._setup import accel_arg
from hamilton_orbits.restart import Capture, flatten

#: The disc's planets p1 and p2 pass 0.15 apart near t = 8.9 (time scale 1.3), which
#: steps of 0.05 do not resolve (the run warns of it); the capture is what is tested.
UNRESOLVED = pytest.mark.filterwarnings(
    "ignore::hamilton_orbits.integrals.UnderResolvedEncounterWarning")


class _Leaf:
    def __init__(self) -> None:
        self.t, self.n, self.flag, self.name = 0.5, 3, True, "leaf"
        self.x = np.zeros(3)
        self.k = np.arange(2)
        self.pair = (self.x, 7.5)
        self.items = [np.ones(2), np.float64(1.0), np.int64(4)]
        self.table = {"a": self.k, "b": None}
        self.f = len


class _Root:
    def __init__(self) -> None:
        self.leaf, self.y, self.big = _Leaf(), np.ones((2, 2)), 2**60
        self.address = accel_arg(_compiled())


def _compiled():  # a compiled kernel's address array is "built", never state
    from hamilton_orbits._kernels import nbody
    return nbody.newtonian_only


def _agrees(capture: Capture, layout: dict, obj) -> bool:
    """True if take() gives a result, which is then exactly what flatten gives now
    (asserted); False if it refuses (always safe: the caller flattens afresh)."""
    taken = capture.take(obj)
    numbers: list = []
    now, arrays = flatten(obj, numbers)
    if taken is None:
        return False
    assert now == layout
    assert len(taken[0]) == len(arrays)
    assert all(a is b for a, b in zip(taken[0], arrays, strict=True))
    assert taken[1] == numbers and [type(x) for x in taken[1]] == [type(x) for x in numbers]
    return True


def _mutations():
    """Changes of a graph, each one flatten records in the layout (or not)."""
    def retime(r):  # numbers change: the layout does not
        r.leaf.t, r.leaf.n, r.leaf.flag = 9.25, 11, False
    def refill(r):  # an array written in place, or replaced by one of its shape
        r.y[:] = 5.0
        r.leaf.items[0] = np.full(2, 3.0)
    def grow(r):
        r.leaf.x = np.zeros(4)
    def retype(r):
        r.leaf.t = 1
    def dtype(r):
        r.y = np.ones((2, 2), np.int64)
    def unalias(r):
        r.leaf.pair = (np.zeros(3), 7.5)
    def alias(r):
        r.y = r.leaf.items[0]
    def rename(r):
        r.leaf.name = "other"
    def add(r):
        r.leaf.extra = 1.0
    def drop(r):
        r.leaf.__dict__.pop("f", None)
    def longer(r):
        r.leaf.items.append(2.0)
    def rekey(r):
        r.leaf.table["c"] = 1.0
    def huge(r):
        r.leaf.n = 2**53
    def small(r):
        r.big = 5
    def npnum(r):
        r.leaf.items[2] = np.int64(-9)
    def unbuild(r):
        r.address = np.zeros(2, np.int64)
    def none(r):
        r.leaf.table["b"] = np.zeros(1)
    return [retime, refill, grow, retype, dtype, unalias, alias, rename, add, drop, longer,
            rekey, huge, small, npnum, unbuild, none]


KEEPS = {"retime", "refill", "npnum"}


@pytest.mark.parametrize("change", _mutations(), ids=lambda f: f.__name__)
def test_take_agrees_with_flatten_or_refuses(change):
    root = _Root()
    numbers: list = []
    layout, _ = flatten(root, numbers)
    capture = Capture(root, layout)
    assert _agrees(capture, layout, root)
    change(root)
    assert _agrees(capture, layout, root) == (change.__name__ in KEEPS)


@pytest.mark.parametrize("change", [f for f in _mutations() if f.__name__ in KEEPS],
                         ids=lambda f: f.__name__)
def test_reread_gives_what_take_gives_after_a_change_that_keeps_the_layout(change):
    """``reread`` (the reads without the checks, for a caller that knows only values
    changed, as between two pauses of one compiled run) returns take's arrays (the
    same objects) and numbers (the same values and types)."""
    root = _Root()
    layout, _ = flatten(root, [])
    capture = Capture(root, layout)
    change(root)
    taken, again = capture.take(root), capture.reread(root)
    assert taken is not None and again is not None
    assert all(a is b for a, b in zip(again[0], taken[0], strict=True))
    assert again[1] == taken[1] and [type(x) for x in again[1]] == [type(x) for x in taken[1]]


def test_random_sequences_of_changes_never_give_another_state():
    rng = np.random.default_rng(20261128)
    changes = _mutations()
    outcomes = set()
    for _ in range(300):
        root = _Root()
        layout, _ = flatten(root, [])
        capture = Capture(root, layout)
        for k in rng.integers(0, len(changes), size=int(rng.integers(1, 4))):
            changes[k](root)
            outcomes.add(_agrees(capture, layout, root))
    assert outcomes == {True, False}


@pytest.mark.parametrize("kw", [dict(method="radau15"), dict(method="wh", dt=0.05),
                                dict(method="dop853"), dict(method="leapfrog", dt=0.05),
                                dict(method="radau15", variational=True),
                                dict(method="radau15",
                                     events=[{"name": "close_encounter", "distance": 2.0}])],
                         ids=["radau15", "wh", "dop853", "leapfrog", "variational", "events"])
@UNRESOLVED
def test_a_propagation_is_captured_as_it_is_flattened(kw):
    from test_simulation_legs import _disc

    sim = Simulation(_disc(), **kw)
    sim.integrate(1.0)
    prop = sim._prop
    layout, arrays = flatten(prop, [])
    capture = Capture(prop, layout)
    for t in (2.0, 3.5, 6.0, 9.0):
        sim.integrate(t)
        if prop.events is not None:
            prop.events.drain()
        now, new = flatten(prop, [])
        same = now == layout and [(a.shape, a.dtype) for a in new] == [
            (a.shape, a.dtype) for a in arrays]
        # taken exactly when the graph kept its shape (events found change it)
        assert _agrees(capture, layout, prop) == same
        layout, arrays, capture = now, new, Capture(prop, now)


def test_an_address_array_is_forgotten_with_its_kernel():
    """The addresses of a kernel that was freed (a generated right-hand side no longer
    used) are forgotten with it: a later array given the freed id, such as a user's
    (2,) int64 array, is state again, saved and restored.  Before, the id stayed
    known, and whether such an array was saved depended on the tests run before."""
    import gc

    from numba import njit

    from hamilton_orbits._kernels.signatures import ACCEL_SIGNATURE
    from hamilton_orbits.integrators import _setup

    @njit(ACCEL_SIGNATURE)
    def no_force(r, v, gm, acc, p):  # pragma: no cover - compiled
        acc[:] = 0.0

    found = accel_arg(no_force)
    gone = id(found)
    assert _setup.is_address(found) and gone in _setup._ADDRESS_IDS
    del found, no_force
    gc.collect()
    assert gone not in _setup._ADDRESS_IDS
