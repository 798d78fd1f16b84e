"""ASSIST's side of ``benchmarks/bench_small_bodies.py``, run in ASSIST's own environment.

ASSIST pins ``rebound<5`` and this package needs rebound 5, so ASSIST runs in a
virtual environment of its own (``python -m venv /tmp/assist_venv &&
/tmp/assist_venv/bin/pip install assist``) and this script is its entry: it reads
one job as JSON on stdin (barycentric ICRS states ``r``, ``v`` in au and au/day,
TDB Julian date ``jd``, ``days``, ``repeat``, the kernels' paths ``planets`` and
``asteroids``), integrates each body with ASSIST's default forces, the post-Newtonian terms of
the Sun, the planets, the Moon and Pluto (``gr_eih_sources = 11``: our force
model, and that of ASSIST's own tests against JPL; its default is the Sun's alone)
and prints the
final states, the median seconds of ``repeat`` runs of all of them, and ASSIST's
force list as JSON.
"""

import json
import statistics
import sys
import time

import assist
import rebound


def run(ephem, x, jd, days):
    sim = rebound.Simulation()
    sim.add(x=x[0], y=x[1], z=x[2], vx=x[3], vy=x[4], vz=x[5])
    sim.t = jd - ephem.jd_ref
    extras = assist.Extras(sim, ephem)
    extras.gr_eih_sources = 11  # the Sun, planets, Moon, Pluto: ours, and ASSIST's JPL cases
    sim.integrate(sim.t + days)
    p = sim.particles[0]
    return [p.x, p.y, p.z, p.vx, p.vy, p.vz], list(extras.forces)


def main():
    job = json.load(sys.stdin)
    ephem = assist.Ephem(job["planets"], job["asteroids"])
    states = [r + v for r, v in zip(job["r"], job["v"], strict=True)]
    start = time.perf_counter()
    final = [run(ephem, x, job["jd"], job["days"]) for x in states]
    seconds = [time.perf_counter() - start] if job["repeat"] == 0 else []  # (0: that run)
    for _ in range(job["repeat"]):
        start = time.perf_counter()
        for x in states:
            run(ephem, x, job["jd"], job["days"])
        seconds.append(time.perf_counter() - start)
    print(json.dumps({"final": [f for f, _ in final], "seconds": statistics.median(seconds),
                      "forces": final[0][1], "version": assist.__version__}))


if __name__ == "__main__":
    main()
