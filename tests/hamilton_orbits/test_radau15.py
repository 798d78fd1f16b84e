"""The adaptive Gauss-Radau integrator (hamilton_orbits.integrators.radau15)."""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
from numpy.polynomial import legendre

from hamilton_orbits._validation import ConvergenceError
from hamilton_orbits.effects import newtonian_rhs
from hamilton_orbits.integrators import radau15
from hamilton_orbits.orbit import KeplerOrbit

EPS = np.finfo(float).eps
# a fixed rotation (rows orthonormal: 3-4-5 triangles) so that no orbit lies in
# a coordinate plane
ROT = np.array([[0.36, 0.48, -0.8], [-0.8, 0.6, 0.0], [0.48, 0.64, 0.6]])


def _two_body(e: float, q: float = 1.0, gm_star: float = 1.0, gm_planet: float = 0.0):
    """Star at the origin at rest and a planet at periapsis (the barycentre moves
    uniformly when the planet has mass: that is part of what is tested)."""
    mu = gm_star + gm_planet
    vp = math.sqrt(mu * (1.0 + e) / q)
    r0 = np.array([[0.0, 0.0, 0.0], ROT @ [q, 0.0, 0.0]])
    v0 = np.array([[0.0, 0.0, 0.0], ROT @ [0.0, vp, 0.0]])
    return r0, v0, np.array([gm_star, gm_planet]), mu


def test_radau_spacings_are_the_gauss_radau_nodes():
    # Everhart (1985): the spacings are 0 and the roots of P_7(x) + P_8(x) on
    # [-1, 1] mapped to [0, 1] (x = 2h - 1).  numpy's roots (a few 1e-15) are
    # polished with mpmath at 40 digits; the constants are correctly rounded.
    coef = np.zeros(9)
    coef[7] = 1.0
    coef[8] = 1.0
    x = np.sort(legendre.legroots(coef))
    np.testing.assert_allclose(x[0], -1.0, rtol=0, atol=16 * EPS)
    with mpmath.workdps(40):
        exact = [
            float(
                (mpmath.findroot(lambda y: mpmath.legendre(7, y) + mpmath.legendre(8, y), xi) + 1)
                / 2
            )
            for xi in x[1:]
        ]
    np.testing.assert_array_equal(radau15.RADAU_SPACINGS[1:], exact)


def test_coefficient_matrices_are_inverse():
    # b = C g and g = D b (Rein & Spiegel 2015, eqs. 4-5): D C = 1 to rounding.
    np.testing.assert_allclose(radau15._D @ radau15._C, np.eye(7), rtol=0, atol=64 * EPS)


@pytest.mark.parametrize("e", [0.0, 0.3, 0.7])
@pytest.mark.parametrize("gm_planet", [0.0, 1e-3])
def test_two_body_matches_kepler_after_100_orbits(e, gm_planet):
    # Reference: the exact two-body solution (universal-variable propagation of
    # KeplerOrbit) of the relative motion, mu = G(m1 + m2).  The truncation error
    # at epsilon = 1e-9 is below rounding (the result does not change with tol);
    # what remains is rounding: an energy error of a few ulp (dE/E ~ 1e-15)
    # shifts the mean motion by 3/2 dE/E and the phase by 1.5e-15 n t ~ 1e-12
    # after 100 orbits.  Measured: 2e-15 .. 2.4e-12 (rebound's IAS15 on the
    # same orbits: 1.4e-12 .. 1.9e-11), hence 5e-12.
    tol_phase = 5e-12
    r0, v0, gm, mu = _two_body(e, gm_planet=gm_planet)
    orbit = KeplerOrbit.from_state(r0[1] - r0[0], v0[1] - v0[0], mu)
    t_end = 100.0 * float(orbit.period)
    r, v, steps = radau15.run(newtonian_rhs(), r0, v0, gm, np.array([0.0, t_end]))
    assert steps > 0
    r_ref, v_ref = orbit.propagate(t_end).state()
    scale_r = np.linalg.norm(r_ref)
    scale_v = np.linalg.norm(v_ref)
    rel_r = np.linalg.norm(r[-1, 1] - r[-1, 0] - r_ref) / scale_r
    rel_v = np.linalg.norm(v[-1, 1] - v[-1, 0] - v_ref) / scale_v
    assert rel_r < tol_phase and rel_v < tol_phase, (rel_r, rel_v)
    # the energy of the relative orbit (Hamilton's vis viva, integral (E)) to a
    # few ulp: measured at most 12 eps after the ~1e4 steps (a random walk of
    # per-step rounding); 32 eps is the bound
    d = r[-1, 1] - r[-1, 0]
    w = v[-1, 1] - v[-1, 0]
    energy = 0.5 * (w @ w) - mu / np.linalg.norm(d)
    energy0 = 0.5 * (v0[1] @ v0[1]) - mu / np.linalg.norm(r0[1])
    assert abs(energy / energy0 - 1.0) < 32 * EPS
    # the barycentre moves uniformly (Hamilton's integral (C)); it starts with
    # velocity gm_planet v_planet / mu
    bary = (gm[:, None] * r[-1]).sum(0) / mu
    bary_ref = (gm[:, None] * (r0 + t_end * v0)).sum(0) / mu
    np.testing.assert_allclose(bary, bary_ref, rtol=0, atol=1e-13 * (1.0 + t_end * 1e-3))


def test_lands_exactly_on_output_times():
    r0, v0, gm, _ = _two_body(0.5)
    t_out = np.array([0.0, 0.1, 0.1 + 1e-9, 3.0, 17.25])
    r, _, _ = radau15.run(newtonian_rhs(), r0, v0, gm, t_out)
    # the same end state from one interval: intermediate outputs only shorten steps
    r1, _, _ = radau15.run(newtonian_rhs(), r0, v0, gm, t_out[[0, -1]])
    orbit = KeplerOrbit.from_state(r0[1], v0[1], 1.0)
    for i, t in enumerate(t_out):
        ref = orbit.propagate(t).state()[0] if t > 0 else r0[1]
        np.testing.assert_allclose(r[i, 1], ref, rtol=0, atol=1e-14 * (1 + t))
    np.testing.assert_allclose(r[-1], r1[-1], rtol=0, atol=1e-13)


def test_fixed_step_mode_converges_at_high_order():
    # Fixed dt over one orbit of e = 0.5: the error falls like dt^p.  Between 12
    # and 32 steps per orbit (coarse enough to stay above rounding) the measured
    # slope is 11 (the asymptotic 15 is not reached with so few steps per
    # perihelion passage); a slope above 10 rules out any low-order defect
    # (a wrong coefficient anywhere drops the order to 8 or less).
    r0, v0, gm, _ = _two_body(0.5)
    orbit = KeplerOrbit.from_state(r0[1], v0[1], 1.0)
    t_end = float(orbit.period)
    ref = orbit.propagate(t_end).state()[0]
    n_steps = np.array([12, 16, 20, 24, 32])
    errs = []
    for n in n_steps:
        r, _, steps = radau15.run(newtonian_rhs(), r0, v0, gm, np.array([0.0, t_end]), dt=t_end / n)
        assert steps == n
        errs.append(np.linalg.norm(r[-1, 1] - ref))
    slope = np.polyfit(np.log(t_end / n_steps), np.log(errs), 1)[0]
    assert slope > 10.0, (slope, errs)


def test_bad_input_names_the_argument():
    r0, v0, gm, _ = _two_body(0.5)
    with pytest.raises(ValueError, match=r"`gm` >= 0, got -1.0 at index 1"):
        radau15.run(newtonian_rhs(), r0, v0, np.array([1.0, -1.0]), np.array([0.0, 1.0]))
    with pytest.raises(ValueError, match=r"`t_out` to be strictly increasing, got 0.5 at index 2"):
        radau15.run(newtonian_rhs(), r0, v0, gm, np.array([0.0, 1.0, 0.5]))
    with pytest.raises(ValueError, match=r"`tol` > 0, got -1e-09"):
        radau15.run(newtonian_rhs(), r0, v0, gm, np.array([0.0, 1.0]), tol=-1e-9)
    with pytest.raises(ValueError, match=r"`r0` to be finite, got nan at index \(1, 0\)"):
        bad = r0.copy()
        bad[1, 0] = np.nan
        radau15.run(newtonian_rhs(), bad, v0, gm, np.array([0.0, 1.0]))


def test_collision_is_an_error_not_nan():
    # a radial free fall from rest hits the centre at t = pi/(2 sqrt 2) (G M = 1, r = 1)
    r0 = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    v0 = np.zeros((2, 3))
    with pytest.raises(ConvergenceError, match=r"radau15 stopped at t = "):
        radau15.run(newtonian_rhs(), r0, v0, np.array([1.0, 0.0]), np.array([0.0, 2.0]))
