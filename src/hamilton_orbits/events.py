"""Events found during a run: close encounters, collisions, escapes, from one registry.

``integrate(system, t, events=[...])`` and scenes (``events = [...]``) list events
by name or as mappings with parameters, like effects::

    {"name": "close_encounter", "bodies": ["jupiter", "comet"], "distance": 0.1 * u.au}
    {"name": "close_encounter", "distance": {"hill": 3}}
    {"name": "collision", "action": "merge"}          # uses Body(radius=)
    {"name": "escape", "distance": 1000 * u.au, "action": "remove"}

A ``distance`` is a length Quantity or a string that reads as one (``"0.1 au"``, as
the effects' parameters read one) for a Quantity system, a plain number in the
system's own length unit for a system of plain floats.

What each finds
---------------
``close_encounter``
    Every closest approach of a watched pair closer than ``distance``: the time
    and distance of the minimum of ``|r_i - r_j|``, found *between* steps (a
    flyby that begins and ends inside one step is still found) and refined on
    the integrator's own interpolant to near rounding error.  Without
    ``bodies``, every pair with at least one massive body is watched.  A
    ``{"hill": k}`` distance is ``k`` Hill radii of the more massive body of the
    pair about the most massive body of the system, ``a (m / 3 M)^(1/3)`` with
    ``a`` its initial osculating semi-major axis (pairs with the most massive body
    itself are then not watched).
``collision``
    The first contact of two bodies with radii (``|r_i - r_j| = R_i + R_j``),
    solved on the interpolant.  ``"stop"`` ends the run there, for good: the
    bodies are in contact, and a later ``integrate`` onwards raises a
    ``ValueError`` naming them (:meth:`EventLog.refuse_going_on`; go on from
    ``sim.system`` with the pair merged or one removed, or watch it with
    ``"merge"``).  ``"merge"`` replaces the pair by one body with their summed
    mass at their centre of mass with their total momentum, and goes on.  Bodies
    that already overlap at the start of a run collide there, at its first time.
``escape``
    A body's distance from the system's centre of mass crossing ``distance``
    outwards.  ``"record"`` (default) goes on; ``"stop"`` ends the run;
    ``"remove"`` takes the body out of the run.

A run stopped by a close approach or an escape goes on at the next
``integrate``, from the state it stopped at, where that event is not found again
(its crossing lies behind it); the next one is.  A stop is the run's end, not a
cut: the trajectory's ``complete`` stays True, ``stopped_by`` says why it ended.

Where actions take effect
-------------------------
``radau15`` and ``dop853`` stop or merge at the event's time itself.  The
symplectic maps (``wh``, ``leapfrog``) report every event at its refined time,
but act (stop, merge, remove) at the end of the step in which it occurred: a
step cut short, or a body changed mid-step, would break the map's symplecticity.
Every event of the step (or of the instant) acts: two pairs that collide in one
step both merge, a stop and a merge in one step end the run with the merge done.
Merging or removing bodies changes the Hamiltonian itself; the integrals'
errors after such an event measure the change, not the integrator.

Tables
------
``traj.events`` is an astropy ``QTable`` with one row per event: ``name``,
``time``, ``bodies``, ``distance``, ``speed``, ``action``; ``traj.stopped_by`` is
the row of the event that ended the run, or None.
"""

from __future__ import annotations

import difflib
import math
import numbers
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = [
    "ACTIONS",
    "EVENTS",
    "EventLog",
    "EventSet",
    "StopAtEvent",
    "watch_table",
]

#: The registered events: name -> (code, allowed actions (the first is the default),
#: parameters with their descriptions).
EVENTS: dict[str, tuple[int, tuple[str, ...], dict[str, str]]] = {
    "close_encounter": (1, ("record", "stop"), {
        "bodies": "two body names (default: every pair with a massive body)",
        "distance": "a length, or {'hill': k} for k Hill radii",
        "action": "'record' (default) or 'stop'",
    }),
    "collision": (2, ("stop", "merge"), {
        "bodies": "two body names (default: every pair of bodies with radii, one of "
                  "them massive; two massless ones collide when named)",
        "action": "'stop' (default) or 'merge'",
    }),
    "escape": (3, ("record", "stop", "remove"), {
        "bodies": "body names (default: every body but the most massive)",
        "distance": "a length from the centre of mass (required; crossed outwards, "
                    "or, in a backward run, outwards as time runs back: an entry)",
        "action": "'record' (default), 'stop' or 'remove'",
    }),
}
#: Action codes in the watch table.
ACTIONS = {"record": 0, "stop": 1, "merge": 2, "remove": 3}
NAMES = {code: name for name, (code, _, _) in EVENTS.items()}

#: Columns of the watch table: event code, body i, body j (-1: the centre of
#: mass), threshold distance, action code.
W_CODE, W_I, W_J, W_DIST, W_ACTION = range(5)
#: Columns of a recorded event: code, i, j, time, distance, speed, action.
E_CODE, E_I, E_J, E_TIME, E_DIST, E_SPEED, E_ACTION = range(7)
#: no body (a stop takes none out; -1 is the second body of a one-body event's row)
_NOBODY = -2
N_EVENT_COLUMNS = 7


@dataclass(frozen=True)
class EventSet:
    """The listed events, checked once: ``(name, params)`` pairs.

    Examples
    --------
    >>> EventSet.of(["collision", {"name": "escape", "distance": 10.0}]).names
    ('collision', 'escape')
    >>> EventSet.of([{"name": "escape"}])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Event at index 0 ('escape'): `distance` is required ...
    """

    items: tuple[tuple[str, dict[str, Any]], ...] = field(default=())

    @classmethod
    def of(cls, events: Any) -> EventSet:
        """Check ``events`` (names or mappings with a ``"name"``)."""
        if isinstance(events, EventSet):
            return events
        if events is None:
            return cls(())
        if isinstance(events, (str, Mapping)):
            events = [events]
        if not isinstance(events, Sequence):
            raise ValueError(f"Expected `events` to be a list of names or mappings, got "
                             f"{events!r}")
        return cls(tuple(_check_entry(item, k) for k, item in enumerate(events)))

    @property
    def names(self) -> tuple[str, ...]:
        """The listed events' names, in order."""
        return tuple(name for name, _ in self.items)

    def __bool__(self) -> bool:
        return bool(self.items)

    def __len__(self) -> int:
        return len(self.items)


def _check_entry(item: Any, k: int) -> tuple[str, dict[str, Any]]:
    if isinstance(item, str):
        name, params = item, {}
    elif isinstance(item, Mapping) and isinstance(item.get("name"), str):
        name, params = item["name"], {key: v for key, v in item.items() if key != "name"}
    else:
        raise ValueError(f"Expected `events` to hold names or mappings with a 'name', got "
                         f"{item!r} at index {k}")
    if name not in EVENTS:
        close = difflib.get_close_matches(name, list(EVENTS), n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise ValueError(f"Unknown event {name!r} at index {k}{hint}; known: "
                         f"{', '.join(EVENTS)}")
    _, actions, takes = EVENTS[name]
    for key in params:
        if key not in takes:
            raise ValueError(f"Event at index {k} ({name!r}) takes no parameter {key!r}; it "
                             f"takes: {', '.join(takes)}")
    action = params.get("action", actions[0])
    if action not in actions:
        raise ValueError(f"Event at index {k} ({name!r}): expected `action` one of "
                         f"{', '.join(map(repr, actions))}, got {action!r}")
    if name == "escape" and "distance" not in params:
        raise ValueError(f"Event at index {k} ({name!r}): `distance` is required (a length "
                         "from the centre of mass)")
    if name == "close_encounter" and "distance" not in params:
        raise ValueError(f"Event at index {k} ({name!r}): `distance` is required (a length "
                         "or {'hill': k})")
    if isinstance(params.get("distance"), Mapping):
        _check_hill(params["distance"], f"Event at index {k} ({name!r})", name)
    if isinstance(params.get("bodies"), (tuple, np.ndarray)):  # (names as a list of str,
        # as a snapshot keeps them; _bodies checks them)
        params["bodies"] = np.asarray(params["bodies"], dtype=object).tolist() \
            if isinstance(params["bodies"], np.ndarray) else list(params["bodies"])
    return name, {**params, "action": action}


def _check_hill(value: Mapping[str, Any], where: str, name: str) -> None:
    """A ``{"hill": k}`` distance: one key, ``k`` a finite number > 0."""
    if name != "close_encounter" or set(value) != {"hill"}:
        form = "a length or {'hill': k}" if name == "close_encounter" else "a length"
        raise ValueError(f"{where}: expected `distance` to be {form}, got {value!r}")
    k = value["hill"]
    if isinstance(k, bool) or not isinstance(k, numbers.Real) or not 0.0 < float(k) < math.inf:
        raise ValueError(f"{where}: expected `distance` {{'hill': k}} with `hill` a number "
                         f"k > 0 (Hill radii), got {k!r}")


def watch_table(events: EventSet, system: Any) -> np.ndarray:
    """The float rows the kernels watch, shape (m, 5): code, i, j, threshold, action.

    Raises
    ------
    ValueError
        For a body name not in the system, a non-positive distance, a
        collision watch with no body radii to collide, or an event of a body or
        pair listed twice (the same event, or two collisions of one pair).

    Examples
    --------
    >>> from hamilton_orbits import Body, System
    >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
    ...             Body("p", 1e-3, [1.0, 0, 0], [0, 1.0, 0])])
    >>> watch_table(EventSet.of([{"name": "close_encounter", "distance": 0.1}]), s).tolist()
    [[1.0, 0.0, 1.0, 0.1, 0.0]]
    """
    rows: list[list[float]] = []
    origin: list[int] = []  # (the event each row is of)
    for k, (name, params) in enumerate(events.items):
        new = _event_rows(name, params, system, f"Event at index {k} ({name!r})")
        rows += new
        origin += [k] * len(new)
    _refuse_repeats(rows, origin, events, system)
    return np.array(rows, dtype=np.float64).reshape(-1, 5)


def _event_rows(name: str, params: Mapping[str, Any], system: Any,
                where: str) -> list[list[float]]:
    """The watch rows of one listed event (:func:`watch_table`)."""
    arrays = system.as_arrays()
    code, _, _ = EVENTS[name]
    action = float(ACTIONS[params["action"]])
    if name == "escape":
        dist = _length(params["distance"], system, where)
        return [[code, i, -1, dist, action] for i in _bodies(params, system, where, single=True)]
    pairs = _pairs(params, system, where, name)
    if _hill(params) and params.get("bodies") is None:
        # in Hill radii, a pair with the most massive body has no encounter sphere
        top = int(np.argmax(arrays.gm))
        pairs = [(i, j) for i, j in pairs if top not in (i, j)]
    if name == "collision" and not pairs:
        raise ValueError(f"{where}: no pair of bodies with radii has a massive body (give "
                         f"Body(radius=...); two massless bodies collide when named: "
                         f"bodies=[a, b])")
    rows = []
    for i, j in pairs:
        if name == "collision":
            dist = arrays.radius[i] + arrays.radius[j]
        else:
            dist = _encounter_distance(params["distance"], system, i, j, where)
        rows.append([code, i, j, dist, action])
    return rows


def _refuse_repeats(rows: list[list[float]], origin: list[int], events: EventSet,
                    system: Any) -> None:
    """Refuse a watch listed twice: the same event of the same bodies (each would be
    recorded twice), or two collisions of one pair (a pair collides once: which
    action would be carried out?)."""
    collision = EVENTS["collision"][0]
    seen: dict[tuple[float, ...], int] = {}
    for row, k in zip(rows, origin, strict=True):
        key = tuple(row[:3]) if row[0] == collision else tuple(row)
        first = seen.setdefault(key, k)
        if first != k:
            name = events.items[k][0]
            who = "-".join(system.names[int(x)] for x in row[1:3] if x >= 0)
            raise ValueError(f"Event at index {k} ({name!r}) watches {who} as the event at "
                             f"index {first} does; list each event of a body or pair once")


def _bodies(params: Mapping[str, Any], system: Any, where: str, single: bool) -> list[int]:
    names = params.get("bodies")
    if names is None:
        gm = system.as_arrays().gm
        top = int(np.argmax(gm))
        return [i for i in range(len(gm)) if i != top]
    if isinstance(names, str):
        names = [names]
    if not isinstance(names, (Sequence, np.ndarray)) or not all(isinstance(x, str)
                                                                 for x in names):
        raise ValueError(f"{where}: expected `bodies` to be body names, got {names!r}")
    out = []
    for k, name in enumerate(names):
        if name not in system.names:
            raise ValueError(f"{where}: `bodies` names {name!r}, which is not in the system; "
                             f"bodies: {', '.join(system.names)}")
        if single and name in names[:k]:
            raise ValueError(f"{where}: `bodies` names {name!r} twice (at indices "
                             f"{list(names).index(name)} and {k})")
        out.append(system.names.index(name))
    return out


def _pairs(params: Mapping[str, Any], system: Any, where: str, name: str) -> list[tuple[int, int]]:
    arrays = system.as_arrays()
    if params.get("bodies") is not None:
        idx = _bodies(params, system, where, single=False)
        if len(idx) != 2 or idx[0] == idx[1]:
            raise ValueError(f"{where}: expected `bodies` to name two different bodies, got "
                             f"{params['bodies']!r}")
        i, j = sorted(idx)
        if name == "collision" and not np.isfinite(arrays.radius[[i, j]]).all():
            raise ValueError(f"{where}: bodies {system.names[i]!r} and {system.names[j]!r} "
                             "need radii to collide (Body(radius=...))")
        return [(i, j)]
    n = len(arrays.gm)
    massive = arrays.gm > 0
    with_radius = np.isfinite(arrays.radius)
    out = []
    for i in range(n):
        for j in range(i + 1, n):
            if not (massive[i] or massive[j]):
                continue
            if name == "collision" and not (with_radius[i] and with_radius[j]):
                continue
            out.append((i, j))
    return out


def _length(value: Any, system: Any, where: str) -> float:
    import astropy.units as u

    from hamilton_orbits.effects.parameters import with_units
    from hamilton_orbits.units import LENGTH, is_quantity

    given, value = value, with_units(value, "distance", where, LENGTH)  # ("0.1 au" as
    # the effects read it)
    if system.quantity and not is_quantity(value):
        raise ValueError(f"{where}: expected `distance` as a length Quantity (or a string "
                         f"such as '0.1 au') for a Quantity system, got {given!r}")
    if not system.quantity and is_quantity(value):  # (it was read in metres: 30 au as
        raise ValueError(f"{where}: expected `distance` as a plain number in the system's "
                         f"own length unit (it was built from plain numbers), got "
                         f"{given!r}")  # 4.5e12 of the system's unit)
    if np.ndim(getattr(value, "value", value)) != 0:  # (float() of an array said "only
        # 0-dimensional arrays can be converted to Python scalars")
        raise ValueError(f"{where}: expected `distance` to be one length, got {given!r}")
    try:
        dist = float(LENGTH("distance", value, u.au if system.quantity else None))
    except (ValueError, TypeError, u.UnitsError) as exc:
        msg = str(exc)
        raise ValueError(f"{where}: {msg[:1].lower()}{msg[1:]}") from None
    if not (np.isfinite(dist) and dist > 0):
        raise ValueError(f"{where}: expected `distance` > 0, got {given!r}")
    return dist


def _hill(params: Mapping[str, Any]) -> bool:
    value = params.get("distance")
    return isinstance(value, Mapping) and set(value) == {"hill"}


def _encounter_distance(value: Any, system: Any, i: int, j: int, where: str) -> float:
    if not (isinstance(value, Mapping) and set(value) == {"hill"}):
        return _length(value, system, where)
    _check_hill(value, where, "close_encounter")
    k = float(value["hill"])
    a = system.as_arrays()
    top = int(np.argmax(a.gm))
    big = i if a.gm[i] >= a.gm[j] else j
    if big == top:
        raise ValueError(f"{where}: a Hill radius about the most massive body itself is not "
                         f"defined (pair {system.names[i]!r}-{system.names[j]!r})")
    d = a.r[big] - a.r[top]
    w = a.v[big] - a.v[top]
    mu = a.gm[top] + a.gm[big]
    inv_a = 2.0 / np.linalg.norm(d) - (w @ w) / mu
    if not inv_a > 0:
        raise ValueError(f"{where}: {system.names[big]!r} is not bound to "
                         f"{system.names[top]!r}; its Hill radius is not defined")
    return k * (1.0 / inv_a) * (a.gm[big] / (3.0 * a.gm[top])) ** (1.0 / 3.0)


def _same_instant(a: float, b: float) -> bool:
    """Whether two events' times are one instant to rounding.  Simultaneous events (of
    a symmetric set-up) are found by separate root solves, whose times can differ in
    their last bits: an event one ulp after the one that acts at its time (radau15,
    dop853) was dropped as not having happened, and its pair passed through each
    other."""
    return abs(a - b) <= 64 * np.spacing(max(abs(a), abs(b)))


class StopAtEvent(Exception):
    """Raised by a driver when an event stopped the run; ``index`` is the output
    row that holds the state at the event's time ``t``, after ``steps`` steps."""

    def __init__(self, index: int, t: float, steps: int) -> None:
        super().__init__(index, t, steps)
        self.index = index
        self.t = t
        self.steps = steps


_NO_WATCH = np.zeros((0, 5))
_NO_RADIUS = np.zeros(0)
_NO_BUFFER = np.zeros((0, N_EVENT_COLUMNS))


class EventLog:
    """What a run records: the watch table, the events found, and why it stopped.

    The drivers pass ``watch``, ``buffer`` and ``count`` to their
    kernels, :meth:`drain` the buffer when asked, and call :meth:`act` for an
    event with an action; the public layer reads :meth:`recorded`.

    Parameters
    ----------
    watch : ndarray, shape (m, 5)
        From ``watch_table``.
    radius : ndarray, shape (n,)
        The bodies' radii (NaN: none), for the contact distance of merged bodies.
    """

    #: working space a saved state leaves out (``hamilton_orbits.restart``): the
    #: buffer holds nothing after :meth:`drain`, which a snapshot does first; the
    #: sign of the driver's time is set with each driver, from the direction
    RESTART_SCRATCH = ("buffer", "sign", "same_approach")
    #: the driver's time over the run's: -1 in a backward run, which integrates the
    #: time-reversed motion in ``s = -t`` (:meth:`drain` turns its times back)
    sign = 1.0
    #: close approaches of one pair recorded closer in time than this are one approach
    #: (``_one_per_approach``): leapfrog's step, set by its driver; 0: none merged
    same_approach = 0.0

    def __init__(self, watch: np.ndarray, radius: np.ndarray, capacity: int = 1024) -> None:
        self.watch = np.ascontiguousarray(watch, dtype=np.float64).reshape(-1, 5)
        self.radius = np.array(radius, dtype=np.float64)
        self.buffer = np.zeros((max(capacity, 2 * len(self.watch)), N_EVENT_COLUMNS))
        self.count = np.zeros(1, dtype=np.int64)
        self.rows: list[np.ndarray] = []
        self.stopped_by: int | None = None
        self.inactive = np.zeros(len(self.radius), dtype=bool)
        #: True once a body has been taken out of the run (``inactive.any()``)
        self.gone = False
        self.gm_changes: list[tuple[float, np.ndarray]] = []
        #: The kernel's body index -> the system's (a driver that reorders bodies
        #: sets it, and passes :meth:`kernel_watch` to its kernel).
        self.index_map: np.ndarray | None = None

    @classmethod
    def none(cls, n: int) -> EventLog:
        """A log that watches nothing (the kernels then skip the scan, and its
        buffer is empty)."""
        log = cls.__new__(cls)  # no radii: nothing merges; nothing to record
        log.watch, log.radius, log.buffer = _NO_WATCH, _NO_RADIUS, _NO_BUFFER
        log.count = np.zeros(1, dtype=np.int64)
        log.rows, log.stopped_by, log.gone, log.gm_changes = [], None, False, []
        log.inactive = np.zeros(n, dtype=bool)
        log.index_map = None
        return log

    def drain(self) -> None:
        """Move the kernel's buffered rows into ``rows`` and empty the buffer."""
        k = int(self.count[0])
        rows = self.buffer[:k].copy()
        if self.sign < 0:  # (found in s = -t; distances and speeds are the same)
            np.negative(rows[:, E_TIME], out=rows[:, E_TIME])
        if k > 1:  # (a step's rows come in the watch list's order: put in time's)
            rows = rows[np.argsort(self.sign * rows[:, E_TIME], kind="stable")]
        if self.index_map is not None:
            rows[:, E_I] = self.index_map[rows[:, E_I].astype(int)]
            pair = rows[:, E_J] >= 0
            rows[pair, E_J] = self.index_map[rows[pair, E_J].astype(int)]
        since = len(self.rows)
        self.rows.extend(rows)
        self.count[0] = 0
        if self.same_approach > 0.0 and k:
            self._one_per_approach(since)

    def _one_per_approach(self, since: int) -> None:
        """The close approaches of one pair recorded (action ``"record"``) less than
        :attr:`same_approach` apart in time, among the rows from ``since`` on and the
        pair's rows before them, made one: the closest kept, at its place in the log.
        leapfrog's path is a straight drift on each side of a kick, and about a
        pericentre the pair can come closest on both sides of one kick: two minima
        half a step apart (one periapsis passage listed twice), where the motion has
        one.  Two approaches of one pair within a step are not resolved by the step
        in any case."""
        code, record, rows = EVENTS["close_encounter"][0], ACTIONS["record"], self.rows
        k = since
        while k < len(rows):
            x = rows[k]
            k += 1
            if x[E_CODE] != code or x[E_ACTION] != record:
                continue
            for m in range(k - 2, -1, -1):  # (back through the rows within the interval)
                y = rows[m]
                if abs(x[E_TIME] - y[E_TIME]) >= self.same_approach:
                    break
                if (y[E_CODE] == code and y[E_ACTION] == record and y[E_I] == x[E_I]
                        and y[E_J] == x[E_J]):
                    if x[E_DIST] < y[E_DIST]:
                        rows[m] = x
                    k -= 1
                    del rows[k]
                    break

    def mask(self, r: np.ndarray, v: np.ndarray) -> None:
        """Set the bodies taken out of the run to NaN in ``r``, ``v`` (one output row
        each, (n, 3); in place; nothing to do while no body has left)."""
        if self.gone:
            r[self.inactive] = np.nan
            v[self.inactive] = np.nan

    def kernel_watch(self) -> np.ndarray:
        """``watch`` with the bodies numbered as the kernel numbers them."""
        if self.index_map is None:
            return self.watch
        back = np.argsort(self.index_map)
        w = self.watch.copy()
        w[:, W_I] = back[w[:, W_I].astype(int)]
        pair = w[:, W_J] >= 0
        w[pair, W_J] = back[w[pair, W_J].astype(int)]
        return np.ascontiguousarray(w)

    def recorded(self) -> np.ndarray:
        """Every recorded row, shape (k, 7)."""
        self.drain()
        return np.array(self.rows).reshape(-1, N_EVENT_COLUMNS)

    def refuse_going_on(self, names: Sequence[str] | None = None, when: Any = None) -> None:
        """Refuse a leg onwards from where a collision with the action ``"stop"`` ended
        the run (the last leg's ``stopped_by``): its bodies are in contact there, and
        integrating on would take them through each other (and, found at once
        again, the same collision would end every later leg where it began).

        Parameters
        ----------
        names : sequence of str, optional
            The bodies' names (default: ``body <index>``).
        when : optional
            The time the run stands at, as the message quotes it.

        Raises
        ------
        ValueError
            Naming the two bodies and what to do.

        Examples
        --------
        >>> log = EventLog(np.array([[2.0, 0, 1, 0.03, ACTIONS["stop"]]]), np.full(2, 0.015))
        >>> log.refuse_going_on(["a", "b"])  # (nothing stopped the run)
        >>> r, v, gm = np.array([[0.0, 0, 0], [0.02, 0, 0]]), np.zeros((2, 3)), np.ones(2)
        >>> log.at_start(0.0, r, v, gm)
        True
        >>> log.refuse_going_on(["a", "b"], 0.0)  # doctest: +ELLIPSIS
        Traceback (most recent call last):
        ...
        ValueError: Bodies 'a' and 'b' are in contact: their collision (action 'stop') ...
        """
        if self.stopped_by is None:
            return
        code, i, j = self.rows[self.stopped_by][[E_CODE, E_I, E_J]].astype(int)
        if code != EVENTS["collision"][0]:
            return  # (a stop at a close approach or an escape: not found again there)
        a, b = (repr(names[k]) if names is not None else f"body {k}" for k in (i, j))
        at = "" if when is None else f", which stands at t = {when}"
        raise ValueError(
            f"Bodies {a} and {b} are in contact: their collision (action 'stop') ended "
            f"this run{at}; it does not go on through them.  Go on from the state "
            f"reached (sim.system) with a new simulation in which they are merged or "
            f"one of them is removed, or watch that collision with action 'merge'")

    def overlapping(self, r: np.ndarray) -> bool:
        """Whether two bodies of a watched collision pair overlap at positions ``r``
        (``|r_i - r_j| <= R_i + R_j``: a collision no crossing will reveal)."""
        return bool(self._overlaps(r)[3].size)

    def _overlaps(self, r: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                np.ndarray]:
        """The watched collision rows, their pairs, the pairs' distances at ``r``, and
        which of them overlap."""
        rows = np.flatnonzero(self.watch[:, W_CODE] == EVENTS["collision"][0])
        pairs = self.watch[rows][:, [W_I, W_J]].astype(int)
        d = np.linalg.norm(r[pairs[:, 0]] - r[pairs[:, 1]], axis=1)
        return rows, pairs, d, np.flatnonzero(d <= self.watch[rows, W_DIST])

    def at_start(self, t: float, r: np.ndarray, v: np.ndarray, gm: np.ndarray) -> bool:
        """Collisions already made at the start ``t`` of a run: every watched pair that
        overlaps there (``|r_i - r_j| <= R_i + R_j``, which no crossing will reveal) is
        recorded at ``t`` and its action carried out on ``r``, ``v``, ``gm`` (in place;
        a merged body that overlaps another collides with it in turn).  True if the
        run must stop there."""
        while True:
            overlaps = self._overlaps(r)
            if not overlaps[3].size:
                return False
            self.drain()
            row = self._record_contact(t, v, overlaps, int(overlaps[3][0]))[0]
            if self.act(row, t, r, v, gm):
                return True

    def _record_contact(self, t: float, v: np.ndarray, overlaps: tuple[np.ndarray, ...],
                        k: int) -> tuple[int, int, int, int]:
        """Record the contact ``k`` of :meth:`_overlaps`'s ``overlaps`` as a collision at
        ``t`` (its distance there, the pair's relative speed in ``v``); returns its
        watch row, its two bodies and its action."""
        rows, pairs, d, _ = overlaps
        row, i, j = int(rows[k]), int(pairs[k, 0]), int(pairs[k, 1])
        action = int(self.watch[row, W_ACTION])
        self.rows.append(np.array([EVENTS["collision"][0], i, j, t, d[k],
                                   float(np.linalg.norm(v[i] - v[j])), action]))
        return row, i, j, action

    def act(self, row: int, t: float, r: np.ndarray, v: np.ndarray, gm: np.ndarray,
            at: float | None = None) -> bool:
        """Carry out the actions of the events of one step (wh, leapfrog) or one
        instant (radau15, dop853) on the state ``r``, ``v``, ``gm`` (changed in place);
        True if the run must stop.

        Parameters
        ----------
        row : int
            The watch row of the event the kernel stopped at.
        t : float
            The time the actions are taken at: the end of the step (wh, leapfrog),
            the event's own time (radau15, dop853).
        r, v : ndarray, shape (n, 3)
            Positions and velocities at ``t``, in the system's body order.
        gm : ndarray, shape (n,)
            The bodies' ``G m``.
        at : float, optional
            The time of the kernel's event, where the action is taken at the end of
            its step (wh, leapfrog); default ``t``.

        Returns
        -------
        bool
            Whether one of the actions is a stop.

        Notes
        -----
        The event of ``row`` acts first (the kernel's: the step's first with an
        action), then every other event with an action (stop, merge, remove) among
        the rows drained here, in the log's (time) order, each as
        ``_kept_until`` keeps the log up to it: the rows the scan found after
        an event of the same bodies are dropped, as are those of another pair of a
        body taken out at the same instant (a body touching two others at once
        merges into the first), and a row of a body an earlier action took out is
        dropped unacted.  Two pairs that touch in one step (wh, leapfrog) or at one
        instant to rounding (radau15, dop853) thus both merge, and two bodies that
        escape with ``"remove"`` both leave (only the kernel's event acted; the
        others stayed listed, their bodies going through each other or on).  The
        rows in the log before this call were acted on in their own steps (the
        drivers drain a step with an action here only), and are not acted on again.
        ``stopped_by`` is the first stop among them; the merges and removals are
        done also where a stop comes first.  ``gm_changes`` gets one entry, at
        ``t``, for each merge or removal.  A merged body that is then in contact with
        another watched for collisions (``|r_i - r_j| <= R_i + R_j``: its radius grew,
        its centre moved) collides with it at ``t``, and so on, as at a leg's start.

        ``"merge"`` keeps the lower-indexed body with the pair's summed ``gm`` at
        their centre of mass, with their total momentum and the radius of their
        summed volume; ``"remove"`` takes a body out.  A body taken out is parked
        far away with ``gm = 0`` (it then pulls on nothing and is pulled by almost
        nothing) and marked ``inactive``; its outputs are NaN from then on.
        """
        before = len(self.rows)
        self.drain()
        fresh = self.rows[before:]  # (this step's or instant's rows: see Notes)
        code, i, j, _, action = self.watch[row]
        done = [self._carry_out(code, int(i), int(j), int(action), t,
                                t if at is None else at, r, v, gm, [])]
        for x in [x for x in fresh if x[E_ACTION] != ACTIONS["record"]]:
            if any(x is y for y, _ in done) or id(x) not in {id(y) for y in self.rows}:
                continue  # (acted on, or dropped by an action as not having happened)
            bodies = [int(x[E_I])] + ([int(x[E_J])] if x[E_J] >= 0 else [])
            if self.inactive[bodies].any():  # (taken out by an action of the batch)
                self.rows = [y for y in self.rows if y is not x]
                continue
            done.append(self._carry_out(  # (at its own time: actions act forwards only)
                x[E_CODE], int(x[E_I]), int(x[E_J]), int(x[E_ACTION]), t, float(x[E_TIME]),
                r, v, gm, [y for y, _ in done]))
        if any(a == ACTIONS["merge"] for _, a in done):
            self._contacts(t, r, v, gm, done)
        stops = [y for y, a in done if a == ACTIONS["stop"]]
        if stops:  # (indices only now: each action's _kept_until drops rows before them)
            where = [k for k, y in enumerate(self.rows) if any(y is s for s in stops)]
            self.stopped_by = min(where) if where else len(self.rows) - 1
        return bool(stops)

    def _contacts(self, t: float, r: np.ndarray, v: np.ndarray, gm: np.ndarray,
                  done: list[tuple[np.ndarray | None, int]]) -> None:
        """After the merges of :meth:`act` (``done``: its actions so far, to which these
        are added), a merged body in contact with another watched for collisions (its
        radius grew, its centre moved: no crossing will reveal it) collides with it at
        ``t``, as at a leg's start (:meth:`at_start`), and so on: a leg begun there
        merged them where one call through went on.  A pair whose collision acted in
        this batch (a stop: still in contact) is not recorded again."""
        code = EVENTS["collision"][0]
        seen = {(int(y[E_I]), int(y[E_J])) for y, _ in done
                if y is not None and y[E_CODE] == code}
        while True:
            overlaps = self._overlaps(r)
            pairs = overlaps[1]
            new = [k for k in overlaps[3] if (int(pairs[k, 0]), int(pairs[k, 1])) not in seen]
            if not new:
                return
            _, i, j, action = self._record_contact(t, v, overlaps, int(new[0]))
            seen.add((i, j))
            done.append(self._carry_out(code, i, j, action, t, t, r, v, gm,
                                        [y for y, _ in done]))

    def _carry_out(self, code: float, i: int, j: int, action: int, t: float, at: float,
                   r: np.ndarray, v: np.ndarray, gm: np.ndarray,
                   acted: list[np.ndarray]) -> tuple[np.ndarray | None, int]:
        """One action of :meth:`act`: the log kept up to its event (the rows in ``acted``,
        carried out before it, kept), then the merge or removal done.  Returns the
        log's row of the event (None where the log has none) and the action."""
        gone = _NOBODY if action == ACTIONS["stop"] else j if action == ACTIONS["merge"] else i
        # (a further event of the instant may lie ulps after ``t``: see _same_instant)
        k = self._kept_until(code, i, j, action, max(t, at), at, gone, acted)
        acting = self.rows[k] if 0 <= k < len(self.rows) else None
        if action == ACTIONS["stop"]:
            return acting, action
        if action == ACTIONS["merge"]:
            m = gm[i] + gm[j]
            wi, wj = (gm[i] / m, gm[j] / m) if m > 0 else (0.5, 0.5)
            r[i] = wi * r[i] + wj * r[j]
            v[i] = wi * v[i] + wj * v[j]
            gm[i] = m
            self.radius[i] = np.cbrt(self.radius[i] ** 3 + self.radius[j] ** 3)
        self._park(gone, r, v, gm)
        self.gm_changes.append((t, gm.copy()))
        return acting, action

    def _kept_until(self, code: float, i: int, j: int, action: int, t: float, at: float,
                    gone: int, acted: Sequence[np.ndarray] = ()) -> int:
        """Keep the rows up to the event that acts: the row of this watch entry (its
        pair, code and action) at or before ``t`` nearest to ``at``, its time.  What the
        scan found later in the same step did not happen, the run going on (or
        ending) from it.  With wh and leapfrog, which act at the end of the step
        (``at < t``), the run has passed through the rest of the step: the rows of
        other bodies up to ``t`` are kept, those of the acting pair after its event
        dropped (they kept them all, listed a second merge of a pair merged once,
        and a stop named the last contact).  At the same instant, a row of another
        pair of the body the action takes out (``gone``) did not happen either (a
        body touching two others at once merges into the first); the same instant
        is the same time to rounding (:func:`_same_instant`).  The rows of
        ``acted``, events acted on before this one in the same step, are kept.
        Returns the index of the row that acts."""
        mine = [k for k, x in enumerate(self.rows)
                if x[E_I] == i and x[E_J] == j and x[E_CODE] == code and x[E_ACTION] == action
                and x[E_TIME] <= t]
        if not mine:  # (not found in the log: every row up to ``t`` kept, as before)
            self.rows = [x for x in self.rows if x[E_TIME] <= t]
            return len(self.rows) - 1
        acting = min(mine, key=lambda k: (abs(self.rows[k][E_TIME] - at), -k))
        t_ev = self.rows[acting][E_TIME]

        pair = {i, j} - {-1}  # (a one-body event's second body is -1: no body)

        def happened(k: int, x: np.ndarray) -> bool:
            bodies = {int(x[E_I]), int(x[E_J])} - {-1}
            if x[E_TIME] < t_ev or k == acting or any(x is y for y in acted):
                return True
            if _same_instant(x[E_TIME], t_ev):
                return gone not in bodies
            return x[E_TIME] <= t and t_ev < t and not pair & bodies

        kept = [k for k, x in enumerate(self.rows) if happened(k, x)]
        self.rows = [self.rows[k] for k in kept]
        return kept.index(acting)

    def park(self, k: int, r: np.ndarray, v: np.ndarray, gm: np.ndarray) -> None:
        """Take body ``k`` out of the run (in place in ``r``, ``v``, ``gm``): parked far
        away with ``gm = 0``, no longer watched (a run continued from a saved state
        whose body ``k`` had left)."""
        self._park(k, r, v, gm)

    def _park(self, k: int, r: np.ndarray, v: np.ndarray, gm: np.ndarray) -> None:
        scale = float(np.max(np.abs(r[~self.inactive]))) if np.any(~self.inactive) else 1.0
        gm[k] = 0.0
        r[k] = (1e8 * max(scale, 1.0)) * np.array([1.0 + k, 0.5, 0.25])
        v[k] = 0.0
        self.inactive[k] = True
        self.gone = True
        keep = ~(self.inactive[self.watch[:, W_I].astype(int)]
                 | ((self.watch[:, W_J] >= 0) & self.inactive[self.watch[:, W_J].astype(int)]))
        self.watch = np.ascontiguousarray(self.watch[keep])
        collision = self.watch[:, W_CODE] == EVENTS["collision"][0]
        pairs = self.watch[collision][:, [W_I, W_J]].astype(int)
        self.watch[collision, W_DIST] = self.radius[pairs[:, 0]] + self.radius[pairs[:, 1]]

    def gm_of(self, t: float, gm0: np.ndarray) -> np.ndarray:
        """``G m`` of every body at the one time ``t`` (n,), a new array: a row of
        :meth:`gm_at` without its arrays (a callback's output stands there: 5 us an
        output that way)."""
        gm = gm0
        for t_change, changed in self.gm_changes:
            if t >= t_change:
                gm = changed
        return np.array(gm, dtype=np.float64)

    def gm_at(self, times: np.ndarray, gm0: np.ndarray) -> np.ndarray:
        """``G m`` of every body at each of ``times`` (n_t, n): changed by merges and
        removals; ``gm0`` before the first."""
        out = np.repeat(np.asarray(gm0, dtype=np.float64)[None, :], len(times), axis=0)
        for t_change, gm in self.gm_changes:
            out[times >= t_change] = gm
        return out
