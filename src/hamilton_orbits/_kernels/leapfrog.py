"""The compiled step of the drift-kick-drift leapfrog (driver:
:mod:`hamilton_orbits.integrators.leapfrog`)."""

from __future__ import annotations

import numpy as np
from numba import njit, types

from hamilton_orbits._kernels import events as _ev
from hamilton_orbits._kernels.entry import entry
from hamilton_orbits._kernels.signatures import ADDRESSES, F1, F2, accel_at, set_clock

__all__ = ["STATUS_DRAIN", "STATUS_EVENT", "STATUS_OK", "STATUS_SLICE", "advance",
           "advance_watched"]

STATUS_OK = 0
STATUS_EVENT = 4
STATUS_DRAIN = 5
STATUS_SLICE = 6  # ``max_steps`` steps done before ``t1``: call again from ``ws[0]``

@njit(cache=True, error_model="numpy")
def _drift(r, v, h, t, watch, ev_out, ev_count, ws, x0, cm_gm):  # pragma: no cover - compiled
    """``r += h v``; with events watched, the straight segment is scanned (``ws``:
    the time and watch row of the first event with an action, see
    :func:`hamilton_orbits._kernels.wh._drift`).  ``watch`` None: no events (decided
    at compile time: no event code is compiled).  The scan's arguments ``a0``, ``b``,
    which a straight line does not use, are zeros made here, writable as wh's are (a
    global array is read-only to numba, another type; made in the caller, the
    unwatched steps compiled 0.2 s longer).  The scan is the straight line's alone
    (``events.scan_line``): a first watched run compiles in 8.2 s instead of 19.4."""
    n = r.shape[0]
    n_watch = 0 if watch is None else watch.shape[0]
    if watch is not None and n_watch > 0:
        for i in range(n):
            for k in range(3):
                x0[i, k] = r[i, k]
    for i in range(n):
        for k in range(3):
            r[i, k] += h * v[i, k]
    if watch is not None and n_watch > 0:
        cm = np.zeros(9)
        total = 0.0
        for i in range(n):
            total += cm_gm[i]
            for k in range(3):
                cm[k] += cm_gm[i] * x0[i, k]
                cm[3 + k] += cm_gm[i] * v[i, k]
                cm[6 + k] += cm_gm[i] * r[i, k]
        for c in range(9):
            cm[c] /= total
        hh, row = _ev.scan_line(watch, _ev.LINE, t, h, x0, v, r, v, np.zeros(1), np.zeros((7, 1)),
                           cm_gm, cm, ev_out, ev_count)
        if row >= 0 and t + hh * h < ws[1]:
            ws[1] = t + hh * h
            ws[3] = row
        if ev_count[0] + 2 * n_watch > ev_out.shape[0]:
            ws[2] = 1.0


def _advance(accel_addr, p, r, v, gm, t0, t1, dt, watch, ev_out, ev_count, ws, max_steps):
    # pragma: no cover - compiled
    """The body of :func:`advance` (``watch``, ``ev_out``, ``ev_count`` None) and
    :func:`advance_watched`, each compiled from it with its own signature (not a
    wrapper calling it: see ``docs/design.md``, "Entries are bodies, not wrappers").
    Steps of at most ``dt`` from ``t0`` to exactly ``t1`` (the steps equal, the
    count rounded up), each ``r += h/2 v; v += h a(r); r += h/2 v``, in place.
    Returns ``(steps, status)``; at ``STATUS_EVENT`` (an event with an action) or
    ``STATUS_DRAIN`` the run stopped at the end of step ``steps``, the time in
    ``ws[0]``; at ``STATUS_SLICE`` after ``max_steps`` steps.  Events are scanned on
    both straight drifts of every step."""
    accel = accel_at(accel_addr[0], accel_addr[1])
    n_steps = int(np.ceil((t1 - t0) / dt - 1e-12))
    if n_steps < 1:
        n_steps = 1
    h = (t1 - t0) / n_steps
    acc = np.empty_like(r)
    x0 = np.empty_like(r)
    n = r.shape[0]
    for s in range(n_steps):
        t = t0 + s * h
        _drift(r, v, 0.5 * h, t, watch, ev_out, ev_count, ws, x0, gm)
        set_clock(p, t + 0.5 * h)
        accel(r, v, gm, acc, p)
        for i in range(n):
            for k in range(3):
                v[i, k] += h * acc[i, k]
        _drift(r, v, 0.5 * h, t + 0.5 * h, watch, ev_out, ev_count, ws, x0, gm)
        if watch is not None and (ws[1] <= t0 + (s + 1) * h or ws[2] > 0.0):
            ws[0] = t0 + (s + 1) * h
            return s + 1, STATUS_EVENT if ws[1] <= ws[0] else STATUS_DRAIN
        if s + 1 >= max_steps and s + 1 < n_steps:
            ws[0] = t0 + (s + 1) * h
            return s + 1, STATUS_SLICE
    ws[0] = t1
    return n_steps, STATUS_OK


# explicit signatures with ``accel`` by its addresses: compiled once and loaded from
# the cache in later processes, whatever the right-hand side
_ARGS = (ADDRESSES, F1, F2, F2, F1, types.float64, types.float64, types.float64)
_RESULT = types.Tuple((types.int64, types.int64))


#: Steps of at most ``dt`` from ``t0`` to exactly ``t1`` watching no events (the
#: three event arguments None; see :func:`_advance`): no event code is compiled into it.
advance = entry(_RESULT(*_ARGS, types.none, types.none, types.none, F1, types.int64),
                name="advance", cache=True, nogil=True, error_model="numpy")(_advance)
#: :func:`advance` watching the events ``watch``, recorded into ``ev_out`` / ``ev_count``.
advance_watched = entry(_RESULT(*_ARGS, F2, F2, types.int64[::1], F1, types.int64),
                        name="advance_watched", cache=True, nogil=True,
                        error_model="numpy")(_advance)
