"""Deprecated: the solar-system effects moved, one module each, into :mod:`hamilton_orbits.effects`.

``eih_energy`` is in :mod:`hamilton_orbits.effects.eih`, ``sun_spin`` in
:mod:`hamilton_orbits.effects.lense_thirring`, ``kuiper_ring_gm`` and
``KUIPER_RING_RADIUS_AU`` in :mod:`hamilton_orbits.effects.kuiper_ring`,
``MOON_EQUATOR_INCLINATION_DEG`` in :mod:`hamilton_orbits.effects.moon_figure`,
``EARTH_ROTATION_RATE`` in :mod:`hamilton_orbits.effects.tides`; ``SPECS`` (the
keyword arguments of their :class:`~hamilton_orbits.effects.EffectSpec`) is
:data:`hamilton_orbits.effects.BUILT_IN`.  Each name used here still works and
emits a ``DeprecationWarning`` naming its new place.
"""

from __future__ import annotations

import importlib
import warnings
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # pragma: no cover
    from hamilton_orbits.effects.eih import eih_energy
    from hamilton_orbits.effects.kuiper_ring import KUIPER_RING_RADIUS_AU, kuiper_ring_gm
    from hamilton_orbits.effects.lense_thirring import sun_spin
    from hamilton_orbits.effects.moon_figure import MOON_EQUATOR_INCLINATION_DEG
    from hamilton_orbits.effects.tides import EARTH_ROTATION_RATE

__all__ = [
    "EARTH_ROTATION_RATE",
    "KUIPER_RING_RADIUS_AU",
    "MOON_EQUATOR_INCLINATION_DEG",
    "eih_energy",
    "kuiper_ring_gm",
    "sun_spin",
]

_MOVED = {
    "EARTH_ROTATION_RATE": "hamilton_orbits.effects.tides",
    "KUIPER_RING_RADIUS_AU": "hamilton_orbits.effects.kuiper_ring",
    "MOON_EQUATOR_INCLINATION_DEG": "hamilton_orbits.effects.moon_figure",
    "eih_energy": "hamilton_orbits.effects.eih",
    "kuiper_ring_gm": "hamilton_orbits.effects.kuiper_ring",
    "sun_spin": "hamilton_orbits.effects.lense_thirring",
}
_SOLAR_SYSTEM = ("eih", "lense_thirring", "zonal", "moon_figure", "earth_tides", "kuiper_ring")


def _specs() -> tuple[dict[str, Any], ...]:
    """The solar-system effects' specs as the keyword arguments they were given."""
    from dataclasses import fields

    from hamilton_orbits.effects import get

    out = []
    for name in _SOLAR_SYSTEM:
        spec = get("nbody", name)
        blank = type(spec)(spec.name, spec.kind, spec.summary)
        out.append({f.name: getattr(spec, f.name) for f in fields(spec)
                    if f.name in ("name", "kind", "summary")
                    or getattr(spec, f.name) != getattr(blank, f.name)})
    return tuple(out)


def __getattr__(name: str) -> Any:
    if name == "SPECS":
        warnings.warn("hamilton_orbits.effects_solar_system.SPECS is deprecated; the effects "
                      "are registered from hamilton_orbits.effects.BUILT_IN (one module each "
                      "under hamilton_orbits.effects)", DeprecationWarning, stacklevel=2)
        return _specs()
    if name in _MOVED:
        warnings.warn(f"hamilton_orbits.effects_solar_system.{name} is deprecated; use "
                      f"{_MOVED[name]}.{name}", DeprecationWarning, stacklevel=2)
        return getattr(importlib.import_module(_MOVED[name]), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__) | {"SPECS"})
