"""The :class:`~hamilton_orbits.nbody.System` a validated ``nbody`` scene starts
from (:func:`build_system`), the bodies its ``[initial]`` table names, and the
frame of its states."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits import schema as S
from hamilton_orbits.frames import frame_label
from hamilton_orbits.scenes.nbody.schema import BODY

# the Sun and the planets with the Earth-Moon barycentre as one body (System.solar_system)
_DEFAULT_SOLAR = ("sun", "mercury", "venus", "earth-moon-barycenter", "mars", "jupiter",
                  "saturn", "uranus", "neptune")


def read_rebound(path: str) -> Any:
    """The last snapshot of the rebound binary ``path``, a ``rebound.Simulation``
    (from its bytes: rebound opens only an ASCII path)."""
    import rebound

    return rebound.Simulation(Path(path).read_bytes())


def rebound_names(path: str) -> list[str]:
    """Names of the particles in a rebound binary (``body<k>`` for unnamed ones)."""
    from hamilton_orbits.rebound_bridge import particle_name

    sim = read_rebound(path)
    return [particle_name(sim.particles[k]) or f"body{k}" for k in range(sim.N)]


def initial_names(spec: dict) -> list[str]:
    """The names of the bodies the ``[initial]`` table brings in, in order."""
    names: list[str] = []
    rb = spec["initial"].get("rebound")
    if rb is not None:
        if spec["initial"].get("names"):
            names += list(spec["initial"]["names"])
        else:
            try:
                names += rebound_names(rb)
            except Exception:  # checked with a message in check.py
                pass
    ss = spec["initial"].get("solar_system")
    if ss is not None:
        names += list(_DEFAULT_SOLAR if ss.get("bodies") is None else ss["bodies"])
    eph = spec["initial"].get("ephemeris")
    if eph is not None:
        from hamilton_orbits.ephemeris import DEFAULT_BODIES

        names += list(DEFAULT_BODIES if eph.get("bodies") is None else eph["bodies"])
    return names


def output_times(spec: dict) -> u.Quantity:
    """The output times of a validated ``nbody`` scene: every ``cadence`` (a thousandth
    of the duration by default) from 0 to ``duration``, the end included."""
    duration = spec["duration"].to(u.d)
    cadence = spec["cadence"].to(u.d) if spec["cadence"] is not None else duration / 1000
    n = max(1, int(np.ceil((duration / cadence).to_value(u.one) - 1e-9)))
    t = np.minimum(np.arange(n + 1) * cadence.value, duration.value)
    return t * u.d


def problem_text(exc: Exception) -> str:
    """An exception's message as a problem's text (after the key path: lower case)."""
    msg = str(exc)
    return "e" + msg[1:] if msg.startswith("Expected ") else msg


def attempt(problems: S.Problems | None, path: str, build, keys=(), values=None):
    """``build()``, or with ``problems`` its ``ValueError`` as a problem at ``path``
    (at ``path.key`` when the message names one of ``keys`` first) and None.

    ``values``: the keys' values as read (Quantities); a message that quotes the
    named key's value as read (``got 200.0 deg``) quotes it as the file writes it
    instead (``got '200 deg'``)."""
    if problems is None:
        return build()
    try:
        return build()
    except ValueError as exc:
        msg = problem_text(exc)
        named = re.search(r"`(\w+)`", msg)
        if named and named.group(1) in keys:
            path = f"{path}.{named.group(1)}"
            msg = _as_written(msg, (values or {}).get(named.group(1)), path, problems)
        problems.add(path, msg)
        return None


def _as_written(msg: str, value: Any, path: str, problems: S.Problems) -> str:
    """``msg`` with the value it quotes after ``, got `` (as the library quotes a
    Quantity: ``200.0 deg``) replaced by the file's text at ``path`` (``'200 deg'``)."""
    if not isinstance(value, u.Quantity) or value.shape != ():
        return msg
    head, sep, tail = msg.partition(", got ")
    read = f"{float(value.value)!r} {value.unit.to_string()}".rstrip()
    quoted = problems.quoted(path, value)
    if not sep or not tail.startswith(read) or not quoted.startswith("'"):
        return msg
    return f"{head}, got {quoted}{tail[len(read):]}"


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


#: The systems built for the last few scenes' specs: a scene builds its system
#: once, while it is checked, and its run takes that one (``id(spec)`` -> (spec,
#: system); the spec is held, so its id is not reused while it is here).
_BUILT: dict[int, tuple[dict, Any]] = {}
_KEEP = 8


def build_system(spec: dict, problems: S.Problems | None = None):
    """The :class:`~hamilton_orbits.nbody.System` a validated n-body scene starts from
    (built once per spec: the check builds it, the run takes it).

    With ``problems`` (while the scene is checked), a refusal of the system, a
    body or its orbit is added there at its key path and None is returned.
    """
    known = _BUILT.get(id(spec))
    if known is not None and known[0] is spec:
        return known[1]
    system = _build(spec, problems)
    if system is not None:
        while len(_BUILT) >= _KEEP:
            del _BUILT[next(iter(_BUILT))]
        _BUILT[id(spec)] = (spec, system)
    return system


def _build(spec: dict, problems: S.Problems | None):
    from hamilton_orbits import System

    init = spec["initial"]
    bodies: list = []
    if init.get("rebound") is not None:
        # lengths in au, times in days, G m in au^3/day^2 (what final.bin holds)
        base = attempt(problems, "initial.rebound", lambda: System.from_rebound(
            read_rebound(init["rebound"]), quantity=True, names=init.get("names")))
        bodies += [] if base is None else [base[n] for n in base.names]
    ss = init.get("solar_system")
    if ss is not None:
        base = attempt(problems, "initial.solar_system", lambda: System.solar_system(
            ss["epoch"], bodies=ss.get("bodies"), frame=scene_frame(spec),
            origin=ss.get("origin") or "barycenter"), ("epoch", "bodies"))
        bodies += [] if base is None else [base[n] for n in base.names]
    eph = init.get("ephemeris")
    if eph is not None:
        base = attempt(problems, "initial.ephemeris", lambda: System.from_ephemeris(
            eph["epoch"], bodies=eph.get("bodies"), frame=scene_frame(spec)),
            ("epoch", "bodies"))
        bodies += [] if base is None else [base[n] for n in base.names]
    by_name = {b.name: b for b in bodies}
    for i, b in enumerate(spec["bodies"]):
        if b["r"] is None and b["primary"] not in by_name:
            continue  # its primary was refused: said already
        if problems is not None and _refuse_no_mu(spec, i, by_name, problems):
            continue
        body = attempt(problems, f"bodies[{i}]", lambda b=b: _scene_body(b, by_name),
                        tuple(BODY.fields), b)
        if body is not None:
            bodies.append(body)
            by_name[body.name] = body
    if problems:
        return None
    return attempt(problems, "bodies", lambda: System(bodies))


def _refuse_no_mu(spec: dict, i: int, by_name: dict, problems: S.Problems) -> bool:
    """Whether body ``i``, given by elements about its primary, has ``mu`` = the
    primary's ``gm`` + its own <= 0 (both 0): a problem then, at the primary's ``gm``
    (no scene key is called ``mu``), or at ``bodies[i].primary`` for a primary of
    ``[initial]``."""
    b = spec["bodies"][i]
    if b["r"] is not None or (by_name[b["primary"]].gm + b["gm"]).value > 0:
        return False
    j = next((k for k, c in enumerate(spec["bodies"]) if c["name"] == b["primary"]), None)
    path = f"bodies[{i}].primary" if j is None else f"bodies[{j}].gm"
    gm = by_name[b["primary"]].gm
    need = "by elements, which need mu = G (m1 + m2), the two gm summed, > 0"
    if j is None:
        problems.add(path, f"{b['primary']!r} has gm {gm} and this body gm 0: it orbits it "
                           f"{need}")
    else:
        problems.add(path, f"expected a value > 0, got {problems.quoted(path, gm)}: "
                           f"bodies[{i}] ({b['name']!r}, gm 0) orbits this body {need}")
    return True


def scene_frame(spec: dict) -> str:
    """The frame of a validated n-body scene's states (``[initial] frame``)."""
    return spec["initial"].get("frame") or "icrs"


def frame_note(spec: dict, given: dict | None = None) -> str:
    """The frame line of a scene's summary: the axes, and the origin of the
    solar-system bodies (``given``: the scene's ``[initial]`` table as written, to
    tell a frame named from the default)."""
    note = frame_label(scene_frame(spec))
    init = spec["initial"]
    if init.get("rebound") is not None and "frame" not in (given or {}) and not any(
            init.get(k) is not None for k in ("solar_system", "ephemeris")):
        # (a rebound binary records no frame: a final.bin of the ecliptic solar
        # system was called ICRS without a word)
        note += (" as taken for the rebound binary's, which records none ([initial] "
                 "frame names them)")
    ss = init.get("solar_system")
    if ss is not None:
        origin = ss.get("origin") or "barycenter"
        note += ("; origin: the centre of mass of the scene's solar-system bodies, at rest"
                 if origin in ("barycenter", "barycentre") else
                 "; origin: the solar-system barycenter (the ephemeris's)")
    return note

