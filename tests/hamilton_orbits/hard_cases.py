"""The named catalogue of hard two-body cases, shared by every test that takes orbits.

Each :class:`HardCase` is a state ``(r, v, mu)`` built here with textbook
perifocal formulas in numpy (independently of the package under test):
``r = p/(1 + e cos nu) (cos nu P + sin nu Q)``,
``v = sqrt(mu/p) (-sin nu P + (e + cos nu) Q)`` (e.g. Vallado, *Fundamentals of
Astrodynamics and Applications*, 4th ed., algorithm 10, COE2RV).

Import with ``from hard_cases import CASES`` (tests/hamilton_orbits is on the
path under pytest's rootdir-relative import mode) or by file path.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["CASES", "HardCase", "perifocal_state"]


@dataclass(frozen=True)
class HardCase:
    """One named state: ``r`` (3,), ``v`` (3,), ``mu``, and what it exercises."""

    name: str
    r: np.ndarray
    v: np.ndarray
    mu: float
    kind: str  # "ellipse", "parabola", "hyperbola", "radial"


def perifocal_state(q, e, inc, lan, argp, nu, mu):
    """Textbook COE2RV from the periapsis distance (works for every non-radial conic)."""
    p = q * (1.0 + e)
    cl, sl = math.cos(lan), math.sin(lan)
    ci, si = (-1.0, 0.0) if inc == math.pi else (math.cos(inc), math.sin(inc))
    cw, sw = math.cos(argp), math.sin(argp)
    P = np.array([cl * cw - sl * sw * ci, sl * cw + cl * sw * ci, sw * si])
    Q = np.array([-cl * sw - sl * cw * ci, -sl * sw + cl * cw * ci, cw * si])
    rr = p / (1.0 + e * math.cos(nu))
    k = math.sqrt(mu / p)
    r = rr * (math.cos(nu) * P + math.sin(nu) * Q)
    v = k * (-math.sin(nu) * P + (e + math.cos(nu)) * Q)
    return r, v


def _kind(e):
    return "ellipse" if e < 1 else ("parabola" if e == 1 else "hyperbola")


def _build() -> list[HardCase]:
    cases: list[HardCase] = []
    # eccentricity ladder, generic orientation, near periapsis (both sides), mid, near apoapsis
    for e in (0.0, 1e-15, 1e-8, 0.5, 1 - 1e-12, 1.0, 1 + 1e-12, 10.0, 1e6):
        nus = [0.7, 1e-12, -1e-12, 0.0]
        if e < 1:
            nus += [math.pi - 1e-9, math.pi, -2.5]
        for nu in nus:
            r, v = perifocal_state(1.3, e, 0.4, 1.1, 2.3, nu, 0.8)
            cases.append(HardCase(f"e={e!r} nu={nu!r}", r, v, 0.8, _kind(e)))
    # inclination ladder, eccentric and circular
    for inc in (0.0, 1e-12, math.pi / 2, math.pi - 1e-12, math.pi):
        for e in (0.0, 0.3, 2.0):
            r, v = perifocal_state(2.0, e, inc, 0.9, 4.0, 0.3, 1.0)
            cases.append(HardCase(f"inc={inc:g} e={e:g}", r, v, 1.0, _kind(e)))
    # axis-aligned periapsis: M ~ 1e-12 is then determined to full relative precision
    for e in (0.5, 3.0):
        r, v = perifocal_state(1.0, e, 0.0, 0.0, 0.0, 1e-12, 1.0)
        cases.append(HardCase(f"axis-aligned e={e:g} nu=1e-12", r, v, 1.0, _kind(e)))
    # radial orbits: bound, parabolic, unbound; in, out and at rest
    d = np.array([1.0, 2.0, 3.0]) / math.sqrt(14.0)
    for label, speed in (("bound", 0.6), ("parabolic", math.sqrt(2.0)), ("unbound", 2.5)):
        for sign in (1.0, -1.0):
            cases.append(
                HardCase(f"radial {label} {'out' if sign > 0 else 'in'}",
                         1.0 * d, sign * speed * d, 1.0, "radial")
            )
    cases.append(HardCase("radial at rest", 2.0 * d, 0.0 * d, 1.0, "radial"))
    cases.append(HardCase("radial along z", np.array([0, 0, 1.5]), np.array([0, 0, 0.3]), 1.0,
                          "radial"))
    cases.append(HardCase("radial in plane", np.array([1.5, -0.5, 0]), np.array([-0.3, 0.1, 0]),
                          1.0, "radial"))
    # extreme scales: length 1e-10 .. 1e10, mu 1e-20 .. 1e20
    for length in (1e-10, 1e10):
        for mu in (1e-20, 1e20):
            for e in (0.2, 1.0, 4.0):
                r, v = perifocal_state(length, e, 0.7, 2.0, 1.0, 0.5, mu)
                cases.append(HardCase(f"scale L={length:g} mu={mu:g} e={e:g}", r, v, mu, _kind(e)))
    return cases


CASES: list[HardCase] = _build()
