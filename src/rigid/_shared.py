"""Helpers shared by the modules of ``rigid`` (public-looking names, not public API).

Everything here works on plain floats (SI for the rigid body, days for the pole):

* :func:`pow2`: an exact power-of-two scale, so that homogeneous problems run
  on numbers of order one (no over- or underflow inside the kernels);
* :func:`free_scale`: the scale of the angular velocity for the exact
  torque-free kernel (:func:`pow2`, or larger rates where the kernel's polhode
  terms would underflow);
* :func:`free_setup_scaled`, :func:`free_flow_scaled`: the exact torque-free
  kernel on such a scaled problem, its failures as ValueErrors naming the
  caller's arguments (used by :mod:`rigid.free`, :mod:`rigid.poinsot` and
  :mod:`rigid.sylvester`);
* :func:`positive_scalar`: the check of a positive scalar parameter (used by
  :mod:`rigid.earth.liouville` and :mod:`rigid.earth.wobble_fit`).

Nothing here imports another ``rigid`` module but the kernels, so every module
of the package may import it without an import circle.
"""

from __future__ import annotations

import math

import numpy as np

from rigid._kernels import free as _fk

__all__ = ["free_flow_scaled", "free_scale", "free_setup_scaled", "positive_scalar", "pow2"]

# The free-motion kernel forms the polhode terms J_i w_i^2 (J_k - J_i) (whose sums are
# 2 T J_k - L^2) before it divides them: each must stay a normal number with room for
# the products and quotients that follow (64 bits above float64's smallest normal).
_POLHODE_FLOOR = -1022 + 64
# The most the rates may be scaled up to lift those terms: 2^270.  A motion the kernel
# does not take as steady (some (J_i - J_j) w_i w_j > 1e-150 max J) with moments within
# 1e-150 of each other has every dominant term above ~2^-1495, a lift of at most 269;
# the kernel's largest quantities, ~ |L|^2 / (A B C), then stay below 2^1023.
_MAX_LIFT = 270


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


def free_scale(moments: np.ndarray, omega: np.ndarray, who: str) -> float:
    """The power of two ``sw`` by which the free-motion kernel takes ``omega``: exact.

    ``pow2(omega)`` (the largest rate in [1, 2)), unless one of the kernel's polhode
    terms ``J_i w_i^2 (J_k - J_i)`` (moments ``J = moments / pow2(moments)``, rates
    ``w = omega / sw``) that dominates its sum ``2 T J_k - L^2`` would fall below the
    normal range of float64: then ``sw`` is smaller, so that the kernel sees larger
    rates (a thin needle, ``A / C = 1e-60``, spinning about its axis at 1e-130 of its
    tumbling rate: 1e-320 underflowed, the kernel divided by zero).  The motion is
    homogeneous in the rates, so any power of two gives the same answer.

    Raises
    ------
    ValueError
        Naming ``who`` (the caller's arguments) when no scale keeps those terms
        normal and the kernel's largest ones finite.

    Examples
    --------
    >>> free_scale(np.array([1.0, 2.0, 3.0]), np.array([0.0, 3.0, 1e-3]), "`omega`")
    2.0
    >>> # 1e-60 x (1e-130)^2 = 1e-320 is subnormal: the rates are taken 2^53 times larger
    >>> free_scale(np.array([1e-60, 1.0, 1.0]), np.array([1e-130, 1.0, 0.0]), "`omega`")
    1.1102230246251565e-16
    """
    sw = pow2(omega)
    moments = moments / pow2(moments)
    # the kernel's own test of a steady motion, run as Python on the numbers it will
    # see (its source, not a mirror: nothing to keep in step, and nothing compiled)
    if _fk.is_steady.py_func(moments.tolist(), (omega / sw).tolist()):
        return sw
    nz = omega != 0.0
    log_w = np.full(3, -np.inf)
    log_w[nz] = np.log2(np.abs(omega[nz])) - math.log2(sw)
    with np.errstate(divide="ignore"):  # log2(0) = -inf: no term
        # terms[k, i]: log2 |J_i w_i^2 (J_k - J_i)|, the term of 2 T J_k - L^2 from axis i
        terms = (np.log2(moments) + 2.0 * log_w)[None, :] + np.log2(
            np.abs(moments[:, None] - moments[None, :]))
    # the row of the intermediate moment (L^2 - 2 T J_mid, the distance from the
    # separatrix) need not be normal: the kernel takes its square root on scaled rates
    # (k'; near the intermediate axis it underflows, 1 - m = 3e-600 for a spin
    # (0, 1, 1e-300) on (1, 2, 3)); with ties it equals another row, which is kept
    rows = np.delete(np.arange(3), int(np.argsort(moments, kind="stable")[1]))
    dominant = terms[rows].max(axis=1)
    dominant = dominant[np.isfinite(dominant)]
    lift = math.ceil((_POLHODE_FLOOR - float(dominant.min())) / 2.0) if dominant.size else 0
    if lift <= 0:
        return sw
    if lift > _MAX_LIFT:
        k = int(np.argmin(moments))
        raise ValueError(
            f"Expected {who} within the range of the exact free motion, got moments "
            f"{(moments * pow2(moments)).tolist()} and omega {omega.tolist()}: the polhode's "
            f"terms (moment x omega^2 x a difference of moments) span more than float64, "
            f"the moment {float(moments[k] * pow2(moments))!r} at index {k} is too thin "
            f"for rates this uneven"
        )
    return math.ldexp(sw, -lift)


def _kernel_failed(who: str, moments: np.ndarray, omega: np.ndarray) -> ValueError:
    return ValueError(
        f"Expected {who} within the range of the exact free motion, got moments "
        f"{moments.tolist()} and omega {omega.tolist()}: the kernel's polhode parameters "
        f"are beyond float64"
    )


def free_setup_scaled(
    moments: np.ndarray, q0: np.ndarray, omega: np.ndarray, who: str, sw: float | None = None
) -> tuple[np.ndarray, float]:
    """``(prm, sw)``: the kernel's parameter vector (:func:`rigid._kernels.free.free_setup`)
    of the problem scaled by ``pow2(moments)`` and ``sw`` (default :func:`free_scale`);
    its rates (``LAM``) are in units of ``sw`` (multiply by ``sw``).

    Raises
    ------
    ValueError
        Naming ``who`` when the problem is beyond the kernel's range.

    Examples
    --------
    >>> prm, sw = free_setup_scaled(np.array([1.0, 2.0, 3.0]), np.array([1.0, 0, 0, 0]),
    ...                             np.array([0.0, 0.0, 2.0]), "`body`")
    >>> float(prm[0]), sw  # steady: a spin about a principal axis
    (0.0, 2.0)
    """
    if sw is None:
        sw = free_scale(moments, omega, who)
    try:
        prm = _fk.free_setup(moments / pow2(moments), q0, np.ascontiguousarray(omega / sw))
    except ZeroDivisionError:
        raise _kernel_failed(who, moments, omega) from None
    if not np.all(np.isfinite(prm)):
        raise _kernel_failed(who, moments, omega)
    return prm, sw


def free_flow_scaled(
    moments: np.ndarray,
    q0: np.ndarray,
    omega0: np.ndarray,
    flat_t: np.ndarray,
    t_name: str,
    who: str = "`moments` and `omega0`",
) -> tuple[np.ndarray, np.ndarray]:
    """The exact free motion on a homogeneously scaled problem (no over- or underflow).

    The motion depends on the moments only through their ratios, and
    ``omega(t; s omega0) = s omega(s t; omega0)``: with exact power-of-two scales
    ``sm ~ max moment`` and ``sw ~ max|omega0|`` (:func:`free_scale`) the kernel sees
    moments and rates of order one, whatever the caller's magnitudes (1e-300 or
    1e300 kg m^2, 1e-200 rad/s).

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
    who : str, optional
        The caller's arguments holding the state, for error messages.

    Returns
    -------
    q : ndarray, shape (n, 4)
    omega : ndarray, shape (n, 3)

    Raises
    ------
    ValueError
        If ``t * |omega|`` is beyond float64, naming ``t_name``, the index and
        the value; if the problem is beyond the kernel's range or an angular
        velocity along the motion is beyond float64, naming ``who``.

    Examples
    --------
    >>> q, w = free_flow_scaled(np.array([1.0, 2.0, 3.0]), np.array([1.0, 0, 0, 0]),
    ...                         np.array([0.0, 0.0, 2.0]), np.array([0.0, np.pi / 2]), "t")
    >>> print(q.round(12) + 0.0)  # half a turn about z (2 rad/s for pi/2 s)
    [[1. 0. 0. 0.]
     [0. 0. 0. 1.]]
    """
    sm = pow2(moments)
    rate = pow2(omega0)
    with np.errstate(over="ignore"):
        bad = ~np.isfinite(flat_t * rate)
    if np.any(bad):
        k = int(np.argwhere(bad)[0][0])
        raise ValueError(
            f"Expected `{t_name}` * |omega| to be finite (the angle turned), got "
            f"{float(flat_t[k])!r} at index {k} with |omega| ~ {rate!r}"
        )
    sw = free_scale(moments, omega0, who)
    out_q = np.empty((flat_t.size, 4))
    out_w = np.empty((flat_t.size, 3))
    try:
        _fk.free_flow(moments / sm, q0, omega0 / sw, flat_t * sw, out_q, out_w)
    except ZeroDivisionError:
        raise _kernel_failed(who, moments, omega0) from None
    if not (np.all(np.isfinite(out_q)) and np.all(np.isfinite(out_w))):
        raise _kernel_failed(who, moments, omega0)
    with np.errstate(over="ignore"):  # a rate beyond float64 is refused below
        out_w *= sw
    bad = ~np.isfinite(out_w).all(axis=-1)
    if np.any(bad):
        k = int(np.argwhere(bad)[0][0])
        raise ValueError(
            f"Expected {who} with an angular velocity within float64 along the motion, got "
            f"{out_w[k].tolist()} at `{t_name}`[{k}] = {float(flat_t[k])!r} from moments "
            f"{moments.tolist()} and omega {omega0.tolist()}"
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
