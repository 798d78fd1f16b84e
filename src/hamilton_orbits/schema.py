"""A small schema language for scene files, with messages in the user's terms.

A scene file is TOML; its schema is a tree of :class:`Field` objects.  Validation
walks the file and the schema together and collects *every* problem, each as
``file: key.path: what is wrong`` with, for an unknown name, the closest valid
names.  Values with units are strings such as ``"1.2 au"`` and are converted to
astropy Quantities of the dimension the key expects.

Nothing here knows about orbits or rigid bodies: scene kinds declare their
schema with these fields (``hamilton_orbits.scene``).

Public: both packages' scene kinds declare their schemas with it.
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import astropy.units as u

from hamilton_orbits.units import Kind, time_quantity

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
    "key_lines",
    "split_path",
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
    """The problems found in one file, each with its key path and, where the
    value comes from the file, its line: ``file:LINE: key.path: message``.

    Parameters
    ----------
    source : str
        The file (or ``<dict>``).
    locate : callable, optional
        ``locate(path) -> line or None``: the line of a key path in the file.
    """

    def __init__(self, source: str,
                 locate: Callable[[str], int | None] | None = None) -> None:
        self.source = source
        self.locate = locate
        self.items: list[str] = []
        #: ``written(path) -> value``: the value of a key path as the file (or an
        #: override) writes it, None where unknown (set by the scene)
        self.written: Callable[[str], Any] | None = None

    def quoted(self, path: str, value: Any) -> str:
        """``value`` (the key ``path``'s, as read) quoted as the file writes it: the
        file's text where it is a string (``'7000 km'``, not ``7000.0 km``), else
        ``str(value)``."""
        raw = None if self.written is None else self.written(path)
        return repr(raw) if isinstance(raw, str) else str(value)

    def add(self, path: str, message: str) -> None:
        line = self.locate(path) if (self.locate is not None and path) else None
        file = self.source if line is None else f"{self.source}:{line}"
        where = f"{file}: {path}" if path else file
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
    """A string (``nonempty``: with something in it besides blanks)."""

    nonempty: bool = False

    def check(self, value: Any, path: str, problems: Problems) -> Any:
        if not isinstance(value, str):
            problems.add(path, f"expected a string, got {value!r}")
            return None
        if self.nonempty and not value.strip():
            problems.add(path, f"expected a non-empty string, got {value!r}")
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
    #: an exclusive upper bound (a tolerance: below 1)
    below: float | None = None

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
        if self.below is not None and not value < self.below:
            problems.add(path, f"expected a number < {self.below}, got {value!r}")
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
    nonnegative : bool
        Require a value >= 0.
    nonzero : bool
        Require a value other than 0.

    Messages quote the value as the file gives it (``'-1 km3/s2'``), not in an
    internal unit.  A scene built in Python may give a Quantity, or an astropy
    TimeDelta: the time Quantity in days it holds
    (:func:`~hamilton_orbits.units.time_quantity`), checked as that Quantity.
    """

    kind: Kind | None = None
    positive: bool = False
    nonnegative: bool = False
    nonzero: bool = False

    def check(self, value: Any, path: str, problems: Problems) -> Any:
        assert self.kind is not None
        value = time_quantity(value)  # (a TimeDelta: the Quantity in days it holds)
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
        elif isinstance(value, u.Quantity):  # a scene built in Python (from_dict)
            q = value
        else:
            problems.add(path, f"expected {self.type_name()}, got {value!r}")
            return None
        try:
            number = self.kind(path, q)
        except u.UnitConversionError:
            wanted = ("a dimensionless number" if self.kind.unit == u.dimensionless_unscaled
                      else f"{self.kind.name} (a unit convertible to {self.kind.unit})")
            problems.add(path, f"expected {wanted}, got {value!r}")
            return None
        except ValueError as exc:
            text = str(exc)
            if isinstance(value, str) and "to be finite, got" in text:  # (quoted as the
                # file writes it: "1e400 yr" was "got inf")
                text = f"{text.partition(', got ')[0]}, got {value!r}"
            problems.add(path, text)
            return None
        if number.shape != ():
            problems.add(path, f"expected one value, got {value!r}")
            return None
        for wanted, ok, text in ((self.positive, float(number) > 0, "a value > 0"),
                                 (self.nonnegative, float(number) >= 0, "a value >= 0"),
                                 (self.nonzero, float(number) != 0, "a nonzero value")):
            if wanted and not ok:
                problems.add(path, f"expected {text}, got {value!r}")
                return None
        return q

    def type_name(self) -> str:
        assert self.kind is not None
        return f"{self.kind.name} ({self.kind.unit})"


@dataclass
class Vector(Field):
    """Three values with units, ``["1 au", "0 au", "0 au"]`` (``nonzero``: not all 0)."""

    kind: Kind | None = None
    size: int = 3
    nonzero: bool = False

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
        out = u.Quantity([p.to_value(unit) for p in parts], unit)
        if self.nonzero and not (out.value != 0).any():
            problems.add(path, f"expected a nonzero direction, got {value!r}")
            return None
        return out

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


# --- where a key is in the file -------------------------------------------------------

_TOKEN = re.compile(
    r"""(?P<comment>\#[^\n]*)
      | (?P<ml>\"\"\"(?:.|\n)*?\"\"\"|\'\'\'(?:.|\n)*?\'\'\')
      | (?P<str>"(?:\\.|[^"\\\n])*"|'[^'\n]*')
      | (?P<nl>\n)
      | (?P<ws>[ \t\r]+)
      | (?P<punct>[\[\]{}=,.])
      | (?P<bare>[A-Za-z0-9_+\-:]+(?:\.[A-Za-z0-9_+\-:]+)*)""",
    re.VERBOSE,
)


def split_path(path: str) -> tuple[str | int, ...]:
    """A key path as its components: ``"bodies[1].pole[2]"`` -> ``("bodies", 1, "pole", 2)``.

    Examples
    --------
    >>> split_path("initial.solar_system.bodies[3]")
    ('initial', 'solar_system', 'bodies', 3)
    """
    out: list[str | int] = []
    for name, index in re.findall(r"([^.\[\]]+)|\[(\d+)\]", path):
        out.append(int(index) if index else name)
    return tuple(out)


class _Lines:
    """A pass over a TOML text (already known to parse) recording the line of every
    key path: keys, tables, array items, keys in inline tables."""

    def __init__(self, text: str) -> None:
        self.toks: list[tuple[str, str, int]] = []
        line = 1
        for m in _TOKEN.finditer(text):
            kind = m.lastgroup or ""
            if kind not in ("comment", "ws"):
                self.toks.append((kind, m.group(), line))
            line += m.group().count("\n")
        self.toks.append(("end", "", line))
        self.pos = 0
        self.lines: dict[tuple, int] = {}

    def _peek(self) -> tuple[str, str, int]:
        return self.toks[self.pos]

    def _skip_newlines(self) -> None:
        while self._peek()[0] == "nl":
            self.pos += 1

    def _key(self) -> tuple[str, ...]:
        parts: list[str] = []
        while True:
            kind, text, _ = self._peek()
            if kind == "bare":
                parts += text.split(".")
            elif kind == "str":
                parts.append(text[1:-1])
            elif text != ".":
                return tuple(parts)
            self.pos += 1

    def _value(self, path: tuple) -> None:
        kind, text, _ = self._peek()
        if text in ("[", "{"):
            self.pos += 1
            close, index = ("]" if text == "[" else "}"), 0
            while True:
                self._skip_newlines()
                kind, text, line = self._peek()
                if text == close or kind == "end":
                    self.pos += 1
                    return
                if close == "]":
                    self.lines.setdefault((*path, index), line)
                    self._value((*path, index))
                    index += 1
                else:
                    sub = (*path, *self._key())
                    self.lines.setdefault(sub, line)
                    self.pos += 1  # "="
                    self._value(sub)
                self._skip_newlines()
                if self._peek()[1] == ",":
                    self.pos += 1
        self.pos += 1
        while self._peek()[0] == "bare":  # a date and a time: "1979-05-27 07:32:00"
            self.pos += 1

    def run(self) -> dict[tuple, int]:
        table: tuple = ()
        counts: dict[tuple, int] = {}
        while self._peek()[0] != "end":
            kind, text, line = self._peek()
            if kind == "nl":
                self.pos += 1
            elif text == "[":
                double = self.toks[self.pos + 1][1] == "["
                self.pos += 2 if double else 1
                name = self._key()
                self.pos += 2 if double else 1
                if double:
                    counts[name] = counts.get(name, -1) + 1
                    table = (*name, counts[name])
                else:
                    table = name
                self.lines.setdefault(table, line)
            else:
                path = (*table, *self._key())
                self.lines.setdefault(path, line)
                self.pos += 1  # "="
                self._value(path)
        return self.lines


def key_lines(text: str) -> dict[tuple, int]:
    r"""The line of every key path of a TOML text (components as :func:`split_path`).

    TOML's parser gives no lines; this reads the text once more.  A text it
    cannot follow gives what it found until then.

    Examples
    --------
    >>> lines = key_lines('kind = "nbody"\n[[bodies]]\nname = "a"\n[[bodies]]\n'
    ...                   'name = "b"\ngm = "1 km3/s2"\neffects = [{ name = "gr" }]\n')
    >>> lines[("bodies", 1, "gm")], lines[("bodies", 1)], lines[("bodies", 1, "effects", 0)]
    (6, 4, 7)
    """
    reader = _Lines(text)
    try:
        reader.run()
    except IndexError:  # a text beyond this reader: keep what it found
        pass
    return reader.lines
