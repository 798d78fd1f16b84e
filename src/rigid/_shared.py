"""Helpers shared by the modules of ``rigid`` (public-looking names, not public API).

Everything here works on plain floats (SI for the rigid body, days for the pole):

* :func:`pow2`: an exact power-of-two scale, so that homogeneous problems run
  on numbers of order one (no over- or underflow inside the kernels);
* :func:`free_flow_scaled`: the exact torque-free kernel on such a scaled
  problem (used by :mod:`rigid.free` and :mod:`rigid.poinsot`);
* :func:`positive_scalar`: the check of a positive scalar parameter (used by
  :mod:`rigid.earth.liouville` and :mod:`rigid.earth.wobble_fit`).

Nothing here imports another ``rigid`` module but the kernels, so every module
of the package may import it without an import circle.
"""

from __future__ import annotations

import math

import numpy as np

from rigid._kernels import free as _fk

__all__ = ["free_flow_scaled", "positive_scalar", "pow2"]


def pow2(x: np.ndarray) -> float:
    """The power of two at or just below ``max|x|`` (1 for zeros): an exact scale.

    ``x / pow2(x)`` has its largest entry in [1, 2); the scale itself is always
    finite and nonzero (down to the subnormals).

    Examples
    --------
    >>> pow2(np.array([3.0, -5.0])), pow2(np.zeros(3)), pow2(np.array([1e-310])) == 2.0**-1030
    (4.0, 1.0, True)
    """
    big = float(np.max(np.abs(x)))
    return 1.0 if big == 0.0 else math.ldexp(1.0, math.frexp(big)[1] - 1)


def free_flow_scaled(
    moments: np.ndarray, q0: np.ndarray, omega0: np.ndarray, flat_t: np.ndarray, t_name: str
) -> tuple[np.ndarray, np.ndarray]:
    """The exact free motion on a homogeneously scaled problem (no over- or underflow).

    The motion depends on the moments only through their ratios, and
    ``omega(t; s omega0) = s omega(s t; omega0)``: with exact power-of-two scales
    ``sm ~ max moment`` and ``sw ~ max|omega0|`` the kernel sees moments and rates
    of order one, whatever the caller's magnitudes (1e-300 or 1e300 kg m^2,
    1e-200 rad/s).

    Parameters
    ----------
    moments : ndarray, shape (3,)
        Validated principal moments (any consistent unit).
    q0 : ndarray, shape (4,)
        Unit attitude quaternion.
    omega0 : ndarray, shape (3,)
        Body angular velocity (per unit of ``flat_t``).
    flat_t : ndarray, shape (n,)
        Times, C-contiguous.
    t_name : str
        The caller's name of the times, for error messages.

    Returns
    -------
    q : ndarray, shape (n, 4)
    omega : ndarray, shape (n, 3)

    Raises
    ------
    ValueError
        If ``t * |omega|`` is beyond float64, naming ``t_name``, the index and
        the value.

    Examples
    --------
    >>> q, w = free_flow_scaled(np.array([1.0, 2.0, 3.0]), np.array([1.0, 0, 0, 0]),
    ...                         np.array([0.0, 0.0, 2.0]), np.array([0.0, np.pi / 2]), "t")
    >>> print(q.round(12) + 0.0)  # half a turn about z (2 rad/s for pi/2 s)
    [[1. 0. 0. 0.]
     [0. 0. 0. 1.]]
    """
    sm = pow2(moments)
    sw = pow2(omega0)
    with np.errstate(over="ignore"):
        ts = flat_t * sw
    bad = ~np.isfinite(ts)
    if np.any(bad):
        k = int(np.argwhere(bad)[0][0])
        raise ValueError(
            f"Expected `{t_name}` * |omega| to be finite (the angle turned), got "
            f"{float(flat_t[k])!r} at index {k} with |omega| ~ {sw!r}"
        )
    out_q = np.empty((flat_t.size, 4))
    out_w = np.empty((flat_t.size, 3))
    _fk.free_flow(moments / sm, q0, omega0 / sw, ts, out_q, out_w)
    out_w *= sw
    bad = ~(np.isfinite(out_q).all(axis=-1) & np.isfinite(out_w).all(axis=-1))
    if np.any(bad):  # pragma: no cover - a kernel failure is a bug, never a silent NaN
        k = int(np.argwhere(bad)[0][0])
        raise ValueError(
            f"free motion failed for moments = {moments.tolist()}, omega = {omega0.tolist()} "
            f"at `{t_name}`[{k}] = {float(flat_t[k])!r}: please report this case"
        )
    return out_q, out_w


def positive_scalar(name: str, value: np.ndarray) -> np.ndarray:
    """Require a scalar ``value > 0`` (``ValueError`` naming ``name`` otherwise).

    Examples
    --------
    >>> positive_scalar("Q", np.array(-3.0))
    Traceback (most recent call last):
    ...
    ValueError: Expected `Q` > 0, got -3.0
    """
    if value.shape != ():
        raise ValueError(f"Expected `{name}` to be a scalar, got shape {value.shape}")
    if not float(value) > 0.0:
        raise ValueError(f"Expected `{name}` > 0, got {float(value)!r}")
    return value
