"""Ensemble overhead: 64 short members locally, on a local Dask cluster, and in sequence.

Each member is the bundled ``dzhanibekov`` scene shortened to 20 s of simulated
time with its own step (a few hundredths of a second of work).  Printed: wall
time of each way, the speed-up over running the members one after another in
this process, and the overhead per member.  Medians of ``--repeats`` runs.

Run: python benchmarks/bench_ensemble.py [--quick] [--repeats N]
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

from hamilton_orbits import Ensemble, Scene
from hamilton_orbits.ensemble import run_member


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="16 members, 1 repeat")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    n = 16 if args.quick else 64
    repeats = 1 if args.quick else args.repeats
    scene = Scene.bundled("dzhanibekov").with_values({"duration": "20 s"})
    steps = [f"{1 + k * 0.01:.2f} ms" for k in range(n)]
    ens = Ensemble(scene, vary={"integrator.dt": steps})
    run_member(scene.data, scene.source, {"integrator.dt": "1 ms"})  # JIT warm-up
    t0 = time.perf_counter()
    ens.run(progress=False)  # starts the local pool: worker imports, kernels from cache
    first_local = time.perf_counter() - t0

    def sequential() -> None:
        for m in ens.members:
            run_member(scene.data, scene.source, m)

    def local() -> None:
        ens.run(progress=False)

    timings: dict[str, list[float]] = {"sequential": [], "local pool": [], "dask local": []}
    for _ in range(repeats):
        for name, fn in (("sequential", sequential), ("local pool", local)):
            t0 = time.perf_counter()
            fn()
            timings[name].append(time.perf_counter() - t0)
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        timings.pop("dask local")
        print("dask not installed: pip install 'hamilton-orbits[dask]'")
    else:
        with LocalCluster(n_workers=os.cpu_count(), threads_per_worker=1,
                          dashboard_address=None) as cluster, Client(cluster) as client:
            ens.run(client=client, progress=False)  # workers import and compile once
            for _ in range(repeats):
                t0 = time.perf_counter()
                ens.run(client=client, progress=False)
                timings["dask local"].append(time.perf_counter() - t0)
    seq = statistics.median(timings["sequential"])
    print(f"{n} members on {os.cpu_count()} cores ({time.strftime('%Y-%m-%d')}), "
          f"median of {repeats}")
    print(f"{'way':<12}{'wall (s)':>10}{'speed-up':>10}{'overhead/member (ms)':>22}")
    for name, ts in timings.items():
        t = statistics.median(ts)
        over = (t - seq / (os.cpu_count() or 1)) / n * 1e3 if name != "sequential" else 0.0
        print(f"{name:<12}{t:>10.2f}{seq / t:>10.2f}{over:>22.1f}")
    print(f"(the first local run, which starts the worker processes, took {first_local:.2f} s;"
          " both pools then keep their workers)")


if __name__ == "__main__":
    main()
