"""Semi-active bodies, ours beside rebound's test particles of type 1, same process.

Run:  NUMBA_NUM_THREADS=1 PYTHONPATH=src python benchmarks/bench_semi_active.py [--years 100]

DE440's state at J2000 (shipped): the Sun, the planets, the Moon, Pluto (11 bodies)
and the 16 asteroids of ``sb441-n16``, Newton's law, for ``--years``: ours (radau15)
with every body active and with the asteroids semi-active (the ``semi_active``
effect: they pull on the others and feel them, but not each other), rebound's IAS15
with every particle active and with ``N_active = 11``, ``testparticle_type = 1``
(the asteroids last); wall times (medians of ``--repeat`` interleaved runs) and
the final positions' largest difference between the two codes in each mode.  Then
the right-hand side alone (``timeit``, best of five) of 11 active bodies and 16, 100
and 400 semi-active ones against Newton's law with every body active: the pairs
left out grow as the square of the semi-active bodies.
"""

from __future__ import annotations

import argparse
import statistics
import time
import timeit

import numpy as np
import rebound

from hamilton_orbits import ephemeris as de
from hamilton_orbits import integrate
from hamilton_orbits._kernels import nbody
from hamilton_orbits.nbody import Body, System

SEMI = [{"name": "semi_active", "bodies": list(de.ASTEROIDS)}]


def ours(s: System, days: float, semi: bool) -> tuple[float, np.ndarray]:
    start = time.perf_counter()
    tr = integrate(s, days, method="radau15", effects=SEMI if semi else ())
    return time.perf_counter() - start, np.asarray(tr.r[-1])


def theirs(s: System, days: float, semi: bool) -> tuple[float, np.ndarray]:
    a = s.as_arrays()
    sim = rebound.Simulation()
    sim.G = 1.0
    for i in range(len(a.gm)):
        sim.add(m=a.gm[i], x=a.r[i, 0], y=a.r[i, 1], z=a.r[i, 2], vx=a.v[i, 0], vy=a.v[i, 1],
                vz=a.v[i, 2])
    if semi:
        sim.N_active, sim.testparticle_type = len(de.DEFAULT_BODIES), 1
    sim.integrator = "ias15"
    start = time.perf_counter()
    sim.integrate(days, exact_finish_time=1)
    wall = time.perf_counter() - start
    return wall, np.array([[p.x, p.y, p.z] for p in sim.particles])


def _system() -> System:
    """The 27 bodies at J2000 as plain floats (au, au/day, au^3/day^2)."""
    q = System.from_ephemeris("J2000", bodies=[*de.DEFAULT_BODIES, *de.ASTEROIDS],
                              frame="icrs")
    a = q.as_arrays()
    return System([Body(name, a.gm[i], a.r[i], a.v[i]) for i, name in enumerate(q.names)])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--years", type=float, default=100.0)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    s, days = _system(), args.years * 365.25
    ours(s, 1.0, True)  # (compiled outside the timing)
    cases = {"ours": lambda: ours(s, days, False), "ours semi": lambda: ours(s, days, True),
             "rebound": lambda: theirs(s, days, False),
             "rebound semi": lambda: theirs(s, days, True)}
    walls: dict[str, list[float]] = {k: [] for k in cases}
    ends: dict[str, np.ndarray] = {}
    for _ in range(args.repeat):
        for k, fn in cases.items():
            wall, ends[k] = fn()
            walls[k].append(wall)
    med = {k: statistics.median(v) for k, v in walls.items()}
    print(time.strftime(f"run of %Y-%m-%d %H:%M UTC; 27 bodies, Newton, {args.years:g} years, "
                        f"medians of {args.repeat}", time.gmtime()))
    for mode, tag in (("every body active", ""), ("asteroids semi-active", " semi")):
        ratio = med["rebound" + tag] / med["ours" + tag]
        apart = np.abs(ends["ours" + tag] - ends["rebound" + tag]).max()
        print(f"  {mode:22s} ours {med['ours' + tag]:.3f} s, rebound IAS15 "
              f"{med['rebound' + tag]:.3f} s, rebound / ours {ratio:.2f}; final positions "
              f"{apart:.1e} au apart")
    print(f"  semi-active / active: ours {med['ours semi'] / med['ours']:.3f}, rebound "
          f"{med['rebound semi'] / med['rebound']:.3f}")
    scaling()


def _best(fn) -> float:
    fn()
    return min(timeit.repeat(fn, number=2000, repeat=5)) / 2000 * 1e6


def _rhs_times(n_semi: int, rng: np.random.Generator) -> tuple[float, float]:
    """Newton's law of 11 active and ``n_semi`` semi-active bodies, us: every body
    active, and the semi-active rule."""
    n = 11 + n_semi
    r, v = rng.normal(size=(n, 3)) * 5.0, np.zeros((n, 3))
    gm = np.full(n, 1e-10)
    gm[:11], gm[0] = 1e-5, 1.0
    acc, p = np.zeros((n, 3)), np.arange(11, n, dtype=float)
    return (_best(lambda: nbody.newtonian_only(r, v, gm, acc, p)),
            _best(lambda: nbody.newtonian_semi_active(r, v, gm, acc, p)))


def scaling() -> None:
    rng = np.random.default_rng(0)
    print("  the right-hand side alone, 11 active bodies (us, best of five):")
    for n_semi in (16, 100, 400):
        full, semi = _rhs_times(n_semi, rng)
        print(f"    + {n_semi:3d} semi-active: every body active {full:.2f}, semi-active "
              f"{semi:.2f}, ratio {full / semi:.2f}")


if __name__ == "__main__":
    main()
