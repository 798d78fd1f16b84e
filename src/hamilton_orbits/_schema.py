"""A small schema language for scene files, with messages in the user's terms.

A scene file is TOML; its schema is a tree of :class:`Field` objects.  Validation
walks the file and the schema together and collects *every* problem, each as
``file: key.path: what is wrong`` with, for an unknown name, the closest valid
names.  Values with units are strings such as ``"1.2 au"`` and are converted to
astropy Quantities of the dimension the key expects.

Nothing here knows about orbits or rigid bodies: scene kinds declare their
schema with these fields (``hamilton_orbits.scene``).
"""

from __future__ import annotations

import difflib
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import astropy.units as u

from hamilton_orbits.units import Kind

__all__ = [
    "Array",
    "Bool",
    "Choice",
    "Field",
    "Number",
    "Problems",
    "Quantity",
    "String",
    "Table",
    "Vector",
    "closest",
]


def closest(name: str, valid: Sequence[str]) -> str:
    """A hint naming the valid names closest to ``name`` (or all, if few).

    Examples
    --------
    >>> closest("duraton", ["duration", "cadence", "effects"])
    " (did you mean 'duration'?)"
    """
    near = difflib.get_close_matches(name, list(valid), n=3, cutoff=0.5)
    if near:
        return " (did you mean " + " or ".join(repr(n) for n in near) + "?)"
    if valid:
        return " (valid: " + ", ".join(repr(v) for v in valid) + ")"
    return ""


class Problems:
    """The problems found in one file, each with its key path."""

    def __init__(self, source: str) -> None:
        self.source = source
        self.items: list[str] = []

    def add(self, path: str, message: str) -> None:
        where = f"{self.source}: {path}" if path else self.source
        self.items.append(f"{where}: {message}")

    def __bool__(self) -> bool:
        return bool(self.items)


def _join(path: str, key: str | int) -> str:
    if isinstance(key, int):
        return f"{path}[{key}]"
    return f"{path}.{key}" if path else key


@dataclass
class Field:
    """Base class: one key of a scene file.

    ``required`` keys must be present; otherwise ``default`` is used.
    """

    doc: str = ""
    required: bool = False
    default: Any = None

    def check(self, value: Any, path: str, problems: Problems) -> Any:  # pragma: no cover
        raise NotImplementedError

    def type_name(self) -> str:  # pragma: no cover - overridden
        return "a value"


@dataclass
class String(Field):
    """A string."""

    def check(self, value: Any, path: str, problems: Problems) -> Any:
        if not isinstance(value, str):
            problems.add(path, f"expected a string, got {value!r}")
            return None
        return value

    def type_name(self) -> str:
        return "a string"


@dataclass
class Bool(Field):
    """true or false."""

    def check(self, value: Any, path: str, problems: Problems) -> Any:
        if not isinstance(value, bool):
            problems.add(path, f"expected true or false, got {value!r}")
            return None
        return value

    def type_name(self) -> str:
        return "true or false"


@dataclass
class Choice(Field):
    """One of a set of names (given, or computed when the file is read)."""

    choices: Sequence[str] | Callable[[], Sequence[str]] = ()

    def names(self) -> list[str]:
        c = self.choices() if callable(self.choices) else self.choices
        return list(c)

    def check(self, value: Any, path: str, problems: Problems) -> Any:
        names = self.names()
        if not isinstance(value, str) or value not in names:
            problems.add(path, f"unknown value {value!r}{closest(str(value), names)}")
            return None
        return value

    def type_name(self) -> str:
        return "one of " + ", ".join(repr(n) for n in self.names())


@dataclass
class Number(Field):
    """A plain number, optionally bounded."""

    minimum: float | None = None
    positive: bool = False
    integer: bool = False

    def check(self, value: Any, path: str, problems: Problems) -> Any:
        if isinstance(value, bool) or not isinstance(value, int | float):
            problems.add(path, f"expected {self.type_name()}, got {value!r}")
            return None
        if self.integer and not isinstance(value, int):
            problems.add(path, f"expected an integer, got {value!r}")
            return None
        if value != value or value in (float("inf"), float("-inf")):
            problems.add(path, f"expected a finite number, got {value!r}")
            return None
        if self.positive and not value > 0:
            problems.add(path, f"expected a number > 0, got {value!r}")
            return None
        if self.minimum is not None and value < self.minimum:
            problems.add(path, f"expected a number >= {self.minimum}, got {value!r}")
            return None
        return value

    def type_name(self) -> str:
        return "an integer" if self.integer else "a number"


@dataclass
class Quantity(Field):
    """A value with a unit, written ``"1.2 au"`` (or a bare number if ``kind`` allows).

    Parameters
    ----------
    kind : hamilton_orbits.units.Kind
        The dimension expected (LENGTH, TIME, ...).
    positive : bool
        Require a value > 0.
    """

    kind: Kind | None = None
    positive: bool = False

    def check(self, value: Any, path: str, problems: Problems) -> Any:
        assert self.kind is not None
        if isinstance(value, bool):
            problems.add(path, f"expected {self.type_name()}, got {value!r}")
            return None
        if isinstance(value, int | float):
            if self.kind.unit == u.dimensionless_unscaled:
                q = value * self.kind.unit
            else:
                problems.add(
                    path,
                    f"expected {self.type_name()} with its unit, e.g. "
                    f'"{value} {self.kind.unit}", got the bare number {value!r}',
                )
                return None
        elif isinstance(value, str):
            try:
                q = u.Quantity(value)
            except (ValueError, TypeError):
                problems.add(path, f"cannot read {value!r} as a number with a unit")
                return None
        else:
            problems.add(path, f"expected {self.type_name()}, got {value!r}")
            return None
        try:
            number = self.kind(path, q)
        except u.UnitConversionError:
            problems.add(
                path,
                f"expected {self.kind.name} (a unit convertible to {self.kind.unit}), "
                f"got {value!r}",
            )
            return None
        except ValueError as exc:
            problems.add(path, str(exc))
            return None
        if self.positive and not float(number) > 0:
            problems.add(path, f"expected a value > 0, got {value!r}")
            return None
        return q

    def type_name(self) -> str:
        assert self.kind is not None
        return f"{self.kind.name} ({self.kind.unit})"


@dataclass
class Vector(Field):
    """Three values with units, ``["1 au", "0 au", "0 au"]``."""

    kind: Kind | None = None
    size: int = 3

    def check(self, value: Any, path: str, problems: Problems) -> Any:
        if not isinstance(value, list) or len(value) != self.size:
            problems.add(path, f"expected a list of {self.size} values, got {value!r}")
            return None
        item = Quantity(kind=self.kind)
        before = len(problems.items)
        parts = [item.check(v, _join(path, i), problems) for i, v in enumerate(value)]
        if len(problems.items) > before:
            return None
        unit = parts[0].unit
        return u.Quantity([p.to_value(unit) for p in parts], unit)

    def type_name(self) -> str:
        return f"a list of {self.size} values"


@dataclass
class Array(Field):
    """A list whose items all follow one field."""

    item: Field | None = None
    name_key: str | None = None  # items are tables addressed by this key in overrides

    def check(self, value: Any, path: str, problems: Problems) -> Any:
        assert self.item is not None
        if not isinstance(value, list):
            problems.add(path, f"expected a list, got {value!r}")
            return None
        return [self.item.check(v, _join(path, i), problems) for i, v in enumerate(value)]

    def type_name(self) -> str:
        return "a list"


@dataclass
class Table(Field):
    """A table with known keys; unknown keys are errors with suggestions."""

    fields: Mapping[str, Field] = field(default_factory=dict)
    open: bool = False  # accept unknown keys as they are (effect parameters)

    def check(self, value: Any, path: str, problems: Problems) -> Any:
        if not isinstance(value, Mapping):
            problems.add(path, f"expected a table, got {value!r}")
            return None
        out: dict[str, Any] = {}
        for key, sub in value.items():
            if key not in self.fields:
                if self.open:
                    out[key] = sub
                    continue
                problems.add(_join(path, key), f"unknown key{closest(key, list(self.fields))}")
                continue
            out[key] = self.fields[key].check(sub, _join(path, key), problems)
        for key, f in self.fields.items():
            if key in value:
                continue
            if f.required:
                problems.add(_join(path, key), f"missing: {f.type_name()} is required")
            elif f.default is not None:
                out[key] = f.check(f.default, _join(path, key), problems)
            else:
                out[key] = None
        return out

    def type_name(self) -> str:
        return "a table"
