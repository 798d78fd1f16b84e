"""The variational equations: Jacobians, tangent maps, the STM, MEGNO and Lyapunov.

Outside authorities: central finite differences (of each effect's own acceleration,
of the Kepler drift, of whole integrations), the symplectic form, and rebound's
MEGNO and Lyapunov exponent (``sim.init_megno``) on the same initial states.
"""

from __future__ import annotations

import numpy as np
import pytest

from hamilton_orbits import Body, Simulation, System, integrate
from hamilton_orbits._kernels import kepler, variational
from hamilton_orbits.rhs import compile_rhs

EPS = np.finfo(float).eps


def _three() -> System:
    """A star and two planets (G = 1), not barycentric on purpose."""
    return System([Body("star", 1.0, [0, 0, 0], [0, 0, 0]),
                   Body("b", 1e-3, [1.0, 0.0, 0.01], [0, 1.0, 0.02]),
                   Body("c", 3e-4, [0, -1.6, 0.03], [0.79, 0.0, 0.0])])


def _symplectic_form(gm: np.ndarray) -> np.ndarray:
    """``sum_i m_i dr_i ^ dv_i`` in the STM's coordinates (body by body x, y, z,
    vx, vy, vz): the form every Hamiltonian n-body flow keeps."""
    j = np.block([[np.zeros((3, 3)), np.eye(3)], [-np.eye(3), np.zeros((3, 3))]])
    return np.kron(np.diag(gm), j)


def _fd_stm(system: System, t: float, h: float, **kw) -> np.ndarray:
    """d(r, v)(t) / d(r, v)(0) by central differences of whole integrations, each
    coordinate displaced by ``h`` times its body's distance (speed) scale."""
    x0 = np.hstack([system.r, system.v])  # (n, 6)
    n = x0.shape[0]
    scale = np.hstack([np.repeat(np.linalg.norm(system.r, axis=1, keepdims=True) + 1.0, 3, 1),
                       np.repeat(np.linalg.norm(system.v, axis=1, keepdims=True) + 1.0, 3, 1)])
    cols = []
    for j in range(6 * n):
        i, c = divmod(j, 6)
        step = h * scale[i, c]
        ends = []
        for sign in (1.0, -1.0):
            x = x0.copy()
            x[i, c] += sign * step
            tr = integrate(system.with_state(x[:, :3], x[:, 3:]), t, **kw)
            ends.append(np.hstack([tr.r[-1], tr.v[-1]]).ravel())
        cols.append((ends[0] - ends[1]) / (2 * step))
    return np.array(cols).T


# ---------------------------------------------------------------------------
# The pieces: Kepler's tangent map and every effect's Jacobian


@pytest.mark.parametrize("state, dt", [
    ([1.0, 0.1, 0.05, 0.02, 1.0, 0.1], 0.3),  # near-circular, a fraction of an orbit
    ([1.0, 0.1, 0.05, 0.02, 1.3, 0.1], 2.3),  # e ~ 0.7
    ([1.0, 0.1, 0.05, 0.02, 1.6, 0.1], 5.0),  # hyperbolic
    ([1.0, 0.0, 0.0, 0.0, 0.9, 0.1], 40.0),  # six periods (reduced modulo the period)
    ([1.0, 0.1, 0.05, 0.02, 1.0, 0.1], -0.7),  # backwards
])
def test_kepler_tangent_is_the_drifts_derivative(state, dt):
    """The Wisdom-Holman drift's tangent map against central differences of the
    drift itself, and its symplecticity (M^T J M = J to rounding).

    FD step 1e-6 (truncation ~1e-12, rounding ~1e-10 of the entries, times the
    growth of the entries over six periods): agreement to 1e-8 relative."""
    x = np.array(state)
    x1 = np.array(kepler.propagate_uv(*x, 1.0, dt))
    dq = np.vstack([np.eye(3), np.zeros((3, 3))])
    du = np.vstack([np.zeros((3, 3)), np.eye(3)])
    variational.kepler_tangent(x[:3].copy(), x[3:].copy(), x1[:3].copy(), x1[3:].copy(), 1.0,
                               dt, dq, du, 0, 1)
    m = np.hstack([dq, du]).T
    fd = np.zeros((6, 6))
    for j in range(6):
        e = np.zeros(6)
        e[j] = 1e-6
        fd[:, j] = (np.array(kepler.propagate_uv(*(x + e), 1.0, dt))
                    - np.array(kepler.propagate_uv(*(x - e), 1.0, dt))) / 2e-6
    assert np.max(np.abs(m - fd)) < 1e-8 * np.max(np.abs(m))
    j = _symplectic_form(np.ones(1))
    assert np.max(np.abs(m.T @ j @ m - j)) < 1e3 * EPS * np.max(np.abs(m)) ** 2


def _solar(bodies=None) -> System:
    return System.from_ephemeris(bodies=bodies)


# (effect, system builder, FD-Jacobian: True for those differentiated numerically)
_EFFECTS = [
    ({"name": "gr", "c": 30.0}, _three, False),
    ({"name": "gr_potential", "c": 30.0}, _three, False),
    ({"name": "j2", "body": "star", "j2": 0.01, "radius": 0.2,
      "pole": None}, _three, False),
    ("eih", lambda: _solar(["sun", "mercury", "venus", "earth", "moon", "jupiter"]), True),
    ("lense_thirring", lambda: _solar(["sun", "mercury", "earth"]), False),
    ("zonal", lambda: _solar(["sun", "earth", "moon"]), False),
    ("moon_figure", lambda: _solar(["sun", "earth", "moon"]), True),
    ("earth_tides", lambda: _solar(["sun", "earth", "moon"]), True),
    ("kuiper_ring", lambda: _solar(["sun", "jupiter", "neptune", "pluto"]), True),
]


def _effect_id(item) -> str:
    eff = item[0]
    return eff if isinstance(eff, str) else eff["name"]


@pytest.mark.parametrize("effect, build, numerical", _EFFECTS,
                         ids=[_effect_id(e) for e in _EFFECTS])
def test_every_effects_jacobian_against_its_acceleration(effect, build, numerical):
    """Each effect's Jacobian (what ``tangent_extra`` adds) against central
    differences of the same effect's acceleration (``extra``), block by block
    (body i's acceleration against body j's position and velocity).

    The reference steps each coordinate by 1e-6 of its body's distance to its
    nearest neighbour (speed relative to it): truncation ~1e-12, rounding
    ~1e-10 of the entry.  Analytic Jacobians agree to 1e-7 of each 3 x 6 block.
    The ones computed by central differences themselves (``numerical``: eih,
    moon_figure, earth_tides, kuiper_ring) are compared body by body
    (:func:`_row_errors_below`) to 1e-5 (measured 2e-9 to 7e-7, the Sun's row
    under EIH the worst): two finite differences with different steps cannot
    agree better on entries at rounding level (a velocity column of EIH is 1e-10
    of the Newtonian part it is computed with), and these are no longer
    measured relative to themselves."""
    if isinstance(effect, dict) and effect.get("pole", 0) is None:
        effect = {k: v for k, v in effect.items() if k != "pole"}
    s = build()
    rhs = compile_rhs(s, [effect], variational=True)
    a = s.as_arrays()
    r, v, gm = (np.array(x, dtype=float) for x in (a.r, a.v, a.gm))
    n = r.shape[0]
    dr = np.zeros((6 * n * n, 3))
    dv = np.zeros((6 * n * n, 3))
    for j in range(6 * n):
        i, c = divmod(j, 6)
        (dr if c < 3 else dv)[j * n + i, c % 3] = 1.0
    da = np.zeros_like(dr)
    rhs.tangent_extra(r, v, gm, dr, dv, da, rhs.p)
    jac = da.reshape(6 * n, 3 * n).T  # (3n accelerations) x (6n coordinates)

    def extra(rr, vv):
        acc = np.zeros_like(rr)
        rhs.extra(np.ascontiguousarray(rr), np.ascontiguousarray(vv), gm, acc, rhs.p)
        return acc.ravel()

    d = np.linalg.norm(r[:, None] - r[None], axis=2) + np.diag(np.full(n, np.inf))
    near = np.argmin(d, axis=1)
    fd = np.zeros_like(jac)
    for j in range(6 * n):
        i, c = divmod(j, 6)
        scale = (d[i, near[i]] if c < 3 else np.linalg.norm(v[i] - v[near[i]]))
        h = 1e-6 * scale
        rp, vp, rm, vm = r.copy(), v.copy(), r.copy(), v.copy()
        (rp if c < 3 else vp)[i, c % 3] += h
        (rm if c < 3 else vm)[i, c % 3] -= h
        fd[:, j] = (extra(rp, vp) - extra(rm, vm)) / (2 * h)
    assert np.any(jac != 0.0)
    if numerical:
        _row_errors_below(jac, fd, r, v, gm, 1e-5)
        return
    top = np.max(np.abs(fd))
    worst = 0.0
    for bi in range(n):
        for bj in range(n):
            blk = fd[3 * bi:3 * bi + 3, 6 * bj:6 * bj + 6]
            diff = jac[3 * bi:3 * bi + 3, 6 * bj:6 * bj + 6] - blk
            worst = max(worst, np.max(np.abs(diff)) / (np.max(np.abs(blk)) + 1e-12 * top))
    assert worst < 1e-7, worst


def _row_errors_below(jac, fd, r, v, gm, tol) -> None:
    """Body by body (the rows of its acceleration), ``|J - J_fd| / |J_fd|`` with the
    velocity columns times the time scale ``L / V`` of the closest pair (so that a
    displacement of positions and one of velocities of the sizes the system sets
    weigh alike: an entry of 1e-13 of a velocity column next to 1e-3 in the position
    columns is not measured relative to itself)."""
    from hamilton_orbits._kernels.jacobians import fd_scales

    n = r.shape[0]
    length, speed = fd_scales(r, v, gm)
    scale = np.tile(np.r_[np.ones(3), np.full(3, length / speed)], n)
    for bi in range(n):
        row, ref = jac[3 * bi:3 * bi + 3] * scale, fd[3 * bi:3 * bi + 3] * scale
        if np.any(ref):
            assert np.max(np.abs(row - ref)) < tol * np.max(np.abs(ref)), bi


def test_newtonian_jacobian_against_finite_differences():
    """The Newtonian part (what every tangent right-hand side starts with), test
    particles included."""
    s = System(list(_three().bodies) + [Body("dust", 0.0, [0.4, 0.5, -0.1], [-1.0, 0.9, 0.0])])
    rhs = compile_rhs(s, (), variational=True)
    a = s.as_arrays()
    r, v, gm = a.r.copy(), a.v.copy(), a.gm.copy()
    n = r.shape[0]
    dr = np.zeros((3 * n * n, 3))
    for j in range(3 * n):
        dr[j * n + j // 3, j % 3] = 1.0
    da = np.zeros_like(dr)
    rhs.tangent(r, v, gm, dr, np.zeros_like(dr), da, rhs.p)
    jac = da.reshape(3 * n, 3 * n).T
    fd = np.zeros_like(jac)
    for j in range(3 * n):
        e = np.zeros_like(r)
        e.ravel()[j] = 1e-7
        fd[:, j] = (rhs.acceleration(r + e, v, gm) - rhs.acceleration(r - e, v, gm)).ravel() / 2e-7
    assert np.max(np.abs(jac - fd)) < 1e-7 * np.max(np.abs(jac))


# ---------------------------------------------------------------------------
# The STM of every integrator against finite differences of whole integrations

_METHODS = [
    ("radau15", {}),
    ("radau15", {"dt": 0.05}),
    ("wh", {"dt": 0.02}),
    ("wh", {"dt": 0.02, "coordinates": "jacobi"}),
    ("leapfrog", {"dt": 0.002}),
    ("dop853", {"tol": 1e-12}),
]


@pytest.mark.parametrize("method, kw", _METHODS, ids=[f"{m}-{'-'.join(k)}" for m, k in _METHODS])
def test_stm_against_finite_differences_of_integrations(method, kw):
    """``traj.stm[-1]`` after 5 orbits of the inner planet against central
    differences of 2 x 18 whole integrations (step 1e-6 of each body's scale,
    truncation ~1e-12 relative and rounding ~1e-16 / 1e-6 times the entries'
    growth): 1e-6 relative or better, for the maps (the derivative of the map
    itself) and for the adaptive methods alike (their steps hardly move for a
    perturbation of 1e-6, and the integration error is far below it)."""
    s = _three()
    t = 5 * 2 * np.pi
    tr = integrate(s, t, method=method, variational=True, stm=True, **kw)
    assert tr.stm.shape == (2, 18, 18)
    assert np.array_equal(tr.stm[0], np.eye(18))
    fd = _fd_stm(s, t, 1e-6, method=method, **kw)
    err = np.max(np.abs(tr.stm[-1] - fd)) / np.max(np.abs(fd))
    assert err < 1e-6, err


@pytest.mark.parametrize("method, kw, effect", [
    ("radau15", {}, {"name": "gr", "c": 30.0}),
    ("radau15", {}, {"name": "j2", "body": "star", "j2": 0.01, "radius": 0.2}),
    ("wh", {"dt": 0.02}, {"name": "j2", "body": "star", "j2": 0.01, "radius": 0.2}),
    ("wh", {"dt": 0.02, "coordinates": "jacobi"}, {"name": "gr_potential", "c": 30.0}),
    ("dop853", {"tol": 1e-12}, {"name": "gr", "c": 30.0}),
], ids=["radau15-gr", "radau15-j2", "wh-j2", "whjacobi-grpotential", "dop853-gr"])
def test_stm_with_effects_against_finite_differences(method, kw, effect):
    """With ``gr`` or ``j2`` on (made strong: c = 30, J2 = 0.01 at R = 0.2, so that
    the effects change the STM by far more than the tolerance), the STM against
    finite differences of integrations with the same effect: 1e-6.  This is what
    rebound's variational equations, which leave reboundx's forces out, do not
    give (rebound issue 800; see the next test)."""
    s = _three()
    t = 5 * 2 * np.pi
    tr = integrate(s, t, method=method, effects=[effect], variational=True, stm=True, **kw)
    fd = _fd_stm(s, t, 1e-6, method=method, effects=[effect], **kw)
    err = np.max(np.abs(tr.stm[-1] - fd)) / np.max(np.abs(fd))
    assert err < 1e-6, err


def test_newtonian_tangent_along_a_gr_orbit_is_wrong():
    """What leaving an effect's Jacobian out costs (rebound's variational particles
    with reboundx's ``gr``): the tangent equations of Newtonian gravity alone along
    the GR trajectory miss the STM by ~1e-3 here, a thousand times what the full
    Jacobian meets.  (dop853 takes ``augmented`` from Python, so the wrong one can
    be put together here.)"""
    from hamilton_orbits import engine
    from hamilton_orbits.integrators._tangent import Tangent
    from hamilton_orbits.rhs import RHS

    s = _three()
    t = 5 * 2 * np.pi
    eff = [{"name": "gr", "c": 30.0}]
    full = compile_rhs(s, eff, variational=True)
    newton = compile_rhs(s, (), variational=True)

    def newtonian_tangent(r, v, gm, acc, p):
        n = gm.shape[0]
        full.accel(r[:n], v[:n], gm, acc[:n], p)
        newton.tangent(r[:n], v[:n], gm, r[n:], v[n:], acc[n:], newton.p)

    wrong = RHS(full.accel, full.extra, full.p, True, full.effects, newton.tangent, None,
                newtonian_tangent)
    stms = []
    for rhs in (full, wrong):
        out = engine.run(s.r, s.v, s.as_arrays().gm, np.array([0.0, t]), rhs, "dop853",
                         tol=1e-12, variational=Tangent(3, 2, stm=True))
        stms.append(out.variational.stm[-1])
    fd = _fd_stm(s, t, 1e-6, method="dop853", tol=1e-12, effects=eff)
    good, bad = (np.max(np.abs(m - fd)) / np.max(np.abs(fd)) for m in stms)
    assert good < 1e-6 and bad > 1e-4, (good, bad)


_BACKWARD = [
    ("radau15", {}, ()),
    ("radau15", {}, ({"name": "gr", "c": 30.0},)),
    ("dop853", {"tol": 1e-12}, ({"name": "gr", "c": 30.0},)),
    ("wh", {"dt": 0.02}, ()),
    ("wh", {"dt": 0.02, "coordinates": "jacobi"}, ({"name": "gr_potential", "c": 30.0},)),
    ("leapfrog", {"dt": 0.002}, ()),
]


@pytest.mark.parametrize("method, kw, effects", _BACKWARD,
                         ids=["radau15", "radau15-gr", "dop853-gr", "wh", "whjacobi-grpotential",
                              "leapfrog"])
def test_backward_stm_against_finite_differences(method, kw, effects):
    """A backward run's STM (the time-reversed motion's tangent vectors, started as
    ``(dr, -dv)`` and turned back at the outputs) against central differences of
    whole backward integrations: 1e-6, as forwards (measured 4.4e-9 to 8.8e-9).
    ``gr`` depends on the velocity: its Jacobian is applied at the true velocity to
    the true velocity's part of each vector (the velocity rows left unturned miss
    by 1.5)."""
    s = _three()
    t = -5 * 2 * np.pi
    tr = integrate(s, t, method=method, effects=list(effects), variational=True, stm=True,
                   **kw)
    assert np.array_equal(tr.stm[0], np.eye(18))
    fd = _fd_stm(s, t, 1e-6, method=method, effects=list(effects), **kw)
    err = np.max(np.abs(tr.stm[-1] - fd)) / np.max(np.abs(fd))
    assert err < 1e-6, err


@pytest.mark.parametrize("method, kw", [("radau15", {}), ("wh", {"dt": 0.02}),
                                        ("dop853", {"tol": 1e-12})])
def test_backward_variational_run_is_the_reflected_forward_one(method, kw):
    """Newton's motion is reversible: running ``(r, v)`` back in time is running
    ``(r, -v)`` forwards, the velocities negated.  The backward run integrates
    exactly that, so its outputs are the reflected forward run's bit for bit: the
    positions, the velocities negated, MEGNO and the Lyapunov exponent (its tangent
    vector's velocity part negated too), and the STM ``D M D`` with
    ``D = diag(1, 1, 1, -1, -1, -1)`` per body."""
    from hamilton_orbits.integrators._tangent import megno_vector

    s = _three()
    times = -np.array([0.0, 3.0, 7.5])
    back = integrate(s, times, method=method, variational=True, stm=True, **kw)
    vector = megno_vector(3) * np.array([1, 1, 1, -1, -1, -1])
    fwd = integrate(s.with_state(s.r, -np.asarray(s.v)), -times, method=method,
                    variational=True, stm=True, tangent=vector, **kw)
    d = np.kron(np.eye(3), np.diag([1.0, 1, 1, -1, -1, -1]))
    assert np.array_equal(back.r, fwd.r) and np.array_equal(back.v, -fwd.v)
    assert np.array_equal(back.megno, fwd.megno)
    assert np.array_equal(back.lyapunov, fwd.lyapunov)
    assert np.array_equal(back.stm, d @ fwd.stm @ d)


# ---------------------------------------------------------------------------
# Symplecticity: M^T J M = J


@pytest.mark.parametrize("sign", [1.0, -1.0], ids=["forwards", "backwards"])
@pytest.mark.parametrize("method, kw", [
    ("wh", {"dt": 0.05}), ("wh", {"dt": 0.05, "coordinates": "jacobi"}),
    ("leapfrog", {"dt": 0.005}), ("radau15", {}), ("radau15", {"tol": 1e-6}),
])
def test_stm_is_symplectic(method, kw, sign):
    """The STM keeps the symplectic form ``sum m_i dr_i ^ dv_i``.  The maps' tangent
    maps are products of symplectic maps: the defect is rounding, which grows
    like eps |M|^2 (measured 0.02-0.1 eps |M|^2 over 100 orbits, 10^4 to 10^5
    steps); bound 1 eps |M|^2.  radau15's flow is symplectic only to its
    integration error, far below its tolerance here: measured 0.006 eps |M|^2 at
    the default 1e-9 and at 1e-6; bound 1e-9 |M|^2 (its tolerance).  Backwards the
    same: the time-reversed flow is Hamiltonian too, and its STM turned back keeps
    the form."""
    s = _three()
    gm = s.as_arrays().gm
    w = _symplectic_form(gm / gm.max())
    tr = integrate(s, sign * 100 * 2 * np.pi, method=method, variational=True, stm=True,
                   **kw)
    m = tr.stm[-1]
    defect = np.max(np.abs(m.T @ w @ m - w))
    bound = (1e-9 if method == "radau15" else EPS) * np.max(np.abs(m)) ** 2
    assert defect < bound, (defect, bound)
    if method != "radau15":
        assert defect < EPS * np.max(np.abs(m)) ** 2


# ---------------------------------------------------------------------------
# MEGNO and the Lyapunov exponent against rebound


def _rebound_pair(a2: float, e: float, m: float = 1e-3):
    import rebound

    sim = rebound.Simulation()
    sim.add(m=1.0)
    sim.add(m=m, a=1.0, e=e)
    sim.add(m=m, a=a2, e=e, f=2.0, inc=0.01)
    sim.move_to_com()
    return sim


def _megno_rebound(sim, integrator: str, t: np.ndarray, seed: int = 1):
    """rebound's MEGNO and Lyapunov exponent at ``t`` (and its initial tangent)."""
    sim.integrator = integrator
    if integrator == "whfast":
        sim.dt = 2 * np.pi / 40
    sim.init_megno(seed=seed)
    start = np.array([[p.x, p.y, p.z, p.vx, p.vy, p.vz] for p in sim.particles_var])
    out = []
    for ti in t:
        sim.integrate(ti, exact_finish_time=integrator != "whfast")
        out.append((sim.megno(), sim.lyapunov()))
    return np.array(out), start


def _ours(sim, method: str, t: np.ndarray, tangent=None):
    kw = {"dt": 2 * np.pi / 40, "coordinates": "jacobi"} if method == "wh" else {}
    tr = integrate(System.from_rebound(sim), t, method=method, variational=True,
                   tangent=tangent, **kw)
    return tr


def _quasi_periodic(orbits: float, ours_method: str, theirs: str) -> None:
    pytest.importorskip("rebound")
    t = np.array([orbits / 10, orbits]) * 2 * np.pi
    theirs_out, start = _megno_rebound(_rebound_pair(2.5, 0.01), theirs, t)
    same = _ours(_rebound_pair(2.5, 0.01), ours_method, t, tangent=start)
    own = _ours(_rebound_pair(2.5, 0.01), ours_method, t)
    assert abs(theirs_out[-1, 0] - 2.0) < 0.05
    assert abs(own.megno[-1] - 2.0) < 0.05
    assert abs(own.megno[-1] - theirs_out[-1, 0]) < 0.02
    assert abs(same.megno[-1] - theirs_out[-1, 0]) < 0.002


def test_megno_quasi_periodic_wh_against_whfast_10000_orbits():
    """Two Jupiter-mass planets at 1 and 2.5 (e = 0.01), 10^4 inner orbits, our
    ``wh`` (Jacobi) against rebound's WHFast at the same step.  A system whose
    MEGNO does not depend on the starting tangent vector (rebound, seeds 0-4:
    1.9979-2.0005 at 10^4 orbits): both within 0.05 of 2, ours with its own
    random vector within 0.02 of rebound's, and from rebound's vector within 0.002
    (the two maps differ in their MEGNO quadrature: rebound's rectangle rule on
    delta'.delta/delta^2 at the step end, our midpoint rule on ln |delta|)."""
    _quasi_periodic(1e4, "wh", "whfast")


def test_megno_quasi_periodic_radau15_against_ias15_1000_orbits():
    """As above with radau15 against IAS15, over 10^3 orbits (the 10^4-orbit run
    is the slow test below)."""
    _quasi_periodic(1e3, "radau15", "ias15")


@pytest.mark.slow
def test_megno_quasi_periodic_radau15_against_ias15_10000_orbits():
    """The 10^4-orbit comparison with radau15 and IAS15 (about 10 s each)."""
    _quasi_periodic(1e4, "radau15", "ias15")


@pytest.mark.parametrize("method, theirs", [("radau15", "ias15"), ("wh", "whfast")])
def test_megno_chaotic_against_rebound(method, theirs):
    """Two Jupiter-mass planets at 1 and 1.3 (e = 0.05): a chaotic pair, MEGNO grows
    from 2 to ~12 by 100 orbits, Lyapunov time ~10 orbits.  Compared over 120 orbits,
    about 12 Lyapunov times: the two codes' trajectories (and tangent vectors, from
    rebound's) then differ by rounding times e^12 ~ 1e5, i.e. still ~1e-10, so they
    measure the same orbit.  Over longer spans the pair scatters (the planets swap
    places) and the Lyapunov time of twin integrations that differ by 1e-13 spreads
    by a factor 2 (measured with rebound alone: 36% at 200 orbits, 110% at 1000):
    no code can be compared with another there.  Both grow; Lyapunov times within
    20%, MEGNO within 5%."""
    pytest.importorskip("rebound")
    t = np.array([20.0, 120.0]) * 2 * np.pi
    theirs_out, start = _megno_rebound(_rebound_pair(1.3, 0.05), theirs, t)
    ours = _ours(_rebound_pair(1.3, 0.05), method, t, tangent=start)
    assert theirs_out[-1, 0] > 8 and ours.megno[-1] > 8
    assert abs(ours.megno[-1] / theirs_out[-1, 0] - 1) < 0.05
    lt_theirs, lt_ours = 1 / theirs_out[-1, 1], 1 / ours.lyapunov[-1]
    assert 0 < lt_ours and abs(lt_ours / lt_theirs - 1) < 0.2, (lt_ours, lt_theirs)
    # the reported Lyapunov time is that inverse, the run spanning ~12 of them
    assert ours.lyapunov_time[-1] == lt_ours and t[-1] * ours.lyapunov[-1] > 10


def test_lyapunov_time_of_a_regular_orbit_is_not_a_negative_time():
    """Issue 32 item 9: on a regular orbit the exponent (the slope of a MEGNO
    settling to 2) comes back negative, so ``1 / lyapunov`` is a negative "time"
    while the scene said inf.  The trajectory's ``lyapunov_time`` is the one
    definition: ``1 / lyapunov`` where ``lyapunov t >= 1`` (the run lasted that
    long), ``inf`` elsewhere; and the quasi-periodic pair's exponent is negative
    at the end (rebound's ``sim.lyapunov()`` too: the same definition)."""
    pytest.importorskip("rebound")
    t = np.linspace(0.0, 1000.0, 11)[1:] * 2 * np.pi
    theirs, start = _megno_rebound(_rebound_pair(2.5, 0.01), "whfast", t)
    ours = _ours(_rebound_pair(2.5, 0.01), "wh", t, tangent=start)
    lyap = ours.lyapunov
    assert lyap[-1] < 0 and theirs[-1, 1] < 0
    tt = np.concatenate(([0.0], t))
    expected = np.where(lyap * tt >= 1.0, 1.0 / np.where(lyap != 0, lyap, 1.0), np.inf)
    np.testing.assert_array_equal(ours.lyapunov_time, expected)
    assert np.all(np.isinf(ours.lyapunov_time))  # regular: no Lyapunov time measured


def test_lyapunov_time_in_legs_and_quantities():
    """``lyapunov_time`` in the unit of ``t`` (a Quantity system), continued across
    legs exactly as one call."""
    import astropy.units as u

    s = System.solar_system(bodies=["sun", "jupiter", "saturn"])
    sim = Simulation(s, "wh", dt=100 * u.day, variational=True)
    first = sim.integrate(500 * u.yr)
    second = sim.integrate(1000 * u.yr)
    once = Simulation(s, "wh", dt=100 * u.day, variational=True).integrate([500, 1000] * u.yr)
    assert second.lyapunov_time.unit == u.yr
    assert np.array_equal(second.lyapunov_time.value, once.lyapunov_time[1:].value)
    assert first.lyapunov_time[0].value == np.inf


def test_megno_is_the_same_for_every_integrator():
    """MEGNO of one quasi-periodic system by the four methods (one tangent vector,
    four integrations of the tangent dynamics: two augmented systems and two exact
    tangent maps): the same to 0.01 after 100 orbits (1.781-1.782)."""
    s = _three()
    t = 100 * 2 * np.pi
    vals = [integrate(s, t, method=m, variational=True, **kw).megno[-1]
            for m, kw in (("radau15", {}), ("wh", {"dt": 0.02}), ("leapfrog", {"dt": 0.002}),
                          ("dop853", {"tol": 1e-11}))]
    assert np.ptp(vals) < 0.01, vals
    assert abs(np.mean(vals) - 1.78) < 0.05  # still rising towards 2 at 100 orbits


def _mercury_megno(years: float) -> dict:
    import astropy.units as u

    s = System.solar_system()
    vec = np.zeros((len(s.names), 6))
    vec[1] = np.random.default_rng(3).normal(size=6)  # a displacement of Mercury alone
    out = {}
    for eff in ((), ("gr",)):
        tr = integrate(s, [years / 2, years] * u.yr, method="radau15", effects=eff,
                       variational=True, tangent=vec)
        out[eff] = (tr.megno, tr.lyapunov.to_value(1 / u.yr))
    return out


def test_megno_of_mercury_with_and_without_gr():
    """MEGNO of a displacement of Mercury in the solar system (the built-in
    ephemeris at J2000), with and without ``gr`` (its Jacobian in the tangent
    equations, which rebound leaves out), over 100 years: quasi-periodic both ways
    (2.019; it falls towards 2 as 2 + O(ln t / t)), and the same to 1e-4.  GR's
    part in Mercury's chaos is the secular g1 - g5 resonance, a matter of Gyr
    (Laskar & Gastineau 2009): over a century it moves MEGNO by ~1e-7."""
    out = _mercury_megno(100.0)
    for megno, lyap in out.values():
        assert abs(megno[-1] - 2.0) < 0.05
        assert abs(lyap[-1]) < 1e-3  # per year: no Lyapunov time below 1000 years
    assert abs(out[()][0][-1] - out[("gr",)][0][-1]) < 1e-4


@pytest.mark.slow
def test_megno_of_mercury_with_and_without_gr_1000_years():
    """The same over 1000 years (MEGNO 2.0052 both ways; ~10 s each)."""
    out = _mercury_megno(1000.0)
    for megno, _ in out.values():
        assert abs(megno[-1] - 2.0) < 0.01
    assert abs(out[()][0][-1] - out[("gr",)][0][-1]) < 1e-4


def test_tangent_vectors_do_not_drive_radau15s_steps():
    """radau15 chooses its step from the bodies alone: with the variational
    equations (55 tangent vectors that grow 100-fold) the same steps as without,
    and the same trajectory to rounding (the predictor-corrector iteration, which
    runs over every component as in rebound's IAS15, may stop one iteration
    apart); ``tangent_control=True`` lets the tangent vectors in."""
    s = _three()
    t = 20 * 2 * np.pi
    plain = integrate(s, t)
    var = integrate(s, t, variational=True, stm=True)
    assert var.steps == plain.steps
    assert np.max(np.abs(var.r[-1] - plain.r[-1])) < 1e-12
    ctrl = integrate(s, t, variational=True, stm=True, tangent_control=True)
    assert ctrl.steps >= plain.steps
    assert np.max(np.abs(ctrl.stm[-1] - var.stm[-1])) < 1e-8 * np.max(np.abs(var.stm[-1]))


@pytest.mark.parametrize("stm", [False, True])
def test_megno_with_the_tangent_vectors_in_radau15s_step_control(stm):
    """``tangent_control=True`` took the rows under step control (all of them) as
    where the MEGNO's tangent vector begins: the kernel read past the state, MEGNO
    0 or NaN, changing from run to run.  With fixed steps the control changes
    nothing: the same MEGNO bit for bit; with adaptive steps a finite MEGNO near
    the converged one (radau15 at 1e-4; MEGNO's mean over time is a sum over the
    steps, first order in the step as rebound's: 0.02 at t = 1 for steps of 0.1,
    the margin)."""
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                Body("e", 3e-6, [1.0, 0, 0], [0, 1.0, 0]),
                Body("j", 1e-3, [5.2, 0, 0.1], [0, 0.44, 0.01])])
    t = np.linspace(0.0, 5.0, 6)

    def megno(**kw):
        return Simulation(s, method="radau15", variational=True, stm=stm,
                          **kw).integrate(t).megno

    np.testing.assert_array_equal(megno(dt=1e-2, tangent_control=True), megno(dt=1e-2))
    ref = megno(dt=1e-4)
    ctrl = megno(tangent_control=True)
    assert np.all(np.isfinite(ctrl)) and np.all(ctrl[1:] > 0.1)
    np.testing.assert_allclose(ctrl, ref, rtol=0, atol=0.03)
    np.testing.assert_array_equal(megno(tangent_control=True), ctrl)


@pytest.mark.parametrize("method, run_kw", [
    ("leapfrog", {}),
    ("wh", {"jacobi": False}),
    ("wh", {"jacobi": True}),
])
def test_tangent_maps_in_slices_and_stop(method, run_kw):
    """The fixed-step tangent maps run in slices of steps as the plain drivers do
    (``stop()`` and Ctrl-C are seen between them): slices of 7 steps give the
    trajectory and the STM of one call to rounding (the same step count; each
    slice recomputes the step from what is left, as the plain leapfrog kernel
    does), and ``stop()`` ends the run inside an output interval; the engine,
    which asks ``stop()`` after each output too, reports such a run incomplete."""
    from hamilton_orbits import engine
    from hamilton_orbits.integrators import StopIntegration, _tangent, output_arrays

    s = _three()
    gm = np.array(s.gm, dtype=np.float64)  # the drivers' own copy
    rhs = compile_rhs(s, (), variational=True)
    t_out = np.array([0.0, 1.0, 2.05])
    state = {"leapfrog": _tangent.LeapfrogTangent, "wh": _tangent.WHTangent}[method]

    def runner(rhs, r0, v0, gm, t_out, tan, *, stop=None, **kw):
        driver = state(rhs, r0, v0, gm, t_out[0], tan, **kw)
        tan.new_leg(len(t_out))
        r, v = output_arrays(None, len(t_out), r0, v0)
        driver.advance(t_out, r, v, None, stop)
        return r, v, driver.steps

    ends = []
    for slice_steps in (_tangent.SLICE, 7):
        tan = _tangent.Tangent(3, 3, stm=True)
        r, v, steps = runner(rhs, s.r, s.v, gm, t_out, tan, dt=0.01, slice_steps=slice_steps,
                             **run_kw)
        ends.append((r[-1], v[-1], tan.stm[-1], tan.megno[-1], steps))
    (r1, v1, m1, y1, n1), (r7, v7, m7, y7, n7) = ends
    assert n1 == n7 == 205
    assert np.max(np.abs(r1 - r7)) < 1e-13 and np.max(np.abs(v1 - v7)) < 1e-13
    assert np.max(np.abs(m1 - m7)) < 1e-11
    # MEGNO's samples restart at each synchronisation (wh): the sum, not each term
    assert abs(y1 - y7) < 1e-2
    asked = []
    with pytest.raises(StopIntegration):
        runner(rhs, s.r, s.v, gm, t_out, _tangent.Tangent(3, 3), dt=0.01, slice_steps=7,
               stop=lambda: asked.append(1) or len(asked) > 2, **run_kw)
    assert len(asked) == 3
    out = engine.run(s.r, s.v, gm, t_out, rhs, method, dt=0.01, stop=lambda: True,
                     variational=_tangent.Tangent(3, 3))
    assert not out.complete and len(out.t) == 2 and out.variational.megno[1] > 0


def test_radau15_variational_asks_stop_between_slices():
    """radau15's variational run asks ``stop()`` between its slices of steps, as
    the plain run does."""
    from hamilton_orbits.integrators import StopIntegration, _tangent

    s = _three()
    rhs = compile_rhs(s, (), variational=True)
    asked = []
    driver = _tangent.Radau15Tangent(rhs, s.r, s.v, np.array(s.gm, dtype=np.float64), 0.0,
                                     _tangent.Tangent(3, 2), dt=0.01, tol=1e-9, prs23=False,
                                     max_steps=10_000, slice_steps=5, control=False)
    r, v = np.empty((2, 3, 3)), np.empty((2, 3, 3))
    with pytest.raises(StopIntegration):
        driver.advance(np.array([0.0, 20.0]), r, v, None,
                       lambda: asked.append(1) or len(asked) > 1)
    assert len(asked) == 2


def test_radau15_variational_stops_with_the_plain_runs_reason():
    """radau15 with ``variational=True`` stopped "(status 3: a non-finite
    acceleration, an underflowing step, or more than max_steps = 10 steps)", leaving
    the cause to guess; it gives the plain run's words: the budget (and the pace)
    as :func:`check_pace` says them, and the step's underflow with its ``dt``."""
    from hamilton_orbits.validation import ConvergenceError

    def message(system, t, **kw):
        with pytest.raises(ConvergenceError) as info:
            integrate(system, t, **kw)
        return str(info.value)

    plain = message(_three(), 20.0, max_steps=10)
    assert "reached t = " in plain and "more than max_steps = 10 " in plain
    assert message(_three(), 20.0, max_steps=10, variational=True) == plain
    crash = System([Body("a", 1.0, [0, 0, 0], [0, 0, 0]), Body("b", 1.0, [1e-3, 0, 0], [0, 0, 0])])
    plain = message(crash, 1.0)
    assert "the step underflowed (dt = " in plain
    assert message(crash, 1.0, variational=True) == plain.replace("radau15 stopped",
                                                                  "radau15 (variational) stopped")


# ---------------------------------------------------------------------------
# The API


def test_variational_api_and_errors():
    s = _three()
    tr = integrate(s, [1.0, 2.0], method="wh", dt=0.01, variational=True)
    assert tr.megno.shape == (3,) and tr.lyapunov.shape == (3,) and tr.stm is None
    assert tr.megno[0] == 0.0
    plain = integrate(s, 2.0, method="wh", dt=0.01)
    assert plain.megno is None and plain.stm is None
    with pytest.raises(ValueError, match="needs `variational=True`"):
        integrate(s, 1.0, stm=True)
    with pytest.raises(ValueError, match="`tangent` to have shape"):
        integrate(s, 1.0, variational=True, tangent=np.ones(5))
    sim = Simulation(s, method="radau15", variational=True)
    sim.integrate(1.0)
    with pytest.raises(ValueError, match=r"in one direction: this run went forwards \(to t = "
                                         r"1\.0\); start a new run"):
        sim.integrate(0.5)
    with pytest.raises(ValueError, match="corrector"):
        integrate(s, 1.0, method="wh", dt=0.01, coordinates="jacobi", corrector=3,
                  variational=True)


def test_variational_with_quantities():
    """A Quantity system: MEGNO dimensionless, the Lyapunov exponent in 1/(the unit
    of t), the STM in au and days."""
    import astropy.units as u

    s = System.solar_system(bodies=["sun", "jupiter", "saturn"])
    tr = integrate(s, 100 * u.yr, method="wh", dt=50 * u.day, variational=True, stm=True)
    assert tr.lyapunov.unit == 1 / u.yr
    assert tr.stm.shape == (2, 18, 18)
    assert abs(tr.megno[-1] - 2) < 0.5


# ---------------------------------------------------------------------------
# Scenes and ensembles


def test_scene_reports_megno_and_lyapunov_time():
    """``variational = true`` in a scene: MEGNO, the Lyapunov exponent and time in the
    summary and the metrics, MEGNO over time as a diagnostic and a figure."""
    import astropy.units as u

    from hamilton_orbits import Scene

    res = Scene.bundled("stability-map").with_values({"duration": "1200 yr",
                                                      "cadence": "300 yr"}).run(progress=False)
    assert abs(res.metrics["MEGNO"] - 2.0) < 0.1  # a = 8 au, e = 0.05: regular
    assert res.metrics["Lyapunov time"].unit == u.yr
    # issue 32 item 9: the exponent is negative (-2.7e-4 per year), the time inf, and
    # the summary says why (not -1/2.7e-4 = -3700 yr)
    assert res.metrics["Lyapunov exponent"].value < 0
    assert res.metrics["Lyapunov time"].value == np.inf
    assert "exponent is not positive" in res.metrics["Lyapunov note"]
    assert "Lyapunov note" in res.summary()
    assert res.diagnostics["megno"].shape == (5,)
    assert "MEGNO" in res.summary() and "Lyapunov time" in res.summary()
    assert [f.get_label() for f in res.plot()][-1] == "megno"


def test_scene_variational_refuses_events():
    from hamilton_orbits import Scene
    from hamilton_orbits.scene import SceneError

    with pytest.raises(SceneError, match="variational"):
        Scene.bundled("stability-map").with_values(
            {"events": [{"name": "escape", "distance": "100 au"}]})


def test_ensemble_rows_carry_megno():
    """Numeric metrics flow into Ensemble rows: MEGNO and the Lyapunov time per
    member (a regular cell, a = 8 au, e = 0.05, and chaotic ones at e = 0.35)."""
    from hamilton_orbits import Ensemble, Scene

    scene = Scene.bundled("stability-map").with_values({"duration": "2400 yr",
                                                        "cadence": "1200 yr"})
    df = Ensemble(scene, vary={"bodies.planet.a": ["8.0 au", "7.5 au"],
                               "bodies.planet.e": [0.05, 0.35]}).run(progress=False, workers=1)
    assert df.attrs["failures"] == 0
    assert {"MEGNO", "Lyapunov time [yr]", "Lyapunov exponent [1 / yr]"} <= set(df.columns)
    assert df["MEGNO"].iloc[0] < 2.2 and df["MEGNO"].max() > 4


@pytest.mark.parametrize("scale", [1e300, 1e-170])
def test_a_tangent_whose_square_leaves_float64_is_refused(scale):
    """MEGNO takes the log of the tangent's squared norm: a tangent of 1e300 (its
    square inf) gave MEGNO and the Lyapunov exponent NaN, without a warning; one of
    1e-170 (its square 0) likewise.  Any scale between gives the same MEGNO."""
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                Body("p", 1e-3, [1.0, 0, 0], [0, 1.0, 0])])
    with pytest.raises(ValueError, match=r"`tangent` of a norm of about 1e-150 to 1e150 .* got "
                                         r"a norm of 3.46e[+-]"):
        integrate(s, 2.0, method="wh", dt=0.01, variational=True,
                  tangent=np.full((2, 6), scale))
    with pytest.raises(ValueError, match=r"`tangent` to be nonzero, got all zeros"):
        integrate(s, 2.0, method="wh", dt=0.01, variational=True, tangent=np.zeros((2, 6)))
    one, wide = (integrate(s, 2.0, method="wh", dt=0.01, variational=True,
                           tangent=np.full((2, 6), k)) for k in (1.0, 1e150))
    np.testing.assert_allclose(wide.megno, one.megno, rtol=1e-13)  # (rounding apart)
