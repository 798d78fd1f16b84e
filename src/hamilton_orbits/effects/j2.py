"""The effect ``j2``: the oblateness J2 of a named body about its pole.

Kernel :func:`~hamilton_orbits._kernels.nbody.j2_field`, Jacobian
:func:`~hamilton_orbits._kernels.jacobians.j2_field_jvp`; ``p = [body index, J2,
radius, pole x, y, z]`` (J2 and the radius default to the Body's, the pole to the
Body's or the z axis); it keeps an energy (the degree-2 zonal potential).  The
Sun's J2 of DE440 is this effect too (``{"name": "j2", "body": "sun"}``;
:meth:`~hamilton_orbits.nbody.System.from_ephemeris` gives the Sun DE440's
``J2SUN`` and ``ASUN`` about its IAU pole).  Higher zonal harmonics:
:mod:`hamilton_orbits.effects.zonal`.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from hamilton_orbits._kernels.jacobians import j2_field_jvp
from hamilton_orbits._kernels.nbody import j2_field
from hamilton_orbits.effects.energy import relative_states
from hamilton_orbits.effects.parameters import parameter_value, source_index
from hamilton_orbits.effects.registry import EffectSpec
from hamilton_orbits.units import DIMENSIONLESS, LENGTH

__all__ = ["SPECS"]


def _params_j2(system: Any, params: Mapping[str, Any]) -> np.ndarray:
    if "body" not in params:
        raise ValueError("Effect 'j2' needs the `body` whose oblateness acts, e.g. "
                         "{'name': 'j2', 'body': 'earth'}")
    b = source_index(system, params, "body", "j2")
    arrays = system.as_arrays()
    body = system.bodies[b]
    j2 = parameter_value(system, params, "j2", "j2", DIMENSIONLESS)
    radius = parameter_value(system, params, "radius", "j2", LENGTH)
    j2 = body.j2 if j2 is None else j2
    radius = (float(arrays.radius[b]) if np.isfinite(arrays.radius[b]) else None
              ) if radius is None else radius
    missing = [k for k, v in (("j2", j2), ("radius", radius)) if v is None]
    if missing:
        raise ValueError(
            f"Effect 'j2': body {body.name!r} has no {' and no '.join(missing)} (give "
            f"{' and '.join(missing)} to the Body, or in the effect's mapping)"
        )
    if not radius > 0:
        raise ValueError(f"Effect 'j2': expected `radius` > 0, got {params['radius']!r}")
    pole = body.pole if body.pole is not None else (0.0, 0.0, 1.0)
    return np.array([b, j2, radius, *pole])


def _energy_j2(r: np.ndarray, v: np.ndarray, gm: np.ndarray, p: np.ndarray) -> np.ndarray:
    """The degree-2 zonal potential ``J2 mu R^2 (3 z^2 / d^2 - 1) / (2 d^3)`` (the
    potential whose gradient ``j2_field`` applies; Vallado 2013, eq. 8-22)."""
    b, j2, rad = int(p[0]), p[1], p[2]
    d, _, dist = relative_states(r, v, b)
    z = d @ p[3:6]
    out = 0.5 * j2 * gm[b] * rad * rad * (3.0 * z * z / (dist * dist) - 1.0) / dist**3
    out[:, b] = 0.0
    return out


def _body_j2(p: np.ndarray) -> int:
    """The oblate body, or -1 for a J2 of zero (for the refusals of ``zonal`` and
    ``moon_figure`` on the same body)."""
    return int(p[0]) if p[1] != 0.0 else -1


SPECS = (
    EffectSpec(
        "j2",
        "nbody",
        "oblateness J2 of a named body about its pole",
        parameters={
            "body": "the oblate body (required)",
            "j2": "J2 (default: the Body's j2)",
            "radius": "equatorial radius (default: the Body's radius)",
        },
        kernel=j2_field,
        jacobian=j2_field_jvp,
        params=_params_j2,
        parameter_kinds={"j2": DIMENSIONLESS, "radius": LENGTH},
        name_parameters=("body",),
        energy=_energy_j2,
        body_of=_body_j2,
        reference="Vallado (2013), Fundamentals of Astrodynamics, 4th ed., sec. 8.6.1",
    ),
)
