"""Per step against rebound at N = 2, 3, 10, 30, 100, for comparing two checkouts.

Run:  NUMBA_NUM_THREADS=1 PYTHONPATH=<checkout>/src python benchmarks/bench_per_step_ab.py

What it prints: ours (radau15 at a fixed step; wh, democratic heliocentric) beside
rebound (IAS15 with epsilon 0; WHFast, democratic heliocentric, safe_mode 0) per step
on a disc (a star of GM 1 and planets of GM 1e-7 at 1-10, dt = 0.05), CPU time, five
interleaved rounds, ratio = rebound / ours (median of the per-round ratios).  Section
[3] of ``bench_nbody.py`` measures the same with more sizes; this one is short enough
to run in alternating processes against an older checkout (``PYTHONPATH`` pointing at
each in turn), which is how a change's before / after is quoted.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable

import numpy as np
import rebound
from bench_overhead import rebound_of  # the same rebound set-up as there

from hamilton_orbits.integrators import radau15, wh
from hamilton_orbits.rhs import newtonian_rhs

DT = 0.05


def disc(n: int, seed: int = 1) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A star (GM 1) and ``n - 1`` planets (GM 1e-7) on circular, slightly inclined orbits."""
    rng = np.random.default_rng(seed)
    a = rng.uniform(1.0, 10.0, n - 1)
    ph = rng.uniform(0, 2 * np.pi, n - 1)
    inc = rng.uniform(0, 0.05, n - 1)
    r, v = np.zeros((n, 3)), np.zeros((n, 3))
    r[1:] = a[:, None] * np.stack([np.cos(ph), np.sin(ph) * np.cos(inc),
                                   np.sin(ph) * np.sin(inc)], axis=1)
    v[1:] = (1 / np.sqrt(a))[:, None] * np.stack([-np.sin(ph), np.cos(ph) * np.cos(inc),
                                                  np.cos(ph) * np.sin(inc)], axis=1)
    gm = np.full(n, 1e-7)
    gm[0] = 1.0
    return r, v, gm


def cpu(fn: Callable[[], object]) -> float:
    start = time.process_time()
    fn()
    return time.process_time() - start


def rounds(ours: Callable[[], object], theirs: Callable[[], object], steps: int
           ) -> tuple[float, float, float]:
    """Ours and theirs per step (us) and the median per-round ratio theirs / ours."""
    ours()
    theirs()
    times = [(cpu(ours), cpu(theirs)) for _ in range(5)]
    med = statistics.median
    return (med(a for a, _ in times) / steps * 1e6, med(b for _, b in times) / steps * 1e6,
            med(b / a for a, b in times))


def main() -> None:
    rhs = newtonian_rhs()
    print("N    radau15 us/step   IAS15   ratio |  wh us/step  WHFast   ratio")
    for n in (2, 3, 10, 30, 100):
        r, v, gm = disc(n)
        steps = int(max(50, min(50_000, 2e7 / (n * n) / 20)))  # ~10^6 pair evaluations
        t_out = np.array([0.0, steps * DT])
        ias, whf = rebound_of(r, v, gm, "ias15", DT), rebound_of(r, v, gm, "whfast", DT)

        def whfast(whf: rebound.Simulation = whf, t_end: float = t_out[1]) -> None:
            copy = whf.copy()
            copy.integrate(t_end, exact_finish_time=0)
            copy.synchronize()

        a = rounds(lambda r=r, v=v, gm=gm, t_out=t_out: radau15.run(rhs, r, v, gm, t_out, dt=DT),
                   lambda ias=ias, t_end=t_out[1]: ias.copy().integrate(
                       t_end, exact_finish_time=0), steps)
        b = rounds(lambda r=r, v=v, gm=gm, t_out=t_out: wh.run(rhs, r, v, gm, t_out, dt=DT),
                   whfast, steps)
        print(f"{n:<4d} {a[0]:12.2f} {a[1]:9.2f} {a[2]:7.2f} | {b[0]:10.2f} {b[1]:8.2f} "
              f"{b[2]:7.2f}", flush=True)


if __name__ == "__main__":
    main()
