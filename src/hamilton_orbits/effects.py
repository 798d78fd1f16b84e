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

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numba import njit

from hamilton_orbits._kernels import nbody as _nbody

__all__ = [
    "RHS",
    "EffectSpec",
    "compile_rhs",
    "get",
    "known",
    "newtonian_rhs",
    "normalize_effects",
    "register",
]


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
        Kind-specific builder (``"rotation"`` effects: a model from keyword
        parameters).
    reference : str
        The source of the model (paper, equation).
    kernel : numba dispatcher or None
        ``"nbody"`` effects: a module-level compiled ``kernel(r, v, gm, acc, p)``
        that *adds* the effect's acceleration to ``acc`` (float64 arrays (n, 3),
        (n, 3), (n,), (n, 3)); ``p`` is the effect's own float64 parameter vector.
    params : callable or None
        ``"nbody"`` effects: ``params(system, mapping) -> ndarray`` (1-d float64),
        the parameter vector ``p`` for ``system`` (a
        :class:`~hamilton_orbits.nbody.System`) from the effect's mapping without
        its ``"name"``; raises ``ValueError`` for bad parameters.
    replaces_newtonian : bool
        True if ``kernel`` computes the whole point-mass interaction itself (as the
        Einstein-Infeld-Hoffmann equations do): the Newtonian kernel is then left
        out of the right-hand side.
    """

    name: str
    kind: str
    summary: str
    velocity_dependent: bool = False
    parameters: Mapping[str, str] = field(default_factory=dict)
    build: Callable[..., Any] | None = None
    reference: str = ""
    kernel: Any = None
    params: Callable[..., np.ndarray] | None = None
    replaces_newtonian: bool = False


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


# ----------------------------------------------------------------------------------
# Composition: exactly the listed effects, nothing else.


def normalize_effects(
    effects: Sequence[str | Mapping[str, Any]] | None, kind: str = "nbody"
) -> tuple[tuple[str, tuple[tuple[str, Any], ...]], ...]:
    """Effects as ``((name, ((key, value), ...)), ...)``, checked against the registry.

    ``"newtonian"`` may be listed and is dropped (it is always present).

    Raises
    ------
    ValueError
        For an unknown name (listing the known ones), an entry that is neither a
        name nor a mapping with a ``"name"``, a parameter the effect does not take,
        or an effect listed twice; naming the index and the value.

    Examples
    --------
    >>> normalize_effects(["gr", {"name": "j2", "body": "earth"}])
    (('gr', ()), ('j2', (('body', 'earth'),)))
    >>> normalize_effects([{"name": "j2", "bdy": "earth"}])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Effect 'j2' at index 0 takes no parameter 'bdy'; it takes: body, ...
    """
    if effects is None:
        return ()
    if isinstance(effects, (str, Mapping)):
        effects = [effects]
    out = []
    seen: set[str] = set()
    for k, item in enumerate(effects):
        if isinstance(item, str):
            name, params = item, {}
        elif isinstance(item, Mapping) and isinstance(item.get("name"), str):
            name = item["name"]
            params = {key: val for key, val in item.items() if key != "name"}
        else:
            raise ValueError(
                f"Expected `effects` to hold names or mappings with a 'name', got {item!r} "
                f"at index {k}"
            )
        spec = get(kind, name)
        for key in params:
            if key not in spec.parameters:
                takes = ", ".join(spec.parameters) or "none"
                raise ValueError(
                    f"Effect {name!r} at index {k} takes no parameter {key!r}; it takes: {takes}"
                )
        if name == "newtonian":
            continue
        if name in seen:
            raise ValueError(f"Effect {name!r} is listed twice (again at index {k})")
        seen.add(name)
        out.append((name, tuple(sorted(params.items()))))
    return tuple(out)


def _chain(first: Any, second: Any) -> Any:
    """A compiled ``f(r, v, gm, acc)`` calling ``first`` then ``second``."""

    @njit
    def chained(r, v, gm, acc):  # pragma: no cover - compiled
        first(r, v, gm, acc)
        second(r, v, gm, acc)

    return chained


def bind(kernel: Any, p: np.ndarray) -> Any:
    """A compiled ``f(r, v, gm, acc)`` calling ``kernel(r, v, gm, acc, p)``.

    ``p`` is frozen into the compiled function as a constant.
    """
    p = np.ascontiguousarray(p, dtype=np.float64)

    @njit
    def bound(r, v, gm, acc):  # pragma: no cover - compiled
        kernel(r, v, gm, acc, p)

    return bound


def _key(system: Any) -> tuple:
    """What a compiled right-hand side depends on besides the state: bodies' shapes."""
    return (
        system.names,
        tuple(system._gm.tolist()),
        tuple((b._radius, b.j2, b.pole) for b in system.bodies),
        system.quantity,
    )


def compile_rhs(system: Any, effects: Sequence[str | Mapping[str, Any]] | None = ()) -> RHS:
    """The right-hand side of ``system`` with exactly the listed ``effects``.

    With no effects this is the cached Newtonian kernel itself; otherwise each
    listed effect's compiled adder is chained after it, so that an effect that is
    not listed is not in the compiled function at all.

    Parameters
    ----------
    system : hamilton_orbits.nbody.System
    effects : sequence of str or mapping
        Names (``"gr"``) or mappings with parameters (``{"name": "j2", "body":
        "earth"}``).

    Examples
    --------
    >>> from hamilton_orbits import Body, System
    >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0])])
    >>> compile_rhs(s).effects
    ('newtonian',)
    >>> compile_rhs(s, ["gr"]).velocity_dependent  # doctest: +SKIP
    True
    """
    normal = normalize_effects(effects, "nbody")
    if not normal:
        return newtonian_rhs()
    return _compile_cached(_key(system), normal, system)


_COMPILED: dict[tuple, RHS] = {}


def _compile_cached(key: tuple, normal: tuple, system: Any) -> RHS:
    cache_key = (key, normal)
    if cache_key in _COMPILED:
        return _COMPILED[cache_key]
    adders = []
    velocity_dependent = False
    newtonian = True
    for name, params in normal:
        spec = get("nbody", name)
        if spec.kernel is None or spec.params is None:
            raise ValueError(f"Effect {name!r} cannot be used in an n-body simulation")
        adders.append(bind(spec.kernel, spec.params(system, dict(params))))
        velocity_dependent = velocity_dependent or spec.velocity_dependent
        newtonian = newtonian and not spec.replaces_newtonian
    extra = adders[0]
    for adder in adders[1:]:
        extra = _chain(extra, adder)
    accel = _chain(_nbody.newtonian, extra) if newtonian else _chain(_nbody.zero, extra)
    rhs = RHS(accel, extra, velocity_dependent, ("newtonian",) + tuple(n for n, _ in normal))
    if len(_COMPILED) > 64:
        _COMPILED.clear()
    _COMPILED[cache_key] = rhs
    return rhs


# ----------------------------------------------------------------------------------
# Built-in n-body effects.

_C_AU_PER_DAY = 299792458.0 * 86400.0 / 149597870700.0  # IAU 2012 au, SI c and day


def _source_index(system: Any, params: Mapping[str, Any], key: str, effect: str) -> int:
    name = params.get(key)
    if name is None:
        return int(np.argmax(system._gm))
    if name not in system.names:
        raise ValueError(
            f"Effect {effect!r}: `{key}` names body {name!r}, which is not in the system; "
            f"bodies: {', '.join(system.names)}"
        )
    idx = system.names.index(name)
    if not system._gm[idx] > 0:
        raise ValueError(f"Effect {effect!r}: body {name!r} is massless (gm = 0)")
    return idx


def _speed_of_light(system: Any, params: Mapping[str, Any], effect: str) -> float:
    from hamilton_orbits.units import SPEED, is_quantity

    c = params.get("c")
    if c is None:
        if system.quantity:
            return _C_AU_PER_DAY
        raise ValueError(
            f"Effect {effect!r}: a system of plain floats needs the speed of light `c` in "
            "its own units, e.g. {'name': 'gr', 'c': 10065.32}"
        )
    if system.quantity and not is_quantity(c):
        raise ValueError(
            f"Effect {effect!r}: expected `c` as a Quantity for a Quantity system, got {c!r}"
        )
    import astropy.units as u

    value = float(SPEED("c", c, u.au / u.day if system.quantity else None))
    if not (np.isfinite(value) and value > 0):
        raise ValueError(f"Effect {effect!r}: expected `c` > 0 and finite, got {value!r}")
    return value


def _params_gr(system: Any, params: Mapping[str, Any]) -> np.ndarray:
    s = _source_index(system, params, "source", "gr")
    c = _speed_of_light(system, params, "gr")
    return np.array([s, c])


def _params_gr_potential(system: Any, params: Mapping[str, Any]) -> np.ndarray:
    s = _source_index(system, params, "source", "gr_potential")
    c = _speed_of_light(system, params, "gr_potential")
    return np.array([s, c])


def _params_j2(system: Any, params: Mapping[str, Any]) -> np.ndarray:
    if "body" not in params:
        raise ValueError("Effect 'j2' needs the `body` whose oblateness acts, e.g. "
                         "{'name': 'j2', 'body': 'earth'}")
    b = _source_index(system, params, "body", "j2")
    body = system.bodies[b]
    j2 = params.get("j2", body.j2)
    radius = params.get("radius", body._radius)
    if j2 is None or radius is None:
        raise ValueError(
            f"Effect 'j2': body {body.name!r} needs `j2` and `radius` (give them to the "
            "Body or in the effect's mapping)"
        )
    if "radius" in params:
        import astropy.units as u

        from hamilton_orbits.units import LENGTH

        radius = float(LENGTH("radius", radius, u.au if system.quantity else None))
    j2 = float(j2)
    if not (np.isfinite(j2) and np.isfinite(radius) and radius > 0):
        raise ValueError(f"Effect 'j2': expected finite j2 and radius > 0, got {j2!r}, {radius!r}")
    pole = body.pole if body.pole is not None else (0.0, 0.0, 1.0)
    return np.array([b, j2, radius, *pole])


register(
    EffectSpec(
        "gr",
        "nbody",
        "first post-Newtonian correction from one dominant body (as reboundx 'gr')",
        velocity_dependent=True,
        parameters={
            "source": "the dominant body (default: the most massive)",
            "c": "speed of light (default: c in au/day for Quantity systems)",
        },
        kernel=_nbody.gr_anderson,
        params=_params_gr,
        reference="Anderson et al. (1975), ApJ 200, 221; reboundx 'gr' (Tamayo et al. 2020)",
    )
)
register(
    EffectSpec(
        "gr_potential",
        "nbody",
        "relativistic perihelion advance from a potential -3 (GM / c r)^2 (symplectic-safe)",
        parameters={
            "source": "the dominant body (default: the most massive)",
            "c": "speed of light (default: c in au/day for Quantity systems)",
        },
        kernel=_nbody.gr_potential,
        params=_params_gr_potential,
        reference="Nobili & Roxburgh (1986), IAU Symp. 114, 105",
    )
)
register(
    EffectSpec(
        "j2",
        "nbody",
        "oblateness J2 of a named body about its pole",
        parameters={
            "body": "the oblate body (required)",
            "j2": "J2 (default: the Body's j2)",
            "radius": "equatorial radius (default: the Body's radius)",
        },
        kernel=_nbody.j2_field,
        params=_params_j2,
        reference="Vallado (2013), Fundamentals of Astrodynamics, 4th ed., sec. 8.6.1",
    )
)

from hamilton_orbits.effects_solar_system import SPECS as _SOLAR_SYSTEM  # noqa: E402

_ = [register(EffectSpec(**spec)) for spec in _SOLAR_SYSTEM]  # eih, zonal, tides, ... (DE440)
