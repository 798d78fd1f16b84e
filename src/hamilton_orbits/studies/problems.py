"""The work-precision report's own problems, each a function ``(quick, progress) ->
list[Row]``: two-body Kepler propagation (:func:`kepler_problem`), the solar system
(:func:`solar_system_problem`) and fidelity against DE440 (:func:`de440_problem`),
problems 1 to 3 of :mod:`hamilton_orbits.studies.report`, which says what each
measures and against which reference.  :data:`SETTINGS` says how each peer is set.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from hamilton_orbits.studies.rows import Row, log, timed

__all__ = ["SETTINGS", "de440_problem", "kepler_problem", "solar_system_problem"]


# --------------------------------------------------------------------------- 1. Kepler
def kepler_problem(quick: bool, progress: bool) -> list[Row]:
    import mpmath
    import rebound
    from scipy.integrate import solve_ivp

    from hamilton_orbits.orbit import KeplerOrbit

    name = "two-body Kepler"
    measure = "max |r - r_ref| / a"
    reference = "Kepler's equation in mpmath (40 digits)"
    a, e, mu = 2.0, 0.5, 1.0
    period = 2 * math.pi * a**1.5
    n_t = 20 if quick else 200
    t = np.linspace(0.0, 10 * period, n_t + 1)[1:]
    r0 = np.array([a * (1 - e), 0.0, 0.0])
    v0 = np.array([0.0, math.sqrt(mu * (1 + e) / (a * (1 - e))), 0.0])

    mpmath.mp.dps = 40
    ref = np.empty((n_t, 3))
    b = mpmath.mpf(a) * mpmath.sqrt(1 - mpmath.mpf(e) ** 2)
    n = mpmath.sqrt(mpmath.mpf(mu) / mpmath.mpf(a) ** 3)
    for k, tk in enumerate(t):
        m_anom = n * mpmath.mpf(tk)
        ecc = mpmath.findroot(lambda x, m_anom=m_anom: x - e * mpmath.sin(x) - m_anom, m_anom)
        ref[k] = [float(a * (mpmath.cos(ecc) - e)), float(b * mpmath.sin(ecc)), 0.0]

    def err(r: np.ndarray) -> float:
        return float(np.max(np.linalg.norm(r - ref, axis=1)) / a)

    rows = []
    orbit = KeplerOrbit.from_state(np.tile(r0, (n_t, 1)), np.tile(v0, (n_t, 1)), np.full(n_t, mu))
    orbit.propagate(t)  # compile / warm up
    wt, out = timed(lambda: orbit.propagate(t).state()[0], 5)
    rows.append(Row(name, "hamilton-orbits", "KeplerOrbit.propagate", f"batch of {n_t}",
                    err(np.asarray(out)), measure, reference, wt))

    def whfast(dt: float) -> np.ndarray:
        sim = rebound.Simulation()
        sim.G = 1.0
        sim.integrator = "whfast"
        sim.add(m=mu)
        sim.add(m=0.0, x=r0[0], y=r0[1], z=r0[2], vx=v0[0], vy=v0[1], vz=v0[2])
        sim.dt = dt
        out = np.empty((n_t, 3))
        for k, tk in enumerate(t):
            sim.integrate(tk, exact_finish_time=1)
            out[k] = np.array(sim.particles[1].xyz) - np.array(sim.particles[0].xyz)
        return out

    for frac in (10, 100) if quick else (10, 100, 1000):
        dt = period / frac
        wt, out = timed(lambda dt=dt: whfast(dt))
        rows.append(Row(name, "rebound", "WHFast", f"dt = P/{frac}", err(out), measure,
                        reference, wt))

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        r = y[:3]
        return np.concatenate([y[3:], -mu * r / np.dot(r, r) ** 1.5])

    for rtol in (1e-6, 1e-9, 1e-12):
        def dop(rtol: float = rtol) -> np.ndarray:
            sol = solve_ivp(rhs, (0.0, t[-1]), np.concatenate([r0, v0]), method="DOP853",
                            t_eval=t, rtol=rtol, atol=rtol * 1e-3)
            return sol.y[:3].T
        wt, out = timed(dop)
        rows.append(Row(name, "scipy", "DOP853", f"rtol = {rtol:g}", err(out), measure,
                        reference, wt))
    log(progress, f"{name}: {len(rows)} rows")
    return rows


# --------------------------------------------------------------------------- 2. solar system
_Case = tuple[str, str, str, Callable[[], np.ndarray]]


def solar_system_problem(quick: bool, progress: bool) -> list[Row]:
    import astropy.units as u

    from hamilton_orbits import System

    name = "solar system"
    years = 10 if quick else 1000
    measure = "max_planet |r - r_ref| / |r_ref| (heliocentric, final)"
    system = System.solar_system("J2000")
    r0 = system.r.to_value(u.au)
    v0 = system.v.to_value(u.au / u.day)
    gm = (system.gm).to_value(u.au**3 / u.day**2)
    t_end = years * 365.25
    ref, reference = _solar_reference(r0, v0, gm, t_end, progress)
    scale = np.linalg.norm(ref, axis=1)
    cases = (_solar_ours(r0, v0, gm, t_end, quick) + _solar_rebound(r0, v0, gm, t_end, quick)
             + _heyoka_cases(r0, v0, gm, t_end, quick, progress))
    rows = []
    for code, method, param, fn in cases:
        wt, out = timed(fn, 2)
        error = float(np.max(np.linalg.norm(_helio(out) - ref, axis=1) / scale))
        rows.append(Row(name, code, method, param, error, measure, reference, wt))
        log(progress, f"{name}: {code} {method} {param}: err {error:.2e} time {wt:.3f} s")
    return rows


def _solar_reference(r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, t_end: float,
                     progress: bool) -> tuple[np.ndarray, str]:
    """The final heliocentric positions of radau15 in double-double at 1-day steps
    (:func:`hamilton_orbits.studies.reference.reference`, cached on disk), and the reference's
    description with its own uncertainty: the same measure between the runs at 1
    and 2 days (an upper bound: the error at 1 day is ~2^16 times smaller)."""
    from hamilton_orbits.studies.reference import reference

    log(progress, f"solar system: reference, radau15 in double-double at 1 and 2 days "
                  f"({t_end / 365.25:g} yr; minutes the first time, then from the cache)")
    ref = reference(r0, v0, gm, np.array([0.0, t_end]), 1.0)
    h, h_check = _helio(ref.r[-1]), _helio(ref.r_check[-1])
    own = float(np.max(np.linalg.norm(h_check - h, axis=1) / np.linalg.norm(h, axis=1)))
    log(progress, f"solar system: reference {'from the cache' if ref.cached else 'computed'}"
                  f" ({ref.seconds:.0f} s), uncertainty {own:.1e}")
    bound = f"{own:.0e}" if own >= 1e-16 else "< 1e-16"  # the doubles compared resolve 1e-16
    return h, (f"radau15 in double-double, dt = 1 d (uncertainty {bound}: its distance from "
               "dt = 2 d)")


def _helio(r: np.ndarray) -> np.ndarray:
    return r[1:] - r[0]


def _rebound_run(r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, t_end: float,
                 integrator: str, dt: float, epsilon: float | None = None,
                 coordinates: str | None = None, corrector: int = 0) -> np.ndarray:
    """rebound's final positions from the same state (G = 1, m = gm); WHFast with
    ``corrector`` runs with ``safe_mode = 0`` (the corrector applied once, as ours)."""
    from hamilton_orbits._rebound import simulation_from_arrays

    sim = simulation_from_arrays([f"b{k}" for k in range(len(gm))], gm, r0, v0)
    sim.integrator = integrator
    if epsilon is not None:
        sim.integrator.epsilon = epsilon
    if coordinates is not None:
        sim.integrator.coordinates = coordinates
    if corrector:  # with safe_mode 0: the corrector applied at the start and end only
        sim.integrator.corrector = corrector
        sim.integrator.safe_mode = 0
    sim.dt = dt
    sim.integrate(t_end, exact_finish_time=1)
    return np.array([p.xyz for p in sim.particles])


def _solar_ours(r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, t_end: float,
                quick: bool) -> list[_Case]:
    """Our integrators through the engine (the kernels compiled before timing)."""
    from hamilton_orbits import engine
    from hamilton_orbits.rhs import newtonian_rhs

    rhs = newtonian_rhs()

    def ours(method: str, dt: float | None = None, tol: float | None = None, **options: Any):
        def run(t: float = t_end) -> np.ndarray:
            return engine.run(r0, v0, gm, np.array([0.0, t]), rhs, method, dt=dt, tol=tol,
                              options=options).r[-1]
        run(10.0)  # warm up (compile) on a short span
        return run

    cases: list[_Case] = []
    for tol in (1e-6, 1e-9) if quick else (1e-6, 1e-9, 1e-12):
        cases.append(("hamilton-orbits", "radau15", f"tol = {tol:g}", ours("radau15", tol=tol)))
    for label, options in (("wh", {}), ("wh (Jacobi)", {"coordinates": "jacobi"}),
                           *((f"wh (Jacobi, corrector {c})", {"coordinates": "jacobi",
                                                              "corrector": c})
                             for c in (3, 11, 17))):
        for dt in _WH_STEPS[quick]:
            cases.append(("hamilton-orbits", label, f"dt = {dt:g} d", ours("wh", dt, **options)))
    for dt in _LEAPFROG_STEPS[quick]:
        cases.append(("hamilton-orbits", "leapfrog", f"dt = {dt:g} d", ours("leapfrog", dt=dt)))
    for tol in (1e-8, 1e-11) if quick else (1e-10, 1e-12, 1e-14):
        cases.append(("hamilton-orbits", "dop853", f"tol = {tol:g}", ours("dop853", tol=tol)))
    return cases


_WH_STEPS = {True: (8.0, 2.0), False: (8.0, 4.0, 2.0, 1.0)}
_LEAPFROG_STEPS = {True: (1.0, 0.25), False: (1.0, 0.5, 0.25)}


def _solar_rebound(r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, t_end: float,
                   quick: bool) -> list[_Case]:
    """rebound's IAS15, WHFast (Jacobi and democratic heliocentric) and leapfrog."""
    def reb(integrator: str, dt: float, epsilon: float | None = None,
            coordinates: str | None = None, corrector: int = 0) -> Callable[[], np.ndarray]:
        return lambda: _rebound_run(r0, v0, gm, t_end, integrator, dt, epsilon, coordinates,
                                    corrector)

    cases: list[_Case] = [("rebound", "IAS15", f"epsilon = {eps:g}", reb("ias15", 1.0, eps))
                          for eps in (1e-6, 1e-9)]
    for dt in _WH_STEPS[quick]:  # rebound's default: Jacobi coordinates
        cases.append(("rebound", "WHFast", f"dt = {dt:g} d", reb("whfast", dt)))
    for corrector in (11, 17):
        for dt in _WH_STEPS[quick]:
            cases.append(("rebound", f"WHFast (corrector {corrector})", f"dt = {dt:g} d",
                          reb("whfast", dt, corrector=corrector)))
    for dt in _WH_STEPS[quick]:  # the map our ``wh`` uses by default
        cases.append(("rebound", "WHFast (democratic heliocentric)", f"dt = {dt:g} d",
                      reb("whfast", dt, coordinates="democraticheliocentric")))
    for dt in _LEAPFROG_STEPS[quick]:
        cases.append(("rebound", "leapfrog", f"dt = {dt:g} d", reb("leapfrog", dt)))
    return cases


def _heyoka_cases(r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, t_end: float,
                  quick: bool, progress: bool) -> list[_Case]:
    """heyoka's adaptive Taylor integrator on the same system, where heyoka is installed.

    The Taylor integrator is built (LLVM compilation, reported, not timed) once per
    tolerance, in heyoka's ``high_accuracy`` mode (compensated summation, its
    recommendation for long integrations: without it the 10-year error at
    tol = 1e-15 is ~1e-11 instead of ~1e-13); each timed run resets its state and
    propagates to ``t_end``.

    heyoka's tolerance is relative to the largest component of the whole state
    vector (Neptune's 30 au), not to each body's own, so Mercury (0.4 au) is
    held 75 times more loosely than the tolerance says: at tol = 1e-15 Mercury's
    error is 3.2e-11 after 10 years, 1.9e-9 after 100 and 1.6e-7 after 1000.
    Tolerances below the double epsilon still help, at almost the same cost
    (measured on 2026-11-25, 1000 years: 3.6e-9 at 1e-16, 3.2e-9 at 1e-17,
    6.3e-10 at 1e-18, 5.1e-10 at 1e-19, where it levels off; 100 years: 5.1e-11
    at 1e-16, 2.8e-11 at 1e-18): tol = 1e-18 is its best setting for this
    problem, and the sweep goes down to it.
    """
    try:
        import heyoka as hy
    except ImportError:
        log(progress, "solar system: heyoka not installed, its rows are left out")
        return []
    n = len(gm)
    state0 = np.hstack([r0, v0]).ravel()
    model = hy.model.nbody(n, masses=[float(m) for m in gm], Gconst=1.0)
    out = []
    for tol in (1e-9, 1e-18) if quick else (1e-9, 1e-12, 1e-15, 1e-16, 1e-18):
        t0 = time.perf_counter()
        ta = hy.taylor_adaptive(model, state0, tol=tol, compact_mode=True, high_accuracy=True)
        log(progress, f"solar system: heyoka tol = {tol:g} compiled in "
                       f"{time.perf_counter() - t0:.2f} s (not timed)")

        def run(ta: Any = ta) -> np.ndarray:
            ta.time = 0.0
            ta.state[:] = state0
            ta.propagate_until(t_end)
            return np.array(ta.state).reshape(n, 6)[:, :3]
        out.append(("heyoka", "taylor_adaptive", f"tol = {tol:g}", run))
    return out


#: How each peer is set, and why that is its best setting for the problem.
SETTINGS = (
    "rebound IAS15: epsilon 1e-6 and 1e-9 (its default), its default step rule (PRS23).",
    "rebound WHFast: Jacobi coordinates (its default), alone and with its symplectic "
    "corrector of order 11 and safe_mode = 0 (its best setting for long runs: the "
    "corrector at the start and end only); and democratic heliocentric coordinates, the "
    "map our `wh` uses by default.",
    "rebound leapfrog: the step swept.",
    "heyoka taylor_adaptive (where installed): high_accuracy = True (compensated "
    "summation, its advice for long runs), compact_mode; its tolerance is relative to the "
    "largest component of the whole state (Neptune's 30 au), so Mercury (0.4 au) is held "
    "75 times more loosely; tolerances below the double epsilon still help at the same "
    "cost, down to tol = 1e-18, its best setting here (1000 years: 1.6e-7 at tol = "
    "1e-15, 3.6e-9 at 1e-16, 6.3e-10 at 1e-18, levelling off at 5.1e-10 at 1e-19).",
    "scipy DOP853: rtol swept, atol = 1e-3 rtol (Kepler) or as rigid.integrate sets it.",
    "Ours: radau15 over tol, wh over dt in each of its coordinate systems, dop853 over tol.",
)


# --------------------------------------------------------------------------- 3. DE440
def de440_problem(quick: bool, progress: bool) -> list[Row]:
    """Fidelity against DE440: each rung of the physics ladder
    (:mod:`hamilton_orbits.studies.ladder`) from DE440's J2000 state, its largest position
    residual against DE440 over the planets and Pluto (as an angle seen from the
    Sun, a relative error) and, on rows of their own, the Moon's (seen from the
    Earth), against its wall time."""
    from hamilton_orbits.studies.ladder import BODIES, RUNGS, run_rung

    years = 10 if quick else 100
    name = "fidelity against DE440"
    reference = "JPL DE440 (Park et al. 2021), its positions at whole years"
    planets = [k for k, b in enumerate(BODIES) if b not in ("moon", "earth")]
    moon = BODIES.index("moon")
    measure = (f"|dr| / r against DE440 after {years} yr: the largest over the planets and "
               "Pluto (heliocentric), and the Moon's (geocentric)")
    rows = []
    for rung in RUNGS:
        res = run_rung(rung, years)
        rad = np.radians(res.arcsec[-1] / 3600.0)
        for code, error in (("hamilton-orbits radau15", rad[planets].max()),
                            ("hamilton-orbits radau15 (the Moon)", rad[moon])):
            rows.append(Row(name, code, rung.name, f"{years} yr", float(error), measure,
                            reference, res.wall_time))
        log(progress, f"{name}: {rung.name}: planets {rows[-2].error:.2e}, Moon "
                      f"{rows[-1].error:.2e} in {res.wall_time:.2f} s")
    return rows
