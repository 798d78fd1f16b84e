"""The numba types shared by the compiled right-hand sides and the stepping kernels.

A right-hand side is ``accel(r, v, gm, acc, p)``: positions and velocities (n, 3),
``G m`` (n,), the output (n, 3) and the parameter vector of the listed effects
(see :mod:`hamilton_orbits.rhs`), all C-contiguous float64.  The stepping kernels
take it as a first-class function of :data:`ACCEL_TYPE`, so that each is compiled
once and cached for every right-hand side.
"""

from __future__ import annotations

from numba import types

__all__ = ["ACCEL_SIGNATURE", "ACCEL_TYPE", "F1", "F2"]

F1 = types.float64[::1]
F2 = types.float64[:, ::1]

#: ``void(r, v, gm, acc, p)``
ACCEL_SIGNATURE = types.void(F2, F2, F1, F2, F1)

#: The first-class function type of a right-hand side.
ACCEL_TYPE = types.FunctionType(ACCEL_SIGNATURE)
