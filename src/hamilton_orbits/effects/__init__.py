"""The effects a simulation may call for, in one registry.

A scene or an ``integrate`` call lists effects by name (``"gr"``) or as mappings
with parameters (``{"name": "j2", "body": "earth"}``).  Only what is listed is
computed: ``hamilton_orbits.rhs.compile_rhs`` builds the right-hand side
from the listed effects' kernels alone, so an effect that is not listed is not in
the compiled function at all (not called, nothing branches on it).

Registry
--------
Effects are registered per *kind* of simulation (``"nbody"``, ``"rotation"``)
with ``register``.  Other packages add effects without ``hamilton_orbits``
importing them: an entry point in the group ``hamilton_orbits.effects`` names a
callable that registers its effects when the kind is first looked up (``rigid``
registers its rotation effects this way).

Normalised once
---------------
``EffectSet.of`` turns what a caller lists into an ``EffectSet``: a
frozen, hashable value, checked against the registry once at the boundary.
Everything downstream (the compiled right-hand side in ``hamilton_orbits.rhs``,
the integrators, rebound's cross-check, scenes) takes the ``EffectSet``.

Where things are
----------------
One module per effect holds everything about it: its ``EffectSpec``
(summary, parameters and their kinds, reference), its parameter builder, its
energy, and its kernel and Jacobian (imported there from
``hamilton_orbits._kernels`` by name).

- ``effects.registry``: ``EffectSpec``, ``register``, :func:`get`, :func:`known`, ``EffectSet``,
  normalisation, :func:`exclusion_problems`, :func:`body_exclusion_problems`, the
  entry points
- ``effects.parameters``: :func:`source_index`, :func:`parameter_value`, :func:`speed_of_light`,
  DE440's defaults
- ``effects.energy``: :func:`effect_energy`, :func:`energy_label`
- ``effects.newtonian``: ``newtonian`` (always present)
- ``effects.relativity``: ``gr``, ``gr_potential``
- ``effects.j2``: ``j2``
- ``effects.eih``: ``eih`` (and ``eih_energy``)
- ``effects.lense_thirring``: ``lense_thirring`` (and ``sun_spin``)
- ``effects.zonal``: ``zonal``
- ``effects.moon_figure``: ``moon_figure``
- ``effects.tides``: ``earth_tides``
- ``effects.kuiper_ring``: ``kuiper_ring`` (and ``kuiper_ring_gm``)
- ``effects.nongrav``: ``nongrav`` (and ``COMET_G``)
- ``effects.semi_active``: ``semi_active``

Examples
--------
>>> known("nbody")  # doctest: +NORMALIZE_WHITESPACE
('earth_tides', 'eih', 'gr', 'gr_potential', 'j2', 'kuiper_ring', 'lense_thirring',
 'moon_figure', 'newtonian', 'nongrav', 'semi_active', 'zonal')
"""

from __future__ import annotations

from hamilton_orbits.effects import (
    eih,
    j2,
    kuiper_ring,
    lense_thirring,
    moon_figure,
    newtonian,
    nongrav,
    relativity,
    semi_active,
    tides,
    zonal,
)
from hamilton_orbits.effects.energy import effect_energy, energy_label
from hamilton_orbits.effects.parameters import (
    C_AU_PER_DAY,
    parameter_value,
    source_index,
    speed_of_light,
)
from hamilton_orbits.effects.registry import (
    EffectSet,
    EffectSpec,
    body_exclusion_problems,
    entry_problems,
    exclusion_problems,
    get,
    known,
    normalize_effects,
    register,
)

__all__ = [
    "BUILT_IN",
    "C_AU_PER_DAY",
    "EffectSet",
    "EffectSpec",
    "body_exclusion_problems",
    "effect_energy",
    "energy_label",
    "entry_problems",
    "exclusion_problems",
    "get",
    "known",
    "normalize_effects",
    "parameter_value",
    "register",
    "source_index",
    "speed_of_light",
]

#: The built-in ``"nbody"`` effects, in the order they are registered.
BUILT_IN: tuple[EffectSpec, ...] = (
    *newtonian.SPECS,
    *relativity.SPECS,
    *j2.SPECS,
    *eih.SPECS,
    *lense_thirring.SPECS,
    *zonal.SPECS,
    *moon_figure.SPECS,
    *tides.SPECS,
    *kuiper_ring.SPECS,
    *nongrav.SPECS,
    *semi_active.SPECS,
)
_ = [register(spec) for spec in BUILT_IN]
