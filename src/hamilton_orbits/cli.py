"""The ``hamilton-orbits`` command.

``hamilton-orbits`` with no argument runs the default demo: Hamilton's quaternion
algebra and a rotation round trip, Hamilton's two-body integrals on a textbook
orbit, then the demo sections that other packages register under the entry-point
group ``hamilton_orbits.demos`` (``rigid`` adds the flip of a free rigid body), so
that ``hamilton_orbits`` never imports ``rigid`` itself (DESIGN.md).
``--version`` and ``--help`` answer at once.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

import numpy as np


def _demo() -> int:
    import astropy.units as u

    from hamilton_orbits import KeplerOrbit, Quaternion

    print("hamilton-orbits: Hamilton's quaternions (1845), Cayley's rotations (1843)")
    i, j, k = Quaternion.from_array(np.eye(4)[1:])
    print(f"  i^2 = {i * i!r}")
    print(f"  ijk = {i * j * k!r}")
    alpha = Quaternion.from_vector([1.0, 2.0, 2.0])
    beta = Quaternion.from_vector([0.0, 3.0, 4.0])
    print(f"  alpha beta = -alpha.beta + alpha x beta = {alpha * beta!r}")
    q = Quaternion.from_axis_angle([1.0, 1.0, 1.0], 2.0 * np.pi / 3.0)
    print("  a third of a turn about (1, 1, 1) permutes the axes:")
    print("    q i q^-1 =", np.round(q.rotate([1.0, 0.0, 0.0]), 15) + 0.0)
    g = q.as_gibbs()
    print("  Cayley's (lambda, mu, nu) = tan(theta/2) axis =", np.round(g, 15))
    rng = np.random.default_rng(1845)
    qs = Quaternion.from_array(rng.normal(size=(1_000_000, 4))).unit()
    back = Quaternion.from_rotation_matrix(qs.as_rotation_matrix())
    print(
        "  10^6 random rotations -> matrices -> quaternions: largest geodesic error "
        f"{qs.rotation_distance(back).max():.2e} rad"
    )

    print("\nHamilton's two-body integrals (Vallado, 4th ed., Example 2-5 state):")
    r = [6524.834, 6862.875, 6448.296] * u.km
    v = [4.901327, 5.533756, -1.976341] * u.km / u.s
    orbit = KeplerOrbit.from_state(r, v, 398600.4418 * u.km**3 / u.s**2)
    print(f"  a = {orbit.a:.3f}, e = {float(orbit.e):.6f}, p = {orbit.p:.3f}")
    print(
        f"  inc = {orbit.inc.to(u.deg):.3f}, lan = {orbit.lan.to(u.deg):.3f}, "
        f"argp = {orbit.argp.to(u.deg):.3f}, nu = {orbit.nu.to(u.deg):.3f}"
    )
    eps = orbit.hamilton_epsilon
    print(f"  Hamilton's epsilon (eq. 13, towards apoapsis) = {np.round(eps, 6)}")
    later = orbit
    for _ in range(7):  # seven steps of a seventh of a period, by universal variables
        later = later.propagate(orbit.period / 7)
    r1, _ = later.state()
    print(
        f"  after 7 steps of P/7 (P = {orbit.period.to(u.h):.4f}) the body is back "
        f"within {np.linalg.norm((r1 - r).to_value(u.mm)):.3g} mm"
    )

    from importlib.metadata import entry_points

    for ep in sorted(entry_points(group="hamilton_orbits.demos"), key=lambda e: e.name):
        print()
        ep.load()()
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``hamilton-orbits`` console script.

    Examples
    --------
    >>> main(["--version"])  # doctest: +ELLIPSIS
    hamilton-orbits ...
    0
    """
    from hamilton_orbits import __version__

    parser = argparse.ArgumentParser(
        prog="hamilton-orbits",
        description="Celestial mechanics and rigid-body rotation on Hamilton's quaternions.",
    )
    parser.add_argument("--version", action="store_true", help="print the version and exit")
    sub = parser.add_subparsers(dest="command")
    sub.add_parser("demo", help="the quaternion / rotation demo (the default)")
    args = parser.parse_args(argv)
    if args.version:
        print(f"hamilton-orbits {__version__}")
        return 0
    return _demo()


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
