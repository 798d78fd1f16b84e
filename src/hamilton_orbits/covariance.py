"""Covariance of the bodies' states mapped through the state transition matrix.

To first order in a small deviation ``d(r, v)(0)`` of the initial state, the
deviation at time ``t`` is ``Phi(t) d(r, v)(0)``, ``Phi`` the state transition
matrix of the variational equations (``Trajectory.stm``); an initial
covariance ``C0`` of the state is therefore carried to ``Phi(t) C0 Phi(t)^T``
(the linear covariance propagation of orbit determination: e.g. Montenbruck &
Gill, *Satellite Orbits*, 2000, sec. 7.2.1, eq. 7.28; Milani & Gronchi, *Theory
of Orbit Determination*, 2010, sec. 5.2).  The bodies' initial errors are taken
independent of each other (a block-diagonal ``C0``); each body's 6 x 6 block at
``t`` sums what every body's initial error contributes to it through the
gravitational coupling.

Examples
--------
>>> import numpy as np
>>> phi = np.tile(np.eye(6), (2, 1, 1))          # no motion: Phi = 1 at both times
>>> phi[1, 0, 3] = 10.0                          # x(t) = x0 + 10 vx0
>>> c0 = np.diag([1e-12, 0, 0, 1e-16, 0, 0])
>>> c = propagate(phi, c0, 1)
>>> c.shape, float(c[1, 0, 0, 0])                # 1e-12 + 10**2 1e-16
((2, 1, 6, 6), 1.01e-12)
"""

from __future__ import annotations

from typing import Any

import numpy as np

from hamilton_orbits.validation import as_float_array, first_index, fmt_index

__all__ = ["propagate"]


def propagate(stm: np.ndarray, cov0: Any, n: int) -> np.ndarray:
    """Each body's covariance of ``(x, y, z, vx, vy, vz)`` at every output time.

    Parameters
    ----------
    stm : ndarray, shape (n_t, 6n, 6n)
        The state transition matrix at each output time, coordinates body by body.
    cov0 : array_like, shape (6, 6) or (n, 6, 6)
        The initial covariance of every body's state (the same for each), or one
        per body, symmetric and positive semi-definite, in the units of the
        state (au and au/day for a Quantity system); the bodies' errors are
        independent of each other.
    n : int
        The number of bodies.

    Returns
    -------
    ndarray, shape (n_t, n, 6, 6)
        ``C_i(t) = sum_j Phi_ij(t) C0_j Phi_ij(t)^T``, symmetrised.

    Raises
    ------
    ValueError
        For a ``cov0`` of another shape, not finite, not symmetric or not positive
        semi-definite, naming the index (in ``cov0``'s own shape) and the value; an
        ``stm`` not of shape ``(n_t, 6n, 6n)`` or not finite (naming the index and
        the value: a NaN went through to the covariances), or ``n`` not a number of
        bodies.
    """
    if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 1:
        raise ValueError(f"Expected `n` to be a number of bodies >= 1, got {n!r}")
    c0 = _checked(cov0, n)
    phi = as_float_array("stm", stm, finite=False)
    if phi.ndim != 3 or phi.shape[1:] != (6 * n, 6 * n):
        raise ValueError(f"Expected `stm` of shape (n_t, {6 * n}, {6 * n}) for n = {n} bodies, "
                         f"got {phi.shape}")
    bad = ~np.isfinite(phi)
    if bad.any():
        at = first_index(bad)
        raise ValueError(f"Expected `stm` finite, got {float(phi[at])!r}{fmt_index(at)}")
    phi = phi.reshape(phi.shape[0], n, 6, n, 6)
    out = np.einsum("tiajb,jbc,tidjc->tiad", phi, c0, phi, optimize=True)
    return 0.5 * (out + np.swapaxes(out, -1, -2))


def _checked(cov0: Any, n: int) -> np.ndarray:
    """``cov0`` as (n, 6, 6) floats, checked."""
    if hasattr(cov0, "unit"):
        raise ValueError("Expected `cov0` as floats in the state's units (au and au/day "
                         "for a Quantity system): its blocks mix units, got a Quantity")
    c0 = as_float_array("cov0", cov0, finite=False)  # (numbers, named; finite below)
    if c0.shape != (6, 6) and c0.shape != (n, 6, 6):
        raise ValueError(f"Expected `cov0` of shape (6, 6) or ({n}, 6, 6), got {c0.shape}")
    _check_covariances(c0[None] if c0.ndim == 2 else c0, shared=c0.ndim == 2)
    return np.broadcast_to(c0, (n, 6, 6)) if c0.ndim == 2 else c0


#: Rounding allowed in the checks of a covariance, relative to its standard deviations
COV_TOL = 1e-12


def _check_covariances(c0: np.ndarray, shared: bool = False) -> None:
    """Refuse covariances ``c0`` (n, 6, 6) that are not finite, not symmetric or not
    positive semi-definite, free of their units: a variance below 0, two transposed
    entries apart by more than :data:`COV_TOL` of ``sigma_j sigma_k``, or the
    correlation matrix ``D^-1/2 C D^-1/2`` (``D`` the variances) with an eigenvalue
    below ``-COV_TOL`` (a variance of 0 with a covariance beside it included), naming
    the index and the value (``shared``: ``c0`` is the caller's one (6, 6) matrix,
    its indices named without the first: they said (0, 3, 3) for its (3, 3)).  A
    test against the largest entry (au^2 beside (au/day)^2, 1e8 times smaller) let
    negative velocity variances through."""
    def at(index: tuple[int, ...]) -> tuple[int, ...]:
        return index[1:] if shared else index

    bad = ~np.isfinite(c0)
    if bad.any():
        where = first_index(bad)
        raise ValueError(f"Expected `cov0` finite, got {float(c0[where])!r}"
                         f"{fmt_index(at(where))}")
    var = np.diagonal(c0, axis1=1, axis2=2)  # (n, 6)
    if (var < 0).any():
        b, j = first_index(var < 0)
        raise ValueError(f"Expected `cov0`'s variances >= 0, got {float(var[b, j])!r}"
                         f"{fmt_index(at((b, j, j)))}")
    sig = np.sqrt(var)
    bound = COV_TOL * sig[:, :, None] * sig[:, None, :]
    asym = np.abs(c0 - np.swapaxes(c0, 1, 2)) > bound
    if asym.any():
        i, j, k = first_index(asym)
        raise ValueError(f"Expected `cov0` symmetric, got {float(c0[i, j, k])!r} and "
                         f"{float(c0[i, k, j])!r} at indices {at((i, j, k))} and "
                         f"{at((i, k, j))}")
    unit = np.where(sig > 0, sig, 1.0)
    corr = 0.5 * (c0 + np.swapaxes(c0, 1, 2)) / (unit[:, :, None] * unit[:, None, :])
    low = np.linalg.eigvalsh(corr)[:, 0]
    if (low < -COV_TOL).any():
        i = int(np.argmax(low < -COV_TOL))
        whose = "every body's (`cov0`)" if shared else f"body {i} (`cov0[{i}]`)"
        raise ValueError(f"Expected `cov0` positive semi-definite, got its correlation "
                         f"matrix's eigenvalue {low[i]:.3g} for {whose}")

