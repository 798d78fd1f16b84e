"""The effects ``gr`` and ``gr_potential``: general relativity from one dominant body.

``gr``
    The first post-Newtonian correction of the one-body metric (Anderson et al.
    1975), velocity dependent: every other body as a test particle in the
    source's field.  reboundx's ``gr`` puts each body's whole Newtonian
    acceleration (the source's pull and every other's) in its 1PN terms: the two
    agree where the source's pull dominates (the planets about the Sun), and
    differ for a body pulled by another (the Moon: 2 km in a year of a
    ``crosscheck`` of Sun, Earth and Moon); ``eih`` is the n-body 1PN equation
    (reboundx's ``gr_full``) for such systems; kernel
    :func:`~hamilton_orbits._kernels.nbody.gr_anderson`, Jacobian
    :func:`~hamilton_orbits._kernels.jacobians.gr_anderson_jvp`.
``gr_potential``
    The perihelion advance from the potential ``-3 (GM / c r)^2`` (Nobili &
    Roxburgh 1986), safe for symplectic maps; kernel
    :func:`~hamilton_orbits._kernels.nbody.gr_potential`, Jacobian
    :func:`~hamilton_orbits._kernels.jacobians.gr_potential_jvp`.

Both take ``p = [source index, c]`` (the source defaults to the most massive body)
and keep an energy.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from hamilton_orbits._kernels.jacobians import gr_anderson_jvp, gr_potential_jvp
from hamilton_orbits._kernels.nbody import gr_anderson, gr_potential
from hamilton_orbits.effects.energy import relative_states
from hamilton_orbits.effects.parameters import source_index, speed_of_light
from hamilton_orbits.effects.registry import EffectSpec
from hamilton_orbits.units import SPEED

__all__ = ["SPECS"]


def _params_gr(system: Any, params: Mapping[str, Any]) -> np.ndarray:
    s = source_index(system, params, "source", "gr")
    c = speed_of_light(system, params, "gr")
    return np.array([s, c])


def _params_gr_potential(system: Any, params: Mapping[str, Any]) -> np.ndarray:
    s = source_index(system, params, "source", "gr_potential")
    c = speed_of_light(system, params, "gr_potential")
    return np.array([s, c])


def _energy_gr(r: np.ndarray, v: np.ndarray, gm: np.ndarray, p: np.ndarray) -> np.ndarray:
    """The first post-Newtonian terms of the specific energy about the source,
    ``(3/8 w^4 + 3/2 mu w^2 / d + 1/2 mu^2 / d^2) / c^2``: with ``w^2 / 2 - mu / d`` the
    energy that the one-body metric's equations of motion (``gr_anderson``) keep
    for a test particle to the order of the 1PN terms themselves (its derivative
    along the motion is of order (v / c)^4: a relative change of 1e-15 at c = 1e4
    in the system's units, falling as 1 / c^4), and to O(m / M v^2 / c^2) for a body
    of mass m."""
    s, c2 = int(p[0]), p[1] * p[1]
    mu = gm[s]
    _, w, dist = relative_states(r, v, s)
    w2 = np.einsum("tij,tij->ti", w, w)
    out = (0.375 * w2 * w2 + 1.5 * mu * w2 / dist + 0.5 * mu * mu / (dist * dist)) / c2
    out[:, s] = 0.0
    return out


def _energy_gr_potential(r: np.ndarray, v: np.ndarray, gm: np.ndarray,
                         p: np.ndarray) -> np.ndarray:
    """The potential ``-3 (mu / (c d))^2`` of Nobili & Roxburgh (1986)."""
    s, c2 = int(p[0]), p[1] * p[1]
    _, _, dist = relative_states(r, v, s)
    out = -3.0 * gm[s] ** 2 / (c2 * dist * dist)
    out[:, s] = 0.0
    return out


# the same two parameters for both: the source and the speed of light
_PARAMETERS = {
    "source": "the dominant body (default: the most massive)",
    "c": "speed of light (default: c in au/day for Quantity systems)",
}

SPECS = (
    EffectSpec(
        "gr",
        "nbody",
        "first post-Newtonian correction from one dominant body (as reboundx 'gr')",
        velocity_dependent=True,
        parameters=_PARAMETERS,
        kernel=gr_anderson,
        jacobian=gr_anderson_jvp,
        params=_params_gr,
        parameter_kinds={"c": SPEED},
        name_parameters=("source",),
        energy=_energy_gr,
        excludes={"gr_potential": "the relativistic perihelion advance of a dominant body "
                                  "(gr_potential is a potential of the same advance; with "
                                  "more than one source, use eih)"},
        reference="Anderson et al. (1975), ApJ 200, 221; reboundx 'gr' (Tamayo et al. 2020)",
    ),
    EffectSpec(
        "gr_potential",
        "nbody",
        "relativistic perihelion advance from a potential -3 (GM / c r)^2 (symplectic-safe)",
        parameters=_PARAMETERS,
        kernel=gr_potential,
        jacobian=gr_potential_jvp,
        params=_params_gr_potential,
        parameter_kinds={"c": SPEED},
        name_parameters=("source",),
        energy=_energy_gr_potential,
        reference="Nobili & Roxburgh (1986), IAU Symp. 114, 105",
    ),
)
