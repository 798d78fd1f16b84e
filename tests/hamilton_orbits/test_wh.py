"""The Wisdom-Holman map (hamilton_orbits.integrators.wh) against WHFast."""

from __future__ import annotations

import math
import re
from fractions import Fraction

import nbody_states
import numpy as np
import pytest
from numba import njit

from hamilton_orbits._kernels import kepler as _kepler
from hamilton_orbits._kernels import nbody as _nbody
from hamilton_orbits._kernels import wh as _kw
from hamilton_orbits._kernels.signatures import ACCEL_SIGNATURE
from hamilton_orbits.integrators import _setup, wh
from hamilton_orbits.orbit import KeplerOrbit
from hamilton_orbits.rhs import RHS, compile_rhs, newtonian_rhs

EPS = np.finfo(float).eps
ROT = np.array([[0.36, 0.48, -0.8], [-0.8, 0.6, 0.0], [0.48, 0.64, 0.6]])


def _energy(r, v, gm):
    """Hamilton's vis viva integral (E), G m-weighted: sum gm v^2/2 - sum gm_i gm_j / r_ij."""
    kin = 0.5 * np.sum(gm[:, None] * v * v, axis=(-2, -1))
    d = np.linalg.norm(r[..., :, None, :] - r[..., None, :, :], axis=-1)
    iu = np.triu_indices(len(gm), 1)
    pot = -np.sum((gm[:, None] * gm[None, :])[iu] / d[..., iu[0], iu[1]], axis=-1)
    return kin + pot


@pytest.fixture(scope="module")
def solar():
    return nbody_states.solar_system()


def _whfast(r0, v0, gm, dt, t_end, coordinates="democraticheliocentric"):
    sim = nbody_states.to_rebound(r0, v0, gm, "whfast")
    sim.dt = dt
    sim.integrator.coordinates = coordinates
    sim.integrate(t_end, exact_finish_time=0)
    sim.synchronize()
    assert sim.t == pytest.approx(t_end, rel=1e-12)
    return nbody_states.rebound_state(sim)


@pytest.mark.parametrize(
    ("coordinates", "peer", "rel_energy"),
    [("democratic_heliocentric", "democraticheliocentric", 1e-3), ("jacobi", "jacobi", 1e-2)],
)
def test_solar_system_100_years_matches_whfast(solar, coordinates, peer, rel_energy):
    # The same map as WHFast in the same coordinates (same splitting, same
    # dt = 4 days, 9131 steps): the two differ only by rounding (their Kepler
    # solvers; in Jacobi coordinates also the Sun-Mercury term, which WHFast
    # leaves out of both the kick and its correction and we cancel).
    # Measured after 100 years: relative positions at most 1.4e-11 (DH) and
    # 9e-11 (Jacobi, Mercury); energy errors equal to 1e-5 (DH, -4.5e-10) and
    # 1e-3 (Jacobi, 4.9e-11) of their size.  Bounds: 1e-9, and 1e-3 / 1e-2.
    _, r0, v0, gm = solar
    dt = 4.0
    t_end = 9131 * dt
    r, v, steps = wh.run(
        newtonian_rhs(), r0, v0, gm, np.array([0.0, t_end]), dt=dt, coordinates=coordinates
    )
    assert steps == 9131
    r_w, v_w = _whfast(r0, v0, gm, dt, t_end, peer)
    scale = np.linalg.norm(r_w - r_w[0], axis=1)
    scale[0] = np.linalg.norm(r_w[0])
    diff = np.linalg.norm(r[-1] - r_w, axis=1) / scale
    assert diff.max() < 1e-9, diff
    e0 = _energy(r0, v0, gm)
    de_ours = _energy(r[-1], v[-1], gm) / e0 - 1.0
    de_whfast = _energy(r_w, v_w, gm) / e0 - 1.0
    assert abs(de_ours - de_whfast) < rel_energy * abs(de_whfast), (de_ours, de_whfast)


def test_energy_error_is_second_order_and_bounded(solar):
    # Wisdom-Holman: the energy error oscillates with an amplitude ~ eps dt^2
    # (no drift).  Halving dt divides the largest error over 20 years by 4
    # (measured 3.72; bounds 3.5 .. 4.5), and the largest error of the second
    # decade is that of the first (measured ratio 1.03 and 1.04; bound 1.2: a
    # drift would grow it).
    _, r0, v0, gm = solar
    t_out = np.linspace(0.0, 20 * 365.25, 41)
    e0 = _energy(r0, v0, gm)
    amp = []
    for dt in (4.0, 2.0):
        r, v, _ = wh.run(newtonian_rhs(), r0, v0, gm, t_out, dt=dt)
        de = np.abs(_energy(r, v, gm) / e0 - 1.0)
        amp.append(de.max())
        assert de[21:].max() < 1.2 * de[1:21].max(), de
    assert 3.5 < amp[0] / amp[1] < 4.5, amp


@pytest.mark.parametrize("coordinates", wh.COORDINATES)
def test_test_particle_drift_is_the_exact_kepler_orbit(coordinates):
    # A massless body about a single star: the kick and the jump vanish, and
    # the map is the exact Kepler propagation (the shared universal-variable
    # kernel) however large dt.  Reference: KeplerOrbit.  Energy: measured
    # 41 eps after the 351 Kepler calls (a random walk of ~2 ulp per call gives
    # ~40), bound 64 eps; position: 1.3e-11 relative after 50 orbits (the
    # phase drift that this energy error and each call's phase rounding
    # produce), bound 5e-11.
    r0 = np.array([[0.0, 0.0, 0.0], ROT @ [0.6, 0.0, 0.0]])
    v0 = np.array([[0.0, 0.0, 0.0], ROT @ [0.0, math.sqrt(1.5 / 0.6), 0.0]])
    orbit = KeplerOrbit.from_state(r0[1], v0[1], 1.0)
    t_end = 50 * float(orbit.period)
    r, v, steps = wh.run(
        newtonian_rhs(),
        r0,
        v0,
        np.array([1.0, 0.0]),
        np.array([0.0, t_end]),
        dt=t_end / 350,
        coordinates=coordinates,
    )
    assert steps == 350
    r_ref, _ = orbit.propagate(t_end).state()
    assert np.linalg.norm(r[-1, 1] - r_ref) / np.linalg.norm(r_ref) < 5e-11
    energy = 0.5 * v[-1, 1] @ v[-1, 1] - 1.0 / np.linalg.norm(r[-1, 1])
    energy0 = 0.5 * v0[1] @ v0[1] - 1.0 / np.linalg.norm(r0[1])
    assert abs(energy / energy0 - 1.0) < 64 * EPS


@pytest.mark.parametrize("coordinates", wh.COORDINATES)
def test_listed_effect_joins_the_kick_and_moves_the_barycentre(solar, coordinates):
    # A uniform field g on every body: the relative motion is unchanged and the
    # barycentre falls as g t^2 / 2, exactly (its net acceleration is applied
    # to the barycentre, none to the heliocentric coordinates).
    _, r0, v0, gm = solar
    g = np.array([1e-6, -2e-6, 3e-7])

    @njit(ACCEL_SIGNATURE)
    def field(r, v, gm, acc, p):  # pragma: no cover - compiled
        for i in range(r.shape[0]):
            for k in range(3):
                acc[i, k] += g[k]

    rhs = RHS(newtonian_rhs().accel, field, np.zeros(1), False, ("newtonian", "field"))
    t = np.array([0.0, 400.0])
    r_f, v_f, _ = wh.run(rhs, r0, v0, gm, t, dt=4.0, coordinates=coordinates)
    r_n, v_n, _ = wh.run(newtonian_rhs(), r0, v0, gm, t, dt=4.0, coordinates=coordinates)
    # 1e-12 absolute: 100 kicks of the barycentre velocity and 100 drifts
    np.testing.assert_allclose(r_f[-1] - r_n[-1], np.tile(0.5 * g * 400.0**2, (9, 1)), atol=1e-12)
    np.testing.assert_allclose(v_f[-1] - v_n[-1], np.tile(g * 400.0, (9, 1)), atol=1e-14)


def _gr_bodies():
    """A star of GM 1, two planets and a test particle (``gr_potential`` at c = 30:
    a perihelion advance of ~2% of a turn per orbit, plain to see)."""
    from hamilton_orbits import Body

    return {"sun": Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
            "p": Body("p", 1e-3, [1.0, 0, 0], [0, 1.0, 0]),
            "q": Body("q", 1e-3, [0, 1.6, 0], [-1 / 1.6**0.5, 0, 0]),
            "tp": Body("tp", 0.0, [0, -1.3, 0], [1 / 1.3**0.5, 0, 0.01])}


GR_C30 = [{"name": "gr_potential", "c": 30}]


@pytest.mark.parametrize("coordinates", wh.COORDINATES)
def test_an_effect_acts_about_its_body_whatever_the_order(coordinates):
    """Issue 32: with the star not listed first, ``System([p, q, sun])``, the kernel's
    rows (the central body first) went to the effect, whose parameters name bodies
    by the caller's indices: ``gr_potential`` acted about the wrong body, and the
    run ended 0.25 from radau15's, as far as without the effect; with the test
    particle first (``[tp, sun, p]``) the effect's source was massless and "the
    Kepler step of body 0 failed".  The effects now see the caller's order.

    References: the star-first run, the same bits after reordering (the rows of
    the kernel are the same, the effect sums in the same order); radau15, to 1e-7
    (measured 5.3e-9 democratic heliocentric, 5.8e-9 Jacobi) where the run without
    the effect is 0.25 away."""
    from hamilton_orbits import System, integrate

    b = _gr_bodies()
    kw = {"method": "wh", "dt": 0.002, "effects": GR_C30, "coordinates": coordinates}
    first = integrate(System([b["sun"], b["p"], b["q"]]), 20.0, **kw)
    last = integrate(System([b["p"], b["q"], b["sun"]]), 20.0, **kw)
    np.testing.assert_array_equal(np.asarray(last.r)[-1][[2, 0, 1]], np.asarray(first.r)[-1])
    np.testing.assert_array_equal(np.asarray(last.v)[-1][[2, 0, 1]], np.asarray(first.v)[-1])
    radau = np.asarray(integrate(System([b["p"], b["q"], b["sun"]]), 20.0,
                                 effects=GR_C30).r)[-1]
    assert np.max(np.abs(np.asarray(last.r)[-1] - radau)) < 1e-7
    newton = integrate(System([b["p"], b["q"], b["sun"]]), 20.0, method="wh", dt=0.002,
                       coordinates=coordinates)
    assert np.max(np.abs(np.asarray(newton.r)[-1] - radau)) > 0.1


@pytest.mark.parametrize(("coordinates", "corrector"), [
    ("democratic_heliocentric", 0), ("jacobi", 0), ("jacobi", 11)])
def test_a_test_particle_listed_first_is_not_the_effects_source(coordinates, corrector):
    """Issue 32: with a test particle in the first slot, ``System([tp, sun, p, q])``,
    the effect's default source (the most massive body, index 1 in the caller's
    order) met the kernel's row 1, the massless particle: "wh: the Kepler step of
    body 0 failed".  Now it runs, and the symplectic corrector's kicks (Jacobi)
    see the caller's order too.

    References: the star-first run ``[sun, tp, p, q]`` (the kernel's rows are the
    same: the same bits after reordering, positions and velocities); radau15 on
    the same system, to 1e-7 (measured 5.3e-9 democratic heliocentric, 5.8e-9
    Jacobi)."""
    from hamilton_orbits import System, integrate

    b = _gr_bodies()
    kw = {"method": "wh", "dt": 0.002, "effects": GR_C30, "coordinates": coordinates}
    if corrector:
        kw["corrector"] = corrector
    tp_first = integrate(System([b["tp"], b["sun"], b["p"], b["q"]]), 20.0, **kw)
    star_first = integrate(System([b["sun"], b["tp"], b["p"], b["q"]]), 20.0, **kw)
    back = [1, 0, 2, 3]
    np.testing.assert_array_equal(np.asarray(tp_first.r)[:, back], np.asarray(star_first.r))
    np.testing.assert_array_equal(np.asarray(tp_first.v)[:, back], np.asarray(star_first.v))
    radau = integrate(System([b["tp"], b["sun"], b["p"], b["q"]]), 20.0, effects=GR_C30)
    np.testing.assert_allclose(np.asarray(tp_first.r)[-1], np.asarray(radau.r)[-1], rtol=0,
                               atol=1e-7)
    np.testing.assert_allclose(np.asarray(tp_first.v)[-1], np.asarray(radau.v)[-1], rtol=0,
                               atol=1e-7)


@pytest.mark.parametrize("coordinates", wh.COORDINATES)
def test_the_tangent_map_with_an_effect_is_the_same_whatever_the_order(coordinates):
    """The tangent map (``variational=True``) evaluates the effect and its Jacobian in
    the caller's order too: the state transition matrix of ``[p, q, sun]`` is the
    star-first one with its rows and columns reordered, bit for bit."""
    from hamilton_orbits import System, integrate

    b = _gr_bodies()
    kw = {"method": "wh", "dt": 0.002, "effects": GR_C30, "coordinates": coordinates,
          "variational": True, "stm": True}
    first = integrate(System([b["sun"], b["p"], b["q"]]), 4.0, **kw)
    last = integrate(System([b["p"], b["q"], b["sun"]]), 4.0, **kw)
    rows = np.array([6 * k + c for k in (2, 0, 1) for c in range(6)])  # sun, p, q in last
    np.testing.assert_array_equal(np.asarray(last.stm)[-1][np.ix_(rows, rows)],
                                  np.asarray(first.stm)[-1])
    np.testing.assert_array_equal(np.asarray(last.r)[-1][[2, 0, 1]], np.asarray(first.r)[-1])


def test_velocity_dependent_effects_are_refused():
    rhs = RHS(newtonian_rhs().accel, newtonian_rhs().accel, np.zeros(1), True,
              ("newtonian", "gr"))
    assert not wh.ACCEPTS_VELOCITY_DEPENDENT
    with pytest.raises(ValueError, match=r"refuses velocity-dependent.*gr.*radau15"):
        wh.run(rhs, np.zeros((1, 3)), np.zeros((1, 3)), np.ones(1), np.array([0.0, 1.0]))


def test_bad_input():
    r0 = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    v0 = np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    with pytest.raises(ValueError, match=r"central body with `gm` > 0"):
        wh.run(newtonian_rhs(), r0, v0, np.zeros(2), np.array([0.0, 1.0]), dt=0.1)
    with pytest.raises(ValueError, match=r"`dt` > 0, got -0.1"):
        wh.run(newtonian_rhs(), r0, v0, np.array([1.0, 0.0]), np.array([0.0, 1.0]), dt=-0.1)
    with pytest.raises(ValueError, match=r"`coordinates` to be one of .*got 'helio'"):
        wh.run(
            newtonian_rhs(), r0, v0, np.array([1.0, 0.0]), np.array([0.0, 1.0]), coordinates="helio"
        )
    with pytest.raises(ValueError, match=r"no body is bound"):
        wh.run(newtonian_rhs(), r0, 10 * v0, np.array([1.0, 0.0]), np.array([0.0, 1.0]))


def test_jacobi_symplectic_corrector_matches_whfast(solar):
    # Third-order corrector (Wisdom, Holman & Touma 1996) on the Jacobi map,
    # against WHFast with corrector = 3 at the same dt = 4 days for 100 years.
    # Measured: positions agree to 3e-11 (Mercury); the energy error falls from
    # 4.9e-11 without corrector to 7e-15 (WHFast: 2e-14).  Bounds: 1e-9 for
    # the positions, 1e-13 for |dE/E| (the corrector removes the eps dt^2
    # term; what is left is eps^2 dt^2 and rounding).
    _, r0, v0, gm = solar
    dt = 4.0
    t_end = 9131 * dt
    r, v, _ = wh.run(
        newtonian_rhs(),
        r0,
        v0,
        gm,
        np.array([0.0, t_end]),
        dt=dt,
        coordinates="jacobi",
        corrector=3,
    )
    sim = nbody_states.to_rebound(r0, v0, gm, "whfast")
    sim.dt = dt
    sim.integrator.coordinates = "jacobi"
    sim.integrator.corrector = 3
    sim.integrate(t_end, exact_finish_time=0)
    sim.synchronize()
    r_w, _ = nbody_states.rebound_state(sim)
    scale = np.linalg.norm(r_w - r_w[0], axis=1)
    scale[0] = np.linalg.norm(r_w[0])
    diff = np.linalg.norm(r[-1] - r_w, axis=1) / scale
    assert diff.max() < 1e-9, diff
    de = _energy(r[-1], v[-1], gm) / _energy(r0, v0, gm) - 1.0
    assert abs(de) < 1e-13, de


def test_corrector_coefficients_solve_the_first_order_conditions():
    # Wisdom, Holman & Touma (1996): the corrector of order p removes the error
    # terms eps h^(n+1) ad_A^n B, n = 1, 3, ..., p - 2, of the kernel; with Z(a, b)
    # contributing -2 b a^n / n! each, the sequence must satisfy
    # sum_k b_k a_k^n = -n! g_{n+1} / 2 over the whole (antisymmetric) sequence.
    # Rounding of the constants: a few ulp of the largest term.
    g = wh.corrector_series(8)
    assert g[:4] == [1, Fraction(-1, 24), Fraction(7, 5760), Fraction(-31, 967680)]
    for order in (3, 5, 7, 11, 17):
        a, b = wh.corrector_coefficients(order)
        m = (order - 1) // 2
        assert a.shape == b.shape == (2 * m,)
        np.testing.assert_array_equal(a[::-1], -a)  # reversed with -a is itself with -b
        np.testing.assert_array_equal(b[::-1], -b)
        np.testing.assert_allclose(a[:m], np.arange(m, 0, -1) * math.sqrt(7 / 40), rtol=1e-15)
        for n in range(1, 2 * m, 2):
            lhs = float(np.sum(b * a**n))
            want = -math.factorial(n) * float(g[(n + 1) // 2]) / 2
            scale = float(np.max(np.abs(b * a**n)))
            assert abs(lhs - want) <= 16 * EPS * scale, (order, n, lhs, want)


def test_corrector_coefficients_agree_with_rebounds():
    # rebound 5.2's whfast.c constants (Rein & Tamayo 2015), for the largest a_k of
    # each order (reb_whfast_corrector_b_31, _51, _71, _111, _178 up to its sign
    # convention for order 3): to the last bit of a double.
    published = {3: 0.024900596027799867499350357910273437,
                 5: -0.0083001986759332891664501193034244791,
                 7: 0.0024926811426922105779030593952776964,
                 11: 0.00020361579647854651301632818774633716,
                 17: -0.0000043347415473373580190650223498124945}
    for order, value in published.items():
        _, b = wh.corrector_coefficients(order)
        assert b[0] == value, (order, b[0], value)
    with pytest.raises(ValueError, match=r"corrector order in 3, 5, 7, 11, 17, got 9"):
        wh.corrector_coefficients(9)


def test_corrector_and_its_inverse_round_trip_to_rounding(solar):
    # The corrector is applied at the start of every output interval and undone at
    # its end: 100 round trips return the Jacobi state to 1e-12 relative (measured
    # 4e-14 to 1.1e-13, a few eps per Kepler solve), while one application moves
    # it by 3e-9 (so the round trip is not trivially exact).
    _, r0, v0, gm = solar
    eta = np.cumsum(gm)
    q0, u0 = np.empty_like(r0), np.empty_like(v0)
    _kw.jacobi_from_inertial(r0, v0, gm, eta, np.arange(len(gm)), q0, u0)
    extra = _setup.accel_arg(_nbody.no_effects)
    scale_q = np.linalg.norm(q0, axis=1)[:, None]
    scale_u = np.linalg.norm(u0, axis=1)[:, None]
    for order in (3, 5, 7, 11, 17):
        a, b = wh.corrector_coefficients(order)
        q, u = q0.copy(), u0.copy()
        args = (extra, np.zeros(1), False, np.arange(len(gm)), q, u, gm, eta, 4.0)
        assert _kw.corrector_jacobi(*args, 1.0, a, b) == -1
        assert np.max(np.abs(q - q0) / scale_q) > 1e-9
        assert _kw.corrector_jacobi(*args, -1.0, a, b) == -1
        for _ in range(99):
            _kw.corrector_jacobi(*args, 1.0, a, b)
            _kw.corrector_jacobi(*args, -1.0, a, b)
        assert np.max(np.abs(q - q0) / scale_q) < 1e-12, order
        assert np.max(np.abs(u - u0) / scale_u) < 1e-12, order


def test_correctors_per_output_interval_cost_only_rounding(solar):
    # 9130 steps of 4 days with one output, and with an output every 10 steps (the
    # corrector applied and undone 913 times): the final positions differ by what
    # splitting the run into output intervals costs without a corrector (measured
    # 3.8e-11 relative without, 8e-11 to 1.2e-10 with), bound 1e-9.
    _, r0, v0, gm = solar
    one = np.array([0.0, 4.0 * 9130])
    many = np.arange(914) * 40.0
    for order in (0, 3, 11, 17):
        kw = dict(dt=4.0, coordinates="jacobi", corrector=order)
        r1, _, s1 = wh.run(newtonian_rhs(), r0, v0, gm, one, **kw)
        r2, _, s2 = wh.run(newtonian_rhs(), r0, v0, gm, many, **kw)
        assert s1 == s2 == 9130
        scale = np.linalg.norm(r1[-1] - r1[-1][0], axis=1)
        scale[0] = np.linalg.norm(r1[-1][0])
        assert np.max(np.linalg.norm(r1[-1] - r2[-1], axis=1) / scale) < 1e-9, order


@pytest.fixture(scope="module")
def solar_reference(solar):
    """IAS15 (epsilon = 0, 0.5-day steps) after 50 years: 4.1e-13 from a run with
    0.25-day steps (heliocentric, relative), far below the errors judged with it."""
    _, r0, v0, gm = solar
    t_end = 4.0 * 4565
    sim = nbody_states.to_rebound(r0, v0, gm, "ias15")
    sim.integrator.epsilon = 0.0
    sim.dt = 0.5
    sim.integrate(t_end, exact_finish_time=1)
    r_ref, _ = nbody_states.rebound_state(sim)
    return t_end, r_ref


def test_correctors_reduce_the_error_as_whfasts_do(solar, solar_reference):
    # Solar system, 50 years at dt = 4 days, Jacobi coordinates: the heliocentric
    # position error against IAS15 (measured: no corrector 4.0e-6, order 3 1.5e-7,
    # orders 5-17 5.6e-8, where the eps^2 dt^2 terms no corrector removes take
    # over) falls as WHFast's does with the same corrector (ours / WHFast's
    # 0.99-1.01); the two runs agree to 2e-11.  Bounds: order 3 at most 1/10 of
    # the uncorrected error, orders 5-17 at most 1/2 of order 3's, ours within 10%
    # of WHFast's, and 1e-9 between the two.
    _, r0, v0, gm = solar
    t_end, r_ref = solar_reference
    h_ref = r_ref[1:] - r_ref[0]

    def error(r):
        return float(np.max(np.linalg.norm(r[1:] - r[0] - h_ref, axis=1)
                            / np.linalg.norm(h_ref, axis=1)))

    errors = {}
    for order in (0, 3, 5, 7, 11, 17):
        r, _, _ = wh.run(newtonian_rhs(), r0, v0, gm, np.array([0.0, t_end]), dt=4.0,
                         coordinates="jacobi", corrector=order)
        sim = nbody_states.to_rebound(r0, v0, gm, "whfast")
        sim.dt = 4.0
        sim.integrator.coordinates = "jacobi"
        sim.integrator.corrector = order
        sim.integrator.safe_mode = 0  # the corrector applied once, as ours (per output)
        sim.integrate(t_end, exact_finish_time=0)
        sim.synchronize()
        r_w, _ = nbody_states.rebound_state(sim)
        errors[order] = error(r[-1])
        assert errors[order] <= 1.1 * error(r_w), (order, errors[order], error(r_w))
        scale = np.linalg.norm(r_w - r_w[0], axis=1)
        scale[0] = np.linalg.norm(r_w[0])
        assert np.max(np.linalg.norm(r[-1] - r_w, axis=1) / scale) < 1e-9, order
    assert errors[3] < errors[0] / 10, errors
    for order in (5, 7, 11, 17):
        assert errors[order] < errors[3] / 2, errors


def test_a_shortened_last_step_gets_its_own_corrector(solar):
    # 10 years (3652.5 days) at dt = 2 days: the last step is half a step.  The
    # corrector conjugates a run of equal steps, so the short step is wrapped in
    # its own C(h) ... C(h)^-1, as WHFast (safe_mode 0, exact_finish_time=1) does
    # when its step changes.  Measured against WHFast: 4.9e-12 (order 11) and
    # 1.9e-12 (17); with one corrector of dt around both, 1e-10.  Bound: 2e-11.
    _, r0, v0, gm = solar
    t_end = 3652.5
    for order in (11, 17):
        r, _, _ = wh.run(newtonian_rhs(), r0, v0, gm, np.array([0.0, t_end]), dt=2.0,
                         coordinates="jacobi", corrector=order)
        sim = nbody_states.to_rebound(r0, v0, gm, "whfast")
        sim.dt = 2.0
        sim.integrator.coordinates = "jacobi"
        sim.integrator.corrector = order
        sim.integrator.safe_mode = 0
        sim.integrate(t_end, exact_finish_time=1)
        sim.synchronize()
        r_w, _ = nbody_states.rebound_state(sim)
        h, h_w = r[-1][1:] - r[-1][0], r_w[1:] - r_w[0]
        assert np.max(np.linalg.norm(h - h_w, axis=1) / np.linalg.norm(h_w, axis=1)) < 2e-11


def test_corrector_needs_jacobi():
    r0 = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    v0 = np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    args = (newtonian_rhs(), r0, v0, np.array([1.0, 0.0]), np.array([0.0, 1.0]))
    with pytest.raises(ValueError, match=r"coordinates='jacobi' with `corrector` = 3"):
        wh.run(*args, dt=0.1, corrector=3)
    with pytest.raises(ValueError, match=r"coordinates='jacobi' with `corrector` = 17"):
        wh.run(*args, dt=0.1, corrector=17)
    for bad in (4, 1, 19, 3.5, 3.0, "3", True, None):
        with pytest.raises(ValueError, match=r"`corrector` to be one of 0, 3, 5, 7, 11, 17, got "
                                             + re.escape(repr(bad))):
            wh.run(*args, dt=0.1, coordinates="jacobi", corrector=bad)


def test_integrate_passes_the_wh_options_and_refuses_others():
    """``integrate(..., coordinates=, corrector=)`` runs the same map as ``wh.run``,
    bit for bit; an option a method does not take names itself and what it takes."""
    import astropy.units as u

    from hamilton_orbits import System, integrate

    s = System.solar_system("J2000", bodies=["sun", "jupiter", "saturn"])
    traj = integrate(s, 400 * u.day, method="wh", dt=4 * u.day, coordinates="jacobi",
                     corrector=3)
    r0 = s.r.to_value(u.au)
    v0 = s.v.to_value(u.au / u.day)
    gm = s.gm.to_value(u.au**3 / u.day**2)
    r, _, _ = wh.run(newtonian_rhs(), r0, v0, gm, np.array([0.0, 400.0]), dt=4.0,
                     coordinates="jacobi", corrector=3)
    np.testing.assert_array_equal(traj.final.r.to_value(u.au), r[-1])
    default = integrate(s, 400 * u.day, method="wh", dt=4 * u.day)
    assert not np.array_equal(default.final.r.to_value(u.au), r[-1])  # a different map
    with pytest.raises(ValueError, match=r"Unknown option `coordinates` = 'jacobi' for method "
                                         r"'radau15'; it takes: max_steps, criterion"):
        integrate(s, 4 * u.day, coordinates="jacobi")
    with pytest.raises(ValueError, match=r"Unknown option `corector` = 3 for method 'wh'; "
                                         r"it takes: coordinates, corrector"):
        integrate(s, 4 * u.day, method="wh", dt=1 * u.day, corector=3)


@pytest.mark.parametrize("bodies", [_kw.LANES_FROM, 9, 70, 150])
@pytest.mark.parametrize("per_row_mu", [False, True])
def test_drift_side_by_side_is_the_kernel_one_by_one(bodies, per_row_mu):
    """The drift of many bodies (their Kepler steps side by side, in blocks of
    ``LANE_BLOCK`` lanes) gives the bits of the shared kernel called body by body,
    the bodies the lanes leave (eccentric orbits heading for periapsis, long steps,
    an open orbit) included; one ``mu`` for all (democratic heliocentric) or one a
    row (Jacobi).  A failing body is reported first in order, as by the loop: the
    rows before it moved, those after it not."""
    rng = np.random.default_rng(bodies)
    n = bodies + 1
    a = rng.uniform(0.5, 30.0, n)
    e = np.where(rng.uniform(size=n) < 0.8, rng.uniform(0.0, 0.3, n), rng.uniform(0.9, 1.5, n))
    p = a * np.abs(1.0 - e * e)
    nu = rng.uniform(-1.5, 1.5, n)
    rad = p / (1 + e * np.cos(nu))
    q = np.stack([rad * np.cos(nu), rad * np.sin(nu), rng.normal(0.0, 0.01, n)], 1) @ ROT.T
    u = np.stack([-np.sin(nu), e + np.cos(nu), rng.normal(0.0, 0.01, n)], 1) / np.sqrt(p)[:, None]
    u = u @ ROT.T
    mu = np.cumsum(rng.uniform(1e-7, 1e-3, n)) + 1.0 if per_row_mu else np.array([1.0])
    for tau in (0.05, -0.3, 4.0, 0.0):
        q1, u1 = q.copy(), u.copy()
        assert _kw._kepler_all(q1, u1, mu, tau) == -1
        for i in range(1, n):
            want = _kepler.propagate_uv(*q[i], *u[i], mu[-1 if mu.shape[0] == 1 else i], tau)
            assert tuple(q1[i]) + tuple(u1[i]) == want, (i, tau)
        np.testing.assert_array_equal(q1[0], q[0])
    bad = n // 2
    q[bad] = 0.0  # at the centre: the kernel gives NaN
    q1, u1 = q.copy(), u.copy()
    assert _kw._kepler_all(q1, u1, mu, 0.05) == bad
    assert not np.array_equal(q1[bad - 1], q[bad - 1])
    np.testing.assert_array_equal(q1[bad:], q[bad:])


def _through_the_nested_loop(kernel):
    """``kernel``'s steps taken by the loop of its events' kernel with nothing watched
    (the nested loop: jumps, kick and drift behind their inline wrappers)."""
    def general(*args):
        return kernel(*args[:-1], np.zeros((0, 8)), np.zeros((0, 8)),
                      np.zeros(1, np.int64), args[-1])
    return general


@pytest.mark.parametrize("coordinates", wh.COORDINATES)
@pytest.mark.parametrize("n_massive, n_test, effects", [
    (2, 0, False), (3, 0, False), (6, 0, False), (7, 0, False), (4, 1, False), (3, 0, True),
    (8, 1, True)])
def test_the_unwatched_steps_are_those_of_the_nested_loop(monkeypatch, coordinates, n_massive,
                                                          n_test, effects):
    """Watching no event, the steps run in a loop of their own
    (``_dh_unwatched_steps``, ``_jacobi_unwatched_steps``: the nested one keeps
    reference counting in the loop, ~half a step at N = 2); it gives the nested
    loop's bits, with and without an effect, with a few bodies (the pairs inlined;
    fewer than ``LANES_FROM``, all massive: the ``_few`` entries, which compile
    neither the Kepler lanes nor the spaced kick), many or a test particle, and
    shortened last steps."""
    rng = np.random.default_rng(n_massive + 10 * n_test)
    n = n_massive + n_test
    a = rng.uniform(1.0, 5.0, n - 1)
    ph = rng.uniform(0.0, 2.0 * np.pi, n - 1)
    r0, v0 = np.zeros((n, 3)), np.zeros((n, 3))
    r0[1:] = np.stack([a * np.cos(ph), a * np.sin(ph), 0.02 * a], axis=1)
    v0[1:] = np.stack([-np.sin(ph), np.cos(ph), 0.01 * ph], axis=1) / np.sqrt(a)[:, None]
    gm = np.concatenate([[1.0], rng.uniform(1e-6, 1e-3, n_massive - 1), np.zeros(n_test)])
    t = np.array([0.0, 1.3, 7.0, 7.04, 20.0])
    rhs = newtonian_rhs()
    if effects:
        from hamilton_orbits import Body, System

        system = System([Body(f"b{i}", gm[i], r0[i], v0[i]) for i in range(n)])
        rhs = compile_rhs(system, [{"name": "j2", "body": "b0", "j2": 1e-3, "radius": 0.05}])
        assert rhs.extra is not None

    def run():
        return wh.run(rhs, r0, v0, gm, t, dt=0.05, coordinates=coordinates)

    names = [f"advance_{c}{kind}" for c in ("dh", "jacobi") for kind in ("", "_effects", "_few")]
    called = []
    for name in names:  # (which entry ran: a few massive bodies take ``_few``)
        monkeypatch.setattr(wh._k, name, (lambda f, k: lambda *a: called.append(k) or f(*a))(
            getattr(_kw, name), name))
    flat = run()
    few = n - 1 < _kw.LANES_FROM and n_test == 0 and not effects
    assert set(called) == {f"advance_{coordinates[:6].replace('democr', 'dh')}"
                           f"{'_effects' if effects else '_few' if few else ''}"}
    for name in names:
        watched = getattr(_kw, name.replace("_effects", "").replace("_few", "") + "_watched")
        monkeypatch.setattr(wh._k, name, _through_the_nested_loop(watched))
    nested = run()
    assert flat[2] == nested[2] == 26 + 114 + 1 + 260  # (0.04: one shortened step)
    assert np.array_equal(flat[0], nested[0]) and np.array_equal(flat[1], nested[1])


@pytest.mark.parametrize("t", [[1000.0], [400.0, 800.0, 1000.0], [1e300]],
                         ids=["one-interval", "several-intervals", "huge"])
def test_a_leg_beyond_max_steps_is_refused_before_its_first_step(t):
    """More than ``max_steps`` steps over a leg are refused up front, whether the leg
    is one interval or several each within the limit (999 / 0.5 = 1998 > 1500), and
    a span whose step count overflows is the same error, not an ``OverflowError``;
    the simulation stays where it was."""
    from hamilton_orbits import Body, Simulation, System

    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("p", 1e-3, [1.0, 0, 0], [0, 1.0, 0])])
    sim = Simulation(s, method="wh", dt=0.5, max_steps=1500)
    sim.integrate(1.0)
    with pytest.raises(ValueError, match=r"wh would take about .* steps of dt = 0\.5 over .* "
                                         r"\(max_steps = 1500\)"):
        sim.integrate(t if len(t) > 1 else t[0])
    assert sim.t == 1.0 and sim.steps == 2
    assert sim.integrate(700.0).steps == 1398  # within the limit: run
