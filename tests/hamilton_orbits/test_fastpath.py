"""Fast paths for plain floats and lazily computed columns must not change results.

Invariants: the fast path and the general path give the same bits; the
classical columns of the basic kernel equal those of the full kernel; errors
still name the argument and index.
"""

from __future__ import annotations

import numpy as np
import pytest

from hamilton_orbits import KeplerOrbit
from hamilton_orbits._kernels import elements as _el

NAMES = ("a", "e", "p", "inc", "lan", "argp", "nu", "argument_of_latitude")


def _states(n: int, seed: int = 3) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    r = rng.normal(size=(n, 3))
    v = rng.normal(size=(n, 3)) * rng.uniform(0.1, 1.6, size=(n, 1))
    v[0] = [0.0, 1.0, 0.0]  # a circle
    r[1], v[1] = [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]  # radial
    return r, v


def _basic_columns(r: np.ndarray, v: np.ndarray, mu: np.ndarray) -> np.ndarray:
    """The reference the classical columns are checked against: the one-state
    kernel with ``full=False`` (no anomaly, M and tau: NaN for non-radial
    orbits), row by row, shape (N, NCOL)."""
    return np.array([
        _el.state_to_elements_scaled(*ri, *vi, m, False, False)
        for ri, vi, m in zip(r, v, mu, strict=True)
    ])


def test_basic_kernel_columns_equal_full_kernel():
    r, v = _states(200)
    mu = np.ones(len(r))
    full = np.empty((len(r), _el.NCOL))
    _el.state_to_elements(r, v, mu, full)
    basic = _basic_columns(r, v, mu)
    keep = [i for i, c in enumerate(_el.COLUMNS) if c not in ("anomaly", "M", "tau")]
    np.testing.assert_array_equal(basic[:, keep], full[:, keep])


def test_lazy_columns_same_in_any_order():
    r, v = _states(50)
    first = KeplerOrbit.from_state(r, v, 1.0)
    m_first, anom_first = first.M, first.anomaly  # the anomalies before anything else
    later = KeplerOrbit.from_state(r, v, 1.0)
    classical = [getattr(later, n) for n in NAMES]
    np.testing.assert_array_equal(later.M, m_first)
    np.testing.assert_array_equal(later.anomaly, anom_first)
    for n, x in zip(NAMES, classical, strict=True):  # unchanged by the fill
        np.testing.assert_array_equal(getattr(later, n), x)
        np.testing.assert_array_equal(getattr(first, n), x)
    assert np.all(np.isfinite(later.M))


@pytest.mark.parametrize("kind", ["list", "tuple", "int", "ndarray"])
def test_plain_inputs_match_general_path(kind):
    r, v = [1.0, 0.25, -0.5], [0.0, 1.0, 0.25]
    if kind == "tuple":
        r, v = tuple(r), tuple(v)
    elif kind == "int":
        r, v = [1, 0, 0], [0, 1, 0]
    elif kind == "ndarray":
        r, v = np.array(r), np.array(v)
    fast = KeplerOrbit.from_state(r, v, 1.0)
    slow = KeplerOrbit.from_state(np.array(r, dtype=object), v, 1.0)  # the general path
    batch = KeplerOrbit.from_state(np.atleast_2d(r), np.atleast_2d(v), np.ones(1))  # arrays
    for n in (*NAMES, "M", "anomaly", "time_since_periapsis", "n", "period", "mean_longitude",
              "energy", "varpi"):
        assert getattr(fast, n) == getattr(slow, n) == getattr(batch, n)[0], n
    assert type(fast.e) is np.float64 and type(fast.a) is np.float64
    assert fast.shape == slow.shape == ()
    for x, y in zip(fast.state(), slow.state(), strict=True):
        np.testing.assert_array_equal(x, y)
    for x, y in zip(fast.propagate(0.7).state(), slow.propagate(0.7).state(), strict=True):
        np.testing.assert_array_equal(x, y)
    assert fast.conic.e == slow.conic.e


def test_propagate_fast_matches_general_path():
    r, v = _states(20)
    o = KeplerOrbit.from_state(r, v, 1.0)
    dt = np.linspace(-3.0, 3.0, 20)
    fast = o.propagate(dt)
    general = o.propagate(dt.tolist())  # a list takes the general path
    np.testing.assert_array_equal(fast.state()[0], general.state()[0])
    np.testing.assert_array_equal(fast.state()[1], general.state()[1])
    one = o[3].propagate(1.5)
    np.testing.assert_array_equal(one.state()[0], o[3].propagate([1.5]).state()[0][0])


@pytest.mark.parametrize(
    ("r", "v", "mu", "match"),
    [
        ([1.0, float("nan"), 0.0], [0.0, 1.0, 0.0], 1.0, "`r`.*nan at index 1"),
        ([1.0, 0.0, 0.0], [0.0, float("inf"), 0.0], 1.0, "`v`.*inf at index 1"),
        ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], -1.0, "`mu`"),
        ([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 1.0, "`r`"),
        ([1.0, 0.0], [0.0, 1.0, 0.0], 1.0, "`r`"),
        ([1.0, 0.0, 1j], [0.0, 1.0, 0.0], 1.0, "`r`"),
    ],
)
def test_fast_path_errors_name_the_argument(r, v, mu, match):
    with pytest.raises(ValueError, match=match):
        KeplerOrbit.from_state(r, v, mu)


@pytest.mark.parametrize("dt", [float("nan"), np.array([np.inf])])
def test_propagate_fast_path_errors_name_dt(dt):
    o = KeplerOrbit.from_state([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 1.0)
    with pytest.raises(ValueError, match="`dt`"):
        o.propagate(dt)


ONE_STATES = [
    ([1.0, 0.25, -0.5], [0.0, 1.0, 0.25]),  # ellipse
    ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),  # circle (e = 0, argp = 0)
    ([1.0, 0.0, 0.0], [0.0, 2.0**0.5, 0.0]),  # parabola (a = inf)
    ([1.0, 0.0, 0.0], [0.0, 3.0, 0.3]),  # hyperbola
    ([1.0, 2.0, 0.5], [0.5, 1.0, 0.25]),  # radial (h = 0)
    ([1e200, 0.0, 0.0], [0.0, 1e-100, 0.0]),  # scaled inside the kernel (a = 1e200)
]


@pytest.mark.parametrize(("r", "v"), ONE_STATES)
def test_one_orbit_row_matches_batch_bits(r, v):
    """One orbit of plain floats reads its elements from one kernel row
    (``classical_one``): the same bits as the batch kernel, the same types."""
    one = KeplerOrbit.from_state(r, v, 1.0)
    batch = KeplerOrbit.from_state(np.array([r]), np.array([v]), np.ones(1))
    for n in ("a", "e", "p", "inc", "lan", "argp", "nu", "n", "period", "energy", "varpi"):
        x = getattr(one, n)
        assert type(x) is np.float64, n
        y = getattr(batch, n)[0]
        assert x == y or (np.isnan(x) and np.isnan(y)), n
    # the lazy columns afterwards leave the classical ones as they were
    assert one.M == batch.M[0] and one.anomaly == batch.anomaly[0]
    assert one.e == batch.e[0] and one.nu == batch.nu[0]


def test_one_orbit_beyond_float64_names_the_state():
    """A state whose elements overflow (e ~ 1e155) is flagged by the one-orbit
    kernel and refused by the general path by name, from any first attribute."""
    for name in ("a", "e", "inc", "nu"):
        o = KeplerOrbit.from_state([1e51, 0.0, 0.0], [0.0, 0.0, 1e52], 1.0)
        with pytest.raises(ValueError, match=r"`r`, `v`, `mu` whose elements fit in float64"):
            getattr(o, name)


def test_batch_a_from_the_kernel_is_one_over_inv_a():
    """A batch reads ``a`` straight from the kernel's column: 1/inv_a bit for bit,
    +inf for the parabola (no warning: the suite turns warnings into errors), and
    the classical columns are those of the basic kernel (no anomaly computed)."""
    r = np.array([s[0] for s in ONE_STATES])
    v = np.array([s[1] for s in ONE_STATES])
    o = KeplerOrbit.from_state(r, v, 1.0)
    a = o.a
    basic = _basic_columns(r, v, np.ones(len(r)))
    inv = basic[:, _el.COLUMNS.index("inv_a")]
    assert a[2] == np.inf and inv[2] == 0.0  # the parabola
    finite = inv != 0
    np.testing.assert_array_equal(a[finite], 1.0 / inv[finite])
    for n in ("e", "p", "inc", "lan", "argp", "nu"):
        np.testing.assert_array_equal(getattr(o, n), basic[:, _el.COLUMNS.index(n)])
    assert "_full" not in o.__dict__  # the anomaly, M and tau were not computed


@pytest.mark.parametrize(("r", "v"), ONE_STATES)
def test_one_orbit_vectors_match_batch_bits(r, v):
    """The areal and eccentricity vectors of one orbit of plain floats (Python
    floats, no floating-point-error guard) equal the batch path's bits."""
    one = KeplerOrbit.from_state(r, v, 1.0)
    batch = KeplerOrbit.from_state(np.array([r]), np.array([v]), np.ones(1))
    for n in ("areal_vector", "eccentricity_vector", "hamilton_epsilon"):
        x = getattr(one, n)
        assert x.shape == (3,) and x.dtype == np.float64, n
        np.testing.assert_array_equal(x, getattr(batch, n)[0], err_msg=n)


def test_one_orbit_vectors_beyond_float64_are_named():
    """|r x v| = 1e400: the general path refuses it by name (such a state's p =
    h^2/mu is beyond float64 too, so the elements' message may come first)."""
    o = KeplerOrbit.from_state([1e200, 0.0, 0.0], [0.0, 1e200, 0.0], 1.0)
    for name in ("areal_vector", "eccentricity_vector", "hamilton_epsilon"):
        with pytest.raises(ValueError, match=r"`r`, `v`, `mu` .*fits? in float64"):
            getattr(o, name)


def test_check_copy_state_counts_exactly_the_invalid_rows():
    """The branch-free validity test of the batch copy: every non-finite entry,
    ``mu <= 0`` and ``r = 0`` are counted, extreme finite values are not (0 * x
    stays 0 for x = +-1.7e308 and for subnormals), and the copy is exact."""
    r, v = _states(64)
    mu = np.full(64, 2.0)
    r[2], v[3] = [1.7e308, -1.7e308, 5e-324], [-1.7e308, 0.0, 5e-324]  # finite: valid
    bad_rows = []
    for k, x in enumerate([np.nan, np.inf, -np.inf]):
        for col in range(7):
            row = 4 + 7 * k + col
            bad_rows.append(row)
            if col < 3:
                r[row, col] = x
            elif col < 6:
                v[row, col - 3] = x
            else:
                mu[row] = x
    mu[30], mu[31], r[32] = 0.0, -1.0, 0.0
    bad_rows += [30, 31, 32]
    outs = np.empty_like(r), np.empty_like(v), np.empty_like(mu)
    assert _el.check_copy_state(r, v, mu, *outs) == len(bad_rows) == 24
    for got, want in zip(outs, (r, v, mu), strict=True):
        np.testing.assert_array_equal(got, want)
    ok = np.setdiff1d(np.arange(64), bad_rows)
    assert _el.check_copy_state(r[ok], v[ok], mu[ok], *(x[ok] for x in outs)) == 0


def _kind_states() -> tuple[np.ndarray, np.ndarray]:
    """Random states and one of every kind: circle, radial ellipse, parabola,
    radial parabola, radial hyperbola, quasi-rectilinear ellipse, hyperbola,
    and states the kernel scales (1e200, 1e-300)."""
    r, v = _states(400, seed=11)
    extra = [
        ([1.0, 0.0, 0.0], [0.5, 0.0, 0.0]),  # radial ellipse
        ([1.0, 0.0, 0.0], [2.0**0.5, 0.0, 0.0]),  # radial parabola
        ([1.0, 0.0, 0.0], [3.0, 0.0, 0.0]),  # radial hyperbola
        ([1.0, 0.0, 0.0], [0.0, 2.0**0.5, 0.0]),  # parabola
        ([1.0, 0.0, 0.0], [1.0, 1e-17, 0.0]),  # quasi-rectilinear (e = 1, 1/a > 0)
        ([1.0, 0.0, 0.0], [0.0, 3.0, 0.3]),  # hyperbola
        ([1e200, 0.0, 0.0], [0.0, 1e-100, 0.0]),  # scaled: a circle, a = 1e200
        ([1e-300, 0.0, 0.0], [1e-50, 2.0**0.5 * 1e150, 0.0]),  # scaled parabola
    ]
    return (np.vstack([r, [x[0] for x in extra]]), np.vstack([v, [x[1] for x in extra]]))


def test_kind_derived_from_the_classical_columns_equals_the_kernel_kind():
    """The batch stores no kind column: ``_columns.kind_of`` (and its numpy form
    in ``KeplerOrbit._kind``) derives it from p, e, 1/a, nu, bit for bit the
    kind the full kernel decides, for every kind of conic."""
    from hamilton_orbits._columns import kind_of

    r, v = _kind_states()
    full = np.empty((len(r), _el.NCOL))
    _el.state_to_elements(r, v, np.ones(len(r)), full)
    kernel_kind = full[:, _el.COLUMNS.index("kind")]
    assert set(np.unique(kernel_kind)) == {0.0, 1.0, 2.0, 3.0, 4.0, 5.0}  # all six kinds
    o = KeplerOrbit.from_state(r, v, 1.0)
    np.testing.assert_array_equal(o._kind, kernel_kind)
    c = [full[:, _el.COLUMNS.index(n)] for n in ("p", "e", "inv_a", "nu")]
    assert [kind_of(*row) for row in zip(*c, strict=True)] == kernel_kind.tolist()
    assert "_full" not in o.__dict__  # derived without the full kernel


def test_parabola_with_underflowed_p_is_not_radial():
    """A parabola nearly along its axis at |r| = 1e-300 has p = h^2/mu below the
    smallest subnormal (p = 0) without being radial (h > 8 eps |r| |v|): the
    derived kind keeps it a parabola, as the kernel does (nu is not pi)."""
    from hamilton_orbits._columns import PARABOLA

    r = np.array([[1e-300, 0.0, 0.0]])
    v = np.array([[2.0**0.5 * 1e150, 1e137, 0.0]])  # h = 1e-163: p ~ 1e-326 -> 0
    full = np.empty((1, _el.NCOL))
    _el.state_to_elements(r, v, np.ones(1), full)
    names = ("p", "e", "inv_a", "nu", "kind")
    p, e, inv_a, nu, kind = (full[0, _el.COLUMNS.index(n)] for n in names)
    assert p == 0.0 and e == 1.0 and inv_a == 0.0 and nu != np.pi and kind == PARABOLA
    assert KeplerOrbit.from_state(r, v, 1.0)._kind[0] == PARABOLA


def test_argument_of_latitude_comes_from_the_full_kernel():
    """u is not a column of the classical kernel: read, it comes from the full
    kernel, bit for bit its u column (atan2 from the position, not argp + nu)."""
    r, v = _kind_states()
    full = np.empty((len(r), _el.NCOL))
    _el.state_to_elements(r, v, np.ones(len(r)), full)
    o = KeplerOrbit.from_state(r, v, 1.0)
    o.e  # the classical columns first  # noqa: B018
    np.testing.assert_array_equal(o.argument_of_latitude, full[:, _el.COLUMNS.index("u")])
    one = KeplerOrbit.from_state(r[0].tolist(), v[0].tolist(), 1.0)
    assert one.argument_of_latitude == full[0, _el.COLUMNS.index("u")]


def test_one_orbit_kernel_checks_and_computes_in_one_call():
    """elements.one_orbit: the state and classical_one's row in one array, from
    r and v as tuples of floats; 0 for a state the rule refuses (every value
    finite, mu > 0, r != 0), 1 for a valid one, 2 when an element is beyond
    float64 (a NaN)."""
    r, v = (1.0, 0.25, -0.5), (0.0, 1.0, 0.25)
    out = np.empty(_el.ONE_ORBIT_SIZE)
    assert _el.one_orbit(out, r, v, 1.0) == 1
    assert out.tolist() == [*r, *v, 1.0, *_el.classical_one(*r, *v, 1.0)]
    nan, inf = float("nan"), float("inf")
    for bad_r, bad_v, mu in [
        ((nan, 0.25, -0.5), v, 1.0),
        (r, (0.0, -inf, 0.25), 1.0),
        (r, v, 0.0),
        ((0.0, 0.0, 0.0), v, 1.0),
    ]:
        assert _el.one_orbit(out, bad_r, bad_v, mu) == 0, (bad_r, bad_v, mu)
    assert _el.one_orbit(out, A_BEYOND_R, A_BEYOND_V, 1.0) == 2


def test_one_orbit_is_compiled_once_whatever_form_the_vectors_take():
    """``KeplerOrbit.from_state``'s one-orbit path hands the kernel ``r`` and ``v`` as
    tuples of floats whether they came as tuples, lists, float64 arrays or strided
    arrays: one compiled type (each form was a type of its own, and each pair of them
    compiled the kernel again, 2.5-3.8 s a time); the same elements to the bit."""
    from numba import types

    r, v = (1.0, 0.25, -0.5), (0.0, 1.0, 0.25)
    wide = np.zeros((3, 2))
    wide[:, 0] = r
    forms = [(r, v), (list(r), np.array(v)), (np.array(r), np.array(v)), (wide[:, 0], list(v))]
    before = set(_el.one_orbit.signatures)
    orbits = [KeplerOrbit.from_state(a, b, 1.0) for a, b in forms]
    rows = [[*np.concatenate(o.state()), o.p, o.e, o.inc, o.lan, o.argp, o.nu] for o in orbits]
    for row in rows[1:]:
        assert row == rows[0]
    added = set(_el.one_orbit.signatures) - before
    assert all(isinstance(sig[1], types.UniTuple) and isinstance(sig[2], types.UniTuple)
               for sig in added), added


# 1/a of this state is subnormal (about 1e-310) but not zero to rounding: a is
# beyond float64 while every other element is finite
A_BEYOND_R = (1e300, 0.0, 0.0)
A_BEYOND_V = (0.0, (2e-300 * (1 - 5e-11)) ** 0.5, 0.0)


@pytest.mark.parametrize("batch", [False, True])
def test_a_alone_beyond_float64_is_named_when_read(batch):
    r, v = list(A_BEYOND_R), list(A_BEYOND_V)
    o = KeplerOrbit.from_state([r], [v], 1.0) if batch else KeplerOrbit.from_state(r, v, 1.0)
    assert np.all((o.e > 0.99) & (o.e < 1.0)) and np.all(np.isfinite(o.p)) and np.all(o.inc == 0)
    with pytest.raises(ValueError, match=r"for which `a` fits in float64, got r=\[1e\+300"):
        o.a  # noqa: B018


def test_elements_of_one_orbit_and_of_many_compile_one_layout():
    """The columns of many state rows are strided views, of one row contiguous ones:
    each layout was another type of the elements' kernels, compiled again (2-2.5 s of
    a first run reading one orbit's elements, then many orbits').  They reach the
    kernels as C-ordered copies; the same elements to the bit as one orbit alone."""
    kernels = (_el.state_to_elements_classical.serial, _el.state_to_elements.serial,
               _el.state_to_time_since_periapsis.serial)
    before = [set(k.signatures) for k in kernels]
    r = np.array([[1.0, 0.25, -0.5], [2.0, 0.0, 0.125]])
    v = np.array([[0.0, 1.0, 0.25], [0.0, 0.5, 0.0]])
    one = KeplerOrbit.from_state(r[:1], v[:1], 1.0)
    many = KeplerOrbit.from_state(r, v, 1.0)
    for name in ("e", "p", "inc", "M", "time_since_periapsis"):
        assert getattr(one, name)[0] == getattr(many, name)[0], name
    for k, seen in zip(kernels, before, strict=True):
        added = set(k.signatures) - seen
        assert all(a.layout == "C" for sig in added for a in sig[:3]), (k, added)
