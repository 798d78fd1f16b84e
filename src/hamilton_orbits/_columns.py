"""The columns of the elements kernels and the conic kinds, without numba.

Re-exported by :mod:`hamilton_orbits._kernels.elements` (which compiles with
them); defined here so that code building on the column layout can be imported
without importing numba.
"""

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
# and a = 1/inv_a
CLASSICAL = ("p", "e", "inv_a", "inc", "lan", "argp", "nu", "u", "kind", "a")
NCLASSICAL = len(CLASSICAL)
