"""Throughput of Kepler's equation, propagation and state -> elements vs peers.

Run:  python benchmarks/bench_kepler.py [--quick]

One process, same data for both sides, times per item (best of a few repeats,
after a JIT warm-up).  Prints ratios (peer time / our time; > 1 means we are
faster).

1. solve_kepler on N (M, e) pairs (elliptic e in [0, 0.99]) against a
   vectorised scipy.optimize.newton, and rebound.M_to_E called per pair
   (on a subsample, per call).
2. propagate N orbits by one dt against rebound WHFast's test-particle Kepler
   drift (N massless particles around one star, N_active = 1), per orbit-step.
3. KeplerOrbit.from_state on N states against rebound's sim.orbits(), per orbit.
"""

from __future__ import annotations

import argparse
import time

import numpy as np


def _best(fn, repeat: int = 3) -> float:
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def _states(n: int, rng: np.random.Generator):
    """Random bound orbits around mu = 1 (a in [0.5, 5], e in [0, 0.9])."""
    from hamilton_orbits.kepler import propagate

    a = rng.uniform(0.5, 5.0, n)
    e = rng.uniform(0.0, 0.9, n)
    q = a * (1 - e)
    vp = np.sqrt((1 + e) / q)
    r = np.zeros((n, 3))
    v = np.zeros((n, 3))
    r[:, 0] = q
    v[:, 1] = vp
    # random orientation (small tilt about x then spin about z) and phase
    inc = rng.uniform(0, np.pi, n)
    v = np.stack([v[:, 0], v[:, 1] * np.cos(inc), v[:, 1] * np.sin(inc)], -1)
    phase = rng.uniform(0, 2 * np.pi, n) * a**1.5
    return propagate(r, v, 1.0, phase)


def bench_solve(n: int, rng: np.random.Generator) -> None:
    import rebound
    from scipy.optimize import newton

    from hamilton_orbits import solve_kepler

    M = rng.uniform(-np.pi, np.pi, n)
    e = rng.uniform(0.0, 0.99, n)
    solve_kepler(M[:10], e[:10])  # JIT / cache load
    t_ours = _best(lambda: solve_kepler(M, e)) / n

    def scipy_solve():
        return newton(
            lambda E: E - e * np.sin(E) - M,
            M + 0.85 * e * np.sign(np.sin(M)),
            fprime=lambda E: 1 - e * np.cos(E),
            tol=1e-13,  # 1e-15 makes some elements oscillate to maxiter (unfair to scipy)
            maxiter=50,
        )

    t_scipy = _best(scipy_solve) / n
    k = min(n, 20000)
    Ms, es = M[:k].tolist(), e[:k].tolist()
    t_reb = _best(lambda: [rebound.M_to_E(ei, mi) for ei, mi in zip(es, Ms, strict=True)]) / k
    E = solve_kepler(M, e)
    res = np.max(np.abs(E - e * np.sin(E) - M))
    print(f"[1] solve_kepler, N = {n:.0e} elliptic pairs (max |E - e sin E - M| = {res:.1e})")
    print(f"    ours          {t_ours * 1e9:9.1f} ns/solve")
    print(f"    scipy newton  {t_scipy * 1e9:9.1f} ns/solve   ratio {t_scipy / t_ours:7.1f}x")
    print(f"    rebound M_to_E{t_reb * 1e9:9.1f} ns/call    ratio {t_reb / t_ours:7.1f}x"
          f"  (per Python call, {k} calls)")


def bench_propagate(n: int, rng: np.random.Generator, steps: int = 5) -> None:
    import rebound

    from hamilton_orbits.kepler import propagate

    r, v = _states(n, rng)
    dt = 0.01
    propagate(r[:10], v[:10], 1.0, dt)
    t_ours = _best(lambda: propagate(r, v, 1.0, dt)) / n

    sim = rebound.Simulation()
    sim.G = 1.0
    sim.add(m=1.0)
    for i in range(n):
        sim.add(m=0.0, x=r[i, 0], y=r[i, 1], z=r[i, 2], vx=v[i, 0], vy=v[i, 1], vz=v[i, 2])
    sim.N_active = 1
    sim.integrator = "whfast"
    sim.dt = dt
    sim.steps(1)  # coordinate set-up outside the timing

    def run():
        for _ in range(steps):
            sim.steps(1)

    t_reb = _best(run, repeat=2) / (n * steps)
    # agreement after one step (WHFast's drift is exact two-body with N_active=1
    # and massless particles, so the two should agree to ~1e-13)
    sim2 = rebound.Simulation()
    sim2.G = 1.0
    sim2.add(m=1.0)
    k = min(n, 1000)
    for i in range(k):
        sim2.add(m=0.0, x=r[i, 0], y=r[i, 1], z=r[i, 2], vx=v[i, 0], vy=v[i, 1], vz=v[i, 2])
    sim2.N_active = 1
    sim2.integrator = "whfast"
    sim2.dt = dt
    sim2.steps(1)
    xyz = np.array([[p.x, p.y, p.z] for p in sim2.particles[1:]])
    r1, _ = propagate(r[:k], v[:k], 1.0, dt)
    diff = np.max(np.linalg.norm(xyz - r1, axis=-1) / np.linalg.norm(r1, axis=-1))
    print(f"[2] propagate, N = {n:.0e} orbits, dt = {dt} (max rel. diff to WHFast {diff:.1e})")
    print(f"    ours          {t_ours * 1e9:9.1f} ns/orbit-step")
    print(f"    rebound WHFast{t_reb * 1e9:9.1f} ns/orbit-step ratio {t_reb / t_ours:7.1f}x"
          "  (target >= 1)")


def bench_elements(n: int, rng: np.random.Generator) -> None:
    import rebound

    try:
        from hamilton_orbits import KeplerOrbit
    except ImportError:
        try:
            from hamilton_orbits.orbit import KeplerOrbit
        except ImportError:
            print("[3] KeplerOrbit.from_state not available yet: skipped")
            return
    r, v = _states(n, rng)
    KeplerOrbit.from_state(r[:10], v[:10], 1.0)
    t_ours = _best(lambda: KeplerOrbit.from_state(r, v, 1.0).M) / n
    sim = rebound.Simulation()
    sim.G = 1.0
    sim.add(m=1.0)
    k = min(n, 100000)
    for i in range(k):
        sim.add(m=0.0, x=r[i, 0], y=r[i, 1], z=r[i, 2], vx=v[i, 0], vy=v[i, 1], vz=v[i, 2])
    t_reb = _best(lambda: sim.orbits(), repeat=2) / k
    print(f"[3] elements from state, N = {n:.0e} (rebound on {k})")
    print(f"    ours          {t_ours * 1e9:9.1f} ns/orbit")
    print(f"    rebound orbits{t_reb * 1e9:9.1f} ns/orbit    ratio {t_reb / t_ours:7.1f}x"
          "  (target >= 100)")


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="N = 1e4 instead of 1e6")
    args = parser.parse_args(argv)
    n = 10_000 if args.quick else 1_000_000
    rng = np.random.default_rng(2024)
    bench_solve(n, rng)
    bench_propagate(n, rng)
    bench_elements(n, rng)


if __name__ == "__main__":
    main()
