"""rebound and reboundx: the same system in the peer code, and a cross-check against it.

The conversion: rebound is given the system's ``G`` and masses ``m = gm / G`` in
its internal units (for Quantity systems au and day, ``G = 1`` and ``m = gm``), so
that positions and velocities pass through bit for bit and ``G m`` too for ``G = 1``
(else to 1 ulp).  Bodies keep their names (rebound's ``Particle.name``).  rebound's
massless test particles (beyond ``N_active``) are massless bodies; massive ones are
refused (:meth:`System.from_rebound`).
"""

from __future__ import annotations

import ctypes
import time as _time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from hamilton_orbits._legs import leg_times
from hamilton_orbits._rebound import particle_name
from hamilton_orbits.effects import (
    EffectSet,
    effect_energy,
    get,
)
from hamilton_orbits.integrals import integral_errors
from hamilton_orbits.nbody import System
from hamilton_orbits.units import time_quantity
from hamilton_orbits.validation import as_flag

__all__ = [
    "CrossCheck",
    "crosscheck",
    "from_rebound",
    "particle_name",
    "rebound_accelerations",
    "rebound_trajectory",
    "reboundx_counterparts",
    "to_rebound",
]


def to_rebound(system: System) -> Any:
    """A ``rebound.Simulation`` holding ``system`` (its internal units; see
    :meth:`System.to_rebound`: the system's G and m = gm / G for a plain-float system,
    G = 1 and m = gm for a Quantity system).

    Examples
    --------
    >>> from hamilton_orbits import Body
    >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
    ...             Body("dust", 0.0, [1.0, 0, 0], [0, 1.0, 0])])
    >>> sim = to_rebound(s)
    >>> sim.particles["dust"].x, sim.G
    (1.0, 1.0)
    """
    return system.to_rebound()


def from_rebound(sim: Any, *, quantity: bool = False, names: Sequence[str] | None = None
                 ) -> System:
    """A :class:`System` from a ``rebound.Simulation`` (see :meth:`System.from_rebound`).

    Examples
    --------
    >>> from hamilton_orbits import Body
    >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
    ...             Body("dust", 0.0, [1.0, 0, 0], [0, 1.0, 0])])
    >>> from_rebound(to_rebound(s)).names
    ('sun', 'dust')
    """
    return System.from_rebound(sim, quantity=quantity, names=names)


def rebound_accelerations(system: System) -> np.ndarray:
    """rebound's own Newtonian accelerations of ``system`` (internal units), shape (n, 3).

    Examples
    --------
    >>> from hamilton_orbits import Body
    >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
    ...             Body("dust", 0.0, [2.0, 0, 0], [0, 0.7, 0])])
    >>> rebound_accelerations(s)[1]
    array([-0.25,  0.  ,  0.  ])
    """
    import rebound

    sim = to_rebound(system)
    rebound.clibrebound.reb_simulation_update_acceleration(ctypes.byref(sim))
    return np.array([[p.ax, p.ay, p.az] for p in sim.particles])


def _add_reboundx_effects(sim: Any, system: System, effects: EffectSet) -> Any:
    """Attach the reboundx equivalents of the listed effects; returns the Extras."""
    if not effects:
        return None
    try:
        import reboundx
    except ImportError:
        raise ImportError("the cross-check of effects against reboundx needs it: python -m "
                          "pip install 'hamilton-orbits[crosscheck]'") from None

    rebx = reboundx.Extras(sim)
    for name, p in reboundx_counterparts(system, effects):
        if name in ("gr", "gr_potential"):  # p = [source, c]
            force = rebx.load_force(name)
            rebx.add_force(force)
            force.params["c"] = float(p[1])
            sim.particles[int(p[0])].params["gr_source"] = 1
        elif name == "eih":  # p = [c, beta, gamma] (every massive body a source)
            force = rebx.load_force("gr_full")
            rebx.add_force(force)
            force.params["c"] = float(p[0])
        else:  # j2: p = [body, j2, radius, pole]
            force = rebx.load_force("gravitational_harmonics")
            rebx.add_force(force)
            b = int(p[0])
            sim.particles[b].params["J2"] = float(p[1])
            sim.particles[b].params["R_eq"] = float(p[2])
    return rebx


def reboundx_counterparts(system: System, effects: Any) -> list[tuple[str, np.ndarray]]:
    """The listed effects with their parameter vectors, where reboundx can run each
    (``gr``, ``gr_potential``, ``j2`` with its pole on z, ``eih`` as reboundx's
    ``gr_full``, the n-body 1PN equations: with every massive body a source, no
    semi-active body, and PPN beta = gamma = 1): checked before anything is
    integrated (a scene with ``crosscheck = true`` is refused as it loads, not after
    its run).

    Raises
    ------
    ValueError
        Naming an effect without a reboundx counterpart, a ``j2`` pole off z, or an
        ``eih`` that ``gr_full`` cannot run (some massive body not a source, a
        semi-active body, beta or gamma other than 1).

    Examples
    --------
    >>> from hamilton_orbits import Body
    >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0])])
    >>> [name for name, _ in reboundx_counterparts(s, [{"name": "eih", "c": 1e4}])]
    ['eih']
    >>> reboundx_counterparts(s, [{"name": "nongrav", "body": "sun"}])
    Traceback (most recent call last):
    ...
    ValueError: Effect 'nongrav' has no reboundx counterpart to cross-check
    """
    out = []
    for name, params in EffectSet.of(effects, "nbody"):
        if name not in ("gr", "gr_potential", "j2", "eih"):
            raise ValueError(f"Effect {name!r} has no reboundx counterpart to cross-check")
        # the effect's own parameter builder: one validation and one unit rule for both codes
        p = get("nbody", name).params(system, dict(params))
        if name == "eih":
            _check_gr_full(system, p)
        if name == "j2" and tuple(p[3:]) != (0.0, 0.0, 1.0):
            raise ValueError(
                f"reboundx's gravitational_harmonics takes the pole along z, and body "
                f"{system.names[int(p[0])]!r} has its pole at {list(map(float, p[3:]))} "
                f"(System.solar_system and from_ephemeris give the Sun, the Earth and the "
                f"Moon their real poles); to cross-check, give the j2 effect "
                f"pole = [0, 0, 1] (the z axis), or rotate the system so that the pole is on "
                f"z, or leave out the cross-check")
        out.append((name, p))
    return out


def _check_gr_full(system: System, p: np.ndarray) -> None:
    """Refuse an ``eih`` (``p = [c, beta, gamma, sources..., -1 - semi-active...]``)
    that reboundx's ``gr_full`` would not run as it is: ``gr_full`` takes every
    massive body for a source, none semi-active, and general relativity's PPN
    beta = gamma = 1."""
    for k, key in ((1, "beta"), (2, "gamma")):
        if p[k] != 1.0:
            raise ValueError(f"Effect 'eih': reboundx's gr_full is general relativity (PPN "
                             f"beta = gamma = 1); to cross-check, leave `{key}` at 1, got "
                             f"{float(p[k])!r}")
    listed = [int(x) for x in p[3:]]
    if any(x < 0 for x in listed):
        raise ValueError("Effect 'eih': reboundx's gr_full has no semi-active bodies; to "
                         "cross-check, leave out `semi_active`")
    massive = np.flatnonzero(system.as_arrays().gm > 0).tolist()
    if listed and sorted(listed) != massive:
        left = [system.names[k] for k in massive if k not in listed]
        raise ValueError(f"Effect 'eih': reboundx's gr_full takes every massive body for a "
                         f"source; to cross-check, leave out `sources` (it leaves out "
                         f"{left})")


@dataclass
class CrossCheck:
    """Ours against rebound on one system: a table with a readable ``str``.

    Attributes
    ----------
    names : tuple of str
    position_difference : ndarray, shape (n,)
        ``|r_ours - r_rebound|`` at the end, internal units (au for Quantity systems).
    relative_position_difference : ndarray, shape (n,)
        The same divided by the body's distance from the centre of mass.
    energy_error : dict
        Final relative energy error, ``{"ours": ..., "rebound": ...}``.
    rebound_energy_error, rebound_angular_momentum_error : ndarray
        rebound's errors at each output time of the trajectory.
    angular_momentum_error : dict
    wall_time : dict
        Seconds of each code.
    steps : dict
    """

    names: tuple[str, ...]
    position_difference: np.ndarray
    relative_position_difference: np.ndarray
    energy_error: dict[str, float]
    angular_momentum_error: dict[str, float]
    wall_time: dict[str, float]
    steps: dict[str, int]
    method: str
    peer: str
    rebound_energy_error: np.ndarray | None = None
    rebound_angular_momentum_error: np.ndarray | None = None
    length_unit: str = ""

    @property
    def rows(self) -> list[dict[str, Any]]:
        """One row per body: final position difference (au for Quantity systems)."""
        dr = f"|dr| ({self.length_unit})" if self.length_unit else "|dr|"
        return [
            {"body": name, dr: float(self.position_difference[k]),
             "|dr|/r": float(self.relative_position_difference[k])}
            for k, name in enumerate(self.names)
        ]

    @property
    def code_rows(self) -> list[dict[str, Any]]:
        """One row per code: final energy and angular-momentum errors, steps, wall time."""
        return [
            {"code": label, "dE/E": self.energy_error[code],
             "dL/L": self.angular_momentum_error[code], "steps": self.steps[code],
             "wall time (s)": round(self.wall_time[code], 3)}
            for code, label in (("ours", f"hamilton-orbits {self.method}"),
                                ("rebound", self.peer))
        ]

    def __str__(self) -> str:
        dr = f"|dr| ({self.length_unit})" if self.length_unit else "|dr|"
        lines = [f"{'body':<24}{dr:>14}{'|dr|/r':>12}"]
        for k, name in enumerate(self.names):
            lines.append(
                f"{name:<24}{self.position_difference[k]:>14.3e}"
                f"{self.relative_position_difference[k]:>12.3e}"
            )
        lines.append("")
        lines.append(f"{'code':<24}{'dE/E':>12}{'dL/L':>12}{'steps':>10}{'wall (s)':>10}")
        for code, label in (("ours", f"ours ({self.method})"), ("rebound", self.peer)):
            lines.append(
                f"{label:<24}{self.energy_error[code]:>12.2e}"
                f"{self.angular_momentum_error[code]:>12.2e}{self.steps[code]:>10d}"
                f"{self.wall_time[code]:>10.2f}"
            )
        return "\n".join(lines)


def run_rebound(system: System, t_end: float, effects: Sequence[Any] = (),
                integrator: str = "ias15", dt: float | None = None) -> tuple[Any, float]:
    """Integrate ``system`` in rebound to internal time ``t_end``; (simulation, seconds)."""
    sim = to_rebound(system)
    sim.integrator = integrator
    if dt is not None:
        sim.dt = dt
    rebx = _add_reboundx_effects(sim, system, EffectSet.of(effects, "nbody"))
    start = _time.perf_counter()
    sim.integrate(t_end, exact_finish_time=1)
    wall = _time.perf_counter() - start
    _ = rebx  # keep the Extras alive while the simulation runs
    return sim, wall


def rebound_trajectory(system: System, t_out: np.ndarray, effects: Sequence[Any] = (),
                       integrator: str = "ias15") -> tuple[np.ndarray, np.ndarray, float, int]:
    """rebound's states at the internal times ``t_out`` (``t_out[0]`` the start).

    Returns ``(r, v, wall_time, steps)`` with ``r``, ``v`` of shape (n_t, n, 3).
    """
    effects = EffectSet.of(effects, "nbody")
    order = _source_first(system, effects)  # (rebound's rows: our bodies in this order)
    work = system if order[0] == 0 else System([system[system.names[k]] for k in order])
    sim = to_rebound(work)
    sim.integrator = integrator
    sim.t = float(t_out[0])
    rebx = _add_reboundx_effects(sim, work, effects)
    n = len(system)
    r = np.empty((len(t_out), n, 3))
    v = np.empty_like(r)
    buf = np.empty((n, 3))
    sim.serialize_particle_data(xyz=buf)
    r[0, order] = buf
    sim.serialize_particle_data(vxvyvz=buf)
    v[0, order] = buf
    wall = 0.0
    for k in range(1, len(t_out)):
        start = _time.perf_counter()
        sim.integrate(float(t_out[k]), exact_finish_time=1)
        wall += _time.perf_counter() - start
        sim.serialize_particle_data(xyz=buf)
        r[k, order] = buf
        sim.serialize_particle_data(vxvyvz=buf)
        v[k, order] = buf
    _ = rebx
    return r, v, wall, int(sim.steps_done)


def _source_first(system: System, effects: EffectSet) -> list[int]:
    """Our bodies in the order rebound is given them: the source of ``gr`` or
    ``gr_potential`` first (reboundx 5.1 takes particle 0 for it whichever particle
    its ``gr_source`` marks: with the Sun last, Mercury's GR precession was not
    there at all, a false disagreement of 1e4 km), the others as they are."""
    n = len(system)
    for name, params in effects:
        if name in ("gr", "gr_potential"):
            source = int(get("nbody", name).params(system, dict(params))[0])
            return [source] + [k for k in range(n) if k != source]
    return list(range(n))


def crosscheck(
    system: System,
    t: Any,
    method: str = "radau15",
    effects: Sequence[str | Mapping[str, Any]] = (),
    *,
    trajectory: Any = None,
    dt: Any = None,
    tol: float | None = None,
    progress: bool = False,
) -> CrossCheck:
    """Integrate ``system`` with ours and with rebound's IAS15 (plus reboundx effects).

    Parameters
    ----------
    system, t, method, effects, dt, tol, progress
        As for :func:`hamilton_orbits.integrate`; ``t`` an end time (a TimeDelta
        is the Quantity in days it holds).
    trajectory : Trajectory, optional
        A trajectory of ours already computed from ``system`` (it is not recomputed):
        of the same ``effects``, and ending at ``t`` (or ``t`` None: its end).  A
        trajectory of other effects, or of another end, is refused.

    Returns
    -------
    CrossCheck
        Final position difference per body, energy and angular-momentum errors and
        the wall time of each code; ``print`` it for a table.

    Examples
    --------
    >>> import numpy as np
    >>> from hamilton_orbits import Body
    >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
    ...             Body("p", 1e-3, [1.0, 0, 0], [0, 1.0, 0])])
    >>> table = crosscheck(s, 2 * np.pi, method="dop853", tol=1e-13)
    >>> bool(table.relative_position_difference.max() < 1e-9)
    True
    """
    from hamilton_orbits.simulation import integrate

    t = time_quantity(t)  # (a TimeDelta: the Quantity in days it holds)
    progress = as_flag("progress", progress)  # (refused with a trajectory given too)
    effects = EffectSet.of(effects, "nbody")
    reboundx_counterparts(system, effects)  # (refused before our run, not after it)
    if trajectory is None:
        trajectory = integrate(system, t, method=method, dt=dt, tol=tol, effects=effects,
                               progress=progress)
    _check_same_start(system, trajectory)
    times = trajectory.t.to_value("day") if system.quantity else np.asarray(trajectory.t)
    _check_same_run(system, trajectory, times, t, effects)
    r_all, v_all, wall, steps = rebound_trajectory(system, times, effects)
    arrays = system.as_arrays()
    energy, ang, _ = integral_errors(r_all, v_all, arrays.gm, times,
                                     effect_energy(system, effects, r_all, v_all))
    r_reb = r_all[-1]
    dr = np.linalg.norm(trajectory.final.as_arrays().r - r_reb, axis=1)
    rc = arrays.gm @ r_reb / arrays.gm.sum()
    dist = np.linalg.norm(r_reb - rc, axis=1)
    rel = dr / np.where(dist > 0, dist, 1.0)
    peer = "rebound ias15" + (" + reboundx" if effects else "")
    return CrossCheck(
        system.names,
        dr,
        rel,
        {"ours": float(trajectory.energy_error[-1]), "rebound": float(energy[-1])},
        {"ours": float(trajectory.angular_momentum_error[-1]), "rebound": float(ang[-1])},
        {"ours": float(trajectory.wall_time), "rebound": wall},
        {"ours": int(trajectory.steps), "rebound": steps},
        trajectory.method,
        peer,
        rebound_energy_error=energy,
        rebound_angular_momentum_error=ang,
        length_unit="au" if system.quantity else "",
    )


def _same_physics(a: EffectSet, b: EffectSet, system: System) -> bool:
    """Whether two effect sets are the same physics for ``system``: the same effects,
    each with the same parameter vector to 8 eps (``c`` given as its default value,
    299792.458 km/s converted at 1 ulp from the default in au/day, or left out
    alike; parameters that are lists compared as well, where a set of the items was
    refused as unhashable), in any order."""
    try:
        pa, pb = a.parameters(system), b.parameters(system)
    except ValueError:
        return False
    ka = sorted((name, tuple(np.ravel(x).tolist())) for name, x in zip(a.names, pa, strict=True))
    kb = sorted((name, tuple(np.ravel(x).tolist())) for name, x in zip(b.names, pb, strict=True))
    return len(ka) == len(kb) and all(
        x[0] == y[0] and len(x[1]) == len(y[1])
        and np.allclose(x[1], y[1], rtol=8 * np.finfo(float).eps, atol=0.0)
        for x, y in zip(ka, kb, strict=True))


def _check_same_run(system: System, trajectory: Any, times: np.ndarray, t: Any,
                    effects: EffectSet) -> None:
    """Refuse a trajectory of other effects than ``effects`` (rebound would run other
    physics: a gr trajectory checked against Newton's law showed 1e-4 for 1e-10) or
    of another end than ``t`` (the check ran to the trajectory's end, unsaid)."""
    theirs = tuple(n for n in getattr(trajectory, "effects", ()) if n != "newtonian")
    mine = tuple(n for n in effects.names if n != "newtonian")
    listed = getattr(trajectory, "effect_set", None)  # (with their parameters, if held)
    if sorted(theirs) != sorted(mine) or (listed is not None
                                          and not _same_physics(listed, effects, system)):
        raise ValueError(f"Expected `effects` to be those of `trajectory` "
                         f"({listed.as_list() if listed is not None else list(theirs)}), got "
                         f"{effects.as_list()}: rebound would integrate other physics; give "
                         f"the trajectory's effects (with their parameters)")
    if t is None:  # (the trajectory's own end)
        return
    end = float(leg_times(t, float(times[0]), system.quantity)[0][-1])
    if not abs(end - times[-1]) <= 1e-12 * max(abs(end), abs(times[-1])):
        raise ValueError(f"Expected `t` to be the end of `trajectory` ({float(times[-1])!r}"
                         f"{' d' if system.quantity else ''}), got {t!r}")


def _check_same_start(system: System, trajectory: Any) -> None:
    """Refuse a trajectory that did not start from ``system``'s bodies and state."""
    if tuple(trajectory.names) != tuple(system.names):
        raise ValueError(f"Expected `trajectory` of the bodies {list(system.names)}, got one "
                         f"of {list(trajectory.names)}")
    r0 = np.asarray(getattr(trajectory.r, "value", trajectory.r))[0]
    v0 = np.asarray(getattr(trajectory.v, "value", trajectory.v))[0]
    arrays = system.as_arrays()
    if not (np.array_equal(r0, arrays.r) and np.array_equal(v0, arrays.v)):
        k = int(np.argmax(np.any((r0 != arrays.r) | (v0 != arrays.v), axis=1)))
        raise ValueError(f"Expected `trajectory` to start from `system`'s state; body "
                         f"{system.names[k]!r} starts elsewhere ({r0[k].tolist()} against "
                         f"{arrays.r[k].tolist()})")
