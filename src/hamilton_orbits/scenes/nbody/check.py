"""The checks of an ``nbody`` scene across keys (:func:`check`): a body an effect
or analysis names exists, the integrator takes the effects, ``a`` and ``e``
agree, the outputs fit in memory; then the system and the effects' parameters
are built as the run will build them."""

from __future__ import annotations

import math
import re
from pathlib import Path

import astropy.units as u
import numpy as np

from hamilton_orbits import effects as _effects
from hamilton_orbits import schema as S
from hamilton_orbits.integrators import WH_CORRECTORS
from hamilton_orbits.integrators.methods import FIXED_STEP
from hamilton_orbits.scenes.base import check_archive_size, check_output_size
from hamilton_orbits.scenes.nbody.build import (
    attempt,
    build_system,
    initial_names,
    output_times,
    problem_text,
    rebound_names,
    scene_frame,
)
from hamilton_orbits.scenes.nbody.schema import ANALYSES, ANALYSIS_KEYS, ANGLE_KEYS, METHODS


def _accepts_velocity_dependent(method: str) -> bool:
    from importlib import import_module

    return bool(import_module(f"hamilton_orbits.integrators.{method}").ACCEPTS_VELOCITY_DEPENDENT)



def check(spec: dict, problems: S.Problems) -> None:
    """Checks across keys, every problem reported with its key path; then, if the
    scene is valid so far, the system and the effects' parameters are built as the
    run will build them, so that nothing the run would refuse passes loading."""
    _check_initial(spec["initial"], problems)
    names = initial_names(spec)
    for i, b in enumerate(spec["bodies"]):
        _check_body(b, f"bodies[{i}]", names, problems)
        names.append(b["name"])
    if not names and spec["initial"].get("rebound") is None:
        problems.add("bodies", "the scene has no bodies")
    _check_effects(spec, names, problems)
    _effects_in_scene_frame(spec, problems)
    _effects_at_scene_epoch(spec, problems)
    _check_events(spec, names, problems)
    if spec["variational"] and spec["events"]:
        problems.add("variational", "the variational equations are integrated without "
                                    "events: remove `events` or set variational = false")
    if spec["variational"] and spec["integrator"]["corrector"]:
        problems.add("integrator.corrector", "not with variational = true (the corrector's "
                                             "tangent map is not implemented)")
    _check_integrator(spec["integrator"], problems)
    _check_analyses(spec["analysis"], names, problems)
    _check_de440_residuals(spec, problems)
    if spec["cadence"] is not None and spec["cadence"] > spec["duration"]:
        problems.add("cadence", f"the cadence {spec['cadence']} exceeds the duration "
                                f"{spec['duration']}")
    per_output = 6 * len(names) * (2 if spec["crosscheck"] else 1) + 4
    check_output_size(spec, problems, per_output,
                      f"{len(names)} bodies" + (" (and rebound's copy)" if spec["crosscheck"]
                                                else ""))
    check_archive_size(spec, problems, len(names))
    if not problems:
        _check_buildable(spec, problems)


def _check_analyses(analyses: list, names: list[str], problems: S.Problems) -> None:
    for i, an in enumerate(analyses):
        required, optional = ANALYSIS_KEYS[an["name"]]
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


def _check_de440_residuals(spec: dict, problems: S.Problems) -> None:
    """``de440_residuals`` compares with DE440 at whole years from the start: it needs
    the start from the ephemeris and at least two outputs at whole years."""
    for i, an in enumerate(spec["analysis"]):
        if an["name"] != "de440_residuals":
            continue
        if spec["initial"].get("ephemeris") is None:
            problems.add(f"analysis[{i}]", "analysis 'de440_residuals' needs the start from "
                                           "DE440: give [initial] ephemeris")
        if spec["duration"] is None:
            continue
        years = output_times(spec).to_value(u.yr)
        whole = int(np.count_nonzero(np.abs(years - np.round(years)) < 1e-9))
        if whole < 2:
            every = "thousandth" if spec["cadence"] is None else spec["cadence"]
            problems.add(f"analysis[{i}]", f"analysis 'de440_residuals' compares at whole "
                                           f"years from the start: the outputs (every "
                                           f"{every} over {spec['duration']}) hold {whole}; "
                                           "give a cadence that divides a year")


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
                problems.add(f"initial.solar_system.{key}", problem_text(exc))
    rb = init.get("rebound")
    if rb is None:
        return
    if not Path(rb).is_file():
        problems.add("initial.rebound", f"no such file {rb!r} (relative to {Path.cwd()})")
        return
    try:
        found = rebound_names(rb)
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
    elements = [k for k in ("a", "p", "q", "e", *ANGLE_KEYS) if b[k] is not None]
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
    written = problems.quoted(f"{path}.a", a)  # (as the file writes it: '7000 km')
    if e == 1.0:
        problems.add(f"{path}.a", f"a parabola ({shown}) has no finite `a`: give `p` or `q`")
    elif e > 1.0 and a.value > 0:
        problems.add(f"{path}.a", f"expected a < 0 for a hyperbola ({shown} > 1), got "
                                  f"a = {written}; an ellipse (a > 0) has e < 1")
    elif e < 1.0 and a.value < 0:
        problems.add(f"{path}.a", f"expected a > 0 for an ellipse ({shown} < 1), got "
                                  f"a = {written}; a hyperbola (a < 0) has e > 1")


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


def _effects_in_scene_frame(spec: dict, problems: S.Problems) -> None:
    """The axes of the scene's states (``[initial] frame``) are those of every effect
    that takes a ``frame`` (its default directions: the ecliptic pole, the Sun's
    and the Earth's poles): filled in where the effect does not say, a problem
    where it says otherwise."""
    frame = scene_frame(spec)
    for i, eff in enumerate(spec["effects"]):
        if "frame" not in _effects.get("nbody", eff["name"]).parameters:
            continue
        if eff.setdefault("frame", frame) != frame:
            problems.add(f"effects[{i}].frame", f"{eff['frame']!r}, but the scene's states are "
                                                f"in {frame!r} axes ([initial] frame)")


def _effects_at_scene_epoch(spec: dict, problems: S.Problems) -> None:
    """An effect about the Earth's pole of date (``pole = "IAU2006"``) takes the
    scene's start as its ``epoch`` (``[initial] ephemeris`` or ``solar_system``'s):
    filled in where it does not say; a problem where it says another, or where the
    scene's states have no epoch (bodies of its own: give the effect's ``epoch``)."""
    init = spec["initial"]
    start = (init.get("ephemeris") or init.get("solar_system") or {}).get("epoch")
    for i, eff in enumerate(spec["effects"]):
        if eff.get("pole") != "IAU2006":
            continue
        if start is None:
            if eff.get("epoch") is None:
                problems.add(f"effects[{i}].epoch", "the pole of date needs the TDB of the "
                             "scene's start: give `epoch` (the scene's states have none)")
        elif eff.setdefault("epoch", start) != start:
            problems.add(f"effects[{i}].epoch", f"{eff['epoch']!r}, but the scene starts at "
                                                f"{start!r} ([initial] epoch)")


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
    if integ["method"] in FIXED_STEP and integ["dt"] is not None and integ["tol"] is not None:
        problems.add("integrator.tol", f"method {integ['method']!r} takes a fixed step `dt` or "
                                       "a tolerance `tol` that chooses it, not both (the "
                                       "tolerance was ignored)")
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
    blocks = []
    for i, eff in enumerate(spec["effects"]):
        ek = _effects.get("nbody", eff["name"])
        for key, value in eff.items():
            number = getattr(value, "value", value)
            if isinstance(number, float | int) and not isinstance(number, bool) \
                    and not math.isfinite(number):
                problems.add(f"effects[{i}].{key}", f"expected a finite value, got {value!r}")
        if ek.params is None or problems:
            continue
        params = {k: v for k, v in eff.items() if k != "name"}
        blocks.append((eff["name"], attempt(problems, f"effects[{i}]",
                                            lambda ek=ek, p=params: ek.params(system, p),
                                            tuple(ek.parameters)), i))
    if blocks and not problems:  # (two effects that count the same body's J2 twice)
        names, vectors, indices = zip(*blocks, strict=True)
        for j, message in _effects.body_exclusion_problems(names, vectors, system.names,
                                                           indices=indices):
            problems.add(f"effects[{j}]", message)
    if spec["crosscheck"] and not problems:  # (refused now, not after the run)
        from hamilton_orbits.rebound_bridge import reboundx_counterparts

        attempt(problems, "crosscheck", lambda: reboundx_counterparts(
            system, [{k: v for k, v in eff.items() if v is not None} for eff in spec["effects"]]),
            ())
    if spec["events"] and not problems:  # (an ensemble's members: no set-up without events)
        _check_simulation(spec, system, problems)


def _check_simulation(spec: dict, system, problems: S.Problems) -> None:
    """Prepare the run's :class:`~hamilton_orbits.Simulation` (its events against the
    bodies: radii for a collision, a Hill sphere about a body that has one)."""
    from hamilton_orbits.scenes.nbody.run import simulation

    try:
        simulation(spec, system)
    except ValueError as exc:
        event = re.match(r"Event at index (\d+) \([^)]*\): (.*)", str(exc), re.S)
        if event:
            problems.add(f"events[{event.group(1)}]", event.group(2))
        else:
            problems.add("integrator", problem_text(exc))

