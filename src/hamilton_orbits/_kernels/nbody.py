"""Hamilton's n-body equation (B) as compiled kernels on plain floats.

Hamilton (1845), equation (B): each body's acceleration is the sum over the
others of ``M_j (alpha_j - alpha_i) / T(alpha_j - alpha_i)^3``.  Here ``gm[j]``
stands for Hamilton's ``M_j`` (G times the mass) and positions are rows of
``r``.  Bodies with ``gm == 0`` are massless test particles: they feel every
massive body and pull on none, so each costs O(n_massive).

Acceleration kernels share one signature, ``accel(r, v, gm, acc)``: ``r`` and
``v`` of shape (n, 3), ``gm`` of shape (n,), all float64, and ``acc`` (n, 3) is
overwritten.  Effect kernels have the same signature but *add* into ``acc``.
No astropy here.
"""

from __future__ import annotations

import math

import numpy as np
from numba import carray, njit, types
from numba.core import cgutils
from numba.extending import intrinsic

from hamilton_orbits._kernels.signatures import ACCEL_SIGNATURE

#: Massive bodies up to which the SIMD form's work space is on the stack (above,
#: it is allocated: 7 float64 a body, beside ``n^2`` pair terms, it costs nothing).
STACK_MASSIVE = 128
#: Test particles summed per block (their work space, 6 float64 each, stays in L1).
BLOCK = 128
#: float64 of the stack work space: massive x, y, z, gm, ax, ay, az; a block's 6.
SCRATCH = 7 * STACK_MASSIVE + 6 * BLOCK
#: The SIMD loops run over a multiple of this many lanes (the columns padded):
#: the widest vector (8 float64); a scalar remainder would cost as much as the
#: vector part at N = 10.
LANES = 8
#: Below this many massive bodies the pair form (pairs once) is faster than the
#: SIMD form (every pair twice, 8 at a time): measured, docs/nbody_integrators.md.
SIMD_FROM = 7


@njit(cache=True, error_model="numpy")
def massive_indices(gm):  # pragma: no cover - compiled
    """Indices of the bodies with ``gm != 0``, in order."""
    n = gm.shape[0]
    idx = np.empty(n, dtype=np.int64)
    nm = 0
    for k in range(n):
        if gm[k] != 0.0:
            idx[nm] = k
            nm += 1
    return idx[:nm]


@njit(cache=True, error_model="numpy")
def zero(r, v, gm, acc):  # pragma: no cover - compiled
    """Overwrites ``acc`` with zeros (the start of a right-hand side whose effects
    compute the point-mass interaction themselves)."""
    for k in range(acc.shape[0]):
        acc[k, 0] = 0.0
        acc[k, 1] = 0.0
        acc[k, 2] = 0.0


@intrinsic
def _stack_scratch(typingctx):  # pragma: no cover - compiled
    """A pointer to :data:`SCRATCH` float64 on the stack of the function that calls
    it (so valid until that function returns: it must not hand the memory back),
    aligned to 64 bytes (a cache line, the widest vector): the columns, multiples
    of :data:`LANES` long, then start on cache lines wherever the stack is."""

    def codegen(context, builder, signature, args):
        with builder.goto_entry_block():  # a fixed frame slot, not filled
            raw = builder.alloca(context.get_value_type(types.float64),
                                 size=cgutils.intp_t(SCRATCH + LANES))
        addr = builder.ptrtoint(raw, cgutils.intp_t)
        aligned = builder.and_(builder.add(addr, addr.type(63)), addr.type(-64))
        return builder.inttoptr(aligned, raw.type)

    return types.CPointer(types.float64)(), codegen


@njit(cache=True, inline="always", error_model="numpy")
def newtonian(r, v, gm, acc):  # pragma: no cover - compiled
    """Newtonian accelerations of equation (B); overwrites ``acc``.

    From :data:`SIMD_FROM` massive bodies on, the SIMD form (:func:`_soa_massive`);
    below, massive pairs are visited once (both accelerations from one separation).
    Both add the same terms in the same order: the results are the same to the bit.
    Test particles are summed over the massive bodies only.  With no test particle
    (the common case) and up to :data:`STACK_MASSIVE` bodies nothing is allocated:
    this runs once per force evaluation, where a small allocation costs as much as
    the 36 pairs of the solar system.
    """
    n = r.shape[0]
    for k in range(n):
        if gm[k] == 0.0:
            # test particles: never the inlined pair form of newtonian_rows
            newtonian_rows_spaced(r, gm, massive_indices(gm), 0, acc)
            return
    if n >= SIMD_FROM:
        w = (carray(_stack_scratch(), SCRATCH) if n <= STACK_MASSIVE
             else np.empty(7 * _padded(n)))
        _gather_massive(r, gm, gm, False, n, w)
        _soa_massive(n, w)
        _scatter_massive(acc, gm, False, n, w)
        return
    _pairs_all(r, gm, acc)


@njit(cache=True, inline="always", error_model="numpy")
def _pairs_all(r, gm, acc):  # pragma: no cover - compiled
    """The pair form of :func:`newtonian` for every row (all massive)."""
    n = r.shape[0]
    for k in range(n):
        acc[k, 0] = 0.0
        acc[k, 1] = 0.0
        acc[k, 2] = 0.0
    for i in range(n):  # j = i + 1 .. n - 1 (``start`` and ``idx`` unused: gm stands in)
        _massive_row(r, gm, i, acc, n, n, False, gm)


@njit(cache=True, error_model="numpy")
def _gather_massive(r, gm, idx, use_idx, nm, w):  # pragma: no cover - compiled
    """Positions and ``gm`` of the massive bodies (rows ``idx[a]``, or ``a``
    without ``use_idx``) into the columns ``w[0:4 np]`` (structure of arrays,
    ``np`` = :func:`_padded` ``(nm)``; the padding lanes at the origin)."""
    m = _padded(nm)
    for a in range(m):
        i = (int(idx[a]) if use_idx else a) if a < nm else 0
        pad = a >= nm
        w[a] = 0.0 if pad else r[i, 0]
        w[m + a] = 0.0 if pad else r[i, 1]
        w[2 * m + a] = 0.0 if pad else r[i, 2]
        w[3 * m + a] = 0.0 if pad else gm[i]


@njit(cache=True, inline="always", error_model="numpy")
def _padded(n):  # pragma: no cover - compiled
    """``n`` rounded up to a multiple of :data:`LANES`."""
    return (n + LANES - 1) // LANES * LANES


@njit(cache=True, error_model="numpy")
def _soa_massive(nm, w):  # pragma: no cover - compiled
    """The accelerations of the massive bodies that :func:`_gather_massive` put in
    ``w`` among themselves, in the SIMD form, summed in ``w[4 np:7 np]``.

    For each source ``b`` in order, every body ``a`` at once (the loop over ``a``
    is what the compiler vectorises: lanes are bodies, no sum is reordered) gets
    ``gm_b (1 / (d^2 sqrt(d^2))) d``, ``d = r_b - r_a`` (zero for ``a = b``).  Body
    ``a`` thus adds its terms in the order of the pair form, and each term is the
    pair form's to the bit: ``d`` is minus the pair's separation exactly, ``d^2``
    the same.  Every pair is computed twice, eight at a time.

    One body beyond a multiple of eight (N = 9, 17, ...) is summed by itself
    (in the same order), not as a vector of seven padding lanes: at N = 9 that
    cost 80 ns of the 220."""
    m = _padded(nm)
    x = w[0:m]
    y = w[m:2 * m]
    z = w[2 * m:3 * m]
    g = w[3 * m:4 * m]
    ax = w[4 * m:5 * m]
    ay = w[5 * m:6 * m]
    az = w[6 * m:7 * m]
    mv = nm - 1 if nm % LANES == 1 else m  # the lanes summed as vectors
    for a in range(m):
        ax[a] = 0.0
        ay[a] = 0.0
        az[a] = 0.0
    for a in range(mv, nm):
        _soa_one(a, nm, w)
    for b in range(nm):
        xb = x[b]
        yb = y[b]
        zb = z[b]
        gb = g[b]
        for a in range(mv):  # the padding lanes too (not finite, never read)
            dx = xb - x[a]
            dy = yb - y[a]
            dz = zb - z[a]
            d2 = dx * dx + dy * dy + dz * dz
            same = a == b
            d2 = 1.0 if same else d2
            inv3 = 1.0 / (d2 * np.sqrt(d2))
            f = 0.0 if same else gb * inv3
            ax[a] += f * dx
            ay[a] += f * dy
            az[a] += f * dz


@njit(cache=True, inline="always", error_model="numpy")
def _soa_one(a, nm, w):  # pragma: no cover - compiled
    """Body ``a``'s sum of :func:`_soa_massive` alone, the same terms in the same
    order (sources ``b`` ascending, ``b != a``)."""
    m = _padded(nm)
    xa = w[a]
    ya = w[m + a]
    za = w[2 * m + a]
    sx = 0.0
    sy = 0.0
    sz = 0.0
    for b in range(nm):
        if b != a:
            dx = w[b] - xa
            dy = w[m + b] - ya
            dz = w[2 * m + b] - za
            d2 = dx * dx + dy * dy + dz * dz
            f = w[3 * m + b] * (1.0 / (d2 * np.sqrt(d2)))
            sx += f * dx
            sy += f * dy
            sz += f * dz
    w[4 * m + a] = sx
    w[5 * m + a] = sy
    w[6 * m + a] = sz


@njit(cache=True, error_model="numpy")
def newtonian_semi_active(r, v, gm, acc, p):  # pragma: no cover - compiled
    """Newton's law with semi-active bodies, ADDED to ``acc``: ``p`` the indices of
    the bodies that pull on every other body and feel every other body, but not
    each other (the ``semi_active`` effect, which replaces the Newtonian kernel).

    The SIMD form of :func:`_soa_massive` with the active bodies first
    (:func:`_soa_semi`): a semi-active source's loop stops after the active
    bodies' lanes, so the pairs of two semi-active bodies are never computed."""
    n = r.shape[0]
    m = _padded(n)
    # (the columns, then the bodies' order: the active bodies, then the semi-active,
    # each in order; then which are semi-active: one scratch, on the stack up to
    # STACK_MASSIVE bodies)
    w = (carray(_stack_scratch(), SCRATCH) if n <= STACK_MASSIVE
         else np.empty(7 * m + 2 * n))
    idx = w[7 * m:7 * m + n]
    semi = w[7 * m + n:7 * m + 2 * n]
    for i in range(n):
        semi[i] = 0.0
    for b in range(p.shape[0]):
        semi[int(p[b])] = 1.0
    na = 0
    for i in range(n):
        if semi[i] == 0.0:
            idx[na] = i
            na += 1
    k = na
    for i in range(n):
        if semi[i] != 0.0:
            idx[k] = i
            k += 1
    _gather_massive(r, gm, idx, True, n, w)
    _soa_semi(n, na, w)
    for a in range(n):
        i = int(idx[a])
        acc[i, 0] += w[4 * m + a]
        acc[i, 1] += w[5 * m + a]
        acc[i, 2] += w[6 * m + a]


@njit(cache=True, error_model="numpy")
def _soa_semi(nm, na, w):  # pragma: no cover - compiled
    """:func:`_soa_massive` for bodies of which the first ``na`` are active and the
    others semi-active: an active source pulls on every lane, a semi-active one on
    the active bodies' lanes alone (the lanes of semi-active bodies among them
    masked)."""
    m = _padded(nm)
    x = w[0:m]
    y = w[m:2 * m]
    z = w[2 * m:3 * m]
    g = w[3 * m:4 * m]
    ax = w[4 * m:5 * m]
    ay = w[5 * m:6 * m]
    az = w[6 * m:7 * m]
    for a in range(m):
        ax[a] = 0.0
        ay[a] = 0.0
        az[a] = 0.0
    for b in range(na):  # an active source: every lane (the padding too: never read)
        xb = x[b]
        yb = y[b]
        zb = z[b]
        gb = g[b]
        for a in range(m):
            dx = xb - x[a]
            dy = yb - y[a]
            dz = zb - z[a]
            d2 = dx * dx + dy * dy + dz * dz
            same = a == b
            d2 = 1.0 if same else d2
            inv3 = 1.0 / (d2 * np.sqrt(d2))
            f = 0.0 if same else gb * inv3
            ax[a] += f * dx
            ay[a] += f * dy
            az[a] += f * dz
    ma = min(_padded(na), m)
    for b in range(na, nm):  # a semi-active source: the active bodies' lanes
        xb = x[b]
        yb = y[b]
        zb = z[b]
        gb = g[b]
        for a in range(ma):
            dx = xb - x[a]
            dy = yb - y[a]
            dz = zb - z[a]
            d2 = dx * dx + dy * dy + dz * dz
            off = a >= na  # (a semi-active body's lane, b's own among them)
            d2 = 1.0 if off else d2
            inv3 = 1.0 / (d2 * np.sqrt(d2))
            f = 0.0 if off else gb * inv3
            ax[a] += f * dx
            ay[a] += f * dy
            az[a] += f * dz


@njit(cache=True, inline="always", error_model="numpy")
def _scatter_massive(acc, idx, use_idx, nm, w):  # pragma: no cover - compiled
    """``acc[idx[a]] = `` the accelerations that :func:`_soa_massive` left in ``w``."""
    m = _padded(nm)
    for a in range(nm):
        i = int(idx[a]) if use_idx else a
        acc[i, 0] = w[4 * m + a]
        acc[i, 1] = w[5 * m + a]
        acc[i, 2] = w[6 * m + a]


@njit(cache=True, error_model="numpy")
def _soa_block(r, k0, k1, nm, w):  # pragma: no cover - compiled
    """The accelerations of rows ``k0 .. k1 - 1`` (at most :data:`BLOCK`) from the
    massive bodies that :func:`_gather_massive` copied into ``w``, into
    ``w[7 np + (3 + c) BLOCK + t]`` for row ``k0 + t``, component ``c``
    (``np`` = :func:`_padded` ``(nm)``).

    Vectorised over the rows (lanes are particles): each adds the massive bodies'
    ``gm_a / (d^2 sqrt(d^2)) d`` in order from zero, as the scalar loop does.  A
    massive row in the block is computed too (against itself: not finite) and
    must be ignored."""
    o = 7 * _padded(nm)
    m = _padded(k1 - k0)  # the padding lanes at the origin, never read
    x = w[o:o + m]
    y = w[o + BLOCK:o + BLOCK + m]
    z = w[o + 2 * BLOCK:o + 2 * BLOCK + m]
    ax = w[o + 3 * BLOCK:o + 3 * BLOCK + m]
    ay = w[o + 4 * BLOCK:o + 4 * BLOCK + m]
    az = w[o + 5 * BLOCK:o + 5 * BLOCK + m]
    for t in range(m):
        pad = k0 + t >= k1
        x[t] = 0.0 if pad else r[k0 + t, 0]
        y[t] = 0.0 if pad else r[k0 + t, 1]
        z[t] = 0.0 if pad else r[k0 + t, 2]
        ax[t] = 0.0
        ay[t] = 0.0
        az[t] = 0.0
    mm = _padded(nm)
    for a in range(nm):
        xa = w[a]
        ya = w[mm + a]
        za = w[2 * mm + a]
        ga = w[3 * mm + a]
        for t in range(m):
            dx = xa - x[t]
            dy = ya - y[t]
            dz = za - z[t]
            d2 = dx * dx + dy * dy + dz * dz
            f = ga / (d2 * np.sqrt(d2))
            ax[t] += f * dx
            ay[t] += f * dy
            az[t] += f * dz


@njit(inline="always", cache=True, error_model="numpy")
def _massive_row(r, gm, i, acc, start, nm, use_idx, idx):  # pragma: no cover - compiled
    """Body ``i`` against the massive bodies after it: ``j = idx[b]`` for ``b`` in
    ``(start, nm)`` (``use_idx``), else ``j = b`` from ``i + 1``.  Body ``i``'s sum
    is kept in registers (``j != i``: the compiler cannot know that ``acc[i]`` and
    ``acc[j]`` differ and would store and reload it every pair); the same
    additions in the same order on both paths."""
    xi = r[i, 0]
    yi = r[i, 1]
    zi = r[i, 2]
    gi = gm[i]
    ax = acc[i, 0]
    ay = acc[i, 1]
    az = acc[i, 2]
    first = start if use_idx else i + 1
    for b in range(first, nm):
        j = int(idx[b]) if use_idx else b
        dx = r[j, 0] - xi
        dy = r[j, 1] - yi
        dz = r[j, 2] - zi
        d2 = dx * dx + dy * dy + dz * dz
        inv3 = 1.0 / (d2 * np.sqrt(d2))
        fi = gm[j] * inv3
        fj = gi * inv3
        ax += fi * dx
        ay += fi * dy
        az += fi * dz
        acc[j, 0] -= fj * dx
        acc[j, 1] -= fj * dy
        acc[j, 2] -= fj * dz
    acc[i, 0] = ax
    acc[i, 1] = ay
    acc[i, 2] = az


@njit(cache=True, inline="always", error_model="numpy")
def newtonian_rows(r, gm, idx, first, acc):  # pragma: no cover - compiled
    """:func:`newtonian` with the massive indices ``idx`` given (so that a
    stepper computes them once, not every step) and the rows below ``first``
    left out (their ``acc`` is not written; ``idx`` must hold every massive row
    from ``first`` on, and no other).  The same arithmetic in the same order as
    :func:`newtonian`; test particles are summed :data:`BLOCK` at a time
    (:func:`_soa_block`).  A few massive bodies and no test particle: the pair
    form inlined into the caller (as :func:`kick_rows`)."""
    nm = idx.shape[0]
    if nm < SIMD_FROM and nm == r.shape[0] - first:
        pairs_rows(r, gm, idx, acc)
    else:
        newtonian_rows_spaced(r, gm, idx, first, acc)


@njit(cache=True, error_model="numpy")
def newtonian_rows_spaced(r, gm, idx, first, acc):  # pragma: no cover - compiled
    """:func:`newtonian_rows` with its work space (SIMD columns, test-particle blocks)."""
    n = r.shape[0]
    nm = idx.shape[0]
    w = (carray(_stack_scratch(), SCRATCH) if nm <= STACK_MASSIVE
         else np.empty(7 * _padded(nm) + 6 * BLOCK))
    _massive_rows(r, gm, idx, acc, w)
    if nm == n - first:
        return
    _test_blocks(r, gm, first, nm, w, acc)


@njit(cache=True, error_model="numpy")
def massless_rows(r, gm, first, acc):  # pragma: no cover - compiled
    """The test particles' rows (``gm == 0``, from ``first`` on) of :func:`newtonian`
    alone, the same to the bit; every other row of ``acc`` left alone.  For a field
    of many bodies that pull on each other but whose own accelerations are not
    wanted (perturbers read from an ephemeris): the massive pairs are not summed."""
    idx = massive_indices(gm)
    nm = idx.shape[0]
    w = (carray(_stack_scratch(), SCRATCH) if nm <= STACK_MASSIVE
         else np.empty(7 * _padded(nm) + 6 * BLOCK))
    _gather_massive(r, gm, idx, True, nm, w)
    _test_blocks(r, gm, first, nm, w, acc)


@njit(cache=True, inline="always", error_model="numpy")
def _test_blocks(r, gm, first, nm, w, acc):  # pragma: no cover - compiled
    """The test particles' rows from ``first`` on, :data:`BLOCK` at a time
    (:func:`_soa_block`), from the ``nm`` massive bodies gathered in ``w``."""
    n = r.shape[0]
    o = 7 * _padded(nm) + 3 * BLOCK
    for k0 in range(first, n, BLOCK):
        k1 = min(k0 + BLOCK, n)
        _soa_block(r, k0, k1, nm, w)
        for k in range(k0, k1):
            if gm[k] == 0.0:
                acc[k, 0] = w[o + k - k0]
                acc[k, 1] = w[o + BLOCK + k - k0]
                acc[k, 2] = w[o + 2 * BLOCK + k - k0]


@njit(cache=True, inline="always", error_model="numpy")
def _massive_rows(r, gm, idx, acc, w):  # pragma: no cover - compiled
    """``acc[idx[a]]``: the massive bodies' accelerations among themselves, in the
    SIMD form from :data:`SIMD_FROM` of them on, else in the pair form (the same
    to the bit); their positions and ``gm`` left in ``w`` either way."""
    nm = idx.shape[0]
    _gather_massive(r, gm, idx, True, nm, w)
    if nm >= SIMD_FROM:
        _soa_massive(nm, w)
        _scatter_massive(acc, idx, True, nm, w)
        return
    pairs_rows(r, gm, idx, acc)


@njit(cache=True, error_model="numpy")
def pairs_rows(r, gm, idx, acc):  # pragma: no cover - compiled
    """``acc[idx[a]]`` in the pair form (each massive pair visited once)."""
    nm = idx.shape[0]
    for a in range(nm):
        acc[idx[a], 0] = 0.0
        acc[idx[a], 1] = 0.0
        acc[idx[a], 2] = 0.0
    for a in range(nm):
        _massive_row(r, gm, idx[a], acc, a + 1, nm, True, idx)


@njit(cache=True, inline="always", error_model="numpy")
def kick_rows(r, gm, idx, first, h, u, acc_m):  # pragma: no cover - compiled
    """``u[k] += h a_k`` for the rows ``k >= first``, ``a`` the Newtonian
    accelerations of :func:`newtonian_rows` (the same arithmetic in the same
    order): the massive rows ``idx`` summed in ``acc_m`` (len(idx), 3), the test
    particles :data:`BLOCK` at a time, each block kicked as soon as it is summed,
    so that no (n, 3) array is needed (a third of the working memory of a
    Wisdom-Holman run of test particles).

    A few massive bodies (below :data:`SIMD_FROM`) and no test particle: the
    pairs inlined into the caller's step loop, without the work space (the call
    and its setup cost as much as the one pair of N = 3); otherwise
    :func:`kick_rows_spaced`."""
    nm = idx.shape[0]
    if nm < SIMD_FROM and nm == r.shape[0] - first:
        compact_pairs(r, gm, idx, acc_m)
        kick_massive(u, idx, h, acc_m)
    else:
        kick_rows_spaced(r, gm, idx, first, h, u, acc_m)


@njit(cache=True, error_model="numpy")
def kick_rows_spaced(r, gm, idx, first, h, u, acc_m):  # pragma: no cover - compiled
    """:func:`kick_rows` with its work space (SIMD columns, test-particle blocks)."""
    n = r.shape[0]
    nm = idx.shape[0]
    w = (carray(_stack_scratch(), SCRATCH) if nm <= STACK_MASSIVE
         else np.empty(7 * _padded(nm) + 6 * BLOCK))
    _gather_massive(r, gm, idx, True, nm, w)
    if nm >= SIMD_FROM:
        _soa_massive(nm, w)
        _scatter_massive(acc_m, idx, False, nm, w)
    else:
        compact_pairs(r, gm, idx, acc_m)
    kick_massive(u, idx, h, acc_m)
    if nm == n - first:
        return
    o = 7 * _padded(nm) + 3 * BLOCK
    for k0 in range(first, n, BLOCK):
        k1 = min(k0 + BLOCK, n)
        _soa_block(r, k0, k1, nm, w)
        for k in range(k0, k1):
            if gm[k] == 0.0:
                u[k, 0] += h * w[o + k - k0]
                u[k, 1] += h * w[o + BLOCK + k - k0]
                u[k, 2] += h * w[o + 2 * BLOCK + k - k0]


@njit(cache=True, inline="always", error_model="numpy")
def kick_massive(u, idx, h, acc_m):  # pragma: no cover - compiled
    """``u[idx[a]] += h acc_m[a]``."""
    for a in range(idx.shape[0]):
        i = idx[a]
        u[i, 0] += h * acc_m[a, 0]
        u[i, 1] += h * acc_m[a, 1]
        u[i, 2] += h * acc_m[a, 2]


@njit(cache=True, inline="always", error_model="numpy")
def compact_pairs(r, gm, idx, acc_m):  # pragma: no cover - compiled
    """The pair form of :func:`_massive_row` into ``acc_m[a]`` for body ``idx[a]``."""
    nm = idx.shape[0]
    for a in range(nm):
        acc_m[a, 0] = 0.0
        acc_m[a, 1] = 0.0
        acc_m[a, 2] = 0.0
    for a in range(nm):
        i = idx[a]
        xi = r[i, 0]
        yi = r[i, 1]
        zi = r[i, 2]
        gi = gm[i]
        ax = acc_m[a, 0]
        ay = acc_m[a, 1]
        az = acc_m[a, 2]
        for b in range(a + 1, nm):
            j = idx[b]
            dx = r[j, 0] - xi
            dy = r[j, 1] - yi
            dz = r[j, 2] - zi
            d2 = dx * dx + dy * dy + dz * dz
            inv3 = 1.0 / (d2 * np.sqrt(d2))
            fi = gm[j] * inv3
            fj = gi * inv3
            ax += fi * dx
            ay += fi * dy
            az += fi * dz
            acc_m[b, 0] -= fj * dx
            acc_m[b, 1] -= fj * dy
            acc_m[b, 2] -= fj * dz
        acc_m[a, 0] = ax
        acc_m[a, 1] = ay
        acc_m[a, 2] = az


# ---------------------------------------------------------------------------
# Effect kernels: ``f(r, v, gm, acc, p)`` ADD their acceleration into ``acc``.
# ``p`` is a float64 parameter vector whose layout each builder in
# :mod:`hamilton_orbits.effects` documents.


@njit(inline="always", cache=True, error_model="numpy")
def _push_pair(acc, i, s, ax, ay, az, back):  # pragma: no cover - compiled
    """Add ``a`` to body ``i`` and the reaction ``-back * a`` to the source ``s``."""
    acc[i, 0] += ax
    acc[i, 1] += ay
    acc[i, 2] += az
    acc[s, 0] -= back * ax
    acc[s, 1] -= back * ay
    acc[s, 2] -= back * az


@njit(cache=True, error_model="numpy")
def gr_anderson(r, v, gm, acc, p):  # pragma: no cover - compiled
    """First post-Newtonian correction from one dominant body (one-body metric).

    ``p = [source, c]``.  For every other body, with ``d``, ``w`` its position and
    velocity relative to the source and ``mu = gm[source]``,

        a = mu / (c^2 |d|^3) [ (4 mu / |d| - w^2) d + 4 (d . w) w ],

    the test-particle limit of the Einstein-Infeld-Hoffmann equations in harmonic
    coordinates that Anderson et al. (1975) use for planetary ephemerides; the
    source receives ``-(gm_i / mu) a`` so that the momentum stays conserved.
    """
    s = int(p[0])
    c2 = p[1] * p[1]
    mu = gm[s]
    n = r.shape[0]
    for i in range(n):
        if i == s:
            continue
        dx = r[i, 0] - r[s, 0]
        dy = r[i, 1] - r[s, 1]
        dz = r[i, 2] - r[s, 2]
        wx = v[i, 0] - v[s, 0]
        wy = v[i, 1] - v[s, 1]
        wz = v[i, 2] - v[s, 2]
        d2 = dx * dx + dy * dy + dz * dz
        d = np.sqrt(d2)
        w2 = wx * wx + wy * wy + wz * wz
        dw = dx * wx + dy * wy + dz * wz
        f = mu / (c2 * d2 * d)
        fr = f * (4.0 * mu / d - w2)
        fv = f * 4.0 * dw
        _push_pair(acc, i, s, fr * dx + fv * wx, fr * dy + fv * wy, fr * dz + fv * wz,
                   gm[i] / mu)


@njit(cache=True, error_model="numpy")
def gr_potential(r, v, gm, acc, p):  # pragma: no cover - compiled
    """Nobili & Roxburgh (1986) potential ``Phi = -3 (mu / (c |d|))^2`` of one body.

    ``p = [source, c]``.  The force ``-grad Phi = -6 mu^2 d / (c^2 |d|^4)`` reproduces
    the relativistic perihelion advance and depends on positions only.
    """
    s = int(p[0])
    c2 = p[1] * p[1]
    mu = gm[s]
    n = r.shape[0]
    for i in range(n):
        if i == s:
            continue
        dx = r[i, 0] - r[s, 0]
        dy = r[i, 1] - r[s, 1]
        dz = r[i, 2] - r[s, 2]
        d2 = dx * dx + dy * dy + dz * dz
        f = -6.0 * mu * mu / (c2 * d2 * d2)
        _push_pair(acc, i, s, f * dx, f * dy, f * dz, gm[i] / mu)


@njit(cache=True, error_model="numpy")
def j2_field(r, v, gm, acc, p):  # pragma: no cover - compiled
    """The J2 (oblateness) field of one body about its pole, on every other body.

    ``p = [body, j2, radius, kx, ky, kz]`` with ``k`` the unit pole.  With ``d`` the
    position relative to the body, ``z = d . k`` and ``mu = gm[body]``,

        a = -(3/2) J2 mu R^2 / |d|^5 [ (1 - 5 z^2 / |d|^2) d + 2 z k ],

    the gradient of the degree-2 zonal potential (Vallado 2013, eq. 8-22 in the
    body's own frame); the body receives ``-(gm_i / mu) a``.
    """
    b = int(p[0])
    j2 = p[1]
    rad2 = p[2] * p[2]
    kx = p[3]
    ky = p[4]
    kz = p[5]
    mu = gm[b]
    n = r.shape[0]
    for i in range(n):
        if i == b:
            continue
        dx = r[i, 0] - r[b, 0]
        dy = r[i, 1] - r[b, 1]
        dz = r[i, 2] - r[b, 2]
        d2 = dx * dx + dy * dy + dz * dz
        d = np.sqrt(d2)
        z = dx * kx + dy * ky + dz * kz
        f = -1.5 * j2 * mu * rad2 / (d2 * d2 * d)
        g = 1.0 - 5.0 * z * z / d2
        _push_pair(acc, i, b, f * (g * dx + 2.0 * z * kx), f * (g * dy + 2.0 * z * ky),
                   f * (g * dz + 2.0 * z * kz), gm[i] / mu)


@njit(cache=True, error_model="numpy")
def min_pair_time(r, gm):  # pragma: no cover - compiled
    """min over pairs (i massive, j != i) of sqrt(d^3 / (gm_i + gm_j)); O(n n_massive)."""
    n = r.shape[0]
    best = math.inf
    for i in range(n):
        if gm[i] == 0.0:
            continue
        for j in range(n):
            if j == i or (gm[j] != 0.0 and j < i):
                continue
            dx = r[j, 0] - r[i, 0]
            dy = r[j, 1] - r[i, 1]
            dz = r[j, 2] - r[i, 2]
            d2 = dx * dx + dy * dy + dz * dz
            if d2 > 0.0:
                t2 = d2 * math.sqrt(d2) / (gm[i] + gm[j])
                if t2 < best:
                    best = t2
    return math.sqrt(best)


@njit(cache=True, error_model="numpy")
def closest_pair(r, gm):  # pragma: no cover - compiled
    """``(d2, i, j)``: the smallest squared separation over pairs with a massive
    member, and the pair (``i < j``); ``(inf, -1, -1)`` without such a pair."""
    n = r.shape[0]
    best = math.inf
    bi = -1
    bj = -1
    for i in range(n):
        if gm[i] == 0.0:
            continue
        for j in range(n):
            if j == i or (gm[j] != 0.0 and j < i):
                continue
            dx = r[j, 0] - r[i, 0]
            dy = r[j, 1] - r[i, 1]
            dz = r[j, 2] - r[i, 2]
            d2 = dx * dx + dy * dy + dz * dz
            if d2 < best:
                best = d2
                bi = min(i, j)
                bj = max(i, j)
    return best, bi, bj


# compiled when first asked for (``integrators._setup.addresses``): a run whose
# method does not evaluate the right-hand side (wh) does not compile it
@njit(cache=True, error_model="numpy")
def newtonian_only(r, v, gm, acc, p):  # pragma: no cover - compiled
    """The right-hand side with no effect listed: :func:`newtonian` (``p`` unused)."""
    newtonian(r, v, gm, acc)


@njit(cache=True, error_model="numpy")
def newtonian_few(r, v, gm, acc, p):  # pragma: no cover - compiled
    """:func:`newtonian_only` for fewer than :data:`SIMD_FROM` bodies, all massive: the
    pair form alone, which is what :func:`newtonian` computes for them (the same
    bits), so that a run of a few bodies compiles neither the SIMD form nor the
    test particles' (``integrators._setup.force_arg`` chooses it)."""
    _pairs_all(r, gm, acc)


@njit(ACCEL_SIGNATURE, cache=True, error_model="numpy")
def no_effects(r, v, gm, acc, p):  # pragma: no cover - compiled
    """The effects part of a right-hand side with no effect listed: adds nothing."""
    return
