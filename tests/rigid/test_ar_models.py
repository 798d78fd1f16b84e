"""Vector autoregressions (rigid.earth.ar_models): fit, forecast, impulses, error growth."""

from __future__ import annotations

import numpy as np
import pytest

from rigid.earth.ar_models import VARModel, accumulate_covariance, fit_var

A1 = np.array([[0.5, 0.2], [-0.1, 0.6]])
A2 = np.array([[0.1, 0.0], [0.05, -0.2]])
SIGMA = np.array([[1.0, 0.3], [0.3, 2.0]])


def _simulate(n: int, seed: int = 7) -> np.ndarray:
    rng = np.random.default_rng(seed)
    e = rng.multivariate_normal(np.zeros(2), SIGMA, size=n)
    z = np.zeros((n, 2))
    for k in range(2, n):
        z[k] = A1 @ z[k - 1] + A2 @ z[k - 2] + e[k]
    return z


def test_fit_recovers_a_known_var2():
    model = fit_var(_simulate(40000), 2)
    # 40000 samples: coefficient errors ~ 1 / sqrt(n) ~ 0.005; 0.03 is six of those
    np.testing.assert_allclose(model.coef[0], A1, atol=0.03)
    np.testing.assert_allclose(model.coef[1], A2, atol=0.03)
    np.testing.assert_allclose(model.cov, SIGMA, rtol=0.05)


def test_fit_is_the_least_squares_solution():
    """The running-sum normal equations give the lagged regression's own solution."""
    z = _simulate(3000).cumsum(axis=0)  # smooth and ill-conditioned, as pole residuals are
    p = 12
    lagged = np.concatenate([z[p - 1 - i:-1 - i] for i in range(p)], axis=1)
    ref, *_ = np.linalg.lstsq(lagged, z[p:], rcond=None)
    got = fit_var(z, p).coef.transpose(1, 0, 2).reshape(2, -1).T
    # cond(lagged) ~ 1e4 here: the normal equations keep ~1e-8 relative
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-7 * np.abs(ref).max())


def test_forecast_and_impulse_response_follow_the_recursion():
    model = VARModel(np.stack([A1, A2]), SIGMA, 100)
    past = np.array([[1.0, -2.0], [0.5, 3.0]])
    z = [past[0], past[1]]
    for _ in range(5):
        z.append(A1 @ z[-1] + A2 @ z[-2])
    np.testing.assert_allclose(model.forecast(past, 5), np.array(z[2:]), rtol=1e-15)
    psi = model.impulse_response(4)
    ref = [np.eye(2), A1]
    for _ in range(2):
        ref.append(A1 @ ref[-1] + A2 @ ref[-2])
    np.testing.assert_allclose(psi, np.array(ref), rtol=1e-15, atol=1e-17)


def test_forecast_error_covariance_matches_simulation():
    """The h-step error covariance sum Psi Sigma Psi^T against simulated futures."""
    model = VARModel(np.stack([A1, A2]), SIGMA, 100)
    cov = accumulate_covariance(model.impulse_response(10), SIGMA)
    rng = np.random.default_rng(3)
    n = 20000
    e = rng.multivariate_normal(np.zeros(2), SIGMA, size=(n, 10))
    z = np.zeros((n, 12, 2))  # from zero history: the future is the error itself
    for k in range(10):
        z[:, k + 2] = z[:, k + 1] @ A1.T + z[:, k] @ A2.T + e[:, k]
    sim = np.einsum("nka,nkb->kab", z[:, 2:], z[:, 2:]) / n
    # 20000 futures: the sample covariance is good to ~ sqrt(2 / n) ~ 1%; 5% is safe
    np.testing.assert_allclose(sim, cov, rtol=0.05, atol=0.05)


def test_bad_input():
    with pytest.raises(ValueError, match="`order` >= 1, got 0"):
        fit_var(np.arange(10.0), 0)
    with pytest.raises(ValueError, match="longer than order"):
        fit_var(np.arange(10.0), 5)
    with pytest.raises(ValueError, match=r"finite, got .*nan.* at index 3"):
        fit_var(np.r_[np.arange(3.0), np.nan, np.arange(20.0)], 2)
    with pytest.raises(ValueError, match="singular"):
        fit_var(np.ones(50), 2)
    with pytest.raises(ValueError, match="at least p = 2 values, got 1"):
        VARModel(np.stack([A1, A2]), SIGMA, 100).forecast([[1.0, 2.0]], 3)
