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
import struct
from collections.abc import Sequence
from typing import Any

import numpy as np

__all__ = ["arrays_from_simulation", "binary_of", "particle_name", "radii_of",
           "simulation_from_arrays"]


def simulation_from_arrays(names: Sequence[str], gm: np.ndarray, r: np.ndarray,
                           v: np.ndarray, radius: np.ndarray | None = None,
                           G: float = 1.0) -> Any:
    """A ``rebound.Simulation`` with ``sim.G = G``, ``m = gm / G`` and the given state
    (and the particles' radii ``radius``, NaN for none).

    Examples
    --------
    >>> sim = simulation_from_arrays(["sun"], np.array([1.0]), np.zeros((1, 3)),
    ...                              np.zeros((1, 3)))
    >>> sim.particles["sun"].m, sim.G
    (1.0, 1.0)
    >>> sim = simulation_from_arrays(["sun"], np.array([1.0]), np.zeros((1, 3)),
    ...                              np.zeros((1, 3)), G=2.0)
    >>> sim.particles["sun"].m, sim.G
    (0.5, 2.0)
    """
    import rebound

    sim = rebound.Simulation()
    sim.G = float(G)  # (with m = gm / G: rebound's energy is the system's, not G times it)
    m = np.asarray(gm, dtype=np.float64) / float(G)
    for k, name in enumerate(names):
        x, y, z = (float(c) for c in r[k])
        vx, vy, vz = (float(c) for c in v[k])
        sim.add(m=float(m[k]), x=x, y=y, z=z, vx=vx, vy=vy, vz=vz)
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


def radii_of(sim: Any, names: Sequence[str] | None = None) -> np.ndarray:
    """The particles' radii of a ``rebound.Simulation``, NaN where it has none (0,
    rebound's default).

    Raises
    ------
    ValueError
        For a negative (or NaN) radius ``r``, naming the particle's index, its name
        (``names``, else rebound's) and the value: read as no radius, it dropped the
        particle's collisions unsaid.

    Examples
    --------
    >>> sim = simulation_from_arrays(["a", "b"], np.array([1.0, 0.0]),
    ...                              np.array([[0.0, 0, 0], [1.0, 0, 0]]), np.zeros((2, 3)),
    ...                              radius=np.array([0.5, np.nan]))
    >>> radii_of(sim).tolist()
    [0.5, nan]
    >>> sim.particles[1].r = -0.1
    >>> radii_of(sim)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Expected `sim`'s particles to have a radius r >= 0 ..., got r = -0.1 ...('b')
    """
    radius = np.array([sim.particles[k].r for k in range(sim.N)], dtype=np.float64)
    bad = np.flatnonzero(~(radius >= 0))
    if bad.size:
        k = int(bad[0])
        name = names[k] if names is not None else particle_name(sim.particles[k])
        raise ValueError(f"Expected `sim`'s particles to have a radius r >= 0 (0 for none), "
                         f"got r = {float(radius[k])!r} for particle {k}"
                         f"{f' ({name!r})' if name else ''}")
    radius[~(radius > 0)] = np.nan
    return radius


def _check_test_particles(sim: Any, names: Sequence[str]) -> None:
    """Refuse particles beyond rebound's ``N_active`` that carry mass (rebound's massive
    test particles): a System has no such bodies, and read as full bodies they pulled
    on every body, other physics than rebound's, unsaid.  Massless ones are our
    massless bodies (they pull on none and feel every massive body): accepted."""
    n, n_active = sim.N, sim.N_active
    if not 0 <= n_active < n:  # (-1: every particle active)
        return
    heavy = [k for k in range(n_active, n) if sim.particles[k].m != 0.0]
    if not heavy:
        return
    k, kind = heavy[0], sim.testparticle_type
    more = f" and {len(heavy) - 1} more" if len(heavy) > 1 else ""
    # (every particle beyond N_active: rebound's test particles feel none of each
    # other, its massless ones not the massive ones either)
    listed = (list(names[n_active:]) if n - n_active <= 6
              else f"<the names of particles {n_active} to {n - 1}>")
    if kind == 1 and n_active > 0:
        what = ("with testparticle_type = 1 rebound lets them pull on the active bodies but "
                "not on each other: for rebound's physics set sim.N_active = -1 and "
                f"integrate with effects=[{{'name': 'semi_active', 'bodies': {listed}}}] "
                "(without it they pull on each other too), or set their m to 0 to make "
                "them test particles that pull on none")
    else:
        what = (f"with testparticle_type = {kind} rebound lets them pull on nothing: set "
                "their m to 0 for rebound's physics (massless bodies), or sim.N_active = -1 "
                "to make them full bodies (other physics: they pull on every body)")
    raise ValueError(f"Expected `sim`'s particles beyond N_active = {n_active} (rebound's test "
                     f"particles) to be massless, got m = {sim.particles[k].m!r} for particle "
                     f"{k} ({names[k]!r}){more}: {what}")


def arrays_from_simulation(
    sim: Any, names: Sequence[str] | None = None
) -> tuple[list[str], np.ndarray, np.ndarray, np.ndarray]:
    """``(names, gm, r, v)`` of a ``rebound.Simulation`` (``gm = G m``).

    Raises
    ------
    ValueError
        If ``sim`` is not a rebound simulation or holds no particle, ``names`` has
        the wrong length, or a particle beyond ``sim.N_active`` carries mass
        (rebound's massive test particles, which pull on nothing with
        ``testparticle_type = 0`` and on the active bodies alone with 1; the
        message says how to read them).  Massless particles beyond ``N_active``
        are massless bodies.

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
    if n == 0:  # (the System built from it blamed `bodies`, which the caller never gave)
        raise ValueError("Expected `sim` to hold at least one particle, got a "
                         "rebound.Simulation with none")
    if isinstance(names, str):  # ("xyz" was taken as the names 'x', 'y', 'z')
        raise ValueError(f"Expected `names` to be a list of {n} names, got the string {names!r}")
    if names is not None and len(names) != n:
        raise ValueError(f"Expected `names` to hold {n} names, got {len(names)}")
    out = names if names is not None else [
        particle_name(sim.particles[k]) or f"body{k}" for k in range(n)]
    _check_test_particles(sim, out)
    r = np.empty((n, 3))
    v = np.empty((n, 3))
    gm = np.empty(n)
    for k in range(n):
        p = sim.particles[k]
        gm[k] = sim.G * p.m
        r[k] = p.x, p.y, p.z
        v[k] = p.vx, p.vy, p.vz
    return list(out), gm, r, v


#: the bytes of a rebound binary's header, before its first field
_HEADER = 64


def _fields(data: bytes) -> dict[bytes, tuple[int, int]] | None:
    """The fields of a rebound binary (one snapshot): name -> (offset, size) of its
    data; None where ``data`` is not laid out as rebound 5 writes it (a 64-byte
    header, then fields of ``size_name``, ``size_data`` (uint64), the name with its
    NUL, the data, up to ``end``)."""
    out, at = {}, _HEADER
    while at + 16 <= len(data):
        size_name, size_data = struct.unpack_from("<QQ", data, at)
        begin = at + 16 + size_name
        if not 0 < size_name < 256 or begin + size_data > len(data):
            return None
        name = data[at + 16:begin - 1]
        if name == b"end":
            return out
        out[name] = (begin, size_data)
        at = begin + size_data
    return None


def binary_of(sim: Any) -> bytes:
    """The bytes of ``sim`` as rebound's ``save_to_file`` writes them (one
    snapshot), the particles' names bound to their strings by numbers 1, 2, ...
    instead of this process's addresses of the strings.

    rebound stores each name with the address it had and each particle with the
    address of its name, and on loading gives a particle the name whose stored
    address is the particle's; but it goes on comparing after it has put the new
    string's address in the particle, so that a file loaded in the process that
    wrote it, whose new string may take the place of another name's freed one,
    gave the first body another's name about every other time (rebound 5.2.2).
    No address is a small number: the names then read as written, in any process.
    Bytes not laid out as expected are given as rebound wrote them.

    Examples
    --------
    >>> import rebound
    >>> sim = simulation_from_arrays(["sun", "saturn"], np.ones(2), np.eye(2, 3),
    ...                              np.zeros((2, 3)))
    >>> back = rebound.Simulation(binary_of(sim))
    >>> [particle_name(p) for p in back.particles]
    ['sun', 'saturn']
    """
    import rebound

    data = bytearray(sim.__reduce__()[1][0])
    fields = _fields(bytes(data))
    if fields is None or b"name_list" not in fields or b"particles" not in fields:
        return bytes(data)
    numbers, (at, size) = {}, fields[b"name_list"]
    end = at + size
    while at < end:
        nul = data.index(b"\0", at, end)
        numbers[struct.unpack_from("<Q", data, nul + 1)[0]] = len(numbers) + 1
        struct.pack_into("<Q", data, nul + 1, len(numbers))
        at = nul + 9
    (at, size), step = fields[b"particles"], ctypes.sizeof(rebound.Particle)
    for k in range(size // step):
        where = at + k * step + rebound.Particle._name.offset
        address = struct.unpack_from("<Q", data, where)[0]
        if address:
            struct.pack_into("<Q", data, where, numbers.get(address, 0))
    return bytes(data)
