"""Effects that know the time (issue 35 item 1): the clock every integrator writes
into ``p``'s last element before it evaluates the right-hand side, the kernels of
six arguments that read it, and ``zonal`` / ``earth_tides`` about the Earth's pole
of date (the IAU 2006 precession)."""

from __future__ import annotations

import astropy.units as u
import numpy as np
import pytest
from astropy.time import Time
from numba import njit

from hamilton_orbits import Body, Simulation, System
from hamilton_orbits import effects as fx
from hamilton_orbits import ephemeris as de
from hamilton_orbits._kernels import figures
from hamilton_orbits.rhs import RHS, compile_rhs, newtonian_rhs, takes_time, time_reversed


@njit
def _ramp(r, v, gm, acc, p, t):  # pragma: no cover - compiled
    """``x'' = c (t + 20)`` on every body but the first (``p = [c]``): an effect whose
    value is the time itself (offset: where ``a = 0`` a step control has no scale)."""
    for i in range(1, r.shape[0]):
        acc[i, 0] += p[0] * (t + 20.0)


C = 1e-3  # the ramp's slope
X0, V0 = np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.1, 0.0])


@pytest.fixture(scope="module")
def ramp():
    spec = fx.register(fx.EffectSpec(
        "ramp_test", "nbody", "x'' = c t (test)", parameters={"c": "slope"}, kernel=_ramp,
        params=lambda system, params: np.array([params.get("c", C)])))
    yield "ramp_test"
    fx.registry._REGISTRY["nbody"].pop(spec.name)


def _free() -> System:
    """A particle beside a body of negligible mass (Newton's pull 1e-27 of the
    ramp's): the motion is the ramp's alone, ``x = x0 + v0 t + c (t^3/6 + 10 t^2)``."""
    return System([Body("c", 1e-30, [0, 0, 0], [0, 0, 0]), Body("p", 0.0, X0, V0)])


def _exact(t: float) -> np.ndarray:
    return X0 + V0 * t + np.array([C * (t**3 / 6 + 10 * t**2), 0.0, 0.0])


@pytest.mark.parametrize("t_end", [10.0, -10.0])
@pytest.mark.parametrize(("method", "kw", "rel"), [
    ("radau15", {}, 1e-14),  # (a cubic: radau15's polynomial holds it exactly)
    ("dop853", {"tol": 1e-13}, 1e-12),  # (eighth order: a cubic exactly, to its tolerance)
])
def test_exact_methods_see_the_time_forwards_and_backwards(ramp, method, kw, t_end, rel):
    sim = Simulation(_free(), method=method, effects=[ramp], **kw)
    x = sim.integrate(t_end).r[-1, 1]
    # the ramp's part c t^3 / 6 = 0.17: a clock off by a step would show at 1e-3
    assert np.abs(x - _exact(t_end)).max() < rel * np.abs(_exact(t_end)).max()


@pytest.mark.parametrize("t_end", [10.0, -10.0])
@pytest.mark.parametrize(("method", "kw"), [("leapfrog", {}), ("wh", {}),
                                            ("wh", {"coordinates": "jacobi"})])
def test_splitting_methods_kick_at_the_middle_of_the_step(ramp, method, kw, t_end):
    """Drift h/2, kick h at the step's middle, drift h/2: the velocity is exact (the
    midpoint rule is exact for a linear ``a(t)``) and each step puts ``c h^3 / 12``
    into the position (``h^2/2 a(t + h/2)`` against ``a(t) h^2/2 + c h^3/6``); a kick
    at the step's start or end would put ``-+c h^2 / 2`` into each step's velocity.
    Backwards the motion in ``s = -t`` has the slope ``-c``: the opposite sign."""
    h, n = 0.01, 1000
    sim = Simulation(_free(), method=method, dt=h, effects=[ramp], **kw)
    traj = sim.integrate(t_end)
    sign = 1.0 if t_end > 0 else -1.0
    err = traj.r[-1, 1] - _exact(t_end)
    expected = sign * n * C * h**3 / 12  # 8.3e-8
    assert err[0] == pytest.approx(expected, rel=1e-6)  # (rounding of 1000 steps: 1e-13)
    assert np.abs(err[1:]).max() < 1e-13
    assert traj.v[-1, 1, 0] == pytest.approx(V0[0] + C * (t_end**2 / 2 + 20 * t_end),
                                             rel=1e-12)


@pytest.mark.parametrize(("method", "kw"), [("radau15", {}), ("leapfrog", {"dt": 0.01}),
                                            ("wh", {"dt": 0.01}), ("dop853", {})])
def test_a_continued_run_keeps_the_clock(ramp, method, kw):
    one = Simulation(_free(), method=method, effects=[ramp], **kw).integrate([0.0, 4.0, 10.0])
    sim = Simulation(_free(), method=method, effects=[ramp], **kw)
    sim.integrate(4.0)
    assert np.array_equal(sim.integrate(10.0).r[-1], one.r[-1])


@pytest.mark.parametrize(("method", "kw"), [("radau15", {}), ("leapfrog", {"dt": 0.01}),
                                            ("wh", {"dt": 0.01}), ("dop853", {})])
def test_the_kernels_that_watch_events_set_the_clock(ramp, method, kw):
    """A watched close encounter the bodies never reach: the run with the events'
    kernels (compiled apart) is the run without them, bit for bit."""
    plain = Simulation(_free(), method=method, effects=[ramp], **kw).integrate(10.0)
    watched = Simulation(_free(), method=method, effects=[ramp], **kw,
                         events=[{"name": "close_encounter", "distance": 1e-3}]).integrate(10.0)
    assert np.array_equal(watched.r[-1], plain.r[-1])


def test_a_saved_run_continues_with_its_clock(ramp, tmp_path):
    whole = Simulation(_free(), method="radau15", effects=[ramp]).integrate([0.0, 3.0, 7.0])
    sim = Simulation(_free(), method="radau15", effects=[ramp])
    sim.integrate(3.0)
    sim.save(tmp_path / "s")
    assert np.array_equal(Simulation.load(tmp_path / "s").integrate(7.0).r[-1], whole.r[-1])


@pytest.mark.parametrize(("method", "kw", "rel"), [("radau15", {}, 1e-13),
                                                   ("dop853", {"tol": 1e-12}, 1e-10)])
def test_the_variational_runs_see_the_time(ramp, method, kw, rel):
    sim = Simulation(_free(), method=method, effects=[ramp], variational=True, **kw)
    x = sim.integrate(10.0).r[-1, 1]
    assert np.abs(x - _exact(10.0)).max() < rel


@pytest.mark.parametrize(("method", "kw"), [("leapfrog", {}), ("wh", {}),
                                            ("wh", {"coordinates": "jacobi"})])
def test_the_variational_splittings_kick_at_the_middle_of_the_step(ramp, method, kw):
    """The tangent kernels set the clock as the plain ones do: the same bits."""
    plain = Simulation(_free(), method=method, dt=0.01, effects=[ramp], **kw).integrate(5.0)
    tangent = Simulation(_free(), method=method, dt=0.01, effects=[ramp], variational=True,
                         **kw).integrate(5.0)
    assert np.array_equal(tangent.r[-1], plain.r[-1])


def test_a_timed_effect_runs_backwards_on_the_reversed_right_hand_side(ramp):
    """The ramp depends on no velocity, but on the time: its backward run needs the
    reversed right-hand side (which reads ``t = -s``), not the forward one."""
    rhs = compile_rhs(_free(), [ramp])
    back = time_reversed(rhs)
    assert back is not rhs
    r, v, gm = np.array([[0.0, 0, 0], X0]), np.array([[0.0, 0, 0], V0]), np.array([1e-30, 0])
    p = back.p.copy()
    p[-1] = -2.0  # s = -2: t = 2
    acc = np.empty((2, 3))
    back.accel(r, -v, gm, acc, p)
    assert np.array_equal(acc, rhs.acceleration(r, v, gm, t=2.0))
    assert rhs.acceleration(r, v, gm, t=2.0)[1, 0] == pytest.approx(22 * C, rel=1e-12)


def test_each_run_has_its_own_clock(ramp):
    """The drivers copy ``p``: a run does not write the right-hand side's own, so two
    copies of a simulation (an ensemble on threads) cannot race on one clock."""
    sim = Simulation(_free(), method="radau15", effects=[ramp])
    p = sim.copy()._prop.rhs.p
    before = p.copy()
    sim.integrate(5.0)
    assert np.array_equal(p, before)


def test_the_rhs_refuses_a_parameter_vector_without_a_clock():
    accel = newtonian_rhs().accel
    for p in (np.zeros(0), np.zeros((1, 1)), np.zeros(2, np.int64)):
        with pytest.raises(ValueError, match="its last the clock"):
            RHS(accel, None, p, False, ("newtonian",))
    frozen = np.zeros(1)
    frozen.setflags(write=False)
    with pytest.raises(ValueError, match="writable"):
        RHS(accel, None, frozen, False, ("newtonian",))


def test_a_kernel_takes_the_time_as_its_sixth_argument_or_not_at_all():
    assert takes_time(_ramp, 5) and not takes_time(figures.zonal_field, 5)
    assert takes_time(figures.zonal_of_date, 5)

    @njit
    def four(r, v, gm, acc):  # pragma: no cover - compiled
        pass

    with pytest.raises(ValueError, match="'four' to take 5 arguments, or 6 with the time"):
        takes_time(four, 5)


# ---------------------------------------------------------------------------
# The Earth's pole of date


def _earth_moon() -> tuple[System, np.ndarray, np.ndarray, np.ndarray]:
    s = System.from_ephemeris(bodies=["sun", "earth", "moon"])
    a = s.as_arrays()
    return s, a.r.copy(), a.v.copy(), a.gm.copy()


@pytest.mark.parametrize("frame", ["icrs", "ecliptic"])
def test_zonal_of_date_is_the_zonal_field_about_the_iau_2006_pole_of_that_time(frame):
    """Bit for bit: the field about ``precessed_pole`` (tested against ERFA's
    ``bp06`` in test_small_bodies) at J2000 + t, turned into the system's axes."""
    s = System.from_ephemeris(bodies=["sun", "earth", "moon"], frame=frame)
    a = s.as_arrays()
    r, v, gm = a.r.copy(), a.v.copy(), a.gm.copy()
    rhs = compile_rhs(s, [{"name": "zonal", "pole": "IAU2006", "frame": frame}])
    fixed = fx.get("nbody", "zonal").params(s, {"frame": frame})[figures.OF_DATE:].copy()
    for t in (0.0, 3652.5, 36525.0, -18262.5):
        k = np.empty(3)
        figures.precessed_pole(t / 36525.0, k)
        q = fixed.copy()
        m = de.frame_rotation(frame)  # (each row's sum left to right, as the kernel's)
        q[2:5] = [m[i, 0] * k[0] + m[i, 1] * k[1] + m[i, 2] * k[2] for i in range(3)]
        acc, got = np.zeros_like(r), np.zeros_like(r)
        figures.zonal_field(r, v, gm, acc, q)
        p = rhs.p.copy()
        p[-1] = t  # (the clock, as an integrator sets it)
        rhs.extra(r, v, gm, got, p)
        assert np.array_equal(got, acc), t


def test_the_epoch_is_the_time_of_the_simulations_start():
    """pole = IAU2006 from epoch J2000 + 100 yr at t = 0 is that from J2000 at t =
    36525 days; the pole moves 20" a year, so the two epochs differ."""
    s, r, v, gm = _earth_moon()
    late = Time("2100-01-01T12:00:00", scale="tdb")
    for name in ("zonal", "earth_tides"):
        at_j2000 = compile_rhs(s, [{"name": name, "pole": "IAU2006"}])
        from_late = compile_rhs(s, [{"name": name, "pole": "IAU2006", "epoch": late}])
        assert np.array_equal(from_late.acceleration(r, v, gm, t=0.0),
                              at_j2000.acceleration(r, v, gm, t=36525.0)), name
        assert not np.array_equal(at_j2000.acceleration(r, v, gm, t=0.0),
                                  at_j2000.acceleration(r, v, gm, t=36525.0)), name


def test_a_fixed_pole_is_the_kernel_without_the_time():
    """The default (the Body's pole) gives the bits of the kernels of five
    arguments, whatever the time."""
    s, r, v, gm = _earth_moon()
    for name, kernel in (("zonal", figures.zonal_field), ("earth_tides", figures.earth_tides)):
        p = fx.get("nbody", name).params(s, {})
        alone = np.zeros_like(r)
        kernel(r, v, gm, alone, p[figures.OF_DATE:])
        for t in (0.0, 1e5):
            acc = np.zeros_like(r)
            fx.get("nbody", name).kernel(r, v, gm, acc, p, t)
            assert np.array_equal(acc, alone), (name, t)


def test_the_pole_of_date_moves_the_moon_by_a_part_of_the_zonal_fields_effect():
    """Ten years of the Sun, the Earth and the Moon with the Earth's J2..J4 about
    the pole of date, against J2000's fixed pole.  The pole turns by ``delta`` <=
    0.056 deg in ten years, so the zonal force differs by at most ``delta`` of
    itself, and (to first order) so does its effect on the Moon: the change is
    above nothing (1 m) and below ``delta`` times the whole field's effect (0.19 of
    192 km; it is 21 m)."""
    s = System.from_ephemeris(bodies=["sun", "earth", "moon"])
    t = 3652.5 * u.day
    moon = {}
    for key, eff in (("none", []), ("fixed", ["zonal"]),
                     ("of date", [{"name": "zonal", "pole": "IAU2006"}])):
        traj = Simulation(s, method="radau15", effects=eff).integrate(t)
        moon[key] = (traj.r[-1, 2] - traj.r[-1, 1]).to_value(u.km)
    moved = np.linalg.norm(moon["of date"] - moon["fixed"])
    whole = np.linalg.norm(moon["fixed"] - moon["none"])
    k0, k1 = np.empty(3), np.empty(3)
    figures.precessed_pole(0.0, k0)
    figures.precessed_pole(0.1, k1)
    delta = np.arccos(k0 @ k1)  # (radians, 9.8e-4)
    assert 1e-3 < moved < delta * whole, (moved, whole, delta)


@pytest.mark.parametrize(("params", "message"), [
    ({"pole": "IAU2000"}, r"Effect 'zonal': expected `pole` to be a vector or 'IAU2006', "
                          r"got 'IAU2000'"),
    ({"epoch": "J2000"}, r"Effect 'zonal': `epoch` is the time of the pole of date; give it "
                         r"with pole = 'IAU2006'"),
    ({"pole": "IAU2006", "epoch": "yesterday"}, r"Effect 'zonal': Expected `epoch` to be a "
                                                r"Time"),
])
def test_bad_pole_of_date_parameters_are_refused_by_name(params, message):
    s = System.from_ephemeris(bodies=["earth", "moon"])
    with pytest.raises(ValueError, match=message):
        s.accelerations([{"name": "zonal", **params}])


def test_the_pole_of_date_needs_a_quantity_system():
    s = System([Body("earth", 1.0, [0, 0, 0], [0, 0, 0]),
                Body("moon", 0.01, [0.00257, 0, 0], [0, 0.0006, 0])])
    with pytest.raises(ValueError, match="pole = 'IAU2006' needs a system of Quantities"):
        compile_rhs(s, [{"name": "zonal", "pole": "IAU2006", "j": [1e-3], "radius": 4e-5,
                         "frame": "icrs"}])


def test_a_systems_accelerations_at_a_time():
    """``System.accelerations(effects, t=...)`` evaluates the effects that know the
    time at ``t`` (the integrators' clock: the same numbers), and refuses a bare
    number for a system of Quantities."""
    s, r, v, gm = _earth_moon()
    eff = [{"name": "zonal", "pole": "IAU2006"}]
    rhs = compile_rhs(s, eff)
    got = s.accelerations(eff, t=100 * u.yr).to_value(u.au / u.day**2)
    assert np.array_equal(got, rhs.acceleration(r, v, gm, t=36525.0))
    assert not np.array_equal(got, s.accelerations(eff).to_value(u.au / u.day**2))
    with pytest.raises(ValueError, match="`t` as a time Quantity"):
        s.accelerations(eff, t=3.0)
    with pytest.raises(ValueError, match="`t` to be finite"):
        s.accelerations(eff, t=np.inf * u.day)
