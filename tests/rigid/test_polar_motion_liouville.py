"""LiouvillePole: the exact propagator against scipy's DOP853, and its effect bookkeeping."""

import itertools

import astropy.units as u
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from hamilton_orbits import effects
from rigid import earth
from rigid.polar_motion import EFFECTS, LiouvillePole

MAS = (1 * u.mas).to_value(u.rad)


def ode(model, t, m0, **kw):
    """DOP853 on dm/dt = i sigma (m - chi) as two real equations."""

    def f(tt, y):
        d = model.rhs(tt, y[0] + 1j * y[1])
        return [d.real, d.imag]

    sol = solve_ivp(f, (t[0], t[-1]), [m0.real, m0.imag], method="DOP853", t_eval=t,
                    rtol=1e-12, atol=1e-12 * abs(m0), **kw)
    assert sol.success
    return sol.y[0] + 1j * sol.y[1]


# DOP853 at rtol 1e-12 over ~10 periods accumulates ~1e-10 relative (global error grows
# linearly with the number of steps); the comparisons use 1e-9 of the amplitude.
TOL = 1e-9


def test_free_damped_wobble_matches_the_ode():
    model = LiouvillePole(("elastic", "damping"), k2=0.28, Q=80)
    t = np.linspace(0.0, 4000.0, 801)
    m0 = 150 * MAS + 20j * MAS
    m = model.solve(t, m0)
    assert np.max(np.abs(m - ode(model, t, m0))) < TOL * abs(m0)
    # the closed form of the homogeneous equation, independently
    sig = 2 * np.pi / earth.chandler_period(0.28).to_value(u.day) * (1 + 0.5j / 80)
    assert np.max(np.abs(m - m0 * np.exp(1j * sig * t))) < 1e-13 * abs(m0)


def test_annual_excitation_with_damping_matches_the_ode():
    model = LiouvillePole(
        ("elastic", "damping", "annual_excitation"), chandler_period=433 * u.day, Q=100,
        annual_prograde=(30 - 10j) * u.mas, annual_retrograde=(4 + 3j) * u.mas,
        annual_epoch=17.0 * u.day,
    )
    t = np.linspace(0.0, 3650.0, 731)
    m0 = 100 * MAS
    m = model.solve(t * u.day, m0)
    assert np.max(np.abs(m - ode(model, t, m0))) < TOL * abs(m0)


def test_forced_response_at_resonance_is_finite_and_exact():
    """chi = c exp(i sigma t), Q = inf: m = m0 e^{i s t} - i s c t e^{i s t} (secular growth)."""
    t_c = 433.0
    model = LiouvillePole(("elastic", "annual_excitation"), chandler_period=t_c * u.day,
                          annual_period=t_c * u.day, annual_prograde=1e-7)
    t = np.linspace(0.0, 2000.0, 201)
    s = 2 * np.pi / t_c
    m = model.solve(t, 1e-6 + 0j)
    exact = (1e-6 - 1j * s * 1e-7 * t) * np.exp(1j * s * t)
    assert np.max(np.abs(m - exact)) < 1e-14 * np.max(np.abs(exact))


def test_piecewise_linear_series_matches_the_ode():
    rng = np.random.default_rng(7)
    chi_t = np.sort(rng.uniform(0, 3000, 60))
    chi_t = np.concatenate([[0.0], chi_t, [3000.0]])
    chi = (rng.normal(size=chi_t.size) + 1j * rng.normal(size=chi_t.size)) * 50 * MAS
    model = LiouvillePole(("elastic", "damping", "excitation_series"), k2=0.28, Q=60,
                          chi_t=chi_t * u.day, chi=chi * u.rad)
    t = np.linspace(100.0, 3000.0, 400)
    m0 = 80 * MAS
    m = model.solve(t, m0)
    # the ODE solver must be told about the kinks of chi: integrate piece by piece
    knots = np.unique(np.concatenate([[100.0], chi_t[chi_t > 100.0]]))
    y = m0
    ref = np.empty(t.size, complex)
    ref[0] = m0  # t[0] = 100 = t0
    for a, b in itertools.pairwise(knots):
        sel = (t > a) & (t < b)
        tt = np.concatenate([[a], t[sel], [b]])
        seg = ode(model, tt, y if y != 0 else 1e-30)
        ref[sel] = seg[1:-1]
        ref[t == b] = seg[-1]
        y = seg[-1]
    assert np.max(np.abs(m - ref)) < TOL * np.max(np.abs(ref))


def test_series_equal_to_a_constant_shifts_the_pole_exactly():
    """A constant chi is an equilibrium: m = chi + (m0 - chi) e^{i sigma t}."""
    chi0 = (20 + 5j) * MAS
    model = LiouvillePole(("excitation_series",), chi_t=[0.0, 1000.0], chi=[chi0, chi0])
    t = np.linspace(0.0, 1000.0, 11)
    sig = 2 * np.pi / earth.euler_period().to_value(u.day)
    m = model.solve(t, 0.0)
    assert np.max(np.abs(m - (chi0 - chi0 * np.exp(1j * sig * t)))) < 1e-13 * abs(chi0)


def test_only_listed_effects_enter():
    t = np.linspace(0.0, 800.0, 9)
    base = LiouvillePole(("free",))
    assert base.q_inv == 0.0 and np.all(base.excitation(t) == 0)
    assert abs(base.period / earth.euler_period().to_value(u.day) - 1) < 1e-15
    with pytest.raises(ValueError, match="`Q` belongs to effect 'damping'"):
        LiouvillePole(("elastic",), k2=0.28, Q=100)
    with pytest.raises(ValueError, match="annual_prograde"):
        LiouvillePole(("free",), annual_prograde=1e-7)
    with pytest.raises(ValueError, match="exactly one of"):
        LiouvillePole(("elastic",))
    with pytest.raises(ValueError, match="needs the parameter `Q`"):
        LiouvillePole(("damping",))
    with pytest.raises(ValueError, match=r"got 'gr' at index 1"):
        LiouvillePole(("free", "gr"))


def test_units_at_the_boundary():
    model = LiouvillePole(("elastic",), chandler_period=433 * u.day)
    m_deg = model.solve([0, 100] * u.day, (0.2 / 3600) * u.deg)
    m_as = model.solve([0, 100] * u.day, 0.2 * u.arcsec)
    assert m_deg.unit == u.deg
    np.testing.assert_allclose(m_deg.to_value(u.arcsec), m_as.to_value(u.arcsec), rtol=1e-14)
    # a year as the time unit is the same as its days
    m_yr = model.solve([0, 100 / 365.25] * u.yr, 0.2 * u.arcsec)
    np.testing.assert_allclose(m_yr.value, m_as.value, rtol=1e-13)
    with pytest.raises(u.UnitConversionError, match="m0"):
        model.solve([0, 1] * u.day, 0.2 * u.m)
    with pytest.raises(u.UnitConversionError, match="chandler_period"):
        LiouvillePole(("elastic",), chandler_period=433 * u.m)
    with pytest.raises(ValueError, match="chi_t"):
        LiouvillePole(("excitation_series",), chi_t=[0.0, 0.0], chi=[0.0, 1.0])
    series = LiouvillePole(("excitation_series",), chi_t=[0.0, 10.0], chi=[0.0, 1e-7])
    with pytest.raises(ValueError, match="span of `chi_t`"):
        series.solve([0.0, 11.0], 0.0)


def test_effects_are_registered_as_rotation_effects():
    names = effects.known("rotation")
    for name in EFFECTS:
        assert name in names
        spec = effects.get("rotation", name)
        assert spec.kind == "rotation" and spec.reference
    model = effects.get("rotation", "damping").build(Q=50)
    assert model.effects == ("free", "damping") and model.q_inv == 1 / 50


@settings(max_examples=30, deadline=None)
@given(
    q=st.floats(20.0, 1e4),
    t1=st.floats(0.0, 3000.0),
    t2=st.floats(0.0, 3000.0),
    phase=st.floats(-np.pi, np.pi),
)
def test_propagator_composes_and_superposes(q, t1, t2, phase):
    """m(t0 -> t2) = m(t1 -> t2) o m(t0 -> t1) (the exact flow is a semigroup), and the
    forced solution is the free one plus the response to chi from m0 = 0 (linearity)."""
    t1, t2 = sorted((t1, t2))
    chi_p = 30 * MAS * np.exp(1j * phase)
    kw = {"chandler_period": 433.0, "Q": q, "annual_prograde": chi_p,
          "annual_retrograde": 0.1 * chi_p}
    model = LiouvillePole(("elastic", "damping", "annual_excitation"), **kw)
    m0 = 100 * MAS * np.exp(-1j * phase)
    direct = model.solve(np.array([t2]), m0, t0=0.0)[0]
    mid = model.solve(np.array([t1]), m0, t0=0.0)[0]
    composed = model.solve(np.array([t2]), mid, t0=t1)[0]
    scale = abs(m0) + 10 * abs(chi_p)
    assert abs(direct - composed) < 1e-13 * scale
    free = LiouvillePole(("elastic", "damping"), chandler_period=433.0, Q=q)
    forced0 = model.solve(np.array([t2]), 0.0, t0=0.0)[0]
    assert abs(direct - (free.solve(np.array([t2]), m0, t0=0.0)[0] + forced0)) < 1e-13 * scale


def test_overflow_backwards_raises_instead_of_inf():
    model = LiouvillePole(("damping",), Q=1.0)
    with pytest.raises(ValueError, match="overflows"):
        model.solve([1e6, -1e6], 1e-6)


def test_entry_point_declared_for_the_registry():
    """hamilton_orbits finds the rotation effects through its entry-point group, not an
    import of rigid (docs/design.md): the declared target exists and registers them."""
    import importlib
    import re
    from pathlib import Path

    text = (Path(__file__).resolve().parents[2] / "pyproject.toml").read_text()
    section = text.split('[project.entry-points."hamilton_orbits.effects"]')[1].split("\n[")[0]
    module, func = re.search(r'^rigid = "([\w.]+):(\w+)"', section, flags=re.M).groups()
    getattr(importlib.import_module(module), func)()
    assert set(EFFECTS) <= set(effects.known("rotation"))
