"""The methods as typed values that check themselves: :class:`Radau15`, :class:`WH`,
:class:`Leapfrog`, :class:`DOP853`.

A method and its options are one frozen value, checked when it is made (as
poliastro's propagators and heyoka's integrator objects are), so that a
:class:`~hamilton_orbits.Simulation` validates them once and its drivers trust
them::

    Simulation(system, method=WH(coordinates="jacobi", corrector=11), dt=0.01)
    Simulation(system, method="wh", coordinates="jacobi", corrector=11, dt=0.01)  # the same

The string form with keyword options keeps working: ``method_of`` turns it
into the typed value (an option the method does not take is refused, naming the
options it does take).  The step ``dt`` and the tolerance ``tol`` are not part of
the method: every method takes them, in the system's units.

Nothing here imports a kernel: making a method costs microseconds.
"""

from __future__ import annotations

import dataclasses
import numbers
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

__all__ = ["CRITERIA", "DOP853", "FIXED_STEP", "INTEGRATORS", "METHODS", "PRECISIONS",
           "RADAU15_TOL_FLOOR", "WH", "WH_COORDINATES", "WH_CORRECTORS", "Leapfrog", "Method",
           "Radau15", "check_run", "method_of"]

#: The methods, in the order they are listed to users.
INTEGRATORS = ("radau15", "wh", "leapfrog", "dop853")
#: The methods of a fixed step: ``dt``, or a ``tol`` that chooses it (not both).
FIXED_STEP = ("wh", "leapfrog")
#: radau15's step-size criteria: ``"global"`` (Rein & Spiegel 2015, section 3.2) and
#: ``"prs23"`` (Pham, Rein & Spiegel 2024, IAS15's default since rebound 4).
CRITERIA = ("global", "prs23")
#: radau15's arithmetics.
PRECISIONS = ("double", "double-double")
#: wh's splittings.
WH_COORDINATES = ("democratic_heliocentric", "jacobi")
#: The orders of ``wh``'s symplectic correctors (Jacobi coordinates; 0: none).
WH_CORRECTORS = (0, 3, 5, 7, 11, 17)
#: Default limit on the steps of one call of radau15 (minutes to an hour of work).
MAX_STEPS = 100_000_000
#: Default limit on the steps of one call of a fixed-step method (refused up front).
MAX_FIXED_STEPS = 1_000_000_000
#: radau15's smallest ``tol`` (float64's rounding): below it a tolerance buys no
#: accuracy, only shorter steps (1e-30: 36 497 steps of an orbit of 39 at the default,
#: 1e-40 260 000 of a 2-day orbit, 1e-60 underflowed); refused by :func:`check_run`.
RADAU15_TOL_FLOOR = 1e-16


def _choice(name: str, value: Any, allowed: tuple) -> None:
    if not isinstance(value, str) or value not in allowed:
        raise ValueError(f"Expected `{name}` to be one of {', '.join(map(repr, allowed))}, "
                         f"got {value!r}")


def _flag(name: str, value: Any) -> None:
    if not isinstance(value, bool):
        raise ValueError(f"Expected `{name}` to be True or False, got {value!r}")


def _count(name: str, value: Any) -> None:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < 1:
        raise ValueError(f"Expected `{name}` to be a positive integer, got {value!r}")


@dataclass(frozen=True)
class Method:
    """What every method value has: its ``name`` and its options as a mapping."""

    name: ClassVar[str] = ""
    #: True if the method accepts velocity-dependent effects (symplectic maps do not).
    accepts_velocity_dependent: ClassVar[bool] = True
    #: True if the method takes an effect that replaces Newtonian gravity (``wh``, which
    #: splits Newtonian gravity into its own Kepler drifts and kicks, does not).
    accepts_newtonian_replaced: ClassVar[bool] = True

    def options(self) -> dict[str, Any]:
        """The options as keyword arguments (field name -> value)."""
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}

    def __str__(self) -> str:
        return self.name


@dataclass(frozen=True)
class Radau15(Method):
    """The adaptive 15th-order Gauss-Radau integrator (IAS15-like;
    :mod:`hamilton_orbits.integrators.radau15`).

    Parameters
    ----------
    max_steps : int
        Give up (``ConvergenceError``) after this many steps in one call, or as soon
        as the pace projects more than 100 times as many.
    criterion : {"prs23", "global"}
        The step-size control (Pham, Rein & Spiegel 2024; or Rein & Spiegel 2015,
        section 3.2).
    tangent_control : bool
        With ``variational=True``: let the tangent vectors take part in the step
        control.
    precision : {"double", "double-double"}
        ``"double-double"``: fixed steps in about 32 digits (references).

    Examples
    --------
    >>> Radau15(criterion="global")
    Radau15(max_steps=100000000, criterion='global', tangent_control=False, precision='double')
    >>> Radau15(criterion="bogus")
    Traceback (most recent call last):
    ...
    ValueError: Expected `criterion` to be one of 'global', 'prs23', got 'bogus'
    """

    name: ClassVar[str] = "radau15"
    max_steps: int = MAX_STEPS
    criterion: str = "prs23"
    tangent_control: bool = False
    precision: str = "double"

    def __post_init__(self) -> None:
        _choice("criterion", self.criterion, CRITERIA)
        _count("max_steps", self.max_steps)
        _flag("tangent_control", self.tangent_control)
        _choice("precision", self.precision, PRECISIONS)


@dataclass(frozen=True)
class WH(Method):
    """The Wisdom-Holman map (:mod:`hamilton_orbits.integrators.wh`).

    Parameters
    ----------
    coordinates : {"democratic_heliocentric", "jacobi"}
        The splitting (Duncan, Levison & Lee 1998; Wisdom & Holman 1991); ``"Jacobi"``
        and other capitalisations are read as the lower-case name.
    corrector : {0, 3, 5, 7, 11, 17}
        With Jacobi coordinates, the symplectic corrector of that order (Wisdom,
        Holman & Touma 1996).
    max_steps : int
        A bound on the steps of one call, refused before it starts.

    Examples
    --------
    >>> WH(coordinates="Jacobi", corrector=11).coordinates
    'jacobi'
    >>> WH(corrector=3)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Expected coordinates='jacobi' with `corrector` = 3, got 'democratic_heliocentric'...
    """

    name: ClassVar[str] = "wh"
    accepts_velocity_dependent: ClassVar[bool] = False
    accepts_newtonian_replaced: ClassVar[bool] = False
    coordinates: str = "democratic_heliocentric"
    corrector: int = 0
    max_steps: int = MAX_FIXED_STEPS

    def __post_init__(self) -> None:
        if isinstance(self.coordinates, str) and self.coordinates.lower() in WH_COORDINATES:
            object.__setattr__(self, "coordinates", self.coordinates.lower())
        _choice("coordinates", self.coordinates, WH_COORDINATES)
        c = self.corrector
        if isinstance(c, bool) or not isinstance(c, numbers.Integral) or c not in WH_CORRECTORS:
            raise ValueError(f"Expected `corrector` to be one of "
                             f"{', '.join(map(str, WH_CORRECTORS))}, got {c!r}")
        object.__setattr__(self, "corrector", int(c))
        if c and self.coordinates != "jacobi":
            raise ValueError(
                f"Expected coordinates='jacobi' with `corrector` = {c}, got "
                f"{self.coordinates!r} (the correctors are defined for the Jacobi splitting)")
        _count("max_steps", self.max_steps)

    @property
    def jacobi(self) -> bool:
        """True for Jacobi coordinates."""
        return self.coordinates == "jacobi"


@dataclass(frozen=True)
class Leapfrog(Method):
    """Drift-kick-drift leapfrog (:mod:`hamilton_orbits.integrators.leapfrog`).

    Parameters
    ----------
    max_steps : int
        A bound on the steps of one call, refused before it starts.

    Examples
    --------
    >>> Leapfrog().options()
    {'max_steps': 1000000000}
    """

    name: ClassVar[str] = "leapfrog"
    accepts_velocity_dependent: ClassVar[bool] = False
    max_steps: int = MAX_FIXED_STEPS

    def __post_init__(self) -> None:
        _count("max_steps", self.max_steps)


@dataclass(frozen=True)
class DOP853(Method):
    """scipy's DOP853 (:mod:`hamilton_orbits.integrators.dop853`).

    Parameters
    ----------
    max_steps : int
        Give up (``ConvergenceError``) after this many steps in one call, or as soon
        as the pace projects more than 100 times as many (scipy's solver has no
        budget of its own: a run of far too many steps would never end).
    tangent_control : bool
        With ``variational=True``: let the tangent vectors take part in the error
        control.

    Examples
    --------
    >>> DOP853(tangent_control="no")
    Traceback (most recent call last):
    ...
    ValueError: Expected `tangent_control` to be True or False, got 'no'
    """

    name: ClassVar[str] = "dop853"
    tangent_control: bool = False
    max_steps: int = MAX_STEPS

    def __post_init__(self) -> None:
        _flag("tangent_control", self.tangent_control)
        _count("max_steps", self.max_steps)


#: Method name -> its typed value's class.
METHODS: dict[str, type[Method]] = {m.name: m for m in (Radau15, WH, Leapfrog, DOP853)}
_DEFAULTS = {name: cls() for name, cls in METHODS.items()}


def method_of(method: Any, options: Mapping[str, Any] | None = None) -> Method:
    """The typed method of ``method`` (a name or a ``Method``) and ``options``.

    Raises
    ------
    ValueError
        For an unknown method, an option the method does not take (listing those
        it takes), options beside a typed value, or a bad option value.

    Examples
    --------
    >>> method_of("wh", {"coordinates": "jacobi"})
    WH(coordinates='jacobi', corrector=0, max_steps=1000000000)
    >>> method_of("leapfrog", {"corrector": 3})
    Traceback (most recent call last):
    ...
    ValueError: Unknown option `corrector` = 3 for method 'leapfrog'; it takes: max_steps
    >>> method_of("rk4")
    Traceback (most recent call last):
    ...
    ValueError: Unknown `method` 'rk4'; known: radau15, wh, leapfrog, dop853
    """
    if not options and isinstance(method, str) and method in _DEFAULTS:
        return _DEFAULTS[method]  # the common case: a name alone (the values are frozen)
    options = dict(options or {})
    if isinstance(method, Method):
        if options:
            raise ValueError(f"Options {', '.join(options)} given beside the method value "
                             f"{method!r}: give them to it instead")
        return method
    cls = METHODS.get(method) if isinstance(method, str) else None
    if cls is None:
        raise ValueError(f"Unknown `method` {method!r}; known: {', '.join(INTEGRATORS)}")
    takes = [f.name for f in dataclasses.fields(cls)]
    for key, value in options.items():
        if key not in takes:
            raise ValueError(
                f"Unknown option `{key}` = {value!r} for method {method!r}; it takes: "
                + (", ".join(takes) if takes else "no options beyond dt and tol"))
    return cls(**options)


def check_run(method: Method, dt: Any, tol: Any, variational: bool) -> None:
    """The refusals of a run's set-up that depend on nothing but its options: made by
    the drivers as they start, and by ``Simulation`` as it is made (an archived one
    would otherwise make its folder before the first call refused it).

    Examples
    --------
    >>> check_run(Leapfrog(), None, None, False)
    Traceback (most recent call last):
    ...
    ValueError: leapfrog needs a step `dt` or a tolerance `tol`, got neither
    >>> check_run(Radau15(), None, 1e-30, False)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Expected radau15's `tol` >= 1e-16 (float64's rounding), got 1e-30: ...
    """
    if method.name == "leapfrog" and dt is None and tol is None:
        raise ValueError("leapfrog needs a step `dt` or a tolerance `tol`, got neither")
    if method.name == "wh" and method.corrector and variational:
        raise ValueError("wh with variational=True takes no `corrector` (its tangent map "
                         "is not implemented); use corrector=0")
    if method.name == "radau15" and method.precision == "double-double" and (
            dt is None or tol is not None):
        raise ValueError("radau15 in double-double runs fixed steps: give `dt` and no "
                         f"`tol`, got dt = {dt!r}, tol = {tol!r}")
    if method.name == "radau15" and tol is not None and float(tol) < RADAU15_TOL_FLOOR:
        raise ValueError(f"Expected radau15's `tol` >= {RADAU15_TOL_FLOOR} (float64's "
                         f"rounding), got {tol!r}: below it a tolerance buys no accuracy, only "
                         "shorter steps (tol=1e-30: 36 497 steps of an orbit of 39 at the "
                         "default, its error no smaller)")

