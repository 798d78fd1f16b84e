"""What a new user waits for: compilation on the first run, each case in a fresh process.

Run:  python benchmarks/bench_first_run.py [--repeats 3] [--quick]

Every case runs in its own process with an empty numba cache (``NUMBA_CACHE_DIR``
a new temporary folder) and an empty cache of generated right-hand sides
(``HAMILTON_ORBITS_CACHE_DIR``), as on a fresh machine; the process reports the
seconds numba spent compiling (its ``numba:compile`` events, through
:mod:`hamilton_orbits.firstrun`) and the wall time of the whole command.  The
cases (issue 31's goals beside them):

- the main job: ``hamilton-orbits run solar-system`` cold and warm (goal: at most 15 s
  of compilation, the cold command at most warm + 15 s);
- the first ``integrate`` of each method (radau15, wh, leapfrog, dop853) of the Sun,
  Jupiter and Saturn with no effect (goal: at most 5 s);
- a new effect list once the method is compiled: ``["gr", "j2"]`` after ``["gr"]``
  with radau15 (goal: at most 2 s).

Compilation is CPU work: on a machine whose cores are busy with other jobs the
wall times grow; the compile seconds printed are those of the process itself.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

PRELUDE = """
import json, time
from hamilton_orbits import firstrun
start = time.perf_counter()
"""

SYSTEM = """
import astropy.units as u
from hamilton_orbits import System, integrate
s = System.solar_system(bodies=["sun", "jupiter", "saturn"])
T, DT = 100.0 * u.d, 10.0 * u.d
# Jupiter's J2 and equatorial radius (Jacobson 2013, as JPL's jup310 gives them)
J2 = {"name": "j2", "body": "jupiter", "j2": 0.014736, "radius": "71492 km"}
"""

CASES = {
    "main job, cold": ("cli", None, 15.0),
    "first integrate radau15": ("code", SYSTEM + "integrate(s, T, method='radau15')", 5.0),
    "first integrate wh": ("code", SYSTEM + "integrate(s, T, method='wh', dt=DT)", 5.0),
    "first integrate leapfrog": ("code", SYSTEM + "integrate(s, T, method='leapfrog', dt=DT)",
                                 5.0),
    "first integrate dop853": ("code", SYSTEM + "integrate(s, T, method='dop853')", 5.0),
    "new effect list (gr, j2 after gr)": (
        "code",
        SYSTEM + "integrate(s, T, method='radau15', effects=['gr'])\n"
        "firstrun.claim_compilation()\nstart = time.perf_counter()\n"
        "integrate(s, T, method='radau15', effects=['gr', J2])",
        2.0,
    ),
}

REPORT = """
compiled = firstrun.claim_compilation()
print("RESULT " + json.dumps({"compile": compiled[0], "count": compiled[1],
                              "wall": time.perf_counter() - start,
                              "kernels": firstrun.last_claim()}))
"""


def _env(numba_dir: str, rhs_dir: str) -> dict[str, str]:
    env = dict(os.environ, NUMBA_CACHE_DIR=numba_dir, HAMILTON_ORBITS_CACHE_DIR=rhs_dir)
    env["PYTHONPATH"] = str(ROOT / "src") + os.pathsep + env.get("PYTHONPATH", "")
    return env


def _main_job(env: dict[str, str], out: str) -> dict:
    """The README's main job as a command; its compile seconds from its summary."""
    start = time.perf_counter()
    res = subprocess.run([sys.executable, "-m", "hamilton_orbits", "--no-progress", "run",
                          "solar-system", "--out", out],
                         env=env, capture_output=True, text=True, check=True)
    wall = time.perf_counter() - start
    line = next((x for x in res.stdout.splitlines() if x.startswith("compiled:")), "")
    seconds = 0.0
    if "numba kernels in" in line:
        seconds = float(line.split("numba kernels in")[1].split()[0])
    return {"compile": seconds, "wall": wall, "line": line}


def run_case(name: str) -> dict:
    kind, code, _ = CASES[name]
    with tempfile.TemporaryDirectory() as tmp:
        env = _env(os.path.join(tmp, "numba"), os.path.join(tmp, "rhs"))
        if kind == "cli":
            cold = _main_job(env, os.path.join(tmp, "out1"))
            warm = _main_job(env, os.path.join(tmp, "out2"))
            return {"compile": cold["compile"], "wall": cold["wall"], "warm": warm["wall"],
                    "line": cold["line"]}
        res = subprocess.run([sys.executable, "-c", PRELUDE + code + REPORT], env=env,
                             capture_output=True, text=True, check=True)
        line = next(x for x in res.stdout.splitlines() if x.startswith("RESULT "))
        return json.loads(line[len("RESULT "):])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="one repeat, main job only")
    parser.add_argument("--cases", nargs="*", default=list(CASES))
    args = parser.parse_args()
    names = ["main job, cold"] if args.quick else args.cases
    repeats = 1 if args.quick else args.repeats
    print(f"run of {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, "
          f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}; "
          f"median of {repeats} (each in a fresh process with empty caches)")
    print(f"{'case':36s} {'compile s':>10s} {'goal':>6s}  wall s   notes")
    for name in names:
        runs = [run_case(name) for _ in range(repeats)]
        comp = statistics.median(r["compile"] for r in runs)
        wall = statistics.median(r["wall"] for r in runs)
        goal = CASES[name][2]
        note = ""
        if "warm" in runs[0]:
            warm = statistics.median(r["warm"] for r in runs)
            note = f"warm {warm:.1f} s; cold - warm {wall - warm:.1f} s (goal <= 15)"
        elif runs[0].get("kernels"):
            top = sorted(runs[0]["kernels"], key=lambda k: -k[1])[:3]
            note = ", ".join(f"{k} {s:.1f}" for k, s in top)
        spread = f"[{min(r['compile'] for r in runs):.1f}-{max(r['compile'] for r in runs):.1f}]"
        print(f"{name:36s} {comp:10.1f} {goal:6.0f}  {wall:6.1f}   {spread} {note}", flush=True)


if __name__ == "__main__":
    main()
