"""The effects registry: :class:`EffectSpec`, :func:`register`, :func:`get`, :class:`EffectSet`.

Effects are registered per *kind* of simulation (``"nbody"``, ``"rotation"``)
with :func:`register`.  Other packages add effects without ``hamilton_orbits``
importing them: an entry point in the group ``hamilton_orbits.effects`` names a
callable that registers its effects when the kind is first looked up (``rigid``
registers its rotation effects this way).

:meth:`EffectSet.of` turns what a caller lists into an :class:`EffectSet`: a
frozen, hashable value, checked against the registry once at the boundary
(:func:`entry_problems`, :func:`normalize_effects`).

The built-in ``"nbody"`` effects are defined one module each beside this one
and registered by :mod:`hamilton_orbits.effects` (the public face of all of it).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from hamilton_orbits.units import Kind, time_quantity

__all__ = [
    "EffectSet",
    "EffectSpec",
    "body_exclusion_problems",
    "entry_problems",
    "exclusion_problems",
    "get",
    "known",
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
        ``da`` (see ``hamilton_orbits._kernels.jacobians``), compiled only when
        the variational equations are asked for.  None: the variational equations
        differentiate ``kernel`` by central differences along each tangent vector
        (compiled, generated in ``hamilton_orbits.rhs``; about 1e-10 relative,
        and two or four evaluations of the kernel per tangent vector).
    energy : callable or None
        ``"nbody"`` effects that keep an energy: ``energy(r, v, gm, p) -> ndarray``
        of shape (n_t, n) for states (n_t, n, 3): the effect's part of each body's
        specific energy (per unit mass; zero for the source), so that Hamilton's
        (E) plus ``sum(gm * energy)`` is conserved (:func:`effect_energy`).  None
        if the effect keeps none (the energy is then reported as not conserved).
    excludes : Mapping[str, str]
        The effects this one already computes (name -> what both would compute),
        refused beside it: ``eih`` holds the 1PN terms that ``gr`` adds, so
        ``["eih", "gr"]`` would count them twice (:func:`exclusion_problems`).
    same_body_excludes : Mapping[str, str]
        As ``excludes``, for the effects that count something twice only when both
        act on the same body (``body_of``): ``zonal`` applies its body's J2, so
        ``j2`` on that body beside it would count J2 twice, ``j2`` on another body
        would not (:func:`body_exclusion_problems`, checked with the system).
    body_of : callable or None
        ``"nbody"`` effects named in a ``same_body_excludes`` (their own or
        another's): ``body_of(p) -> int``, the index of the body the effect acts
        on, read from its parameter vector ``p``, or -1 where it computes nothing
        another could count twice (a J2 of zero).
    singular : callable or None
        ``singular(system, r, p) -> str | None``: where the effect's field is not
        finite at positions ``r`` (a body on a singularity of it), why, naming the
        body and its index; for the refusal of such a state
        (``hamilton_orbits.rhs.refuse_nonfinite``).  None: the bodies whose
        acceleration is not finite are named.
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
    excludes: Mapping[str, str] = field(default_factory=dict)
    same_body_excludes: Mapping[str, str] = field(default_factory=dict)
    body_of: Callable[[np.ndarray], int] | None = None
    singular: Callable[[Any, np.ndarray, np.ndarray], str | None] | None = None


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


def exclusion_problems(names: Sequence[str], kind: str = "nbody") -> list[tuple[int, str]]:
    """``(index, message)`` for each listed effect that another listed one already
    computes (``EffectSpec.excludes``), at the later of the two indices.

    Examples
    --------
    >>> exclusion_problems(["eih", "j2", "gr"])  # doctest: +NORMALIZE_WHITESPACE
    [(2, "effect 'gr' (at index 2) is refused beside 'eih' (at index 0): 'eih' already
      computes the first post-Newtonian terms of the dominant body, which would count
      twice; list one of them")]
    """
    out = []
    first: dict[str, int] = {}
    for k, name in enumerate(names):
        first.setdefault(name, k)
    for k, name in enumerate(names):
        if name not in known(kind):
            continue
        for other, what in get(kind, name).excludes.items():
            if other in first:
                j = first[other]
                out.append((max(j, k), f"effect {other!r} (at index {j}) is refused beside "
                                       f"{name!r} (at index {k}): {name!r} already computes "
                                       f"{what}, which would count twice; list one of them"))
    return sorted(out)


def body_exclusion_problems(
    names: Sequence[str], blocks: Sequence[np.ndarray], bodies: Sequence[str],
    kind: str = "nbody", indices: Sequence[int] | None = None,
) -> list[tuple[int, str]]:
    """``(index, message)`` for each listed effect that another listed one already
    computes on the same body (``EffectSpec.same_body_excludes``, the bodies read
    by ``EffectSpec.body_of`` from the parameter vectors), at the later of the two
    indices.

    Parameters
    ----------
    names : sequence of str
        The listed effects' names.
    blocks : sequence of ndarray
        Their parameter vectors (``EffectSpec.params``), in the same order.
    bodies : sequence of str
        The system's body names (``System.names``).
    kind : str
        The kind of simulation.
    indices : sequence of int or None
        Each effect's index in the caller's list, for the messages (default: its
        position in ``names``).

    Returns
    -------
    list of (int, str)
        Sorted by index; empty if nothing counts twice.

    Examples
    --------
    >>> import numpy as np
    >>> j2_earth = np.array([1, 1.08e-3, 4.3e-5, 0, 0, 1])
    >>> zonal_earth = np.array([0.0] * 11 + [1, 4.3e-5, 0, 0, 1, 1.08e-3, -2.5e-6])
    >>> body_exclusion_problems(["j2", "zonal"], [j2_earth, zonal_earth],
    ...                         ["sun", "earth"])  # doctest: +NORMALIZE_WHITESPACE
    [(1, "effect 'j2' (at index 0) is refused beside 'zonal' (at index 1) on body
      'earth': 'zonal' already computes its body's J2 (the first of its `j`), which
      would count twice; list one of them, or put 'j2' on another body")]
    >>> j2_sun = np.array([0, 2.2e-7, 4.7e-3, 0, 0, 1])
    >>> body_exclusion_problems(["j2", "zonal"], [j2_sun, zonal_earth], ["sun", "earth"])
    []
    """
    indices = list(range(len(names))) if indices is None else list(indices)
    acting: dict[str, tuple[int, int]] = {}  # name -> (body, index)
    for name, p, k in zip(names, blocks, indices, strict=True):
        spec = get(kind, name) if name in known(kind) else None
        if spec is not None and spec.body_of is not None:
            acting.setdefault(name, (int(spec.body_of(np.asarray(p))), k))
    out = []
    for name, (body, k) in acting.items():
        for other, what in get(kind, name).same_body_excludes.items():
            if other in acting and body >= 0 and acting[other][0] == body:
                j = acting[other][1]
                out.append((max(j, k), f"effect {other!r} (at index {j}) is refused beside "
                                       f"{name!r} (at index {k}) on body {bodies[body]!r}: "
                                       f"{name!r} already computes {what}, which would "
                                       f"count twice; list one of them, or put {other!r} "
                                       f"on another body"))
    return sorted(out)


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
        an effect listed twice, or one listed beside an effect that already
        computes it (:func:`exclusion_problems`); naming the index and the value.

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
    listed: list[str] = []
    seen: dict[str, int] = {}
    for k, item in enumerate(effects):
        name, params, problems = entry_problems(item, kind)
        if problems:
            key, message = problems[0]
            where = f", `{key}`" if key and key != "name" else ""
            raise ValueError(f"Effect at index {k}{where}: {message}")
        listed.append(name)
        if name == "newtonian":
            continue
        if name in seen:
            raise ValueError(f"Effect {name!r} is listed twice (at indices {seen[name]} and {k})")
        seen[name] = k
        out.append((name, tuple(sorted((key, _as_kept(val)) for key, val in params.items()))))
    for _, message in exclusion_problems(listed, kind)[:1]:
        raise ValueError(message[0].upper() + message[1:])
    return tuple(out)


def _as_kept(value: Any) -> Any:
    """A parameter value as an :class:`EffectSet` keeps it: an astropy TimeDelta as
    the time Quantity in days it holds (:func:`~hamilton_orbits.units.time_quantity`,
    as the effects' reader ``parameters.with_units`` takes it), and a list or tuple
    holding TimeDeltas as the one Quantity its values join into (each TimeDelta that
    Quantity where they do not join: the reader refuses them by name), so that the
    set is saved, archived and compared as with that Quantity; anything else as
    given.

    Examples
    --------
    >>> from astropy.time import TimeDelta
    >>> import astropy.units as u
    >>> _as_kept([TimeDelta(0.5, format="jd"), 12 * u.h])
    <Quantity [0.5, 0.5] d>
    >>> _as_kept([TimeDelta(0.5, format="jd"), "earth"])
    [<Quantity 0.5 d>, 'earth']
    >>> _as_kept("earth")
    'earth'
    """
    if not isinstance(value, (list, tuple)):
        return time_quantity(value)
    kept = [_as_kept(x) for x in value]
    if all(k is x for k, x in zip(kept, value, strict=True)):
        return value
    import astropy.units as u

    try:
        return u.Quantity(kept, dtype=np.float64)
    except (TypeError, ValueError):  # UnitConversionError included
        return kept if isinstance(value, list) else tuple(kept)


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
    :attr:`names` (see ``hamilton_orbits.rhs``).

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
    #: each item's index in the list it was built from (``"newtonian"`` counted),
    #: for messages; not part of the value (equality, hash)
    indices: tuple[int, ...] = field(default=(), compare=False)

    @classmethod
    def of(cls, effects: Any, kind: str = "nbody") -> EffectSet:
        """Normalise ``effects`` (an EffectSet of this kind passes through).

        Raises
        ------
        ValueError
            As :func:`normalize_effects`, for an unknown ``kind`` (listing the known
            ones), or for an EffectSet of another kind.

        Examples
        --------
        >>> EffectSet.of(["gr"], "bogus-kind")  # doctest: +ELLIPSIS
        Traceback (most recent call last):
        ...
        ValueError: Unknown effect `kind` 'bogus-kind'; known: nbody...
        """
        if not _REGISTRY.get(kind) and not known(kind):
            kinds = sorted(k for k, specs in _REGISTRY.items() if specs)
            raise ValueError(f"Unknown effect `kind` {kind!r}; known: {', '.join(kinds)}")
        if isinstance(effects, EffectSet):
            if effects.kind != kind:
                raise ValueError(f"Expected {kind} effects, got an EffectSet of {effects.kind!r}")
            return effects
        items = normalize_effects(effects, kind)
        listed = [effects] if isinstance(effects, (str, Mapping)) else effects  # (one alone)
        indices = tuple(k for k, item in enumerate(listed)
                        if (item if isinstance(item, str) else item["name"]) != "newtonian")
        return cls(kind, items, indices)

    @property
    def names(self) -> tuple[str, ...]:
        """The listed effects' names, in order."""
        return tuple(name for name, _ in self.items)

    @property
    def velocity_dependent(self) -> bool:
        """True if any listed effect depends on velocities."""
        return any(get(self.kind, name).velocity_dependent for name in self.names)

    def parameters(self, system: Any) -> list[np.ndarray]:
        """Each listed effect's parameter vector for ``system`` (its
        ``EffectSpec.params``), in order.

        Raises
        ------
        ValueError
            For an effect without a parameter builder, or bad parameters: the
            builder's message, naming the effect and the parameter, and the
            effect's index in the list the set was built from (``"Effect 'eih':
            expected `c` ... (effects[0])"``); or for an effect that another
            listed one already computes on the same body of ``system``
            (:func:`body_exclusion_problems`: ``j2`` on the Earth beside ``zonal``).

        Examples
        --------
        >>> from hamilton_orbits import Body, System
        >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0])])
        >>> EffectSet.of([{"name": "j2", "body": "sun", "j2": 1e-3, "radius": 0.1},
        ...               {"name": "gr", "c": -1.0}]).parameters(s)
        Traceback (most recent call last):
        ...
        ValueError: Effect 'gr': expected `c` > 0, got -1.0 (effects[1])
        """
        out = []
        indices = self.indices or range(len(self.items))
        for k, (name, params) in zip(indices, self.items, strict=True):
            spec = get(self.kind, name)
            if spec.params is None:
                raise ValueError(f"Effect {name!r} cannot be used in an n-body simulation")
            try:
                out.append(spec.params(system, dict(params)))
            except ValueError as exc:  # astropy's UnitConversionError included
                msg = str(exc)
                if not msg.startswith(f"Effect {name!r}"):
                    msg = f"Effect {name!r}: {msg}"
                raise type(exc)(f"{msg} (effects[{k}])") from None
        for _, message in body_exclusion_problems(self.names, out, system.names, self.kind,
                                                  indices)[:1]:
            raise ValueError(message[0].upper() + message[1:])
        return out

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
