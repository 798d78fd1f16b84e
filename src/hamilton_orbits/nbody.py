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

Where the rest lives: :class:`Body` in :mod:`hamilton_orbits._body` (imported here, its
documented path); the constructors from others' states (:meth:`System.solar_system`,
:meth:`System.from_ephemeris`, :meth:`System.from_rebound`) and the solar system's
tables in :mod:`hamilton_orbits.initial_states`; how well a run keeps (C), (D), (E)
in :mod:`hamilton_orbits.integrals`.

References
----------
W. R. Hamilton, "On the application of the method of quaternions to some dynamical
questions", Proc. R. Irish Acad. 3 (1847), Appendix, pp. xxxvi-l: equations (A)-(E).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from typing import Any, NamedTuple

import astropy.units as u
import numpy as np

from hamilton_orbits._body import (
    A_UNIT,
    AU,
    DAY,
    E_SI,
    G_SI,
    GM_UNIT,
    L_SI,
    L_UNIT,
    V_UNIT,
    Body,
    body_arrays,
    body_from_floats,
)
from hamilton_orbits.deprecation import moved_name
from hamilton_orbits.initial_states import InitialStates, names_repr
from hamilton_orbits.integrals import energy_gm
from hamilton_orbits.integrators import _setup
from hamilton_orbits.units import DIMENSIONLESS, GM, LENGTH, SPEED, require_consistent
from hamilton_orbits.validation import as_float_array, check_finite

__all__ = ["Body", "System", "SystemArrays"]

_ = AU, DAY  # the internal units of Quantity systems (hamilton_orbits._body), here too


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


class System(InitialStates):
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
        if isinstance(bodies, Body) or not isinstance(bodies, Iterable):
            raise ValueError(f"Expected `bodies` to be a list of Body objects, got {bodies!r}")
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
            g = G_SI
        else:
            g = 1.0 if G is None else DIMENSIONLESS.scalar("G", G)
            if not g > 0:
                raise ValueError(f"Expected `G` > 0, got {G!r}")
        self._set_arrays(
            tuple(b.name for b in bodies), seen, quantity, g, *body_arrays(bodies),
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
            Finite radii > 0, NaN for none.
        G : float, optional
            For a plain-float system, as in :class:`System`.

        Raises
        ------
        ValueError
            Naming the argument and index: non-finite values (an infinite
            ``radius``), wrong shapes, negative ``gm``, no body, no massive body, duplicate
            names, two bodies at one position; a mix of Quantities and floats.

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
        if n == 0:  # (it spoke of massless bodies that were not there)
            raise ValueError("Expected `gm`, `r` and `v` to hold at least one body, got none "
                             "(shape (0,))")
        if not np.any(gm_a > 0):
            raise ValueError("Expected at least one body with `gm` > 0, got only massless bodies")
        rad = np.full(n, math.nan)
        if radius is not None:
            rad = np.array(LENGTH("radius", radius, L_UNIT if quantity else None, finite=False),
                           dtype=np.float64)
            if rad.shape != (n,):
                raise ValueError(f"Expected `radius` to have shape ({n},), got {rad.shape}")
            check_positive("radius", np.where(np.isnan(rad), 1.0, rad))
            check_finite("radius", rad[~np.isnan(rad)], np.flatnonzero(~np.isnan(rad)))
        if isinstance(names, str):  # (its letters would be the names, one a body)
            raise ValueError(f"Expected `names` to be {n} non-empty strings, got the one "
                             f"string {names!r} (one body's name is a list of one: "
                             f"[{names!r}])")
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
        g = G_SI if quantity else (1.0 if G is None else DIMENSIONLESS.scalar("G", G))
        if not g > 0:
            raise ValueError(f"Expected `G` > 0, got {G!r}")
        out = object.__new__(cls)
        nan3 = np.full((n, 3), math.nan)
        out._set_arrays(names_t, index, quantity, g, gm_a.copy(), arrays[0], arrays[1], rad,
                        np.full(n, math.nan), nan3, None)
        out._check_positions()
        return out

    @classmethod
    def from_system_arrays(cls, arrays: SystemArrays) -> System:
        """The system of :meth:`as_arrays`' fields, bit for bit (the inverse of
        :meth:`as_arrays`; a saved simulation is rebuilt from it).

        Examples
        --------
        >>> s = System([Body("a", 1.0, [0, 0, 0], [0, 0, 0], radius=0.5, j2=1e-3),
        ...             Body("b", 0.0, [1, 0, 0], [0, 1, 0])])
        >>> again = System.from_system_arrays(s.as_arrays())
        >>> again.names, again["a"].j2, bool(np.array_equal(again.as_arrays().r, s.r))
        (('a', 'b'), 0.001, True)
        """
        names = tuple(str(x) for x in arrays.names)
        n = len(names)
        fields = [np.array(x, dtype=np.float64) for x in (arrays.gm, arrays.r, arrays.v,
                                                           arrays.radius, arrays.j2,
                                                           arrays.pole)]
        shapes = [(n,), (n, 3), (n, 3), (n,), (n,), (n, 3)]
        labels = ("gm", "r", "v", "radius", "j2", "pole")
        for name, arr, shape in zip(labels, fields, shapes, strict=True):
            if arr.shape != shape:
                raise ValueError(f"Expected `{name}` to have shape {shape}, got {arr.shape}")
        index = {name: k for k, name in enumerate(names)}
        if len(index) != n:
            raise ValueError(f"Expected unique body names, got {names!r}")
        out = object.__new__(cls)
        out._set_arrays(names, index, bool(arrays.quantity), float(arrays.G), *fields, None)
        out._check_state()
        return out

    # ------------------------------------------------------------------ checks
    def _check_positions(self) -> None:
        """Refuse two bodies (one of them massive) at one position, or so close that
        the cube of their separation underflows float64 (the force would be
        infinite or undefined): :func:`hamilton_orbits.integrators._setup.check_apart`."""
        _setup.check_apart(self._r, self._gm, self.names)

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
        return body_from_floats(
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
        return f"System({names_repr(self.names)}{', au/day' if self._quantity else ''})"

    def with_state(self, r: np.ndarray, v: np.ndarray, gm: np.ndarray | None = None,
                   keep: np.ndarray | None = None, *, check: bool = True,
                   radius: np.ndarray | None = None) -> System:
        """The same bodies at internal-unit positions ``r`` and velocities ``v`` (n, 3);
        with ``gm`` (n,) their new ``G m`` and ``radius`` (n,) their new radii (after
        merges), and with the boolean ``keep`` (n,) only the bodies it marks (after
        removals).

        Units: a Quantity is converted (a system of Quantities only); plain numbers
        are the internal units, which for a system of Quantities are au, au/day and
        au^3/day^2 (the integrators hand their states back so), beside Quantities
        too: each argument is read on its own.

        The new system shares the names, radii, J2 and poles (read-only arrays) and
        copies the state once: no :class:`Body` object is made until one is asked
        for.  ``check=False`` skips the checks of the state (finite, shapes, no two
        bodies at one position), for a state an integrator has just produced.

        Raises
        ------
        ValueError
            For a non-finite or ill-shaped ``r``, ``v`` or ``gm``, a negative
            ``gm``, no massive body left, or two bodies (one of them massive) at
            one position; as :meth:`from_arrays`, for a list holding Quantities
            (``u.Quantity(...)`` joins it), bools, text, masked values, and a
            radius that is not NaN (none) or > 0.

        Examples
        --------
        >>> s = System([Body("a", 1.0, [0, 0, 0], [0, 0, 0])])
        >>> s.with_state(np.ones((1, 3)), np.zeros((1, 3))).r
        array([[1., 1., 1.]])
        >>> s.with_state(np.ones((2, 3)), np.zeros((2, 3)))
        Traceback (most recent call last):
        ...
        ValueError: Expected `r` to have shape (1, 3), got (2, 3)
        >>> s.with_state(np.ones((1, 3)), np.zeros((1, 3)), gm=[-1.0])
        Traceback (most recent call last):
        ...
        ValueError: Expected `gm` >= 0, got -1.0 at index 0
        """
        out = object.__new__(System)
        r = self._internal("r", r, LENGTH, L_UNIT, check)
        v = self._internal("v", v, SPEED, V_UNIT, check)
        gm = self._gm if gm is None else self._internal("gm", gm, GM, GM_UNIT, check)
        if check and gm.shape != self._gm.shape:
            raise ValueError(f"Expected `gm` to have shape {self._gm.shape}, got {gm.shape}")
        radius = self._radius if radius is None else self._internal("radius", radius, LENGTH,
                                                                      L_UNIT, check)
        if check:
            self._check_new(radius, keep)
        arrays = (gm, r, v, radius, self._j2, self._pole)
        names, index = self._names, self._index
        if keep is not None and not np.all(keep):
            keep = np.asarray(keep, dtype=bool)
            arrays = tuple(np.ascontiguousarray(a[keep]) for a in arrays)
            names, index = tuple(n for n, k in zip(names, keep, strict=True) if k), None
        out._set_arrays(names, index, self._quantity, self._G, *arrays, None)
        if check:
            out._check_state()
        return out

    def _internal(self, name: str, value: Any, kind: Any, unit: Any,
                  check: bool = True) -> np.ndarray:
        """``value`` of :meth:`with_state` in the internal units, a copy: a Quantity
        converted (for a system of Quantities; refused for one of plain numbers, whose
        units are the caller's own), plain numbers as they are.  ``check``: refused
        as :func:`~hamilton_orbits.validation.as_float_array` refuses (a list holding
        Quantities, whose units would be dropped; bools, text, masked values);
        otherwise an integrator's own arrays, copied."""
        if isinstance(value, u.Quantity):
            if not self._quantity:
                raise ValueError(f"Expected `{name}` as plain numbers in this system's own "
                                 f"units (it was built from plain numbers), got {value!r}")
            return np.array(kind(name, value, unit, finite=False), dtype=np.float64)
        if check:
            return np.array(as_float_array(name, value, finite=False), dtype=np.float64)
        return np.array(value, dtype=np.float64)

    def _check_new(self, radius: np.ndarray, keep: Any) -> None:
        """:meth:`with_state`'s ``radius`` (n,), each NaN (none) or finite and > 0,
        and ``keep``, None or n booleans."""
        from hamilton_orbits.validation import check_positive

        n = len(self._names)
        if radius.shape != (n,):
            raise ValueError(f"Expected `radius` to have shape ({n},), got {radius.shape}")
        check_positive("radius", np.where(np.isnan(radius), 1.0, radius))  # (as a Body's)
        check_finite("radius", radius[~np.isnan(radius)], np.flatnonzero(~np.isnan(radius)))
        if keep is not None and np.shape(keep) != (n,):
            raise ValueError(f"Expected `keep` to have shape ({n},), got {np.shape(keep)}")
        if keep is not None and np.asarray(keep).dtype != np.bool_:  # (indices 0, 1 were
            # read as False, True: another body kept than the one meant)
            raise ValueError(f"Expected `keep` to be {n} booleans (True for a body kept), "
                             f"got {np.asarray(keep).tolist()!r}")
        if keep is not None and not np.any(keep):
            raise ValueError(f"Expected `keep` to keep at least one body, got {n} False")

    def _check_state(self) -> None:
        from hamilton_orbits.validation import check_positive

        n = len(self._names)
        check_finite("gm", self._gm)
        check_positive("gm", self._gm, strict=False)
        if n == 0:  # (it spoke of massless bodies that were not there)
            raise ValueError("Expected at least one body, got none")
        if not np.any(self._gm > 0):
            raise ValueError("Expected at least one body with `gm` > 0, got only massless bodies")
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
    def accelerations(self, effects: Sequence[str | Mapping[str, Any]] = (), t: Any = 0.0):
        """Accelerations of every body by equation (B), plus the listed effects.

        Parameters
        ----------
        effects : sequence of str or mapping, optional
            Effects as for :func:`hamilton_orbits.integrate` (``"gr"``, ...).
        t : Quantity, TimeDelta or float
            The time of this state, one number, for the effects that know it
            (``zonal`` with ``pole="IAU2006"``, ...): 0 at the simulation's start.
            For a Quantity system a time Quantity or a TimeDelta (a bare number is
            refused but for the default 0); for a system of plain floats a float in
            the system's own unit (a Quantity or a TimeDelta is refused, as
            :func:`~hamilton_orbits.integrate` refuses it: that unit is not known).

        Returns
        -------
        ndarray or Quantity, shape (n, 3)
            au/day^2 for Quantity systems.

        Raises
        ------
        ValueError
            For a ``t`` of the wrong kind for the system (above), not one number,
            not finite, or of the wrong dimension (astropy's UnitConversionError),
            naming ``t`` and the value; for an effect whose acceleration is not
            finite in this state (a body on the Kuiper ring), naming the effect, its
            index, the body and the cause (``hamilton_orbits.rhs.refuse_nonfinite``).

        Examples
        --------
        >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
        ...             Body("dust", 0.0, [2.0, 0, 0], [0, 0.7, 0])])
        >>> s.accelerations()
        array([[ 0.  ,  0.  ,  0.  ],
               [-0.25,  0.  ,  0.  ]])
        """
        from hamilton_orbits.rhs import compile_rhs, refuse_nonfinite
        from hamilton_orbits.units import TIME, is_quantity, time_quantity

        given = t
        t = time_quantity(t)  # (a TimeDelta: the Quantity in days it holds)
        if not self._quantity and is_quantity(t):
            raise ValueError(f"Expected `t` as a plain float for a system of plain floats "
                             f"(its time unit is the caller's own), got {given!r}")
        days = TIME.scalar("t", t, "d" if self._quantity else None)  # (refuses inf, NaN)
        if self._quantity and not is_quantity(t) and days != 0:
            raise ValueError(f"Expected `t` as a time Quantity for a system of Quantities, "
                             f"got {t!r}")
        acc = compile_rhs(self, effects).acceleration(self._r, self._v, self._gm, t=days)
        refuse_nonfinite(self, effects, acc, self._r, self._v, self._gm, days)
        if not np.isfinite(acc).all():  # (no effect's: the bodies' own)
            k = int(np.argmax(~np.isfinite(acc).all(axis=1)))
            raise ValueError(f"The acceleration of body {self.names[k]!r} (index {k}) is not "
                             f"finite: two bodies at one position?")
        return acc * A_UNIT if self._quantity else acc

    def _energy_hamilton(self) -> float:
        """Hamilton's vis viva form (E): Sigma gm v^2 / 2 - Sigma gm gm' / r (G E)."""
        return float(energy_gm(self._r, self._v, self._gm))

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
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            e = self._energy_hamilton()
            e = e * E_SI if self._quantity else e / self._G
        self._representable("energy", e)
        return e * u.J if self._quantity else e

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
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            h = self._angular_momentum_hamilton()
            h = h * L_SI if self._quantity else h / self._G
        self._representable("angular momentum", h)
        return h * (u.kg * u.m**2 / u.s) if self._quantity else h

    def _representable(self, what: str, value: Any) -> None:
        """Refuse an integral of the state beyond float64 (its terms overflowed)."""
        if not np.all(np.isfinite(value)):
            raise ValueError(f"Expected a state whose {what} is within float64, got {value} "
                             f"(positions, velocities or gm too large, or G too small)")

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


# the names that moved out of this module, and where to
_MOVED = {
    **dict.fromkeys(("DEFAULT_BODIES", "SOLAR_SYSTEM_GM", "SOLAR_SYSTEM_SPAN",
                     "solar_system_bodies", "solar_system_epoch"),
                    "hamilton_orbits.initial_states"),
    **dict.fromkeys(("LostStateError", "accelerations_quaternion", "energy_gm_many",
                     "integral_errors"), "hamilton_orbits.integrals"),
}


def __getattr__(name: str) -> Any:
    """The names that moved out (a DeprecationWarning naming their new module)."""
    return moved_name(__name__, _MOVED, name)
