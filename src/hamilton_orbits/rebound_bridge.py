"""rebound and reboundx: the same system in the peer code, and a cross-check against it.

The conversion is exact: rebound is given ``G = 1`` and masses equal to the
system's ``gm`` in its internal units (au and day for Quantity systems), so that
positions, velocities and ``G m`` pass through bit for bit.  Bodies keep their
names (rebound's ``Particle.name``).
"""

from __future__ import annotations

import ctypes
import time as _time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from hamilton_orbits.effects import normalize_effects
from hamilton_orbits.nbody import Body, System

__all__ = [
    "CrossCheck",
    "crosscheck",
    "from_rebound",
    "rebound_accelerations",
    "rebound_trajectory",
    "to_rebound",
]


def to_rebound(system: System) -> Any:
    """A ``rebound.Simulation`` holding ``system`` (G = 1, m = gm, internal units).

    Examples
    --------
    >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
    ...             Body("dust", 0.0, [1.0, 0, 0], [0, 1.0, 0])])
    >>> sim = to_rebound(s)
    >>> sim.particles["dust"].x, sim.G
    (1.0, 1.0)
    """
    import rebound

    sim = rebound.Simulation()
    sim.G = 1.0
    for k, name in enumerate(system.names):
        x, y, z = (float(c) for c in system._r[k])
        vx, vy, vz = (float(c) for c in system._v[k])
        sim.add(m=float(system._gm[k]), x=x, y=y, z=z, vx=vx, vy=vy, vz=vz)
        # set through the particle in the simulation: rebound copies the name into
        # memory the simulation owns (``add(name=...)`` keeps a pointer to a
        # temporary Python buffer, which may be reused before the file is written)
        sim.particles[k].name = name
    return sim


def particle_name(particle: Any) -> str | None:
    """The name of a rebound particle, read from the C string it points to.

    rebound's ``Particle.name`` getter can return a stale Python buffer for a
    particle of a simulation loaded from a binary file (ctypes caches the
    objects assigned to ``c_char_p`` fields); reading the pointer itself is exact.
    """
    import rebound

    ptr = ctypes.c_void_p.from_buffer(particle, rebound.Particle._name.offset).value
    return ctypes.string_at(ptr).decode("utf-8") if ptr else None


def from_rebound(sim: Any, *, quantity: bool = False, names: Sequence[str] | None = None
                 ) -> System:
    """A :class:`System` from a ``rebound.Simulation`` (``gm = G m``; exact for G = 1).

    Parameters
    ----------
    sim : rebound.Simulation
    quantity : bool
        Read the simulation as au, day, au^3/day^2 (what :func:`to_rebound` writes
        for a Quantity system) and return a Quantity system.
    names : sequence of str, optional
        Names for particles; default their rebound names, else ``"body<k>"``.

    Examples
    --------
    >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
    ...             Body("dust", 0.0, [1.0, 0, 0], [0, 1.0, 0])])
    >>> from_rebound(to_rebound(s)).names
    ('sun', 'dust')
    """
    import astropy.units as u

    n = sim.N
    if names is not None and len(names) != n:
        raise ValueError(f"Expected `names` to hold {n} names, got {len(names)}")
    bodies = []
    for k in range(n):
        p = sim.particles[k]
        name = names[k] if names is not None else (particle_name(p) or f"body{k}")
        gm = sim.G * p.m
        r = [p.x, p.y, p.z]
        v = [p.vx, p.vy, p.vz]
        if quantity:
            bodies.append(Body._from_floats(name, gm, r, v, None, None, None, True))
        else:
            bodies.append(Body(name, gm, r, v))
    _ = u
    return System(bodies)


def rebound_accelerations(system: System) -> np.ndarray:
    """rebound's own Newtonian accelerations of ``system`` (internal units), shape (n, 3).

    Examples
    --------
    >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
    ...             Body("dust", 0.0, [2.0, 0, 0], [0, 0.7, 0])])
    >>> rebound_accelerations(s)[1]
    array([-0.25,  0.  ,  0.  ])
    """
    import rebound

    sim = to_rebound(system)
    rebound.clibrebound.reb_simulation_update_acceleration(ctypes.byref(sim))
    return np.array([[p.ax, p.ay, p.az] for p in sim.particles])


def _add_reboundx_effects(sim: Any, system: System, normal: tuple) -> Any:
    """Attach the reboundx equivalents of the listed effects; returns the Extras."""
    if not normal:
        return None
    import reboundx

    from hamilton_orbits.effects import _C_AU_PER_DAY, _source_index, _speed_of_light

    rebx = reboundx.Extras(sim)
    for name, params in normal:
        params = dict(params)
        if name in ("gr", "gr_potential"):
            force = rebx.load_force(name)
            rebx.add_force(force)
            c = _speed_of_light(system, params, name) if (
                "c" in params or not system.quantity) else _C_AU_PER_DAY
            force.params["c"] = c
            s = _source_index(system, params, "source", name)
            sim.particles[s].params["gr_source"] = 1
        elif name == "j2":
            force = rebx.load_force("gravitational_harmonics")
            rebx.add_force(force)
            b = _source_index(system, params, "body", "j2")
            body = system.bodies[b]
            if body.pole not in (None, (0.0, 0.0, 1.0)):
                raise ValueError(
                    "reboundx's gravitational_harmonics takes the pole along z; rotate the "
                    f"system so that body {body.name!r} has its pole on z to cross-check"
                )
            sim.particles[b].params["J2"] = float(params.get("j2", body.j2))
            sim.particles[b].params["R_eq"] = float(params.get("radius", body._radius))
        else:
            raise ValueError(f"Effect {name!r} has no reboundx counterpart to cross-check")
    return rebx


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

    @property
    def rows(self) -> list[dict[str, Any]]:
        """One row per body: final position difference (au for Quantity systems)."""
        return [
            {"body": name, "|dr|": float(self.position_difference[k]),
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
        lines = [f"{'body':<24}{'|dr| (au)' :>14}{'|dr|/r':>12}"]
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
    normal = normalize_effects(effects, "nbody")
    sim = to_rebound(system)
    sim.integrator = integrator
    if dt is not None:
        sim.dt = dt
    rebx = _add_reboundx_effects(sim, system, normal)
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
    normal = normalize_effects(effects, "nbody")
    sim = to_rebound(system)
    sim.integrator = integrator
    sim.t = float(t_out[0])
    rebx = _add_reboundx_effects(sim, system, normal)
    n = len(system)
    r = np.empty((len(t_out), n, 3))
    v = np.empty_like(r)
    buf = np.empty((n, 3))
    sim.serialize_particle_data(xyz=buf)
    r[0] = buf
    sim.serialize_particle_data(vxvyvz=buf)
    v[0] = buf
    wall = 0.0
    for k in range(1, len(t_out)):
        start = _time.perf_counter()
        sim.integrate(float(t_out[k]), exact_finish_time=1)
        wall += _time.perf_counter() - start
        sim.serialize_particle_data(xyz=buf)
        r[k] = buf
        sim.serialize_particle_data(vxvyvz=buf)
        v[k] = buf
    _ = rebx
    return r, v, wall, int(sim.steps_done)


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
        As for :func:`hamilton_orbits.integrate`; ``t`` an end time.
    trajectory : Trajectory, optional
        A trajectory of ours already computed from ``system`` (it is not recomputed).

    Returns
    -------
    CrossCheck
        Final position difference per body, energy and angular-momentum errors and
        the wall time of each code; ``print`` it for a table.

    Examples
    --------
    >>> import numpy as np
    >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
    ...             Body("p", 1e-3, [1.0, 0, 0], [0, 1.0, 0])])
    >>> table = crosscheck(s, 2 * np.pi, method="dop853", tol=1e-13)
    >>> bool(table.relative_position_difference.max() < 1e-9)
    True
    """
    from hamilton_orbits.simulation import _diagnostics, integrate

    if trajectory is None:
        trajectory = integrate(system, t, method=method, dt=dt, tol=tol, effects=effects,
                               progress=progress)
    times = trajectory.t.to_value("day") if system.quantity else np.asarray(trajectory.t)
    effects = normalize_effects(effects)
    r_all, v_all, wall, steps = rebound_trajectory(
        system, times, [dict(name=n, **dict(p)) for n, p in effects]
    )
    energy, ang, _ = _diagnostics(system, r_all, v_all, times)
    final = trajectory.final
    r_reb = r_all[-1]
    dr = np.linalg.norm(final._r - r_reb, axis=1)
    rc = system._gm @ r_reb / system._gm.sum()
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
    )
