"""The effect ``newtonian``: Newtonian mutual gravitation, Hamilton's equation (B).

Always present, so never listed (listing it changes nothing): every compiled
right-hand side (:mod:`hamilton_orbits.rhs`) starts from :data:`KERNEL`, unless a
listed effect replaces it (``eih``); without effects the right-hand side is
:data:`KERNEL_ALONE` itself, and the variational equations start from
:data:`JACOBIAN`.  Its energy is Hamilton's integral (E) itself
(:meth:`hamilton_orbits.nbody.System.energy`).
"""

from __future__ import annotations

from hamilton_orbits._kernels.jacobians import newtonian_jvp
from hamilton_orbits._kernels.nbody import newtonian, newtonian_only
from hamilton_orbits.effects.registry import EffectSpec

__all__ = ["JACOBIAN", "KERNEL", "KERNEL_ALONE", "SPECS"]

#: ``newtonian(r, v, gm, acc)``: overwrites ``acc`` with the Newtonian accelerations.
KERNEL = newtonian
#: ``newtonian_only(r, v, gm, acc, p)``: the right-hand side of no effect.
KERNEL_ALONE = newtonian_only
#: ``newtonian_jvp(r, v, gm, dr, dv, da)``: the Newtonian Jacobian on tangent vectors.
JACOBIAN = newtonian_jvp

SPECS = (
    EffectSpec(
        "newtonian",
        "nbody",
        "Newtonian mutual gravitation, Hamilton's equation (B); always present",
        reference="Hamilton (1845), equation (B)",
    ),
)
