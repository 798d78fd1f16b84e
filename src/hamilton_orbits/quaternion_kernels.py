"""Hamilton's product and rotation as compiled scalar kernels, for other packages' kernels.

The building blocks that :class:`hamilton_orbits.Quaternion` and the compiled kernels of
``rigid`` (Euler's equations, the exact torque-free flow, the splittings) stand on.  They
are numba functions compiled with ``inline="always"``, meant to be *called from other
numba kernels* (a call from Python works too, through numba's dispatcher, but costs
microseconds: for arrays use :class:`~hamilton_orbits.Quaternion`).  The code lives in
the private ``hamilton_orbits._kernels.quaternion``; this module is its public name, and
re-exports the very same objects (nothing is wrapped or recompiled).

Layout: scalar first, a quaternion ``q = w + x i + y j + z k`` is the four floats
``(w, x, y, z)``, passed and returned one by one (no arrays, so that they inline into
any loop without allocation); vectors are ``(vx, vy, vz)``.

:func:`qmul` ``(aw, ax, ay, az, bw, bx, by, bz) -> (w, x, y, z)``
    The Hamilton product ``a b``: with ``a = (s, alpha)``, ``b = (t, beta)``,
    ``a b = (s t - alpha . beta, s beta + t alpha + alpha x beta)`` (Hamilton 1845).
    Not commutative; exact to rounding, no normalisation.
:func:`qrot` ``(w, x, y, z, vx, vy, vz) -> (vx', vy', vz')``
    The rotation ``q v q^-1`` of the vector ``v`` by any nonzero ``q`` (its scale
    cancels): ``v' = v + (2/|q|^2) (w (u x v) + u x (u x v))``, ``u`` the vector part.
    Full precision for components from 1e-308 to 1e308 (exact power-of-two scaling
    outside safe bounds); the zero quaternion gives NaN and a result too large for a
    float gives inf, which the caller checks.

Examples
--------
>>> from hamilton_orbits.quaternion_kernels import qmul, qrot
>>> qmul(0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0)   # i j = k
(0.0, 0.0, 0.0, 1.0)
>>> import math
>>> c = s = math.sqrt(0.5)                            # a quarter turn about z
>>> [round(v, 12) for v in qrot(c, 0.0, 0.0, s, 1.0, 0.0, 0.0)]
[0.0, 1.0, 0.0]
"""

from __future__ import annotations

from hamilton_orbits._kernels.quaternion import qmul, qrot

__all__ = ["qmul", "qrot"]
