"""DE440's own Chebyshev segments as arrays, evaluated by a compiled kernel.

The planets, the Sun and the Moon of DE440 are SPK type-2 segments, each the
motion of one body (``target``) about another (``center``) as Chebyshev series
over fixed records (``hamilton_orbits._kernels.chebyshev``).  :class:`Segments`
holds some of them as plain arrays, read from the ``[ephemeris]`` extra's kernel
(:meth:`Segments.from_kernel`, any span DE440 covers) or from a file of them
(:meth:`Segments.load`; ``tools/make_de440_excerpt.py`` writes the two years the
package ships, :data:`EXCERPT`), and gives barycentric states of the bodies by chaining the segments
(the Moon: the Earth-Moon barycentre about the solar-system barycentre, plus the
Moon about the Earth-Moon barycentre), in au and au/day, with no Python per time.
This is the evaluation under ephemeris-driven perturbers (issue 35).

Examples
--------
A made-up Sun moving along x at 1 au a day over one record of 10 days (x = 5 au +
5 au s: T_0 and T_1), evaluated at its middle:

>>> au = de.constant("AU")
>>> coef = np.zeros((3, 1, 2)); coef[0, 0] = [5 * au, 5 * au]
>>> sun = Segments({(0, 10): Segment(2451545.0, 10.0, coef)})
>>> r, v = sun.states([2451550.0], ["sun"])
>>> r[0, 0].tolist(), v[0, 0].tolist()
([5.0, 0.0, 0.0], [1.0, 0.0, 0.0])
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hamilton_orbits import ephemeris as de
from hamilton_orbits._kernels.chebyshev import add_states
from hamilton_orbits.ephemeris import CHAINS

__all__ = ["EXCERPT", "Segment", "Segments"]

#: DE440's segments of the Sun, the planets and the Moon over two years about J2000
#: (all from JD 2451504.5; the Earth and the Moon to 2452316.5, the common span, the
#: Sun, Mercury, Venus and the Earth-Moon barycentre to 2452320.5, Mars to Pluto to
#: 2452336.5: each segment's whole records), shipped with the package for examples and tests
#: (``tools/make_de440_excerpt.py``): ``Segments.load(EXCERPT)``; no asteroid.
EXCERPT = Path(__file__).resolve().parent / "data" / "de440_excerpt.npz"

@dataclass(frozen=True)
class Segment:
    """One SPK type-2 segment's records: from TDB Julian date ``init``, of
    ``intlen`` days each, ``coef`` (3, n records, m coefficients) in km.

    Raises
    ------
    ValueError
        For an ``init`` that is not a finite number, an ``intlen`` that is not a
        finite number of days > 0, or a ``coef`` that is not a float array of shape
        (3, n, m), n and m >= 1, of finite numbers (the compiled evaluation reads
        three components: with two it read past the array), naming the argument.
    """

    init: float
    intlen: float
    coef: np.ndarray

    def __post_init__(self) -> None:
        for name in ("init", "intlen"):
            x = getattr(self, name)
            if (isinstance(x, bool) or not isinstance(x, (int, float, np.integer, np.floating))
                    or not np.isfinite(x) or (name == "intlen" and not x > 0)):
                what = "a number of days > 0" if name == "intlen" else "a Julian date"
                raise ValueError(f"Expected `{name}` of a Segment to be {what} (finite), got "
                                 f"{x!r}")
            object.__setattr__(self, name, float(x))
        coef = self.coef
        shape = np.shape(coef) if isinstance(coef, np.ndarray) else None
        if (shape is None or coef.dtype.kind not in "fiu" or len(shape) != 3 or shape[0] != 3
                or shape[1] < 1 or shape[2] < 1):
            raise ValueError(f"Expected `coef` of a Segment to be a float array of shape "
                             f"(3, n records, m coefficients), got "
                             f"{'shape ' + str(shape) if shape is not None else repr(coef)}")
        coef = np.ascontiguousarray(coef, dtype=np.float64)  # (the kernel's one typing)
        if not np.isfinite(coef).all():
            at = tuple(int(i) for i in np.argwhere(~np.isfinite(coef))[0])
            raise ValueError(f"Expected `coef` of a Segment to be finite, got a non-finite "
                             f"value at index {at}")
        object.__setattr__(self, "coef", coef)


class Segments:
    """Some of DE440's segments: ``{(center, target): (init, intlen, coef)}``."""

    def __init__(self, segments: dict[tuple[int, int], Segment]) -> None:
        if not isinstance(segments, dict):
            raise ValueError(f"Expected `segments` to be a dict {{(center, target): Segment}}, "
                             f"got {type(segments).__name__}")
        for pair, seg in segments.items():
            if (not isinstance(pair, tuple) or len(pair) != 2
                    or not all(isinstance(x, (int, np.integer)) and not isinstance(x, bool)
                               for x in pair)):
                raise ValueError(f"Expected `segments` keyed by (center, target) NAIF ids, got "
                                 f"{pair!r}")
            if not isinstance(seg, Segment):
                raise ValueError(f"Expected `segments` of Segment values, got "
                                 f"{type(seg).__name__} for {pair!r}")
        self.segments = segments

    @classmethod
    def from_kernel(cls, start_jd: float, end_jd: float,
                    pairs: Sequence[tuple[int, int]] | None = None,
                    small_bodies: bool = False) -> Segments:
        """The records of the extra's DE440 kernel (with ``small_bodies``: of JPL's
        sb441-n16, the 16 asteroids about the Sun) that cover TDB Julian dates
        ``start_jd`` to ``end_jd`` (every chain's segments unless ``pairs``; of a
        pair the kernel holds in several segments, the one covering the span).

        Raises
        ------
        ValueError
            Without the kernel's extra, or for a span it does not cover.
        """
        if not de.kernel_available():
            raise ValueError(f"DE440's segments need the kernel: {de.EXTRA_HINT}")
        kernel = de.small_kernel() if small_bodies else de.spk_kernel()
        default = ([chain[-1] for chain in de.ASTEROID_CHAINS.values()] if small_bodies
                   else [p for chain in CHAINS.values() for p in chain])
        wanted = set(pairs or default)
        out, seen = {}, {}
        for seg in kernel.segments:
            pair = (seg.center, seg.target)
            if pair not in wanted or pair in out:
                continue
            seen[pair] = (seg.start_jd, seg.end_jd)
            if not seg.start_jd <= start_jd <= end_jd <= seg.end_jd:
                continue
            init, intlen, coef = seg.load_array()
            first = int(np.floor((start_jd - init) / intlen))
            last = min(int(np.floor((end_jd - init) / intlen)), coef.shape[1] - 1)
            out[pair] = Segment(init + first * intlen, intlen,
                                np.ascontiguousarray(coef[:, first:last + 1]))
        for pair in sorted(wanted - set(out)):
            span = seen.get(pair)
            raise ValueError(f"Expected the kernel to cover JD {start_jd}..{end_jd} with the "
                             f"segment {pair}, got "
                             f"{'no such segment' if span is None else f'JD {span[0]}..{span[1]}'}")
        return cls(out)

    def save(self, path: Path) -> None:
        """Write the segments to an ``.npz`` file (read back by :meth:`load`)."""
        arrays = {}
        for (c, t), seg in self.segments.items():
            arrays[f"s{c}_{t}_coef"] = seg.coef
            arrays[f"s{c}_{t}_span"] = np.array([seg.init, seg.intlen])
        np.savez_compressed(path, **arrays)

    @classmethod
    def load(cls, path: Path) -> Segments:
        """The segments of a file :meth:`save` wrote."""
        with np.load(path) as data:
            out = {}
            for key in data.files:
                if key.endswith("_coef"):
                    c, t = (int(x) for x in key[1:-5].split("_"))
                    init, intlen = data[f"s{c}_{t}_span"]
                    out[(c, t)] = Segment(float(init), float(intlen),
                                           np.ascontiguousarray(data[key]))
        return cls(out)

    def states(self, jd: np.ndarray, names: Sequence[str] | str) -> tuple[np.ndarray, np.ndarray]:
        """Barycentric ICRF positions and velocities (au, au/day) of ``names`` (body
        names; one name alone is a list of one) at TDB Julian dates ``jd`` (n_t,):
        arrays (n_t, n, 3).

        Raises
        ------
        ValueError
            For dates that are not one date or a 1-d array of finite numbers, a body
            without its segments here, or a date they do not cover, naming it (all
            but the last before anything is compiled).
        """
        jd = de.checked_jd(jd)
        chains = self._chains(names)
        jd1 = np.floor(jd)
        jd2 = jd - jd1
        au = de.constant("AU")
        out = np.zeros((len(chains), jd.shape[0], 6))
        for k, (name, chain) in enumerate(chains):
            for pair in chain:
                seg = self.segments[pair]
                bad = add_states(seg.coef, seg.init, seg.intlen, jd1, jd2, out[k])
                if bad >= 0:
                    end = seg.init + seg.intlen * seg.coef.shape[1]
                    raise ValueError(f"Expected `jd` within JD {seg.init}..{end} (the "
                                     f"segments of {name!r}), got {float(jd[bad])!r} at "
                                     f"index {bad}")
        out /= au
        return out[:, :, :3].transpose(1, 0, 2).copy(), out[:, :, 3:].transpose(1, 0, 2).copy()

    def _chains(self, names: Sequence[str] | str) -> list[tuple[str, tuple[tuple[int, int], ...]]]:
        """Each of ``names`` (one name alone: a list of one) with its chain of segments,
        all of them here (``ValueError`` naming `names`, the index and the value)."""
        if isinstance(names, str):
            names = [names]
        out = []
        for k, name in enumerate(names):
            key = str(name).lower()
            chain = CHAINS.get(key) or de.ASTEROID_CHAINS.get(key)
            if chain is None or any(pair not in self.segments for pair in chain):
                raise ValueError(f"Expected `names` among the bodies of these segments, got "
                                 f"{name!r} at index {k}")
            out.append((name, chain))
        return out
