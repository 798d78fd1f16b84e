"""The effect ``moon_figure``: the Moon's degree-2 figure acting on every other body.

DE440's ``AM``, ``J2M``, ``C22M`` in principal axes built from the Earth-Moon
geometry and Cassini's laws (the axes follow the orbit normal, from the
Earth-Moon relative velocity: velocity dependent), with the lunar equator
inclined by :data:`MOON_EQUATOR_INCLINATION_DEG` to the ecliptic (less for an
orbit within ``MOON_NODE_TILT``, 1e-6 rad, of the ecliptic, whose node is
ill-defined: none at zero tilt, where the equator is the orbit's plane; see
:func:`~hamilton_orbits._kernels.figures.moon_frame`).  Kernel
:func:`~hamilton_orbits._kernels.figures.moon_figure`; no analytic Jacobian (the
Moon's frame is a nested function of the state): the variational equations
differentiate the kernel by compiled central differences
(:mod:`hamilton_orbits.rhs`).  ``p = [moon index, earth index, radius, J2, C22,
ecliptic pole x, y, z, inclination]``.  It keeps no registered energy.

References
----------
W. M. Folkner, J. G. Williams, D. H. Boggs, R. S. Park, P. Kuchynka, "The Planetary
and Lunar Ephemerides DE430 and DE431", IPN Progress Report 42-196 (2014), eq. 28.
R. S. Park, W. M. Folkner, J. G. Williams, D. H. Boggs, AJ 161, 105 (2021).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from hamilton_orbits import ephemeris as de
from hamilton_orbits._kernels.figures import moon_figure
from hamilton_orbits.effects.parameters import (
    FRAME_PARAMETER,
    PARK_2021,
    axes_frame,
    body_index,
    distinct_bodies,
    require_de440_units,
    scalar_parameter,
)
from hamilton_orbits.effects.registry import EffectSpec
from hamilton_orbits.units import ANGLE, DIMENSIONLESS, LENGTH

__all__ = ["MOON_EQUATOR_INCLINATION_DEG", "SPECS"]

# The mean inclination of the lunar equator to the ecliptic, I = 1.5424 deg
# (Cassini's third law; the IAU lunar rotation model, Archinal et al. 2018, and
# Eckhardt 1981's I = 1 deg 32' 33")
MOON_EQUATOR_INCLINATION_DEG = 1.5424


def _params_moon_figure(system: Any, params: Mapping[str, Any]) -> np.ndarray:
    m = body_index(system, params, "moon", "moon", "moon_figure", massive=True)
    e = body_index(system, params, "earth", "earth", "moon_figure")
    distinct_bodies(system, {"moon": m, "earth": e}, "moon_figure")
    require_de440_units(system, params, "moon_figure", ("radius",))
    radius = scalar_parameter(system, params, "radius", "moon_figure", LENGTH,
                              de.constant("AM") / de.constant("AU"), positive=True)
    j2 = scalar_parameter(system, params, "j2", "moon_figure", DIMENSIONLESS,
                          de.constant("J2M"))
    c22 = scalar_parameter(system, params, "c22", "moon_figure", DIMENSIONLESS,
                           de.constant("C22M"))
    inc = np.deg2rad(scalar_parameter(system, params, "inclination_deg", "moon_figure", ANGLE,
                                      MOON_EQUATOR_INCLINATION_DEG))
    pole = de.ecliptic_pole(axes_frame(system, params, "moon_figure"))
    return np.array([m, e, radius, j2, c22, *pole, inc])


def _body_moon_figure(p: np.ndarray) -> int:
    """The Moon, or -1 for a J2 of zero (only C22: the J2 left to ``j2`` or
    ``zonal``)."""
    return int(p[0]) if p[3] != 0.0 else -1


_MOON_J2 = "the Moon's J2 (its `j2`, DE440's J2M by default)"

SPECS = (
    EffectSpec(
        name="moon_figure", kind="nbody",
        summary="the Moon's J2 and C22 in axes from Cassini's laws, on every other body",
        # its axes follow the orbit normal, from the Earth-Moon relative velocity
        velocity_dependent=True,
        parameters={"moon": "default 'moon'", "earth": "default 'earth'",
                    "radius": "a length (default DE440's AM)", "j2": "default DE440's J2M",
                    "c22": "default DE440's C22M",
                    "inclination_deg": "lunar equator to ecliptic, degrees (default 1.5424)",
                    "frame": FRAME_PARAMETER},
        kernel=moon_figure, params=_params_moon_figure,
        parameter_kinds={"radius": LENGTH, "j2": DIMENSIONLESS, "c22": DIMENSIONLESS},
        name_parameters=("moon", "earth"),
        same_body_excludes={"j2": _MOON_J2, "zonal": _MOON_J2},
        body_of=_body_moon_figure,
        reference=f"Folkner et al. (2014), IPN PR 42-196, eq. 28; {PARK_2021}",
    ),
)
