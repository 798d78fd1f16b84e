"""The screen of fixed-step runs' close approaches, without a compilation on a first run.

Every call of a fixed-step run (``wh``, ``leapfrog``, radau15 with ``dt``) asks
whether a close approach between its outputs went under-resolved
(:func:`hamilton_orbits.integrals.under_resolved_encounters`).  Its compiled
screen (``hamilton_orbits._kernels.integrals.screen``) answers in a microsecond
but costs a first run 2-3 s of compilation, about as much as the step loop of
``leapfrog`` itself.  :func:`screen` therefore asks numpy first while that kernel
is neither compiled in this process nor in numba's on-disk cache: a looser test
(:func:`may_be_near`: every pair, none of the hierarchy of primaries and Hill
spheres the kernel applies) that rules out the runs whose bodies never come near
for their speed, which are most first runs; the kernel is compiled only where
that test cannot rule a run out, when a system is too large for numpy's arrays
of every pair at every output, or once a process has made enough calls for a
microsecond a call to matter (a loop of calls).  The answer is the kernel's
whenever it is asked, and the looser test never rules out what the kernel would
flag (tested on the kernel's own random legs): what is found is the same.
"""

from __future__ import annotations

import threading

import numpy as np

from hamilton_orbits._kernels import integrals
from hamilton_orbits.validation import read_only

__all__ = ["PREFILTER_CALLS", "PREFILTER_SIZE", "may_be_near", "output_steps", "primaries",
           "screen"]

#: Calls a process answers by numpy before it compiles the screen (a loop of
#: calls: the compilation then costs it less than numpy's 20-100 us a call)
PREFILTER_CALLS = 64
#: The most pairs times outputs numpy's test takes (its arrays: 10 bodies over 2000
#: outputs; beyond, the screen is compiled)
PREFILTER_SIZE = 100_000
#: A margin on the test's reach, far beyond the rounding of its two forms
_MARGIN = 1.0 + 1e-6

_state = {"ready": False, "looked": False, "calls": 0}
_lock = threading.Lock()


def screen(r: np.ndarray, v: np.ndarray, gm: np.ndarray, t: np.ndarray, step: float,
           exempt: int, exempt_dist: float, fraction: float, light: float) -> bool:
    """The compiled screen's answer (whether the whole check could find an
    approach), asked only where :func:`may_be_near` cannot rule the run out while
    the kernel is not compiled: the arguments are the kernel's (C-ordered float64
    arrays ``r``, ``v`` (n_t, n, 3), ``gm`` (n,), ``t`` (n_t,)).

    Examples
    --------
    >>> t = np.array([0.0, 1.0]); gm = np.array([1.0, 0.0])
    >>> r = np.zeros((2, 2, 3)); r[:, 1, 0] = 1.0; v = np.zeros((2, 2, 3)); v[:, 1, 1] = 1.0
    >>> screen(r, v, gm, t, 0.01, -1, 0.0, 1 / 30, 1e-10)  # a circular orbit, 628 steps a turn
    False
    """
    # (read-only, as a system's G m is: a merged or loaded run's writable one compiled
    # the kernel again for another type, 0.7 s)
    gm = read_only(gm)
    args = (r, v, gm, t, step, exempt, exempt_dist, fraction, light)
    if _state["ready"]:  # (a continuing call: the kernel's answer, at once)
        return integrals.screen(*args)
    pairs = r.shape[1] * (r.shape[1] - 1) // 2
    if _ready(integrals.screen, args) or r.shape[0] * pairs > PREFILTER_SIZE:
        return bool(integrals.screen(*args))
    with _lock:
        _state["calls"] += 1
    return may_be_near(r, v, gm, t, step, (exempt, exempt_dist), fraction, light) and bool(
        integrals.screen(*args))


def _ready(kernel: object, args: tuple) -> bool:
    """Whether the kernel is compiled here, in the on-disk cache (looked at once a
    process), or has been put off for :data:`PREFILTER_CALLS` calls."""
    if _state["ready"]:
        return True
    if getattr(kernel, "signatures", None) or _state["calls"] >= PREFILTER_CALLS:
        _state["ready"] = True
    elif not _state["looked"]:
        from hamilton_orbits._kernels.entry import on_disk

        _state["looked"] = True
        _state["ready"] = on_disk(kernel, args)
    return _state["ready"]


def may_be_near(r: np.ndarray, v: np.ndarray, gm: np.ndarray, t: np.ndarray, step: float,
                exempt: tuple[int, float], fraction: float, light: float) -> bool:
    """Whether the compiled screen could find an approach: False only where it
    would not.  Its test on every pair of a massive body with a lighter one (the
    "particle"; of two equal, the later), with ``mu`` their summed GM (bodies of at
    most ``light`` of the largest GM massless): at an output, or at the two-body
    periapsis of a pair that passed its closest point between two outputs (its
    radial velocity from approaching to receding in the run's direction), a
    distance ``d`` at a relative speed ``u`` with ``min(d / u, sqrt(d^3 / mu))``
    under ``1 / fraction`` of the step (the step, or the output interval where
    shorter), about the particle's primary or within three Hill radii of the body
    about the body's own primary (:func:`primaries`); a massive body and its own
    primary are left out (its own orbit: the energy's error measures it), and so
    are the approaches to the body ``exempt[0]`` beyond ``exempt[1]`` (those the
    method integrates exactly; -1: none).  Looser than the screen (either distance
    may count) and with a margin on each comparison, far beyond the rounding of the
    two forms.

    Examples
    --------
    >>> t = np.array([0.0, 1.0]); gm = np.array([1.0, 0.0])
    >>> r = np.zeros((2, 2, 3)); r[:, 1, 0] = 0.01; v = np.zeros((2, 2, 3)); v[:, 1, 1] = 20.0
    >>> none = (-1, 0.0)
    >>> may_be_near(r, v, gm, t, 0.1, none, 1 / 30, 1e-10)
    True
    >>> may_be_near(r, v, gm, t, 1e-5, none, 1 / 30, 1e-10)  # a step that resolves it
    False
    >>> may_be_near(r, v, gm, t, 0.1, (0, 0.0), 1 / 30, 1e-10)  # wh's Sun: exact
    False
    """
    n_t, n = r.shape[0], r.shape[1]
    if n_t < 2 or n < 2:
        return False
    if not (np.isfinite(gm).all() and np.isfinite(t).all()):
        return True  # (the screen's comparisons pass over a NaN as numpy's do not)
    if not np.max(gm) > 0:
        return False
    gm0 = np.where(gm <= light * np.max(gm), 0.0, gm)
    prim = primaries(r[0], v[0], gm0)
    a, b = np.triu_indices(n, 1)
    swap = gm0[b] <= gm0[a]  # (the particle the lighter, of two equal the later)
    a, b = np.where(swap, b, a), np.where(swap, a, b)
    keep = (gm0[b] > 0) & ~((gm0[a] > 0) & (prim[a] == b))
    a, b = a[keep], b[keep]
    mu, own, cb = gm0[a] + gm0[b], prim[a] == b, prim[b]
    d, u = r[:, a] - r[:, b], v[:, a] - v[:, b]  # (n_t, pairs, 3)
    d2 = (d[..., 0] * d[..., 0] + d[..., 1] * d[..., 1]) + d[..., 2] * d[..., 2]
    u2 = (u[..., 0] * u[..., 0] + u[..., 1] * u[..., 1]) + u[..., 2] * u[..., 2]
    rad = (d[..., 0] * u[..., 0] + d[..., 1] * u[..., 1]) + d[..., 2] * u[..., 2]
    sep = r[:, b] - r[:, np.maximum(cb, 0)]  # (the body from its own primary)
    sep2 = (sep[..., 0] ** 2 + sep[..., 1] ** 2) + sep[..., 2] ** 2
    rule = (own | (cb < 0), 81.0 * gm0[b] ** 2 * sep2 ** 3 * _MARGIN, gm0[cb] ** 2,
            b != exempt[0], (exempt[1] * _MARGIN) ** 2)
    reach2 = ((output_steps(t, step) / fraction * _MARGIN) ** 2)[:, None]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        if np.any(_within(d2, u2, mu, reach2, rule)):
            return True
        ahead = np.sign(t[1:] - t[:-1])[:, None]  # the legs' direction of time
        k, p = np.nonzero((ahead * rad[:-1] < 0) & (ahead * rad[1:] > 0))
        q0, inv0 = _periapsis(d2[k, p], u2[k, p], rad[k, p], mu[p])
        q1, inv1 = _periapsis(d2[k + 1, p], u2[k + 1, p], rad[k + 1, p], mu[p])
        q = np.maximum(q0, q1)
        speed2 = np.maximum(mu[p] * (2.0 / q - np.maximum(inv0, inv1)), 0.0)
        rule = (rule[0][p], rule[1][k + 1, p], rule[2][p], rule[3][p], rule[4])
        return bool(np.any(_within(q * q, speed2, mu[p], reach2[k + 1, 0], rule)))


def primaries(r: np.ndarray, v: np.ndarray, gm0: np.ndarray) -> np.ndarray:
    """Each body's primary in the state ``r``, ``v`` (n, 3), as the compiled screen
    finds it (``hamilton_orbits._kernels.integrals.primaries(..., massive=True)``,
    with the same arithmetic in the same order, so the same bits): the heavier body
    (of two equal massive ones, the earlier) it is bound to with the largest ``1/a``
    (a massless one: to which its ``1/a`` is largest and positive), else the first
    of largest GM; -1 for that body.

    Examples
    --------
    >>> r = np.array([[0.0, 0, 0], [1.0, 0, 0], [1.0026, 0, 0], [2.0, 0, 0]])
    >>> v = np.array([[0.0, 0, 0], [0, 1.0, 0], [0, 1.03, 0], [0, 0.7, 0]])
    >>> primaries(r, v, np.array([1.0, 3e-6, 3.7e-8, 0.0])).tolist()  # a moon's is 1
    [-1, 0, 1, 0]
    """
    n = len(gm0)
    top = int(np.argmax(gm0))
    d, w = r[:, None, :] - r[None, :, :], v[:, None, :] - v[None, :, :]  # (i, j, 3)
    d2 = (d[..., 0] ** 2 + d[..., 1] ** 2) + d[..., 2] ** 2
    w2 = (w[..., 0] ** 2 + w[..., 1] ** 2) + w[..., 2] ** 2
    gi, gj = gm0[:, None], gm0[None, :]
    mu = gj + gi
    below = np.arange(n)[None, :] < np.arange(n)[:, None]
    heavier = (gj > gi) | ((gj == gi) & below & (gj > 0))
    with np.errstate(divide="ignore", invalid="ignore"):
        inv_a = 2.0 / np.sqrt(d2) - w2 / mu
        unbound = (w2 * w2 * d2 >= 4.0 * mu * mu) & (gi > 0)
    bound = heavier & ~unbound & (inv_a > 0.0)
    best = np.argmax(np.where(bound, inv_a, -np.inf), axis=1)
    prim = np.where(bound[np.arange(n), best], best, top)
    return np.where(np.arange(n) != top, prim, -1)


def output_steps(t: np.ndarray, step: float) -> np.ndarray:
    """The step taken about each output of times ``t`` (n_t,) of a run of fixed
    ``step``: ``step``, or the longer of the output intervals beside it where that
    is shorter (steps land on the outputs), as the check of close approaches
    (:func:`hamilton_orbits.integrals.under_resolved_encounters`) takes it (``n_t >= 2``).

    Examples
    --------
    >>> output_steps(np.array([0.0, 0.5, 10.0, 10.25]), 1.0).tolist()
    [0.5, 1.0, 1.0, 0.25]
    """
    gap = np.abs(np.diff(t))
    return np.minimum(step, np.maximum(np.concatenate((gap[:1], gap)),
                                       np.concatenate((gap, gap[-1:]))))


def _within(d2: np.ndarray, u2: np.ndarray, mu: np.ndarray, reach2: np.ndarray,
            rule: tuple) -> np.ndarray:
    """Where ``min(d / u, sqrt(d^3 / mu))`` is within the reach (in squares, with a
    factor of 2 on the fall time), the distance about the particle's primary or
    within three Hill radii of the body, and not an exempt body's beyond its distance
    (``rule``: where no Hill sphere applies, ``81 gm_b^2 sep^6`` and ``gm_cb^2``,
    where the body is not exempt, and the exempt distance squared, as
    :func:`may_be_near` makes them)."""
    near = (d2 < reach2 * u2) | (d2 * d2 * d2 < 2.0 * (reach2 * mu) ** 2)
    hill = rule[0] | (d2 * d2 * d2 * rule[2] <= rule[1])
    return near & hill & (rule[3] | (d2 <= rule[4]))


def _periapsis(d2: np.ndarray, u2: np.ndarray, rad: np.ndarray,
               mu: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The two-body periapsis ``q`` and ``1/a`` from ``|d|^2``, ``|u|^2``, ``d . u``."""
    inv_a = 2.0 / np.sqrt(d2) - u2 / mu
    h2 = np.maximum(d2 * u2 - rad * rad, 0.0)
    ecc = np.sqrt(np.maximum(1.0 - h2 / mu * inv_a, 0.0))
    return h2 / mu / (1.0 + ecc), inv_a
