"""The effect ``kuiper_ring``: the Kuiper belt as DE440 models it.

A ring of radius :data:`KUIPER_RING_RADIUS_AU` in the ecliptic, centred on the
Sun, of the total GM of DE440's 36 ring masses (``MA8201`` ... ``MA8236``,
:func:`kuiper_ring_gm`).  Kernel :func:`~hamilton_orbits._kernels.figures.ring_field`;
no analytic Jacobian: the variational equations differentiate the kernel by
compiled central differences (:mod:`hamilton_orbits.rhs`).  ``p = [centre index,
GM, radius, normal x, y, z]``.  It keeps no registered energy.

References
----------
R. S. Park, W. M. Folkner, J. G. Williams, D. H. Boggs, AJ 161, 105 (2021), section 3.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from hamilton_orbits import ephemeris as de
from hamilton_orbits._kernels.figures import ring_field
from hamilton_orbits.effects.parameters import (
    FRAME_PARAMETER,
    PARK_2021,
    axes_frame,
    body_index,
    given_frame,
    require_de440_units,
    scalar_parameter,
    unit_vector,
)
from hamilton_orbits.effects.registry import EffectSpec
from hamilton_orbits.units import GM, LENGTH

__all__ = ["KUIPER_RING_RADIUS_AU", "SPECS", "kuiper_ring_gm"]

# Park et al. (2021), section 3: DE440's Kuiper-belt ring, 36 point masses at 44 au
KUIPER_RING_RADIUS_AU = 44.0


def kuiper_ring_gm() -> float:
    """The GM of DE440's Kuiper-belt ring: the sum of its 36 ring masses, au^3/day^2.

    Examples
    --------
    >>> round(kuiper_ring_gm() / de.constant("GMS") / 3.0034896e-6, 4)  # Earth masses
    0.0224
    """
    c = de.constants()
    return float(sum(c[f"MA{8200 + k}"] for k in range(1, 37)))


def _params_kuiper_ring(system: Any, params: Mapping[str, Any]) -> np.ndarray:
    b = body_index(system, params, "centre", "sun", "kuiper_ring", massive=True)
    require_de440_units(system, params, "kuiper_ring", ("gm", "radius"))
    big_m = scalar_parameter(system, params, "gm", "kuiper_ring", GM, kuiper_ring_gm(),
                             nonnegative=True)
    radius = scalar_parameter(system, params, "radius", "kuiper_ring", LENGTH,
                              KUIPER_RING_RADIUS_AU, positive=True)
    given_frame(params, "kuiper_ring")  # (checked if given, used or not)
    normal = (unit_vector("normal", params["normal"], "kuiper_ring") if "normal" in params
              else de.ecliptic_pole(axes_frame(system, params, "kuiper_ring")))
    return np.array([b, big_m, radius, *normal])


def _singular_ring(system: Any, r: np.ndarray, p: np.ndarray) -> str | None:
    """The body on the ring itself (its potential singular there), or None."""
    b, rad, k = int(p[0]), p[2], p[3:6]
    d = r - r[b]
    z = d @ k
    rho = np.linalg.norm(d - np.outer(z, k), axis=1)
    off = np.hypot(rho - rad, z)
    off[b] = np.inf
    i = int(np.argmin(off))
    if not off[i] <= 1e-9 * rad:
        return None
    return (f"body {system.names[i]!r} (index {i}) lies on the ring (radius {float(rad)!r}, "
            f"its distance to the ring {float(off[i])!r}): the ring's potential is singular "
            f"there; move it off the ring")


SPECS = (
    EffectSpec(
        name="kuiper_ring", kind="nbody",
        summary="the Kuiper belt as DE440's ring (44 au, ecliptic, centred on the Sun)",
        parameters={"centre": "default 'sun'", "gm": "a GM (default DE440's 36 ring masses)",
                    "radius": "a length (default 44 au)", "normal": "default the ecliptic pole",
                    "frame": FRAME_PARAMETER},
        kernel=ring_field, params=_params_kuiper_ring,
        parameter_kinds={"gm": GM, "radius": LENGTH}, name_parameters=("centre",),
        singular=_singular_ring,
        reference=f"{PARK_2021}, section 3 (ring masses MA8201..MA8236)",
    ),
)
