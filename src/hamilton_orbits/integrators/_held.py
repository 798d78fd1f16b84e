"""Ctrl-C held while a compiled call's steps are counted.

A stepping kernel runs compiled, without the GIL, through a slice of up to some
hundred thousand steps, changing the state's arrays in place.  A Ctrl-C meanwhile
is seen by Python only when the call returns, and CPython looks for it at the end
of the call instruction itself: Python's own handler raises ``KeyboardInterrupt``
before the driver has taken the call's result, the steps it took and the time it
reached.  The arrays have moved a slice on; the driver's clock and step count have
not.  A simulation kept after that Ctrl-C (``on_interrupt="keep"``, or the
``KeyboardInterrupt`` caught) went on from a state a slice ahead of its clock,
without a word: a 10-body ``wh`` run 19 au off its uninterrupted self after 6000
more time units; a ``radau15`` one 20 000 steps short in its count.

:data:`HELD` is entered around each compiled stepping call and the count of what
it did.  Python's default SIGINT handler is replaced, on each such call in the
main thread that finds it in place (Jupyter puts it back before each cell), by
one that does what it does (raise ``KeyboardInterrupt``)
except within :data:`HELD`: there the Ctrl-C is held, and raised as :data:`HELD`
is left, the state and its counts then agreeing.  A Ctrl-C while numba compiles
the call's kernel (a first call, within: no step taken yet,
:func:`hamilton_orbits.firstrun.compiling`) and a second Ctrl-C within are raised
at once (a first one waited for the compilation, seconds, and then for the first
slice of steps).  A handler of one's own is left alone (it may call
:meth:`CtrlCHeld.interrupt` to be held likewise); other threads are not held.

Examples
--------
>>> from hamilton_orbits.integrators._held import HELD
>>> try:
...     with HELD:
...         HELD.interrupt()  # (as a Ctrl-C within: held until HELD is left)
...         print("counted")
... except KeyboardInterrupt:
...     print("then raised")
counted
then raised
>>> HELD.depth, HELD.pending
(0, False)
"""

from __future__ import annotations

import functools
import signal
import sys
import threading
from collections.abc import Callable
from types import FrameType, TracebackType
from typing import Any, TypeVar

# the C function behind signal.getsignal, without its conversion to an enum: 10 ns
# against 1.5 us a call (the handlers are compared by identity: the same either way)
try:
    from _signal import getsignal as _getsignal
except ImportError:  # pragma: no cover - (another Python: the public one)
    _getsignal = signal.getsignal

__all__ = ["HELD", "CtrlCHeld", "held"]

_thread = threading.get_ident
_SIGINT = signal.SIGINT


def _compiling() -> bool:
    """Whether numba compiles a call's kernel (:func:`hamilton_orbits.firstrun.
    compiling`; never before that module is imported: this one imports no numba,
    for the archive's files it guards too)."""
    firstrun = sys.modules.get("hamilton_orbits.firstrun")
    return firstrun is not None and firstrun.compiling()


class CtrlCHeld:
    """A Ctrl-C held within (``with``), raised as it is left (see the module)."""

    __slots__ = ("_handler", "_main", "depth", "pending")

    def __init__(self) -> None:
        #: how deep the main thread is within
        self.depth = 0
        #: a Ctrl-C within, to raise as it is left
        self.pending = False
        self._main = threading.main_thread().ident
        self._handler = self._on_sigint  # (one bound method: installed, and looked for)

    def __enter__(self) -> CtrlCHeld:
        if _thread() == self._main:
            if _getsignal(_SIGINT) is not self._handler:  # (looked at each time: Python's
                self._install()  # default may have been put back, as Jupyter does per cell)
            if not self.depth:  # (one left by a second Ctrl-C amid __exit__, raised then)
                self.pending = False
            self.depth += 1
        return self

    def __exit__(self, kind: type[BaseException] | None, value: BaseException | None,
                 traceback: TracebackType | None) -> None:
        if _thread() != self._main or not self.depth:
            return
        self.depth -= 1
        if not self.depth and self.pending:
            self.pending = False
            if kind is None:  # (an exception going on is not replaced)
                raise KeyboardInterrupt

    def interrupt(self) -> None:
        """A Ctrl-C: ``KeyboardInterrupt`` raised now, or held as the first within."""
        if self.depth and not self.pending and _thread() == self._main:
            self.pending = True
        else:
            raise KeyboardInterrupt

    def _on_sigint(self, signum: int, frame: FrameType | None) -> None:
        if self.depth and not self.pending and not _compiling():
            self.pending = True
        else:  # (raised at once also while numba compiles the call's kernel: no step
            signal.default_int_handler(signum, frame)  # taken yet, nothing to count)

    def _install(self) -> None:
        """This one's handler for SIGINT where Python's default is (the main thread)."""
        if _getsignal(_SIGINT) is signal.default_int_handler:
            try:
                signal.signal(_SIGINT, self._handler)
            except ValueError:  # pragma: no cover - (not the main interpreter)
                pass


#: the one :class:`CtrlCHeld` the drivers enter
HELD = CtrlCHeld()


_F = TypeVar("_F", bound=Callable[..., Any])


def held(function: _F) -> _F:
    """``function`` called within :data:`HELD`: a Ctrl-C meanwhile raised as it
    returns.  For the archive's files: a Ctrl-C between a system call that opens a
    file (or makes one) and the statement that keeps its descriptor left the
    descriptor open for good, or a temporary file behind; a function so wrapped
    keeps what it opens where its caller's cleanup finds it (its return value is
    then lost: wrap the method that stores a descriptor, not the one returning it).
    If the function raises meanwhile, the Ctrl-C is raised instead, the error its
    cause (the caller that handles the error would have gone on as if no Ctrl-C
    had come)."""

    @functools.wraps(function)
    def call(*args: Any, **kwargs: Any) -> Any:
        with HELD:
            try:
                return function(*args, **kwargs)
            except Exception as exc:  # (a Ctrl-C held meanwhile is not lost with it:
                if HELD.depth == 1 and HELD.pending:  # raised, the error its cause)
                    HELD.pending = False
                    raise KeyboardInterrupt from exc
                raise

    return call  # type: ignore[return-value]

