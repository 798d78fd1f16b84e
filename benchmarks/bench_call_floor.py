"""The floor of a continuing wh call that returns a Trajectory, beside WHFast's call.

Run:  NUMBA_NUM_THREADS=1 python benchmarks/bench_call_floor.py [--rounds 7]

Issue 30 asks a continuing ``sim.integrate(t + dt)`` of one wh step of ten bodies
to cost no more than rebound's WHFast ``sim.integrate(t + dt)``.  This script
measures, in one process, on the disc of ``bench_overhead.py`` (a star and nine
planets of GM 1e-7, dt = 0.01, democratic heliocentric):

1. ours: ``Simulation.integrate(sim.t + dt)``, the library's call;
2. lean: the same kernels with the least Python around them that still returns
   the leg (the step count, the kernel, the conversion to inertial coordinates,
   the finite check, a ``Trajectory`` made by hand; nothing validated);
3. fused: one compiled function doing the step count, the steps, the conversion
   and the finite check (written here, from the kernels' own inline parts), with
   the same least Python around it;
4. the fused function alone (numba's dispatch of its 12 arguments and the step);
5. WHFast, ``safe_mode`` 1 (rebound's default: synchronised after each call, the
   same work as ours) and 0.

The times are ``timeit``'s best of ``--rounds`` repeats of 20 000 calls (the
machine is shared: the best is the least disturbed).  The private kernel parts
are imported on purpose: this is an experiment on what a compiled continuing
entry could reach, not a path of the library.
"""

from __future__ import annotations

import argparse
import math
import time
import timeit

import numpy as np
from bench_overhead import _disc10, rebound_of
from numba import njit

from hamilton_orbits import Simulation, System
from hamilton_orbits._kernels import wh as _k
from hamilton_orbits._kernels.checks import all_finite
from hamilton_orbits._kernels.signatures import accel_at
from hamilton_orbits.trajectory import Trajectory

DT = 0.01


@njit(error_model="numpy")
def _fused(extra_addr, p, order, q, u, gm, com, dt, t0, t1, ws, rows):  # pragma: no cover
    """Steps from ``t0`` to ``t1`` (the last shortened), inertial rows 1 of ``rows``,
    and whether all of ``rows`` is finite."""
    span = t1 - t0
    n = max(1, math.ceil(span / dt * (1.0 - 1e-12)))
    ws[0] = t0
    extra = accel_at(extra_addr[0], extra_addr[1])
    _, _, mu, _, kick = _k._dh_setup(gm, False, False, order, gm)
    steps, bad, _ = _k._dh_unwatched_steps(None, extra, p, q, u, gm, com, dt, n,
                                           span - (n - 1) * dt, ws, mu, kick, True)
    _k.dh_to_inertial(q, u, gm, com, order, rows[0, 1], rows[1, 1])
    finite = True
    for x in rows.reshape(-1):
        if not math.isfinite(x):
            finite = False
    return steps, bad, finite


def _leg(names, t0, t_end, rows, steps, wall):
    """A Trajectory of a two-row leg, made by hand (no integrals, no final system)."""
    traj = Trajectory.__new__(Trajectory)
    traj.__dict__.update({"t": np.array((t0, t_end)), "r": rows[0], "v": rows[1],
                          "names": names, "steps": steps, "method": "wh", "effects": (),
                          "wall_time": wall, "complete": True, "_integrals": None,
                          "_final_source": None})
    return traj


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=7)
    args = parser.parse_args()
    r, v, gm = _disc10()
    system = System.from_arrays(gm, r, v)
    sims = [Simulation(system, method="wh", dt=DT) for _ in range(3)]
    for sim in sims:
        sim.integrate(DT)  # (the integrator made: the later calls continue)
    names = system.names

    def parts(sim):
        prop = sim._prop
        split = prop.driver.split
        return prop, prop.driver, split, (split.extra, split.p, split.order, split.q,
                                          split.u, split.g, split.com)

    def lean(sim=sims[1]):
        prop, driver, split, a = parts(sim)
        t0, t_end = prop.t, prop.t + DT
        span = t_end - t0
        n = max(1, math.ceil(span / DT * (1.0 - 1e-12)))
        rows = np.empty((2, 2) + prop.r.shape)
        rows[0, 0], rows[1, 0] = prop.r, prop.v
        driver.ws[0] = t0
        start = time.perf_counter()
        steps, _, _ = _k.advance_dh_few(a[0], a[1], False, *a[2:], DT, n, span - (n - 1) * DT,
                                        driver.ws)
        _k.dh_to_inertial(split.q, split.u, split.g, split.com, split.order, rows[0, 1],
                          rows[1, 1])
        wall = time.perf_counter() - start
        all_finite(rows.reshape(-1))
        driver.steps += steps
        driver.t = prop.t = t_end
        prop.r, prop.v = rows[0, 1], rows[1, 1]
        return _leg(names, t0, t_end, rows, steps, wall)

    def fused(sim=sims[2]):
        prop, driver, _, a = parts(sim)
        t0, t_end = prop.t, prop.t + DT
        rows = np.empty((2, 2) + prop.r.shape)
        rows[0, 0], rows[1, 0] = prop.r, prop.v
        start = time.perf_counter()
        steps, _, _ = _fused(*a, DT, t0, t_end, driver.ws, rows)
        wall = time.perf_counter() - start
        driver.steps += steps
        driver.t = prop.t = t_end
        prop.r, prop.v = rows[0, 1], rows[1, 1]
        return _leg(names, t0, t_end, rows, steps, wall)

    # the three give the same bits (the floor is of the same computation)
    legs = [sims[0].integrate(sims[0].t + DT), lean(), fused()]
    same = all(np.array_equal(leg.r, legs[0].r) and np.array_equal(leg.v, legs[0].v)
               for leg in legs[1:])
    prop, driver, _, a = parts(sims[2])
    scratch = np.empty((2, 2) + prop.r.shape)
    peers = {}
    for mode in (1, 0):
        reb = rebound_of(r, v, gm, "whfast", DT)
        reb.integrator.safe_mode = mode
        peers[mode] = reb
    cases = {
        "ours: Simulation.integrate": lambda: sims[0].integrate(sims[0].t + DT),
        "lean Python, the same kernels": lean,
        "fused kernel, lean Python": fused,
        "fused kernel alone": lambda: _fused(*a, DT, driver.t, driver.t + DT, driver.ws,
                                             scratch),
        "WHFast, safe_mode 1": lambda: peers[1].integrate(peers[1].t + DT,
                                                          exact_finish_time=0),
        "WHFast, safe_mode 0": lambda: peers[0].integrate(peers[0].t + DT,
                                                          exact_finish_time=0),
    }
    print(time.strftime("run of %Y-%m-%d %H:%M UTC", time.gmtime()) + ": one wh step of 10 "
          f"bodies per call, best of {args.rounds} x 20000 calls; the three of ours give the "
          f"same bits: {same}")
    best = {}
    for name, fn in cases.items():
        fn()
        best[name] = min(timeit.repeat(fn, number=20000, repeat=args.rounds)) / 20000 * 1e6
    peer = best["WHFast, safe_mode 1"]
    for name, us in best.items():
        print(f"  {name:32s} {us:6.2f} us   x{us / peer:.2f} WHFast's (safe_mode 1)")


if __name__ == "__main__":
    main()
