"""The columns of the elements kernels and the conic kinds, without numba.

Re-exported by :mod:`hamilton_orbits._kernels.elements` (which compiles with
them); defined here so that code building on the column layout can be imported
without importing numba.
"""

import math

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


def kind_of(p: float, e: float, inv_a: float, nu: float) -> float:
    """The ``kind`` column of one orbit from its classical columns.

    As the kernel decides it: ``e < 1`` ellipse, ``e > 1`` hyperbola; ``e = 1``
    (exactly, as the kernel sets it) with ``1/a > 0`` or ``< 0`` a radial (or
    quasi-rectilinear) ellipse or hyperbola; with ``1/a = 0`` the radial
    parabola (``p = 0`` and ``nu = pi``, as the radial branch sets them; a
    parabola with ``p`` underflowed to 0 cannot have ``nu = pi``) or else the
    parabola.

    Examples
    --------
    >>> import math
    >>> kind_of(1.0, 0.5, 1.0, 0.0) == ELLIPSE, kind_of(0.0, 1.0, 0.0, math.pi)
    (True, 4.0)
    """
    if e < 1.0:
        return ELLIPSE
    if e > 1.0:
        return HYPERBOLA
    if inv_a > 0.0:
        return RADIAL_ELLIPSE
    if inv_a < 0.0:
        return RADIAL_HYPERBOLA
    return RADIAL_PARABOLA if p == 0.0 and nu == math.pi else PARABOLA

