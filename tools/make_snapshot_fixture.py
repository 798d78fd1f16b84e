"""Write tests/hamilton_orbits/data/snapshot-v<FORMAT_VERSION>.nc: the snapshot that
tests/hamilton_orbits/test_snapshot.py reads with every later version of the format.

A planet of zero mass on a Kepler ellipse (a = 1, e = 0.3, inc = 0.2, lan = 0.5,
argp = 1.0, nu = 0 at t = 0) about a star of GM 1, integrated by wh (dt = 0.01) to
t = 10 and saved.  Run once per new format version:

    python tools/make_snapshot_fixture.py
"""

from __future__ import annotations

from pathlib import Path

from hamilton_orbits import Body, KeplerOrbit, Simulation, System
from hamilton_orbits.snapshot import FORMAT_VERSION


def main() -> None:
    orbit = KeplerOrbit.from_elements(a=1.0, e=0.3, inc=0.2, lan=0.5, argp=1.0, nu=0.0, mu=1.0)
    r, v = orbit.state()
    system = System([Body("star", 1.0, [0, 0, 0], [0, 0, 0]), Body("planet", 0.0, r, v)])
    sim = Simulation(system, method="wh", dt=0.01)
    sim.integrate(10.0)
    out = Path(__file__).resolve().parents[1] / "tests" / "hamilton_orbits" / "data"
    out.mkdir(parents=True, exist_ok=True)
    sim.save(out / f"snapshot-v{FORMAT_VERSION}.nc")


if __name__ == "__main__":
    main()
