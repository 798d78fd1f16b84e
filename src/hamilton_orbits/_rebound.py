"""A system as a ``rebound.Simulation`` and back, on plain arrays (exact).

rebound is given ``G = 1`` and masses equal to the ``gm`` in the system's internal
units (au and day for Quantity systems), so that positions, velocities and
``G m`` pass through bit for bit.  Bodies keep their names (rebound's
``Particle.name``).  :class:`hamilton_orbits.nbody.System` and
:mod:`hamilton_orbits.rebound_bridge` build on these two functions; this module
imports neither.
"""

from __future__ import annotations

import ctypes
from collections.abc import Sequence
from typing import Any

import numpy as np

__all__ = ["arrays_from_simulation", "particle_name", "radii_of", "simulation_from_arrays"]


def simulation_from_arrays(names: Sequence[str], gm: np.ndarray, r: np.ndarray,
                           v: np.ndarray, radius: np.ndarray | None = None) -> Any:
    """A ``rebound.Simulation`` with ``G = 1``, ``m = gm`` and the given state (and
    the particles' radii ``radius``, NaN for none).

    Examples
    --------
    >>> sim = simulation_from_arrays(["sun"], np.array([1.0]), np.zeros((1, 3)),
    ...                              np.zeros((1, 3)))
    >>> sim.particles["sun"].m, sim.G
    (1.0, 1.0)
    """
    import rebound

    sim = rebound.Simulation()
    sim.G = 1.0
    for k, name in enumerate(names):
        x, y, z = (float(c) for c in r[k])
        vx, vy, vz = (float(c) for c in v[k])
        sim.add(m=float(gm[k]), x=x, y=y, z=z, vx=vx, vy=vy, vz=vz)
        if radius is not None and radius[k] > 0:  # (NaN: none, rebound's 0)
            sim.particles[k].r = float(radius[k])
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

    Examples
    --------
    >>> sim = simulation_from_arrays(["sun"], np.ones(1), np.zeros((1, 3)), np.zeros((1, 3)))
    >>> particle_name(sim.particles[0])
    'sun'
    """
    import rebound

    ptr = ctypes.c_void_p.from_buffer(particle, rebound.Particle._name.offset).value
    return ctypes.string_at(ptr).decode("utf-8") if ptr else None


def radii_of(sim: Any) -> np.ndarray:
    """The particles' radii of a ``rebound.Simulation``, NaN where it has none (0).

    Examples
    --------
    >>> sim = simulation_from_arrays(["a", "b"], np.array([1.0, 0.0]),
    ...                              np.array([[0.0, 0, 0], [1.0, 0, 0]]), np.zeros((2, 3)),
    ...                              radius=np.array([0.5, np.nan]))
    >>> radii_of(sim).tolist()
    [0.5, nan]
    """
    radius = np.array([sim.particles[k].r for k in range(sim.N)], dtype=np.float64)
    radius[~(radius > 0)] = np.nan
    return radius


def arrays_from_simulation(
    sim: Any, names: Sequence[str] | None = None
) -> tuple[list[str], np.ndarray, np.ndarray, np.ndarray]:
    """``(names, gm, r, v)`` of a ``rebound.Simulation`` (``gm = G m``).

    Raises
    ------
    ValueError
        If ``sim`` is not a rebound simulation, or ``names`` has the wrong length.

    Examples
    --------
    >>> sim = simulation_from_arrays(["a", "b"], np.array([1.0, 0.0]),
    ...                              np.array([[0.0, 0, 0], [1.0, 0, 0]]), np.zeros((2, 3)))
    >>> names, gm, r, v = arrays_from_simulation(sim)
    >>> names, gm.tolist(), r[1].tolist()
    (['a', 'b'], [1.0, 0.0], [1.0, 0.0, 0.0])
    """
    import rebound

    if not isinstance(sim, rebound.Simulation):
        raise ValueError(f"Expected `sim` to be a rebound.Simulation, got {sim!r}")
    n = sim.N
    if names is not None and len(names) != n:
        raise ValueError(f"Expected `names` to hold {n} names, got {len(names)}")
    out = names if names is not None else [
        particle_name(sim.particles[k]) or f"body{k}" for k in range(n)]
    r = np.empty((n, 3))
    v = np.empty((n, 3))
    gm = np.empty(n)
    for k in range(n):
        p = sim.particles[k]
        gm[k] = sim.G * p.m
        r[k] = p.x, p.y, p.z
        v[k] = p.vx, p.vy, p.vz
    return list(out), gm, r, v
