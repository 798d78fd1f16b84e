"""One body of a :class:`~hamilton_orbits.nbody.System`, and the units a Quantity system
is held in.

:class:`Body` is documented (and imported) as :class:`hamilton_orbits.nbody.Body`
and ``hamilton_orbits.Body``; it lives here, below :mod:`hamilton_orbits.nbody`,
:mod:`hamilton_orbits.initial_states` and :mod:`hamilton_orbits.integrals`, which
all build on it.  A body built from astropy Quantities is held in **au, day and
au^3/day^2** (GM); :func:`body_arrays` and :func:`body_from_floats` are the float
views a :class:`~hamilton_orbits.nbody.System` builds its arrays from and makes
its bodies with.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import astropy.constants as const
import astropy.units as u
import numpy as np

from hamilton_orbits.units import DIMENSIONLESS, GM, LENGTH, SPEED, require_consistent

__all__ = [
    "AU",
    "A_UNIT",
    "DAY",
    "E_SI",
    "GM_UNIT",
    "G_SI",
    "L_SI",
    "L_UNIT",
    "V_UNIT",
    "Body",
    "body_arrays",
    "body_from_floats",
]

# internal units of Quantity systems
AU = u.au
DAY = u.day
L_UNIT = u.au
V_UNIT = u.au / u.day
GM_UNIT = u.au**3 / u.day**2
A_UNIT = u.au / u.day**2
G_SI = const.G.to_value(u.m**3 / (u.kg * u.s**2))
# energy of a Quantity system: (sum of gm v^2 terms in au^5/day^4) / G -> J
E_SI = (u.au**5 / u.day**4).to(u.m**5 / u.s**4) / G_SI
L_SI = (u.au**5 / u.day**3).to(u.m**5 / u.s**3) / G_SI


def _as_vector(kind, name: str, value: Any, unit) -> np.ndarray:
    arr = kind(name, value, unit)
    if arr.shape != (3,):
        raise ValueError(f"Expected `{name}` to have shape (3,), got {arr.shape}")
    return arr


@dataclass(frozen=True, init=False)
class Body:
    """One body: a name, its GM, its position and velocity; optionally its shape.

    Parameters
    ----------
    name : str
        A unique name within its :class:`~hamilton_orbits.nbody.System` (``"earth"``).
    gm : Quantity or float
        G times the mass (Hamilton's m), >= 0; 0 makes a massless test particle.
    r, v : Quantity or array_like, shape (3,)
        Position and velocity (barycentric for
        ``System.solar_system``).
    radius : Quantity or float, optional
        Equatorial radius (needed by the ``j2`` effect).
    j2 : float, optional
        Dimensionless oblateness coefficient J2 (the ``j2`` effect).
    pole : array_like, shape (3,), optional
        Direction of the symmetry axis (normalised here); the frame's z axis when a
        ``j2`` is given without a pole.

    Raises
    ------
    ValueError
        For a negative GM, a NaN or infinite value, a wrong shape, a zero pole,
        naming the body and the value; or a mix of Quantities and plain floats.

    Examples
    --------
    >>> import astropy.units as u
    >>> earth = Body("earth", gm=3.986004418e14 * u.m**3 / u.s**2,
    ...              r=[1.0, 0.0, 0.0] * u.au, v=[0.0, 29.78, 0.0] * u.km / u.s)
    >>> earth.r
    <Quantity [1., 0., 0.] AU>
    >>> Body("p", gm=-1.0, r=[1, 0, 0], v=[0, 1, 0])
    Traceback (most recent call last):
    ...
    ValueError: Body 'p': expected `gm` >= 0, got -1.0
    """

    name: str
    _gm: float
    _r: np.ndarray
    _v: np.ndarray
    _radius: float | None
    j2: float | None
    pole: tuple[float, float, float] | None
    quantity: bool

    def __init__(
        self,
        name: str,
        gm: Any,
        r: Any,
        v: Any,
        radius: Any = None,
        j2: Any = None,
        pole: Any = None,
    ) -> None:
        if not isinstance(name, str) or not name:
            raise ValueError(f"Expected `name` to be a non-empty string, got {name!r}")
        try:
            quantity = require_consistent(("gm", "r", "v", "radius"), (gm, r, v, radius))
            g = GM.scalar("gm", gm, GM_UNIT if quantity else None)
            if not g >= 0:
                raise ValueError(f"expected `gm` >= 0, got {gm if quantity else repr(g)}")
            rr = _as_vector(LENGTH, "r", r, L_UNIT if quantity else None)
            vv = _as_vector(SPEED, "v", v, V_UNIT if quantity else None)
            rad = None
            if radius is not None:
                rad = LENGTH.scalar("radius", radius, L_UNIT if quantity else None)
                if not rad > 0:
                    raise ValueError(
                        f"expected `radius` > 0, got {radius if quantity else repr(rad)}")
            jj = None
            if j2 is not None:
                jj = DIMENSIONLESS.scalar("j2", j2)
            pl = None
            if pole is not None or jj is not None:
                p = np.array([0.0, 0.0, 1.0]) if pole is None else _as_vector(
                    DIMENSIONLESS, "pole", pole, None
                )
                big = float(np.max(np.abs(p)))
                if not big > 0:
                    raise ValueError(f"expected `pole` to be nonzero, got {p.tolist()}")
                p = p / big  # scaled first: no overflow (1e308) nor underflow (1e-320)
                pl = tuple(float(x) for x in p / np.sqrt(p @ p))
        except (ValueError, u.UnitConversionError) as exc:
            msg = str(exc)
            if msg.startswith("Expected"):
                msg = "e" + msg[1:]
            raise type(exc)(f"Body {name!r}: {msg}") from None
        object.__setattr__(self, "name", name)
        object.__setattr__(self, "_gm", float(g))
        rr.setflags(write=False)
        vv.setflags(write=False)
        object.__setattr__(self, "_r", rr)
        object.__setattr__(self, "_v", vv)
        object.__setattr__(self, "_radius", rad)
        object.__setattr__(self, "j2", jj)
        object.__setattr__(self, "pole", pl)
        object.__setattr__(self, "quantity", quantity)

    @property
    def gm(self):
        """G times the mass (au^3/day^2 Quantity, or the caller's float)."""
        return self._gm * GM_UNIT if self.quantity else self._gm

    @property
    def r(self):
        """Position, shape (3,) (au Quantity, or the caller's floats)."""
        return self._r * L_UNIT if self.quantity else self._r.copy()

    @property
    def v(self):
        """Velocity, shape (3,) (au/day Quantity, or the caller's floats)."""
        return self._v * V_UNIT if self.quantity else self._v.copy()

    @property
    def radius(self):
        """Equatorial radius or None (au Quantity, or the caller's float)."""
        if self._radius is None or not self.quantity:
            return self._radius
        return self._radius * L_UNIT

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Body):
            return NotImplemented
        return (
            self.name == other.name and self._gm == other._gm
            and np.array_equal(self._r, other._r) and np.array_equal(self._v, other._v)
            and self._radius == other._radius and self.j2 == other.j2
            and self.pole == other.pole and self.quantity == other.quantity
        )

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        unit = " (au, day)" if self.quantity else ""
        return f"Body({self.name!r}, gm={self._gm!r}{unit})"




def body_from_floats(name, gm, r, v, radius, j2, pole, quantity) -> Body:
    """A :class:`Body` from validated internal floats (no unit conversion, exact values).

    Examples
    --------
    >>> body_from_floats("a", 1.0, [0, 0, 0], [0, 1, 0], None, None, None, False)
    Body('a', gm=1.0)
    """
    obj = object.__new__(Body)
    r = np.array(r, dtype=float)
    v = np.array(v, dtype=float)
    r.setflags(write=False)
    v.setflags(write=False)
    for key, val in (
        ("name", name), ("_gm", float(gm)), ("_r", r), ("_v", v), ("_radius", radius),
        ("j2", j2), ("pole", pole), ("quantity", quantity),
    ):
        object.__setattr__(obj, key, val)
    return obj


def body_arrays(bodies: Sequence[Body]) -> tuple[np.ndarray, ...]:
    """The internal floats of ``bodies`` as the arrays a system holds: ``gm`` (n,),
    ``r``, ``v`` (n, 3), ``radius``, ``j2`` (n,) and ``pole`` (n, 3), NaN where a body
    has none.

    Examples
    --------
    >>> gm, r, v, radius, j2, pole = body_arrays([Body("a", 1.0, [0, 0, 0], [0, 1, 0], j2=1e-3)])
    >>> gm.tolist(), radius.tolist(), j2.tolist(), pole.tolist()
    ([1.0], [nan], [0.001], [[0.0, 0.0, 1.0]])
    """
    return (
        np.array([b._gm for b in bodies]),
        np.array([b._r for b in bodies]).reshape(-1, 3),
        np.array([b._v for b in bodies]).reshape(-1, 3),
        np.array([math.nan if b._radius is None else b._radius for b in bodies]),
        np.array([math.nan if b.j2 is None else b.j2 for b in bodies]),
        np.array([(math.nan,) * 3 if b.pole is None else b.pole
                  for b in bodies]).reshape(-1, 3),
    )
