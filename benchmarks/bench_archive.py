"""Archives against rebound's Simulationarchive, same runs, same process.

Run:  NUMBA_NUM_THREADS=1 PYTHONPATH=src python benchmarks/bench_archive.py [--lengths | --ab]

(``--lengths``: section [8] alone; ``--ab``: section [9] alone.)

What it prints (medians over interleaved rounds; the machine is shared):

[1] one snapshot of the 10-body disc appended to an archive: ours (the state
    captured, a record appended to the segment with its CRC-32, the count in the
    header updated; ``sync=False`` as an archive writes by default) against
    rebound's ``save_to_file`` (a blob appended to one file); and ours saved alone
    (``Simulation.save``: a netCDF file written whole with its SHA-256, synced);
[2] a run with a snapshot every 100 steps: radau15 against IAS15 (adaptive,
    default tolerances) and wh against WHFast (dt = 0.05), each as the ratio of
    the archived run's time to the same run without an archive (ours: snapshots at
    every multiple of 100 mean steps, ``every=``, and for radau15 also
    ``every_steps=100``, snapshots between two steps; rebound: ``step=100``), over
    ``T_END`` (2000: 4-9 ms of fixed cost per archived call weigh on a 40 ms run)
    and ``10 * T_END`` (a run of 0.4 s);
[3] loading the last snapshot: ``Simulation.load(folder)`` against
    ``rebound.Simulation(file)``;
[4] where an ``every_steps=100`` snapshot's time goes in the 0.4 s radau15 run:
    the archive's fixed cost, the pauses alone, the whole (per snapshot);
[5] a simulation called 1200 times (radau15, 10 bodies, 0.5 days a call, one
    snapshot a call: each call goes on in the segment the last one wrote), the
    time per call over the first and the last 200 calls, against the same calls
    without an archive and rebound's IAS15 call followed by ``save_to_file`` (a
    snapshot appended to its archive);
[6] loading the last snapshot, and one in the middle, of a long run's archive
    (a snapshot every 10 steps of the 0.3 s radau15 run) against rebound's
    Simulationarchive of IAS15 with ``step=10``: a snapshot read alone, whatever
    the segment's length;
[7] where a snapshot's time goes in the 0.3 s radau15 run, ``every=`` and
    ``every_steps=100``: inside the calls of the compiled steps (their entry,
    ``every=``'s landing steps) and outside them (the Python of pauses, outputs
    and snapshots, the archive's fixed cost spread over the run), per snapshot;
[8] the cost against the run's length: ``every_steps=100`` and ``every=`` (their
    snapshots appended by radau15's compiled call once two are written, and,
    beside each, all of them written by Python, ``segment.COMPILED_WRITES =
    False``; radau15, the 10-body disc) and rebound's IAS15 with ``step=100``, each
    archived / plain in CPU time of the process (the machine's other work not
    counted), over runs of
    125 to 20000 time units (2 ms to 0.3 s of ours, twice that of IAS15): the
    archive's fixed cost per call (its folder, lock, two files and first snapshot)
    against the per-snapshot cost, and the shortest run within 5%;
[9] (``--ab`` only) for comparing two checkouts in alternating processes
    (``PYTHONPATH`` pointing at each in turn): a run of 125 time units (3
    snapshots), then one of 5000 (92 snapshots), plain, and the extra CPU time of
    ``every_steps=100`` and of ``every=`` (every 100 mean steps of time), each the
    minimum over interleaved rounds (25, then 15) less the plain run's (on a busy
    host the minimum is what repeats).
"""

from __future__ import annotations

import math
import shutil
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import rebound
from bench_overhead import rebound_of

from hamilton_orbits import Archive, Body, Simulation, System, segment

T_END = 2000.0
DT = 0.05


def disc10() -> System:
    """A star (GM 1) and nine planets (GM 1e-5) on near-circular orbits at 1-10."""
    rng = np.random.default_rng(1)
    a = rng.uniform(1.0, 10.0, 9)
    ph = rng.uniform(0, 2 * np.pi, 9)
    bodies = [Body("star", 1.0, [0, 0, 0], [0, 0, 0])]
    for k in range(9):
        r = [a[k] * np.cos(ph[k]), a[k] * np.sin(ph[k]), 0.01 * k]
        v = [-np.sin(ph[k]) / np.sqrt(a[k]), np.cos(ph[k]) / np.sqrt(a[k]), 0.0]
        bodies.append(Body(f"p{k}", 1e-5, r, v))
    return System(bodies)


def timed(fn: Callable[[], object], clock: Callable[[], float] = time.perf_counter) -> float:
    start = clock()
    fn()
    return clock() - start


def interleaved(fns: dict[str, Callable[[], object]], rounds: int,
                clock: Callable[[], float] = time.perf_counter) -> dict[str, list[float]]:
    for fn in fns.values():
        fn()
    out: dict[str, list[float]] = {k: [] for k in fns}
    for _ in range(rounds):
        for k, fn in fns.items():
            out[k].append(timed(fn, clock))
    return out


def one_snapshot(tmp: Path, repeat: int) -> None:
    from hamilton_orbits.checkpoint import ArchiveWriter

    s = disc10()
    arrays = s.as_arrays()
    sim = Simulation(s, method="radau15")
    sim.integrate(10.0)
    reb = rebound_of(arrays.r, arrays.v, arrays.gm, "ias15", DT)
    reb.integrate(10.0)
    reb_file = tmp / "rebound-one.bin"
    writer = ArchiveWriter(tmp / "ours-one", every=1.0)
    writer.open()

    def ours() -> None:
        writer.write(*sim._record(archive=True))

    def saved() -> None:
        sim.save(tmp / "ours-one.nc")

    def theirs() -> None:
        reb.save_to_file(str(reb_file))

    t = interleaved({"ours": ours, "saved": saved, "rebound": theirs}, repeat)
    writer.close()
    med = {k: statistics.median(v) * 1e3 for k, v in t.items()}
    print("[1] one snapshot of 10 bodies appended to an archive (ms, median of", repeat, "):")
    print(f"    ours {med['ours']:.3f}, rebound {med['rebound']:.3f}; ours / rebound = "
          f"{med['ours'] / med['rebound']:.2f}  (Simulation.save, a synced file: "
          f"{med['saved']:.3f})")


def runs(tmp: Path, rounds: int, t_end: float = T_END) -> None:
    s = disc10()
    arrays = s.as_arrays()
    probe = Simulation(s, method="radau15")
    probe.integrate(t_end)
    mean_step = t_end / probe.steps
    every = {"radau15": 100 * mean_step, "wh": 100 * DT}

    def ours(method: str, archived: bool | str | None) -> Callable[[], None]:
        count = iter(range(10**6))

        def go() -> None:
            folder = tmp / f"ours-{method}-{archived}-{next(count)}"  # a new folder each run
            # (archived None: the archive's fixed cost alone, a snapshot at the start)
            kw = dict(archive=folder, every=every[method] if archived else 1e9)
            if archived is False:
                kw = {}
            elif archived == "steps":
                kw = dict(archive=folder, every_steps=100)
            sim = Simulation(s, method=method, dt=DT if method == "wh" else None, **kw)
            sim.integrate(t_end)
        return go

    def theirs(integrator: str, archived: bool) -> Callable[[], None]:
        def go() -> None:
            reb = rebound_of(arrays.r, arrays.v, arrays.gm, integrator, DT)
            if integrator == "ias15":
                reb.integrator.epsilon = 1e-9  # rebound's default
            if archived:
                reb.save_to_file(str(tmp / f"reb-{integrator}.bin"), step=100, delete_file=True)
            reb.integrate(t_end, exact_finish_time=1)
        return go

    print(f"[2] a run of {t_end:g} (10 bodies) with a snapshot every 100 steps: archived / "
          f"plain (median of {rounds} rounds)")
    for method, peer in (("radau15", "ias15"), ("wh", "whfast")):
        cases = {"ours": ours(method, False), "ours-archived": ours(method, True),
                 "ours-once": ours(method, None),
                 "theirs": theirs(peer, False), "theirs-archived": theirs(peer, True)}
        if method == "radau15":
            cases["ours-steps"] = ours(method, "steps")
        t = interleaved(cases, rounds)
        fixed = statistics.median(a - b for a, b in zip(t["ours-once"], t["ours"],
                                                        strict=True))
        r_ours = statistics.median(a / b for a, b in zip(t["ours-archived"], t["ours"],
                                                          strict=True))
        r_theirs = statistics.median(a / b for a, b in zip(t["theirs-archived"], t["theirs"],
                                                            strict=True))
        n_ours = len(Archive(tmp / f"ours-{method}-True-1"))
        print(f"    {method:8s} x{r_ours:.3f} ({n_ours} snapshots, plain "
              f"{statistics.median(t['ours']) * 1e3:.1f} ms; of which the archive's fixed "
              f"cost, its folder and first snapshot, {fixed * 1e3:.2f} ms);  {peer} "
              f"x{r_theirs:.3f} (plain {statistics.median(t['theirs']) * 1e3:.1f} ms)")
        if "ours-steps" in t:
            r_steps = statistics.median(a / b for a, b in zip(t["ours-steps"], t["ours"],
                                                               strict=True))
            n_steps = len(Archive(tmp / f"ours-{method}-steps-1"))
            print(f"    {method:8s} every_steps=100: x{r_steps:.3f} ({n_steps} snapshots, "
                  f"between two steps)")


def loading(tmp: Path, repeat: int) -> None:
    folder, reb_file = tmp / "ours-radau15-True-1", tmp / "reb-ias15.bin"

    def ours() -> None:
        Simulation.load(folder)

    def theirs() -> None:
        sa = rebound.Simulationarchive(str(reb_file))
        sa[-1]

    t = interleaved({"ours": ours, "theirs": theirs}, repeat)
    med = {k: statistics.median(v) * 1e3 for k, v in t.items()}
    print(f"[3] loading the last snapshot (ms): ours {med['ours']:.2f} (the whole snapshot "
          f"verified, the simulation rebuilt), rebound {med['theirs']:.2f}")


def parts(tmp: Path, rounds: int, t_end: float = 10 * T_END) -> None:
    """Where the time of an ``every_steps=100`` snapshot goes in a radau15 run: the
    archive's fixed cost alone (one snapshot at the start), the pauses with nothing
    written (the schedule kept), and the whole; per snapshot, against the plain run
    (interleaved rounds, one process)."""
    from hamilton_orbits import _saving

    s, count, whole = disc10(), iter(range(10**6)), _saving.Saving._snapshot

    def nothing(self: object, rows: object, again: bool = False) -> None:
        if not again:
            return whole(self, rows, again)
        arch = self._archive  # (the schedule kept, nothing written)
        arch.count += 1
        arch.last_steps = self._prop.steps

    folders: dict[str, Path] = {}

    def go(every: int | None, snapshot: Callable[..., None] = whole) -> Callable[[], None]:
        def run() -> None:
            _saving.Saving._snapshot = snapshot
            folder = folders[snapshot.__name__] = tmp / f"parts-{next(count)}"
            kw = {} if every is None else dict(archive=folder, every_steps=every)
            try:
                Simulation(s, method="radau15", **kw).integrate(t_end)
            finally:
                _saving.Saving._snapshot = whole
        return run

    t = interleaved({"plain": go(None), "fixed": go(10**9), "pauses": go(100, nothing),
                     "whole": go(100)}, rounds)
    n = len(Archive(folders["_snapshot"]))  # (the whole: every snapshot written)
    plain = statistics.median(t["plain"])
    print(f"[4] an every_steps=100 snapshot in a radau15 run of {t_end:g}, per snapshot "
          f"({n}), median of {rounds} rounds: " + ", ".join(
              f"{k} {(statistics.median(t[k]) - plain) / n * 1e6:.1f} us"
              for k in ("fixed", "pauses", "whole")))


def inside_and_out(tmp: Path, rounds: int, t_end: float = 10 * T_END) -> None:
    """Where a snapshot's time goes in a radau15 run, ``every=`` (every 100 mean steps
    of time) and ``every_steps=100``: in the calls of the compiled steps (timed
    around each: a call's entry and its first steps with cold caches, and for
    ``every=`` the landing steps and their corrector iterations) and outside them
    (the Python of the pauses, the outputs and the snapshots, the archive's fixed
    cost), per snapshot, against the plain run (interleaved rounds)."""
    from hamilton_orbits._kernels import radau15 as kernels

    s, count, stepping = disc10(), iter(range(10**6)), kernels.advance
    probe = Simulation(s, method="radau15")
    probe.integrate(t_end)
    inside = [0.0]

    def timed_kernel(*args: object) -> object:
        start = time.perf_counter()
        out = stepping(*args)
        inside[0] += time.perf_counter() - start
        return out

    def go(kw: dict[str, object]) -> Callable[[], tuple[float, float]]:
        def run() -> tuple[float, float]:
            extra = dict(kw, archive=tmp / f"split-{next(count)}") if kw else {}
            inside[0] = 0.0
            start = time.perf_counter()
            Simulation(s, method="radau15", **extra).integrate(t_end)
            return time.perf_counter() - start, inside[0]
        return run

    cases = {"plain": go({}), "every": go(dict(every=100 * t_end / probe.steps)),
             "every_steps": go(dict(every_steps=100))}
    kernels.advance = timed_kernel  # (looked up at each call by the driver)
    try:
        out: dict[str, list[tuple[float, float]]] = {k: [] for k in cases}
        for fn in cases.values():
            fn()
        for _ in range(rounds):
            for k, fn in cases.items():
                out[k].append(fn())
    finally:
        kernels.advance = stepping
    n = probe.steps // 100
    med = {k: (statistics.median(x[0] for x in v), statistics.median(x[1] for x in v))
           for k, v in out.items()}
    plain_in, plain_out = med["plain"][1], med["plain"][0] - med["plain"][1]
    print(f"[7] a snapshot in a radau15 run of {t_end:g} (about {n}), per snapshot, median "
          f"of {rounds} rounds: " + "; ".join(
              f"{k} in the compiled calls {(med[k][1] - plain_in) / n * 1e6:+.1f} us, outside "
              f"them {(med[k][0] - med[k][1] - plain_out) / n * 1e6:+.1f} us (x"
              f"{med[k][0] / med['plain'][0]:.3f} in all)" for k in ("every", "every_steps")))


def many_calls(tmp: Path, calls: int = 1200, block: int = 200) -> None:
    s = disc10()
    arrays = s.as_arrays()
    archived = Simulation(s, method="radau15", archive=tmp / "calls", every=1e9)
    plain = Simulation(s, method="radau15")
    reb_file = tmp / "calls-rebound.bin"
    reb = rebound_of(arrays.r, arrays.v, arrays.gm, "ias15", DT)
    reb.integrator.epsilon = 1e-9

    def rebound_call(t: float) -> None:  # (its call, then a snapshot appended)
        reb.integrate(t, exact_finish_time=1)
        reb.save_to_file(str(reb_file))

    per_call: dict[str, list[float]] = {"archived": [], "plain": [], "rebound": []}
    for k in range(1, calls + 1):
        for name, sim in (("archived", archived), ("plain", plain)):
            per_call[name].append(timed(lambda sim=sim, k=k: sim.integrate(0.5 * k)))
        per_call["rebound"].append(timed(lambda k=k: rebound_call(0.5 * k)))
    first, last = (slice(1, block + 1), slice(calls - block, calls))
    ms = {f"{n} {w}": statistics.median(per_call[n][part]) * 1e3
          for n in per_call for w, part in (("first", first), ("last", last))}
    files = len(list((tmp / "calls").iterdir()))
    print(f"[5] {calls} calls of one simulation, one snapshot each (ms per call, medians of "
          f"{block}): archived {ms['archived first']:.2f} (calls 2-{block + 1}) and "
          f"{ms['archived last']:.2f} (the last {block}; {files} files in the folder); "
          f"plain {ms['plain first']:.3f} and {ms['plain last']:.3f}; rebound's IAS15 call "
          f"and save_to_file {ms['rebound first']:.3f} and {ms['rebound last']:.3f}")


def long_archive(tmp: Path, repeat: int = 15, t_end: float = 10 * T_END) -> None:
    """Loading the last snapshot, and one in the middle, of a long run's archive: a
    snapshot every 10 steps of the 0.3 s radau15 run (one segment of ~3700), against
    rebound's Simulationarchive of IAS15 with ``step=10`` over the same time."""
    s = disc10()
    arrays = s.as_arrays()
    folder, reb_file = tmp / "long-archive", tmp / "long-rebound.bin"
    Simulation(s, method="radau15", archive=folder, every_steps=10).integrate(t_end)
    reb = rebound_of(arrays.r, arrays.v, arrays.gm, "ias15", DT)
    reb.integrator.epsilon = 1e-9
    reb.save_to_file(str(reb_file), step=10, delete_file=True)
    reb.integrate(t_end, exact_finish_time=1)
    archive = Archive(folder)
    n, size = len(archive), sum(p.stat().st_size for p in folder.iterdir())
    n_reb = len(rebound.Simulationarchive(str(reb_file)))

    def ours_last() -> None:
        Simulation.load(folder)

    def ours_middle() -> None:
        archive[n // 2]

    def theirs_last() -> None:
        rebound.Simulationarchive(str(reb_file))[-1]

    def theirs_middle() -> None:
        rebound.Simulationarchive(str(reb_file))[n_reb // 2]

    opened = rebound.Simulationarchive(str(reb_file))

    def theirs_opened() -> None:
        opened[n_reb // 2]

    t = interleaved({"ours last": ours_last, "ours middle": ours_middle,
                     "theirs last": theirs_last, "theirs middle": theirs_middle,
                     "theirs opened": theirs_opened}, repeat)
    med = {k: statistics.median(v) * 1e3 for k, v in t.items()}
    print(f"[6] a long run's archive ({n} snapshots, {size / 1e6:.1f} MB; rebound's "
          f"{n_reb}, {reb_file.stat().st_size / 1e6:.1f} MB), ms, median of {repeat}: the "
          f"last loaded: ours {med['ours last']:.2f}, rebound {med['theirs last']:.2f}; "
          f"the middle one: ours {med['ours middle']:.2f} (Archive[k], the archive listed "
          f"once before), rebound {med['theirs middle']:.2f} (the file opened each time), "
          f"{med['theirs opened']:.2f} (opened once before)")


def lengths(tmp: Path, rounds: int, ends: tuple[float, ...] = (125.0, 250.0, 500.0, 1000.0,
                                                               2000.0, 5000.0, 20000.0)) -> None:
    """Archived / plain against the run's length, ours (``every_steps=100``) and
    rebound's (IAS15, ``step=100``), interleaved rounds per length; and a fit of
    ours as ``1 + per_snapshot * n / plain + fixed / plain`` (least squares over the
    lengths' medians of the extra time), to say from which length it is within 5%
    (``every=``, every 100 mean steps of time, beside it)."""
    s = disc10()
    arrays = s.as_arrays()
    count = iter(range(10**6))

    def ours(t_end: float, archived: dict[str, float] | None,
             kernel: bool = True) -> Callable[[], None]:
        def go() -> None:
            kw = {} if archived is None else dict(archived, archive=tmp / f"len-{next(count)}")
            segment.COMPILED_WRITES = kernel
            try:
                Simulation(s, method="radau15", **kw).integrate(t_end)
            finally:
                segment.COMPILED_WRITES = True
        return go

    def theirs(t_end: float, archived: bool) -> Callable[[], None]:
        def go() -> None:
            reb = rebound_of(arrays.r, arrays.v, arrays.gm, "ias15", DT)
            reb.integrator.epsilon = 1e-9
            if archived:
                reb.save_to_file(str(tmp / "len-rebound.bin"), step=100, delete_file=True)
            reb.integrate(t_end, exact_finish_time=1)
        return go

    print(f"[8] archived / plain against the run's length, a snapshot every 100 steps "
          f"(CPU time of the process, medians of {rounds} interleaved rounds):")
    extra, plain_ms, snaps = [], [], []
    for t_end in ends:
        probe = Simulation(s, method="radau15")
        probe.integrate(t_end)
        n = probe.steps // 100 + 1  # (the start's snapshot, then one every 100 steps)
        t = interleaved({"ours": ours(t_end, None),
                         "ours-archived": ours(t_end, {"every_steps": 100}),
                         "ours-python": ours(t_end, {"every_steps": 100}, kernel=False),
                         "ours-every": ours(t_end, {"every": 100 * t_end / probe.steps}),
                         "ours-every-python": ours(t_end, {"every": 100 * t_end / probe.steps},
                                                   kernel=False),
                         "theirs": theirs(t_end, False),
                         "theirs-archived": theirs(t_end, True)}, rounds, time.process_time)
        r_ours, r_python, r_every, r_every_python = (
            statistics.median(a / b for a, b in zip(t[k], t["ours"], strict=True))
            for k in ("ours-archived", "ours-python", "ours-every", "ours-every-python"))
        r_theirs = statistics.median(a / b for a, b in zip(t["theirs-archived"], t["theirs"],
                                                            strict=True))
        plain = statistics.median(t["ours"])
        extra.append(statistics.median(a - b for a, b in zip(t["ours-archived"], t["ours"],
                                                             strict=True)))
        plain_ms.append(plain)
        snaps.append(n)
        print(f"    {t_end:7g}: ours x{r_ours:.3f} (Python's records x{r_python:.3f}), every= "
              f"x{r_every:.3f} (Python's x{r_every_python:.3f}) (plain "
              f"{plain * 1e3:6.1f} ms, {n:3d} snapshots), rebound x{r_theirs:.3f} (plain "
              f"{statistics.median(t['theirs']) * 1e3:6.1f} ms)")
    per, fixed = np.linalg.lstsq(np.column_stack([snaps, np.ones(len(snaps))]),
                                 np.array(extra), rcond=None)[0]
    step = plain_ms[-1] / (snaps[-1] - 1) / 100  # (seconds per step, the longest run)
    rate = per / (100 * step)
    within = fixed / (0.05 - rate) if rate < 0.05 else math.inf
    print(f"    fit of ours: {per * 1e6:.1f} us a snapshot ({rate * 100:.1f}% of its 100 "
          f"steps), {fixed * 1e3:.2f} ms fixed a call: within 5% from a run of "
          f"{within * 1e3:.0f} ms")


def extra_minima(tmp: Path, rounds: int, t_end: float = 5000.0) -> None:
    """Section [9]: the plain run's minimum CPU time and what each schedule adds to
    it (minimum less minimum), interleaved rounds."""
    s = disc10()
    probe = Simulation(s, method="radau15")
    probe.integrate(t_end)
    count = iter(range(10**6))
    kinds = {"plain": None, "every_steps": {"every_steps": 100},
             "every": {"every": 100 * t_end / probe.steps}}

    def run(kw: dict[str, float] | None) -> Callable[[], None]:
        def go() -> None:
            more = {} if kw is None else dict(kw, archive=tmp / f"ab-{t_end:g}-{next(count)}")
            Simulation(s, method="radau15", **more).integrate(t_end)
        return go

    t = interleaved({k: run(kw) for k, kw in kinds.items()}, rounds, time.process_time)
    plain = min(t["plain"])
    print(f"[9] a run of {t_end:g} ({probe.steps // 100 + 1} snapshots), CPU time, minima "
          f"of {rounds} rounds: plain {plain * 1e3:.1f} ms; every_steps=100 adds "
          f"{(min(t['every_steps']) - plain) * 1e3:.2f} ms, every= "
          f"{(min(t['every']) - plain) * 1e3:.2f} ms")


def main() -> None:
    print(time.strftime("run of %Y-%m-%d %H:%M UTC", time.gmtime()))
    tmp = Path(tempfile.mkdtemp(prefix="bench-archive-"))
    if "--ab" in sys.argv:  # (section 9 alone: a run of 3 snapshots, then one of 92)
        try:
            extra_minima(tmp, 25, 125.0)
            extra_minima(tmp, 15)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
        return
    if "--lengths" in sys.argv:  # (section 8 alone)
        try:
            (tmp / "lengths").mkdir()
            lengths(tmp / "lengths", 15)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
        return
    try:
        one_snapshot(tmp, 200)
        runs(tmp, 9)
        loading(tmp, 30)
        (tmp / "long").mkdir()
        runs(tmp / "long", 9, 10 * T_END)
        (tmp / "parts").mkdir()
        parts(tmp / "parts", 15)
        many_calls(tmp)
        long_archive(tmp)
        (tmp / "split").mkdir()
        inside_and_out(tmp / "split", 9)
        (tmp / "lengths").mkdir()
        lengths(tmp / "lengths", 15)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
