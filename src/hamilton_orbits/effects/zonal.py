"""The effect ``zonal``: zonal harmonics J2..Jn of one body about its pole.

For the Earth (the default) DE440's ``RE``, ``J2E``, ``J3E``, ``J4E``, acting on
every other body (the Moon above all); another body needs ``j`` and ``radius``.
Kernel :func:`~hamilton_orbits._kernels.figures.zonal_of_date` (it knows the
time), Jacobian :func:`~hamilton_orbits._kernels.jacobians.zonal_of_date_jvp`;
``p = [the pole of date's 10 numbers, body index, radius, pole x, y, z, J2, J3,
...]`` (:func:`~hamilton_orbits.effects.parameters.pole_of_date`).  With
``pole = "IAU2006"`` the pole is the Earth's of each time (the IAU 2006
precession), else fixed.  It keeps no registered energy.  J2 alone about any
body: :mod:`hamilton_orbits.effects.j2`.

References
----------
T. D. Moyer, JPL Technical Report 32-1527 (1971), eqs. 173-174.
R. S. Park, W. M. Folkner, J. G. Williams, D. H. Boggs, AJ 161, 105 (2021).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from hamilton_orbits import ephemeris as de
from hamilton_orbits._kernels.figures import OF_DATE, zonal_of_date
from hamilton_orbits._kernels.jacobians import zonal_of_date_jvp
from hamilton_orbits.effects.parameters import (
    EPOCH_PARAMETER,
    FRAME_PARAMETER,
    PARK_2021,
    POLE_PARAMETER,
    body_index,
    finite_floats,
    pole_of_date,
    scalar_parameter,
)
from hamilton_orbits.effects.registry import EffectSpec
from hamilton_orbits.units import LENGTH

__all__ = ["SPECS"]


def _params_zonal(system: Any, params: Mapping[str, Any]) -> np.ndarray:
    b = body_index(system, params, "body", "earth", "zonal", massive=True)
    if system.names[b] != "earth" or not system.quantity:
        for key in ("j", "radius"):
            if key not in params:
                raise ValueError(f"Effect 'zonal': body {system.names[b]!r} needs `{key}` "
                                 "(DE440's defaults are the Earth's, in au)")
    j = finite_floats("j", params.get("j", [de.constant(f"J{n}E") for n in (2, 3, 4)]), None,
                "zonal")
    if j.size == 0:
        raise ValueError("Effect 'zonal': expected `j` to be [J2, J3, ...], at least J2, "
                         "got an empty list")
    radius = scalar_parameter(system, params, "radius", "zonal", LENGTH,
                              de.constant("RE") / de.constant("AU"), positive=True)
    lead = pole_of_date(system, b, params, "zonal")
    return np.array([*lead[:OF_DATE], b, radius, *lead[OF_DATE:], *j])


def _body_zonal(p: np.ndarray) -> int:
    """The body of the harmonics, or -1 for a J2 of zero (``j = [0, J3, ...]``: the
    J2 left to ``j2``)."""
    return int(p[OF_DATE]) if p[OF_DATE + 5] != 0.0 else -1


SPECS = (
    EffectSpec(
        name="zonal", kind="nbody",
        summary="zonal harmonics J2..Jn of one body (default the Earth's J2, J3, J4)",
        parameters={"body": "the body (default 'earth')",
                    "j": "[J2, J3, ...] (default DE440's J2E, J3E, J4E)",
                    "radius": "reference radius, a length (default DE440's RE)",
                    "pole": POLE_PARAMETER, "epoch": EPOCH_PARAMETER,
                    "frame": FRAME_PARAMETER},
        kernel=zonal_of_date, params=_params_zonal,
        parameter_kinds={"radius": LENGTH}, name_parameters=("body",),
        jacobian=zonal_of_date_jvp,
        same_body_excludes={"j2": "its body's J2 (the first of its `j`)"},
        body_of=_body_zonal,
        reference=f"Moyer (1971), JPL TR 32-1527, eqs. 173-174; {PARK_2021}",
    ),
)
