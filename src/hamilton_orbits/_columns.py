"""The columns of the elements kernels and the conic kinds, without numba.

Re-exported by :mod:`hamilton_orbits._kernels.elements` (which compiles with
them); defined here so that code building on the column layout can be imported
without importing numba.
"""

import math

import numpy as np

# conic kinds (the ``kind`` column)
ELLIPSE = 0.0
PARABOLA = 1.0
HYPERBOLA = 2.0
RADIAL_ELLIPSE = 3.0
RADIAL_PARABOLA = 4.0
RADIAL_HYPERBOLA = 5.0

COLUMNS = (
    "p",
    "e",
    "inv_a",
    "inc",
    "lan",
    "argp",
    "nu",
    "anomaly",
    "M",
    "u",
    "kind",
    "tau",
)
NCOL = len(COLUMNS)

# the columns of state_to_elements_classical / classical_one: the classical
# elements (no anomaly, M, tau: those cost a third more, computed when asked),
# and a = 1/inv_a.  Not u (the argument of latitude, from the full kernel when
# asked) nor kind (derived from p, e, inv_a and nu: :func:`kind_of`): every
# column a batch stores is fresh memory (8 bytes per orbit, ~2 ns on one thread)
CLASSICAL = ("p", "e", "inv_a", "inc", "lan", "argp", "nu", "a")
NCLASSICAL = len(CLASSICAL)

# the output of the one-orbit kernel (elements.one_orbit): the state rx, ry, rz,
# vx, vy, vz, mu, then the CLASSICAL columns
ONE_ORBIT_SIZE = 7 + NCLASSICAL


def kind_of(p, e, inv_a, nu):
    """The ``kind`` column from the classical columns, for one orbit or many.

    As the kernel decides it: ``e < 1`` ellipse, ``e > 1`` hyperbola; ``e = 1``
    (exactly, as the kernel sets it) with ``1/a > 0`` or ``< 0`` a radial (or
    quasi-rectilinear) ellipse or hyperbola; with ``1/a = 0`` the radial
    parabola (``p = 0`` and ``nu = pi``, as the radial branch sets them; a
    parabola with ``p`` underflowed to 0 cannot have ``nu = pi``) or else the
    parabola.  The one place this rule is written on the Python side: numpy
    selects, so floats and arrays (broadcast together) take the same path.

    Parameters
    ----------
    p, e, inv_a, nu : float or ndarray, broadcastable
        Semi-latus rectum, eccentricity, 1/a and true anomaly (kernel columns).

    Returns
    -------
    numpy.float64 or ndarray
        One of ``ELLIPSE`` ... ``RADIAL_HYPERBOLA``, of the broadcast shape.

    Examples
    --------
    >>> import math
    >>> bool(kind_of(1.0, 0.5, 1.0, 0.0) == ELLIPSE), float(kind_of(0.0, 1.0, 0.0, math.pi))
    (True, 4.0)
    >>> kind_of(np.array([1.0, 0.0]), np.array([1.0, 1.0]), 0.0, math.pi).tolist()
    [1.0, 4.0]
    """
    radial = np.where(
        inv_a > 0.0, RADIAL_ELLIPSE, np.where(inv_a < 0.0, RADIAL_HYPERBOLA, np.where(
            (p == 0.0) & (nu == math.pi), RADIAL_PARABOLA, PARABOLA)))
    return np.where(e < 1.0, ELLIPSE, np.where(e > 1.0, HYPERBOLA, radial))[()]
