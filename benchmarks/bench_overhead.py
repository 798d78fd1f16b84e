"""Per-call overhead, throughput beside a minimal kernel, and the first run.

Run:  python benchmarks/bench_overhead.py [--quick] [--nmax N] [--clock cpu]

On a machine shared with other jobs, ``--clock cpu`` times parts 1 and 2 by the
process's CPU time (``time.process_time``) instead of the wall clock, so that
time slices given to other processes do not count; ``NUMBA_NUM_THREADS=1`` for
one thread.

One process for ours and rebound, same states for both.  Times are medians of
several repeats (each repeat loops a call until it has run >= 20 ms), after a
warm-up; ratios are peer time / our time (> 1: we are faster).

1. Per call at N = 1, 10, ..., 1e7 (1e6 with --quick) orbits:
   * elements: ``KeplerOrbit.from_state(r, v, mu)`` then reading a, e, inc,
     lan, argp, nu, beside rebound's ``p.orbit(primary=star)`` for each of N
     test particles (a Python loop over particles, reading the same six).
   * propagation: ``orbit.propagate(dt)`` beside rebound WHFast's one step of
     ``dt`` of N massless particles around one star (N_active = 1), the
     Kepler drift of every particle in one C call (``sim.integrate``).
   rebound stops at 1e5 (1e6 without --quick) orbits: its cost per orbit is
   flat by then.
2. Elements throughput at N = 1e6 on one thread (``numba.set_num_threads(1)``)
   and on all cores: ours (the same call as in 1, and the kernel alone) beside
   a minimal kernel written here (a, e, inc, lan, argp, nu of one state by the
   textbook formulas, no special cases, no validation) as the yardstick, and
   beside rebound per orbit (single-threaded), per core and on all cores.
4. The cost of an n-body call (10 bodies: a star and nine planets on a disc,
   masses 1e-7, dt = 0.01), CPU time, one step per call: a continuing
   ``sim.integrate(t + dt)`` of a prepared :class:`~hamilton_orbits.Simulation`
   beside rebound's ``sim.integrate(t + dt, exact_finish_time=0)`` (radau15 at a
   fixed step beside IAS15 with epsilon = 0; wh beside WHFast, democratic
   heliocentric, safe_mode 0), and beside rebound's call plus what ours also
   does (``synchronize()`` and the state read out: ``serialize_particle_data``);
   and the one-shot ``integrate(system, dt)`` beside rebound's ``copy()`` +
   ``integrate``.  Ratios rebound / ours (> 1: ours is cheaper), the median of
   per-round ratios, ours and rebound's calls interleaved round by round.
3. The main job (``hamilton-orbits``, the solar-system scene) in a subprocess:
   cold (``NUMBA_CACHE_DIR`` a fresh empty folder) and warm, wall clock; and
   ``import hamilton_orbits`` beside ``import numpy, scipy, astropy.units,
   numba`` and numpy alone, and a whole process computing one orbit's
   elements, ours beside rebound (median of 5 subprocesses each).
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numba
import numpy as np
from numba import njit, prange

SRC = str(Path(__file__).resolve().parents[1] / "src")


# --------------------------------------------------------------- yardstick
def _minimal_body(r, v, mu, out):  # pragma: no cover - compiled
    """a, e, inc, lan, argp, nu of each state: the textbook formulas only."""
    two_pi = 2.0 * math.pi
    for i in prange(r.shape[0]):
        rx, ry, rz = r[i, 0], r[i, 1], r[i, 2]
        vx, vy, vz = v[i, 0], v[i, 1], v[i, 2]
        m = mu[i]
        rr = math.sqrt(rx * rx + ry * ry + rz * rz)
        v2 = vx * vx + vy * vy + vz * vz
        rv = rx * vx + ry * vy + rz * vz
        hx = ry * vz - rz * vy
        hy = rz * vx - rx * vz
        hz = rx * vy - ry * vx
        h = math.sqrt(hx * hx + hy * hy + hz * hz)
        inv_a = 2.0 / rr - v2 / m
        f = v2 - m / rr
        ex = (f * rx - rv * vx) / m
        ey = (f * ry - rv * vy) / m
        ez = (f * rz - rv * vz) / m
        rho = math.hypot(hx, hy)
        nx = -hy / rho
        ny = hx / rho
        u = math.atan2(hz * (ry * nx - rx * ny) + rz * rho, h * (rx * nx + ry * ny))
        nu = math.atan2(rv * h, h * h - m * rr)
        out[i, 0] = 1.0 / inv_a
        out[i, 1] = math.sqrt(ex * ex + ey * ey + ez * ez)
        out[i, 2] = math.atan2(rho, hz)
        out[i, 3] = math.atan2(hx, -hy) % two_pi
        out[i, 4] = (u - nu) % two_pi
        out[i, 5] = nu


minimal_parallel = njit(parallel=True)(_minimal_body)


# ------------------------------------------------------------------ timing
# the clock of parts 1 and 2: wall clock, or (--clock cpu) the CPU time of the
# process, which a loaded machine's other jobs do not inflate (summed over the
# threads: on more than one thread part 2 then reads as time per core)
CLOCKS = {"wall": time.perf_counter, "cpu": time.process_time}
_clock = CLOCKS["wall"]


def _per_call(fn, repeat: int) -> float:
    """Median over ``repeat`` of the time per call, each repeat >= 20 ms."""
    fn()
    t0 = _clock()
    fn()
    once = _clock() - t0
    loops = max(1, int(0.02 / max(once, 1e-7)))
    times = []
    for _ in range(repeat):
        t0 = _clock()
        for _ in range(loops):
            fn()
        times.append((_clock() - t0) / loops)
    return statistics.median(times)


def _states(n: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Bound, inclined orbits around mu = 1 (a in [0.5, 5], e in [0, 0.9])."""
    rng = np.random.default_rng(seed)
    a = rng.uniform(0.5, 5.0, n)
    e = rng.uniform(0.0, 0.9, n)
    inc = rng.uniform(0.01, np.pi - 0.01, n)
    lan = rng.uniform(0.0, 2 * np.pi, n)
    nu = rng.uniform(-np.pi, np.pi, n)
    p = a * (1 - e * e)
    rr = p / (1 + e * np.cos(nu))
    x, y = rr * np.cos(nu), rr * np.sin(nu)
    k = np.sqrt(1.0 / p)
    vx, vy = -k * np.sin(nu), k * (e + np.cos(nu))
    ci, si, cl, sl = np.cos(inc), np.sin(inc), np.cos(lan), np.sin(lan)
    r = np.stack([x * cl - y * ci * sl, x * sl + y * ci * cl, y * si], -1)
    v = np.stack([vx * cl - vy * ci * sl, vx * sl + vy * ci * cl, vy * si], -1)
    return np.ascontiguousarray(r), np.ascontiguousarray(v)


def _rebound_sim(r: np.ndarray, v: np.ndarray):
    import rebound

    sim = rebound.Simulation()
    sim.G = 1.0
    sim.add(m=1.0)
    for i in range(len(r)):
        sim.add(m=0.0, x=r[i, 0], y=r[i, 1], z=r[i, 2], vx=v[i, 0], vy=v[i, 1], vz=v[i, 2])
    sim.N_active = 1
    sim.testparticle_type = 0
    return sim


# ------------------------------------------------------------------- parts
def bench_per_call(nmax: int, nmax_rebound: int, repeat: int) -> None:
    from hamilton_orbits import KeplerOrbit

    print("\n1. Per call (median of repeats), ours beside rebound")
    print(f"{'N':>9} | {'elements ours':>14} {'rebound':>12} {'ratio':>7} | "
          f"{'propagate ours':>14} {'rebound':>12} {'ratio':>7}")
    dt = 0.37
    n = 1
    while n <= nmax:
        r, v = _states(n)
        if n == 1:
            r, v = r[0], v[0]
        mu = 1.0

        def ours_el(r=r, v=v, mu=mu):
            o = KeplerOrbit.from_state(r, v, mu)
            return o.a, o.e, o.inc, o.lan, o.argp, o.nu

        orbit = KeplerOrbit.from_state(r, v, mu)
        rep = repeat if n <= 100_000 else max(3, repeat // 2)
        t_el = _per_call(ours_el, rep)
        t_pr = _per_call(lambda orbit=orbit: orbit.propagate(dt), rep)
        if n <= nmax_rebound:
            sim = _rebound_sim(np.atleast_2d(r), np.atleast_2d(v))
            ps = sim.particles
            star = ps[0]
            plist = [ps[i] for i in range(1, n + 1)]

            def reb_el(plist=plist, star=star):
                for p in plist:
                    o = p.orbit(primary=star)
                    o.a, o.e, o.inc, o.Omega, o.omega, o.f  # noqa: B018

            sim.integrator = "whfast"
            sim.dt = dt
            xyz = np.zeros((n + 1, 3))
            vxyz = np.zeros((n + 1, 3))
            sim.serialize_particle_data(xyz=xyz, vxvyvz=vxyz)

            def reb_pr(sim=sim, xyz=xyz, vxyz=vxyz):
                sim.t = 0.0
                sim.set_serialized_particle_data(xyz=xyz, vxvyvz=vxyz)
                sim.integrate(dt)  # one WHFast step: the Kepler drift of each particle

            t_rel = _per_call(reb_el, rep)
            t_rpr = _per_call(reb_pr, rep)
            print(f"{n:>9} | {t_el * 1e6:>11.2f} us {t_rel * 1e6:>9.2f} us {t_rel / t_el:>7.2f} | "
                  f"{t_pr * 1e6:>11.2f} us {t_rpr * 1e6:>9.2f} us {t_rpr / t_pr:>7.2f}")
        else:
            print(f"{n:>9} | {t_el * 1e6:>11.2f} us {'-':>12} {'-':>7} | "
                  f"{t_pr * 1e6:>11.2f} us {'-':>12} {'-':>7}")
        n *= 10


def bench_throughput(n: int, repeat: int, rounds: int) -> None:
    from hamilton_orbits import KeplerOrbit
    from hamilton_orbits._kernels import elements as _el

    r, v = _states(n, seed=1)
    mu = np.ones(n)
    out6 = np.empty((n, 6))
    out = np.empty((n, _el.NCLASSICAL))  # the classical columns (a the last)

    def ours():
        o = KeplerOrbit.from_state(r, v, mu)
        return o.a, o.e, o.inc, o.lan, o.argp, o.nu

    nr = min(n, 100_000)
    sim = _rebound_sim(r[:nr], v[:nr])
    ps = sim.particles
    star = ps[0]
    plist = [ps[i] for i in range(1, nr + 1)]

    def reb():
        for p in plist:
            o = p.orbit(primary=star)
            o.a, o.e, o.inc, o.Omega, o.omega, o.f  # noqa: B018

    t_reb = _per_call(reb, max(3, repeat // 2)) / nr
    all_threads = numba.config.NUMBA_NUM_THREADS
    print(f"\n2. Elements throughput, N = {n:.0e} (ns per orbit; rebound "
          f"{t_reb * 1e9:.0f} ns/orbit, one thread)")
    print("minimal: the yardstick into a preallocated output; +alloc: allocating its output"
          " (as an API returning fresh arrays must); kernel: our elements kernel alone;"
          " ours: from_state + reading the six.  The variants run in turn in each of"
          f" {rounds} rounds; times are medians, ratios medians of the per-round ratios"
          " (so that load that varies between rounds cancels).  rebound/ours: rebound on"
          " one core against ours on the threads; per core: against ours x threads.")
    print(f"{'threads':>8} | {'minimal':>9} {'+alloc':>9} {'kernel':>9} {'ours':>9} | "
          f"{'kernel/min':>10} {'ours/min':>8} {'ours/+alloc':>11} | {'rebound/ours':>12} "
          f"{'per core':>8}")
    variants = {
        "min": lambda: minimal_parallel(r, v, mu, out6),
        "mina": lambda: minimal_parallel(r, v, mu, np.empty((n, 6))),
        "kernel": lambda: _el.state_to_elements_classical.parallel(r, v, mu, out),
        "ours": ours,
    }
    for threads in sorted({1, all_threads}):
        numba.set_num_threads(threads)
        for f in variants.values():  # warm-up
            f()
        times: dict[str, list[float]] = {k: [] for k in variants}
        for _ in range(rounds):
            for k, f in variants.items():
                t0 = _clock()
                f()
                times[k].append((_clock() - t0) / n)
        med = {k: statistics.median(x) for k, x in times.items()}

        def ratio(a: str, b: str, times=times) -> float:
            return statistics.median(x / y for x, y in zip(times[a], times[b], strict=True))

        print(f"{threads:>8} | {med['min'] * 1e9:>9.1f} {med['mina'] * 1e9:>9.1f} "
              f"{med['kernel'] * 1e9:>9.1f} {med['ours'] * 1e9:>9.1f} | "
              f"{ratio('kernel', 'min'):>10.2f} {ratio('ours', 'min'):>8.2f} "
              f"{ratio('ours', 'mina'):>11.2f} | {t_reb / med['ours']:>12.1f} "
              f"{t_reb / (med['ours'] * threads):>8.1f}")
    numba.set_num_threads(all_threads)


def _wall(cmd: list[str], env: dict, cwd: str) -> tuple[float, str]:
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, env=env, cwd=cwd, capture_output=True, text=True, timeout=3600)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        raise RuntimeError(proc.stderr[-2000:])
    return wall, proc.stderr


def bench_first_run(repeat_warm: int) -> None:
    print("\n3. First run")
    env = dict(os.environ, PYTHONPATH=SRC + os.pathsep + os.environ.get("PYTHONPATH", ""))
    py = [sys.executable, "-c"]
    imp = [*py, "import hamilton_orbits"]
    imp_names = [*py, "from hamilton_orbits import KeplerOrbit, Quaternion"]
    first = [*py, "from hamilton_orbits import KeplerOrbit\n"
             "o = KeplerOrbit.from_state([1.0, 0.2, 0.1], [-0.1, 1.1, 0.05], 1.0)\n"
             "o.a, o.e, o.inc, o.lan, o.argp, o.nu"]
    first_reb = [*py, "import rebound\nsim = rebound.Simulation()\nsim.G = 1.0\n"
                 "sim.add(m=1.0)\nsim.add(m=0.0, x=1.0, y=0.2, z=0.1, vx=-0.1, vy=1.1, vz=0.05)\n"
                 "o = sim.particles[1].orbit(primary=sim.particles[0])\n"
                 "o.a, o.e, o.inc, o.Omega, o.omega, o.f"]
    base = [*py, "import numpy, scipy, astropy.units, numba"]
    numpy_only = [*py, "import numpy"]
    with tempfile.TemporaryDirectory() as cwd:
        _wall(first, env, cwd)  # the numba cache warm
        t = {}
        for name, cmd in (("imp", imp), ("names", imp_names), ("first", first),
                          ("reb", first_reb), ("base", base), ("numpy", numpy_only)):
            t[name] = statistics.median(_wall(cmd, env, cwd)[0] for _ in range(5))
    print(f"warm import hamilton_orbits {t['imp']:.2f} s (median of 5 processes, wall clock); "
          f"from hamilton_orbits import KeplerOrbit, Quaternion {t['names']:.2f} s; "
          f"numpy alone {t['numpy']:.2f} s; numpy+scipy+astropy.units+numba {t['base']:.2f} s "
          f"(ratio {t['imp'] / t['base']:.2f})")
    print(f"process that imports and computes one orbit's elements: ours {t['first']:.2f} s "
          f"(numba's first kernel load included), rebound {t['reb']:.2f} s")
    job = [sys.executable, "-m", "hamilton_orbits.cli", "run", "--no-progress"]
    with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as cwd:
        cold_env = dict(env, NUMBA_CACHE_DIR=cache)
        t_cold, err = _wall(job, cold_env, cwd)
        notice = "notice printed" if "compiling numerical kernels" in err else "NO notice"
        warm = [_wall(job, cold_env, cwd)[0] for _ in range(repeat_warm)]
    print(f"hamilton-orbits (solar-system scene): cold {t_cold:.1f} s ({notice}), "
          f"warm {statistics.median(warm):.1f} s (median of {repeat_warm})")


def _disc10() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A star (GM 1) and nine planets (GM 1e-7) on circular orbits at 1-10."""
    rng = np.random.default_rng(1)
    a = rng.uniform(1.0, 10.0, 9)
    ph = rng.uniform(0, 2 * np.pi, 9)
    r = np.zeros((10, 3))
    v = np.zeros((10, 3))
    r[1:, 0], r[1:, 1] = a * np.cos(ph), a * np.sin(ph)
    v[1:, 0], v[1:, 1] = -np.sin(ph) / np.sqrt(a), np.cos(ph) / np.sqrt(a)
    gm = np.full(10, 1e-7)
    gm[0] = 1.0
    return r, v, gm


def rebound_of(r: np.ndarray, v: np.ndarray, gm: np.ndarray, integrator: str, dt: float):
    import rebound

    sim = rebound.Simulation()
    sim.G = 1.0
    for i in range(len(gm)):
        sim.add(m=gm[i], x=r[i, 0], y=r[i, 1], z=r[i, 2], vx=v[i, 0], vy=v[i, 1], vz=v[i, 2])
    sim.integrator = integrator
    sim.dt = dt
    if integrator == "ias15":
        sim.integrator.epsilon = 0.0
    else:
        sim.integrator.coordinates = "democraticheliocentric"
        sim.integrator.safe_mode = 0
    return sim


def _interleaved(fns: dict, rounds: int, secs: float = 0.05) -> dict:
    """CPU time per call of each of ``fns``, round by round in turn (each call looped
    for ``secs``); per round the times, so that ratios can be taken per round."""
    for fn in fns.values():
        fn()
    out: dict = {k: [] for k in fns}
    for _ in range(rounds):
        for k, fn in fns.items():
            n, t0 = 0, time.process_time()
            while True:
                fn()
                n += 1
                spent = time.process_time() - t0
                if spent >= secs:
                    break
            out[k].append(spent / n)
    return out


def bench_simulation_calls(rounds: int) -> None:
    from hamilton_orbits import Simulation, System, integrate

    r, v, gm = _disc10()
    system = System.from_arrays(gm, r, v)
    dt = 0.01
    print("\n4. Cost of an n-body call, 10 bodies, one step of dt = 0.01 (CPU time, median of "
          f"{rounds} rounds; ratio = rebound / ours, median of per-round ratios)")
    print(f"{'method':>9} | {'ours continuing':>15} {'rebound':>9} {'ratio':>6} | "
          f"{'rebound+state':>13} {'ratio':>6} | {'ours one-shot':>13} {'copy+integrate':>14} "
          f"{'ratio':>6}")
    for method, peer in (("radau15", "ias15"), ("wh", "whfast")):
        sim = Simulation(system, method=method, dt=dt)
        reb = rebound_of(r, v, gm, peer, dt)
        xyz, vxyz = np.empty((10, 3)), np.empty((10, 3))

        def ours(sim=sim) -> None:
            sim.integrate(sim.t + dt)

        def theirs(reb=reb) -> None:
            reb.integrate(reb.t + dt, exact_finish_time=0)

        def theirs_state(reb=reb, peer=peer, xyz=xyz, vxyz=vxyz) -> None:
            reb.integrate(reb.t + dt, exact_finish_time=0)
            if peer == "whfast":
                reb.synchronize()
            reb.serialize_particle_data(xyz=xyz, vxvyvz=vxyz)

        def ours_once(method=method) -> None:
            integrate(system, dt, method=method, dt=dt)

        def theirs_once(reb=reb) -> None:
            copy = reb.copy()
            copy.integrate(copy.t + dt, exact_finish_time=0)

        t = _interleaved({"o": ours, "p": theirs, "ps": theirs_state, "o1": ours_once,
                          "p1": theirs_once}, rounds)
        med = {k: statistics.median(x) for k, x in t.items()}

        def ratio(a: str, b: str, t=t) -> float:
            return statistics.median(x / y for x, y in zip(t[a], t[b], strict=True))

        print(f"{method:>9} | {med['o'] * 1e6:>12.2f} us {med['p'] * 1e6:>6.2f} us "
              f"{ratio('p', 'o'):>6.2f} | {med['ps'] * 1e6:>10.2f} us {ratio('ps', 'o'):>6.2f} | "
              f"{med['o1'] * 1e6:>10.2f} us {med['p1'] * 1e6:>11.2f} us {ratio('p1', 'o1'):>6.2f}")
    _quantity_calls(rounds)


def _quantity_calls(rounds: int) -> None:
    """A continuing call of a Quantity system (the Sun, Jupiter, Saturn at J2000, wh, dt
    = 10 d), its end time a Quantity in days, beside the same call of the system as
    floats: what the units cost (rebound has none)."""
    import astropy.units as u

    from hamilton_orbits import Simulation, System

    s = System.solar_system("J2000", bodies=["sun", "jupiter", "saturn"])
    arrays = s.as_arrays()
    plain = System.from_arrays(arrays.gm, arrays.r, arrays.v)
    sim_q = Simulation(s, method="wh", dt=10 * u.day)
    sim_f = Simulation(plain, method="wh", dt=10.0)
    step_q, step_f = 10 * u.day, 10.0
    t = _interleaved({"q": lambda: sim_q.integrate(sim_q.t + step_q),
                      "f": lambda: sim_f.integrate(sim_f.t + step_f),
                      "t": lambda: sim_q.t + step_q}, rounds)
    med = {k: statistics.median(x) * 1e6 for k, x in t.items()}
    print(f"  Quantity system (3 bodies, wh, dt = 10 d), continuing sim.integrate(sim.t + 10 * "
          f"u.day): {med['q']:.2f} us, of which sim.t + 10 * u.day {med['t']:.2f} us; the "
          f"same system as floats: {med['f']:.2f} us")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="smaller sizes, fewer repeats")
    parser.add_argument("--skip", nargs="*", default=[],
                        choices=["calls", "throughput", "first", "simulation"],
                        help="parts to leave out")
    parser.add_argument("--nmax", type=int, default=None,
                        help="largest N of part 1 (default 1e7, 1e6 with --quick; 1: one orbit)")
    parser.add_argument("--clock", choices=sorted(CLOCKS), default="wall",
                        help="clock of parts 1 and 2 (cpu: process CPU time, for a loaded machine)")
    args = parser.parse_args()
    global _clock
    _clock = CLOCKS[args.clock]
    nmax = args.nmax or (10**6 if args.quick else 10**7)
    nmax_reb = 10**5 if args.quick else 10**6
    repeat = 5 if args.quick else 9
    print(f"numba {numba.__version__}, threading layer after first use; "
          f"{numba.config.NUMBA_NUM_THREADS} threads; load average {os.getloadavg()[0]:.1f}; "
          f"{args.clock} clock")
    if "calls" not in args.skip:
        bench_per_call(nmax, nmax_reb, repeat)
    if "throughput" not in args.skip:
        bench_throughput(10**6, repeat, 9 if args.quick else 15)
    if "simulation" not in args.skip:
        bench_simulation_calls(5 if args.quick else 11)
    if "first" not in args.skip:
        bench_first_run(2 if args.quick else 5)


if __name__ == "__main__":
    main()
