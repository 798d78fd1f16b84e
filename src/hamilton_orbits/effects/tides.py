"""The effect ``earth_tides``: the tides raised on the Earth, acting on the Moon.

The tides the Moon and the Sun raise on the Earth acting on the Moon, DE440's
constant-time-lag model (``K2E0..2``, ``TAUE0..2``, ``TAUER1..2``): it gives the
Moon its secular deceleration.  Kernel
:func:`~hamilton_orbits._kernels.figures.earth_tides_of_date` (it knows the time:
with ``pole = "IAU2006"`` the Earth's pole is that of each time, by the IAU 2006
precession, else fixed); no analytic Jacobian (the tides' delays are nested
functions of the state): the variational equations differentiate the kernel by
compiled central differences (:mod:`hamilton_orbits.rhs`).  ``p = [the pole of
date's 10 numbers, earth index, moon index, sun index (-1: no Sun), radius,
omega, pole x, y, z, k20, k21, k22, TAUE0, TAUE1, TAUE2, TAUER1, TAUER2]``
(:func:`~hamilton_orbits.effects.parameters.pole_of_date`).  It keeps no
registered energy (tides dissipate).

References
----------
W. M. Folkner, J. G. Williams, D. H. Boggs, R. S. Park, P. Kuchynka, "The Planetary
and Lunar Ephemerides DE430 and DE431", IPN Progress Report 42-196 (2014), eq. 32.
R. S. Park, W. M. Folkner, J. G. Williams, D. H. Boggs, AJ 161, 105 (2021).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from hamilton_orbits import ephemeris as de
from hamilton_orbits._kernels.figures import OF_DATE, earth_tides_of_date
from hamilton_orbits.effects.parameters import (
    EPOCH_PARAMETER,
    FRAME_PARAMETER,
    PARK_2021,
    POLE_PARAMETER,
    body_index,
    distinct_bodies,
    finite_floats,
    optional_body_index,
    parameter_array,
    pole_of_date,
    require_de440_units,
    scalar_parameter,
)
from hamilton_orbits.effects.registry import EffectSpec
from hamilton_orbits.units import ANGULAR_SPEED, LENGTH, TIME

__all__ = ["EARTH_ROTATION_RATE", "SPECS"]

# IERS Conventions 2010, table 1.1: the Earth's nominal mean angular velocity, rad/s
EARTH_ROTATION_RATE = 7.292115e-5
# DE440's time lags of the Earth's tides (days), in the order of `tau`
_TAU = ("TAUE0", "TAUE1", "TAUE2", "TAUER1", "TAUER2")


def _params_earth_tides(system: Any, params: Mapping[str, Any]) -> np.ndarray:
    e = body_index(system, params, "earth", "earth", "earth_tides", massive=True)
    m = body_index(system, params, "moon", "moon", "earth_tides")
    require_de440_units(system, params, "earth_tides", ("radius", "omega", "tau"))
    sun = optional_body_index(system, params, "sun", "sun", "earth_tides")
    distinct_bodies(system, {"earth": e, "moon": m, "sun": sun}, "earth_tides")
    radius = scalar_parameter(system, params, "radius", "earth_tides", LENGTH,
                              de.constant("RE") / de.constant("AU"), positive=True)
    omega = scalar_parameter(system, params, "omega", "earth_tides", ANGULAR_SPEED,
                             EARTH_ROTATION_RATE * 86400.0)
    k2 = finite_floats("k2", params.get("k2", [de.constant(f"K2E{j}") for j in range(3)]), 3,
                 "earth_tides")
    tau = parameter_array(system, params, "tau", "earth_tides", TIME)
    if tau is None:
        tau = np.array([de.constant(k) for k in _TAU])
    elif tau.shape != (5,):
        raise ValueError(f"Effect 'earth_tides': expected `tau` to be 5 finite numbers, got "
                         f"{params['tau']!r}")
    lead = pole_of_date(system, e, params, "earth_tides")
    return np.array([*lead[:OF_DATE], e, m, sun, radius, omega, *lead[OF_DATE:], *k2, *tau])


SPECS = (
    EffectSpec(
        name="earth_tides", kind="nbody",
        summary="tides raised on the Earth by the Moon and Sun acting on the Moon (DE440)",
        velocity_dependent=True,
        parameters={"earth": "default 'earth'", "moon": "default 'moon'",
                    "sun": "tide raiser besides the Moon (default 'sun' if present; "
                           "'none' for none)",
                    "radius": "a length (default DE440's RE)",
                    "omega": "Earth's rotation rate (default IERS's, 7.292115e-5 rad/s)",
                    "k2": "[k20, k21, k22] (default DE440's K2E0..2)",
                    "tau": "time lags [TAUE0, TAUE1, TAUE2, TAUER1, TAUER2] (default "
                           "DE440's)",
                    "pole": POLE_PARAMETER, "epoch": EPOCH_PARAMETER,
                    "frame": FRAME_PARAMETER},
        kernel=earth_tides_of_date, params=_params_earth_tides,
        parameter_kinds={"radius": LENGTH, "omega": ANGULAR_SPEED, "tau": TIME},
        name_parameters=("earth", "moon"),
        reference=f"Folkner et al. (2014), IPN PR 42-196, eq. 32; {PARK_2021}",
    ),
)
