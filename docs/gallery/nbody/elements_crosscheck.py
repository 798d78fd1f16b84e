"""
Cross-check KeplerOrbit's elements against rebound's ``sim.orbits()``.
======================================================================

Runs on random orbits and on the hard-case catalogue (tests/hamilton_orbits/
hard_cases.py); prints a table of the largest differences and the cases rebound
cannot do, and writes the same text to ``examples/out/elements_crosscheck.txt``.

    python examples/nbody/elements_crosscheck.py [--quick]
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np
import rebound

from hamilton_orbits.orbit import KeplerOrbit

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1] / "tests" / "hamilton_orbits"))
from hard_cases import CASES  # noqa: E402

NAMES = ("a", "e", "inc", "lan", "argp", "nu", "M")


def rebound_elements(r, v, mu):
    out = []
    for ri, vi, m in zip(r, v, mu, strict=True):
        sim = rebound.Simulation()
        sim.G = 1.0
        sim.add(m=m)
        sim.add(x=ri[0], y=ri[1], z=ri[2], vx=vi[0], vy=vi[1], vz=vi[2])
        o = sim.orbits()[0]
        out.append([o.a, o.e, o.inc, o.Omega, o.omega, o.f, o.M])
    return np.array(out)


def ours(r, v, mu):
    o = KeplerOrbit.from_state(r, v, mu)
    return np.stack([np.asarray(getattr(o, n), float) for n in
                     ("a", "e", "inc", "lan", "argp", "nu", "M")], axis=-1)


def diff(A, B):
    d = np.empty_like(A)
    with np.errstate(invalid="ignore", divide="ignore"):
        d[:, 0] = np.abs(A[:, 0] / B[:, 0] - 1)
        d[:, 1] = np.abs(A[:, 1] - B[:, 1])
        x = np.mod(A[:, 2:] - B[:, 2:], 2 * math.pi)
        d[:, 2:] = np.minimum(x, 2 * math.pi - x)
    return d


def main(argv=None) -> str:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", help="write elements_crosscheck.txt into this folder "
                                  "(default: examples/out)")
    args = ap.parse_args(argv)
    n = 2000 if args.quick else 100000
    lines = []
    rng = np.random.default_rng(0)
    r = rng.normal(size=(n, 3))
    v = 0.8 * rng.normal(size=(n, 3))
    mu = np.ones(n)
    t0 = time.perf_counter()
    A = rebound_elements(r, v, mu)
    t1 = time.perf_counter()
    B = ours(r, v, mu)
    t2 = time.perf_counter()
    d = diff(A, B)
    lines.append(f"{n} random orbits: largest |rebound - ours| "
                 "(a relative, e absolute, angles in rad modulo 2 pi)")
    lines.append("  " + "  ".join(f"{k:>9s}" for k in NAMES))
    lines.append("  " + "  ".join(f"{x:9.2e}" for x in np.nanmax(d, axis=0)))
    lines.append(f"  NaN: rebound {int(np.isnan(A).any(axis=1).sum())}, "
                 f"ours {int(np.isnan(B).any(axis=1).sum())}")
    lines.append(f"  time (one rebound Simulation per orbit here, not a benchmark): "
                 f"rebound {t1 - t0:.2f} s, ours {t2 - t1:.3f} s")
    lines.append("")
    lines.append("hard-case catalogue: where rebound returns NaN/inf or differs from us")
    lines.append(f"  {'case':44s} {'element':8s} {'rebound':>12s} {'ours':>12s}")
    r = np.array([c.r for c in CASES])
    v = np.array([c.v for c in CASES])
    mu = np.array([c.mu for c in CASES])
    A = rebound_elements(r, v, mu)
    B = ours(r, v, mu)
    d = diff(A, B)
    assert np.all(np.isfinite(B[:, 1:])), "ours must be finite on every hard case"
    for i, c in enumerate(CASES):
        for j, name in enumerate(NAMES):
            bad = not np.isfinite(A[i, j]) and np.isfinite(B[i, j])
            big = np.isfinite(d[i, j]) and d[i, j] > 1e-8 and name not in ("lan", "argp")
            if bad or big:
                lines.append(f"  {c.name:44s} {name:8s} {A[i, j]:12.5g} {B[i, j]:12.5g}")
    lines.append("  (lan/argp differences at degenerate inc or e are convention: ours are 0)")
    text = "\n".join(lines)
    out = HERE.parent / "out" if args.out is None else Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "elements_crosscheck.txt").write_text(text + "\n")
    print(text)
    return text


if __name__ == "__main__":
    main()
