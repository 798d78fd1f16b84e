"""The ``semi_active`` effect and ``eih``'s ``semi_active`` parameter (issue 35 item
8): bodies that pull on every other body and feel every other body, but not each
other (rebound's test particles of type 1)."""

from __future__ import annotations

import re

import numpy as np
import pytest

from hamilton_orbits import Body, System, integrate
from hamilton_orbits.rhs import compile_rhs

SEMI = ["b2", "b3", "b5"]


def _system() -> System:
    """A star, eight bodies of masses 1e-9 to 1e-4 scattered within a few units."""
    rng = np.random.default_rng(1)
    return System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0])]
                  + [Body(f"b{k}", 10 ** rng.uniform(-9, -4), rng.normal(size=3) * 3,
                          rng.normal(size=3) * 0.3) for k in range(8)])


def _direct(r: np.ndarray, gm: np.ndarray, semi: list[int]) -> np.ndarray:
    """Newton's law summed body by body, every ordered pair apart, the pairs of two
    semi-active bodies left out (numpy; another order of the same sums)."""
    acc = np.zeros_like(r)
    for i in range(len(r)):
        for j in range(len(r)):
            if i != j and not (i in semi and j in semi):
                d = r[j] - r[i]
                acc[i] += gm[j] * d / np.linalg.norm(d) ** 3
    return acc


def _state(s: System) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return np.array(s.r, dtype=float), np.array(s.v, dtype=float), s.as_arrays().gm


def test_the_acceleration_leaves_out_the_semi_active_pairs_alone():
    """Against the direct sum, to 1e-15 of the largest acceleration (measured 7e-17:
    the two sums' rounding); the pairs left out are what it differs from Newton's
    law by (7.8e-10 here, far above the rounding)."""
    s = _system()
    r, v, gm = _state(s)
    semi = [s.names.index(x) for x in SEMI]
    got = compile_rhs(s, [{"name": "semi_active", "bodies": SEMI}]).acceleration(r, v, gm)
    want = _direct(r, gm, semi)
    scale = np.abs(want).max()
    assert np.abs(got - want).max() < 1e-15 * scale
    full = compile_rhs(s).acceleration(r, v, gm)
    assert np.abs(full - got).max() > 1e-6 * np.abs(_direct(r, gm, []) - want).max() > 0


@pytest.mark.parametrize(("n", "semi"), [(3, [1, 2]), (9, [0, 4, 8]), (27, list(range(11, 27))),
                                         (150, list(range(10, 150, 2)))])
def test_the_simd_form_at_every_size(n, semi):
    """The kernel's SIMD form (the active bodies' lanes first, a semi-active source
    stopping after them; on the stack up to 128 bodies, allocated beyond), a
    massless semi-active body among them, against the direct sum: 1e-14 of the
    largest acceleration (the two sums' rounding over up to 150 terms)."""
    from hamilton_orbits._kernels.nbody import newtonian_semi_active

    rng = np.random.default_rng(n)
    r, v = rng.normal(size=(n, 3)) * 3.0, rng.normal(size=(n, 3))
    gm = 10 ** rng.uniform(-9, -3, n)
    gm[semi[-1]] = 0.0
    acc = np.zeros((n, 3))
    newtonian_semi_active(r, v, gm, acc, np.array(semi, dtype=float))
    want = _direct(r, gm, semi)
    assert np.abs(acc - want).max() < 1e-14 * np.abs(want).max()


def test_eih_with_semi_active_bodies_is_newton_without_their_pairs_at_large_c():
    """``eih``'s ``semi_active``: at c = 1e12 (the 1PN terms below 1e-24 of Newton's)
    the same direct sum, to 1e-15; at c = 1e4 the pairs left out are the whole
    difference from ``eih`` without them, to 1e-14 of the largest acceleration (what
    else differs: the 1PN terms of the pairs and of the semi-active bodies' mutual
    potentials, and the rounding of a difference of accelerations; measured
    1.3e-15)."""
    s = _system()
    r, v, gm = _state(s)
    semi = [s.names.index(x) for x in SEMI]
    want = _direct(r, gm, semi)
    scale = np.abs(want).max()
    big_c = compile_rhs(s, [{"name": "eih", "c": 1e12, "semi_active": SEMI}])
    assert np.abs(big_c.acceleration(r, v, gm) - want).max() < 1e-15 * scale
    with_semi, without = (compile_rhs(s, [{"name": "eih", "c": 1e4, **kw}]).acceleration(
        r, v, gm) for kw in ({"semi_active": SEMI}, {}))
    pairs = _direct(r, gm, []) - want
    assert np.abs((without - with_semi) - pairs).max() < 1e-14 * scale


def test_semi_active_bodies_are_not_eih_sources_by_default():
    """Without ``sources``, every massive body but the semi-active ones is a source:
    the same bits as listing those."""
    s = _system()
    r, v, gm = _state(s)
    others = [x for x in s.names if x not in SEMI]
    a, b = (compile_rhs(s, [{"name": "eih", "c": 1e4, "semi_active": SEMI, **kw}])
            .acceleration(r, v, gm) for kw in ({}, {"sources": others}))
    assert np.array_equal(a, b)


def test_a_run_keeps_the_momentum():
    """Every pair left in acts both ways: the centre of mass moves uniformly to
    rounding (radau15 and leapfrog, 1000 days; measured 2.5e-19 and 1.6e-17)."""
    s = _system()
    for method, kw in (("radau15", {}), ("leapfrog", {"dt": 0.01})):
        tr = integrate(s, 1000.0, method=method,
                       effects=[{"name": "semi_active", "bodies": SEMI}], **kw)
        assert np.max(tr.barycentre_drift) < 1e-13, method


def test_against_rebounds_semi_active_test_particles():
    """rebound's own test particles of type 1 (``N_active``, ``testparticle_type =
    1``; IAS15): a star, two planets and four bodies of 1e-5 between 2.2 and 2.65,
    which pull on each other strongly enough that leaving their pairs out moves
    them by 0.02 in 50 time units.  Ours (radau15) and rebound's end 5.6e-15 apart
    with the rule (6.0e-14 without it, both codes at their default tolerances);
    the bound, 1e-11, is two hundred times the latter."""
    import rebound

    rng = np.random.default_rng(7)
    bodies = [Body("star", 1.0, [0, 0, 0], [0, 0, 0]),
              Body("p1", 1e-3, [1, 0, 0], [0, 1, 0]),
              Body("p2", 3e-4, [0, -1.6, 0.02], [0.79, 0, 0])]
    for k in range(4):
        a, ph = 2.2 + 0.15 * k, rng.uniform(0, 2 * np.pi)
        bodies.append(Body(f"s{k}", 1e-5, [a * np.cos(ph), a * np.sin(ph), 0.01 * k],
                           [-np.sin(ph) / np.sqrt(a), np.cos(ph) / np.sqrt(a), 0]))
    s = System(bodies)
    r, v, gm = _state(s)

    def theirs(semi: bool) -> np.ndarray:
        sim = rebound.Simulation()
        sim.G = 1.0
        for i in range(len(gm)):
            sim.add(m=gm[i], x=r[i, 0], y=r[i, 1], z=r[i, 2], vx=v[i, 0], vy=v[i, 1],
                    vz=v[i, 2])
        if semi:
            sim.N_active, sim.testparticle_type = 3, 1
        sim.integrator = "ias15"
        sim.integrate(50.0, exact_finish_time=1)
        return np.array([[p.x, p.y, p.z] for p in sim.particles])

    semi = [f"s{k}" for k in range(4)]
    ours = integrate(s, 50.0, effects=[{"name": "semi_active", "bodies": semi}]).r[-1]
    ref = theirs(True)
    assert np.abs(ours - ref).max() < 1e-11
    assert np.abs(ref - theirs(False)).max() > 1e-2


@pytest.mark.parametrize(("effects", "kw", "match"), [
    ([{"name": "semi_active", "bodies": SEMI}], {"method": "wh", "dt": 0.01},
     "Effect 'semi_active' replaces Newtonian gravity, which integrator 'wh' splits into "
     "Kepler drifts and kicks of its own; integrators that accept it: radau15, leapfrog, "
     "dop853"),
    (["eih", {"name": "semi_active", "bodies": SEMI}], {},
     "Effect 'eih' (at index 0) is refused beside 'semi_active' (at index 1)"),
    ([{"name": "semi_active"}], {}, "Effect 'semi_active' needs the `bodies`"),
    ([{"name": "semi_active", "bodies": "b2"}], {},
     "Effect 'semi_active': expected `bodies` to be a list of body names, got 'b2'"),
    ([{"name": "semi_active", "bodies": ["b2", "b3", "b2"]}], {},
     "Effect 'semi_active': `bodies` names 'b2' twice (at index 2)"),
    ([{"name": "semi_active", "bodies": ["b2", "vesta"]}], {},
     "Effect 'semi_active': `bodies` names body 'vesta', which is not in the system"),
    ([{"name": "eih", "c": 1e4, "sources": ["sun", "b2"], "semi_active": SEMI}], {},
     "Effect 'eih': 'b2' is both a source and semi-active"),
])
def test_bad_semi_active_input_is_refused_by_name(effects, kw, match):
    with pytest.raises(ValueError, match=re.escape(match)):
        integrate(_system(), 1.0, effects=effects, **kw)
