"""Write tests/hamilton_orbits/data/snapshot-v<FORMAT_VERSION>.nc and
archive-v<ARCHIVE_VERSION>/: the snapshot and the archive that
tests/hamilton_orbits/test_snapshot.py and test_archive.py read with every later
version of the formats.  A fixture that exists is left as it is: it was written by
the version it pins.

A planet of zero mass on a Kepler ellipse (a = 1, e = 0.3, inc = 0.2, lan = 0.5,
argp = 1.0, nu = 0 at t = 0) about a star of GM 1, integrated by wh (dt = 0.01):
saved at t = 10 (from snapshot format 2 on, integrated by dop853 instead: its
``max_step``, infinite, is what format 2 writes as strict JSON); archived every 2
time units through the output times 0, 1, ..., 5 (a kill after the snapshot at
t = 4 is what the archive looks like).  From format 3 on, two calls follow, to 7
and to 9, which go on in the same segment, each record holding its call (a kill
after the snapshot at t = 8, in the third call).
Run once per new format version (``archive-v1`` was written by format 1;
``archive-v2`` by format 2, at commit 6e3b256; ``archive-v3`` by format 3, in
session 18 of 2026-11-29; ``archive-v4`` by format 4, in session 20 of
2026-11-29; ``snapshot-v2.nc`` by snapshot format 2, in session 25 of 2026-11-30):

    python tools/make_snapshot_fixture.py
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from hamilton_orbits import Body, KeplerOrbit, Simulation, System
from hamilton_orbits.checkpoint import ARCHIVE_VERSION
from hamilton_orbits.snapshot import FORMAT_VERSION


def main() -> None:
    orbit = KeplerOrbit.from_elements(a=1.0, e=0.3, inc=0.2, lan=0.5, argp=1.0, nu=0.0, mu=1.0)
    r, v = orbit.state()
    system = System([Body("star", 1.0, [0, 0, 0], [0, 0, 0]), Body("planet", 0.0, r, v)])
    if FORMAT_VERSION >= 2:
        sim = Simulation(system, method="dop853", tol=1e-12)
    else:
        sim = Simulation(system, method="wh", dt=0.01)
    sim.integrate(10.0)
    out = Path(__file__).resolve().parents[1] / "tests" / "hamilton_orbits" / "data"
    out.mkdir(parents=True, exist_ok=True)
    saved = out / f"snapshot-v{FORMAT_VERSION}.nc"
    if not saved.exists():
        sim.save(saved)
    folder = out / f"archive-v{ARCHIVE_VERSION}"
    if folder.exists():
        return
    archived = Simulation(system, method="wh", dt=0.01, archive=folder, every=2.0)
    archived.integrate(np.arange(6.0))
    if ARCHIVE_VERSION >= 3:  # (calls that go on in the segment the last one wrote)
        archived.integrate(7.0)
        archived.integrate(9.0)


if __name__ == "__main__":
    main()
