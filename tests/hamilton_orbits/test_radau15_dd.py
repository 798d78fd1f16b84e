"""radau15 in double-double (precision="double-double") and the reference built on it."""

from __future__ import annotations

import decimal
import math

import nbody_states
import numpy as np
import pytest

from hamilton_orbits import Body, System, integrate
from hamilton_orbits._kernels import radau15 as _k
from hamilton_orbits._kernels import radau15_dd as _dd
from hamilton_orbits.events import EventLog
from hamilton_orbits.integrators import radau15
from hamilton_orbits.rhs import compile_rhs, newtonian_rhs
from hamilton_orbits.studies.reference import reference

D = decimal.Decimal


@pytest.fixture(scope="module")
def solar():
    return nbody_states.solar_system()


def _dec(pair) -> decimal.Decimal:
    return D(float(pair[0])) + D(float(pair[1]))


def test_spacings_are_the_gauss_radau_nodes_to_40_digits():
    # The 30-digit table radau15 rounds to doubles (Everhart 1985, as IAS15
    # quotes it) holds 26 to 30 correct digits (measured differences 5e-31 for
    # h_1 growing to 1.2e-26 for h_7: ample for doubles); the defining polynomial
    # P_7(2h - 1) + P_8(2h - 1) vanishes at the refined values to 1e-40.
    h = _dd.spacings()
    for ours, table in zip(h, _k.DECIMAL_SPACINGS, strict=True):
        assert abs(ours - D(table)) < D("2e-26"), (ours, table)
    with decimal.localcontext() as ctx:
        ctx.prec = 60
        for x in h[1:]:
            y = 2 * x - 1
            p = [D(1), y]
            for n in range(1, 8):
                p.append(((2 * n + 1) * y * p[n] - n * p[n - 1]) / (n + 1))
            assert abs(p[7] + p[8]) < D("1e-40"), x


def test_double_double_constants_hold_to_30_digits():
    # C (b from g) and D (g from b) are inverse; each constant is hi + lo with
    # |lo| <= ulp(hi) / 2, so it carries ~32 digits.
    k = _dd.constants()
    with decimal.localcontext() as ctx:
        ctx.prec = 50
        c = [[_dec(k["c"][i, j]) for j in range(7)] for i in range(7)]
        d = [[_dec(k["d"][i, j]) for j in range(7)] for i in range(7)]
        for i in range(7):
            for j in range(7):
                s = sum((c[i][m] * d[m][j] for m in range(7)), D(0))
                assert abs(s - (1 if i == j else 0)) < D("1e-29"), (i, j, s)
    for name in ("h", "rinv", "c", "d", "kx", "ax", "av"):
        hi, lo = k[name][..., 0], k[name][..., 1]
        assert np.all(np.abs(lo) <= np.spacing(np.abs(hi)) / 2), name


def test_double_double_accelerations_to_30_digits():
    # Hamilton's equation (B) in 50-digit decimals against the kernel, for four
    # bodies with states that are not short doubles: relative error below 1e-30
    # (a double-precision kernel: 1e-16).
    rng = np.random.default_rng(3)
    x = np.zeros((4, 3, 2))
    x[:, :, 0] = rng.normal(size=(4, 3))
    x[:, :, 1] = x[:, :, 0] * 1e-17 * rng.normal(size=(4, 3))
    gm = np.array([1.0, 1e-3, 3e-6, 0.5])
    a = np.empty((4, 3, 2))
    _dd.accel(x, gm, a)
    with decimal.localcontext() as ctx:
        ctx.prec = 50
        pos = [[_dec(x[i, k]) for k in range(3)] for i in range(4)]
        for i in range(4):
            want = [D(0)] * 3
            for j in range(4):
                if j == i:
                    continue
                dv = [pos[j][k] - pos[i][k] for k in range(3)]
                r2 = sum(c * c for c in dv)
                f = D(float(gm[j])) / (r2 * r2.sqrt())
                want = [w + f * c for w, c in zip(want, dv, strict=True)]
            for k in range(3):
                got = _dec(a[i, k])
                assert abs(got - want[k]) <= D("1e-30") * abs(want[k]), (i, k, got, want[k])


def test_double_double_agrees_with_itself_and_with_double_precision(solar):
    # The solar system over 10 years (3652.5 days: the last step of each of the 4
    # output intervals is shortened): double-double at 2 and 1 days agree below
    # the doubles' resolution (measured 0); double precision at 1 day is off by
    # its rounding (measured 1.4e-13 after 10 years).  Bounds: 1e-15; 1e-12.
    _, r0, v0, gm = solar
    t = np.linspace(0.0, 3652.5, 5)
    runs = {dt: radau15.run(newtonian_rhs(), r0, v0, gm, t, dt=dt, precision="double-double")
            for dt in (2.0, 1.0)}
    r_double, _, _ = radau15.run(newtonian_rhs(), r0, v0, gm, t, dt=1.0)
    assert runs[1.0][2] == 3656

    def helio(r):
        return r[:, 1:] - r[:, :1]

    ref = helio(runs[1.0][0])
    scale = np.linalg.norm(ref, axis=2)
    dd = np.max(np.linalg.norm(helio(runs[2.0][0]) - ref, axis=2) / scale)
    double = np.max(np.linalg.norm(helio(r_double) - ref, axis=2) / scale)
    assert dd < 1e-15, dd
    assert 0.0 < double < 1e-12, double


def test_double_double_through_integrate():
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("p", 0.0, [1.0, 0, 0], [0, 1.0, 0])])
    traj = integrate(s, 2 * math.pi, method="radau15", dt=2 * math.pi / 64,
                     precision="double-double")
    assert np.abs(traj.final["p"].r - [1.0, 0, 0]).max() < 1e-14


def test_double_double_refuses_what_it_does_not_do():
    r0 = np.array([[0.0, 0, 0], [1.0, 0, 0]])
    v0 = np.array([[0.0, 0, 0], [0, 1.0, 0]])
    args = (newtonian_rhs(), r0, v0, np.array([1.0, 0.0]), np.array([0.0, 1.0]))
    with pytest.raises(ValueError, match=r"`precision` to be one of 'double', 'double-double', "
                                         r"got 'quad'"):
        radau15.run(*args, dt=0.1, precision="quad")
    with pytest.raises(ValueError, match=r"fixed steps: give `dt` and no `tol`, got dt = None"):
        radau15.run(*args, precision="double-double")
    with pytest.raises(ValueError, match=r"fixed steps: give `dt` and no `tol`, got dt = 0.1, "
                                         r"tol = 1e-09"):
        radau15.run(*args, dt=0.1, tol=1e-9, precision="double-double")
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("p", 1e-3, [1, 0, 0], [0, 1, 0])])
    rhs = compile_rhs(s, [{"name": "gr_potential", "c": 1e4}])
    with pytest.raises(ValueError, match=r"Newtonian gravity only; listed: gr_potential"):
        radau15.run(rhs, *args[1:], dt=0.1, precision="double-double")
    log = EventLog(np.array([[3.0, 1.0, -1.0, 10.0, 0.0]]), np.full(2, np.nan))
    with pytest.raises(ValueError, match=r"watches no events"):
        radau15.run(*args, dt=0.1, precision="double-double", events=log)


def test_reference_is_cached_by_problem(tmp_path, monkeypatch):
    monkeypatch.setenv("HAMILTON_ORBITS_CACHE_DIR", str(tmp_path))
    r0 = np.array([[0.0, 0, 0], [1.0, 0, 0]])
    v0 = np.array([[0.0, 0, 0], [0, 1.1, 0]])
    gm = np.array([1.0, 1e-3])
    t = np.array([0.0, 5.0, 10.0])
    first = reference(r0, v0, gm, t, 0.05)
    again = reference(r0, v0, gm, t, 0.05)
    other = reference(r0, v0, gm, t, 0.1)
    assert not first.cached and again.cached and not other.cached
    np.testing.assert_array_equal(first.r, again.r)
    np.testing.assert_array_equal(first.r_check, again.r_check)
    assert len(list((tmp_path / "reference").glob("*.npz"))) == 2
    assert np.abs(first.r - first.r_check).max() < 1e-14


@pytest.mark.slow
def test_the_1000_year_reference_agrees_with_itself_to_1e_13(solar):
    # Issue 22: two step sequences (1 and 2 days) agree to better than 1e-13
    # after 1000 years (measured: see docs; the runs take minutes, cached).
    _, r0, v0, gm = solar
    ref = reference(r0, v0, gm, np.array([0.0, 365250.0]), 1.0)
    h = ref.r[-1][1:] - ref.r[-1][0]
    h_check = ref.r_check[-1][1:] - ref.r_check[-1][0]
    assert np.max(np.linalg.norm(h_check - h, axis=1) / np.linalg.norm(h, axis=1)) < 1e-13


# Issue 32: the double-double step guard (class 12), its options (class 14) and the
# reference cache (class 15).

def test_double_double_counts_its_steps_before_the_first():
    """``dt = 1e-12`` over a unit span never returned (1e12 steps of 0.5 ms) and
    ``max_steps=5`` was ignored (100 steps ran): both are refused up front, naming
    the steps, ``dt`` and ``max_steps``; 100 steps with ``max_steps=100`` run."""
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("p", 0.0, [1, 0, 0], [0, 1, 0])])
    with pytest.raises(ValueError, match=r"radau15 in double-double would take about 1e\+12 "
                                         r"steps of dt = 1e-12 over 1 \(max_steps = 100000000\)"):
        integrate(s, 1.0, precision="double-double", dt=1e-12)
    with pytest.raises(ValueError, match=r"about 100 steps of dt = 0.01 over 1 \(max_steps = 5\)"):
        integrate(s, 1.0, precision="double-double", dt=0.01, max_steps=5)
    traj = integrate(s, 1.0, precision="double-double", dt=0.01, max_steps=100)
    assert traj.steps == 100
    # the circular orbit: exact cos t, sin t
    np.testing.assert_allclose(traj.final["p"].r, [math.cos(1.0), math.sin(1.0), 0.0],
                               rtol=0, atol=1e-15)


def test_double_double_options_are_checked_by_name():
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("p", 0.0, [1, 0, 0], [0, 1, 0])])
    with pytest.raises(ValueError, match=r"Expected `criterion` to be one of 'global', 'prs23', "
                                         r"got 'bogus'"):
        integrate(s, 1.0, precision="double-double", dt=0.1, criterion="bogus")
    # the precision is named, not double-double
    with pytest.raises(ValueError, match=r"Expected `precision` to be one of 'double', "
                                         r"'double-double', got 'quad'"):
        integrate(s, 1.0, precision="quad", variational=True)
    with pytest.raises(ValueError, match=r"double-double integrates no variational equations"):
        integrate(s, 1.0, precision="double-double", dt=0.1, variational=True)


def test_double_double_names_a_collision():
    """Two bodies at one point reach the double-double kernel only past the checks
    (a Propagation made directly): its division by zero is a ConvergenceError."""
    from hamilton_orbits import engine
    from hamilton_orbits.integrators import Radau15
    from hamilton_orbits.validation import ConvergenceError

    prop = engine.Propagation(np.zeros((2, 3)), np.array([[0.0, 0, 0], [0, 1.0, 0]]),
                              np.array([1.0, 1.0]), 0.0, newtonian_rhs(),
                              Radau15(precision="double-double"), dt=0.1)
    with pytest.raises(ConvergenceError, match=r"double-double stopped before t_out\[1\] = 1.0: "
                                               r"two bodies met"):
        prop.advance(np.array([0.0, 1.0]))


def _problem():
    r0 = np.array([[0.0, 0, 0], [1.0, 0, 0]])
    v0 = np.array([[0.0, 0, 0], [0, 1.1, 0]])
    return r0, v0, np.array([1.0, 1e-3]), np.array([0.0, 1.0])


@pytest.mark.parametrize("damage", [b"", b"PK\x03\x04cut", b"\x93NUMPY" + b"\x00" * 40,
                                    "other-shape"])
def test_a_damaged_cached_reference_is_named_and_computed_again(tmp_path, monkeypatch, damage):
    """A cache file cut short (an EOFError, a BadZipFile), overwritten with other bytes
    (numpy's "pickled data" error) or holding arrays of another problem's shape: a
    RuntimeWarning naming the file, the reference computed again (the same bits as
    without a cache) and the file replaced."""
    monkeypatch.setenv("HAMILTON_ORBITS_CACHE_DIR", str(tmp_path))
    fresh = reference(*_problem(), 0.1, cache=False)
    assert not reference(*_problem(), 0.1).cached
    (path,) = (tmp_path / "reference").glob("*.npz")
    if damage == "other-shape":
        np.savez(path, r=np.zeros((3, 2, 3)), v=fresh.v, r_check=fresh.r_check,
                 v_check=fresh.v_check)
    else:
        path.write_bytes(damage)
    with pytest.warns(RuntimeWarning, match=rf"The cached reference {path} is damaged .*; "
                                            r"computing it again"):
        again = reference(*_problem(), 0.1)
    assert not again.cached
    assert np.array_equal(again.r, fresh.r) and np.array_equal(again.r_check, fresh.r_check)
    assert reference(*_problem(), 0.1).cached
    assert [p.name for p in path.parent.iterdir()] == [path.name]


def test_reference_input_is_named(tmp_path, monkeypatch):
    monkeypatch.setenv("HAMILTON_ORBITS_CACHE_DIR", str(tmp_path))
    r0, v0, gm, t = _problem()
    with pytest.raises(ValueError, match=r"Expected `dt` > 0, got 0.0"):
        reference(r0, v0, gm, t, 0.0)
    with pytest.raises(ValueError, match=r"Expected `dt` > 0, got None"):
        reference(r0, v0, gm, t, None)
    with pytest.raises(ValueError, match=r"Bodies at indices 0 and 1 of `r0` are at one "
                                         r"position \[0.0, 0.0, 0.0\]"):
        reference(np.zeros((2, 3)), v0, gm, t, 0.1)
    with pytest.raises(ValueError, match=r"Expected `t_out` to be strictly increasing, got 0.5 "
                                         r"at index 2 after 1.0"):
        reference(r0, v0, gm, [0.0, 1.0, 0.5], 0.1)


def test_two_writers_of_one_reference_write_through_files_of_their_own(tmp_path, monkeypatch):
    """Two processes computing the same reference wrote one shared temporary file
    name: the second's rename could move a file the first was still writing.
    Each writer now has a temporary file of its own: two writers held inside
    ``np.savez`` at once write two files, and the one left is whole."""
    import threading

    from hamilton_orbits.studies import reference as module

    monkeypatch.setenv("HAMILTON_ORBITS_CACHE_DIR", str(tmp_path))
    both_inside = threading.Barrier(2, timeout=30)
    names: list[str] = []
    savez = np.savez

    def held(f, **arrays):
        names.append(f.name)
        both_inside.wait()
        savez(f, **arrays)

    monkeypatch.setattr(module.np, "savez", held)
    r = reference(*_problem(), 0.1, cache=False)
    path = tmp_path / "one.npz"
    writers = [threading.Thread(target=module._write, args=(path,),
                                kwargs=dict(r=r.r, v=r.v, r_check=r.r_check, v_check=r.v_check))
               for _ in range(2)]
    for w in writers:
        w.start()
    for w in writers:
        w.join()
    assert len(set(names)) == 2 and all(str(tmp_path) in n for n in names)
    with np.load(path) as z:
        assert np.array_equal(z["r"], r.r)
    assert [p.name for p in tmp_path.iterdir()] == ["one.npz"]
