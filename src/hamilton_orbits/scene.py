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

Scene *kinds* (``nbody`` here; ``rotation`` from ``rigid``) are registered in
:data:`KINDS`; other packages add theirs through the entry-point group
``hamilton_orbits.scene_kinds`` so that ``hamilton_orbits`` never imports them.
"""

from __future__ import annotations

import copy
import json
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

import astropy.units as u
import numpy as np
import tomllib

from hamilton_orbits import _schema as S
from hamilton_orbits import effects as _effects

__all__ = ["KINDS", "Result", "Scene", "SceneError", "SceneKind", "register_kind"]


class SceneError(ValueError):
    """A scene that is not valid; ``problems`` lists every problem found.

    Each problem reads ``file: key.path: what is wrong``.
    """

    def __init__(self, problems: Sequence[str]) -> None:
        self.problems = list(problems)
        n = len(self.problems)
        head = "1 problem" if n == 1 else f"{n} problems"
        super().__init__(f"invalid scene ({head}):\n  " + "\n  ".join(self.problems))


@dataclass(frozen=True)
class SceneKind:
    """A kind of scene: its keys, its checks across keys, and how it runs.

    Parameters
    ----------
    name : str
        The ``kind = "..."`` value.
    summary : str
        One line for listings.
    schema : Mapping[str, _schema.Field]
        The kind's keys (besides ``kind``, ``description`` and ``effects``).
    effect_kind : str
        Which effect registry the kind's ``effects`` come from.
    check : callable
        ``check(spec, problems)``: checks across keys (a body an effect names
        exists, the integrator accepts the effects), adding to ``problems``.
    run : callable
        ``run(scene, progress, stop) -> Result``; ``stop()`` is true once the
        user asked to stop (Ctrl-C): the run ends early and keeps what it has.
    crosscheck : callable or None
        ``crosscheck(scene) -> str``: the same scene in a peer code, tabled.
    """

    name: str
    summary: str
    schema: Mapping[str, S.Field]
    effect_kind: str
    check: Callable[[dict, S.Problems], None]
    run: Callable[..., Result]
    crosscheck: Callable[[Scene], str] | None = None


KINDS: dict[str, SceneKind] = {}
_KIND_ENTRY_POINTS_LOADED = False


def register_kind(kind: SceneKind) -> SceneKind:
    """Register a scene kind (``rigid`` registers ``rotation`` through an entry point)."""
    KINDS[kind.name] = kind
    return kind


def _kinds() -> dict[str, SceneKind]:
    global _KIND_ENTRY_POINTS_LOADED
    if not _KIND_ENTRY_POINTS_LOADED:
        _KIND_ENTRY_POINTS_LOADED = True
        from importlib.metadata import entry_points

        from hamilton_orbits import _scene_nbody  # noqa: F401  (registers "nbody")

        for ep in entry_points(group="hamilton_orbits.scene_kinds"):
            ep.load()()
    return KINDS


def _effect_entry(effect_kind: str) -> S.Field:
    return _EffectField(effect_kind=effect_kind)


@dataclass
class _EffectField(S.Field):
    """An effect: a registered name, or a table ``{name = "j2", body = "earth"}``."""

    effect_kind: str = "nbody"

    def check(self, value: Any, path: str, problems: S.Problems) -> Any:
        if isinstance(value, str):
            value = {"name": value}
        if not isinstance(value, Mapping) or not isinstance(value.get("name"), str):
            problems.add(path, f'expected an effect name or a table with a "name", got {value!r}')
            return None
        name = value["name"]
        known = _effects.known(self.effect_kind)
        if name not in known:
            problems.add(f"{path}.name", f"unknown effect {name!r}{S.closest(name, known)}")
            return None
        spec = _effects.get(self.effect_kind, name)
        params = {k: v for k, v in value.items() if k != "name"}
        for key in params:
            if key not in spec.parameters:
                hint = S.closest(key, list(spec.parameters))
                problems.add(f"{path}.{key}", f"unknown parameter of effect {name!r}{hint}")
        return {"name": name, **params}


def _parse_override(value: str) -> Any:
    try:
        return tomllib.loads(f"x = {value}")["x"]
    except tomllib.TOMLDecodeError:
        return value


def _set_path(data: dict, key: str, value: Any, source: str) -> None:
    """Set ``key`` ("integrator.tol", "bodies[2].gm", "bodies.mercury.e") in ``data``."""
    parts: list[str | int] = []
    for piece in key.split("."):
        while "[" in piece and piece.endswith("]"):
            head, _, idx = piece.partition("[")
            if head:
                parts.append(head)
            parts.append(int(idx.split("]")[0]))
            piece = piece[piece.index("]") + 1 :]
        if piece:
            parts.append(piece)
    node: Any = data
    for i, part in enumerate(parts[:-1]):
        nxt = parts[i + 1]
        if isinstance(node, list):
            if isinstance(part, str):  # a table in a list addressed by its name
                match = [x for x in node if isinstance(x, dict) and x.get("name") == part]
                if not match:
                    names = [x.get("name", "?") for x in node if isinstance(x, dict)]
                    where = ".".join(str(p) for p in parts[:i])
                    raise SceneError(
                        [f"{source}: {key}: no entry named {part!r} in {where}"
                         f"{S.closest(part, names)}"]
                    )
                node = match[0]
            else:
                node = node[part]
        else:
            node = node.setdefault(part, [] if isinstance(nxt, int) else {})
    last = parts[-1]
    if isinstance(node, list) and isinstance(last, int):
        node[last] = value
    else:
        node[last] = value


class Scene:
    """A validated description of one study.

    Build one with :meth:`from_toml`, :meth:`bundled` or :meth:`from_dict`;
    nothing is simulated until :meth:`run`.

    Examples
    --------
    >>> scene = Scene.bundled("mercury-gr")
    >>> scene.kind, [e["name"] for e in scene.effects]
    ('nbody', ['gr'])
    >>> Scene.from_dict({"kind": "nbody", "duraton": "1 yr"})  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    hamilton_orbits.scene.SceneError: invalid scene (...):
      <dict>: duraton: unknown key (did you mean 'duration'...?)
      ...
    """

    def __init__(self, data: Mapping[str, Any], source: str = "<dict>") -> None:
        self.source = source
        self.data = copy.deepcopy(dict(data))
        self.spec = self._validate(self.data)

    # --- construction -------------------------------------------------
    @classmethod
    def from_dict(cls, data: Mapping[str, Any], source: str = "<dict>") -> Scene:
        """A scene from a mapping shaped like the TOML file."""
        return cls(data, source)

    @classmethod
    def from_toml(cls, path: str | Path) -> Scene:
        """Read and validate a scene file.

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
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise SceneError([f"{p}: TOML syntax error: {exc}"]) from exc
        return cls(data, str(p))

    @staticmethod
    def _bundled_dir():
        return resources.files("hamilton_orbits") / "data" / "scenes"

    @classmethod
    def bundled(cls, name: str) -> Scene:
        """One of the scenes that ship with the package (see :meth:`list_bundled`)."""
        names = [n for n, _ in cls.list_bundled()]
        if name not in names:
            raise SceneError([f"{name}: no bundled scene of that name{S.closest(name, names)}"])
        res = cls._bundled_dir() / f"{name}.toml"
        data = tomllib.loads(res.read_text(encoding="utf-8"))
        return cls(data, f"{name}.toml")

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
        """
        data = copy.deepcopy(self.data)
        for key, value in values.items():
            v = _parse_override(value) if isinstance(value, str) else value
            _set_path(data, key, v, self.source)
        return Scene(data, self.source)

    # --- validation ---------------------------------------------------
    def _validate(self, data: dict) -> dict:
        problems = S.Problems(self.source)
        kinds = _kinds()
        kind_name = data.get("kind")
        if kind_name is None:
            problems.add("kind", f"missing: one of {', '.join(map(repr, sorted(kinds)))}")
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
        if not problems:
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
    def run(self, progress: bool = True, stop: Callable[[], bool] | None = None) -> Result:
        """Simulate the scene; returns a :class:`Result`."""
        return KINDS[self.kind].run(self, progress=progress, stop=stop or (lambda: False))

    def crosscheck(self) -> str:
        """The same scene in a peer code, the differences tabled (text)."""
        kind = KINDS[self.kind]
        if kind.crosscheck is None:
            return f"{self.name}: no peer code to cross-check a {self.kind} scene against"
        return kind.crosscheck(self)


def _fmt(value: Any) -> str:
    if isinstance(value, u.Quantity):
        if value.isscalar:
            return f"{value.value:.6g} {value.unit:unicode}".strip()
        return str(value)
    if isinstance(value, float):
        return f"{value:.6g}"
    return str(value)


def format_table(rows: Sequence[Mapping[str, Any]]) -> str:
    """An aligned text table of ``rows`` (dicts with the same keys).

    Examples
    --------
    >>> print(format_table([{"body": "sun", "dr": 1e-12}, {"body": "earth", "dr": 2.5e-10}]))
    body   dr
    -----  -------
    sun    1e-12
    earth  2.5e-10
    """
    if not rows:
        return ""
    keys = list(rows[0])
    cells = [[_fmt(r.get(k, "")) for k in keys] for r in rows]
    widths = [max(len(k), *(len(c[i]) for c in cells)) for i, k in enumerate(keys)]
    lines = ["  ".join(k.ljust(w) for k, w in zip(keys, widths, strict=True)).rstrip()]
    lines.append("  ".join("-" * w for w in widths))
    for c in cells:
        lines.append("  ".join(x.ljust(w) for x, w in zip(c, widths, strict=True)).rstrip())
    return "\n".join(lines)


@dataclass
class Result:
    """What a scene's run produced.

    Attributes
    ----------
    scene : Scene
    times : Quantity
        The output times.
    diagnostics : dict
        Named series on ``times`` (energy error, angular-momentum error, ...).
    metrics : dict
        Headline numbers (Quantities or floats), e.g. the perihelion advance.
    tables : dict
        Named tables (lists of row dicts), e.g. the per-body cross-check.
    states : dict
        Arrays to save (``names``, ``r``, ``v`` for n-body scenes).
    wall_time : float
        Seconds the simulation took.
    complete : bool
        False if the run was stopped early (Ctrl-C); what was done is kept.
    """

    scene: Scene
    times: u.Quantity
    diagnostics: dict[str, Any] = field(default_factory=dict)
    metrics: dict[str, Any] = field(default_factory=dict)
    tables: dict[str, list[dict]] = field(default_factory=dict)
    states: dict[str, Any] = field(default_factory=dict)
    wall_time: float = 0.0
    complete: bool = True
    plotters: list[Callable[[Result], Any]] = field(default_factory=list, repr=False)
    writers: list[Callable[[Result, Path], list[Path]]] = field(default_factory=list,
                                                                repr=False)

    def summary(self) -> str:
        """The summary table as text (what the command prints)."""
        s = self.scene
        lines = [f"scene {s.name} ({s.kind}): {s.spec.get('description', '').strip()}"]
        effects = ", ".join(e["name"] for e in s.effects) or "none"
        lines.append(f"effects: {effects}")
        if not self.complete:
            lines.append("STOPPED EARLY: the results cover the part that was run")
        span = self.times[-1] - self.times[0] if len(self.times) else 0 * u.d
        asked = s.spec.get("duration")
        if isinstance(asked, u.Quantity) and asked.unit.physical_type == "time":
            span = span.to(asked.unit)
        elif span > 1 * u.yr:
            span = span.to(u.yr)
        lines.append(f"simulated: {_fmt(span)} in {self.wall_time:.2f} s")
        if self.metrics:
            lines.append("")
            rows = [{"quantity": k, "value": v} for k, v in self.metrics.items()]
            lines.append(format_table(rows))
        for title, rows in self.tables.items():
            lines.append("")
            lines.append(title)
            lines.append(format_table(rows))
        return "\n".join(lines)

    def plot(self) -> list:
        """The scene's figures (matplotlib), one per plotter."""
        try:
            import matplotlib

            matplotlib.use("Agg", force=False)
        except ImportError as exc:  # pragma: no cover - depends on the install
            raise ImportError(
                "figures need matplotlib: python -m pip install 'hamilton-orbits[plot]'"
            ) from exc
        return [p(self) for p in self.plotters]

    def _json(self) -> dict:
        def conv(v: Any) -> Any:
            if isinstance(v, u.Quantity):
                return {"value": v.value.tolist(), "unit": str(v.unit)}
            if isinstance(v, np.ndarray):
                return v.tolist()
            if isinstance(v, float) and not math.isfinite(v):
                return str(v)
            if isinstance(v, np.floating | np.integer):
                return v.item()
            return v

        return {
            "scene": self.scene.name,
            "kind": self.scene.kind,
            "description": self.scene.spec.get("description", ""),
            "effects": [dict(e) for e in self.scene.effects],
            "complete": self.complete,
            "wall_time_s": self.wall_time,
            "metrics": {k: conv(v) for k, v in self.metrics.items()},
            "tables": {k: [{c: conv(x) for c, x in r.items()} for r in rows]
                       for k, rows in self.tables.items()},
        }

    def save(self, directory: str | Path) -> list[Path]:
        """Write the summary (Markdown, JSON), the figures (PNG) and the states (netCDF).

        A scene kind may add files (n-body scenes: the final state as a rebound
        binary, ``final.bin``).  Returns the paths written.  The states file is
        netCDF-3 (scipy's writer), which xarray, netCDF4 and ``ncdump`` read.
        """
        out = Path(directory)
        out.mkdir(parents=True, exist_ok=True)
        written = []
        md = out / "summary.md"
        md.write_text(f"# {self.scene.name}\n\n```\n{self.summary()}\n```\n", encoding="utf-8")
        written.append(md)
        js = out / "summary.json"
        js.write_text(json.dumps(self._json(), indent=2) + "\n", encoding="utf-8")
        written.append(js)
        if self.plotters:
            import matplotlib.pyplot as plt

            for i, fig in enumerate(self.plot()):
                name = getattr(fig, "_hamilton_name", f"figure{i + 1}")
                path = out / f"{name}.png"
                fig.savefig(path, dpi=110, bbox_inches="tight")
                plt.close(fig)
                written.append(path)
        written.extend(self._save_states(out))
        for writer in self.writers:
            written.extend(writer(self, out))
        return written

    def _save_states(self, out: Path) -> list[Path]:
        from scipy.io import netcdf_file

        path = out / "states.nc"
        t = self.times.to_value(u.d)
        with netcdf_file(path, "w") as f:
            f.title = f"hamilton-orbits scene {self.scene.name}"
            f.createDimension("time", len(t))
            var = f.createVariable("time", "d", ("time",))
            var[:] = t
            var.units = "day"
            for name, series in self.diagnostics.items():
                arr = np.asarray(getattr(series, "value", series), dtype=float)
                if arr.shape != t.shape:
                    continue
                var = f.createVariable(name, "d", ("time",))
                var[:] = arr
                var.units = str(getattr(series, "unit", ""))
            for name, value in self.states.items():
                arr = np.asarray(getattr(value, "value", value))
                if arr.dtype.kind not in "fi" or arr.ndim == 0:
                    continue
                dims = ["time"] + [f"{name}_dim{k}" for k in range(1, arr.ndim)]
                if arr.shape[0] != len(t):
                    continue
                for k in range(1, arr.ndim):
                    f.createDimension(dims[k], arr.shape[k])
                var = f.createVariable(name, "d", tuple(dims))
                var[:] = arr
                var.units = str(getattr(value, "unit", ""))
            names = self.states.get("names")
            if names is not None:
                f.bodies = ",".join(str(n) for n in names)
        return [path]
