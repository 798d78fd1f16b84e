"""Autoregressive models of a vector time series: fit, forecast and forecast-error growth.

The model (Lütkepohl 2005, New Introduction to Multiple Time Series Analysis, eq. 2.1.1
without intercept; a univariate AR is the case ``d = 1``)::

    z_k = A_1 z_{k-1} + ... + A_p z_{k-p} + e_k,   e_k ~ N(0, Sigma)

with ``z_k`` of dimension ``d``, is fitted by least squares (``A`` from the lagged
regression, ``Sigma`` from its residuals, Lütkepohl sec. 3.2).  The ``h``-step forecast
continues the recursion with ``e = 0``; its error is ``sum_{j<h} Psi_j e_{k+h-j}`` with the
impulse responses ``Psi_0 = I``, ``Psi_j = sum_i A_i Psi_{j-i}`` (Lütkepohl eq. 2.2.9), so
its covariance is ``sum_{j<h} Psi_j Sigma Psi_j^T`` (eq. 2.2.11).

Plain floats throughout (the caller's units); the recursion is a compiled kernel
(:mod:`rigid._kernels.var`), so no Python loop runs over the steps.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from rigid._kernels import var as _vk

__all__ = ["SingularRegressionError", "VARModel", "accumulate_covariance", "fit_var"]


class SingularRegressionError(ValueError):
    """:func:`fit_var` of a series that does not determine the model: its lagged
    regression is singular (a constant series, or a few exact sinusoids, which obey a
    short linear recurrence exactly).

    Attributes
    ----------
    order : int
        The VAR order ``p``.
    pivot : int
        The Cholesky pivot (1-based) that failed, of ``size``.
    size : int
        ``p d``, the unknowns per component.
    """

    def __init__(self, message: str, *, order: int, pivot: int, size: int) -> None:
        super().__init__(message)
        self.order, self.pivot, self.size = order, pivot, size


@dataclass(frozen=True)
class VARModel:
    """A fitted vector autoregression (see the module docstring).

    Attributes
    ----------
    coef : ndarray, shape (p, d, d)
        ``A_1 ... A_p``.
    cov : ndarray, shape (d, d)
        Innovation covariance ``Sigma`` (residual sum of squares / (n - p d)).
    n : int
        Number of equations in the least-squares fit.
    """

    coef: np.ndarray
    cov: np.ndarray
    n: int

    @property
    def order(self) -> int:
        """``p``."""
        return int(self.coef.shape[0])

    @property
    def dim(self) -> int:
        """``d``."""
        return int(self.coef.shape[1])

    def forecast(self, past: Any, steps: int) -> np.ndarray:
        """The next ``steps`` values after ``past`` (shape (n, d) or (n,), oldest first).

        Returns an array of shape (steps, d).

        Examples
        --------
        >>> model = VARModel(np.array([[[0.5]]]), np.eye(1), 100)
        >>> model.forecast([4.0], 3).ravel()
        array([2. , 1. , 0.5])
        """
        hist = np.asarray(past, dtype=np.float64).reshape(-1, self.dim)
        if hist.shape[0] < self.order:
            raise ValueError(
                f"Expected `past` to hold at least p = {self.order} values, got {hist.shape[0]}"
            )
        out = np.empty((int(steps), self.dim))
        _vk.var_recursion(self.coef, np.ascontiguousarray(hist[-self.order:]), out)
        return out

    def impulse_response(self, steps: int) -> np.ndarray:
        """``Psi_0 ... Psi_{steps-1}``, shape (steps, d, d) (``Psi_0`` the identity).

        Examples
        --------
        >>> VARModel(np.array([[[0.5]]]), np.eye(1), 100).impulse_response(3).ravel()
        array([1.  , 0.5 , 0.25])
        """
        p, d = self.order, self.dim
        psi = np.empty((int(steps), d, d))
        if steps == 0:
            return psi
        for col in range(d):  # one recursion per column of Psi (d <= 2 here)
            hist = np.zeros((p, d))
            hist[-1, col] = 1.0
            psi[0, :, col] = hist[-1]
            if steps > 1:
                out = np.empty((int(steps) - 1, d))
                _vk.var_recursion(self.coef, hist, out)
                psi[1:, :, col] = out
        return psi


def accumulate_covariance(response: np.ndarray, cov: np.ndarray) -> np.ndarray:
    """``C_h = sum_{j<h} G_j Sigma G_j^T`` for ``h = 1 .. steps``: the forecast-error
    covariance of a linear response ``G`` (shape (steps, q, d)) to innovations of
    covariance ``Sigma`` (d, d).  Returns shape (steps, q, q).

    Examples
    --------
    >>> g = np.ones((3, 1, 1))  # a random walk: the variance grows by Sigma per step
    >>> accumulate_covariance(g, np.array([[2.0]])).ravel()
    array([2., 4., 6.])
    """
    terms = np.einsum("jab,bc,jdc->jad", response, cov, response)
    return np.cumsum(terms, axis=0)


def _normal_equations(z: np.ndarray, p: int) -> tuple[np.ndarray, np.ndarray]:
    """``X^T X`` and ``X^T Y`` of the lagged regression, from running sums of lagged
    products: O(n p d^2) instead of the O(n p^2 d^2) of forming ``X^T X`` (and no BLAS
    call, which a loaded 2-core machine makes slow).  The sums are the same (in another
    order of addition).

    Row ``r`` of ``X`` holds ``z[a + r]`` in block ``i = p - 1 - a``; ``Y`` row ``r`` is
    ``z[p + r]``.  Block ``(a, b)`` of ``X^T X`` with ``l = a - b >= 0`` is
    ``sum_{s=b}^{b+N-1} z[s + l] z[s]^T = P_l[b + N] - P_l[b]`` with the prefix sums
    ``P_l[s] = sum_{s' < s} z[s' + l] z[s']^T``.
    """
    n, d = z.shape
    big_n = n - p
    prod = np.zeros((p + 1, n + 1, d, d))
    for lag in range(p + 1):  # p + 1 vectorised products (no loop over the samples)
        prod[lag, 1:n - lag + 1] = np.einsum("sa,sb->sab", z[lag:], z[:n - lag])
    prefix = np.cumsum(prod, axis=1)
    a, b = np.meshgrid(np.arange(p), np.arange(p), indexing="ij")
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    block = prefix[hi - lo, lo + big_n] - prefix[hi - lo, lo]  # z[hi + r] z[lo + r]^T
    block = np.where((a >= b)[..., None, None], block, np.swapaxes(block, -1, -2))
    i = p - 1 - a  # block (a, b) sits at (p - 1 - a, p - 1 - b)
    normal = np.empty((p, p, d, d))
    normal[i, p - 1 - b] = block
    normal = normal.transpose(0, 2, 1, 3).reshape(p * d, p * d)
    lags = p - np.arange(p)  # X block i = p - 1 - a against Y: sum z[a + r] z[p + r]^T
    aa = np.arange(p)
    cross = np.swapaxes(prefix[lags, aa + big_n] - prefix[lags, aa], -1, -2)  # (p, d, d)
    cross = cross[p - 1 - aa].reshape(p * d, d)
    return normal, cross


def fit_var(series: Any, order: int) -> VARModel:
    """Least-squares fit of a VAR(``order``) without intercept to ``series``.

    Parameters
    ----------
    series : array_like, shape (n,) or (n, d), real
        Equally spaced, oldest first, of zero mean (remove the mean or the deterministic
        model first).
    order : int
        ``p >= 1``.

    Returns
    -------
    VARModel

    Raises
    ------
    ValueError
        For an order below 1, a series too short for the order (``n - p`` must exceed
        ``p d``), non-finite values, or a series that does not determine the model (a
        singular lagged regression, e.g. a constant series: a
        :class:`SingularRegressionError`).

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> z = np.zeros(20000)
    >>> for k in range(1, z.size):
    ...     z[k] = 0.9 * z[k - 1] + rng.normal()
    >>> model = fit_var(z, 1)
    >>> print(round(float(model.coef[0, 0, 0]), 2), round(float(model.cov[0, 0]), 1))
    0.9 1.0
    """
    z = np.asarray(series, dtype=np.float64)
    if z.ndim == 1:
        z = z[:, None]
    if z.ndim != 2:
        raise ValueError(f"Expected `series` of shape (n,) or (n, d), got {z.shape}")
    p = int(order)
    if p < 1:
        raise ValueError(f"Expected `order` >= 1, got {order!r}")
    n, d = z.shape
    if n - p <= p * d:
        raise ValueError(
            f"Expected `series` longer than order * (dim + 1) = {p * (d + 1)}, got {n} values"
        )
    if not np.all(np.isfinite(z)):
        k = int(np.argmin(np.all(np.isfinite(z), axis=1)))
        raise ValueError(f"Expected `series` to be finite, got {z[k]!r} at index {k}")
    # lagged design: row k holds z_{k+p-1}, ..., z_k (lag 1 first)
    lagged = np.concatenate([z[p - 1 - i:n - 1 - i] for i in range(p)], axis=1)
    target = z[p:]
    normal, cross = _normal_equations(z, p)
    # normal equations: for the pole and excitation residuals fitted here cond(lagged) is
    # below ~1e5, so they lose < 1e-6 relative (forecasts within 1e-7 mas of a QR solution)
    sol = np.array(cross)  # (p d, d), solved in place (compiled Cholesky, one thread)
    status = _vk.spd_solve(np.array(normal), sol)
    if status:
        raise SingularRegressionError(
            f"Expected `series` to determine a VAR({p}): the lagged regression is singular "
            f"(pivot {status} of {p * d})", order=p, pivot=int(status), size=p * d)
    resid = target - np.einsum("ni,ij->nj", lagged, sol)
    cov = np.einsum("ni,nj->ij", resid, resid) / (target.shape[0] - p * d)
    coef = np.ascontiguousarray(sol.T.reshape(d, p, d).transpose(1, 0, 2))
    return VARModel(coef=coef, cov=cov, n=int(target.shape[0]))
