"""The effect ``lense_thirring``: the Sun's gravitomagnetic field, DE440's spin.

The Lense-Thirring acceleration of a spinning body (default the Sun, with DE440's
spin :func:`sun_spin`) on every other body, velocity dependent.  Kernel
:func:`~hamilton_orbits._kernels.relativity.lense_thirring`, Jacobian
:func:`~hamilton_orbits._kernels.jacobians.lense_thirring_jvp`; ``p = [body
index, c, gamma, spin x, y, z]``.  It keeps no registered energy.

References
----------
IERS Conventions (2010), IERS Technical Note 36, eq. 10.12.
R. S. Park, W. M. Folkner, J. G. Williams, D. H. Boggs, AJ 161, 105 (2021).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from hamilton_orbits import ephemeris as de
from hamilton_orbits._kernels.jacobians import lense_thirring_jvp
from hamilton_orbits._kernels.relativity import lense_thirring
from hamilton_orbits.effects.parameters import (
    FRAME_PARAMETER,
    PARK_2021,
    SPECIFIC_ANGULAR_MOMENTUM,
    axes_frame,
    body_index,
    de440_c_au_per_day,
    given_frame,
    parameter_array,
    require_de440_units,
    scalar_parameter,
)
from hamilton_orbits.effects.registry import EffectSpec
from hamilton_orbits.units import DIMENSIONLESS, SPEED

__all__ = ["SPECS", "sun_spin"]


def sun_spin(frame: str = "icrs") -> np.ndarray:
    """The Sun's spin angular momentum per unit mass (au^2/day) from DE440's constants.

    ``MOISUN * ASUN^2 * OMGSUN`` (moment-of-inertia factor, radius, rotation rate in
    rad/day) along the Sun's IAU pole in ``frame``.

    Examples
    --------
    >>> round(float(np.linalg.norm(sun_spin())) * 1e7, 3)  # au^2/day
    3.689
    """
    radius = de.constant("ASUN") / de.constant("AU")
    size = de.constant("MOISUN") * radius**2 * de.constant("OMGSUN")
    return size * de.sun_pole(frame)


def _params_lense_thirring(system: Any, params: Mapping[str, Any]) -> np.ndarray:
    b = body_index(system, params, "body", "sun", "lense_thirring", massive=True)
    require_de440_units(system, params, "lense_thirring", ("c", "spin"))
    if system.names[b] != "sun" and "spin" not in params:
        raise ValueError("Effect 'lense_thirring': a body other than the Sun needs `spin`")
    given_frame(params, "lense_thirring")  # (checked if given, used or not)
    spin = parameter_array(system, params, "spin", "lense_thirring", SPECIFIC_ANGULAR_MOMENTUM)
    if spin is None:
        spin = sun_spin(axes_frame(system, params, "lense_thirring"))
    elif spin.shape != (3,):
        raise ValueError(f"Effect 'lense_thirring': expected `spin` to be 3 finite numbers, "
                         f"got {params['spin']!r}")
    c = scalar_parameter(system, params, "c", "lense_thirring", SPEED, de440_c_au_per_day(),
                         positive=True)
    gamma = scalar_parameter(system, params, "gamma", "lense_thirring", DIMENSIONLESS,
                             de.constant("GAMMA"))
    return np.array([b, c, gamma, *spin])


SPECS = (
    EffectSpec(
        name="lense_thirring", kind="nbody",
        summary="the Sun's gravitomagnetic (Lense-Thirring) field, DE440's spin",
        velocity_dependent=True,
        parameters={"body": "default 'sun'",
                    "spin": "angular momentum per unit mass (default DE440's "
                            "MOISUN ASUN^2 OMGSUN about the IAU pole)",
                    "c": "speed of light, a speed (default DE440's CLIGHT)",
                    "gamma": "default DE440's GAMMA",
                    "frame": FRAME_PARAMETER},
        kernel=lense_thirring, params=_params_lense_thirring,
        parameter_kinds={"spin": SPECIFIC_ANGULAR_MOMENTUM, "c": SPEED,
                         "gamma": DIMENSIONLESS},
        name_parameters=("body",),
        jacobian=lense_thirring_jvp,
        reference=f"IERS Conventions (2010), eq. 10.12; {PARK_2021}",
    ),
)
