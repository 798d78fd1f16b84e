"""The effect ``eih``: the Einstein-Infeld-Hoffmann equations for every body.

Newtonian gravity plus its first post-Newtonian correction, PPN beta = gamma = 1
as DE440 has them, *replacing* Newtonian gravity (``replaces_newtonian``: the
right-hand side starts from zero); ``gr`` and ``gr_potential`` are refused beside
it (their terms are in it already).  Kernel
:func:`~hamilton_orbits._kernels.relativity.eih`; no analytic Jacobian (three
pages of terms): the variational equations differentiate the kernel by compiled
central differences (:mod:`hamilton_orbits.rhs`).  ``p = [c, beta, gamma,
source indices...]`` (no sources: every massive body).  Its conserved energy
(to second post-Newtonian order) is :func:`eih_energy`, not registered: the
reported energy error of a run with ``eih`` is the Newtonian one.

References
----------
T. D. Moyer, *Formulation for Observed and Computed Values of Deep Space Network
Data Types for Navigation*, JPL DESCANSO monograph 2 (2003), eq. 4-26.
R. S. Park, W. M. Folkner, J. G. Williams, D. H. Boggs, AJ 161, 105 (2021), eq. 1.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from hamilton_orbits import ephemeris as de
from hamilton_orbits._kernels.relativity import eih
from hamilton_orbits.effects.parameters import (
    PARK_2021,
    body_list,
    de440_c_au_per_day,
    require_de440_units,
    scalar_parameter,
)
from hamilton_orbits.effects.registry import EffectSpec
from hamilton_orbits.units import DIMENSIONLESS, SPEED

__all__ = ["SPECS", "eih_energy"]


def _params_eih(system: Any, params: Mapping[str, Any]) -> np.ndarray:
    require_de440_units(system, params, "eih", ("c",))
    c = scalar_parameter(system, params, "c", "eih", SPEED, de440_c_au_per_day(),
                         positive=True)
    beta = scalar_parameter(system, params, "beta", "eih", DIMENSIONLESS, de.constant("BETA"))
    gamma = scalar_parameter(system, params, "gamma", "eih", DIMENSIONLESS,
                             de.constant("GAMMA"))
    sources = body_list(system, params, "sources", "eih")
    gm = system.as_arrays().gm
    for k, b in enumerate(sources):
        if not gm[b] > 0:  # (its 1PN field would be dropped silently: ``gr`` refuses it)
            raise ValueError(f"Effect 'eih': `sources` names body {system.names[b]!r} (at "
                             f"index {k}), which is massless (gm = 0): it has no field")
    semi = body_list(system, params, "semi_active", "eih")
    if semi and len(semi) == len(system.names):
        raise ValueError("Effect 'eih': `semi_active` lists every body, so that none would "
                         "pull on another")
    for b in semi:
        if b in sources:
            raise ValueError(f"Effect 'eih': {system.names[b]!r} is both a source and "
                             f"semi-active (a semi-active body acts by Newton's law)")
    # (the semi-active bodies after the sources, as -1 - index: relativity.eih)
    return np.array([c, beta, gamma, *sources, *(-1.0 - b for b in semi)], dtype=float)


SPECS = (
    EffectSpec(
        name="eih", kind="nbody",
        summary="Einstein-Infeld-Hoffmann 1PN n-body gravity (replaces Newtonian; radau15)",
        velocity_dependent=True, replaces_newtonian=True,
        parameters={"c": "speed of light, a speed (default DE440's CLIGHT)",
                    "beta": "PPN beta (default DE440's, 1)",
                    "gamma": "PPN gamma (default DE440's, 1)",
                    "sources": "bodies whose 1PN field is computed (default every "
                               "massive body but the semi-active ones; the others act "
                               "by Newton's law)",
                    "semi_active": "bodies that pull on every other body and feel every "
                                   "other body, but not each other (rebound's "
                                   "testparticle_type = 1; none a source)"},
        kernel=eih, params=_params_eih,
        parameter_kinds={"c": SPEED, "beta": DIMENSIONLESS, "gamma": DIMENSIONLESS},
        excludes={"gr": "the first post-Newtonian terms of the dominant body",
                  "gr_potential": "the relativistic perihelion advance"},
        reference=f"Moyer (2003), DESCANSO monograph 2, eq. 4-26; {PARK_2021}",
    ),
)


def eih_energy(r: np.ndarray, v: np.ndarray, gm: np.ndarray, c: float) -> float:
    """The conserved energy of the EIH equations, in gm units (G times the energy).

    The Einstein-Infeld-Hoffmann Lagrangian (Landau & Lifshitz, *The Classical
    Theory of Fields*, eq. 106.17) gives, with ``n_ab`` the unit vector from b to a,

        E = sum_a gm_a v_a^2 / 2 + 3/(8 c^2) sum_a gm_a v_a^4
            - 1/2 sum_{a != b} gm_a gm_b / r_ab
            + 1/c^2 sum_{a != b} gm_a gm_b / r_ab
                  [3 v_a^2 / 2 - (7 v_a . v_b + (v_a . n_ab)(v_b . n_ab)) / 4]
            + 1/(2 c^2) sum_a sum_{b != a} sum_{k != a} gm_a gm_b gm_k / (r_ab r_ak),

    which the EIH accelerations of the ``eih`` effect (PPN beta = gamma = 1) conserve
    up to second post-Newtonian order.

    Parameters
    ----------
    r, v : ndarray, shape (n, 3)
    gm : ndarray, shape (n,)
    c : float
        The speed of light in the same units.

    Examples
    --------
    >>> r = np.array([[0.0, 0, 0], [1.0, 0, 0]])
    >>> v = np.array([[0.0, 0, 0], [0.0, 1.0, 0]])
    >>> eih_energy(r, v, np.array([1.0, 0.0]), 1e8)  # a test particle adds nothing
    0.0
    """
    r = np.asarray(r, dtype=float)
    v = np.asarray(v, dtype=float)
    gm = np.asarray(gm, dtype=float)
    c2 = float(c) ** 2
    d = r[:, None, :] - r[None, :, :]  # r_a - r_b
    dist = np.sqrt(np.einsum("abk,abk->ab", d, d))
    np.fill_diagonal(dist, np.inf)
    inv = 1.0 / dist
    n = d * inv[:, :, None]
    v2 = np.einsum("ak,ak->a", v, v)
    gg = gm[:, None] * gm[None, :] * inv
    vv = v @ v.T
    van = np.einsum("abk,ak->ab", n, v)  # v_a . n_ab
    vbn = np.einsum("abk,bk->ab", n, v)  # v_b . n_ab
    pair = np.sum(gg * (1.5 * v2[:, None] - 0.25 * (7.0 * vv + van * vbn))) / c2
    phi = (gm[None, :] * inv).sum(axis=1)  # sum_{b != a} gm_b / r_ab
    triple = np.sum(gm * phi * phi) / (2.0 * c2)
    newton = 0.5 * np.sum(gm * v2) - 0.5 * np.sum(gg)
    return float(newton + 3.0 / (8.0 * c2) * np.sum(gm * v2 * v2) + pair + triple)
