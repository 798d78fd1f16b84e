"""The effects a simulation may call for, in one registry.

A scene or an ``integrate`` call lists effects by name (``"gr"``) or as mappings
with parameters (``{"name": "j2", "body": "earth"}``).  Only what is listed is
computed: :func:`compile_rhs` builds the right-hand side from the listed
effects' kernels alone, so an effect that is not listed is not in the compiled
function at all (not called, nothing branches on it).

Registry
--------
Effects are registered per *kind* of simulation (``"nbody"``, ``"rotation"``)
with :func:`register`.  Other packages add effects without ``hamilton_orbits``
importing them: an entry point in the group ``hamilton_orbits.effects`` names a
callable that registers its effects when the kind is first looked up (``rigid``
registers its rotation effects this way).

The right-hand side contract
----------------------------
An :class:`RHS` carries compiled functions with the signature
``f(r, v, gm, acc)`` (float64 arrays (n, 3), (n, 3), (n,), (n, 3)):

- ``accel`` overwrites ``acc`` with the total acceleration (Newtonian plus the
  listed effects);
- ``extra`` *adds* the listed effects' accelerations only (``None`` when no
  effect is listed); splitting integrators (Wisdom-Holman) use it for their kicks.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from hamilton_orbits._kernels import nbody as _nbody

__all__ = ["RHS", "EffectSpec", "get", "known", "newtonian_rhs", "register"]


@dataclass(frozen=True)
class EffectSpec:
    """One registered effect.

    Parameters
    ----------
    name : str
        The name a scene or a call uses (``"gr"``).
    kind : str
        The kind of simulation it belongs to (``"nbody"`` or ``"rotation"``).
    summary : str
        One line for listings (``hamilton-orbits scenes``).
    velocity_dependent : bool
        True if the force depends on velocities (refused by symplectic maps).
    parameters : Mapping[str, str]
        Parameter name -> description, for validation and documentation.
    build : callable or None
        Kind-specific builder; for ``"nbody"``: ``build(system, params)`` returns
        a compiled ``f(r, v, gm, acc)`` adding the effect's acceleration.
    reference : str
        The source of the model (paper, equation).
    """

    name: str
    kind: str
    summary: str
    velocity_dependent: bool = False
    parameters: Mapping[str, str] = field(default_factory=dict)
    build: Callable[..., Any] | None = None
    reference: str = ""


_REGISTRY: dict[str, dict[str, EffectSpec]] = {}
_LOADED_ENTRY_POINTS: set[str] = set()


def register(spec: EffectSpec) -> EffectSpec:
    """Add ``spec`` to the registry (replacing one of the same kind and name).

    Examples
    --------
    >>> spec = register(EffectSpec("example", "test-kind", "does nothing"))
    >>> known("test-kind")
    ('example',)
    """
    _REGISTRY.setdefault(spec.kind, {})[spec.name] = spec
    return spec


def _load_entry_points() -> None:
    from importlib.metadata import entry_points

    for ep in entry_points(group="hamilton_orbits.effects"):
        if ep.name not in _LOADED_ENTRY_POINTS:
            _LOADED_ENTRY_POINTS.add(ep.name)
            ep.load()()


def known(kind: str) -> tuple[str, ...]:
    """The effect names registered for ``kind``, sorted.

    Examples
    --------
    >>> "newtonian" in known("nbody")
    True
    """
    if kind not in _REGISTRY:
        _load_entry_points()
    return tuple(sorted(_REGISTRY.get(kind, {})))


def get(kind: str, name: str) -> EffectSpec:
    """The registered effect ``name`` of ``kind``.

    Raises
    ------
    ValueError
        For an unknown name, listing the known ones and the closest matches.

    Examples
    --------
    >>> get("nbody", "newtonian").kind
    'nbody'
    >>> get("nbody", "newtonain")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Unknown nbody effect 'newtonain' (did you mean 'newtonian'?); known: ...
    """
    import difflib

    names = known(kind)
    if name not in names:
        close = difflib.get_close_matches(name, names, n=3)
        hint = f" (did you mean {', '.join(repr(c) for c in close)}?)" if close else ""
        raise ValueError(
            f"Unknown {kind} effect {name!r}{hint}; known: {', '.join(names) or 'none'}"
        )
    return _REGISTRY[kind][name]


@dataclass(frozen=True)
class RHS:
    """A compiled right-hand side built from exactly the listed effects.

    Attributes
    ----------
    accel : numba dispatcher
        ``accel(r, v, gm, acc)``: overwrites ``acc`` with the total acceleration.
    extra : numba dispatcher or None
        ``extra(r, v, gm, acc)``: adds the listed effects only; None if none.
    velocity_dependent : bool
        True if any listed effect depends on velocities.
    effects : tuple of str
        The names of what is computed, ``"newtonian"`` first.
    """

    accel: Any
    extra: Any
    velocity_dependent: bool
    effects: tuple[str, ...]


def newtonian_rhs() -> RHS:
    """The right-hand side of Newtonian gravity alone (Hamilton's equation (B)).

    Examples
    --------
    >>> newtonian_rhs().effects
    ('newtonian',)
    """
    return RHS(_nbody.newtonian, None, False, ("newtonian",))


register(
    EffectSpec(
        "newtonian",
        "nbody",
        "Newtonian mutual gravitation, Hamilton's equation (B); always present",
        reference="Hamilton (1845), equation (B)",
    )
)
