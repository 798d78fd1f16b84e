"""The published hard cases on default settings: ours (radau15) against rebound's IAS15.

For each case of ``tests/hamilton_orbits/test_nbody_hard_cases.py`` (the same
initial states), both codes run from the same state with their defaults (tol /
epsilon 1e-9, the PRS23 step rule; Burrau's problem also with the global rule):
steps, the final relative energy error, the largest position difference between
the two at the end (relative to the largest distance), and the CPU time of each,
in one process.

    python benchmarks/bench_hard_cases.py
"""

from __future__ import annotations

import time

import numpy as np

from hamilton_orbits import Body, KeplerOrbit, System, integrate


def figure_eight() -> tuple[System, float]:
    x1 = np.array([0.97000436, -0.24308753, 0.0])
    v3 = np.array([-0.93240737, -0.86473146, 0.0])
    s = System([Body("a", 1.0, x1, -v3 / 2), Body("b", 1.0, -x1, -v3 / 2),
                Body("c", 1.0, [0.0, 0.0, 0.0], v3)])
    return s, 100 * 6.32591398


def burrau() -> tuple[System, float]:
    s = System([Body("m3", 3.0, [1, 3, 0], [0, 0, 0]), Body("m4", 4.0, [-2, -1, 0], [0, 0, 0]),
                Body("m5", 5.0, [1, -1, 0], [0, 0, 0])])
    return s, 70.0


def kozai() -> tuple[System, float]:
    inner = KeplerOrbit.from_elements(a=1.0, e=0.01, inc=np.radians(65.0), lan=0.0,
                                      argp=np.pi / 2, nu=0.3, mu=1.0)
    ri, vi = inner.state()
    vp = np.sqrt(2.0 / 20.0)
    r0, v0 = -0.5 * np.array([20.0, 0, 0]), -0.5 * np.array([0, vp, 0])
    s = System([Body("star", 1.0, r0, v0), Body("perturber", 1.0, -r0, -v0),
                Body("particle", 0.0, r0 + ri, v0 + vi)])
    return s, 4.0 * 8000.0


def comet() -> tuple[System, float]:
    mu_j, a_j = 1e-3, 5.2
    n = np.sqrt((1 + mu_j) / a_j**3)
    f = mu_j / (1 + mu_j)
    sun = Body("sun", 1.0, [-f * a_j, 0, 0], [0, -f * a_j * n, 0])
    jup = Body("jupiter", mu_j, [(1 - f) * a_j, 0, 0], [0, (1 - f) * a_j * n, 0])
    c = KeplerOrbit.from_elements(q=0.5, e=0.9999, inc=np.radians(10), lan=0.3, argp=2.0,
                                  M=-1e-4, mu=1.0)
    rc, vc = c.state()
    return System([sun, jup, Body("comet", 0.0, rc + sun.r, vc + sun.v)]), 600.0


def flyby() -> tuple[System, float]:
    mu, q, v_inf = 398600.4418, 2 * 6378.1363, 7.0
    a = -mu / v_inf**2
    orbit = KeplerOrbit.from_elements(a=a, e=1 - q / a, inc=0.0, lan=0.0, argp=0.0,
                                      M=-np.sqrt(mu / abs(a) ** 3) * 2 * 86400.0, mu=mu)
    r, v = orbit.state()
    return System([Body("earth", mu, [0, 0, 0], [0, 0, 0]), Body("craft", 0.0, r, v)]), 4 * 86400.0


def ias15(system: System, t_end: float, mode: int) -> tuple[np.ndarray, float, int, float]:
    sim = system.to_rebound()
    sim.integrator = "ias15"
    sim.integrator.adaptive_mode = mode
    e0 = sim.energy()
    t0 = time.process_time()
    sim.integrate(t_end, exact_finish_time=1)
    wall = time.process_time() - t0
    de = abs(sim.energy() - e0) / abs(e0) if e0 != 0 else abs(sim.energy() - e0)
    return np.array([p.xyz for p in sim.particles]), de, int(sim.steps_done), wall


def main() -> None:
    print(f"hard cases, default settings (tol = epsilon = 1e-9), "
          f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}")
    print(f"{'case':<28}{'steps ours/IAS15':>20}{'|dE/E| ours':>13}{'IAS15':>10}"
          f"{'|dr| / r':>11}{'CPU ours/IAS15 (s)':>22}")
    cases = [("figure-eight, 100 periods", figure_eight, "prs23"),
             ("Burrau to t = 70", burrau, "prs23"),
             ("Burrau, global rule", burrau, "global"),
             ("Kozai-Lidov, 4 t_K", kozai, "prs23"),
             ("comet e = 0.9999 past Jupiter", comet, "prs23"),
             ("flyby at 2 Earth radii", flyby, "prs23")]
    for label, build, rule in cases:
        system, t_end = build()
        integrate(system, t_end / 1000, criterion=rule)  # compile
        t0 = time.process_time()
        traj = integrate(system, t_end, criterion=rule)
        ours = time.process_time() - t0
        r, de, steps, theirs = ias15(system, t_end, 2 if rule == "prs23" else 1)
        dr = np.max(np.linalg.norm(r - traj.r[-1], axis=1)) / np.max(np.linalg.norm(r, axis=1))
        print(f"{label:<28}{traj.steps:>10}/{steps:<9}{abs(traj.energy_error[-1]):>13.1e}"
              f"{de:>10.1e}{dr:>11.1e}{ours:>11.3f}/{theirs:<9.3f}")


if __name__ == "__main__":
    main()
