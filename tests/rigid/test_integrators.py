"""Tests for rigid.integrators: orders, invariants, exact flow + kicks, DOP853."""

from __future__ import annotations

import astropy.units as u
import numpy as np
import pytest

from hamilton_orbits import Quaternion
from hamilton_orbits.trajectory import TrajectoryBase
from rigid import (
    BodyTorque,
    GravityGradientTorque,
    RigidBody,
    SpaceTorque,
    integrate,
)
from rigid._kernels.euler import sin_versin
from rigid.drivers import integrate_arrays
from rigid.free import free_motion_arrays

EPS = np.finfo(float).eps
MOMENTS = np.array([1.0, 2.0, 3.0])
Q0 = Quaternion.from_axis_angle([0.2, -0.5, 0.8], 1.3)
W0 = np.array([0.4, 1.1, -0.3])
BODY = RigidBody(MOMENTS, attitude=Q0, omega=W0)
T_END = 10.0


def _exact(t):
    q, w = free_motion_arrays(MOMENTS, Q0.as_array(), W0, np.asarray(t))
    return Quaternion(q), w


def _error(tr):
    q, w = _exact(tr.t)
    return float(np.max(tr.attitude.rotation_distance(q))), float(np.max(np.abs(tr.omega - w)))


def _rel_dev(x):
    return float(np.max(np.abs(x / x[0] - 1.0)))


@pytest.mark.parametrize(
    ("method", "order", "dt"),
    [("splitting2", 2, 0.02), ("splitting4", 4, 0.08), ("splitting4y", 4, 0.04),
     ("rk4", 4, 0.04)],
)
def test_measured_order_free_body(method, order, dt):
    # Halving dt divides the error by 2^order (4 or 16); asymptotic regime
    # checked at 20 % (the dt are small enough that the next term is < 10 %).
    e1 = _error(integrate(BODY, np.linspace(0.0, T_END, 11), dt=dt, method=method))
    e2 = _error(integrate(BODY, np.linspace(0.0, T_END, 11), dt=dt / 2, method=method))
    for a, b in zip(e1, e2, strict=True):
        assert 0.8 * 2**order < a / b < 1.2 * 2**order


@pytest.mark.parametrize(
    ("method", "order", "dt"), [("splitting2", 2, 0.05), ("splitting4", 4, 0.2),
                                ("splitting4y", 4, 0.05)],
)
def test_splittings_conserve_momentum_to_rounding_and_energy_to_order(method, order, dt):
    a = integrate(BODY, np.linspace(0.0, T_END, 201), dt=dt, method=method)
    b = integrate(BODY, np.linspace(0.0, T_END, 201), dt=dt / 2, method=method)
    # Every sub-flow is an exact rotation: |L| and the space-frame L change only
    # by the random walk of rounding over ~1e3 sub-rotations (~sqrt(n) eps).
    for tr in (a, b):
        assert _rel_dev(np.linalg.norm(tr.angular_momentum_body, axis=-1)) < 1e-13
        ls = tr.angular_momentum_space
        assert np.max(np.abs(ls - ls[0])) < 1e-13 * np.linalg.norm(ls[0])
        assert tr.norm_drift < 1e-14
    # Energy: O(dt^order), ratio 2^order when dt is halved.
    ea = _rel_dev(a.kinetic_energy)
    eb = _rel_dev(b.kinetic_energy)
    assert 0.7 * 2**order < ea / eb < 1.3 * 2**order


def test_splitting_energy_error_bounded_no_drift():
    # Symplectic (Poisson) integrator: the energy error oscillates without
    # secular growth.  Over 2000 s (~40000 steps) its maximum over the last tenth
    # is no larger than over the first tenth (up to the oscillation's envelope).
    tr = integrate(BODY, np.linspace(0.0, 2000.0, 4001), dt=0.05, method="splitting2")
    de = np.abs(tr.kinetic_energy / tr.kinetic_energy[0] - 1.0)
    first, last = de[:400].max(), de[-400:].max()
    assert first > 1e-6  # the error is visible, so the comparison means something
    assert last < 1.5 * first


def test_sin_versin_to_an_ulp():
    # The rotation kernels take sin x and 1 - cos x from Taylor polynomials for
    # |x| < 1/4 and from libm (sin x, 2 sin^2(x/2)) above: both to ~1 ulp relative.
    mpmath = pytest.importorskip("mpmath")
    xs = np.concatenate([np.geomspace(1e-12, 3.0, 400), -np.geomspace(1e-9, 1.0, 100),
                         [0.25 - 1e-12, 0.25]])
    with mpmath.workdps(40):
        for x in xs:
            s, v = sin_versin(float(x))
            assert abs(s - float(mpmath.sin(x))) <= 2 * EPS * abs(s)
            assert abs(v - float(1 - mpmath.cos(x))) <= 2 * EPS * v


def test_splitting_rounding_over_a_million_steps():
    # 1e6 steps = 4e6 sub-rotations: the compensated increments keep |L| and the
    # space-frame L to a few ulp (the plain cos/sin rotations drifted 3e-13
    # here, ~1e-16 per op with a persistent sign).
    tr = integrate(BODY, np.linspace(0.0, 100.0, 5), dt=1e-4, method="splitting2")
    assert _rel_dev(np.linalg.norm(tr.angular_momentum_body, axis=-1)) <= 2 * EPS
    ls = tr.angular_momentum_space
    assert np.max(np.abs(ls - ls[0])) <= 8 * EPS * np.linalg.norm(ls[0])
    assert tr.norm_drift <= 4 * EPS


@pytest.mark.parametrize("moments", [[1.0, 1.0, 2.0], [2.0, 3.0, 3.0], [1.5, 1.5, 1.5]])
def test_splitting4_exact_for_symmetric_bodies_to_rounding(moments):
    # With I_a = I_m (axisymmetric) or the sphere, the Casimir-shifted split has
    # at most one non-zero axis part, which commutes with the Casimir: the method
    # is exact and 2e5 steps (2.6e6 rotations) show only its rounding error.
    body = RigidBody(moments, attitude=Q0, omega=W0)
    tr = integrate(body, np.linspace(0.0, 20.0, 3), dt=1e-4, method="splitting4")
    q, w = free_motion_arrays(np.asarray(moments), Q0.as_array(), W0, np.asarray(tr.t))
    assert float(np.max(tr.attitude.rotation_distance(Quaternion(q)))) < 1e-13
    assert float(np.max(np.abs(tr.omega - w))) < 1e-13


def test_splitting4_error_floor_below_1e12():
    # 10 periods of omega (155 s) at 2^13 steps per period (81920 steps): the
    # truncation error is ~1e-13 and the rounding floor lower (Yoshida's triple
    # jump with plain rotations floored at 6e-11 here).
    period = 15.481839  # of omega for BODY (rigid.free.free_parameters)
    tr = integrate(BODY, np.linspace(0.0, 10 * period, 11), dt=period / 2**13,
                   method="splitting4")
    assert max(_error(tr)) < 1e-12


def test_exact_kick_is_exact_for_the_free_body():
    # The drift is the closed-form free motion: any step size is exact up to the
    # rounding of the exact solution accumulated over 20 steps.
    tr = integrate(BODY, np.linspace(0.0, T_END, 21), dt=0.5, method="exact_kick")
    eq, ew = _error(tr)
    assert eq < 1e-12
    assert ew < 1e-12


def test_dop853_against_exact_and_norm_policy():
    # rtol 1e-13 over 10 s (about four precession periods of this body): the
    # attitude and omega agree with the exact solution to 1e-11.
    tr = integrate(BODY, np.linspace(0.0, T_END, 51), method="dop853", tol=1e-13)
    eq, ew = _error(tr)
    assert eq < 1e-11
    assert ew < 1e-11
    # q is integrated unconstrained and normalised on output: its norm drift is
    # of the order of the integration error, and the output is unit.
    assert tr.norm_drift < 1e-12
    np.testing.assert_allclose(tr.attitude.norm(), 1.0, rtol=0, atol=4 * EPS)
    assert tr.nfev > 0


@pytest.mark.parametrize(
    "torque",
    [SpaceTorque([0.05, -0.02, 0.03]), BodyTorque([0.0, 0.0, 0.0])],
)
@pytest.mark.parametrize("method", ["splitting2", "splitting4", "splitting4y", "exact_kick"])
def test_constant_space_torque_momentum_law(method, torque):
    # dL_space/dt = N: a kick adds N h to L_space exactly and every drift keeps
    # L_space fixed, so L_space(t) = L_space(0) + N t at any step size, to rounding.
    tr = integrate(BODY, np.linspace(0.0, T_END, 11), dt=0.1, method=method, torque=torque)
    _, params = torque.encode()
    n_space = params if isinstance(torque, SpaceTorque) else np.zeros(3)
    ls = tr.angular_momentum_space
    ref = ls[0] + np.asarray(tr.t)[:, None] * n_space
    np.testing.assert_allclose(ls, ref, rtol=0, atol=1e-13 * np.abs(ref).max())


def test_exact_kick_and_splittings_against_dop853_torqued():
    # Gravity-gradient torque on a turning direction: no closed form, so DOP853
    # at rtol 1e-13 is the reference.  exact_kick and splitting2 converge at
    # order 2, splitting4 at order 4 and reaches 1e-9.
    body = RigidBody(MOMENTS, attitude=Q0, omega=W0)
    tq = GravityGradientTorque(0.25, mean_motion=0.5)
    ref = integrate(body, np.linspace(0.0, T_END, 11), method="dop853", tol=1e-13, torque=tq)

    def err(method, dt):
        tr = integrate(body, np.linspace(0.0, T_END, 11), dt=dt, method=method, torque=tq)
        np.testing.assert_allclose(np.asarray(tr.t), np.asarray(ref.t), rtol=0, atol=1e-12)
        return float(np.max(tr.attitude.rotation_distance(ref.attitude)))

    for method, order, dt in (("exact_kick", 2, 0.02), ("splitting2", 2, 0.02),
                              ("splitting4", 4, 0.04), ("splitting4y", 4, 0.04)):
        r = err(method, dt) / err(method, dt / 2)
        assert 0.8 * 2**order < r < 1.2 * 2**order, (method, r)
    assert err("splitting4", 0.005) < 1e-9
    assert err("exact_kick", 0.001) < 1e-5


def test_progress_and_quantities():
    a = integrate(BODY, np.linspace(0.0, T_END * u.s, 5), dt=0.1 * u.s, method="splitting4")
    b = integrate(BODY, np.linspace(0.0, T_END, 5), dt=0.1, method="splitting4", progress=True)
    assert a.t.unit == u.s
    assert a.omega.unit == u.rad / u.s
    np.testing.assert_array_equal(a.attitude.as_array(), b.attitude.as_array())
    np.testing.assert_array_equal(a.omega.to_value(u.rad / u.s), b.omega)
    np.testing.assert_array_equal(b.t, np.linspace(0.0, T_END, 5))


def test_bad_input():
    with pytest.raises(ValueError, match="`method` to be one of"):
        integrate(BODY, 1.0, dt=0.1, method="euler")
    # (the deprecated tolerances were taken and ignored by a fixed-step method)
    with pytest.warns(DeprecationWarning), pytest.raises(
            ValueError, match=r"Expected `rtol` only with method 'dop853' \(a fixed-step "
                              r"method takes `dt`\), got rtol = 1e-06 for method 'splitting4'"):
        integrate(BODY, 1.0, dt=0.1, rtol=1e-6)
    # (a non-finite cayley_rk4 run blamed `dt` alone: a huge `recentre` is the cause)
    with pytest.raises(ValueError, match=r"non-finite state .* with method 'cayley_rk4' .* "
                                         r"\(or a `recentre` of about 1"):
        integrate(RigidBody([1.0, 2.0, 3.0], omega=[0.4, 1.1, -0.3]), 50.0, dt=0.001,
                  method="cayley_rk4", recentre=1e300)
    with pytest.raises(ValueError, match="Expected `dt` for method 'splitting2'"):
        integrate(BODY, 1.0, method="splitting2")
    with pytest.raises(ValueError, match="`t` to be finite, got nan"):
        integrate(BODY, np.nan, dt=0.1)
    with pytest.raises(ValueError, match=r"`t` > 0, got -1.0"):
        integrate(BODY, -1.0, dt=0.1)
    with pytest.raises(ValueError, match=r"`dt` > 0, got 0.0"):
        integrate(BODY, 1.0, dt=0.0)
    with pytest.raises(ValueError, match=r"`t` to be finite, got nan at index 1"):
        integrate(BODY, [1.0, np.nan], dt=0.1)
    with pytest.raises(ValueError, match=r"`t` strictly increasing, got 1.0 after 2.0 at index 2"):
        integrate(BODY, [0.0, 2.0, 1.0], dt=0.1)
    with pytest.raises(ValueError, match=r"`t` >= 0 \(times from the body's state\), got -1.0 at "
                       r"index 0"):
        integrate(BODY, [-1.0, 2.0], dt=0.1)
    with pytest.raises(ValueError, match=r"`t` to be an end time or a 1-d array of output times, "
                       r"got shape \(1, 2\)"):
        integrate(BODY, [[1.0, 2.0]], dt=0.1)
    with pytest.raises(ValueError, match=r"`t` to reach beyond 0"):
        integrate(BODY, [0.0], dt=0.1)
    with pytest.raises(ValueError, match=r"`tol` only with method 'dop853'"):
        integrate(BODY, 1.0, dt=0.1, tol=1e-9)
    with pytest.raises(ValueError, match=r"`tol` > 0, got -1.0"):
        integrate(BODY, 1.0, method="dop853", tol=-1.0)
    with pytest.raises(ValueError, match="Expected `torque` to be None"):
        integrate(BODY, 1.0, dt=0.1, torque=[1.0, 0.0, 0.0])
    with pytest.raises(u.UnitConversionError, match="`dt`"):
        integrate(BODY, 1.0 * u.s, dt=0.1 * u.m)
    with pytest.raises(ValueError, match=r"Expected `t`, an end time or an array of output "
                       r"times, got None"):
        integrate(BODY, dt=0.1)


# --- issue 19: one trajectory shape, one integrate(obj, t, *, method, dt, tol) -------------


@pytest.mark.parametrize("moments", [[1.0, 1.0, 2.0], [2.0, 3.0, 3.0], [1.5, 1.5, 1.5]])
def test_energy_error_of_splitting4_is_rounding_for_symmetric_bodies(moments):
    # splitting4 is exact for these bodies (see above) and its compensated rotations
    # keep T and L_s to an ulp or two over 2e5 steps (measured <= 1.6 eps): the base
    # fields report exactly that, relative to T(0) and |L_s(0)|.
    tr = integrate(RigidBody(moments, attitude=Q0, omega=W0), [10.0, 20.0], dt=1e-4,
                   method="splitting4")
    assert isinstance(tr, TrajectoryBase)
    assert tr.steps == 200_000 and tr.method == "splitting4" and tr.wall_time > 0.0
    assert tr.energy_error.shape == tr.angular_momentum_error.shape == (3,)
    assert tr.energy_error[0] == 0.0 and tr.angular_momentum_error[0] == 0.0
    assert np.max(np.abs(tr.energy_error)) <= 4 * EPS
    assert np.max(tr.angular_momentum_error) <= 8 * EPS


def test_energy_error_of_exact_kick_is_rounding_and_matches_the_definition():
    # exact_kick on the triaxial body: each of the 20 steps re-derives the exact
    # motion from the rounded state, a random walk of a few ulp (measured 4.9 eps
    # in T, 3.9 eps in L_s).
    tr = integrate(BODY, np.linspace(0.0, T_END, 21), dt=0.5, method="exact_kick")
    assert tr.steps == 20 and tr.nfev == 0 and tr.n_recentre == 0
    assert np.max(np.abs(tr.energy_error)) <= 16 * EPS
    assert np.max(tr.angular_momentum_error) <= 16 * EPS
    # the definitions, from the trajectory's own integrals
    energy = tr.kinetic_energy
    np.testing.assert_allclose(tr.energy_error, energy / energy[0] - 1.0, rtol=0, atol=2 * EPS)
    ls = tr.angular_momentum_space
    np.testing.assert_allclose(tr.angular_momentum_error,
                               np.linalg.norm(ls - ls[0], axis=-1) / np.linalg.norm(ls[0]),
                               rtol=0, atol=2 * EPS)


def test_splitting2_energy_error_is_its_truncation_error():
    # not conserved by splitting2 (O(dt^2)), so the field must show it: the same
    # value as the relative change of the kinetic energy, and > 1e-6 at dt = 0.05
    tr = integrate(BODY, np.linspace(0.0, 200.0, 401), dt=0.05, method="splitting2")
    de = tr.kinetic_energy / tr.kinetic_energy[0] - 1.0
    assert np.max(np.abs(de)) > 1e-6
    np.testing.assert_allclose(tr.energy_error, de, rtol=0, atol=2 * EPS)


def test_repr_is_one_line():
    tr = integrate(BODY, T_END * u.s, dt=0.01 * u.s, method="splitting4")
    text = repr(tr)
    assert "\n" not in text and str(tr) == text and len(text) < 160
    assert text.startswith("RigidTrajectory(101 outputs, t = 0 .. 10 s, method='splitting4', "
                           "steps=1000, max |dT/T| = ")


def test_t_as_output_times():
    # DOP853 outputs at the times given (it restarts there); a fixed-step method at
    # the nearest step (here whole steps: 0.3 s = 30 steps of 0.01 s); a start at 0 is
    # added when missing, like the n-body integrate
    times = np.array([0.3, 1.0, 2.5])
    dop = integrate(BODY, times, method="dop853", tol=1e-13)
    assert dop.t.tolist() == [0.0, 0.3, 1.0, 2.5] and dop.steps > 0 and dop.nfev > dop.steps
    fix = integrate(BODY, times, dt=0.01, method="splitting4")
    np.testing.assert_allclose(fix.t, [0.0, 0.3, 1.0, 2.5], rtol=0, atol=4 * EPS)
    assert fix.steps == 250
    assert np.max(fix.attitude.rotation_distance(dop.attitude)) < 1e-8  # splitting4 at 0.01
    # one run to the last time, sampled: the same states as the run to each time
    one = integrate(BODY, [1.0], dt=0.01, method="splitting4")
    np.testing.assert_array_equal(one.attitude.as_array()[-1], fix.attitude.as_array()[2])
    # times nearer a step than dt: the step reached is reported, not the time asked
    odd = integrate(BODY, [0.004, 0.0161, 1.0], dt=0.01, method="rk4")
    np.testing.assert_allclose(odd.t, [0.0, 0.0, 0.02, 1.0], rtol=0, atol=4 * EPS)


def test_t_units_are_the_callers():
    # Quantities in: t in the caller's unit (days here), omega rad/s, moments kg m^2
    body = RigidBody([1.0, 2.0, 3.0] * u.kg * u.m**2, omega=[1e-5, 2e-5, 7e-5] * u.rad / u.s)
    tr = integrate(body, [1.0, 2.0] * u.day, dt=1.0 * u.hour, method="splitting4")
    assert tr.t.unit == u.day and tr.t.value.tolist() == [0.0, 1.0, 2.0]
    assert tr.omega.unit == u.rad / u.s and tr.moments.unit == u.kg * u.m**2
    dop = integrate(body, [1.0, 2.0] * u.day, method="dop853")
    assert dop.t.unit == u.day and dop.t.value.tolist() == [0.0, 1.0, 2.0]
    plain = integrate(RigidBody([1.0, 2.0, 3.0], omega=[0.1, 0.2, 0.7]), [1.0], dt=0.1)
    assert not isinstance(plain.t, u.Quantity) and plain.t.tolist() == [0.0, 1.0]


def test_dop853_tol_sets_both_tolerances_scale_free():
    # tol is relative; the absolute part follows |omega0|, so a body 1e5 times slower,
    # run 1e5 times longer, is integrated to the same relative accuracy in omega (the
    # absolute atol 1e-14 of before would have allowed 1e-9 of its |omega| ~ 1e-5).
    # Steps differ a little: scipy's first-step guess has an absolute floor.
    slow_w0 = W0 * 1e-5
    slow = integrate(RigidBody(MOMENTS, attitude=Q0, omega=slow_w0), [T_END * 1e5],
                     method="dop853", tol=1e-10)
    fast = integrate(BODY, [T_END], method="dop853", tol=1e-10)
    _, w_slow = free_motion_arrays(MOMENTS, Q0.as_array(), slow_w0, np.array(T_END * 1e5))
    _, w_fast = free_motion_arrays(MOMENTS, Q0.as_array(), W0, np.array(T_END))
    err_slow = np.max(np.abs(slow.omega[-1] - w_slow)) / np.max(np.abs(slow_w0))
    err_fast = np.max(np.abs(fast.omega[-1] - w_fast)) / np.max(np.abs(W0))
    assert err_fast < 1e-9 and err_slow < 1e-9
    assert abs(slow.steps - fast.steps) <= 0.2 * fast.steps
    # dt caps the step of dop853, as in the n-body integrate
    capped = integrate(BODY, [T_END], method="dop853", tol=1e-10, dt=0.01)
    assert capped.steps >= 1000


def test_deprecated_keywords_warn_and_keep_working():
    new = integrate(BODY, np.linspace(0.0, T_END, 11), dt=0.1, method="splitting4")
    with pytest.warns(DeprecationWarning, match=r"`t_end=` is deprecated; pass .* as `t`") as rec:
        old = integrate(BODY, t_end=np.linspace(0.0, T_END, 11), dt=0.1, method="splitting4")
    assert rec[0].filename == __file__  # the warning points at the caller
    np.testing.assert_array_equal(old.attitude.as_array(), new.attitude.as_array())
    with pytest.warns(DeprecationWarning, match=r"`n_out=` is deprecated; pass an array of "
                      r"output times as `t`"):
        old = integrate(BODY, T_END, dt=0.1, method="splitting4", n_out=11)
    np.testing.assert_array_equal(old.t, new.t)
    np.testing.assert_array_equal(old.omega, new.omega)
    with pytest.warns(DeprecationWarning,
                      match=r"`RigidTrajectory.n_steps` is deprecated; use `steps`"):
        assert old.n_steps == old.steps == 100
    # rtol / atol are used as they are (as before), with a warning naming `tol`
    with pytest.warns(DeprecationWarning, match=r"`rtol=` is deprecated; pass `tol`"), \
            pytest.warns(DeprecationWarning, match=r"`atol=` is deprecated; pass `tol`"):
        old = integrate(BODY, [T_END], method="dop853", rtol=1e-13, atol=1e-15)
    _, q, w, steps, _, _ = integrate_arrays(MOMENTS, Q0.as_array(), W0, np.array([0.0, T_END]),
                                            method="dop853", rtol=1e-13, atol=1e-15)
    np.testing.assert_array_equal(old.omega, w)
    np.testing.assert_array_equal(old.attitude.as_array(), q)
    assert old.steps == steps


def test_deprecated_keywords_refuse_a_mix_with_the_new_ones():
    with pytest.warns(DeprecationWarning), pytest.raises(ValueError, match="got both"):
        integrate(BODY, 1.0, t_end=1.0, dt=0.1)
    with pytest.warns(DeprecationWarning), pytest.raises(ValueError, match="got both"):
        integrate(BODY, 1.0, method="dop853", tol=1e-9, rtol=1e-9)
    with pytest.warns(DeprecationWarning), pytest.raises(
            ValueError, match=r"`n_out` only with an end time `t`, got an array"):
        integrate(BODY, [0.5, 1.0], dt=0.1, n_out=3)
    with pytest.warns(DeprecationWarning), pytest.raises(
            ValueError, match=r"`n_out` to be an integer in \[2, 1e9\], got 1"):
        integrate(BODY, 1.0, dt=0.1, n_out=1)


@pytest.mark.parametrize("method", ["splitting4", "exact_kick", "rk4", "cayley_rk4"])
def test_stop_ends_a_run_between_chunks_with_the_outputs_reached(method):
    """``stop()`` is asked between chunks of about 1% of the steps: never true, the
    run is the one without it, bit for bit; true after the tenth look, the run ends
    there with the outputs reached, each the whole run's."""
    b = RigidBody([1.0, 2.0, 3.0], omega=[0.1, 1.0, 0.1])
    t = np.linspace(0.0, 50.0, 41)
    whole = integrate(b, t, dt=0.01, method=method)
    looks = []
    same = integrate(b, t, dt=0.01, method=method, stop=lambda: looks.append(1) and False)
    assert len(looks) == 99  # (100 chunks: no look after the last)
    np.testing.assert_array_equal(same.omega, whole.omega)
    np.testing.assert_array_equal(same.attitude.as_array(), whole.attitude.as_array())
    looks.clear()
    cut = integrate(b, t, dt=0.01, method=method,
                    stop=lambda: len(looks.append(1) or looks) >= 10)
    n = len(cut.t)
    assert 2 <= n < len(t) and len(looks) == 10
    np.testing.assert_array_equal(cut.t, whole.t[:n])
    np.testing.assert_array_equal(cut.omega, whole.omega[:n])
    np.testing.assert_array_equal(cut.attitude.as_array(), whole.attitude.as_array()[:n])
    with pytest.raises(ValueError, match=r"Expected `stop` to be callable or None, got 3"):
        integrate(b, t, dt=0.01, method=method, stop=3)


@pytest.mark.parametrize("method", ["splitting4", "rk4", "dop853"])
def test_an_error_of_the_callers_stop_reaches_the_caller_as_it_is(method):
    """An exception raised by the caller's ``stop`` was taken for the run's own
    failure: a ZeroDivisionError became "Expected `dt` small enough ...", a
    ValueError of DOP853's run "Expected `tol` and `dt` within DOP853's reach, got
    <the caller's message>"; it reaches the caller unchanged."""
    b = RigidBody([1.0, 2.0, 2.5], omega=[0.1, 0.5, 1.0])

    def divides():
        return 1 / 0

    def refuses():
        raise ValueError("the caller's own message")

    with pytest.raises(ZeroDivisionError, match="division by zero") as info:
        integrate(b, 50.0, method=method, dt=0.01, stop=divides)
    assert info.traceback[-1].name == "divides"
    with pytest.raises(ValueError, match=r"^the caller's own message$"):
        integrate(b, 50.0, method=method, dt=0.01, stop=refuses)


def test_dop853_asks_stop_and_ends_with_the_outputs_reached():
    """DOP853 ran to the end whatever ``stop()`` said (a rotation scene's Ctrl-C was
    not heard): it asks every ``STOP_EVERY`` steps; never true, the run is the one
    without it, bit for bit; true at the third look, the run ends there with the
    outputs reached, each the whole run's."""
    from hamilton_orbits.integrators.dop853 import STOP_EVERY

    b = RigidBody([1.0, 2.0, 3.0], omega=[0.1, 1.0, 0.1])
    t = np.linspace(0.0, 200.0, 201)
    whole = integrate(b, t, method="dop853")
    assert whole.steps > 5 * STOP_EVERY
    looks = []
    same = integrate(b, t, method="dop853", stop=lambda: looks.append(1) and False)
    assert len(looks) == (whole.steps - 1) // STOP_EVERY
    np.testing.assert_array_equal(same.attitude.as_array(), whole.attitude.as_array())
    np.testing.assert_array_equal(same.omega, whole.omega)
    looks.clear()
    cut = integrate(b, t, method="dop853", stop=lambda: len(looks.append(1) or looks) >= 3)
    n = len(cut.t)
    assert 2 <= n < len(t) and len(looks) == 3
    np.testing.assert_array_equal(cut.t, whole.t[:n])
    np.testing.assert_array_equal(cut.omega, whole.omega[:n])
    np.testing.assert_array_equal(cut.attitude.as_array(), whole.attitude.as_array()[:n])


@pytest.mark.parametrize("method", ["splitting2", "splitting4", "splitting4y", "exact_kick",
                                    "rk4", "cayley_rk4"])
def test_a_run_in_chunks_is_the_run_in_one_call_with_a_torque_of_time(method, monkeypatch):
    """A long run is cut into compiled calls of at most ``_CHUNK`` steps (a Ctrl-C is
    seen between them: it waited for the whole run, 43 s of a 46 s one), and a bar or
    a ``stop`` cuts it into about 100: the same bits as one call, also with a torque
    that depends on time (a chunk from step ``a`` took its time as ``a h + (n - 1) h``
    against ``(a + n - 1) h``: 2e-14 off for splitting4, 9e-12 for exact_kick)."""
    from rigid import drivers
    from rigid.euler import GravityGradientTorque

    b = RigidBody([1.0, 2.0, 3.0], omega=[0.1, 1.0, 0.1])
    kw = dict(dt=0.01, method=method, torque=GravityGradientTorque(0.3, 0.37, 0.1))
    t = np.linspace(0.0, 50.0, 41)
    name = {"exact_kick": "run_exact_kick", "rk4": "run_rk4_quaternion",
            "cayley_rk4": "run_rk4_cayley"}.get(method, "run_splitting")
    kernel, calls = getattr(drivers._k, name), []

    def counted(*args):
        calls.append(args[{"run_splitting": -8, "run_rk4_quaternion": -5}.get(name, -6)])
        # (the call's steps: its argument before ``out_steps``)
        return kernel(*args)

    monkeypatch.setattr(drivers._k, name, counted)
    whole = integrate(b, t, **kw)
    assert calls == [5000]
    monkeypatch.setattr(drivers, "_CHUNK", 700)
    calls.clear()
    cut = integrate(b, t, **kw)
    assert len(calls) == 8 and max(calls) <= 700 and sum(calls) == 5000
    calls.clear()
    stepped = integrate(b, t, stop=lambda: False, **kw)
    assert len(calls) == 100 and sum(calls) == 5000
    for other in (cut, stepped):
        np.testing.assert_array_equal(other.attitude.as_array(), whole.attitude.as_array())
        np.testing.assert_array_equal(other.omega, whole.omega)
        np.testing.assert_array_equal(other.t, whole.t)


def test_a_run_whose_quaternion_norm_drifted_says_so():
    # The rigid Earth with rk4 at a step of one day (its spin turns once a step): |q|
    # grows to 1e9 in 29 steps and the attitude, normalised on output, is over a radian
    # from the exact one (free_motion), with no other sign (|L| and T stay within 1e-7:
    # the error is in the spin's phase).  splitting4 at the same step keeps |q| to 1e-13.
    import warnings

    from rigid import free_motion
    from rigid.earth import rigid_body
    from rigid.integrators import NORM_DRIFT_WARNING

    earth, t = rigid_body(), np.arange(0.0, 30.0) * u.day
    with pytest.warns(RuntimeWarning, match=r"norm drifted by 1.36e\+09 in this rk4 run .* "
                                            r"shorter `dt` than 86400.0 s"):
        bad = integrate(earth, t, dt=1.0 * u.day, method="rk4")
    assert bad.attitude.rotation_distance(free_motion(earth, bad.t).attitude).max() > 1.0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        good = integrate(earth, t, dt=1.0 * u.day, method="splitting4")
    assert good.norm_drift < NORM_DRIFT_WARNING * 1e-9


def test_progress_is_true_or_false():
    # a text was a bar ("no" is true), as in hamilton_orbits' integrate
    with pytest.raises(ValueError, match="`progress` to be True or False, got 'no'"):
        integrate(BODY, 1.0, dt=0.1, method="splitting4", progress="no")
