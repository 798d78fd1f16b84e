"""What watching for close encounters costs: ours against rebound's exit_min_distance.

The Sun and planets (J2000, built-in ephemeris) and N test particles on orbits that
cross the inner planets' (perihelia 0.3-1 au, aphelia 1.5-4 au, inclinations below
10 degrees), integrated for a span of years: with ``close_encounter`` watching every
pair with a massive body (within 3 Hill radii of the planet; the Sun's pairs are
then not watched) and without events, with radau15 and with wh (dt = 1 day), all in
one process.  rebound's IAS15 with ``exit_min_distance`` (one distance for all
pairs; it stops at the first encounter, so it is timed per step until then) against
the same run without it.

The cost of watching is printed as the ratio (time per step with events) / (time
per step without), medians of interleaved repeats.

    python benchmarks/bench_events.py            # 100 years, 1000 particles
    python benchmarks/bench_events.py --quick    # 10 years, 200 particles
    python benchmarks/bench_events.py --years 1000
"""

from __future__ import annotations

import argparse
import statistics
import time

import astropy.units as u
import numpy as np


def system_with_crossers(n: int, seed: int = 1):
    """The solar system plus ``n`` massless crossers of the inner planets' orbits."""
    from hamilton_orbits import Body, KeplerOrbit, System

    base = System.solar_system("J2000")
    rng = np.random.default_rng(seed)
    q = rng.uniform(0.3, 1.0, n)
    big_q = rng.uniform(1.5, 4.0, n)
    gm_sun = base.gm[0]
    orbits = KeplerOrbit.from_elements(
        a=(q + big_q) / 2 * u.au, e=(big_q - q) / (big_q + q),
        inc=rng.uniform(0, 10, n) * u.deg, lan=rng.uniform(0, 360, n) * u.deg,
        argp=rng.uniform(0, 360, n) * u.deg, M=rng.uniform(0, 360, n) * u.deg,
        mu=np.full(n, gm_sun.to_value(u.km**3 / u.s**2)) * u.km**3 / u.s**2)
    r, v = orbits.state()
    sun = base["sun"]
    crossers = [Body(f"c{k}", 0 * u.km**3 / u.s**2, sun.r + r[k], sun.v + v[k])
                for k in range(n)]
    return System(list(base.bodies) + crossers)


def time_ours(system, years: float, method: str, events, **kw) -> tuple[float, int, int]:
    from hamilton_orbits import integrate

    t0 = time.process_time()
    traj = integrate(system, years * u.yr, method=method, events=events, **kw)
    return time.process_time() - t0, traj.steps, len(traj.events)


def time_rebound(system, years: float, exit_min: float | None) -> tuple[float, int, float]:
    import rebound

    sim = system.to_rebound()
    sim.N_active = int(np.count_nonzero(system.as_arrays().gm))  # massless: test particles
    sim.testparticle_type = 0
    sim.integrator = "ias15"
    if exit_min is not None:
        sim.exit_min_distance = exit_min
    t0 = time.process_time()
    try:
        sim.integrate(years * 365.25, exact_finish_time=0)
    except rebound.Encounter:
        pass
    return time.process_time() - t0, int(sim.steps_done), float(sim.t) / 365.25


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="10 years, 200 particles")
    parser.add_argument("--years", type=float, default=None)
    parser.add_argument("--particles", type=int, default=None)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    years = args.years or (10.0 if args.quick else 100.0)
    n = args.particles or (200 if args.quick else 1000)
    system = system_with_crossers(n)
    watch = [{"name": "close_encounter", "distance": {"hill": 3}}]
    print(f"solar system + {n} crossers of the inner planets, {years:g} years, "
          f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}")
    for method, kw in (("radau15", {}), ("wh", {"dt": 1 * u.day})):
        time_ours(system, 0.1, method, watch, **kw)  # compile
        plain, watched, found = [], [], 0
        for _ in range(args.repeat):
            t, s, _ = time_ours(system, years, method, (), **kw)
            plain.append(t / s)
            t, s, found = time_ours(system, years, method, watch, **kw)
            watched.append(t / s)
        ratio = statistics.median(np.array(watched) / np.array(plain))
        print(f"  ours {method:8s} {statistics.median(plain) * 1e6:8.1f} us/step without events, "
              f"{statistics.median(watched) * 1e6:8.1f} with ({found} encounters within 3 Hill "
              f"radii): cost of watching x{ratio:.2f}")
    # rebound: one distance for every pair (0.01 au); it stops at the first encounter
    plain, watched = [], []
    for _ in range(args.repeat):
        t, s, _ = time_rebound(system, years, None)
        plain.append(t / s)
        t, s, t_stop = time_rebound(system, years, 0.01)
        watched.append(t / max(s, 1))
    ratio = statistics.median(np.array(watched) / np.array(plain))
    print(f"  rebound IAS15 {statistics.median(plain) * 1e6:8.1f} us/step without, "
          f"{statistics.median(watched) * 1e6:8.1f} with exit_min_distance = 0.01 au (stopped at "
          f"the first encounter, t = {t_stop:.3g} yr): cost x{ratio:.2f}")


if __name__ == "__main__":
    main()
