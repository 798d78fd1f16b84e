"""The effect ``semi_active``: Newton's law in which the listed bodies do not pull on
each other.

Semi-active bodies (rebound's test particles of type 1, ``sim.testparticle_type =
1``: its tutorial ``ipython_examples/Testparticles.ipynb``) pull on every other
body and feel every other body, as massive bodies do, but their pairs are left
out: the 16 asteroids of the ``de440-century`` ladder then cost ``16 N`` pairs, not
``16 N + 120``.  The effect replaces the Newtonian kernel
(``replaces_newtonian``); with ``eih``, which replaces it too, the same rule is
``eih``'s own ``semi_active`` parameter.  Kernel
:func:`~hamilton_orbits._kernels.nbody.newtonian_semi_active`; no analytic
Jacobian (the variational equations difference the kernel).  ``p`` = the
semi-active bodies' indices.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from hamilton_orbits._kernels.nbody import newtonian_semi_active
from hamilton_orbits.effects.parameters import body_list
from hamilton_orbits.effects.registry import EffectSpec

__all__ = ["SPECS"]


def _params_semi_active(system: Any, params: Mapping[str, Any]) -> np.ndarray:
    bodies = body_list(system, params, "bodies", "semi_active")
    if not bodies:
        raise ValueError("Effect 'semi_active' needs the `bodies` that do not pull on each "
                         "other, e.g. {'name': 'semi_active', 'bodies': ['ceres', 'vesta']}")
    if len(bodies) == len(system.names):
        raise ValueError("Effect 'semi_active': `bodies` lists every body, so that none "
                         "would pull on another; list only those that do not pull on each "
                         "other")
    return np.array(bodies, dtype=float)


SPECS = (
    EffectSpec(
        name="semi_active", kind="nbody",
        summary="Newtonian gravity in which the listed bodies do not pull on each other "
                "(rebound's testparticle_type = 1; replaces Newtonian)",
        replaces_newtonian=True,
        parameters={"bodies": "the semi-active bodies: they pull on every other body and "
                              "feel every other body, but not each other"},
        kernel=newtonian_semi_active, params=_params_semi_active,
        excludes={"eih": "Newtonian gravity (with eih, list the bodies as its own "
                         "`semi_active`)"},
        reference="rebound's test particles of type 1 (testparticle_type = 1; its "
                  "tutorial ipython_examples/Testparticles.ipynb)",
    ),
)
