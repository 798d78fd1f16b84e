"""Scenes: a file says what to simulate and which effects; ``run`` does it.

A scene is a short TOML file (``docs/scenes.md`` documents the format)::

    kind = "nbody"
    description = "Mercury's relativistic perihelion advance"
    duration = "100 yr"
    cadence = "10 d"
    effects = ["gr"]

    [integrator]
    method = "radau15"

    [initial]
    solar_system = { epoch = "J2000", bodies = ["sun", "mercury"] }

    [[analysis]]
    name = "perihelion_advance"
    body = "mercury"

Every key is checked before anything is simulated; every problem is reported
with the file, the key path (``bodies[2].gm``) and, for an unknown name, the
closest valid names.  Only the listed effects are computed.
Scene *kinds* (``nbody``; ``rotation`` from ``rigid``) come from the registry of
:mod:`hamilton_orbits.scenes.base`, which every package (this one too) fills
through the entry-point group ``hamilton_orbits.scene_kinds``, so that
``hamilton_orbits`` never imports them.  This module holds :class:`Scene`,
``SceneError``, the ``effects`` key every kind shares, and the overrides
(:meth:`Scene.with_values`, ``--set KEY=VALUE``).
"""

from __future__ import annotations

import copy
import datetime
import functools
import re
import tomllib
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

from hamilton_orbits import effects as _effects
from hamilton_orbits import schema as S
from hamilton_orbits.effects.parameters import unit_example
from hamilton_orbits.scenes.base import KINDS, registered_kinds
from hamilton_orbits.scenes.result import Result
from hamilton_orbits.units import ANGLE, DIMENSIONLESS
from hamilton_orbits.validation import as_flag

__all__ = ["Scene", "SceneError"]


class SceneError(ValueError):
    """A scene that is not valid; ``problems`` lists every problem found.

    Each problem reads ``file:LINE: key.path: what is wrong`` (``file: key.path:
    ...`` where the key is not in the file).
    """

    def __init__(self, problems: Sequence[str]) -> None:
        self.problems = list(problems)
        n = len(self.problems)
        head = "1 problem" if n == 1 else f"{n} problems"
        super().__init__(f"invalid scene ({head}):\n  " + "\n  ".join(self.problems))


def _effect_entry(effect_kind: str) -> S.Field:
    return _EffectField(effect_kind=effect_kind)


@dataclass
class _EffectField(S.Field):
    """An effect: a registered name, or a table ``{name = "j2", body = "earth"}``.

    A parameter with a dimension (the effect's ``parameter_kinds``: ``c``, a
    speed) is read like any value with a unit (``c = "299792.458 km/s"``; a list,
    such as ``earth_tides``'s time lags ``tau``, value by value); a bare number
    is refused for it (``docs/effects.md``).  A parameter that names a body must
    be a string.
    """

    effect_kind: str = "nbody"

    def check(self, value: Any, path: str, problems: S.Problems) -> Any:
        name, params, found = _effects.entry_problems(value, self.effect_kind)
        for key, message in found:
            problems.add(f"{path}.{key}" if key else path, message)
        if name is None:
            return None
        spec = _effects.get(self.effect_kind, name)
        out = dict(params)
        for key, val in params.items():
            where = f"{path}.{key}"
            if key in spec.parameter_kinds:
                out[key] = _effect_quantity(spec.parameter_kinds[key], val, where, problems)
            elif key in spec.name_parameters:
                out[key] = S.String(nonempty=True).check(val, where, problems)
        return {"name": name, **out}


def _effect_quantity(kind: Any, value: Any, path: str, problems: S.Problems) -> Any:
    """An effect's parameter with a dimension: a value with its unit, or a list of
    them; a bare number is refused, naming the unit it needs (a scene's system is
    in Quantities: ``docs/effects.md``), but for a dimensionless parameter and an
    angle, whose bare number is the effect's own (radians for the Liouville
    pole's ``annual_prograde``) and is passed on as given."""
    items = value if isinstance(value, list) else [value]
    bare = [v for v in items if isinstance(v, int | float) and not isinstance(v, bool)]
    if bare and kind not in (DIMENSIONLESS, ANGLE):
        problems.add(path, f"expected {kind.name} ({kind.unit}) with its unit, e.g. "
                           f"\"{unit_example(kind)}\", got the bare number {bare[0]!r} (a unit "
                           "cannot be guessed)")
        return None
    if kind is ANGLE and len(bare) == len(items):  # (the schema's Quantity would refuse it)
        return value
    field = (S.Vector(kind=kind, size=len(value)) if isinstance(value, list)
             else S.Quantity(kind=kind))
    return field.check(value, path, problems)


def _parse_override(value: str) -> Any:
    try:
        parsed = tomllib.loads(f"x = {value}")["x"]
    except tomllib.TOMLDecodeError:
        return value
    if isinstance(parsed, datetime.date | datetime.time):  # (TOML reads 2000-01-01 as a
        return value.strip()  # date; a scene's epoch is text: "expected a string, got
        # datetime.datetime(2000, 1, 1)" for what was one)
    return parsed


def _override_parts(key: str, source: str) -> list[str | int]:
    """``"bodies[2].gm"`` -> ``["bodies", 2, "gm"]``; an unreadable path is a SceneError."""
    parts: list[str | int] = []
    for piece in key.split("."):
        m = re.fullmatch(r"\s*([^\[\]\s]*)\s*((?:\[[^\[\]]*\]\s*)*)", piece)
        if m is None or not (m.group(1) or m.group(2)):
            raise SceneError([f"{source}: {key}: cannot read the key path (write it as "
                              "integrator.tol, bodies[1].gm or bodies.earth.gm)"])
        if m.group(1):
            parts.append(m.group(1))
        for index in re.findall(r"\[([^\[\]]*)\]", m.group(2)):
            if not index.strip().isdigit():
                raise SceneError([f"{source}: {key}: expected a number in [...], got "
                                  f"[{index}] (a table in a list is addressed by its name: "
                                  "bodies.earth.gm)"])
            parts.append(int(index))
    return parts


def _path_text(parts: Sequence[str | int]) -> str:
    """``("bodies", 1, "gm")`` -> ``"bodies[1].gm"`` (the key paths of problems)."""
    return "".join(f"[{p}]" if isinstance(p, int) else (f".{p}" if k else p)
                   for k, p in enumerate(parts))


def _set_path(data: dict, key: str, value: Any, source: str) -> tuple[str | int, ...]:
    """Set ``key`` ("integrator.tol", "bodies[2].gm", "bodies.mercury.e") in ``data``.

    Returns the path set, with names of tables in lists resolved to indices.

    Raises
    ------
    SceneError
        For a path that cannot be read, an index beyond a list, a name not in a
        list, or a key below a value, naming the key.
    """
    parts = _override_parts(key, source)
    resolved: list[str | int] = []
    node: Any = data

    def fail(message: str) -> SceneError:
        return SceneError([f"{source}: {key}: {message}"])

    for i, part in enumerate(parts):
        where = _path_text(resolved) or "the scene"
        last = i == len(parts) - 1
        if isinstance(node, list):
            if isinstance(part, str):  # a table in a list addressed by its name
                names = [x.get("name") for x in node if isinstance(x, dict)]
                if part not in names:
                    raise fail(f"no entry named {part!r} in {where}"
                               f"{S.closest(part, [str(n) for n in names])}"
                               f"{_initial_note(data, where)}")
                part = names.index(part)
            elif not part < len(node):
                held = (f"{len(node)} entries (indices 0 to {len(node) - 1})" if node
                        else "no entries")
                raise fail(f"{where} has {held}; [{part}] is beyond it (an override "
                           f"changes an entry, it does not add one){_initial_note(data, where)}")
        elif isinstance(node, dict):
            if isinstance(part, int):
                raise fail(f"{where} is a table, not a list: name its key, not [{part}]")
            if not last and part not in node:
                if not resolved and part == "bodies" and isinstance(parts[i + 1], str):
                    # (a scene of no [[bodies]]: "bodies: expected a list, got
                    # {'mercury': {'e': 0.5}}" for the table made here)
                    raise fail(f"no entry named {parts[i + 1]!r} in bodies: the scene has "
                               f"no [[bodies]]{_initial_note(data, 'bodies')}")
                node[part] = [] if isinstance(parts[i + 1], int) else {}
        else:
            raise fail(f"{where} is a value ({node!r}), not a table: it has no key {part!r}")
        resolved.append(part)
        if last:
            node[part] = value
        else:
            node = node[part]
    return tuple(resolved)


#: where an n-body scene's ``[initial]`` takes bodies from, and what of it an override
#: may set (the states themselves are read, not keys)
_INITIAL_KEYS = {
    "solar_system": ("initial.solar_system.epoch", "initial.solar_system.bodies"),
    "ephemeris": ("initial.ephemeris.epoch", "initial.ephemeris.bodies"),
    "rebound": ("initial.rebound", "initial.names"),
}


def _initial_note(data: Mapping[str, Any], where: str) -> str:
    """For an entry of ``bodies`` not found: where the scene's other bodies come
    from (``[initial]``) and what of it may be set; "" for another list or a scene
    whose ``[initial]`` gives no bodies.

    Examples
    --------
    >>> _initial_note({"initial": {"solar_system": {"epoch": "J2000"}}}, "bodies")[:52]
    '; the scene takes bodies from [initial] solar_system'
    >>> _initial_note({"bodies": []}, "bodies")
    ''
    """
    init = data.get("initial")
    if where != "bodies" or not isinstance(init, Mapping):
        return ""
    given = [k for k in _INITIAL_KEYS if init.get(k) is not None]
    if not given:
        return ""
    keys = " or ".join(key for k in given for key in _INITIAL_KEYS[k])
    return (f"; the scene takes bodies from [initial] {' and '.join(given)}, whose "
            f"states are read, not set by key: set {keys}, or give the body as a "
            f"[[bodies]] entry of a scene file (a primary and its elements) and leave it "
            f"out of [initial]")


def _with_values(data: Mapping[str, Any], source: str, values: Mapping[str, Any],
                 overrides: Sequence[tuple]) -> tuple[dict, list[tuple]]:
    """A copy of ``data`` with ``values`` set at their key paths, and the key paths set."""
    if not isinstance(values, Mapping):
        raise SceneError([f"{source}: expected the values as a mapping "
                          f"{{'key.path': value}}, got {values!r}"])
    data = copy.deepcopy(dict(data))
    overrides = list(overrides)
    for key, value in values.items():
        if not isinstance(key, str):
            raise SceneError([f"{source}: expected a key path such as "
                              f"'integrator.tol', got {key!r}"])
        v = _parse_override(value) if isinstance(value, str) else value
        overrides.append(_set_path(data, key, v, source))
    return data, overrides


class _Recorded(S.Problems):
    """Problems with their key paths; true while ``earlier`` holds, so that a kind's
    check does not build the system from keys that were refused."""

    def __init__(self, source: str, locate, earlier: bool) -> None:
        super().__init__(source, locate)
        self.paths: list[str] = []
        self.earlier = earlier

    def add(self, path: str, message: str) -> None:
        self.paths.append(path)
        super().add(path, message)

    def __bool__(self) -> bool:
        return self.earlier or bool(self.items)


def _written(data: dict, path: str) -> Any:
    """The value at key ``path`` of a scene's mapping as written (None if absent)."""
    node: Any = data
    try:
        for part in S.split_path(path):
            node = node[part]
    except (KeyError, IndexError, TypeError):
        return None
    return node


def _related(a: str, b: str) -> bool:
    """One key path is the other or under it (``bodies[1]`` and ``bodies[1].gm``)."""
    short, long = sorted((a, b), key=len)
    return long == short or long.startswith((short + ".", short + "[")) or not short


def _cross_key_problems(kind: Any, spec: dict, problems: S.Problems) -> None:
    """Add the problems across keys of a spec whose keys on their own already have
    ``problems`` (their paths recorded): those not about a refused key (which reads as
    missing in ``spec``), as far as the refused keys let the checks run."""
    refused = list(getattr(problems, "paths", ()))
    cross = _Recorded(problems.source, problems.locate, earlier=True)
    cross.written = problems.written
    try:
        kind.check(spec, cross)
    except (TypeError, AttributeError, KeyError, ValueError):
        pass  # a check that needs a refused key: what it found before stays
    for path, item in zip(cross.paths, cross.items, strict=True):
        if not any(_related(path, r) for r in refused):
            problems.items.append(item)


class Scene:
    """A validated description of one study.

    Build one with :meth:`from_toml`, :meth:`bundled` or :meth:`from_dict`;
    nothing is simulated until :meth:`run`.  Every problem of an invalid scene is
    reported at once (``SceneError``), as ``file:LINE: key.path: message``
    (the line where the file sets the key; none for a key the file leaves out,
    for a value set by :meth:`with_values`, or for a scene from a mapping).

    Examples
    --------
    >>> scene = Scene.bundled("mercury-gr")
    >>> scene.kind, [e["name"] for e in scene.effects]
    ('nbody', ['gr'])
    >>> Scene.from_dict({"kind": "nbody", "duraton": "1 yr"})  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    hamilton_orbits.scenes.scene.SceneError: invalid scene (...):
      <dict>: duraton: unknown key (did you mean 'duration'...?)
      ...
    """

    def __init__(self, data: Mapping[str, Any], source: str = "<dict>", *,
                 text: str | None = None, overrides: Sequence[tuple] = ()) -> None:
        if not isinstance(data, Mapping):
            raise SceneError([f"{source}: expected a mapping shaped like a scene file "
                              f"(kind, duration, ...), got {data!r}"])
        self.source = source
        self.data = copy.deepcopy(dict(data))
        # the file's text (for the lines of keys) and the key paths set since (no line)
        self._text = text
        self._overrides = tuple(overrides)
        self.spec = self._validate(self.data)

    @property
    def changed(self) -> dict[str, Any]:
        """The keys set since the scene's file or mapping (``--set KEY=VALUE``,
        :meth:`with_values`), ``{"key.path": value}``, in the order set (the
        ``description`` is the file's: it does not follow them).

        Examples
        --------
        >>> Scene.bundled("dzhanibekov").with_values({"duration": "40 s"}).changed
        {'duration': '40 s'}
        """
        out: dict[str, Any] = {}
        for path in self._overrides:
            node: Any = self.data
            try:
                for part in path:
                    node = node[part]
            except (KeyError, IndexError, TypeError):  # (a later value of a key above it
                continue  # replaced it: that one is listed)
            out[_path_text(path)] = node
        return out

    # --- construction -------------------------------------------------
    @classmethod
    def from_dict(cls, data: Mapping[str, Any], source: str = "<dict>") -> Scene:
        """A scene from a mapping shaped like the TOML file.

        Raises
        ------
        SceneError
            For anything but a mapping, or any invalid key.
        """
        return cls(data, source)

    @classmethod
    def from_toml(cls, path: str | Path, values: Mapping[str, Any] | None = None) -> Scene:
        """Read and validate a scene file (``values``: keys replaced first, as
        :meth:`with_values` does, the scene then checked once: a value the file gets
        wrong may be set right).

        Raises
        ------
        SceneError
            For a missing file, a TOML syntax error (with the line), or any
            invalid key, naming the file.
        """
        p = Path(path)
        try:
            text = p.read_text(encoding="utf-8")
        except OSError as exc:
            raise SceneError([f"{p}: cannot read the scene file ({exc.strerror})"]) from exc
        except UnicodeDecodeError as exc:
            raise SceneError([f"{p}: not a scene file: not text in UTF-8 (byte "
                              f"{exc.object[exc.start]:#04x} at offset {exc.start})"]) from None
        return cls.from_text(text, str(p), values)

    @classmethod
    def from_text(cls, text: str, source: str,
                  values: Mapping[str, Any] | None = None) -> Scene:
        r"""A scene from the text of a scene file (``source``: the file, for messages;
        ``values``: keys replaced before the scene is checked, as in :meth:`from_toml`).
        A leading byte-order mark (U+FEFF) is skipped.

        Raises
        ------
        SceneError
            For a TOML syntax error (with the line) or any invalid key.

        Examples
        --------
        >>> text = "\n".join(['kind = "rotation"', 'duration = "60 s"', 'cadence = "1 s"',
        ...                   '[body]', 'moments = ["1 kg m2", "2 kg m2", "3 kg m2"]',
        ...                   'omega = ["0.001 rad/s", "2 rad/s", "0.001 rad/s"]',
        ...                   '[integrator]', 'dt = "1 ms"'])
        >>> scene = Scene.from_text(text, "mine.toml")
        >>> scene.kind, scene.source
        ('rotation', 'mine.toml')
        """
        # a byte-order mark (an editor's "UTF-8 with BOM") is no TOML: it was "Invalid
        # statement (at line 1, column 1)"; read past it, as utf-8-sig does
        text = text[1:] if text.startswith("\ufeff") else text
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise SceneError([f"{source}: TOML syntax error: {exc}"]) from exc
        return cls._checked(data, source, text, values)

    @classmethod
    def _checked(cls, data: dict, source: str, text: str,
                 values: Mapping[str, Any] | None) -> Scene:
        """The scene of ``data`` (read from ``text``) with ``values`` replaced, checked
        once."""
        if not values:
            return cls(data, source, text=text)
        data, overrides = _with_values(data, source, values, ())
        return cls(data, source, text=text, overrides=overrides)

    @staticmethod
    def _bundled_dir():
        return resources.files("hamilton_orbits") / "data" / "scenes"

    @classmethod
    def bundled(cls, name: str, values: Mapping[str, Any] | None = None) -> Scene:
        """One of the scenes that ship with the package (see :meth:`list_bundled`;
        ``values`` as in :meth:`from_toml`)."""
        names = [n for n, _ in cls.list_bundled()]
        if not isinstance(name, str):  # (None went into difflib: a TypeError)
            raise SceneError([f"{name!r}: expected a bundled scene's name (a string), one of "
                              f"{', '.join(names)}"])
        if name not in names:
            raise SceneError([f"{name}: no bundled scene of that name{S.closest(name, names)}"])
        res = cls._bundled_dir() / f"{name}.toml"
        text = res.read_text(encoding="utf-8")
        return cls._checked(tomllib.loads(text), f"{name}.toml", text, values)

    @classmethod
    def list_bundled(cls) -> list[tuple[str, str]]:
        """The bundled scenes: ``(name, one-line description)``, sorted by name.

        Examples
        --------
        >>> "solar-system" in dict(Scene.list_bundled())
        True
        """
        out = []
        for res in cls._bundled_dir().iterdir():
            if res.name.endswith(".toml"):
                data = tomllib.loads(res.read_text(encoding="utf-8"))
                out.append((res.name[:-5], str(data.get("description", "")).split("\n")[0]))
        return sorted(out)

    def with_values(self, values: Mapping[str, Any]) -> Scene:
        """A copy with some keys replaced: ``{"integrator.tol": 1e-10}``.

        String values are read as TOML values where they parse (``"1e-10"`` is
        a number, ``"100 yr"`` stays a string), as ``--set KEY=VALUE`` does.

        Raises
        ------
        SceneError
            For a key path that cannot be read or does not lead to a key (an
            index beyond a list, a name not in it, a key below a value), or an
            invalid scene, naming the key.
        """
        data, overrides = _with_values(self.data, self.source, values, self._overrides)
        return Scene(data, self.source, text=self._text, overrides=overrides)

    @classmethod
    def from_values(cls, data: Mapping[str, Any], source: str,
                    values: Mapping[str, Any]) -> Scene:
        """The scene of ``data`` with some keys replaced, checked once (what
        ``Scene(data, source).with_values(values)`` gives, without checking the
        scene of ``data`` first: an ensemble's member).

        Examples
        --------
        >>> base = Scene.bundled("dzhanibekov")
        >>> Scene.from_values(base.data, base.source, {"duration": "40 s"}).spec["duration"]
        <Quantity 40. s>
        """
        data, overrides = _with_values(data, source, values, ())
        return cls(data, source, overrides=overrides)

    def _locate(self):
        """``path -> line`` in the scene's file (None for keys set since, or no file)."""
        if self._text is None:
            return None
        lines = S.key_lines(self._text)
        overrides = self._overrides

        def locate(path: str) -> int | None:
            parts = S.split_path(path)
            if any(parts[:len(o)] == o for o in overrides):
                return None
            while parts:
                if parts in lines:
                    return lines[parts]
                parts = parts[:-1]
            return None

        return locate

    # --- validation ---------------------------------------------------
    def _validate(self, data: dict) -> dict:
        problems = _Recorded(self.source, self._locate(), earlier=False)
        problems.written = functools.partial(_written, data)
        kinds = registered_kinds()
        kind_name = data.get("kind")
        if kind_name is None:
            problems.add("kind", f"missing: one of {', '.join(map(repr, sorted(kinds)))}")
            raise SceneError(problems.items)
        if not isinstance(kind_name, str):
            problems.add("kind", f"expected a string, one of "
                                 f"{', '.join(map(repr, sorted(kinds)))}, got {kind_name!r}")
            raise SceneError(problems.items)
        if kind_name not in kinds:
            problems.add("kind", f"unknown kind {kind_name!r}{S.closest(str(kind_name), kinds)}")
            raise SceneError(problems.items)
        kind = kinds[kind_name]
        schema = S.Table(
            fields={
                "kind": S.String(required=True),
                "description": S.String(default=""),
                "runtime": S.String(default=""),
                "effects": S.Array(item=_effect_entry(kind.effect_kind), default=[]),
                **kind.schema,
            }
        )
        spec = schema.check(data, "", problems)
        first: dict[str, int] = {}
        listed = [(k, e) for k, e in enumerate(spec.get("effects") or []) if e is not None]
        for k, effect in listed:  # (None: refused above)
            if effect["name"] in first:
                problems.add(f"effects[{k}]", f"effect {effect['name']!r} is listed twice "
                                              f"(first at effects[{first[effect['name']]}])")
            first.setdefault(effect["name"], k)
        names = [effect["name"] for _, effect in listed]
        for j, message in _effects.exclusion_problems(names, kind.effect_kind):
            problems.add(f"effects[{listed[j][0]}]", message)
        if problems:  # the keys together too, where the keys on their own allow it
            _cross_key_problems(kind, spec, problems)
            raise SceneError(problems.items)
        kind.check(spec, problems)
        if problems:
            raise SceneError(problems.items)
        return spec

    # --- what it is ---------------------------------------------------
    @property
    def kind(self) -> str:
        """The scene's kind (``"nbody"``, ``"rotation"``)."""
        return self.spec["kind"]

    @property
    def name(self) -> str:
        """The scene's name: its file name without ``.toml``."""
        return Path(self.source).name.removesuffix(".toml")

    @property
    def effects(self) -> tuple[dict, ...]:
        """Exactly what will be computed besides the kind's base model, as mappings."""
        return tuple(self.spec["effects"])

    def __repr__(self) -> str:
        names = ", ".join(e["name"] for e in self.effects) or "none"
        return f"Scene({self.name!r}, kind={self.kind!r}, effects=[{names}])"

    # --- running ------------------------------------------------------
    def run(self, progress: bool = True, stop: Callable[[], bool] | None = None,
            archive: str | Path | None = None) -> Result:
        """Simulate the scene; returns a :class:`Result`.

        ``archive``: the folder of the archive an ``nbody`` scene with ``[output]
        archive_every`` writes while it runs; when it holds a killed run's
        snapshots, the run is resumed from the last one (``docs/archive.md``).

        ``result.compile_time`` holds the seconds numba spent compiling kernels
        for the run (the first run on a machine; 0 once they are cached): during
        the run, and before it, since the previous run in the process, when the
        kernels' modules were imported; ``result.compile_count`` how many
        compilations, ``result.compiled`` which, with their seconds.  The kinds
        take the compilation inside the integration out of ``result.wall_time``,
        the integration proper.
        """
        from hamilton_orbits.firstrun import claim_compilation, last_claim

        extra = {} if archive is None else {"archive": archive}
        progress = as_flag("progress", progress)  # (every kind's, before it builds anything)
        result = KINDS[self.kind].run(self, progress=progress, stop=stop or (lambda: False),
                                      **extra)
        result.compile_time, result.compile_count = claim_compilation()
        result.compiled = last_claim()
        return result

    def crosscheck(self) -> str:
        """The same scene in a peer code, the differences tabled (text)."""
        kind = KINDS[self.kind]
        if kind.crosscheck is None:
            return f"{self.name}: no peer code to cross-check a {self.kind} scene against"
        return kind.crosscheck(self)
