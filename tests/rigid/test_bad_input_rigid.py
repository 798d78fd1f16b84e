"""Bad input on the rigid-body and pole surfaces, refused at its root (issue 20).

The reproducers of the issue for ``rigid``: a wobble fit asked beyond the record,
a C04 file that is not one, the Liouville model with an effect listed twice, and
the rigid scene kinds; the n-body, scene and CLI ones are in
``tests/hamilton_orbits/test_bad_input.py``.
"""

from __future__ import annotations

import re

import astropy.units as u
import pytest
from astropy.time import Time

from hamilton_orbits import Scene
from hamilton_orbits.scene import SceneError
from rigid.polar_motion import LiouvillePole, fit_wobble, load_c04


@pytest.fixture(scope="module")
def record():
    return load_c04()


def _span(record) -> str:
    first, last = record.time[0].iso[:10], record.time[-1].iso[:10]
    return rf"within the record \(1962.00-\d{{4}}.\d\d, {first} to {last}\)"


def test_a_fit_beyond_the_record_is_refused_not_cut_short(record):
    # fit_wobble(rec, 2020, 2100) fitted 2020-2026 without saying so
    with pytest.raises(ValueError, match=rf"Expected `end` {_span(record)}, got 2100, after "
                                         r"the record ends \(leave `end` out"):
        fit_wobble(record, start=2020, end=2100)
    with pytest.raises(ValueError, match=rf"Expected `start` {_span(record)}, got 1950, before "
                                         r"it begins"):
        fit_wobble(record, start=1950, end=2000)
    with pytest.raises(ValueError, match=r"Expected `start` within the record .*got <Time"):
        record.select(Time("1961-06-01", scale="utc"), 2000)


def test_a_window_to_the_end_of_the_record_is_taken(record):
    last = float(2000 + (record.time[-1].mjd - 51544) / 365.25)
    sub = record.select(2020, last + 1 / 365.25)  # one sample beyond the last epoch: all of it
    assert sub.time[-1] == record.time[-1]


@pytest.mark.parametrize(("content", "pattern"), [
    (bytes(range(256)) * 4, r"to be an IERS C04 table.*got a file that is not text \(byte "
                            r"0x80 at offset 128\)"),
    (b"kind = 'nbody'\n", r"to be an IERS C04 table.*invalid column index 4"),
    (b"1962 1 1 0 37665 -0.012700 0.213000\n", r"with at least 2 rows, got 1"),
    (b"1962 1 1 0 37666 -0.0127 0.2130\n1962 1 1 0 37665 -0.0125 0.2140\n",
     r"Expected the epochs \(MJD\) of `path` .* to increase, got 37665.0 after 37666.0 at data "
     r"row 1"),
    (b"1962 1 1 0 37665 nan 0.2130\n1962 1 2 0 37666 -0.0125 0.2140\n",
     r"finite pole coordinates: Expected `x` to be finite, got nan at index 0"),
])
def test_a_file_that_is_not_a_c04_table(tmp_path, content, pattern):
    path = tmp_path / "eopc04.txt"
    path.write_bytes(content)
    with pytest.raises(ValueError, match=pattern) as info:
        load_c04(path)
    assert str(path) in str(info.value)


@pytest.mark.parametrize("effects", [("elastic", "elastic"), ("elastic", "damping", "elastic")])
def test_liouville_refuses_an_effect_listed_twice_as_integrate_does(effects):
    k = effects.index("elastic", 1)
    with pytest.raises(ValueError, match=rf"Effect 'elastic' is listed twice \(at indices 0 and "
                                         rf"{k}\)"):
        LiouvillePole(effects, chandler_period=433.0, Q=100)


def test_liouville_parameters_of_the_wrong_shape_or_kind():
    with pytest.raises(ValueError, match=r"Expected `k2` to be one number, got shape \(2,\)"):
        LiouvillePole(("elastic",), k2=[0.1, 0.2])
    with pytest.raises(u.UnitConversionError, match=r"Expected `Q` to be dimensionless"):
        LiouvillePole(("damping",), Q=100 * u.s)
    with pytest.raises(ValueError, match=r"Expected `effects` to be a list of names"):
        LiouvillePole(3)
    with pytest.raises(ValueError, match=r"Expected `effects` from .* got 3 at index 1"):
        LiouvillePole(("free", 3))


def test_polar_scene_window_beyond_the_record_fails_at_loading(tmp_path):
    path = tmp_path / "pole.toml"
    path.write_text('kind = "polar_motion"\nstart = 2020\nend = 2100\n')
    with pytest.raises(SceneError) as info:
        Scene.from_toml(path)
    (problem,) = info.value.problems
    assert problem.startswith(f"{path}:3: end: expected `end` within the record")


def test_polar_scene_reads_periods_with_units_and_refuses_a_duplicate(tmp_path):
    scene = Scene.from_dict({"kind": "polar_motion", "start": 1980, "end": 1990, "effects": [
        {"name": "elastic", "chandler_period": "433 d"}, {"name": "damping", "Q": 100}]})
    assert scene.effects[0]["chandler_period"] == 433 * u.day
    result = scene.run(progress=False)
    assert result.metrics["model period"].to_value(u.day) == pytest.approx(433, rel=1e-12)
    with pytest.raises(SceneError, match=r"effects\[0\].chandler_period: expected a time"):
        Scene.from_dict({"kind": "polar_motion",
                         "effects": [{"name": "elastic", "chandler_period": "433 m"}]})
    with pytest.raises(SceneError, match=r"effects\[1\]: effect 'elastic' is listed twice"):
        Scene.from_dict({"kind": "polar_motion", "effects": ["elastic", "elastic"]})


def test_polar_scene_reads_the_annual_excitation_as_an_angle_with_its_unit():
    """``annual_prograde = "5 mas"`` was refused ("Expected `annual_prograde` to be
    numeric, got array('5 mas', dtype='<U5')") while the periods took "433 d": any
    angular unit is read (DESIGN.md, one unit boundary per kind), a bare number stays
    radians, and a unit of another dimension is refused naming the key."""
    def scene(value):
        return Scene.from_dict({"kind": "polar_motion", "start": 1980, "end": 2010,
                                "effects": [{"name": "damping", "Q": 179},
                                            {"name": "annual_excitation",
                                             "annual_prograde": value,
                                             "annual_retrograde": value}]})
    for value, expected in (("5 mas", 5 * u.mas), ("2e-6 deg", 2e-6 * u.deg)):
        effect = scene(value).effects[1]
        assert effect["annual_prograde"] == effect["annual_retrograde"] == expected
    assert scene(2.4e-8).effects[1]["annual_prograde"] == 2.4e-8
    with pytest.raises(SceneError) as info:
        scene("5 m")
    assert [p.split(": ", 1)[1] for p in info.value.problems] == [
        f"effects[1].{key}: expected an angle (a unit convertible to rad), got '5 m'"
        for key in ("annual_prograde", "annual_retrograde")]


def test_rotation_scene_cadence_beyond_memory_fails_at_loading(tmp_path):
    path = tmp_path / "spin.toml"
    path.write_text('kind = "rotation"\nduration = "60 s"\ncadence = "1e-9 s"\n[body]\n'
                    'moments = ["1 kg m2", "2 kg m2", "3 kg m2"]\n'
                    'omega = ["0 rad/s", "1 rad/s", "0 rad/s"]\n[integrator]\ndt = "1 ms"\n')
    with pytest.raises(SceneError) as info:
        Scene.from_toml(path)
    (problem,) = info.value.problems
    assert re.match(rf"{re.escape(str(path))}:3: cadence: 6e\+10 outputs of a rigid body would "
                    r"take .* beyond the limit of 1 GiB", problem), problem


def test_a_spin_given_in_hertz_is_refused_not_read_as_radians_per_second():
    """``omega = [0, 0, 1] Hz`` (one turn a second) was read as 1 rad/s, a spin 2 pi
    too slow, silently; it is refused naming ``omega``, and one turn a second as
    cycle/s is 2 pi rad/s."""
    import numpy as np

    from rigid import RigidBody

    with pytest.raises(u.UnitConversionError, match=r"`omega` .* got Hz: the hertz counts "
                                                    r"cycles"):
        RigidBody([1.0, 2.0, 3.0] * u.kg * u.m**2, omega=[0.0, 0.0, 1.0] * u.Hz)
    body = RigidBody([1.0, 2.0, 3.0] * u.kg * u.m**2, omega=[0.0, 0.0, 1.0] * u.cycle / u.s)
    assert body.omega.to_value(u.rad / u.s)[2] == 2 * np.pi


def test_an_array_where_one_number_is_asked_is_refused_by_name():
    """``recentre`` and ``annual_prograde`` given as arrays raised numpy's
    ``TypeError: only 0-dimensional arrays can be converted to Python scalars``."""
    from rigid import RigidBody
    from rigid.rodrigues import cayley_propagate

    body = RigidBody([1.0, 1.0, 1.0], omega=[0.0, 0.0, 1.0])
    with pytest.raises(ValueError, match=r"Expected `recentre` to be one number, got shape "
                                          r"\(2,\)"):
        cayley_propagate(body, 1.0, 0.01, recentre=[1.0, 2.0])
    for name in ("annual_prograde", "annual_retrograde"):
        kw = {"annual_prograde": 1e-7, name: [1e-7, 2e-7]}
        with pytest.raises(ValueError, match=rf"Expected `{name}` to be one \(complex\) "
                                              rf"angle, got shape \(2,\)"):
            LiouvillePole(("annual_excitation",), **kw)


def test_a_squared_rate_in_hertz_is_refused_and_in_radians_taken():
    """``GravityGradientTorque``'s ``gm_over_r3`` (n squared) in Hz**2 was read as
    1/s**2 (4 pi**2 too small, were the hertz cycles); it is refused, and n**2 of a
    rad/s Quantity, refused before ("got rad2 / s2"), is taken."""
    from rigid.euler import GravityGradientTorque

    with pytest.raises(u.UnitConversionError, match=r"`gm_over_r3` .* got Hz2: the hertz"):
        GravityGradientTorque((1e-3 * u.Hz) ** 2)
    radians = GravityGradientTorque((1e-3 * u.rad / u.s) ** 2).encode()
    per_second = GravityGradientTorque(1e-6 / u.s**2).encode()
    assert radians[0] == per_second[0] and radians[1].tolist() == per_second[1].tolist()


@pytest.mark.parametrize("flag", ["False", "no", 0, None])
def test_the_triaxial_flag_takes_a_bool_only(flag):
    """``triaxial="False"`` was true (any non-empty text is): the triaxial Euler
    period, the moments A != B kept; refused by name."""
    from rigid.earth.constants import chandler_period, euler_period, rigid_body
    from rigid.earth.free_wobble import simulate_wobble

    pattern = rf"Expected `triaxial` to be True or False, got {re.escape(repr(flag))}"
    for call in (lambda: euler_period(triaxial=flag), lambda: rigid_body(triaxial=flag),
                 lambda: chandler_period(0.3, triaxial=flag),
                 lambda: simulate_wobble(2 * u.yr, method="exact", triaxial=flag)):
        with pytest.raises(ValueError, match=pattern):
            call()


def test_the_excitation_of_a_series_is_refused_beyond_its_span():
    """``excitation`` and ``rhs`` (for checks with an ODE solver) held the series'
    end value beyond ``chi_t`` while ``solve`` refused those times: a check then
    integrated another model."""
    model = LiouvillePole(("elastic", "excitation_series"), chandler_period=433 * u.day,
                          chi_t=[0.0, 10.0, 20.0] * u.day, chi=[0.0, 1e-7, 2e-7])
    assert model.excitation([5.0, 20.0])[1] == 2e-7  # (within: interpolated)
    for call in (lambda: model.excitation([5.0, 100.0]), lambda: model.rhs(100.0, 0j),
                 lambda: model.solve([0.0, 100.0], 0j)):
        with pytest.raises(ValueError, match=r"Expected `t` within the span of `chi_t` "
                                             r"\[0.0, 20.0\] d, got 100.0"):
            call()


def test_a_periodogram_takes_cycles_per_year(record):
    """``u.cycle / u.yr`` (the docstring's "cycles per year") was refused as "not
    1/time"; it is the frequency of as many turns a year."""
    from rigid.polar_motion import periodogram

    turns = periodogram(record.select(2000, 2010), [0.843, -1.0] * u.cycle / u.yr)
    plain = periodogram(record.select(2000, 2010), [0.843, -1.0] / u.yr)
    assert turns["amplitude"].value.tolist() == plain["amplitude"].value.tolist()


def test_a_list_of_quantities_and_a_duration_array_are_named_as_such():
    """A list of Quantities was "the plain number [...]"; a duration of shape (1,)
    was told to be ">= 1 day"."""
    from rigid import RigidBody, free_motion
    from rigid.earth.free_wobble import simulate_wobble

    body = RigidBody([1.0, 2.0, 3.0] * u.kg * u.m**2, omega=[0.4, 1.1, -0.3] * u.rad / u.s)
    with pytest.raises(ValueError, match=r"got a list of Quantities \[.*\]: make it one "
                                         r"Quantity \(u.Quantity\(t\)\)"):
        free_motion(body, [0 * u.s, 1 * u.min])
    with pytest.raises(ValueError, match=r"Expected `duration` to be one time, got "
                                         r"<Quantity \[3.\] yr> of shape \(1,\)"):
        simulate_wobble([3] * u.yr, method="exact")
