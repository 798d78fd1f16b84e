"""The effects' energies: what Hamilton's (E) becomes when effects act.

An ``"nbody"`` effect that keeps an energy registers ``energy(r, v, gm, p)``, its
part of each body's specific energy (see :class:`~hamilton_orbits.effects.EffectSpec`);
:func:`effect_energy` sums the listed effects' parts, :func:`energy_label` says
what the reported energy error then measures.  :func:`relative_states` is the
geometry the energies about one body share.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from hamilton_orbits.effects.registry import EffectSet, get

__all__ = ["effect_energy", "energy_label", "relative_states"]


def relative_states(r: np.ndarray, v: np.ndarray, s: int
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Positions and velocities relative to body ``s``, and the distances (1 where
    zero, at ``s`` itself), for states of shape (n_t, n, 3).

    Examples
    --------
    >>> r = np.array([[[0.0, 0, 0], [3.0, 4.0, 0]]])
    >>> relative_states(r, np.zeros_like(r), 0)[2].tolist()
    [[1.0, 5.0]]
    """
    d = r - r[:, s:s + 1]
    w = v - v[:, s:s + 1]
    dist = np.sqrt(np.einsum("tij,tij->ti", d, d))
    return d, w, np.where(dist > 0, dist, 1.0)


def effect_energy(system: Any, effects: Any, r: np.ndarray, v: np.ndarray
                  ) -> np.ndarray | None:
    """The listed effects' part of every body's specific energy, shape (n_t, n).

    Parameters
    ----------
    system : hamilton_orbits.nbody.System
        The system the effects' parameters are read from.
    effects : EffectSet or sequence
        The effects (normalised by :meth:`EffectSet.of`).
    r, v : ndarray, shape (n_t, n, 3)
        States in the system's internal units.

    Returns
    -------
    ndarray or None
        Zeros without effects; None if a listed effect keeps no energy.

    Examples
    --------
    >>> from hamilton_orbits import Body, System
    >>> s = System([Body("a", 1.0, [0, 0, 0], [0, 0, 0]), Body("b", 0.0, [2.0, 0, 0],
    ...                                                        [0, 1.0, 0])])
    >>> r, v = s.as_arrays().r[None], s.as_arrays().v[None]
    >>> effect_energy(s, [{"name": "gr_potential", "c": 1.0}], r, v).tolist()
    [[0.0, -0.75]]
    """
    eff = EffectSet.of(effects, "nbody")
    gm = system.as_arrays().gm
    total = np.zeros(r.shape[:2])
    for name, params in eff:
        spec = get("nbody", name)
        if spec.energy is None or spec.params is None:
            return None
        total += spec.energy(r, v, gm, spec.params(system, dict(params)))
    return total


def energy_label(gm: np.ndarray, effects: Any, names: Sequence[str] | None = None) -> str:
    """What the relative energy error of a system with ``gm`` and ``effects`` measures.

    Examples
    --------
    >>> energy_label(np.array([1.0, 1e-3]), ["gr"])
    'the total energy with the gr (1PN) terms'
    >>> energy_label(np.array([1.0, 0.0]), [], ["earth", "satellite"])
    "the test particles' specific orbital energy about earth"
    """
    eff = EffectSet.of(effects, "nbody")
    massive = np.flatnonzero(np.asarray(gm) > 0)
    if len(massive) == 1 and len(gm) > 1:
        primary = names[int(massive[0])] if names is not None else "the massive body"
        base = f"the test particles' specific orbital energy about {primary}"
    else:
        base = "the total energy"
    lacking = [n for n in eff.names if get("nbody", n).energy is None]
    if lacking:
        return f"{base}, Newtonian (not conserved under {', '.join(lacking)})"
    if not eff:
        return base
    terms = ", ".join(f"{n} (1PN)" if n == "gr" else n for n in eff.names)
    return f"{base} with the {terms} terms"
