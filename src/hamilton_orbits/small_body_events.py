"""Close encounters of small bodies with the ephemeris's bodies, for
:func:`hamilton_orbits.small_bodies.propagate`.

The perturbers are not in the integrated state: they are read from the ephemeris.
So that the events' machinery (:mod:`hamilton_orbits.events`: a closest approach
found on the integrator's own interpolant of each step, its time bisected to the
last bit) can watch a small body and a perturber, each watched perturber gets a
*shadow* row in the state: started on the perturber's state, driven by the second
derivative of its ephemeris (``hamilton_orbits._kernels.perturbers``, ``p[17]``),
acting on nothing, it follows the ephemeris to the integrator's accuracy.  A
closest approach within ``distance`` is recorded with its time, distance and
relative speed, as for an n-body run (``traj.events``).

``events`` entries: ``{"name": "close_encounter", "bodies": ..., "distance": ...}``
(``"action": "record"``, the only action here: a stop would end one chunk of
small bodies and not the others).  ``bodies`` names perturbers (each small body
with each of them) and, optionally, small bodies (only those).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, NamedTuple

import numpy as np

__all__ = ["Encounter", "EventBodies", "encounters", "event_rows", "watch_for"]


class Encounter(NamedTuple):
    """A watched pair: small body ``body`` (an index), perturber ``perturber``, the
    distance within which a closest approach is recorded (au)."""

    body: int
    perturber: str
    distance: float


class EventBodies(NamedTuple):
    """The names the rows of :func:`event_rows` index (the small bodies, then the
    perturbers), as ``hamilton_orbits.trajectory.event_table`` reads a system."""

    names: tuple[str, ...]
    quantity: bool = True


def encounters(events: Any, names: Sequence[str], perturbers: Sequence[str]
               ) -> tuple[Encounter, ...]:
    """The pairs that ``events`` asks to watch (see the module).

    Raises
    ------
    ValueError
        Naming the event's index: not a mapping, another event or action, an
        unknown key, a name neither a small body nor a perturber, no perturber, a
        distance that is not a positive length.

    Examples
    --------
    >>> import astropy.units as u
    >>> encounters([{"name": "close_encounter", "bodies": "earth", "distance": 0.05 * u.au}],
    ...            ["a", "b"], ["sun", "earth"])  # doctest: +NORMALIZE_WHITESPACE
    (Encounter(body=0, perturber='earth', distance=0.05),
     Encounter(body=1, perturber='earth', distance=0.05))
    """
    if isinstance(events, Mapping) or not isinstance(events, (list, tuple)):
        raise ValueError(f"Expected `events` to be a list of mappings, got {events!r}")
    out: list[Encounter] = []
    for k, event in enumerate(events):
        where = f"Event at index {k}"
        if not isinstance(event, Mapping):
            raise ValueError(f"{where}: expected a mapping, got {event!r}")
        if event.get("name") != "close_encounter":
            raise ValueError(f"{where}: small_bodies.propagate watches 'close_encounter' (a "
                             f"small body and a perturber), got {event.get('name')!r}")
        extra = set(event) - {"name", "bodies", "distance", "action"}
        if extra:
            raise ValueError(f"{where}: unknown keys {sorted(extra)} (bodies, distance, "
                             "action)")
        if event.get("action", "record") != "record":
            raise ValueError(f"{where}: the action is 'record' here (a stop would end one "
                             f"chunk of small bodies), got {event['action']!r}")
        mine, theirs = _named(event.get("bodies"), names, perturbers, where)
        dist = _distance(event.get("distance"), where)
        watched = [Encounter(i, p, dist) for i in mine or range(len(names)) for p in theirs]
        _refuse_repeats(watched, out, where, names)
        out += watched
    return tuple(out)


def _refuse_repeats(watched: list[Encounter], before: list[Encounter], where: str,
                    names: Sequence[str]) -> None:
    """Refuse a pair watched at a distance an earlier event watches it at (each
    encounter would be recorded twice), as the n-body events do."""
    known = set(before)
    for pair in watched:
        if pair in known:
            raise ValueError(f"{where} watches {names[pair.body]}-{pair.perturber} within "
                             f"{pair.distance!r} au as an earlier event does; list each "
                             f"event of a pair once")


def _named(bodies: Any, names: Sequence[str], perturbers: Sequence[str], where: str
           ) -> tuple[list[int], list[str]]:
    if isinstance(bodies, str):
        bodies = [bodies]
    if not isinstance(bodies, (list, tuple)) or not all(isinstance(b, str) for b in bodies):
        raise ValueError(f"{where}: expected `bodies` to name perturbers (and small bodies), "
                         f"got {bodies!r}")
    mine, theirs = [], []
    for name in bodies:
        if name in names:
            mine.append(list(names).index(name))
        elif name.lower() in perturbers:
            theirs.append(name.lower())
        else:
            raise ValueError(f"{where}: `bodies` names {name!r}, neither a small body nor a "
                             f"perturber ({', '.join(perturbers)})")
    if not theirs:
        raise ValueError(f"{where}: `bodies` names no perturber, got {bodies!r}")
    if len(set(mine)) < len(mine) or len(set(theirs)) < len(theirs):
        raise ValueError(f"{where}: `bodies` names a body twice, got {bodies!r}")
    return mine, theirs


def _distance(value: Any, where: str) -> float:
    from hamilton_orbits.effects.parameters import with_units
    from hamilton_orbits.units import LENGTH

    if value is None:
        raise ValueError(f"{where}: needs `distance` (a length, or au)")
    given, value = value, with_units(value, "distance", where, LENGTH)  # ("0.1 au")
    try:
        dist = float(LENGTH("distance", value, "au"))
    except (ValueError, TypeError) as exc:
        raise ValueError(f"{where}: {exc}") from None
    if not (np.isfinite(dist) and dist > 0):
        raise ValueError(f"{where}: expected `distance` > 0, got {given!r}")
    return dist


def watch_for(pairs: Sequence[Encounter], n: int) -> tuple[tuple[str, ...], np.ndarray]:
    """The shadows (the perturbers watched, in order of first use) and the watch
    table (``hamilton_orbits.events.watch_table``'s rows) of ``pairs`` (their
    bodies indices among the ``n`` small bodies of one run, whose clock is row
    ``n`` and shadows the rows after).

    Examples
    --------
    >>> watch_for([Encounter(1, "earth", 0.01)], 2)
    (('earth',), array([[1.  , 1.  , 3.  , 0.01, 0.  ]]))
    """
    from hamilton_orbits.events import ACTIONS, EVENTS

    shadows = tuple(dict.fromkeys(e.perturber for e in pairs))
    code = EVENTS["close_encounter"][0]
    rows = [[code, e.body, n + 1 + shadows.index(e.perturber), e.distance,
             ACTIONS["record"]] for e in pairs]
    return shadows, np.array(rows, dtype=np.float64).reshape(-1, 5)


def event_rows(runs: Sequence[tuple[Sequence[int], Any, tuple[str, ...]]], n: int,
               perturbers: Sequence[str], backward: bool = False) -> np.ndarray:
    """The events recorded by ``runs`` (each: its small bodies' indices, its
    ``EngineRun``, its shadows), their rows' bodies turned from a run's rows into
    indices of :class:`EventBodies` (``n`` small bodies, then ``perturbers``), in
    the order the runs met them: of time, or of decreasing time ``backward``."""
    from hamilton_orbits.events import E_I, E_J, E_TIME, N_EVENT_COLUMNS

    parts = [np.zeros((0, N_EVENT_COLUMNS))]
    for rows, out, shadows in runs:
        if out.events is None:
            continue
        found = out.events.recorded().copy()
        found[:, E_I] = np.asarray(rows, dtype=float)[found[:, E_I].astype(int)]
        found[:, E_J] = [n + list(perturbers).index(shadows[int(j) - len(rows) - 1])
                         for j in found[:, E_J]]
        parts.append(found)
    out_rows = np.concatenate(parts)
    return out_rows[np.argsort(-out_rows[:, E_TIME] if backward else out_rows[:, E_TIME],
                               kind="stable")]
