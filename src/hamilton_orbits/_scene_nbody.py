"""The ``nbody`` scene kind: bodies, an integrator, effects, analyses.

Registered in :data:`hamilton_orbits.scene.KINDS` on import.  The keys are
documented in ``docs/scenes.md``; this module turns a validated scene into a
:class:`~hamilton_orbits.nbody.System`, runs :func:`hamilton_orbits.integrate`
in chunks (a progress bar over the whole run; Ctrl-C keeps what is done), and
measures what the scene's ``[[analysis]]`` entries ask for.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits import effects as _effects
from hamilton_orbits import schema as S
from hamilton_orbits._scene_base import (
    Result,
    SceneKind,
    check_output_size,
    format_table,
    register_kind,
)
from hamilton_orbits.frames import FRAMES, frame_label
from hamilton_orbits.integrators import WH_CORRECTORS
from hamilton_orbits.units import ANGLE, DIMENSIONLESS, GM, LENGTH, SPEED, TIME

METHODS = ("radau15", "wh", "leapfrog", "dop853")
SOLAR_SYSTEM = (
    "sun", "mercury", "venus", "earth-moon-barycenter", "earth", "moon", "mars", "jupiter",
    "saturn", "uranus", "neptune",
)
ANALYSES = {
    "perihelion_advance": "secular rate of the longitude of perihelion of `body` about `primary`",
    "nodal_regression": "secular rate of the node of `body` about `primary`, beside the J2 formula",
    "close_approach": "the smallest distance between `body` and `other`, and when",
    "de440_residuals": "the positions against JPL's DE440 at whole years from J2000 (needs "
                       "[initial] ephemeris)",
}
# the keys of each analysis besides its name: (required, optional)
_ANALYSIS_KEYS = {
    "perihelion_advance": (("body",), ("primary",)),
    "nodal_regression": (("body",), ("primary",)),
    "close_approach": (("body", "other"), ("primary",)),
    "de440_residuals": ((), ()),
}


def _accepts_velocity_dependent(method: str) -> bool:
    from importlib import import_module

    return bool(import_module(f"hamilton_orbits.integrators.{method}").ACCEPTS_VELOCITY_DEPENDENT)


_ANGLE_KEYS = ("inc", "lan", "argp", "M", "nu")
BODY = S.Table(
    fields={
        "name": S.String(required=True, nonempty=True),
        "gm": S.Quantity(kind=GM, nonnegative=True),
        "r": S.Vector(kind=LENGTH),
        "v": S.Vector(kind=SPEED),
        "primary": S.String(),
        "a": S.Quantity(kind=LENGTH, nonzero=True),
        "p": S.Quantity(kind=LENGTH, positive=True),
        "q": S.Quantity(kind=LENGTH, positive=True),
        "e": S.Quantity(kind=DIMENSIONLESS, nonnegative=True),
        **{k: S.Quantity(kind=ANGLE) for k in _ANGLE_KEYS},
        "radius": S.Quantity(kind=LENGTH, positive=True),
        "j2": S.Quantity(kind=DIMENSIONLESS),
        "pole": S.Vector(kind=DIMENSIONLESS, nonzero=True),
    }
)

@dataclass
class _EventDistance(S.Field):
    """An event's distance: a length (``"0.1 au"``) or ``{hill = k}``."""

    def check(self, value: Any, path: str, problems: S.Problems) -> Any:
        if isinstance(value, dict):
            k = value.get("hill")
            if set(value) != {"hill"} or isinstance(k, bool) or not isinstance(k, int | float) \
                    or not k > 0:
                problems.add(path, f"expected a length or {{hill = k}} with k > 0, got {value!r}")
                return None
            return {"hill": float(k)}
        return S.Quantity(kind=LENGTH, positive=True).check(value, path, problems)

    def type_name(self) -> str:
        return 'a length ("0.1 au") or {hill = k}'


SCHEMA: dict[str, S.Field] = {
    "duration": S.Quantity(kind=TIME, required=True, positive=True),
    "cadence": S.Quantity(kind=TIME, positive=True),
    "crosscheck": S.Bool(default=False),
    # the variational equations: MEGNO and the Lyapunov time in the summary
    "variational": S.Bool(default=False),
    "integrator": S.Table(
        default={},
        fields={
            "method": S.Choice(choices=METHODS, default="radau15"),
            "tol": S.Number(positive=True),
            "dt": S.Quantity(kind=TIME, positive=True),
            # options of ``wh`` (integrate(..., coordinates=, corrector=))
            "coordinates": S.Choice(choices=("democratic_heliocentric", "jacobi")),
            "corrector": S.Number(integer=True, minimum=0),
        },
    ),
    "initial": S.Table(
        default={},
        fields={
            "solar_system": S.Table(
                fields={
                    "epoch": S.String(default="J2000"),
                    "bodies": S.Array(item=S.Choice(choices=SOLAR_SYSTEM)),
                    "origin": S.Choice(choices=("barycentre", "ssb"), default="barycentre"),
                }
            ),
            "ephemeris": S.Table(
                fields={
                    "epoch": S.String(default="J2000"),
                    "bodies": S.Array(item=S.String()),
                }
            ),
            "rebound": S.String(),
            "names": S.Array(item=S.String()),
            # the axes of every state and element of the scene (hamilton_orbits.frames)
            "frame": S.Choice(choices=tuple(FRAMES), default="icrs"),
        },
    ),
    "bodies": S.Array(item=BODY, default=[]),
    "events": S.Array(item=S.Table(fields={
        "name": S.Choice(choices=("close_encounter", "collision", "escape"), required=True),
        "bodies": S.Array(item=S.String()),
        "distance": _EventDistance(),
        "action": S.Choice(choices=("record", "stop", "merge", "remove")),
    }), default=[]),
    "analysis": S.Array(
        default=[],
        item=S.Table(
            fields={
                "name": S.Choice(choices=tuple(ANALYSES), required=True),
                "body": S.String(),
                "primary": S.String(),
                "other": S.String(),
            }
        ),
    ),
}

# the Sun and the planets with the Earth-Moon barycentre as one body (System.solar_system)
_DEFAULT_SOLAR = ("sun", "mercury", "venus", "earth-moon-barycenter", "mars", "jupiter",
                  "saturn", "uranus", "neptune")


def _rebound_names(path: str) -> list[str]:
    """Names of the particles in a rebound binary (``body<k>`` for unnamed ones)."""
    import rebound

    from hamilton_orbits.rebound_bridge import particle_name

    sim = rebound.Simulation(str(path))
    return [particle_name(sim.particles[k]) or f"body{k}" for k in range(sim.N)]


def _initial_names(spec: dict) -> list[str]:
    names: list[str] = []
    rb = spec["initial"].get("rebound")
    if rb is not None:
        if spec["initial"].get("names"):
            names += list(spec["initial"]["names"])
        else:
            try:
                names += _rebound_names(rb)
            except Exception:  # checked with a message in _check
                pass
    ss = spec["initial"].get("solar_system")
    if ss is not None:
        names += list(_DEFAULT_SOLAR if ss.get("bodies") is None else ss["bodies"])
    eph = spec["initial"].get("ephemeris")
    if eph is not None:
        from hamilton_orbits.ephemeris import DEFAULT_BODIES

        names += list(DEFAULT_BODIES if eph.get("bodies") is None else eph["bodies"])
    return names


def _check(spec: dict, problems: S.Problems) -> None:
    """Checks across keys, every problem reported with its key path; then, if the
    scene is valid so far, the system and the effects' parameters are built as the
    run will build them, so that nothing the run would refuse passes loading."""
    _check_initial(spec["initial"], problems)
    names = _initial_names(spec)
    for i, b in enumerate(spec["bodies"]):
        _check_body(b, f"bodies[{i}]", names, problems)
        names.append(b["name"])
    if not names and spec["initial"].get("rebound") is None:
        problems.add("bodies", "the scene has no bodies")
    _check_effects(spec, names, problems)
    _check_events(spec, names, problems)
    if spec["variational"] and spec["events"]:
        problems.add("variational", "the variational equations are integrated without "
                                    "events: remove `events` or set variational = false")
    if spec["variational"] and spec["integrator"]["corrector"]:
        problems.add("integrator.corrector", "not with variational = true (the corrector's "
                                             "tangent map is not implemented)")
    _check_integrator(spec["integrator"], problems)
    _check_analyses(spec["analysis"], names, problems)
    if spec["cadence"] is not None and spec["cadence"] > spec["duration"]:
        problems.add("cadence", f"the cadence {spec['cadence']} exceeds the duration "
                                f"{spec['duration']}")
    per_output = 6 * len(names) * (2 if spec["crosscheck"] else 1) + 4
    check_output_size(spec, problems, per_output,
                      f"{len(names)} bodies" + (" (and rebound's copy)" if spec["crosscheck"]
                                                else ""))
    if not problems:
        _check_buildable(spec, problems)


def _check_analyses(analyses: list, names: list[str], problems: S.Problems) -> None:
    for i, an in enumerate(analyses):
        required, optional = _ANALYSIS_KEYS[an["name"]]
        for key in ("body", "primary", "other"):
            where = f"analysis[{i}].{key}"
            if an.get(key) is None:
                if key in required:
                    problems.add(where, f"missing: analysis {an['name']!r} needs `{key}` "
                                        f"({ANALYSES[an['name']]})")
            elif key not in required + optional:
                problems.add(where, f"analysis {an['name']!r} takes no `{key}` (it takes "
                                    f"{', '.join(required + optional)})")
            elif an[key] not in names:
                problems.add(where, f"no body named {an[key]!r}"
                                    f"{S.closest(str(an[key]), names)}")
            elif key != "body" and an[key] == an.get("body"):
                problems.add(where, f"expected a body other than `body` ({an[key]!r})")


def _check_initial(init: dict, problems: S.Problems) -> None:
    from hamilton_orbits.initial_states import solar_system_bodies, solar_system_epoch

    given = [k for k in ("solar_system", "ephemeris", "rebound") if init.get(k) is not None]
    if len(given) > 1:
        problems.add("initial", f"give one of `solar_system`, `ephemeris`, `rebound`, not "
                                f"{' and '.join(given)}")
    ss = init.get("solar_system")
    if ss is not None:
        checks = [("epoch", solar_system_epoch, ss.get("epoch")),
                  ("bodies", solar_system_bodies, ss.get("bodies"))]
        for key, check, value in checks:
            if value is None or (key == "bodies" and None in value):
                continue  # the default, or an item the schema refused (said already)
            try:
                check(value)
            except ValueError as exc:
                problems.add(f"initial.solar_system.{key}", _problem_text(exc))
    rb = init.get("rebound")
    if rb is None:
        return
    if not Path(rb).is_file():
        problems.add("initial.rebound", f"no such file {rb!r} (relative to {Path.cwd()})")
        return
    try:
        found = _rebound_names(rb)
    except Exception as exc:
        problems.add("initial.rebound", f"not a rebound binary: {exc}")
        return
    given = init.get("names")
    if given and len(given) != len(found):
        problems.add("initial.names", f"expected {len(found)} names (the file "
                     f"holds {len(found)} particles), got {len(given)}")
    elif not given and len(set(found)) != len(found):
        problems.add("initial.names", "missing: the particle names read from "
                     f"the file are not unique ({found}); give `names`")


def _check_body(b: dict, path: str, names: list[str], problems: S.Problems) -> None:
    if b["name"] in names:
        problems.add(f"{path}.name", f"a body named {b['name']!r} is already in the scene")
    if b["gm"] is None:
        problems.add(f"{path}.gm", 'missing: GM is required ("0 m3/s2" for a test particle)')
    has_state = b["r"] is not None or b["v"] is not None
    elements = [k for k in ("a", "p", "q", "e", *_ANGLE_KEYS) if b[k] is not None]
    if has_state and elements:
        problems.add(path, f"give either `r` and `v` or orbital elements, not both "
                           f"({', '.join(elements)})")
    elif has_state:
        for k in ("r", "v"):
            if b[k] is None:
                problems.add(f"{path}.{k}", "missing: `r` and `v` go together")
    elif elements:
        sizes = [k for k in ("a", "p", "q") if b[k] is not None]
        if len(sizes) != 1:
            problems.add(path, "give exactly one of `a`, `p`, `q` with the elements")
        elif sizes == ["a"]:
            _check_a_and_e(b, path, problems)
        if len([k for k in ("M", "nu") if b[k] is not None]) > 1:
            problems.add(path, "give at most one of `M`, `nu`")
        if b["primary"] is None:
            problems.add(f"{path}.primary", "missing: elements need the body they orbit")
        elif b["primary"] not in names:
            problems.add(f"{path}.primary",
                         f"no body named {b['primary']!r}{S.closest(b['primary'], names)}")
    else:
        problems.add(path, "missing: a state (`r`, `v`) or orbital elements (`a`, `e`, ...)")


def _check_a_and_e(b: dict, path: str, problems: S.Problems) -> None:
    """``a > 0`` is an ellipse (``e < 1``), ``a < 0`` a hyperbola (``e > 1``); a
    parabola (``e = 1``) has no finite ``a``."""
    a = b["a"]
    e = 0.0 if b["e"] is None else float(b["e"].to_value(u.one))
    shown = f"e = {e:g}" + ("" if b["e"] is not None else " (the default)")
    if e == 1.0:
        problems.add(f"{path}.a", f"a parabola ({shown}) has no finite `a`: give `p` or `q`")
    elif e > 1.0 and a.value > 0:
        problems.add(f"{path}.a", f"expected a < 0 for a hyperbola ({shown} > 1), got "
                                  f"a = {a}; an ellipse (a > 0) has e < 1")
    elif e < 1.0 and a.value < 0:
        problems.add(f"{path}.a", f"expected a > 0 for an ellipse ({shown} < 1), got "
                                  f"a = {a}; a hyperbola (a < 0) has e > 1")


def _check_effects(spec: dict, names: list[str], problems: S.Problems) -> None:
    method = spec["integrator"]["method"]
    for i, eff in enumerate(spec["effects"]):
        for key in ("body", "primary"):
            if key in eff and eff[key] not in names:
                problems.add(f"effects[{i}].{key}",
                             f"no body named {eff[key]!r}{S.closest(str(eff[key]), names)}")
        ek = _effects.get("nbody", eff["name"])
        if ek.velocity_dependent and not _accepts_velocity_dependent(method):
            ok = [m for m in METHODS if _accepts_velocity_dependent(m)]
            problems.add(
                f"effects[{i}]",
                f"effect {eff['name']!r} depends on velocities and integrator {method!r} "
                f"cannot take it; use one of {', '.join(ok)}",
            )


def _check_events(spec: dict, names: list[str], problems: S.Problems) -> None:
    from hamilton_orbits.events import EventSet

    for i, ev in enumerate(spec["events"]):
        for name in ev.get("bodies") or []:
            if name not in names:
                problems.add(f"events[{i}].bodies",
                             f"no body named {name!r}{S.closest(str(name), names)}")
        try:
            EventSet.of([{k: v for k, v in ev.items() if v is not None}])
        except ValueError as exc:
            problems.add(f"events[{i}]", str(exc).split(": ", 1)[-1])


def _check_integrator(integ: dict, problems: S.Problems) -> None:
    for option in ("coordinates", "corrector"):
        if integ[option] is not None and integ["method"] != "wh":
            problems.add(f"integrator.{option}",
                         f"an option of method 'wh' only, not of {integ['method']!r}")
    if integ["method"] == "leapfrog" and integ["dt"] is None and integ["tol"] is None:
        problems.add("integrator.dt", "missing: method 'leapfrog' takes a fixed step `dt` "
                                      "(or a tolerance `tol` from which to choose one)")
    if integ["corrector"] not in (None, *WH_CORRECTORS):
        problems.add("integrator.corrector", "expected one of "
                     f"{', '.join(map(str, WH_CORRECTORS))}, got {integ['corrector']!r}")
    elif integ["corrector"] and integ["coordinates"] != "jacobi":
        problems.add("integrator.corrector",
                     "the corrector needs integrator.coordinates = 'jacobi'")


def _check_buildable(spec: dict, problems: S.Problems) -> None:
    """Build the system and every effect's parameters as the run will, each refusal
    a problem at the key it comes from."""
    system = build_system(spec, problems)
    if system is None:
        return
    for i, eff in enumerate(spec["effects"]):
        ek = _effects.get("nbody", eff["name"])
        if ek.params is None:
            continue
        params = {k: v for k, v in eff.items() if k != "name"}
        _attempt(problems, f"effects[{i}]", lambda ek=ek, p=params: ek.params(system, p),
                 tuple(ek.parameters))


def _problem_text(exc: Exception) -> str:
    """An exception's message as a problem's text (after the key path: lower case)."""
    msg = str(exc)
    return "e" + msg[1:] if msg.startswith("Expected ") else msg


def _attempt(problems: S.Problems | None, path: str, build, keys=()):
    """``build()``, or with ``problems`` its ``ValueError`` as a problem at ``path``
    (at ``path.key`` when the message names one of ``keys`` first) and None."""
    if problems is None:
        return build()
    try:
        return build()
    except ValueError as exc:
        msg = str(exc)
        named = re.search(r"`(\w+)`", msg)
        if named and named.group(1) in keys:
            path = f"{path}.{named.group(1)}"
        problems.add(path, _problem_text(exc))
        return None


def _scene_body(b: dict, by_name: dict):
    """The :class:`~hamilton_orbits.nbody.Body` of one ``[[bodies]]`` table."""
    from hamilton_orbits import Body, KeplerOrbit

    extra = {k: b[k] for k in ("radius", "j2", "pole") if b[k] is not None}
    if b["r"] is not None:
        return Body(b["name"], gm=b["gm"], r=b["r"], v=b["v"], **extra)
    prim = by_name[b["primary"]]
    mu = (prim.gm + b["gm"]).to(u.km**3 / u.s**2)
    kw = {k: b[k] for k in ("a", "p", "q", "M", "nu") if b[k] is not None}
    orbit = KeplerOrbit.from_elements(
        e=b["e"] if b["e"] is not None else 0.0,
        inc=b["inc"] if b["inc"] is not None else 0 * u.rad,
        lan=b["lan"] if b["lan"] is not None else 0 * u.rad,
        argp=b["argp"] if b["argp"] is not None else 0 * u.rad,
        mu=mu,
        **({"M": 0 * u.rad} if "M" not in kw and "nu" not in kw else {}),
        **kw,
    )
    r, v = orbit.state()
    return Body(b["name"], gm=b["gm"], r=prim.r + r, v=prim.v + v, **extra)


def build_system(spec: dict, problems: S.Problems | None = None):
    """The :class:`~hamilton_orbits.nbody.System` a validated n-body scene starts from.

    With ``problems`` (while the scene is checked), a refusal of the system, a
    body or its orbit is added there at its key path and None is returned.
    """
    from hamilton_orbits import System

    init = spec["initial"]
    bodies: list = []
    if init.get("rebound") is not None:
        import rebound

        # lengths in au, times in days, G m in au^3/day^2 (what final.bin holds)
        base = _attempt(problems, "initial.rebound", lambda: System.from_rebound(
            rebound.Simulation(str(init["rebound"])), quantity=True, names=init.get("names")))
        bodies += [] if base is None else [base[n] for n in base.names]
    ss = init.get("solar_system")
    if ss is not None:
        base = _attempt(problems, "initial.solar_system", lambda: System.solar_system(
            ss["epoch"], bodies=ss.get("bodies"), frame=scene_frame(spec),
            origin=ss.get("origin") or "barycentre"), ("epoch", "bodies"))
        bodies += [] if base is None else [base[n] for n in base.names]
    eph = init.get("ephemeris")
    if eph is not None:
        base = _attempt(problems, "initial.ephemeris", lambda: System.from_ephemeris(
            eph["epoch"], bodies=eph.get("bodies"), frame=scene_frame(spec)),
            ("epoch", "bodies"))
        bodies += [] if base is None else [base[n] for n in base.names]
    by_name = {b.name: b for b in bodies}
    for i, b in enumerate(spec["bodies"]):
        if b["r"] is None and b["primary"] not in by_name:
            continue  # its primary was refused: said already
        body = _attempt(problems, f"bodies[{i}]", lambda b=b: _scene_body(b, by_name),
                        tuple(BODY.fields))
        if body is not None:
            bodies.append(body)
            by_name[body.name] = body
    if problems:
        return None
    return _attempt(problems, "bodies", lambda: System(bodies))


def scene_frame(spec: dict) -> str:
    """The frame of a validated n-body scene's states (``[initial] frame``)."""
    return spec["initial"].get("frame") or "icrs"


def frame_note(spec: dict) -> str:
    """The frame line of a scene's summary: the axes, and the origin of the
    solar-system bodies."""
    note = frame_label(scene_frame(spec))
    ss = spec["initial"].get("solar_system")
    if ss is not None:
        origin = ss.get("origin") or "barycentre"
        note += ("; origin: the centre of mass of the scene's solar-system bodies, at rest"
                 if origin == "barycentre" else
                 "; origin: the solar-system barycentre (the ephemeris's)")
    return note


def _times(spec: dict) -> u.Quantity:
    duration = spec["duration"].to(u.d)
    cadence = spec["cadence"].to(u.d) if spec["cadence"] is not None else duration / 1000
    n = max(1, int(np.ceil((duration / cadence).to_value(u.one) - 1e-9)))
    t = np.minimum(np.arange(n + 1) * cadence.value, duration.value)
    return t * u.d


def _progress_bar(total: int, enabled: bool):
    import sys

    if not enabled:
        return None
    try:
        from tqdm import tqdm
    except ImportError:  # pragma: no cover - tqdm is in the [progress] extra
        return None
    return tqdm(total=total, unit="output", disable=not sys.stderr.isatty(), leave=False)


def _integrator_args(spec: dict) -> tuple[str, dict[str, Any]]:
    """The method and the engine's keyword arguments (internal units: days)."""
    integ = spec["integrator"]
    kw: dict[str, Any] = {
        "tol": integ["tol"],
        "dt": None if integ["dt"] is None else float(integ["dt"].to_value(u.d)),
        "options": {k: integ[k] for k in ("coordinates", "corrector") if integ[k] is not None},
    }
    return integ["method"], kw


def _run(scene: Any, progress: bool = True, stop=lambda: False) -> Result:
    from hamilton_orbits import engine
    from hamilton_orbits.rhs import compile_rhs
    from hamilton_orbits.simulation import check_method, event_log

    spec = scene.spec
    system = build_system(spec)
    t_all = _times(spec).to_value(u.d)
    method, kw = _integrator_args(spec)
    effects = check_method(method, spec["effects"], kw["options"])
    tangent = None
    if spec["variational"]:
        from hamilton_orbits.integrators._tangent import Tangent

        tangent = Tangent(len(system.names), len(t_all))
    rhs = compile_rhs(system, effects, variational=tangent is not None)
    log = event_log(system, [{k: v for k, v in ev.items() if v is not None}
                             for ev in spec["events"]])
    arrays = system.as_arrays()
    bar = _progress_bar(len(t_all) - 1, progress)
    try:
        out = without_compilation(lambda: engine.run(
            arrays.r, arrays.v, arrays.gm, t_all, rhs, method, stop=stop,
            on_output=None if bar is None else (lambda i, steps: bar.update(1)), events=log,
            variational=tangent, **kw))
    finally:
        if bar is not None:
            bar.close()
    if len(out.t) < 2:
        raise KeyboardInterrupt
    result = _result(scene, system, out, method, effects)
    _events_into(result, system, out)
    _chaos_into(result, out)
    for an in spec["analysis"]:
        _ANALYSIS_FUNCS[an["name"]](result, system, an)
    if spec["crosscheck"] and result.complete:
        _crosscheck_into(result, system, out, method, effects)
    return result


def _events_into(result: Result, system, out) -> None:
    """The events found: a table, their count, the first of each kind (what an
    ``Ensemble`` row carries), and what stopped the run."""
    from hamilton_orbits.simulation import event_table

    if out.events is None:
        return
    table, stopped = event_table(out.events, system, u.yr)
    result.metrics["events found"] = len(table)
    for name in dict.fromkeys(table["name"]):
        first = table[table["name"] == name][0]
        result.metrics[f"first {name} at"] = first["time"]
        result.metrics[f"first {name} bodies"] = str(first["bodies"])
    if stopped is not None:
        result.metrics["stopped by"] = f"{stopped['name']} of {stopped['bodies']}"
    result.tables["events"] = [
        {"event": str(row["name"]), "time": row["time"], "bodies": str(row["bodies"]),
         "distance": row["distance"], "speed": row["speed"].to(u.km / u.s),
         "action": str(row["action"])} for row in table]


def without_compilation(run: Any) -> Any:
    """``run()`` (an engine call), its ``wall_time`` less the numba compilation that
    happened inside it (the integration proper: a first run compiles the stepping
    kernels on their first call)."""
    import dataclasses

    from hamilton_orbits.firstrun import compile_seconds

    before = compile_seconds()
    out = run()
    compiled = compile_seconds() - before
    return dataclasses.replace(out, wall_time=max(out.wall_time - compiled, 0.0))


def _chaos_into(result: Result, out) -> None:
    """With ``variational = true``: MEGNO and the Lyapunov exponent at the end (as
    rebound's ``sim.megno()`` and ``sim.lyapunov()``), the Lyapunov time
    ``1 / lyapunov`` (infinite when the exponent is not positive: no exponential
    growth measured), and MEGNO over time as a diagnostic and a figure."""
    tan = out.variational
    if tan is None:
        return
    k = len(out.t)
    megno = tan.megno[:k]
    lyap = float(tan.lyapunov[k - 1]) / u.d
    result.diagnostics["megno"] = megno.copy()
    result.metrics["MEGNO"] = float(megno[-1])
    result.metrics["Lyapunov exponent"] = lyap.to(1 / u.yr)
    result.metrics["Lyapunov time"] = (1 / lyap).to(u.yr) if lyap.value > 0 else np.inf * u.yr
    result.plotters.append(_plot_megno)


def _plot_megno(result: Result):
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4))
    t = result.times.to_value(u.yr)
    ax.plot(t, result.diagnostics["megno"], lw=0.8, label="MEGNO <Y>")
    ax.axhline(2.0, color="0.6", lw=0.6, ls=":", label="2 (quasi-periodic)")
    ax.set_xlabel("time [yr]")
    ax.set_ylabel("MEGNO <Y> (dimensionless)")
    ax.set_title(f"{result.scene.name}: MEGNO")
    ax.legend()
    fig._hamilton_name = "megno"
    return fig


def _result(scene: Any, system, out, method: str, effects) -> Result:
    """The :class:`Result` of an engine run: states, Hamilton's integrals, figures,
    and the final state as a rebound binary."""
    from hamilton_orbits.integrals import integral_errors

    gm = system.as_arrays().gm.copy()
    extra = _effects.effect_energy(system, effects, out.r, out.v)
    energy, ang, drift = integral_errors(out.r, out.v, gm, out.t, extra)
    result = Result(
        scene=scene,
        times=out.t * u.d,
        diagnostics={"energy_error": energy, "angular_momentum_error": ang,
                     "barycentre_drift": drift},
        states={"names": list(system.names), "r": out.r * u.au, "v": out.v * (u.au / u.d)},
        wall_time=out.wall_time,
        complete=out.complete,
    )
    result.metrics["integrator"] = method
    result.metrics["steps"] = out.steps
    what = _effects.energy_label(gm, effects, system.names)
    conserved = extra is not None
    result.metrics["energy"] = what
    key = "max |relative energy error|" if conserved else "max |relative energy change|"
    result.metrics[key] = float(np.max(np.abs(energy)))
    frame = scene_frame(scene.spec)
    result.frame = frame_note(scene.spec)
    result.plotters.append(lambda res: _plot_orbits(res, gm, frame))
    result.plotters.append(lambda res: _plot_energy(res, what, conserved))
    final = system.with_state(out.r[-1], out.v[-1])

    def write_rebound(_result: Result, folder: Path) -> list[Path]:
        path = folder / "final.bin"
        if path.exists():
            path.unlink()  # rebound appends to an existing archive
        final.to_rebound().save_to_file(str(path))
        return [path]

    result.writers.append(write_rebound)
    return result


def _relative_orbits(result: Result, system, body: str, primary: str):
    from hamilton_orbits import KeplerOrbit

    names = list(system.names)
    i, j = names.index(body), names.index(primary)
    r = result.states["r"][:, i] - result.states["r"][:, j]
    v = result.states["v"][:, i] - result.states["v"][:, j]
    gm = system.gm
    mu = gm[i] + gm[j]
    return KeplerOrbit.from_state(r.to(u.km), v.to(u.km / u.s), mu.to(u.km**3 / u.s**2))


CENTURY = u.def_unit("century", 100 * u.yr)


def _rate(times: u.Quantity, angle: u.Quantity) -> u.Quantity:
    """Least-squares slope of an unwrapped angle against time."""
    y = np.unwrap(angle.to_value(u.rad))
    t = times.to_value(u.d)
    slope = np.polyfit(t - t.mean(), y, 1)[0]
    return slope * u.rad / u.d


def _perihelion_advance(result: Result, system, an: dict) -> None:
    primary = an.get("primary") or system.names[int(np.argmax(np.asarray(
        getattr(system.gm, "value", system.gm))))]
    orbits = _relative_orbits(result, system, an["body"], primary)
    rate = _rate(result.times, orbits.varpi).to(u.arcsec / CENTURY)
    result.metrics[f"perihelion advance of {an['body']}"] = rate


def _nodal_regression(result: Result, system, an: dict) -> None:
    primary = an.get("primary") or system.names[0]
    orbits = _relative_orbits(result, system, an["body"], primary)
    rate = _rate(result.times, orbits.lan).to(u.deg / u.d)
    result.metrics[f"nodal regression of {an['body']}"] = rate
    prim = system[primary]
    j2 = getattr(prim, "j2", None)
    if j2 is not None and getattr(prim, "radius", None) is not None:
        # first-order secular rate: dOmega/dt = -3/2 n J2 (R/p)^2 cos i (Vallado 4th ed. 9-41)
        o = orbits[0]
        j2v = float(getattr(j2, "value", j2))
        formula = (-1.5 * o.n * j2v * (prim.radius / o.p).to(u.one) ** 2 * np.cos(o.inc))
        formula = formula.to(u.deg / u.d)
        result.metrics["J2 first-order formula"] = formula
        result.metrics["ratio simulated / formula"] = float(rate / formula)


def _close_approach(result: Result, system, an: dict) -> None:
    """Smallest distance between two bodies, refined between outputs.

    Around the closest sampled output the relative motion is taken as straight
    (``d + w t``) over at most half a cadence either side, which is accurate when
    the cadence is short beside the encounter's duration; the heliocentric (or
    ``primary``-centric) orbit of ``body`` before and after is reported too.
    """
    names = list(system.names)
    i, j = names.index(an["body"]), names.index(an["other"])
    r = result.states["r"].to_value(u.au)
    v = result.states["v"].to_value(u.au / u.d)
    t = result.times.to_value(u.d)
    d = r[:, i] - r[:, j]
    w = v[:, i] - v[:, j]
    dist = np.linalg.norm(d, axis=-1)
    k = int(np.argmin(dist))
    lo = 0.5 * (t[max(k - 1, 0)] - t[k])  # half-way to the neighbouring outputs,
    hi = 0.5 * (t[min(k + 1, len(t) - 1)] - t[k])  # never beyond the run's ends
    ww = float(w[k] @ w[k])
    tau = float(np.clip(-(d[k] @ w[k]) / ww, lo, hi)) if ww > 0 else 0.0
    closest = float(np.linalg.norm(d[k] + w[k] * tau))
    result.metrics[f"closest approach {an['body']}-{an['other']}"] = closest * u.au
    result.metrics["at time"] = ((t[k] + tau) * u.d).to(u.yr)
    primary = an.get("primary")
    if primary:
        orbits = _relative_orbits(result, system, an["body"], primary)
        for label, idx in (("before", 0), ("after", -1)):
            o = orbits[idx]
            # 1/a too: it is continuous through the parabola (a jumps from +inf to
            # -inf there, as a clone that escapes does), and q, finite for every conic
            result.metrics[f"{an['body']} orbit {label}: a"] = o.a.to(u.au)
            result.metrics[f"{an['body']} orbit {label}: 1/a"] = (1 / o.a).to(1 / u.au)
            result.metrics[f"{an['body']} orbit {label}: q"] = o.q.to(u.au)
            result.metrics[f"{an['body']} orbit {label}: e"] = float(o.e)


def _de440_residuals(result: Result, system, an: dict) -> None:
    """The positions against DE440's at the whole years from J2000 among the outputs:
    km and arcsec per body (heliocentric; the Moon geocentric) at 10, 50 and 100
    years (those reached), and a figure of the residual against time."""
    from hamilton_orbits.studies.ladder import BODIES, residuals

    years = result.times.to_value(u.yr)  # Julian years of 365.25 d from the start (J2000)
    whole = np.flatnonzero(np.abs(years - np.round(years)) < 1e-9)
    if result.scene.spec["initial"].get("ephemeris") is None or len(whole) < 2:
        result.metrics["DE440 residuals"] = "need [initial] ephemeris and yearly outputs"
        return
    if scene_frame(result.scene.spec) != "icrs":
        from hamilton_orbits.frames import frame_rotation

        rot = frame_rotation(scene_frame(result.scene.spec))
        r = result.states["r"].to_value(u.au)[whole] @ rot  # back to ICRS axes
    else:
        r = result.states["r"].to_value(u.au)[whole]
    yrs = np.round(years[whole]).astype(int)
    km, arcsec = residuals(system.names, r, yrs)
    result.diagnostics["de440_years"] = yrs
    result.diagnostics["de440_km"] = km
    rows = []
    for k, body in enumerate(BODIES):
        row = {"body": body}
        for y in (10, 50, 100):
            if y in yrs:
                i = int(np.flatnonzero(yrs == y)[0])
                row[f"{y} yr"] = f"{km[i, k]:.3g} km ({arcsec[i, k]:.2g}\")"
        rows.append(row)
    result.tables["residuals against DE440 (heliocentric; the Moon geocentric)"] = rows
    result.metrics["largest residual at the end"] = (
        f"{BODIES[int(np.argmax(km[-1]))]}: {km[-1].max():.3g} km")
    result.plotters.append(_plot_de440)


def _plot_de440(result: Result):
    import matplotlib.pyplot as plt

    from hamilton_orbits.studies.ladder import BODIES

    fig, ax = plt.subplots(figsize=(7, 4.5))
    years = result.diagnostics["de440_years"]
    km = result.diagnostics["de440_km"]
    colors = plt.cm.tab20(np.arange(len(BODIES)) / len(BODIES))
    for k, body in enumerate(BODIES):
        moon = body == "moon"
        ax.semilogy(years[1:], np.maximum(km[1:, k], 1e-6), lw=1.4 if moon else 1,
                    ls="--" if moon else "-", color="k" if moon else colors[k],
                    label="moon (from the earth)" if moon else body)
    ax.set_xlabel("time from J2000 [yr]")
    ax.set_ylabel("position residual against DE440 [km]")
    ax.set_title(f"{result.scene.name}: heliocentric residuals (the Moon geocentric), ICRS")
    ax.legend(fontsize=7, ncol=2)
    fig._hamilton_name = "de440_residuals"
    return fig


_ANALYSIS_FUNCS = {
    "de440_residuals": _de440_residuals,
    "perihelion_advance": _perihelion_advance,
    "nodal_regression": _nodal_regression,
    "close_approach": _close_approach,
}


def _crosscheck_into(result: Result, system, out, method: str, effects) -> None:
    """Integrate the same initial state with rebound (IAS15) at the same output times."""
    from hamilton_orbits import crosscheck
    from hamilton_orbits.simulation import make_trajectory

    traj = make_trajectory(system, out, u.d, method, ("newtonian", *effects.names), effects)
    table = crosscheck(system, None, method=method, effects=effects, trajectory=traj)
    result.tables["cross-check against rebound: final position difference"] = table.rows
    result.tables["cross-check against rebound: codes"] = table.code_rows
    result.diagnostics["rebound_energy_error"] = table.rebound_energy_error
    result.metrics["rebound wall time (s)"] = table.wall_time["rebound"]
    result.metrics["max relative position difference"] = float(
        table.relative_position_difference.max())


def orbit_view(names: list[str], gm: np.ndarray, r: np.ndarray) -> dict[str, Any]:
    """What the orbit figure draws: positions relative to the primary (the most
    massive body), in km below 0.01 au of extent and au above, and the bodies of an
    inner panel (those inside the largest gap, by a factor 2.5 or more, in the
    bodies' largest distances from the primary, when the outermost is 5 times
    farther).

    Parameters
    ----------
    names : list of str, (n,)
    gm : ndarray, (n,)
    r : ndarray, (n_t, n, 3)
        Positions in au.

    Examples
    --------
    >>> r = np.zeros((2, 3, 3)); r[:, 1, 0] = 1.0; r[:, 2, 0] = 30.0
    >>> view = orbit_view(["sun", "earth", "neptune"], np.array([1.0, 3e-6, 5e-5]), r)
    >>> view["primary"], view["unit"], view["inner"]
    ('sun', 'au', ['earth'])
    """
    k = int(np.argmax(gm))
    rel = r - r[:, k:k + 1]
    reach = np.linalg.norm(rel, axis=-1).max(axis=0)
    others = [i for i in range(len(names)) if i != k]
    unit = "au" if reach.max(initial=0.0) > 0.01 else "km"
    scale = 1.0 if unit == "au" else (1 * u.au).to_value(u.km)
    inner: list[str] = []
    if len(others) > 1:
        order = sorted(others, key=lambda i: reach[i])
        dist = np.maximum(reach[order], 1e-300)
        ratios = dist[1:] / dist[:-1]
        cut = int(np.argmax(ratios))
        if ratios[cut] >= 2.5 and dist[-1] >= 5 * dist[cut]:
            inner = [names[i] for i in order[:cut + 1]]
    return {"primary": names[k], "rel": rel * scale, "unit": unit, "inner": inner,
            "reach": reach * scale, "scale": scale, "index": k}


def _coarse(cadence: float, r: np.ndarray, v: np.ndarray, mu: float) -> bool:
    """True if the outputs are more than a 36th of the two-body period apart (10
    degrees of mean anomaly: a line would draw chords, or, at a cadence near the
    period, a short stroke where the orbit is): then dots are drawn."""
    energy = 0.5 * float(v @ v) - mu / float(np.linalg.norm(r))
    if not energy < 0:
        return False
    period = 2 * np.pi * np.sqrt((-mu / (2 * energy)) ** 3 / mu)
    return bool(cadence > period / 36)


def axis_label(axis: str, unit: str, frame: str, primary: str) -> str:
    """A position axis's label: the axis, the origin, the frame and the unit.

    Examples
    --------
    >>> axis_label("x", "au", "ecliptic", "sun")
    'x from sun, J2000 mean ecliptic and equinox [au]'
    """
    return f"{axis} from {primary}, {frame_label(frame)} [{unit}]"


def osculating_ellipse(r: np.ndarray, v: np.ndarray, mu: float, n: int = 361
                       ) -> np.ndarray | None:
    """Points of the two-body ellipse through the state ``r``, ``v`` (relative to the
    primary, ``mu`` = G (m_primary + m)), shape (n, 3); None unless 0 <= e < 0.95.

    ``r(E) = a (cos E - e) P + a sqrt(1 - e^2) sin E Q`` with ``P`` towards the
    periapsis (the modern eccentricity vector) and ``Q = h x P / |h|``.

    Examples
    --------
    >>> pts = osculating_ellipse(np.array([1.0, 0, 0]), np.array([0, 1.0, 0]), 1.0, 5)
    >>> np.round(pts[:, :2], 12).tolist()
    [[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [-0.0, -1.0], [1.0, -0.0]]
    """
    h = np.cross(r, v)
    dist = float(np.linalg.norm(r))
    ecc = np.cross(v, h) / mu - r / dist
    e = float(np.linalg.norm(ecc))
    energy = 0.5 * float(v @ v) - mu / dist
    if not (energy < 0 and e < 0.95 and np.linalg.norm(h) > 0):
        return None
    a = -mu / (2 * energy)
    p_hat = ecc / e if e > 1e-12 else r / dist
    q_hat = np.cross(h, p_hat) / np.linalg.norm(h)
    big_e = np.linspace(0.0, 2 * np.pi, n)[:, None]
    return a * (np.cos(big_e) - e) * p_hat + a * np.sqrt(1 - e * e) * np.sin(big_e) * q_hat


def _draw_orbits(ax: Any, view: dict, names: list[str], frame: str) -> None:
    primary = view["primary"]
    for k, name in enumerate(view["names"]):
        if name not in names or name == primary:
            continue
        xy = view["rel"][:, k, :2]
        if not _coarse(view["cadence"], view["rel0"][k], view["vrel0"][k], view["mu"][k]):
            ax.plot(xy[:, 0], xy[:, 1], lw=0.7, label=name)
            continue
        # outputs too far apart for a line: a dot per output, and the osculating
        # two-body orbit of the first output as a thin line to read them against
        (dots,) = ax.plot(xy[:, 0], xy[:, 1], ".", ms=1.2,
                          label=f"{name} (a dot every {view['cadence_text']})")
        ellipse = osculating_ellipse(view["rel0"][k], view["vrel0"][k], view["mu"][k])
        if ellipse is not None:
            ax.plot(ellipse[:, 0], ellipse[:, 1], lw=0.4, color=dots.get_color(), alpha=0.8)
    ax.plot([0.0], [0.0], "o", color="orange", mec="k", mew=0.4, ms=6,
            label=f"{primary} (origin)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(axis_label("x", view["unit"], frame, primary), fontsize=8)
    ax.set_ylabel(axis_label("y", view["unit"], frame, primary), fontsize=8)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.09), ncol=2,
              frameon=False)


def _plot_orbits(result: Result, gm: np.ndarray, frame: str):
    """The orbits about the primary, projected on the frame's x-y plane; an inner
    panel where the inner bodies would be a blob beside the outer ones."""
    import matplotlib.pyplot as plt

    names = list(result.states["names"])
    view = orbit_view(names, gm, result.states["r"].to_value(u.au))
    view["names"] = names
    k = view["index"]
    v0 = result.states["v"][0].to_value(u.au / u.d)
    view["rel0"] = view["rel"][0]  # in the figure's unit; velocities and mu to match
    view["vrel0"] = (v0 - v0[k]) * view["scale"]
    view["mu"] = (gm + gm[k]) * view["scale"] ** 3
    view["cadence"] = float(np.median(np.diff(result.times.to_value(u.d))))
    cadence = view["cadence"] * u.d
    unit = u.yr if cadence >= 100 * u.d else u.d if cadence >= 1 * u.d else u.min
    view["cadence_text"] = f"{cadence.to_value(unit):.3g} {unit}"
    panels = [names] + ([view["inner"]] if view["inner"] else [])
    fig, axes = plt.subplots(1, len(panels), figsize=(6.2 * len(panels), 7.2), squeeze=False)
    for ax, shown in zip(axes[0], panels, strict=True):
        _draw_orbits(ax, view, shown, frame)
    axes[0, 0].set_title(f"{result.scene.name}: orbits about {view['primary']}, "
                         f"projected on the frame's x-y plane", fontsize=10)
    if view["inner"]:
        axes[0, 1].set_title(f"inner bodies: {', '.join(view['inner'])}", fontsize=10)
    fig.tight_layout()
    fig._hamilton_name = "orbits"
    return fig


def _plot_energy(result: Result, what: str, conserved: bool):
    """The relative energy error against time (log scale).  Exact zeros (the
    energy came back bit for bit) have no place on a log axis: they are counted
    in the legend, not drawn at an invented floor."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 4.2))
    span = result.times[-1] - result.times[0]
    t_unit = u.yr if span > 1 * u.yr else u.d
    t = result.times.to_value(t_unit)
    series = [("hamilton-orbits", result.diagnostics["energy_error"], {})]
    peer = result.diagnostics.get("rebound_energy_error")
    if peer is not None:
        series.append(("rebound IAS15", peer, {"alpha": 0.6}))
    for label, values, style in series:
        err = np.abs(np.asarray(values[1:], dtype=float))
        nonzero = err > 0
        zeros = int(np.count_nonzero(~nonzero))
        note = f" ({zeros} of {len(err)} outputs exactly 0, not drawn)" if zeros else ""
        ax.semilogy(t[1:][nonzero], err[nonzero], ".", ms=2, label=label + note, **style)
    eps = np.finfo(float).eps
    ax.axhline(eps, color="0.5", lw=0.7, ls=":", label=f"machine epsilon {eps:.1e}")
    if not ax.has_data() or not np.any(np.abs(result.diagnostics["energy_error"]) > 0):
        ax.set_ylim(eps / 100, eps * 100)
    ax.set_xlabel(f"time since the start [{t_unit}]")
    ax.set_ylabel("|relative energy error|" if conserved else "|relative energy change|")
    title = "energy error" if conserved else "energy change (not an error: not conserved)"
    ax.set_title(f"{result.scene.name}: {title}\nof {what}", fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig._hamilton_name = "energy_error"
    return fig


def _crosscheck(scene: Any) -> str:
    from hamilton_orbits import crosscheck

    spec = scene.spec
    system = build_system(spec)
    integ = spec["integrator"]
    table = crosscheck(system, spec["duration"], method=integ["method"],
                       effects=list(spec["effects"]))
    return (
        f"{scene.name}: hamilton-orbits {integ['method']} against {table.peer}, "
        f"{spec['duration']}\n\n{format_table(table.rows)}\n\n{format_table(table.code_rows)}"
    )


register_kind(
    SceneKind(
        name="nbody",
        summary="bodies under Hamilton's equation (B) and the listed effects",
        schema=SCHEMA,
        effect_kind="nbody",
        check=_check,
        run=_run,
        crosscheck=_crosscheck,
    )
)
