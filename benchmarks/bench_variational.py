"""What the variational equations cost, ours and rebound's, and a MEGNO map on both.

1. The solar system (the Sun and eight planets, built-in ephemeris at J2000): the
   wall time with ``variational=True`` (one tangent vector: MEGNO and the Lyapunov
   exponent) as a ratio to the plain run, for ``wh`` (2-day step, 1000 yr) and
   ``radau15`` (100 yr), beside rebound's WHFast and IAS15 with ``init_megno()``
   (one set of variational particles) on the same state; best of ``--repeats``.
   Also ``wh`` with ``stm=True`` (55 tangent vectors), and both backwards (ours: the
   time-reversed motion's tangent vectors; rebound: a negative step).
2. The stability map of ``examples/chaos/stability_map.py`` (Jupiter and a Saturn-mass
   planet over (a, e)), ``--n`` x ``--n`` cells of ``--orbits`` orbits of Jupiter:
   ours through ``Ensemble`` on the local cores, rebound's WHFast MEGNO (Jacobi,
   the same 120-day step) over a ``multiprocessing`` pool of as many processes,
   on the same initial states; the wall times, and how often the two agree on
   the verdict (MEGNO above or below 4).

Run: python benchmarks/bench_variational.py [--quick] [--n 64] [--orbits 10000]
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import os
import time

import astropy.units as u
import numpy as np

from hamilton_orbits import Ensemble, Scene, System, integrate

P_JUPITER_YR = 11.8558
DAYS_PER_YR = 365.25


def _best(fn, repeats: int) -> float:
    best = np.inf
    for _ in range(repeats):
        best = min(best, fn())
    return best


def _ours(system: System, years: float, method: str, kw: dict, variational: bool,
          stm: bool = False) -> float:
    """Our wall time over ``years`` (negative: backwards)."""
    tr = integrate(system, years * u.yr, method=method, variational=variational, stm=stm, **kw)
    return tr.wall_time


def _rebound(system: System, years: float, integrator: str, variational: bool) -> float:
    """rebound's wall time over ``years`` (negative: backwards, a negative step)."""
    sim = system.to_rebound()  # G = 1, au, days
    sim.integrator = integrator
    if integrator == "whfast":
        sim.dt = 2.0 if years > 0 else -2.0
    if variational:
        sim.init_megno(seed=1)
    start = time.perf_counter()
    sim.integrate(sim.t + years * DAYS_PER_YR, exact_finish_time=0)
    return time.perf_counter() - start


def cost(repeats: int, quick: bool) -> None:
    s = System.solar_system()
    spans = {"wh": 100.0 if quick else 1000.0, "radau15": 10.0 if quick else 100.0}
    print(f"1. cost of variational=True, the solar system ({len(s.names)} bodies), "
          f"best of {repeats}, {time.strftime('%Y-%m-%d')}, {os.cpu_count()} cores")
    print(f"{'code':<34}{'span (yr)':>10}{'plain (s)':>11}{'variational (s)':>17}{'ratio':>8}")
    for method, peer, kw in (("wh", "whfast", {"dt": 2 * u.day}),
                             ("radau15", "ias15", {})):
        years = spans[method]
        _ours(s, years / 10, method, kw, True)  # compile and load outside the timing
        plain = _best(lambda m=method, k=kw, y=years: _ours(s, y, m, k, False), repeats)
        var = _best(lambda m=method, k=kw, y=years: _ours(s, y, m, k, True), repeats)
        print(f"{'hamilton-orbits ' + method:<34}{years:>10g}{plain:>11.3f}{var:>17.3f}"
              f"{var / plain:>8.2f}")
        if method == "wh":
            stm = _best(lambda y=years, k=kw: _ours(s, y / 10, "wh", k, True, stm=True), repeats)
            print(f"{'hamilton-orbits wh, stm=True':<34}{years / 10:>10g}{plain / 10:>11.3f}"
                  f"{stm:>17.3f}{stm / (plain / 10):>8.2f}")
        rp = _best(lambda i=peer, y=years: _rebound(s, y, i, False), repeats)
        rv = _best(lambda i=peer, y=years: _rebound(s, y, i, True), repeats)
        print(f"{'rebound ' + peer + ' (init_megno)':<34}{years:>10g}{rp:>11.3f}{rv:>17.3f}"
              f"{rv / rp:>8.2f}")
        _ours(s, -years / 10, method, kw, True)  # (the time-reversed kernels compiled)
        for name, run in ((f"hamilton-orbits {method}, backwards",
                           lambda v, m=method, k=kw, y=years: _ours(s, -y, m, k, v)),
                          (f"rebound {peer}, backwards",
                           lambda v, i=peer, y=years: _rebound(s, -y, i, v))):
            bp, bv = (_best(lambda v=v, r=run: r(v), repeats) for v in (False, True))
            print(f"{name:<34}{-years:>10g}{bp:>11.3f}{bv:>17.3f}{bv / bp:>8.2f}")


def _rebound_cell(args: tuple) -> float:
    """rebound's MEGNO of one cell (a worker of the pool): WHFast, Jacobi, 120 d."""
    import rebound

    r, v, gm, days = args
    sim = rebound.Simulation()
    for k in range(len(gm)):
        sim.add(m=gm[k], x=r[k, 0], y=r[k, 1], z=r[k, 2], vx=v[k, 0], vy=v[k, 1], vz=v[k, 2])
    sim.integrator = "whfast"
    sim.dt = 120.0
    sim.init_megno(seed=1)
    try:
        sim.integrate(days, exact_finish_time=0)
    except Exception:  # an escape or a failure: no verdict
        return np.nan
    return sim.megno()


def stability_map(n: int, orbits: float) -> None:
    from hamilton_orbits.scenes.nbody.build import build_system

    a = [f"{float(x)!r} au" for x in np.linspace(7.0, 10.0, n)]
    e = [float(x) for x in np.linspace(0.0, 0.5, n)]
    years = orbits * P_JUPITER_YR
    scene = Scene.bundled("stability-map").with_values({"duration": f"{years} yr",
                                                        "cadence": f"{years} yr"})
    ens = Ensemble(scene, vary={"bodies.planet.a": a, "bodies.planet.e": e})
    cores = os.cpu_count() or 1
    print(f"\n2. stability map: {n} x {n} cells, {orbits:g} orbits of Jupiter "
          f"({years:.0f} yr, 120-day steps) on {cores} cores")
    Ensemble(scene.with_values({"duration": "100 yr", "cadence": "100 yr"}),
             members=ens.members[:cores]).run(progress=False)  # start the pool
    start = time.perf_counter()
    table = ens.run(progress=False)
    ours_wall = time.perf_counter() - start
    ours = table["MEGNO"].to_numpy(dtype=float)
    cells = []
    for m in ens.members:
        arrays = build_system(scene.with_values(m).spec).as_arrays()
        cells.append((np.array(arrays.r), np.array(arrays.v), np.array(arrays.gm),
                      years * DAYS_PER_YR))
    with mp.get_context("spawn").Pool(cores) as pool:
        pool.map(_rebound_cell, [(c[0], c[1], c[2], 100.0) for c in cells[:cores]])
        start = time.perf_counter()
        theirs = np.array(pool.map(_rebound_cell, cells, chunksize=4))
        theirs_wall = time.perf_counter() - start
    ok = np.isfinite(ours) & np.isfinite(theirs)
    agree = np.mean((ours[ok] > 4) == (theirs[ok] > 4))
    regular = ok & (ours < 2.5) & (theirs < 2.5)
    print(f"{'code':<44}{'wall (s)':>10}{'per cell (ms)':>15}{'chaotic':>9}")
    for name, wall, vals in (("hamilton-orbits wh, Ensemble (local pool)", ours_wall, ours),
                             ("rebound WHFast, multiprocessing.Pool", theirs_wall, theirs)):
        print(f"{name:<44}{wall:>10.1f}{1e3 * wall * cores / n**2:>15.1f}"
              f"{100 * np.nanmean(vals > 4):>8.1f}%")
    print(f"same verdict (MEGNO > 4 or not) in {100 * agree:.1f}% of {ok.sum()} cells; "
          f"regular cells in both: {regular.sum()}, their MEGNO differ by at most "
          f"{np.max(np.abs(ours[regular] - theirs[regular])):.4f}; ours/rebound wall time "
          f"{ours_wall / theirs_wall:.2f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="short spans, 8 x 8 x 200")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--n", type=int, default=64)
    parser.add_argument("--orbits", type=float, default=1e4)
    parser.add_argument("--skip-cost", action="store_true")
    parser.add_argument("--skip-map", action="store_true")
    args = parser.parse_args()
    if not args.skip_cost:
        cost(1 if args.quick else args.repeats, args.quick)
    if not args.skip_map:
        stability_map(8 if args.quick else args.n, 200.0 if args.quick else args.orbits)


if __name__ == "__main__":
    main()
