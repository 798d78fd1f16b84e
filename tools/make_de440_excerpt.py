"""Write the excerpt of DE440's segments the tests use (``tests/hamilton_orbits/data/``).

The records of every chain's segment (the Sun, the planets, the Earth, the Moon)
that cover J2000 - 40 days to J2000 + 2 Julian years + 40 days, as
:class:`hamilton_orbits.spk.Segments` saves them: a few hundred kB, enough to
test the compiled evaluation against the shipped yearly table (J2000, + 1 yr,
+ 2 yr) without the 114 MB kernel.

Run:  python tools/make_de440_excerpt.py   (needs the ``[ephemeris]`` extra)
"""

from __future__ import annotations

from pathlib import Path

from hamilton_orbits.ephemeris import J2000_JD
from hamilton_orbits.spk import Segments

OUT = Path(__file__).resolve().parents[1] / "src" / "hamilton_orbits" / "data" / \
    "de440_excerpt.npz"  # (hamilton_orbits.spk.EXCERPT)


def main() -> None:
    segments = Segments.from_kernel(J2000_JD - 40.0, J2000_JD + 2 * 365.25 + 40.0)
    segments.save(OUT)
    size = OUT.stat().st_size
    print(f"wrote {OUT} ({size / 1024:.0f} kB, {len(segments.segments)} segments)")


if __name__ == "__main__":
    main()
