"""The field of bodies read from an ephemeris, as a compiled right-hand side.

:func:`field_rhs` puts together what ``hamilton_orbits._kernels.perturbers``
evaluates at every stage of every step: the header of its parameter vector, the
effects' parameters (those of the n-body effects on the perturbers followed by the
small bodies, made once per process), the tables of the perturbers and of the
Chebyshev segments they are read from (kept per :class:`~hamilton_orbits.spk.Segments`),
and the cache.  :func:`hamilton_orbits.small_bodies.propagate` runs it.
"""

from __future__ import annotations

import functools
import weakref
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from hamilton_orbits import ephemeris as de
from hamilton_orbits.spk import Segments

__all__ = ["EFFECTS", "NONGRAV_KEYS", "PERTURBERS", "field_rhs", "perturber_chain"]


#: the perturbers read from the ephemeris, in the order they are put before the
#: small bodies
PERTURBERS = ("sun", "mercury", "venus", "earth", "moon", "mars", "jupiter", "saturn",
              "uranus", "neptune", "pluto")
#: the effects :func:`~hamilton_orbits.small_bodies.propagate` knows, as the n-body effects they are
EFFECTS = {"eih": {"name": "eih", "sources": list(PERTURBERS)},
           "sun_j2": {"name": "j2", "body": "sun"},
           "earth_zonal": {"name": "zonal", "body": "earth"}}
def _combined_system(n: int, perturbers: Sequence[str]) -> Any:
    """The perturbers (DE440's GMs, radii, J2 and poles) and ``n`` massless small
    bodies: the System the effects' parameters are made for (they depend on the
    bodies' indices and constants, not on their states: placeholders here)."""
    import astropy.units as u

    from hamilton_orbits.nbody import Body, System

    bodies = [Body(**spec) for spec in de.body_specs("J2000", list(perturbers))]
    for k in range(n):  # (named apart: a small body may be an asteroid perturber)
        bodies.append(Body(f"small body {k}", 0.0 * u.au**3 / u.day**2, [1.0, 0, 0] * u.au,
                           [0, 0.01, 0] * u.au / u.day))
    return System(bodies)


@functools.lru_cache(maxsize=32)
def _blocks(perturbers: tuple[str, ...], effects: tuple[str, ...], n: int
            ) -> tuple[tuple[str, np.ndarray], ...]:
    """The parameter vectors of ``effects`` for ``perturbers`` and ``n`` small bodies
    (they depend on nothing else: made once per process)."""
    from hamilton_orbits._kernels.figures import OF_DATE
    from hamilton_orbits.effects import EffectSet

    system = _combined_system(n, perturbers)
    blocks = EffectSet.of([EFFECTS[e] for e in effects], "nbody").parameters(system)
    # (the zonal field's parameters after the pole of date's numbers: the field takes
    # its pole of date from its clock row, :func:`field_rhs`'s ``earth_pole``)
    blocks = [b[OF_DATE:] if e == "earth_zonal" else b for e, b in zip(effects, blocks,
                                                                       strict=True)]
    for block in blocks:
        block.setflags(write=False)
    return tuple(zip(effects, blocks, strict=True))


def perturber_chain(name: str) -> tuple[tuple[int, int], ...]:
    """The segments whose states add up to a perturber's barycentric state.

    Parameters
    ----------
    name : str
        A body of DE440 (``hamilton_orbits.ephemeris.CHAINS``) or one of the 16
        asteroids of ``sb441-n16``, in any case (stripped, as elsewhere in the
        package).

    Returns
    -------
    tuple of (center, target)
        NAIF ids of the segments, the barycentre's first.

    Raises
    ------
    ValueError
        For a name that is not a string or not known, naming ``name`` and listing
        the known names (it was a bare KeyError, for "Earth" too).

    Examples
    --------
    >>> perturber_chain("Earth")
    ((0, 3), (3, 399))
    """
    key = name.strip().lower() if isinstance(name, str) else None
    chain = None if key is None else de.CHAINS.get(key) or de.ASTEROID_CHAINS.get(key)
    if chain is None:
        raise ValueError(f"Expected `name` to be a perturber's name, got {name!r}; known: "
                         f"{', '.join([*de.CHAINS, *de.ASTEROID_CHAINS])}")
    return chain


def field_rhs(segments: Segments, names: Sequence[str], epoch: tuple[float, float],
              effects: Sequence[str],
              perturbers: Sequence[str] = PERTURBERS, without: str | None = None,
              nongrav: Any = None, variational: bool = False,
              earth_pole: str = "J2000", shadows: Sequence[str] = ()) -> Any:
    """The right-hand side of the small bodies ``names`` and the clock, in the field
    of ``perturbers`` (:data:`~hamilton_orbits.perturber_field.PERTURBERS`, then
    any of the 16 asteroids) read from ``segments`` from TDB Julian date ``epoch``
    (two parts), with ``effects`` (keys of
    :data:`~hamilton_orbits.perturber_field.EFFECTS`), ``without`` one perturber's
    pull (its GM 0), ``nongrav`` the non-gravitational accelerations, ``earth_pole``
    (both as :func:`~hamilton_orbits.small_bodies.propagate` takes them); its
    time-reversed form attached (``hamilton_orbits.rhs.time_reversed``), and with
    ``variational`` the variational equations (``augmented``, for radau15 and
    dop853); ``shadows`` perturbers (of ``perturbers``) followed by rows after the
    clock, in that order, each on its ephemeris' acceleration (the rows that
    events between a small body and a perturber watch).

    Raises
    ------
    ValueError
        For an unknown effect, or a perturber the segments do not hold.
    """
    from hamilton_orbits._kernels.perturbers import (
        HEADER,
        cache_size,
        small_bodies_augmented,
        small_bodies_field,
    )
    from hamilton_orbits.effects import EffectSet
    from hamilton_orbits.rhs import RHS

    for k, name in enumerate(effects):
        if name not in EFFECTS:
            raise ValueError(f"Expected `effects` among {sorted(EFFECTS)}, got {name!r} at "
                             f"index {k}")
    blocks = dict(_blocks(tuple(perturbers), tuple(effects), len(names)))
    outgassing = _nongrav_effect(nongrav, len(names))
    if outgassing is not None:  # (its parameters are the bodies' own: made each time)
        system = _combined_system(len(names), perturbers)
        blocks["nongrav"] = EffectSet.of([outgassing], "nbody").parameters(system)[0]
    head = np.zeros(HEADER)
    head[0], head[2], head[3], head[4] = len(names), epoch[0], epoch[1], len(perturbers)
    head[5] = de.constant("AU")
    head[1] = 1.0 if earth_pole == "IAU2006" else 0.0  # (the zonal field's pole of date)
    parts, at = [head], HEADER
    for slot, name in ((6, "eih"), (8, "sun_j2"), (10, "earth_zonal"), (12, "nongrav")):
        block = blocks.get(name, np.empty(0))
        head[slot], head[slot + 1] = at, at + len(block)
        parts.append(block)
        at += len(block)
    seg_rows, pert_table, coefs = _tables(segments, tuple(perturbers), without)
    seg_table = seg_rows.copy()
    seg_table[4::5] += at + len(seg_table) + len(pert_table)  # (the coefficients' starts)
    head[15], head[14] = at, at + len(seg_table)
    shadow_table = np.array([list(perturbers).index(name) for name in shadows], dtype=float)
    head[17], head[18] = len(shadows), at + len(seg_table) + len(pert_table) + len(coefs)
    head[16] = head[18] + len(shadow_table)
    cache = np.full(cache_size(len(perturbers)), np.nan)
    cache[0] = 0.0  # (the next slot; a NaN time matches no time)
    p = np.concatenate([*parts, seg_table, pert_table, coefs, shadow_table, cache,
                        np.zeros(1)])  # (the integrators' clock last: this field reads
    # the time from its clock row)
    velocity = "eih" in effects or outgassing is not None
    tag = ("newtonian", "small_bodies", *blocks)
    # the time-reversed motion: the same kernels and parameters, the clock's velocity
    # (-1) says which (and one run at a time uses the cache); its variational
    # equations the central differences of that field along the tangent vectors of
    # the reversed motion, (dr, -dv)
    augmented = small_bodies_augmented if variational else None
    reverse = RHS(small_bodies_field, None, p, velocity, tag, augmented=augmented,
                  per_run=True)
    return RHS(small_bodies_field, None, p, velocity, tag, reversed=reverse,
               augmented=augmented, per_run=True)


#: the parameters of one body's non-gravitational acceleration and their kinds
NONGRAV_KEYS = {"A1": "acceleration", "A2": "acceleration", "A3": "acceleration",
                "alpha": "", "r0": "length", "m": "", "n": "", "k": ""}
_NONGRAV_DEFAULTS = {"A1": 0.0, "A2": 0.0, "A3": 0.0, "alpha": 1.0, "r0": 1.0, "m": 2.0,
                     "n": 0.0, "k": 0.0}


def _nongrav_effect(nongrav: Any, n: int) -> dict[str, Any] | None:
    """The ``nongrav`` effect of the ``n`` small bodies from ``nongrav``: one mapping
    for every body, or one mapping (or None) per body; None where no body has one."""
    import astropy.units as u

    from hamilton_orbits.effects.parameters import with_units
    from hamilton_orbits.units import ACCELERATION, LENGTH, is_quantity

    if nongrav is None:
        return None
    rows = [nongrav] * n if isinstance(nongrav, Mapping) else list(nongrav)
    if len(rows) != n:
        raise ValueError(f"Expected `nongrav` to be a mapping or one per body ({n}), got "
                         f"{len(rows)}")
    bodies, values = [], {key: [] for key in NONGRAV_KEYS}
    for k, row in enumerate(rows):
        if row is None:
            continue
        if not isinstance(row, Mapping) or set(row) - set(NONGRAV_KEYS):
            raise ValueError(f"Expected `nongrav` mappings of {sorted(NONGRAV_KEYS)}, got "
                             f"{row!r} at index {k}")
        bodies.append(f"small body {k}")
        for key, kind in NONGRAV_KEYS.items():
            x = row.get(key, _NONGRAV_DEFAULTS[key])
            unit = {"acceleration": u.au / u.day**2, "length": u.au}.get(kind)
            if unit is not None:  # ("-2.9e-14 au/day2" as the effects read it)
                x = with_units(x, key, f"`nongrav` at index {k}",
                               ACCELERATION if kind == "acceleration" else LENGTH)
            if is_quantity(x) and unit is None and x.unit.is_equivalent(u.one):
                x = x.to_value(u.one)  # (a dimensionless exponent, `2 * u.one`)
            if is_quantity(x) and unit is not None:
                if not x.unit.is_equivalent(unit):
                    raise u.UnitConversionError(
                        f"Expected `nongrav` {key} to be an {kind} (such as {unit}), got "
                        f"{x!r} at index {k}")
                x = x.to_value(unit)
            if (not isinstance(x, (int, float, np.floating, np.integer))
                    or isinstance(x, bool) or not np.isfinite(x)):  # (True: read as 1)
                raise ValueError(f"Expected `nongrav` {key} a finite number (or Quantity), "
                                 f"got {row[key]!r} at index {k}")
            values[key].append(float(x))
    if not bodies:
        return None
    units = {"acceleration": u.au / u.day**2, "length": u.au, "": u.dimensionless_unscaled}
    return {"name": "nongrav", "body": bodies,
            **{key: np.array(x) * units[NONGRAV_KEYS[key]] for key, x in values.items()}}


def _tables(segments: Segments, perturbers: tuple[str, ...], without: str | None
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The segments' table (the coefficients' starts from 0), the perturbers' and
    the coefficients (see ``hamilton_orbits._kernels.perturbers``), kept for the
    last few ``segments`` (a run's fixed cost: the coefficients of ten years are
    1.4 MB)."""
    key = (id(segments), perturbers, without)
    kept = _TABLES.get(key)
    if kept is not None and kept[0]() is segments:
        return kept[1]
    made = _make_tables(segments, perturbers, without)
    if len(_TABLES) >= 8:
        _TABLES.pop(next(iter(_TABLES)))
    _TABLES[key] = (weakref.ref(segments), made)
    return made


#: :func:`_tables` kept, by the segments' identity (checked through a weak reference)
_TABLES: dict[tuple[Any, ...], tuple[Any, tuple[np.ndarray, np.ndarray, np.ndarray]]] = {}


def _make_tables(segments: Segments, perturbers: tuple[str, ...], without: str | None
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_tables`, made."""
    pairs = sorted({pair for name in perturbers for pair in perturber_chain(name)})
    missing = [p for p in pairs if p not in segments.segments]
    if missing:
        raise ValueError(f"Expected `ephemeris` to hold the segments {missing} (of the "
                         f"perturbers {list(perturbers)})")
    # segments on one grid of records side by side: the kernel computes their
    # Chebyshev polynomials once
    pairs.sort(key=lambda pair: (segments.segments[pair].init, segments.segments[pair].intlen,
                                 segments.segments[pair].coef.shape[1], pair))
    first = 0
    seg_rows, coefs = [], []
    for pair in pairs:
        seg = segments.segments[pair]
        seg_rows.append([seg.init, seg.intlen, seg.coef.shape[1], seg.coef.shape[2], first])
        coefs.append(np.ascontiguousarray(seg.coef, dtype=np.float64).ravel())
        first += coefs[-1].size
    pert_rows = []
    for name in perturbers:
        links = [pairs.index(pair) for pair in perturber_chain(name)]
        gm = 0.0 if name == without else de.gm(name)
        pert_rows.append([gm, len(links), *links, *([0] * (2 - len(links)))])
    return (np.asarray(seg_rows, dtype=np.float64).ravel(),
            np.asarray(pert_rows, dtype=np.float64).ravel(), np.concatenate(coefs))
