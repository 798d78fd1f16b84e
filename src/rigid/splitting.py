"""The Lie-Poisson splittings of the free rigid body: which exact flows, in which order.

A step of ``"splitting2"``, ``"splitting4"`` or ``"splitting4y"`` (see
:mod:`rigid.integrators` for what each is and does) is a list of exact flows, each a
rotation of the body angular momentum and of the attitude about one principal axis, the
torque kick or the Casimir flow; :func:`split_ops` writes it down as the arrays that
the compiled loop :func:`rigid._kernels.euler.run_splitting` runs (op types 0-2 the
principal axes, 3 the kick, 4 the Casimir flow).  The compositions:

* Strang: ``S2(h) = K(h/2) R1(h/2) R2(h/2) R3(h) R2(h/2) R1(h/2) K(h/2)`` (McLachlan
  1993, Phys. Rev. Lett. 71, 3043; Touma & Wisdom 1994, AJ 107, 1189);
* Yoshida's (1990) triple jump of it, :data:`YOSHIDA_W`;
* Blanes & Moan's (2002) S6, :data:`BM_A`, :data:`BM_B`, in its Lie-Trotter/adjoint
  form on the split about the middle moment.

Neighbouring flows of one part commute and are fused (also across steps).  Plain
Python on a few numbers, computed once per run.
"""

from __future__ import annotations

import numpy as np

__all__ = ["BM_A", "BM_B", "SPLITTINGS", "YOSHIDA_W", "split_ops"]

#: the methods of :func:`rigid.integrate` that are splittings
SPLITTINGS = ("splitting2", "splitting4", "splitting4y")

# Yoshida (1990, Phys. Lett. A 150, 262, eq. 5.4) triple jump: a symmetric
# second-order map S2 composed as S2(w1 h) S2(w0 h) S2(w1 h) is of order four.
_CBRT2 = 2.0 ** (1.0 / 3.0)
YOSHIDA_W = (1.0 / (2.0 - _CBRT2), -_CBRT2 / (2.0 - _CBRT2), 1.0 / (2.0 - _CBRT2))

# Blanes & Moan (2002), J. Comput. Appl. Math. 142, 313-330, Table 2, method
# S6 (order 4, 6 stages, symmetric): for H = A + B,
#   e^{a1 A} e^{b1 B} e^{a2 A} e^{b2 B} e^{a3 A} e^{b3 B} e^{a4 A} e^{b3 B} ... e^{a1 A},
# a4 = 1 - 2 (a1 + a2 + a3), b3 = 1/2 - (b1 + b2).
BM_A = (0.0792036964311957, 0.353172906049774, -0.0420650803577195)
BM_B = (0.209515106613362, -0.143851773179818)
_BM_A = (*BM_A, 1.0 - 2.0 * sum(BM_A), *BM_A[::-1])
_BM_B = (*BM_B, 0.5 - sum(BM_B), 0.5 - sum(BM_B), *BM_B[::-1])


def _bm_lie_coefficients() -> tuple[tuple[float, ...], tuple[float, ...]]:
    """S6 as a composition Phi*_{d6} Phi_{c6} ... Phi*_{d1} Phi_{c1} (c_i, d_i).

    With Phi_c = e^{cB} e^{cA} (A first) and Phi*_d = e^{dA} e^{dB} its adjoint,
    the product runs A(c1) B(c1 + d1) A(d1 + c2) ... B(c6 + d6) A(d6): so
    c1 = a1, d_i = b_i - c_i, c_{i+1} = a_{i+1} - d_i (McLachlan 1995, SIAM J.
    Sci. Comput. 16, 151; Hairer, Lubich & Wanner, GNI, sec. III.5).  With Phi
    the Lie-Trotter product of *any* number of exact flows, this composition is
    of order 4 (its order conditions coincide with those of the two-part
    splitting up to order 4; checked by the halving tests).
    """
    c: list[float] = []
    d: list[float] = []
    prev = 0.0
    for a, b in zip(_BM_A[:6], _BM_B, strict=True):
        c.append(a - prev)
        d.append(b - c[-1])
        prev = d[-1]
    return tuple(c), tuple(d)


_BM_C, _BM_D = _bm_lie_coefficients()

_KICK = 3
_CASIMIR = 4


def _strang(w: float, torqued: bool) -> list[tuple[int, float]]:
    """S2(w h) = K(w/2) R1(w/2) R2(w/2) R3(w) R2(w/2) R1(w/2) K(w/2)."""
    ops = [(0, 0.5 * w), (1, 0.5 * w), (2, w), (1, 0.5 * w), (0, 0.5 * w)]
    return [(_KICK, 0.5 * w), *ops, (_KICK, 0.5 * w)] if torqued else ops


def split_ops(
    method: str, moments: np.ndarray, torqued: bool
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(types, fractions of h, time offsets in h, inverse moments) of one step.

    Types 0-2 are principal-axis rotations, 3 a torque kick, 4 the Casimir flow
    (see :func:`rigid._kernels.euler.run_splitting`).
    """
    inv = np.concatenate([1.0 / moments, [0.0, 0.0]])  # axes 0-2, (kick), Casimir
    # Time (for time-dependent torques) is carried by one part: the one with the
    # full step in the Strang splitting, the Casimir flow in "splitting4".
    time_part = 2
    if method == "splitting2":
        ops = _strang(1.0, torqued)
    elif method == "splitting4y":
        ops = [op for w in YOSHIDA_W for op in _strang(w, torqued)]
    elif method == "splitting4":
        # T = |L|^2 / (2 I_m) + sum over the two other axes of (1/I_k - 1/I_m) L_k^2 / 2,
        # I_m the middle moment: the Casimir part commutes with everything (free
        # body) and the two axis parts are smaller than 1/I_k.  S6 of Blanes &
        # Moan on the two axis parts, in its Lie-Trotter/adjoint form; with a
        # torque the Lie-Trotter product is kick, axis, Casimir, axis.
        ref = int(np.argsort(moments, kind="stable")[1])
        inv[:3] -= 1.0 / moments[ref]
        inv[_CASIMIR] = 1.0 / moments[ref]
        ax = [k for k in range(3) if k != ref]
        parts = [_KICK, ax[0], _CASIMIR, ax[1]] if torqued else ax
        ops = []
        for c, d in zip(_BM_C, _BM_D, strict=True):
            ops += [(p, c) for p in parts]  # Phi_c
            ops += [(p, d) for p in parts[::-1]]  # Phi*_d
        if not torqued:  # the Casimir flow commutes: one per step
            ops.insert(len(ops) // 2, (_CASIMIR, 1.0))
        time_part = _CASIMIR
    else:  # pragma: no cover - guarded by the callers
        raise ValueError(method)
    fused: list[list[float]] = []
    for typ, fr in ops:  # flows of the same part commute: fuse neighbours
        if fused and fused[-1][0] == typ:
            fused[-1][1] += fr
        else:
            fused.append([typ, fr])
    types = np.array([int(t) for t, _ in fused], dtype=np.int64)
    fracs = np.array([fr for _, fr in fused])
    toffs = np.concatenate([[0.0], np.cumsum(np.where(types == time_part, fracs, 0.0))[:-1]])
    return types, fracs, toffs, inv

