"""rigid.trajectory: Cayley's integrals of a run (``integral_errors``)."""

import numpy as np

from rigid.trajectory import integral_errors

EPS = np.finfo(float).eps


def test_the_changes_of_a_body_started_at_rest_are_absolute_in_the_callers_units():
    """A body at rest (moments 1, 2, 3) spun up to omega = (0, 0, 1/3), the state
    BodyTorque([0, 0, 1]) gives after 1 s (C dr/dt = 1): T = C r^2 / 2 = 1/6 and
    |L_s| = C r = 1.  The errors were 4/3 and 2 (the changes of the integrals of
    moments and omega rescaled by powers of two); the docstring promises the
    absolute changes.  With the moments and the torque times 8 (the same omega)
    they are 8 times larger.  (A few roundings of the scaled sums: 4 eps.)"""
    q = np.array([[1.0, 0.0, 0.0, 0.0], [np.cos(0.3), 0.0, 0.0, np.sin(0.3)]])
    omega = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 1.0 / 3.0]])
    for k in (1.0, 8.0, 3.0):
        de, dl = integral_errors(k * np.array([1.0, 2.0, 3.0]), q, omega)
        np.testing.assert_allclose(de, [0.0, k / 6.0], rtol=4 * EPS, atol=0)
        np.testing.assert_allclose(dl, [0.0, k], rtol=4 * EPS, atol=0)
