"""Quaternion throughput: ours against quaternionic, numpy-quaternion and scipy.

Run ``python benchmarks/bench_quaternion.py`` (``--quick`` for 10^4 elements).
Every peer runs in this same process on the same data; the script prints the
time per element and the ratio peer/ours (> 1 means ours is faster).  Peers
that are not installed are reported as missing (``pip install -e ".[bench]"``).

Targets (issue 2): product within 1.3x of quaternionic; rotate faster than
scipy's ``Rotation.apply``; one scalar product no slower than 2x numpy-quaternion.
"""

from __future__ import annotations

import argparse
import timeit
from collections.abc import Callable

import numpy as np
from scipy.spatial.transform import Rotation

from hamilton_orbits import Quaternion


def best(fn: Callable[[], object], number: int, repeat: int = 5) -> float:
    """Best wall time of one call of ``fn`` over ``repeat`` rounds of ``number`` calls."""
    fn()  # warm-up (JIT compile, caches)
    return min(timeit.repeat(fn, number=number, repeat=repeat)) / number


def row(name: str, ours: float, peers: dict[str, float | None], per: int) -> None:
    cells = [f"{name:<22} ours {ours / per * 1e9:9.2f} ns/elem"]
    for peer, t in peers.items():
        if t is None:
            cells.append(f"{peer}: not installed")
        else:
            cells.append(f"{peer} {t / per * 1e9:9.2f} ns (ratio {t / ours:6.2f})")
    print("  |  ".join(cells))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="10^4 elements instead of 10^6")
    args = parser.parse_args()
    n = 10_000 if args.quick else 1_000_000
    number = 20 if args.quick else 3
    rng = np.random.default_rng(2)
    a = rng.normal(size=(n, 4))
    b = rng.normal(size=(n, 4))
    a /= np.linalg.norm(a, axis=1)[:, None]
    b /= np.linalg.norm(b, axis=1)[:, None]
    v = rng.normal(size=(n, 3))
    qa, qb = Quaternion(a), Quaternion(b)

    try:
        import quaternionic
    except ImportError:  # pragma: no cover - optional peer
        quaternionic = None
    try:
        import quaternion as npq
    except ImportError:  # pragma: no cover - optional peer
        npq = None

    print(f"hamilton-orbits quaternion benchmark, n = {n:,} (ratio = peer time / our time)")

    # --- product
    ours = best(lambda: qa * qb, number)
    peers: dict[str, float | None] = {}
    if quaternionic is not None:
        A, B = quaternionic.array(a), quaternionic.array(b)
        peers["quaternionic"] = best(lambda: A * B, number)
    else:
        peers["quaternionic"] = None
    if npq is not None:
        Aq, Bq = npq.as_quat_array(a), npq.as_quat_array(b)
        peers["numpy-quaternion"] = best(lambda: Aq * Bq, number)
    else:
        peers["numpy-quaternion"] = None
    ra = Rotation.from_quat(a, scalar_first=True)
    rb = Rotation.from_quat(b, scalar_first=True)
    peers["scipy Rotation *"] = best(lambda: ra * rb, number)
    row("product", ours, peers, n)
    ratio_product = (peers["quaternionic"] or np.nan) / ours

    # --- rotate
    ours = best(lambda: qa.rotate(v), number)
    peers = {"scipy apply": best(lambda: ra.apply(v), number)}
    if quaternionic is not None:
        A = quaternionic.array(a)
        V = quaternionic.array.from_vector_part(v)
        peers["quaternionic q v q̄"] = best(lambda: (A * V * A.conj()).vector, number)
    if npq is not None:
        Aq = npq.as_quat_array(a)
        Vq = npq.from_vector_part(v)
        peers["numpy-quaternion q v q̄"] = best(
            lambda: npq.as_vector_part(Aq * Vq * Aq.conj()), number
        )
    row("rotate", ours, peers, n)
    ratio_rotate = peers["scipy apply"] / ours

    # --- rotation matrix
    ours = best(lambda: qa.as_rotation_matrix(), number)
    peers = {"scipy as_matrix": best(lambda: ra.as_matrix(), number)}
    if quaternionic is not None:
        A = quaternionic.array(a)
        peers["quaternionic"] = best(lambda: A.to_rotation_matrix, number)
    if npq is not None:
        Aq = npq.as_quat_array(a)
        peers["numpy-quaternion"] = best(lambda: npq.as_rotation_matrix(Aq), number)
    row("as_rotation_matrix", ours, peers, n)

    # --- one scalar product
    p, q = Quaternion(a[0]), Quaternion(b[0])
    ours = best(lambda: p * q, 20_000)
    peers = {}
    if npq is not None:
        p1, q1 = npq.quaternion(*a[0]), npq.quaternion(*b[0])
        peers["numpy-quaternion"] = best(lambda: p1 * q1, 20_000)
    if quaternionic is not None:
        p2, q2 = quaternionic.array(a[0]), quaternionic.array(b[0])
        peers["quaternionic"] = best(lambda: p2 * q2, 20_000)
    row("scalar product", ours, peers, 1)
    ratio_scalar = ours / peers["numpy-quaternion"] if "numpy-quaternion" in peers else np.nan

    print()
    print(f"target product within 1.3x of quaternionic: ours / theirs = {1 / ratio_product:.2f}")
    print(f"target rotate faster than scipy apply: scipy / ours = {ratio_rotate:.2f}")
    print(f"target scalar product <= 2x numpy-quaternion: ours / theirs = {ratio_scalar:.2f}")


if __name__ == "__main__":
    main()
