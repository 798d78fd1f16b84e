"""Reliability of rigid's public API (issue 7, rigid part; issue 9, item 6).

Every reproducer of the issue is a test here; then the unit boundary walked over
every public function's arguments (a table), then a property test of the
contract: finite input gives finite output or a ValueError / UnitConversionError
naming the argument, never a warning or a bare kernel error.
"""

from __future__ import annotations

import contextlib
import functools
import re
import warnings

import astropy.units as u
import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import rigid
from hamilton_orbits import Quaternion
from rigid import (
    BodyTorque,
    GravityGradientTorque,
    RigidBody,
    SpaceTorque,
    confocal,
    confocal_rotation,
    contrafocal,
    disk_equivalent,
    free_motion,
    free_motion_arrays,
    free_parameters,
    integrate,
    plot_poinsot,
    poinsot,
    time_between,
)
from rigid.euler import euler_equations, quaternion_rate, torque_on

EPS = np.finfo(float).eps
KGM2 = u.kg * u.m**2
RADS = u.rad / u.s
Q0 = [0.9, 0.1, -0.3, 0.2]


def qbody():
    return RigidBody([1.0, 2.0, 3.0] * KGM2, Q0, [1.0, 0.3, 0.8] * RADS)


# --- item 1: units --------------------------------------------------------------------------


def test_attitude_in_metres_is_refused():
    with pytest.raises(u.UnitConversionError, match="`attitude` to be dimensionless"):
        RigidBody([1.0, 2.0, 3.0] * KGM2, attitude=[1.0, 0.0, 0.0, 0.0] * u.m)
    with pytest.raises(u.UnitConversionError, match="`attitude` to be dimensionless"):
        RigidBody([1.0, 2.0, 3.0], attitude=[1.0, 0.0, 0.0, 0.0] * u.deg)  # not an angle
    # a dimensionless Quantity is a plain quaternion
    body = RigidBody([1.0, 2.0, 3.0], attitude=[2.0, 0.0, 0.0, 0.0] * u.one)
    assert body.attitude.as_array().tolist() == [1.0, 0.0, 0.0, 0.0]


def test_integrate_refuses_quantity_end_with_plain_step():
    body = RigidBody([1.0, 2.0, 3.0], omega=[1.0, 0.3, 0.8])
    with pytest.raises(ValueError, match=r"Expected `dt` to be a Quantity like `t`"):
        integrate(body, 1.0 * u.s, dt=0.1)
    with pytest.raises(ValueError, match=r"Expected `t` to be a Quantity like `dt`"):
        integrate(body, 1.0, dt=0.1 * u.s)
    with pytest.raises(ValueError, match=r"Expected `t` to be a Quantity like `body`"):
        integrate(qbody(), 1.0, dt=0.1)


def test_integrate_in_other_time_units():
    # 1 min at 1 s steps equals 60 s at 1 s steps: the same run, t in the caller's unit.
    tr_min = integrate(qbody(), [0.5, 1.0] * u.min, dt=1.0 * u.s, method="splitting2")
    tr_s = integrate(qbody(), [30.0, 60.0] * u.s, dt=1.0 * u.s, method="splitting2")
    assert tr_min.t.unit == u.min and tr_min.t.to_value(u.s).tolist() == [0.0, 30.0, 60.0]
    np.testing.assert_array_equal(tr_min.omega.value, tr_s.omega.value)
    assert tr_min.moments.unit == KGM2 and tr_min.omega.unit == RADS
    assert tr_min.kinetic_energy.unit == u.J
    assert tr_min.angular_momentum_space.unit == KGM2 / u.s
    # T = (A p^2 + B q^2 + C r^2) / 2 = (1 + 0.18 + 1.92) / 2 at t = 0, by hand
    assert tr_min.kinetic_energy[0].to_value(u.J) == pytest.approx(1.55, rel=4 * EPS)


def test_poinsot_keeps_the_times_as_given():
    # Issue 7 reproducer: poinsot(t in ms).t held the ms numbers of a run in seconds.
    body = RigidBody([1.0, 2.0, 3.0], omega=[1.0, 0.3, 0.8])
    t = [0.0, 500.0, 1000.0] * u.ms
    paths = poinsot(body, t)
    assert paths.t.unit == u.ms and paths.t.value.tolist() == [0.0, 500.0, 1000.0]
    plain = poinsot(body, [0.0, 0.5, 1.0])
    np.testing.assert_array_equal(paths.polhode.value, plain.polhode)
    # the ellipsoid x . I x = 1 lives in (kg m^2)^(-1/2); rho . I rho = 1 (a few ulp)
    unit = (u.kg * u.m**2) ** -0.5
    assert paths.polhode.unit == unit and paths.distance.unit == unit
    rho = plain.polhode
    np.testing.assert_allclose(np.sum([1.0, 2.0, 3.0] * rho**2, axis=-1), 1.0, rtol=8 * EPS)
    # the distance sqrt(2T)/|L| by hand: 2T = 3.1, L^2 = 1 + 0.36 + 5.76 = 7.12
    assert float(plain.distance) == pytest.approx(np.sqrt(3.1 / 7.12), rel=4 * EPS)
    with pytest.raises(ValueError, match="Expected `t` to be a Quantity like `body`"):
        poinsot(qbody(), [0.0, 1.0])


def test_state_and_results_are_quantities_for_a_quantity_body():
    body = qbody()
    assert body.moments.unit == KGM2 and body.omega.unit == RADS
    _, w = free_motion(body, [0.0, 1.0] * u.s)
    assert w.unit == RADS
    par = free_parameters(body)
    assert par.period.unit == u.s and par.flip_interval.unit == u.s and par.lam.unit == 1 / u.s
    # the flip interval is half the period (exactly, both 2K/lam and 4K/lam in floats)
    assert par.period.value == 2.0 * par.flip_interval.value
    plain = free_parameters(RigidBody([1.0, 2.0, 3.0], Q0, [1.0, 0.3, 0.8]))
    assert plain.period == par.period.value
    # confocal: 1/A' = 1/A + lam, same L; in Quantities for a body with units
    lam = 0.1 / KGM2
    cb = confocal(body, lam)
    assert cb.moments.unit == KGM2
    np.testing.assert_allclose(1.0 / cb.moments.value, 1.0 / body.moments.value + 0.1,
                               rtol=2 * EPS)
    np.testing.assert_allclose(cb.angular_momentum_body.value, body.angular_momentum_body.value,
                               rtol=4 * EPS)
    assert contrafocal(body, 2.0 / KGM2).omega.unit == RADS
    rot = confocal_rotation(body, lam, [0.0, 1.0] * u.s)
    assert rot.shape == (2,)
    disk, _, lam_d, delta = disk_equivalent(body)
    assert disk.moments.unit == KGM2 and lam_d.unit == 1 / KGM2 and delta.unit == RADS**2
    _, w25 = free_motion(body, 2.5 * u.s)
    dt = time_between(body, body.omega, w25)
    assert dt.unit == u.s and dt.value == pytest.approx(2.5, rel=1e-13)
    # the same answers in g cm^2 and deg/s: units convert, results are SI Quantities
    other = RigidBody([1e7, 2e7, 3e7] * u.g * u.cm**2, Q0,
                      np.rad2deg([1.0, 0.3, 0.8]) * u.deg / u.s)
    np.testing.assert_allclose(free_motion(other, 1.0 * u.s)[1].value,
                               free_motion(body, 1.0 * u.s)[1].value, rtol=64 * EPS)


# --- item 3 is in test_free.py (thin symmetric bodies) -------------------------------------
# --- item 4: overflow in the attitude --------------------------------------------------------


def test_huge_attitude_is_normalised_with_scaling():
    # Issue 7 reproducer: [1e300, 1e300, 0, 0] stored a zero quaternion with a warning.
    body = RigidBody([1.0, 2.0, 3.0], attitude=[1e300, 1e300, 0.0, 0.0])
    np.testing.assert_allclose(body.attitude.as_array(), [0.5**0.5, 0.5**0.5, 0.0, 0.0],
                               rtol=EPS, atol=0)
    tiny = RigidBody([1.0, 2.0, 3.0], attitude=[0.0, 0.0, 3e-320, 4e-320])  # subnormals
    np.testing.assert_allclose(tiny.attitude.as_array(), [0.0, 0.0, 0.6, 0.8], rtol=1e-3)
    q, _ = free_motion_arrays([1.0, 2.0, 3.0], [1e300, 1e300, 0.0, 0.0], [0.0, 0.0, 1.0], 0.0)
    np.testing.assert_allclose(q, [0.5**0.5, 0.5**0.5, 0.0, 0.0], rtol=EPS, atol=0)


# --- item 5: no bare ZeroDivisionError; homogeneous problems scaled --------------------------


def test_tiny_spin_is_well_posed():
    # Issue 7 reproducer: omega = 1e-200 raised ZeroDivisionError.  Over t = 1 s the body
    # turns by 1.7e-200 rad, so omega stays omega0 to ~1e-200 relative and the attitude
    # is the identity to within that angle (plus rounding).
    w0 = [1e-200] * 3
    att, w = free_motion(RigidBody([1.0, 2.0, 3.0], omega=w0), 1.0)
    np.testing.assert_allclose(w, w0, rtol=4 * EPS)
    assert abs(att.as_array()[0] - 1.0) <= EPS and np.abs(att.as_array()[1:]).max() < 1e-199
    # homogeneity: omega(t; s omega0) = s omega(s t; omega0), s = 2^-660 exactly
    s = 2.0**-660
    q_ref, w_ref = free_motion_arrays([1.0, 2.0, 3.0], Q0, [1.0, 0.3, 0.8], 7.0)
    q_s, w_s = free_motion_arrays([1.0, 2.0, 3.0], Q0, np.array([1.0, 0.3, 0.8]) * s, 7.0 / s)
    # powers of two scale exactly: the kernel sees the very same numbers
    np.testing.assert_array_equal(w_s / s, w_ref)
    np.testing.assert_array_equal(q_s, q_ref)


@pytest.mark.parametrize("scale", [1e-300, 1e300, 2.0**-1000, 2.0**1000])
def test_extreme_moments_scale_out(scale):
    # Issue 7 reproducer: RigidBody([1e-300, 2e-300, 3e-300]) then free motion raised
    # ZeroDivisionError (1e300: NaN).  The motion depends on the ratios of the moments
    # only: for a power-of-two scale the answer is bit-identical, for 1e+-300 the
    # ratios round (1 ulp), which moves the state by ~eps x the angle (~10 rad here).
    ref_q, ref_w = free_motion_arrays([1.0, 2.0, 3.0], Q0, [1.0, 0.3, 0.8], [0.0, 3.0, 10.0])
    body = RigidBody(np.array([1.0, 2.0, 3.0]) * scale, Q0, [1.0, 0.3, 0.8])
    att, w = free_motion(body, [0.0, 3.0, 10.0])
    tol = 0.0 if np.log2(scale).is_integer() else 64 * EPS
    np.testing.assert_allclose(w, ref_w, rtol=0, atol=tol)
    np.testing.assert_allclose(att.as_array(), ref_q, rtol=0, atol=tol)
    assert np.isfinite(body.kinetic_energy) and body.kinetic_energy > 0.0


INTEGRATE_METHODS = ["splitting2", "splitting4", "exact_kick", "rk4", "cayley_rk4", "dop853"]


@pytest.mark.parametrize("method", INTEGRATE_METHODS)
@pytest.mark.parametrize("s", [2.0**-660, 2.0**-500, 2.0**500])
def test_integrate_is_homogeneous_in_the_rates(method, s):
    # omega(t; s omega0) = s omega(s t; omega0), the gravity gradient's GM/R^3 by s^2 and
    # its mean motion by s: integrate scales the rates by powers of two before the
    # kernels, so the run on 2^-660 rad/s (Euler's equations underflowed: exact_kick
    # divided by zero) and on 2^500 rad/s (overflowed) is the unit run bit for bit.
    # (The gravity gradient where GM/R^3 s^2 is a normal number: s >= 2^-511.)
    t = np.linspace(0.0, 10.0, 5)
    cases = [(None, None)]
    if s >= 2.0**-511:
        cases.append((GravityGradientTorque(0.5, mean_motion=0.1),
                      GravityGradientTorque(0.5 * s * s, mean_motion=0.1 * s)))
    for torque, scaled in cases:
        ref = integrate(RigidBody([1.0, 2.0, 3.0], Q0, [1.0, 0.3, 0.8]), t, dt=0.01,
                        method=method, torque=torque)
        got = integrate(RigidBody([1.0, 2.0, 3.0], Q0, np.array([1.0, 0.3, 0.8]) * s), t / s,
                        dt=0.01 / s, method=method, torque=scaled)
        np.testing.assert_array_equal(got.omega / s, ref.omega)
        np.testing.assert_array_equal(got.attitude.as_array(), ref.attitude.as_array())


@pytest.mark.parametrize("method", INTEGRATE_METHODS)
@pytest.mark.parametrize("s", [2.0**-1000, 2.0**1000])
def test_integrate_is_homogeneous_in_the_moments(method, s):
    # I omega' = N - omega x I omega is homogeneous in (I, N): moments 2^-1000 with the
    # torque 2^-1000 times as large run as the unit body, bit for bit, for a body- and
    # a space-fixed torque and the gravity gradient (which does not depend on I's scale).
    t = np.linspace(0.0, 10.0, 5)
    n = np.array([0.1, 0.0, 0.2])
    for torque, scaled in ((BodyTorque(n), BodyTorque(n * s)),
                           (SpaceTorque(n), SpaceTorque(n * s)),
                           (GravityGradientTorque(0.5), GravityGradientTorque(0.5))):
        ref = integrate(RigidBody([1.0, 2.0, 3.0], Q0, [1.0, 0.3, 0.8]), t, dt=0.01,
                        method=method, torque=torque)
        got = integrate(RigidBody(np.array([1.0, 2.0, 3.0]) * s, Q0, [1.0, 0.3, 0.8]), t,
                        dt=0.01, method=method, torque=scaled)
        np.testing.assert_array_equal(got.omega, ref.omega)
        np.testing.assert_array_equal(got.attitude.as_array(), ref.attitude.as_array())


@pytest.mark.parametrize(
    ("moments", "match"),
    [
        ([0.0, 1.0, 1.0], r"Expected `moments` > 0, got 0.0 at index 0"),
        ([-1.0, 2.0, 3.0], r"Expected `moments` > 0, got -1.0 at index 0"),
        ([1.0, 2.0, 5.0], r"Expected `moments` to satisfy A \+ B >= C, got 5.0 at index 2"),
        ([1.0, np.nan, 2.0], r"Expected `moments` to be finite, got nan at index 1"),
        ([1.0 + 1j, 2.0, 3.0], r"Expected `moments` to be real, got complex"),
        ([1.0, 2.0], r"Expected `moments` to have shape \(3,\), got \(2,\)"),
    ],
)
def test_free_motion_arrays_checks_the_moments(moments, match):
    # Issue 7 reproducers: [0, 1, 1] raised ZeroDivisionError, [-1, 2, 3] gave NaN.
    with pytest.raises(ValueError, match=match):
        free_motion_arrays(moments, [1.0, 0.0, 0.0, 0.0], [1.0, 2.0, 3.0], 1.0)


def test_complex_state_is_refused():
    with pytest.raises(ValueError, match="Expected `omega0` to be real"):
        free_motion_arrays([1.0, 2.0, 3.0], [1, 0, 0, 0], [1.0, 2.0j, 3.0], 1.0)
    with pytest.raises(ValueError, match="Expected `t` to be real"):
        free_motion_arrays([1.0, 2.0, 3.0], [1, 0, 0, 0], [1.0, 2.0, 3.0], 1.0j)
    with pytest.raises(ValueError, match="Expected `omega` to be real"):
        RigidBody([1.0, 2.0, 3.0], omega=[1.0, 2.0j, 3.0])


def test_angle_beyond_float64_is_refused():
    with pytest.raises(ValueError, match=r"Expected `t` \* \|omega\| to be finite"):
        free_motion(RigidBody([1.0, 2.0, 3.0], omega=[1e200, 1e200, 1e200]), 1e200)
    with pytest.raises(ValueError, match="representable kinetic energy"):
        integrate(RigidBody([1e300, 2e300, 3e300], omega=[1e10, 1.0, 1.0]), 1.0, dt=0.1)


# --- item 7: messages name the user's argument ----------------------------------------------


def test_messages_name_the_users_argument():
    body = RigidBody([1.0, 2.0, 3.0], omega=[1.0, 1.0, 1.0])
    with pytest.raises(ValueError, match=r"Expected `t` to be finite, got nan at index 1"):
        free_motion(body, [0.0, np.nan])
    with pytest.raises(ValueError, match=r"Expected `t` to be finite, got nan"):
        integrate(body, np.nan, dt=0.1)
    with pytest.raises(ValueError, match=r"Expected `dt` to be finite, got inf"):
        integrate(body, 1.0, dt=np.inf)
    # Issue 7 reproducer: named `angle`
    with pytest.raises(ValueError, match=r"Expected `lam` to be finite, got nan"):
        confocal_rotation(body, np.nan, 1.0)
    with pytest.raises(ValueError, match=r"Expected `lam` to be a scalar, got shape \(2,\)"):
        confocal(body, [0.1, 0.2])
    # Issue 7 reproducer: integrate(None) raised AttributeError
    with pytest.raises(ValueError, match=r"Expected `body` to be a RigidBody, got None"):
        integrate(None, 1.0, dt=0.1)
    with pytest.warns(DeprecationWarning, match="`n_out=` is deprecated"), pytest.raises(
            ValueError, match=r"`n_out` to be an integer in \[2, 1e9\], got None"):
        integrate(body, 1.0, dt=0.1, n_out=None)
    with pytest.raises(ValueError, match=r"Expected `method` to be one of"):
        integrate(body, 1.0, dt=0.1, method=None)
    with pytest.raises(ValueError, match=r"Expected `dt` to give at most 1e\+12 steps"):
        integrate(body, 1e300, dt=1.0)
    for f in (free_motion, free_parameters, poinsot, disk_equivalent):
        args = (None, 1.0) if f in (free_motion, poinsot) else (None,)
        with pytest.raises(ValueError, match=r"Expected `body` to be a RigidBody, got None"):
            f(*args)


# --- item 14: representation ------------------------------------------------------------------


def test_repr_and_str_show_units():
    body = qbody()
    text = str(body)
    assert "m2 kg" in text and "rad / s" in text
    assert re.search(r"moments \[1\. 2\. 3\.\] m2 kg", text)
    # repr round-trips (astropy's units as `u`)
    again = eval(repr(body), {"u": u, "RigidBody": RigidBody})
    np.testing.assert_array_equal(again.moments.value, body.moments.value)
    np.testing.assert_array_equal(again.omega.value, body.omega.value)
    # renormalising a unit quaternion may move it by an ulp
    np.testing.assert_allclose(again.attitude.as_array(), body.attitude.as_array(), atol=2 * EPS)
    plain = RigidBody([1.0, 2.0, 3.0], omega=[0.5, 0.0, 0.0])
    assert "SI" in str(plain) and "rad / s" in str(plain)
    assert eval(repr(plain), {"RigidBody": RigidBody}).omega.tolist() == [0.5, 0.0, 0.0]


# --- the unit boundary, walked over every public function's arguments ------------------------

BODY_F = RigidBody([1.0, 2.0, 3.0], Q0, [1.0, 0.3, 0.8])
W3 = [1.0, 0.3, 0.8] * RADS
I3 = [1.0, 2.0, 3.0] * KGM2


@functools.cache
def _w25() -> u.Quantity:
    """The spin of ``qbody()`` after 2.5 s, made at the first test that asks (not at
    collection: every test process would compile the free motion's kernel there)."""
    return free_motion(qbody(), 2.5 * u.s)[1]


# (label, argument name, call with the argument given the wrong dimension `bad`)
UNIT_TABLE = [
    ("RigidBody", "inertia", lambda bad: RigidBody([1.0, 2.0, 3.0] * bad, omega=W3)),
    ("RigidBody", "omega", lambda bad: RigidBody(I3, omega=[1.0, 0.3, 0.8] * bad)),
    ("RigidBody", "attitude", lambda bad: RigidBody(I3, [1.0, 0.0, 0.0, 0.0] * bad, W3)),
    ("free_motion", "t", lambda bad: free_motion(qbody(), 1.0 * bad)),
    ("free_motion_arrays", "moments", lambda bad: free_motion_arrays(I3.value * bad, Q0, W3,
                                                                     1.0 * u.s)),
    ("free_motion_arrays", "q0", lambda bad: free_motion_arrays(I3, np.array(Q0) * bad, W3,
                                                                1.0 * u.s)),
    ("free_motion_arrays", "omega0", lambda bad: free_motion_arrays(I3, Q0, W3.value * bad,
                                                                    1.0 * u.s)),
    ("free_motion_arrays", "t", lambda bad: free_motion_arrays(I3, Q0, W3, 1.0 * bad)),
    ("integrate", "t", lambda bad: integrate(qbody(), 1.0 * bad, dt=0.1 * u.s)),
    ("integrate", "dt", lambda bad: integrate(qbody(), 1.0 * u.s, dt=0.1 * bad)),
    ("poinsot", "t", lambda bad: poinsot(qbody(), [0.0, 1.0] * bad)),
    ("plot_poinsot", "t", lambda bad: plot_poinsot(qbody(), [0.0, 1.0] * bad)),
    ("confocal", "lam", lambda bad: confocal(qbody(), 0.1 * bad)),
    ("contrafocal", "lam", lambda bad: contrafocal(qbody(), 2.0 * bad)),
    ("confocal_rotation", "lam", lambda bad: confocal_rotation(qbody(), 0.1 * bad, 1.0 * u.s)),
    ("confocal_rotation", "t", lambda bad: confocal_rotation(qbody(), 0.1 / KGM2, 1.0 * bad)),
    ("time_between", "omega1", lambda bad: time_between(qbody(), W3.value * bad, _w25())),
    ("time_between", "omega2", lambda bad: time_between(qbody(), W3, _w25().value * bad)),
    ("BodyTorque", "torque", lambda bad: BodyTorque([0.0, 0.0, 1.0] * bad)),
    ("SpaceTorque", "torque", lambda bad: SpaceTorque([0.0, 0.0, 1.0] * bad)),
    ("GravityGradientTorque", "gm_over_r3", lambda bad: GravityGradientTorque(1.0 * bad)),
    ("GravityGradientTorque", "mean_motion",
     lambda bad: GravityGradientTorque(1.0 / u.s**2, mean_motion=1.0 * bad)),
    ("GravityGradientTorque", "phase",
     lambda bad: GravityGradientTorque(1.0 / u.s**2, phase=1.0 * bad)),
    ("GravityGradientTorque", "e1", lambda bad: GravityGradientTorque(1.0, e1=[1, 0, 0] * bad)),
    ("euler_equations", "moments", lambda bad: euler_equations(I3.value * bad, W3)),
    ("euler_equations", "omega", lambda bad: euler_equations(I3, W3.value * bad)),
    ("euler_equations", "torque", lambda bad: euler_equations(I3, W3, [0, 0, 1] * bad)),
    ("torque_on", "moments", lambda bad: torque_on(BodyTorque([0, 0, 1]), I3.value * bad, Q0)),
    ("torque_on", "attitude", lambda bad: torque_on(None, I3, np.array(Q0) * bad)),
    ("torque_on", "t", lambda bad: torque_on(None, I3, Q0, 1.0 * bad)),
    ("quaternion_rate", "attitude", lambda bad: quaternion_rate(np.array(Q0) * bad, W3)),
    ("quaternion_rate", "omega", lambda bad: quaternion_rate(Q0, W3.value * bad)),
]

# public callables of `rigid` without a dimensional argument of their own (the body
# carries its units) or that are classes of results
NO_DIMENSIONAL_ARGUMENT = {"free_parameters", "disk_equivalent", "FreeParameters",
                           "PoinsotPaths", "RigidTrajectory", "FreeMotion", "BodySI"}


def test_unit_table_covers_the_public_api():
    covered = {label for label, _, _ in UNIT_TABLE} | NO_DIMENSIONAL_ARGUMENT
    public = {name for name in rigid.__all__ if callable(getattr(rigid, name))}
    assert public <= covered, f"add these to UNIT_TABLE: {sorted(public - covered)}"


@pytest.mark.parametrize(("label", "name", "call"), UNIT_TABLE,
                         ids=[f"{a}-{b}" for a, b, _ in UNIT_TABLE])
def test_wrong_dimension_names_the_argument(label, name, call):
    # metres fit none of rigid's arguments; a dimensionless one (attitude, e1) also
    # refuses an angle, which is checked with degrees below
    with pytest.raises(u.UnitConversionError, match=f"`{name}`"):
        call(u.m)


@pytest.mark.parametrize(("label", "name", "call"),
                         [row for row in UNIT_TABLE if row[1] in ("attitude", "q0", "e1")])
def test_dimensionless_arguments_refuse_angles(label, name, call):
    with pytest.raises(u.UnitConversionError, match=f"`{name}` to be dimensionless"):
        call(u.deg)


def test_any_unit_of_the_right_dimension_works():
    # degrees per day where rad/s is expected, grams cm^2 for kg m^2, days for seconds
    day = 86400.0
    w_deg_day = np.rad2deg([1e-5, 3e-6, 8e-6]) * day * u.deg / u.day
    b1 = RigidBody([1e7, 2e7, 3e7] * u.g * u.cm**2, Q0, w_deg_day)
    b2 = RigidBody([1.0, 2.0, 3.0] * KGM2, Q0, [1e-5, 3e-6, 8e-6] * RADS)
    np.testing.assert_allclose(b1.omega.value, b2.omega.value, rtol=4 * EPS)
    _, w1 = free_motion(b1, 2.0 * u.day)
    _, w2 = free_motion(b2, 2.0 * day * u.s)
    np.testing.assert_allclose(w1.value, w2.value, rtol=1e-13)
    gg = GravityGradientTorque(1.0 / u.s**2, phase=90.0 * u.deg)
    gr = GravityGradientTorque(1.0 / u.s**2, phase=np.pi / 2 * u.rad)
    np.testing.assert_array_equal(gg.encode()[1], gr.encode()[1])


# --- found by the property test on extreme inputs (issue 32) --------------------------------

TINY_SPHERE = ([1e-300] * 3, [0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 1.0])


@pytest.mark.parametrize("method", ["splitting2", "splitting4", "exact_kick", "rk4",
                                    "cayley_rk4"])
def test_step_far_too_long_on_tiny_moments(method):
    # Hypothesis' reproducer: moments 1e-300, h |omega| = 1.9e10 with rk4 overflowed
    # in |q|^2 (RuntimeWarning in drivers._run_fixed).  A sphere keeps omega exactly,
    # and its motion does not depend on the moments: the run on 1e-300 equals the run
    # on 1 bit for bit, attitudes of unit norm.
    # rk4's |q| grows without bound at such a step (to 1e154): said by a warning
    t = np.linspace(0.0, 7.6e10, 3)

    def drifts():
        return (pytest.warns(RuntimeWarning, match="norm drifted by 1.33e") if method == "rk4"
                else contextlib.nullcontext())

    with drifts():
        tiny = integrate(RigidBody(*TINY_SPHERE), t, dt=1.9e10, method=method)
    with drifts():
        unit = integrate(RigidBody([1.0] * 3, *TINY_SPHERE[1:]), t, dt=1.9e10, method=method)
    np.testing.assert_array_equal(tiny.omega, [[0.0, 0.0, 1.0]] * 3)
    np.testing.assert_array_equal(tiny.attitude.as_array(), unit.attitude.as_array())
    np.testing.assert_allclose(np.linalg.norm(tiny.attitude.as_array(), axis=-1), 1.0,
                               rtol=0, atol=4 * EPS)


def test_dop853_over_a_span_it_cannot_finish_stops_at_once():
    # 7.6e10 rad of steady spin at tol 1e-12 is some 1e11 DOP853 steps: scipy's
    # solver takes no budget, and this run used to go on for days; the pace after
    # its first 100 steps projects far beyond 100 times the budget (1e8 steps)
    import time

    from hamilton_orbits.validation import ConvergenceError

    start = time.perf_counter()
    with pytest.raises(ConvergenceError, match=r"method 'dop853' cannot finish this span: "
                                               r"dop853 reached t = .* of 76000000000.0 in "
                                               r"\d+ steps; .* \(a step far shorter than the "
                                               r"span: a shorter span, or a fixed-step method"):
        integrate(RigidBody(*TINY_SPHERE), np.linspace(0.0, 7.6e10, 3), method="dop853")
    assert time.perf_counter() - start < 60.0  # (a cold cache compiles here too)


@pytest.mark.parametrize("method", ["rk4", "cayley_rk4"])
@pytest.mark.parametrize("torque", [None, GravityGradientTorque(1.0)])
def test_step_far_too_long_for_a_finite_state_names_dt(method, torque):
    # An asymmetric body at h |omega| = 1e5: the Runge-Kutta state leaves float64 (or
    # Cayley's re-centring divides by zero): a ValueError naming `dt`, not a warning.
    body = RigidBody([1e-300, 2e-300, 3e-300], Q0, [1.0, 0.3, 0.8])
    with pytest.raises(ValueError, match=r"Expected `dt` small enough for a (finite|repre"
                                         r"sentable) solution, got .* dt = 100000.0 s"):
        integrate(body, np.linspace(0.0, 4e5, 3), dt=1e5, method=method, torque=torque)


def test_confocal_bodies_at_the_end_of_float64():
    # Hypothesis' reproducer: confocal(body, 1.797e308) and contrafocal(body, -1.797e308)
    # with moments 1e-300 warned of an overflow in 1/A + lam.  1/A' = 1/A + lam is now
    # refused beyond float64 naming `lam`, the index and the values; below it, the body
    # is finite (its moments subnormal, ~5.6e-309, to 2^-1074).
    body = RigidBody([1e-300, 2e-300, 3e-300], Q0, [1.0, 0.3, 0.8])
    big = np.finfo(float).max
    with pytest.raises(ValueError, match=r"Expected `lam` to keep the reciprocal moments "
                                         r"within float64, got 1/A'\[0\] = 1/A \+ lam beyond "
                                         r"it at index 0, with A = 1e-300 and lam = 1.79769"):
        confocal(body, big)
    for f, lam in ((confocal, -big), (confocal, -1.797e308), (contrafocal, -1.797e308)):
        with pytest.raises(ValueError, match=r"Expected `lam` to leave every reciprocal "
                                             r"moment positive, got 1/A'\[0\] = -1.79"):
            f(body, lam)
    cb = confocal(body, 1.797e308)
    recip = 1.0 / body.moments + 1.797e308
    np.testing.assert_allclose(cb.moments, 1.0 / recip, rtol=0, atol=4 * 2.0**-1074)
    np.testing.assert_allclose(cb.angular_momentum_body, body.angular_momentum_body,
                               rtol=4 * EPS)
    assert np.all(np.isfinite(cb.omega))
    assert np.all(np.isfinite(contrafocal(body, 1.797e308).omega))
    # at t = 0 the confocal rotation is the identity, whatever lam |L|
    assert confocal_rotation(body, big, 0.0).as_array().tolist() == [1.0, 0.0, 0.0, 0.0]


# --- the contract, as a property -------------------------------------------------------------

NAMES = ("inertia", "omega", "attitude", "body", "t", "moments", "q0", "omega0", "lam",
         "t_end", "dt", "omega1", "omega2", "torque", "gm_over_r3")

finite = st.floats(allow_nan=False, allow_infinity=False, width=64)
magnitudes = st.sampled_from([0.0, 1e-300, 1e-200, 1e-12, 1.0, 3.0, 1e12, 1e200, 1e300])
signed = st.builds(lambda m, s, f: s * m * f, magnitudes, st.sampled_from([-1.0, 1.0]),
                   st.floats(0.5, 2.0))
value = st.one_of(finite, signed)
vec3 = st.lists(value, min_size=3, max_size=3)
vec4 = st.lists(value, min_size=4, max_size=4)


def _check(call):
    """Run ``call``: finite results, or a ValueError / UnitConversionError naming an argument."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            out = call()
        except (ValueError, u.UnitConversionError) as exc:
            msg = str(exc)
            assert any(f"`{n}`" in msg for n in NAMES), msg
            return None
        except RuntimeWarning as exc:  # (a run whose |q| drifted: its attitude is garbage)
            assert "norm drifted" in str(exc) and "`dt`" in str(exc), str(exc)
            return None
    leaves = out if isinstance(out, tuple) else (out,)
    for leaf in leaves:
        arr = leaf.as_array() if isinstance(leaf, Quaternion) else getattr(leaf, "value", leaf)
        if isinstance(arr, (np.ndarray, float)):
            assert np.all(np.isfinite(arr)), (call, out)
    return out


@settings(deadline=None, max_examples=150)
@example(moments=TINY_SPHERE[0], attitude=TINY_SPHERE[1], omega=TINY_SPHERE[2], t=7.6e10,
         lam=1.797e308, method="rk4")
@example(moments=TINY_SPHERE[0], attitude=TINY_SPHERE[1], omega=TINY_SPHERE[2], t=7.6e10,
         lam=-1.797e308, method="cayley_rk4")
@given(moments=vec3, attitude=vec4, omega=vec3, t=value, lam=value,
       method=st.sampled_from(["splitting2", "splitting4", "exact_kick", "rk4", "cayley_rk4"]))
def test_public_api_contract(moments, attitude, omega, t, lam, method):
    body = _check(lambda: RigidBody(moments, attitude, omega))
    _check(lambda: free_motion_arrays(moments, attitude, omega, [0.0, t]))
    _check(lambda: euler_equations(moments, omega, omega))
    _check(lambda: quaternion_rate(attitude, omega))
    _check(lambda: torque_on(GravityGradientTorque(abs(lam)), moments, attitude, t))
    if body is None:
        return
    for prop in ("kinetic_energy", "angular_momentum_space", "angular_momentum_norm"):
        _check(lambda prop=prop: getattr(body, prop))
    _check(lambda: free_motion(body, [0.0, t]))
    _check(lambda: free_parameters(body))
    _check(lambda: poinsot(body, [0.0, t]))
    _check(lambda: confocal(body, lam))
    _check(lambda: contrafocal(body, lam))
    _check(lambda: confocal_rotation(body, lam, t))
    _check(lambda: disk_equivalent(body))
    _check(lambda: time_between(body, omega, omega))
    _check(lambda: integrate(body, np.linspace(0.0, abs(t), 3), dt=abs(t) / 4.0 if t else 1.0,
                             method=method))
