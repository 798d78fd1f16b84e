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

Normalised once
---------------
:meth:`EffectSet.of` turns what a caller lists into an :class:`EffectSet`: a
frozen, hashable value, checked against the registry once at the boundary.
Everything downstream (the compiled right-hand side in :mod:`hamilton_orbits.rhs`,
the integrators, rebound's cross-check, scenes) takes the :class:`EffectSet`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from hamilton_orbits._kernels import jacobians as _jacobians
from hamilton_orbits._kernels import nbody as _nbody
from hamilton_orbits.units import DIMENSIONLESS, LENGTH, SPEED, Kind, is_quantity

__all__ = [
    "C_AU_PER_DAY",
    "EffectSet",
    "EffectSpec",
    "effect_energy",
    "energy_label",
    "entry_problems",
    "get",
    "known",
    "normalize_effects",
    "parameter_value",
    "register",
    "source_index",
    "speed_of_light",
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
    parameter_kinds : Mapping[str, hamilton_orbits.units.Kind]
        The dimension of each scalar parameter that has one (``"c"``: a speed):
        a Quantity of that kind for a Quantity system, a plain number in the
        system's own units otherwise (read by :func:`parameter_value`; a scene
        reads ``"299792.458 km/s"`` into a Quantity of that kind).
    name_parameters : tuple of str
        The parameters that name a body of the system (``"body"``, ``"source"``).
    jacobian : numba dispatcher or None
        ``"nbody"`` effects: a module-level compiled ``jacobian(r, v, gm, dr, dv,
        da, p)`` that *adds* the effect's Jacobian times ``k`` tangent vectors to
        ``da`` (see :mod:`hamilton_orbits._kernels.jacobians`), compiled only when
        the variational equations are asked for.  None: the variational equations
        differentiate ``kernel`` by central differences along each tangent vector
        (compiled, generated in :mod:`hamilton_orbits.rhs`; about 1e-10 relative,
        and two or four evaluations of the kernel per tangent vector).
    energy : callable or None
        ``"nbody"`` effects that keep an energy: ``energy(r, v, gm, p) -> ndarray``
        of shape (n_t, n) for states (n_t, n, 3): the effect's part of each body's
        specific energy (per unit mass; zero for the source), so that Hamilton's
        (E) plus ``sum(gm * energy)`` is conserved (:func:`effect_energy`).  None
        if the effect keeps none (the energy is then reported as not conserved).
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
    parameter_kinds: Mapping[str, Kind] = field(default_factory=dict)
    name_parameters: tuple[str, ...] = ()
    jacobian: Any = None
    energy: Callable[..., np.ndarray] | None = None


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


def entry_problems(item: Any, kind: str = "nbody") -> tuple[str | None, dict, list]:
    """Check one listed effect: ``(name, params, problems)`` with ``problems`` a list
    of ``(key, message)`` (``key`` ``""`` for the entry itself, ``"name"``, or the
    parameter at fault); ``name`` is None when the entry has no valid name.

    Examples
    --------
    >>> entry_problems({"name": "j2", "bdy": "earth"})[2]  # doctest: +ELLIPSIS
    [('bdy', "unknown parameter of effect 'j2' (did you mean 'body'?); it takes: body, ...")]
    >>> entry_problems("grr")[2]  # doctest: +ELLIPSIS
    [('name', "unknown effect 'grr' (did you mean 'gr'...?); known: ...gr, gr_potential, ...")]
    """
    import difflib

    if isinstance(item, str):
        name, params = item, {}
    elif isinstance(item, Mapping) and isinstance(item.get("name"), str):
        name = item["name"]
        params = {key: val for key, val in item.items() if key != "name"}
    else:
        return None, {}, [("", f"expected an effect name or a mapping with a 'name', got "
                               f"{item!r}")]
    names = known(kind)
    if name not in names:
        close = difflib.get_close_matches(name, names, n=3)
        hint = f" (did you mean {', '.join(repr(c) for c in close)}?)" if close else ""
        return None, params, [("name", f"unknown effect {name!r}{hint}; known: "
                                       f"{', '.join(names) or 'none'}")]
    takes = list(get(kind, name).parameters)
    problems = []
    for key in params:
        if key not in takes:
            close = difflib.get_close_matches(str(key), takes, n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            problems.append((key, f"unknown parameter of effect {name!r}{hint}; it takes: "
                                  f"{', '.join(takes) or 'none'}"))
    return name, params, problems


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
    ValueError: Effect at index 0, `bdy`: unknown parameter of effect 'j2' (did you mean 'body'?)...
    """
    if effects is None:
        return ()
    if isinstance(effects, (str, Mapping)):
        effects = [effects]
    if not isinstance(effects, Sequence):
        raise ValueError(f"Expected `effects` to be a list of names or mappings, got {effects!r}")
    out = []
    seen: dict[str, int] = {}
    for k, item in enumerate(effects):
        name, params, problems = entry_problems(item, kind)
        if problems:
            key, message = problems[0]
            where = f", `{key}`" if key and key != "name" else ""
            raise ValueError(f"Effect at index {k}{where}: {message}")
        if name == "newtonian":
            continue
        if name in seen:
            raise ValueError(f"Effect {name!r} is listed twice (at indices {seen[name]} and {k})")
        seen[name] = k
        out.append((name, tuple(sorted(params.items()))))
    return tuple(out)


def _frozen(value: Any) -> Any:
    """A hashable stand-in for a parameter value (a Quantity as value and unit, a
    sequence as a tuple), for :class:`EffectSet`'s equality and hash."""
    unit = getattr(value, "unit", None)
    if unit is not None and hasattr(value, "value"):
        return ("quantity", _frozen(np.asarray(value.value).tolist()), str(unit))
    if isinstance(value, np.ndarray):
        return _frozen(value.tolist())
    if isinstance(value, (list, tuple)):
        return tuple(_frozen(v) for v in value)
    if isinstance(value, Mapping):
        return tuple(sorted((str(k), _frozen(v)) for k, v in value.items()))
    try:
        hash(value)
    except TypeError:  # a set or another unhashable value: compared by its text
        return ("unhashable", type(value).__name__, repr(value))
    return value


@dataclass(frozen=True, eq=False)
class EffectSet:
    """The listed effects, normalised once: a frozen, hashable value.

    Build it with :meth:`of`; iterate over ``(name, params)`` pairs.  Two sets are
    equal when they list the same effects with the same parameters in the same
    order; their hash follows.  The compiled right-hand side depends only on
    :attr:`names` (see :mod:`hamilton_orbits.rhs`).

    Attributes
    ----------
    kind : str
        ``"nbody"`` or ``"rotation"``.
    items : tuple of (str, tuple of (str, object))
        ``(name, ((key, value), ...))`` per listed effect (``"newtonian"`` dropped).

    Examples
    --------
    >>> eff = EffectSet.of(["gr", {"name": "j2", "body": "earth"}])
    >>> eff.names
    ('gr', 'j2')
    >>> eff == EffectSet.of([{"name": "gr"}, {"body": "earth", "name": "j2"}])
    True
    >>> len({eff, EffectSet.of(["gr", {"name": "j2", "body": "earth"}])})
    1
    >>> eff.as_list()
    ['gr', {'name': 'j2', 'body': 'earth'}]
    """

    kind: str
    items: tuple[tuple[str, tuple[tuple[str, Any], ...]], ...]

    @classmethod
    def of(cls, effects: Any, kind: str = "nbody") -> EffectSet:
        """Normalise ``effects`` (an EffectSet of this kind passes through).

        Raises
        ------
        ValueError
            As :func:`normalize_effects`, or for an EffectSet of another kind.
        """
        if isinstance(effects, EffectSet):
            if effects.kind != kind:
                raise ValueError(f"Expected {kind} effects, got an EffectSet of {effects.kind!r}")
            return effects
        return cls(kind, normalize_effects(effects, kind))

    @property
    def names(self) -> tuple[str, ...]:
        """The listed effects' names, in order."""
        return tuple(name for name, _ in self.items)

    @property
    def velocity_dependent(self) -> bool:
        """True if any listed effect depends on velocities."""
        return any(get(self.kind, name).velocity_dependent for name in self.names)

    def as_list(self) -> list[str | dict[str, Any]]:
        """The effects as a caller lists them (names, or mappings with parameters)."""
        return [dict(name=n, **dict(p)) if p else n for n, p in self.items]

    def __iter__(self):
        return iter(self.items)

    def __len__(self) -> int:
        return len(self.items)

    def __bool__(self) -> bool:
        return bool(self.items)

    def _key(self) -> tuple:
        return (self.kind, tuple((n, _frozen(dict(p))) for n, p in self.items))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, EffectSet):
            return NotImplemented
        return self._key() == other._key()

    def __hash__(self) -> int:
        return hash(self._key())

    def __repr__(self) -> str:
        return f"EffectSet({self.as_list()!r})"


# ----------------------------------------------------------------------------------
# Built-in n-body effects.

C_AU_PER_DAY = 299792458.0 * 86400.0 / 149597870700.0  # IAU 2012 au, SI c and day


def source_index(system: Any, params: Mapping[str, Any], key: str, effect: str) -> int:
    """The index of the body that mapping ``params`` names under ``key`` (default: the
    most massive), refusing a name not in ``system`` and a massless body.

    Examples
    --------
    >>> from hamilton_orbits import Body, System
    >>> s = System([Body("a", 1.0, [0, 0, 0], [0, 0, 0]), Body("b", 2.0, [1, 0, 0], [0, 0, 0])])
    >>> source_index(s, {}, "source", "gr"), source_index(s, {"source": "a"}, "source", "gr")
    (1, 0)
    """
    name = params.get(key)
    gm = system.as_arrays().gm
    if name is None:
        return int(np.argmax(gm))
    if not isinstance(name, str):
        raise ValueError(f"Effect {effect!r}: expected `{key}` to be the name of a body, got "
                         f"{name!r}; bodies: {', '.join(system.names)}")
    if name not in system.names:
        raise ValueError(
            f"Effect {effect!r}: `{key}` names body {name!r}, which is not in the system; "
            f"bodies: {', '.join(system.names)}"
        )
    idx = system.names.index(name)
    if not gm[idx] > 0:
        raise ValueError(f"Effect {effect!r}: body {name!r} is massless (gm = 0)")
    return idx


# the internal units of a Quantity system (hamilton_orbits.nbody: au, day)
_SYSTEM_UNITS = {LENGTH: "au", SPEED: "au / d", DIMENSIONLESS: ""}


def parameter_value(system: Any, params: Mapping[str, Any], key: str, effect: str,
                    kind: Kind) -> float | None:
    """The scalar parameter ``key`` of mapping ``params`` in ``system``'s own units,
    or None if it is not given.

    One rule for every dimensioned parameter of every effect: a Quantity of
    ``kind`` for a Quantity system (converted to au, au/day), a plain number in
    the caller's own units for a system of plain floats; a plain number for a
    Quantity system and a Quantity for a system of plain floats are refused (a
    unit cannot be guessed, nor dropped).  A dimensionless parameter takes either.

    Raises
    ------
    ValueError
        For the wrong kind of value, a value that is not one finite number,
        naming the effect, the parameter and the value.
    astropy.units.UnitConversionError
        For a Quantity of the wrong dimension.

    Examples
    --------
    >>> import astropy.units as u
    >>> from hamilton_orbits import Body, System
    >>> s = System([Body("a", 1.0, [0, 0, 0], [0, 0, 0])])
    >>> parameter_value(s, {"c": 10.0}, "c", "gr", SPEED)
    10.0
    >>> parameter_value(s, {"c": 3e5 * u.km / u.s}, "c", "gr", SPEED)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Effect 'gr': expected `c` as a plain number in the units of the system ...
    """
    if key not in params:
        return None
    value = params[key]
    if kind is not DIMENSIONLESS:
        if system.quantity and not is_quantity(value):
            raise ValueError(
                f"Effect {effect!r}: expected `{key}` as a Quantity ({kind.name}, convertible "
                f"to {kind.unit}) for a system of Quantities, got the plain number {value!r}")
        if not system.quantity and is_quantity(value):
            raise ValueError(
                f"Effect {effect!r}: expected `{key}` as a plain number in the units of the "
                f"system (a system of plain floats), got the Quantity {value}")
    unit = _SYSTEM_UNITS[kind] if system.quantity else None
    try:
        arr = kind(key, value, unit)
    except ValueError as exc:  # UnitConversionError included
        raise type(exc)(f"Effect {effect!r}: {exc}") from None
    if arr.shape != ():
        raise ValueError(f"Effect {effect!r}: expected `{key}` to be one number, got "
                         f"{value!r} (shape {arr.shape})")
    return float(arr)


def speed_of_light(system: Any, params: Mapping[str, Any], effect: str) -> float:
    """The speed of light in ``system``'s units from mapping ``params`` (key ``"c"``;
    default c in au/day for a Quantity system); see :func:`parameter_value`.

    Examples
    --------
    >>> from hamilton_orbits import Body, System
    >>> s = System([Body("a", 1.0, [0, 0, 0], [0, 0, 0])])
    >>> speed_of_light(s, {"c": 10.0}, "gr")
    10.0
    """
    c = parameter_value(system, params, "c", effect, SPEED)
    if c is None:
        if system.quantity:
            return C_AU_PER_DAY
        raise ValueError(
            f"Effect {effect!r}: a system of plain floats needs the speed of light `c` in "
            "its own units, e.g. {'name': 'gr', 'c': 10065.32}"
        )
    if not c > 0:
        raise ValueError(f"Effect {effect!r}: expected `c` > 0, got {params['c']!r}")
    return c


def _params_gr(system: Any, params: Mapping[str, Any]) -> np.ndarray:
    s = source_index(system, params, "source", "gr")
    c = speed_of_light(system, params, "gr")
    return np.array([s, c])


def _params_gr_potential(system: Any, params: Mapping[str, Any]) -> np.ndarray:
    s = source_index(system, params, "source", "gr_potential")
    c = speed_of_light(system, params, "gr_potential")
    return np.array([s, c])


def _params_j2(system: Any, params: Mapping[str, Any]) -> np.ndarray:
    if "body" not in params:
        raise ValueError("Effect 'j2' needs the `body` whose oblateness acts, e.g. "
                         "{'name': 'j2', 'body': 'earth'}")
    b = source_index(system, params, "body", "j2")
    arrays = system.as_arrays()
    body = system.bodies[b]
    j2 = parameter_value(system, params, "j2", "j2", DIMENSIONLESS)
    radius = parameter_value(system, params, "radius", "j2", LENGTH)
    j2 = body.j2 if j2 is None else j2
    radius = (float(arrays.radius[b]) if np.isfinite(arrays.radius[b]) else None
              ) if radius is None else radius
    missing = [k for k, v in (("j2", j2), ("radius", radius)) if v is None]
    if missing:
        raise ValueError(
            f"Effect 'j2': body {body.name!r} has no {' and no '.join(missing)} (give "
            f"{' and '.join(missing)} to the Body, or in the effect's mapping)"
        )
    if not radius > 0:
        raise ValueError(f"Effect 'j2': expected `radius` > 0, got {params['radius']!r}")
    pole = body.pole if body.pole is not None else (0.0, 0.0, 1.0)
    return np.array([b, j2, radius, *pole])


def _relative(r: np.ndarray, v: np.ndarray, s: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Positions and velocities relative to body ``s``, and the distances (1 where
    zero, at ``s`` itself), for states of shape (n_t, n, 3)."""
    d = r - r[:, s:s + 1]
    w = v - v[:, s:s + 1]
    dist = np.sqrt(np.einsum("tij,tij->ti", d, d))
    return d, w, np.where(dist > 0, dist, 1.0)


def _energy_gr(r: np.ndarray, v: np.ndarray, gm: np.ndarray, p: np.ndarray) -> np.ndarray:
    """The first post-Newtonian terms of the specific energy about the source,
    ``(3/8 w^4 + 3/2 mu w^2 / d + 1/2 mu^2 / d^2) / c^2``: with ``w^2 / 2 - mu / d`` the
    energy that the one-body metric's equations of motion (``gr_anderson``) keep
    exactly for a test particle (its time derivative vanishes identically), and to
    O(m / M v^2 / c^2) for a body of mass m."""
    s, c2 = int(p[0]), p[1] * p[1]
    mu = gm[s]
    _, w, dist = _relative(r, v, s)
    w2 = np.einsum("tij,tij->ti", w, w)
    out = (0.375 * w2 * w2 + 1.5 * mu * w2 / dist + 0.5 * mu * mu / (dist * dist)) / c2
    out[:, s] = 0.0
    return out


def _energy_gr_potential(r: np.ndarray, v: np.ndarray, gm: np.ndarray,
                         p: np.ndarray) -> np.ndarray:
    """The potential ``-3 (mu / (c d))^2`` of Nobili & Roxburgh (1986)."""
    s, c2 = int(p[0]), p[1] * p[1]
    _, _, dist = _relative(r, v, s)
    out = -3.0 * gm[s] ** 2 / (c2 * dist * dist)
    out[:, s] = 0.0
    return out


def _energy_j2(r: np.ndarray, v: np.ndarray, gm: np.ndarray, p: np.ndarray) -> np.ndarray:
    """The degree-2 zonal potential ``J2 mu R^2 (3 z^2 / d^2 - 1) / (2 d^3)`` (the
    potential whose gradient ``j2_field`` applies; Vallado 2013, eq. 8-22)."""
    b, j2, rad = int(p[0]), p[1], p[2]
    d, _, dist = _relative(r, v, b)
    z = d @ p[3:6]
    out = 0.5 * j2 * gm[b] * rad * rad * (3.0 * z * z / (dist * dist) - 1.0) / dist**3
    out[:, b] = 0.0
    return out


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
        jacobian=_jacobians.gr_anderson_jvp,
        params=_params_gr,
        parameter_kinds={"c": SPEED},
        name_parameters=("source",),
        energy=_energy_gr,
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
        jacobian=_jacobians.gr_potential_jvp,
        params=_params_gr_potential,
        parameter_kinds={"c": SPEED},
        name_parameters=("source",),
        energy=_energy_gr_potential,
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
        jacobian=_jacobians.j2_field_jvp,
        params=_params_j2,
        parameter_kinds={"j2": DIMENSIONLESS, "radius": LENGTH},
        name_parameters=("body",),
        energy=_energy_j2,
        reference="Vallado (2013), Fundamentals of Astrodynamics, 4th ed., sec. 8.6.1",
    )
)

from hamilton_orbits.effects_solar_system import SPECS as _SOLAR_SYSTEM  # noqa: E402

_ = [register(EffectSpec(**spec)) for spec in _SOLAR_SYSTEM]  # eih, zonal, tides, ... (DE440)
