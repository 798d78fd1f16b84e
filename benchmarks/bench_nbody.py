"""N-body integrators against rebound: wall time, cost per step, work-precision.

Run:  python benchmarks/bench_nbody.py [--quick]

One process, the same initial floats for both sides (rebound with G = 1, so
m = GM; au and day).  Ratios are rebound time / our time (> 1: we are faster),
the median over repeats of the per-repeat ratio.  JIT warm-up (first call:
loading the numba cache, or compiling when there is none) is reported apart.

0. JIT warm-up of radau15 and wh.
1. The solar system (Sun + 8 planets, J2000, astropy's built-in ephemeris,
   DE430 GM) over 1000 years (100 with --quick): radau15 vs IAS15, each with
   its default step criterion (PRS23) and with the global one, energy errors.
2. wh vs WHFast at the same dt (4 days), time per step and energy error:
   democratic-heliocentric (against WHFast with and without safe mode) and
   Jacobi (without and with the third-order corrector).
3. Scaling, cost per step: 3, 10, 100, 1000 massive bodies, and 1e2 .. 1e5
   test particles around the solar system; radau15 (fixed dt: IAS15 with
   epsilon = 0) and wh vs WHFast.
4. Work-precision sweep on the solar system (1000 years; 100 with --quick):
   radau15 over tol, wh in democratic-heliocentric coordinates and in Jacobi
   coordinates with every corrector (0, 3, 5, 7, 11, 17) over dt, rebound's
   IAS15 over epsilon and WHFast (Jacobi, correctors 0, 3, 11, 17, safe_mode
   0) over dt, and heyoka's Taylor integrator where installed (its best
   setting here: high_accuracy=True, compact_mode=False, over tol); error = max
   over planets of the heliocentric position error over the distance against
   radau15 in double-double at 1 day (hamilton_orbits.studies.reference, cached),
   whose own uncertainty (its distance from 2 days) is printed beside every
   error; CPU time, the shortest of 2 runs; and the CPU time each code needs
   to reach 1e-6, 1e-8, 1e-10.  Written to
   benchmarks/results/nbody_work_precision.{md,png}.
5. leapfrog against rebound's; 6. what an effect costs (radau15).
7. Cost per call beyond its steps at N = 2, 10, 100 and 10 + 1e5 test
   particles: ours ``integrate`` on a System, rebound ``sim.copy()``,
   ``integrate``, ``synchronize`` and the states read out.
8. Peak memory per test particle of one call (10 + 1e5; 1e4 with --quick),
   each in its own process.
9. KeplerOrbit.propagate of 1e6 orbits on one and two threads beside a
   compute-only yardstick (what the shared machine's second core gives), in a
   child process with two threads.
10. One radau15 step of the N = 10 disc: its floating-point operations, the
    fraction of the machine's scalar and SIMD throughput it reaches; the force
    evaluation beside a SIMD form.
11. wh against WHFast over a seeded spread of independent discs (N = 3 and 10;
    planet masses log-uniform 1e-7 .. 1e-3; tight or wide spacings;
    near-circular or eccentric orbits; dt 1/1000 .. 1/20 of the innermost
    period), democratic heliocentric for both (WHFast safe_mode 0), the same
    steps on both sides: per disc us/step and the ratio WHFast / ours, then
    the spread (min, median, max).

``--only 2 11`` runs those sections alone ([0], the warm-up, always first).
"""

from __future__ import annotations

import argparse
import importlib
import itertools
import math
import time
from pathlib import Path

import numpy as np

AU_KM = 149597870.7
DAY_S = 86400.0
GM_DE430_KM3_S2 = {  # Folkner et al. (2014), IPN Progress Report 42-196, table 8
    "sun": 132712440041.939400,
    "mercury": 22031.780000,
    "venus": 324858.592000,
    "earth-moon-barycenter": 403503.235502,
    "mars": 42828.375214,
    "jupiter": 126712764.800000,
    "saturn": 37940585.200000,
    "uranus": 5794548.600000,
    "neptune": 6836527.100580,
}
RESULTS = Path(__file__).resolve().parent / "results"


def solar_system():
    """r (au), v (au/day), GM (au^3/day^2) of the Sun and 8 planets at J2000 TDB."""
    import astropy.units as u
    from astropy.coordinates import get_body_barycentric_posvel, solar_system_ephemeris
    from astropy.time import Time

    t = Time("2000-01-01T12:00:00", scale="tdb")
    r = np.empty((9, 3))
    v = np.empty((9, 3))
    with solar_system_ephemeris.set("builtin"):
        for i, name in enumerate(GM_DE430_KM3_S2):
            p, w = get_body_barycentric_posvel(name, t)
            r[i] = p.xyz.to_value(u.au)
            v[i] = w.xyz.to_value(u.au / u.day)
    gm = np.array(list(GM_DE430_KM3_S2.values())) * DAY_S**2 / AU_KM**3
    return r, v, gm


def energy(r, v, gm):
    """Total energy (G m-weighted), Hamilton's integral (E)."""
    kin = 0.5 * np.sum(gm[:, None] * v * v)
    iu = np.triu_indices(len(gm), 1)
    d = np.linalg.norm(r[iu[0]] - r[iu[1]], axis=1)
    return kin - np.sum(gm[iu[0]] * gm[iu[1]] / d)


def to_rebound(r, v, gm, integrator):
    import rebound

    sim = rebound.Simulation()
    sim.G = 1.0
    sim.integrator = integrator
    for k in range(len(gm)):
        sim.add(
            m=float(gm[k]),
            x=float(r[k, 0]),
            y=float(r[k, 1]),
            z=float(r[k, 2]),
            vx=float(v[k, 0]),
            vy=float(v[k, 1]),
            vz=float(v[k, 2]),
        )
    n_active = int(np.count_nonzero(gm))
    if n_active < len(gm):
        sim.N_active = n_active
    return sim


def reb_state(sim):
    return np.array([p.xyz for p in sim.particles]), np.array([p.vxyz for p in sim.particles])


def timed(fn):
    """Process CPU time of one call (other jobs' time slices do not count)."""
    t0 = time.process_time()
    out = fn()
    return time.process_time() - t0, out


def timed_best(fn, repeat=3):
    """Shortest of ``repeat`` runs (for the sweep's short runs on a shared machine)."""
    best = np.inf
    for _ in range(repeat):
        t, out = timed(fn)
        best = min(best, t)
    return best, out


def median_ratio(ours, peer, repeat):
    """Run both ``repeat`` times, interleaved; medians and median ratio."""
    to, tp = [], []
    out_o = out_p = None
    for _ in range(repeat):
        t, out_o = timed(ours)
        to.append(t)
        t, out_p = timed(peer)
        tp.append(t)
    to, tp = np.array(to), np.array(tp)
    return float(np.median(to)), float(np.median(tp)), float(np.median(tp / to)), out_o, out_p


def rhs():
    from hamilton_orbits.rhs import newtonian_rhs

    return newtonian_rhs()


# ---------------------------------------------------------------------------


def bench_warmup() -> None:
    from hamilton_orbits.integrators import radau15, wh

    r0 = np.array([[0.0, 0, 0], [1.0, 0, 0], [0, 2.0, 0]])
    v0 = np.array([[0.0, 0, 0], [0, 1.0, 0], [-(0.5**0.5), 0, 0]])
    gm = np.array([1.0, 1e-3, 1e-3])
    t = np.array([0.0, 1.0])
    t_r, _ = timed(lambda: radau15.run(rhs(), r0, v0, gm, t))
    t_w, _ = timed(lambda: wh.run(rhs(), r0, v0, gm, t, dt=0.1))
    print("[0] JIT warm-up (first call in this process: numba cache load, or compile)")
    print(f"    radau15 {t_r:7.3f} s    wh {t_w:7.3f} s")


def bench_solar(years: float, repeat: int) -> None:
    from hamilton_orbits.integrators import radau15

    r0, v0, gm = solar_system()
    t_end = years * 365.25
    e0 = energy(r0, v0, gm)
    print(f"[1] solar system (9 bodies), {years:g} years: radau15 vs rebound IAS15")
    for crit, mode in (("prs23", "PRS23"), ("global", "GLOBAL")):

        def ours(crit=crit):
            return radau15.run(rhs(), r0, v0, gm, np.array([0.0, t_end]), criterion=crit)

        def peer(mode=mode):
            sim = to_rebound(r0, v0, gm, "ias15")
            sim.integrator.adaptive_mode = mode
            sim.dt = 1.0
            sim.integrate(t_end, exact_finish_time=1)
            return sim

        t_o, t_p, ratio, (r, v, steps), sim = median_ratio(ours, peer, repeat)
        x, w = reb_state(sim)
        de_o = abs(energy(r[-1], v[-1], gm) / e0 - 1)
        de_p = abs(energy(x, w, gm) / e0 - 1)
        scale = np.linalg.norm(x - x[0], axis=1)
        scale[0] = np.linalg.norm(x[0])
        dpos = np.max(np.linalg.norm(r[-1] - x, axis=1) / scale)
        print(
            f"    criterion {crit:6s}: ours {t_o:7.3f} s ({steps} steps, |dE/E| {de_o:.1e})"
            f"   IAS15 {t_p:7.3f} s ({sim.steps_done} steps, |dE/E| {de_p:.1e})"
            f"   ratio {ratio:5.2f}   max rel. position difference {dpos:.1e}"
        )


def bench_wh(years: float, repeat: int) -> None:
    from hamilton_orbits.integrators import wh

    r0, v0, gm = solar_system()
    dt = 4.0
    n = round(years * 365.25 / dt)
    t_end = n * dt
    e0 = energy(r0, v0, gm)
    print(f"[2] wh vs WHFast, solar system, dt = {dt} d, {n} steps (ratio = WHFast / ours)")
    cases = [
        ("democratic_heliocentric", 0, "democraticheliocentric", 0),
        ("democratic_heliocentric", 0, "democraticheliocentric", 1),
        ("jacobi", 0, "jacobi", 0),
        ("jacobi", 3, "jacobi", 0),
        ("jacobi", 11, "jacobi", 0),
        ("jacobi", 17, "jacobi", 0),
    ]
    for coords, corr, peer_coords, safe in cases:

        def ours(coords=coords, corr=corr):
            return wh.run(
                rhs(),
                r0,
                v0,
                gm,
                np.array([0.0, t_end]),
                dt=dt,
                coordinates=coords,
                corrector=corr,
            )

        def peer(peer_coords=peer_coords, corr=corr, safe=safe):
            sim = to_rebound(r0, v0, gm, "whfast")
            sim.dt = dt
            sim.integrator.coordinates = peer_coords
            sim.integrator.safe_mode = safe
            sim.integrator.corrector = corr
            sim.integrate(t_end, exact_finish_time=0)
            sim.synchronize()
            return sim

        t_o, t_p, ratio, (r, v, steps), sim = median_ratio(ours, peer, repeat)
        x, w = reb_state(sim)
        de_o = abs(energy(r[-1], v[-1], gm) / e0 - 1)
        de_p = abs(energy(x, w, gm) / e0 - 1)
        label = f"{coords}, corrector {corr}, WHFast safe_mode={safe}"
        print(
            f"    {label:55s}: ours {t_o / steps * 1e6:6.2f} us/step (|dE/E| {de_o:.1e})"
            f"   WHFast {t_p / steps * 1e6:6.2f} us/step (|dE/E| {de_p:.1e})   ratio {ratio:5.2f}"
        )


def _disc(n_massive: int, n_test: int, rng):
    """A star (GM 1) and bodies on near-circular, slightly inclined orbits."""
    n = n_massive + n_test
    a = rng.uniform(1.0, 10.0, n - 1)
    phase = rng.uniform(0, 2 * np.pi, n - 1)
    inc = rng.uniform(0, 0.05, n - 1)
    r = np.zeros((n, 3))
    v = np.zeros((n, 3))
    r[1:, 0] = a * np.cos(phase)
    r[1:, 1] = a * np.sin(phase) * np.cos(inc)
    r[1:, 2] = a * np.sin(phase) * np.sin(inc)
    s = 1 / np.sqrt(a)
    v[1:, 0] = -s * np.sin(phase)
    v[1:, 1] = s * np.cos(phase) * np.cos(inc)
    v[1:, 2] = s * np.cos(phase) * np.sin(inc)
    gm = np.zeros(n)
    gm[0] = 1.0
    gm[1:n_massive] = 1e-7
    return r, v, gm


def bench_scaling(quick: bool, repeat: int) -> None:
    from hamilton_orbits.integrators import radau15, wh

    rng = np.random.default_rng(1)
    dt = 0.05
    cases = [(2, 0), (3, 0), (10, 0), (30, 0), (100, 0), (1000, 0)]
    tests = [100, 1000, 10000, 100000]
    if quick:
        cases = cases[:5]
        tests = tests[:3]
    rs, vs, gs = solar_system()
    print("[3] cost per step (us); ratio = rebound / ours")
    print("    bodies (massive+test)   radau15   IAS15(eps=0)  ratio       wh   WHFast  ratio")
    rows = [(nm, 0, *_disc(nm, 0, rng)) for nm, _ in cases]
    for nt in tests:
        r, v, g = _disc(1, nt, rng)
        r = np.concatenate([rs, 1.5 * r[1:] + rs[0]])
        v = np.concatenate([vs, 0.0172 / np.sqrt(1.5) * v[1:] + vs[0]])
        g = np.concatenate([gs, np.zeros(nt)])
        rows.append((9, nt, r, v, g))
    for nm, nt, r, v, g in rows:
        work = (nm + nt) * nm
        # at least 50 steps, and ~10^6 pair evaluations at small N (10^4 steps at
        # N = 10, 5 * 10^4 at N = 2-3), so that a call's fixed cost (input checks,
        # setup: ~0.07 ms for ours, ~0.03 for rebound's, section [7]) does not
        # pass for cost per step: with 1000 steps of 1 us at N = 10 it was 4% of it
        n_steps = int(max(50, min(50_000, 2e7 / work / 20)))
        dtw = dt if nt == 0 else 1.0
        t_end = n_steps * dtw

        def ours_r(r=r, v=v, g=g, t_end=t_end, dtw=dtw):
            return radau15.run(rhs(), r, v, g, np.array([0.0, t_end]), dt=dtw)

        # rebound's simulations are built outside the timed region (adding
        # particles from Python would dominate); the timed part copies one
        sim_r = to_rebound(r, v, g, "ias15")
        sim_r.integrator.epsilon = 0.0
        sim_r.dt = dtw
        sim_w = to_rebound(r, v, g, "whfast")
        sim_w.dt = dtw
        sim_w.integrator.coordinates = "democraticheliocentric"
        sim_w.integrator.safe_mode = 0

        def peer_r(sim_r=sim_r, t_end=t_end):
            sim = sim_r.copy()
            sim.integrate(t_end, exact_finish_time=0)
            return sim

        def ours_w(r=r, v=v, g=g, t_end=t_end, dtw=dtw):
            return wh.run(rhs(), r, v, g, np.array([0.0, t_end]), dt=dtw)

        def peer_w(sim_w=sim_w, t_end=t_end):
            sim = sim_w.copy()
            sim.integrate(t_end, exact_finish_time=0)
            sim.synchronize()
            return sim

        tr_o, tr_p, rr, *_ = median_ratio(ours_r, peer_r, repeat)
        tw_o, tw_p, rw, *_ = median_ratio(ours_w, peer_w, repeat)
        k = n_steps
        print(
            f"    {nm:5d} + {nt:6d}  {tr_o / k * 1e6:12.1f} {tr_p / k * 1e6:12.1f} {rr:6.2f}"
            f" {tw_o / k * 1e6:10.1f} {tw_p / k * 1e6:8.1f} {rw:6.2f}"
        )


# ---------------------------------------------------------------------------
# work-precision


def _ours_modules():
    out = {}
    for name in ("radau15", "wh", "leapfrog", "dop853"):
        try:
            out[name] = importlib.import_module(f"hamilton_orbits.integrators.{name}")
        except ImportError:
            print(f"    (hamilton_orbits.integrators.{name} not present: skipped)")
    return out


WH_DTS = (8.0, 4.0, 2.0, 1.0, 0.5)
OUR_CORRECTORS = (0, 3, 5, 7, 11, 17)
WHFAST_CORRECTORS = (0, 3, 11, 17)
HEYOKA = "taylor_adaptive, high_accuracy=True, compact_mode=False"


def _wp_ours(r0, v0, gm, t_end, quick):
    """(code, method, parameter, value, run) of our integrators in the sweep."""
    mods = _ours_modules()
    t = np.array([0.0, t_end])
    cases = []
    for tol in (1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9) + (() if quick else (1e-10, 1e-11)):
        cases.append(("ours", "radau15", "tol", tol,
                      lambda tol=tol: mods["radau15"].run(rhs(), r0, v0, gm, t, tol=tol)))
    for dt in WH_DTS:
        cases.append(("ours", "wh", "dt", dt,
                      lambda dt=dt: mods["wh"].run(rhs(), r0, v0, gm, t, dt=dt)))
    for c in OUR_CORRECTORS:
        for dt in WH_DTS:
            cases.append(("ours", f"wh-jacobi-c{c}", "dt", dt,
                          lambda dt=dt, c=c: mods["wh"].run(rhs(), r0, v0, gm, t, dt=dt,
                                                            coordinates="jacobi", corrector=c)))
    return cases


def _wp_peers(r0, v0, gm, t_end, quick):
    """rebound's IAS15 and WHFast (Jacobi, correctors 0, 3, 11, 17; safe_mode 0, the
    corrector applied once as ours is) and heyoka where installed."""
    cases = []

    def ias15(eps):
        sim = to_rebound(r0, v0, gm, "ias15")
        sim.integrator.epsilon = eps
        sim.dt = 1.0
        sim.integrate(t_end, exact_finish_time=1)
        return reb_state(sim)

    def whfast(dt, c):
        sim = to_rebound(r0, v0, gm, "whfast")
        sim.dt = dt
        sim.integrator.coordinates = "jacobi"
        sim.integrator.safe_mode = 0
        sim.integrator.corrector = c
        sim.integrate(t_end, exact_finish_time=0)
        sim.synchronize()
        return reb_state(sim)

    for eps in (1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9):
        cases.append(("rebound", "ias15", "epsilon", eps, lambda eps=eps: ias15(eps)))
    for c in WHFAST_CORRECTORS:
        for dt in WH_DTS:
            cases.append(("rebound", f"whfast-jacobi-c{c}", "dt", dt,
                          lambda dt=dt, c=c: whfast(dt, c)))
    try:
        import heyoka as hy
    except ImportError:
        print("    (heyoka not installed: its rows are left out)")
        return cases
    model = hy.model.nbody(len(gm), masses=[float(m) for m in gm], Gconst=1.0)
    state0 = np.hstack([r0, v0]).ravel()
    for tol in (1e-9, 1e-12, 1e-15):
        ta = hy.taylor_adaptive(model, state0, tol=tol, compact_mode=False, high_accuracy=True)

        def run(ta=ta):
            ta.time = 0.0
            ta.state[:] = state0
            ta.propagate_until(t_end)
            s = np.array(ta.state).reshape(len(gm), 6)
            return s[:, :3], s[:, 3:]
        cases.append(("heyoka", "taylor", "tol", tol, run))
    return cases


def _time_to_reach(points, target):
    """The CPU time a method needs for ``target`` error, interpolated in log-log
    between its two settings that bracket it (None if none reaches it)."""
    pts = sorted(points)  # by time
    best = None
    for (t0, e0), (t1, e1) in itertools.pairwise(pts):
        if e0 > target >= e1 > 0 and e0 > 0:
            f = math.log(e0 / target) / math.log(e0 / e1)
            t = math.exp(math.log(t0) + f * math.log(t1 / t0))
            best = t if best is None else min(best, t)
    reached = [t for t, e in pts if e <= target]
    if reached:
        best = min(reached) if best is None else min(best, min(reached))
    return best


def bench_work_precision(years: float, repeat: int = 2) -> None:
    """Work-precision against radau15 in double-double (hamilton_orbits.studies.reference),
    whose own uncertainty (its distance from the run at twice the step) is
    printed beside the errors; CPU time, the shortest of ``repeat`` runs."""
    from hamilton_orbits.studies.reference import reference

    r0, v0, gm = solar_system()
    t_end = 8.0 * math.floor(years * 365.25 / 8.0)  # a multiple of every fixed dt below
    e0 = energy(r0, v0, gm)
    ref = reference(r0, v0, gm, np.array([0.0, t_end]), 1.0)
    x_ref = ref.r[-1]
    h_ref = x_ref[1:] - x_ref[0]
    scale = np.linalg.norm(h_ref, axis=1)
    own = float(np.max(np.linalg.norm((ref.r_check[-1][1:] - ref.r_check[-1][0]) - h_ref, axis=1)
                       / scale))
    own_s = f"{own:.0e}" if own >= 1e-16 else "< 1e-16"  # the doubles compared resolve 1e-16
    print(f"[4] work-precision, solar system {years:g} years; error = max over planets of the "
          f"heliocentric position error / distance against radau15 in double-double at 1 d "
          f"({'cached' if ref.cached else f'computed in {ref.seconds:.0f} s'}; its own "
          f"uncertainty, the distance from 2 d: {own_s}); CPU time, best of {repeat}")
    rows = []
    for code, method, par, value, fn in (_wp_ours(r0, v0, gm, t_end, years < 500)
                                         + _wp_peers(r0, v0, gm, t_end, years < 500)):
        best = math.inf
        for _ in range(repeat):
            c0 = time.process_time()
            out = fn()
            best = min(best, time.process_time() - c0)
            if best > 20.0:
                break
        r, v = out[0], out[1]
        r, v = (r[-1], v[-1]) if np.ndim(r) == 3 else (r, v)
        err = float(np.max(np.linalg.norm((r[1:] - r[0]) - h_ref, axis=1) / scale))
        de = abs(energy(r, v, gm) / e0 - 1)
        rows.append((code, method, par, value, best, err, de))
        print(f"    {code:8s} {method:18s} {par}={value:<8g} {best:8.3f} s   error {err:8.1e} "
              f"(reference +- {own_s})   |dE/E| {de:8.1e}")
    _equal_error(rows)
    _write_work_precision(rows, years, own, own_s)


def _equal_error(rows):
    """For each target error, the fastest setting of each code's families."""
    groups: dict[tuple[str, str], list] = {}
    for code, method, _, _, secs, err, _ in rows:
        groups.setdefault((code, method), []).append((secs, err))
    print("    CPU time to reach an error (log-log interpolation between settings):")
    for target in (1e-6, 1e-8, 1e-10):
        cells = []
        for (code, method), pts in groups.items():
            t = _time_to_reach(pts, target)
            if t is not None:
                cells.append((t, f"{code} {method}"))
        cells.sort()
        ours = next((c for c in cells if c[1].startswith("ours")), None)
        peer = next((c for c in cells if not c[1].startswith("ours")), None)
        text = ", ".join(f"{name} {t:.3g} s" for t, name in cells[:6])
        ratio = f"; fastest peer / fastest ours = {peer[0] / ours[0]:.2f}" if ours and peer else ""
        print(f"      {target:.0e}: {text}{ratio}")


def _write_work_precision(rows, years, own, own_s):
    RESULTS.mkdir(exist_ok=True)
    md = RESULTS / "nbody_work_precision.md"
    with md.open("w") as f:
        f.write(f"# Work-precision: solar system, {years:g} years (benchmarks/bench_nbody.py)\n\n"
                f"Reference: radau15 in double-double at 1-day steps; its own uncertainty (its "
                f"distance from 2-day steps) {own_s}.  CPU time.  heyoka: {HEYOKA}.\n\n")
        f.write("| code | method | parameter | CPU time (s) | max rel. pos. error | |dE/E| |\n")
        f.write("|---|---|---|---|---|---|\n")
        for code, method, par, value, secs, err, de in rows:
            f.write(f"| {code} | {method} | {par}={value:g} | {secs:.3f} | {err:.1e} "
                    f"| {de:.1e} |\n")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print(f"    table: {md} (matplotlib not installed: no figure)")
        return
    fig, ax = plt.subplots(figsize=(9, 6))
    groups: dict[tuple[str, str], list] = {}
    for code, method, _, _, secs, err, _ in rows:
        groups.setdefault((code, method), []).append((secs, err))
    colours = matplotlib.colormaps["tab20"].colors  # one colour per line (up to 20)
    for k, ((code, method), pts) in enumerate(groups.items()):
        ax.loglog([p[0] for p in pts], [max(p[1], 1e-17) for p in pts],
                  "-" if code == "ours" else "--", marker="o" if code == "ours" else "s",
                  ms=3, color=colours[k % 20], label=f"{code} {method}")
    ax.axhline(max(own, 1e-16), color="k", lw=0.8, ls=":",
               label=f"reference's own uncertainty ({own_s})")
    ax.set_xlabel("CPU time (s)")
    ax.set_ylabel("max relative heliocentric position error")
    ax.grid(True, which="both", alpha=0.3)
    # the empty corner above the reference line: no curve hidden
    ax.legend(fontsize=6, ncol=2, loc="lower left", bbox_to_anchor=(0.0, 0.1))
    ax.set_title(f"Solar system, {years:g} years: what accuracy costs")
    fig.tight_layout()
    png = RESULTS / "nbody_work_precision.png"
    fig.savefig(png, dpi=110)
    print(f"    table: {md}\n    figure: {png}")


def bench_leapfrog(years: float, repeat: int) -> None:
    from hamilton_orbits.integrators import leapfrog

    r0, v0, gm = solar_system()
    dt = 0.5
    n = round(years * 365.25 / dt)
    t_end = n * dt
    print(f"[5] leapfrog vs rebound leapfrog, solar system, dt = {dt} d, {n} steps")

    def ours():
        return leapfrog.run(rhs(), r0, v0, gm, np.array([0.0, t_end]), dt=dt)

    def peer():
        sim = to_rebound(r0, v0, gm, "leapfrog")
        sim.dt = dt
        sim.integrate(t_end, exact_finish_time=0)
        return sim

    t_o, t_p, ratio, (r, _, steps), sim = median_ratio(ours, peer, repeat)
    x, _ = reb_state(sim)
    dpos = np.max(np.linalg.norm(r[-1] - x, axis=1)[1:] / np.linalg.norm(x[1:] - x[0], axis=1))
    print(f"    ours {t_o / steps * 1e6:6.2f} us/step   rebound {t_p / sim.steps_done * 1e6:6.2f}"
          f" us/step   ratio {ratio:5.2f}   max rel. position difference {dpos:.1e}")


def bench_effects_cost(years: float, repeat: int) -> None:
    """effects=() against a Newtonian kernel written here, and the price of listed effects."""
    from numba import njit

    from hamilton_orbits._kernels.signatures import ACCEL_SIGNATURE
    from hamilton_orbits.integrators import radau15
    from hamilton_orbits.nbody import Body, System
    from hamilton_orbits.rhs import RHS, compile_rhs

    @njit(ACCEL_SIGNATURE)
    def plain_newton(r, v, gm, acc, p):  # gravity alone, written for this benchmark
        n = r.shape[0]
        for i in range(n):
            acc[i, 0] = 0.0
            acc[i, 1] = 0.0
            acc[i, 2] = 0.0
        for i in range(n):
            for j in range(i + 1, n):
                dx = r[j, 0] - r[i, 0]
                dy = r[j, 1] - r[i, 1]
                dz = r[j, 2] - r[i, 2]
                d2 = dx * dx + dy * dy + dz * dz
                f = 1.0 / (d2 * np.sqrt(d2))
                acc[i, 0] += gm[j] * f * dx
                acc[i, 1] += gm[j] * f * dy
                acc[i, 2] += gm[j] * f * dz
                acc[j, 0] -= gm[i] * f * dx
                acc[j, 1] -= gm[i] * f * dy
                acc[j, 2] -= gm[i] * f * dz

    r0, v0, gm = solar_system()
    system = System([Body(f"b{k}", gm[k], r0[k], v0[k]) for k in range(len(gm))])
    t = np.array([0.0, years * 365.25])
    plain = RHS(plain_newton, None, np.zeros(1), False, ("newtonian",))
    variants = {
        "effects=()": compile_rhs(system, ()),
        "hand-written Newtonian kernel": plain,
        "effects=['gr_potential']": compile_rhs(system, [{"name": "gr_potential",
                                                           "c": 173.1446}]),
        "effects=['gr']": compile_rhs(system, [{"name": "gr", "c": 173.1446}]),
    }
    for rhs_ in variants.values():  # compile every variant before timing
        radau15.run(rhs_, r0, v0, gm, np.array([0.0, 1.0]), dt=0.5)
    print(f"[6] what an effect costs: radau15 at a fixed 1-day step, {years:g} years "
          "(time per step, median of interleaved repeats; x: median of per-round ratios)")
    # the variants take turns in each round, so that load varying between rounds
    # meets them all; the ratio is the median of the per-round ratios
    times: dict[str, list[float]] = {name: [] for name in variants}
    for _ in range(repeat):
        for name, rhs_ in variants.items():
            t0 = time.perf_counter()
            _, _, steps = radau15.run(rhs_, r0, v0, gm, t, dt=1.0)
            times[name].append((time.perf_counter() - t0) / steps)
    base = np.array(times["effects=()"])
    for name, ts in times.items():
        ratio = float(np.median(np.array(ts) / base))
        print(f"    {name:<32}{np.median(ts) * 1e6:8.2f} us/step   x{ratio:5.2f}")


def _cpu(fn, min_seconds=0.02, rounds=5):
    """Median over ``rounds`` of the CPU time per call (each round loops ``fn`` until
    it has run ``min_seconds``)."""
    fn()
    out = []
    for _ in range(rounds):
        k, c0 = 0, time.process_time()
        while True:
            fn()
            k += 1
            spent = time.process_time() - c0
            if spent >= min_seconds:
                break
        out.append(spent / k)
    return float(np.median(out)), float(min(out)), float(max(out))


def bench_per_call(quick: bool) -> None:
    """What a call costs beyond its steps: (one-step call) - (one step), one step
    taken from a call of 21 steps; ours ``integrate(system, dt, ...)`` on a System
    built before (validation, set-up, the integrals, the result), rebound's
    ``sim.copy()`` of a Simulation built before (the equivalent of not changing
    the input), ``integrate``, ``synchronize`` and the states read into arrays."""
    from hamilton_orbits import System, integrate

    rng = np.random.default_rng(1)
    print("[7] cost per call beyond its steps (CPU, median of 5 rounds; ms); "
          "ratio = rebound / ours")
    print("    system                 method    ours    rebound   ratio   "
          "(one step: ours / rebound)")
    sizes = [(2, 0), (10, 0), (100, 0)] + ([] if quick else [(10, 100000)])
    for nm, nt in sizes:
        r, v, g = _disc(nm, nt, rng)
        system = System.from_arrays(g, r, v)
        for method, integ in (("radau15", "ias15"), ("wh", "whfast")):
            dt = 0.01

            def ours(k, method=method, system=system, dt=dt):
                return integrate(system, k * dt, method=method, dt=dt)

            sim = to_rebound(r, v, g, integ)
            sim.dt = dt
            if integ == "ias15":
                sim.integrator.epsilon = 0.0
            else:
                sim.integrator.coordinates = "democraticheliocentric"
                sim.integrator.safe_mode = 0

            def peer(k, sim=sim, dt=dt):
                s2 = sim.copy()
                s2.integrate(k * dt, exact_finish_time=0)
                if s2.integrator == "whfast":
                    s2.synchronize()
                x, w = np.empty((s2.N, 3)), np.empty((s2.N, 3))
                s2.serialize_particle_data(xyz=x, vxvyvz=w)
                return x

            secs = 0.2 if nt else 0.02
            o1, p1 = _cpu(lambda: ours(1), secs), _cpu(lambda: peer(1), secs)
            o21, p21 = _cpu(lambda: ours(21), secs), _cpu(lambda: peer(21), secs)
            so, sp = (o21[0] - o1[0]) / 20, (p21[0] - p1[0]) / 20
            fo, fp = o1[0] - so, p1[0] - sp
            print(f"    {nm:4d} + {nt:6d}          {method:8s} {fo * 1e3:7.3f}  {fp * 1e3:8.3f}  "
                  f"{fp / fo:6.2f}   ({so * 1e3:.3f} / {sp * 1e3:.3f} ms)")


_MEMORY_CHILD = """
import sys, numpy as np
sys.path.insert(0, {bench!r})
from bench_nbody import _disc, to_rebound
def rss():
    with open("/proc/self/status") as f:
        d = dict(line.split(":", 1) for line in f)
    return int(d["VmRSS"].split()[0]) * 1024, int(d["VmHWM"].split()[0]) * 1024
code, method, nt = sys.argv[1], sys.argv[2], int(sys.argv[3])
r, v, g = _disc(10, 100, np.random.default_rng(1))
if code == "ours":
    from hamilton_orbits import System, integrate
    integrate(System.from_arrays(g, r, v), 0.03, method=method, dt=0.01)  # load the kernels
    base0 = rss()[0]
    r, v, g = _disc(10, nt, np.random.default_rng(1))
    system = System.from_arrays(g, r, v)
else:
    base0 = rss()[0]
    r, v, g = _disc(10, nt, np.random.default_rng(1))
    system = to_rebound(r, v, g, method)
    system.dt = 0.01
    if method == "whfast":
        system.integrator.coordinates = "democraticheliocentric"
        system.integrator.safe_mode = 0
    else:
        system.integrator.epsilon = 0.0
del r, v, g
base = rss()[0]
with open("/proc/self/clear_refs", "w") as f:
    f.write("5")  # reset the peak (VmHWM) to the current RSS
if code == "ours":
    traj = integrate(system, 0.03, method=method, dt=0.01)
else:
    system.integrate(0.03, exact_finish_time=0)
    if method == "whfast":
        system.synchronize()
    x, w = np.empty((system.N, 3)), np.empty((system.N, 3))
    system.serialize_particle_data(xyz=x, vxvyvz=w)
peak = rss()[1]
print((base - base0) / (nt + 10), (peak - base) / (nt + 10))
"""


def bench_memory(quick: bool) -> None:
    """Peak memory per test particle of one call (3 steps, two outputs), each case in
    its own process: the peak RSS during the call (Linux: /proc/self/clear_refs
    resets it) over the RSS with the input built (ours a System.from_arrays,
    rebound a Simulation; rebound integrates it in place, ours leaves it as it is
    and returns the history, two rows here)."""
    import subprocess
    import sys

    nt = 10**4 if quick else 10**5
    print(f"[8] memory per test particle, 10 bodies + {nt} test particles (bytes; input, "
          "peak of one call)")
    env = dict(__import__("os").environ)
    script = _MEMORY_CHILD.format(bench=str(Path(__file__).resolve().parent))
    for code, method in (("ours", "radau15"), ("rebound", "ias15"), ("ours", "wh"),
                         ("rebound", "whfast")):
        out = subprocess.run([sys.executable, "-c", script, code, method, str(nt)], env=env,
                             capture_output=True, text=True, check=True).stdout.split()
        print(f"    {code:8s} {method:8s} input {float(out[0]):6.0f}   call peak "
              f"{float(out[1]):6.0f}")


def bench_propagate(rounds: int) -> None:
    """KeplerOrbit's batch kernel on 1e6 orbits on one and two threads, beside a
    yardstick that only computes (no memory traffic) run the same way: its
    speed-up is what the machine's second core gives at that moment (the machine
    is shared), the kernel's is what it takes of it.  Wall time, medians of
    interleaved rounds."""
    import numba
    from numba import njit, prange

    @njit(parallel=True)
    def burn(out, reps):  # pragma: no cover - compiled
        for i in prange(out.shape[0]):
            x = 0.1 + i * 1e-9
            for _ in range(reps):
                x = x * 1.0000001 + 1e-9
                x = x - 1e-9 * x * x
            out[i] = x

    from hamilton_orbits import KeplerOrbit

    n = 10**6
    rng = np.random.default_rng(0)  # bound, inclined orbits (benchmarks/bench_overhead.py's)
    a, e = rng.uniform(0.5, 5.0, n), rng.uniform(0.0, 0.9, n)
    inc, lan, nu = (rng.uniform(0.01, np.pi - 0.01, n), rng.uniform(0.0, 2 * np.pi, n),
                    rng.uniform(-np.pi, np.pi, n))
    orbit = KeplerOrbit.from_elements(a=a, e=e, inc=inc, lan=lan, argp=np.zeros(n), nu=nu,
                                      mu=1.0)
    out = np.empty(4)
    cases = {"KeplerOrbit.propagate 1e6": lambda: orbit.propagate(0.37),
             "compute-only yardstick": lambda: burn(out, 5_000_000)}
    for f in cases.values():
        f()
    times: dict[tuple[str, int], list[float]] = {}
    threads = (1, min(2, numba.config.NUMBA_NUM_THREADS))
    for _ in range(rounds):
        for th in threads:
            numba.set_num_threads(th)
            for name, f in cases.items():
                t0, c0 = time.perf_counter(), time.process_time()
                f()
                wall = time.perf_counter() - t0
                times.setdefault((name, th), []).append(wall)
                times.setdefault((name, -th), []).append((time.process_time() - c0) / wall)
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    print(f"[9] batch kernels on 1 and {threads[1]} threads (wall time, median of {rounds} "
          f"interleaved rounds; load average {__import__('os').getloadavg()[0]:.1f})")
    for name in cases:
        one, two = np.array(times[(name, 1)]), np.array(times[(name, threads[1])])
        s = one / two
        busy = np.median(times[(name, -threads[1])])  # cores the run held on average
        print(f"    {name:26s} {np.median(one) * 1e3:7.1f} ms / {np.median(two) * 1e3:7.1f} ms"
              f"  speed-up {np.median(s):.2f} ({s.min():.2f}-{s.max():.2f}), CPU/wall {busy:.2f}"
              + (f"   {np.median(one) / n * 1e9:.0f} / {np.median(two) / n * 1e9:.0f} ns/orbit"
                 if name.startswith("Kepler") else ""))


def _radau15_flops(n: int, rounds: float) -> tuple[float, float]:
    """Floating-point operations of one radau15 step on ``n`` massive bodies with
    ``rounds`` predictor-corrector rounds, counted from the kernels' formulas
    (``_kernels/radau15.py``, ``_kernels/nbody.py``; a square root or a division
    counts as one): ``(force part, the rest)``.

    Per pair of one force evaluation: 3 differences, 5 for ``d^2``, square root,
    product, division, 2 factors, 12 for the six accumulations = 25.  Per
    component and round (7 substeps): positions 19 and the ``g``/``b`` update
    with compensated sums 7 + 7 j at substep j + 1: 329.  Per component and
    step: the prediction 57, ``g`` from ``b`` 42, the compensated update 111,
    keeping ``d`` 57, the PRS23 step rule 40: 307."""
    pairs = n * (n - 1) / 2
    m = 3 * n
    return (1 + 7 * rounds) * 25 * pairs, m * (329 * rounds + 307)


_PEAK_CHILD = """
import time, numpy as np
from numba import njit
@njit
def poly(x, y, a, b, reps):
    for _ in range(reps):
        for i in range(x.shape[0]):
            t = x[i]
            t = t * a + b; t = t * a + b; t = t * a + b; t = t * a + b
            t = t * a + b; t = t * a + b; t = t * a + b; t = t * a + b
            y[i] = t
x = np.random.default_rng(0).uniform(0.5, 1.0, 1024); y = np.empty_like(x)
poly(x, y, 0.999, 1e-3, 1)
best = 1e9
for _ in range(7):
    c0 = time.process_time()
    poly(x, y, 0.999, 1e-3, 20000)
    best = min(best, time.process_time() - c0)
print(16 * 1024 * 20000 / best / 1e9)
"""


def _peak(vectorize: bool) -> float:
    """GFlop/s of 8 dependent multiply-adds per element over 1024 elements (in L1):
    compiled with numba's loop and SLP vectorisers on (SIMD) or off (scalar), in a
    child process (the flags are read when numba starts)."""
    import os
    import subprocess
    import sys

    env = dict(os.environ, NUMBA_LOOP_VECTORIZE=str(int(vectorize)),
               NUMBA_SLP_VECTORIZE=str(int(vectorize)), NUMBA_CACHE_DIR="")
    out = subprocess.run([sys.executable, "-c", _PEAK_CHILD], env=env, capture_output=True,
                         text=True, check=True)
    return float(out.stdout.split()[-1])


def bench_flops(quick: bool) -> None:
    """One radau15 step of the N = 10 disc: its floating-point operations (counted,
    :func:`_radau15_flops`, with the rounds a step takes, counted by a right-hand
    side that counts its calls), its CPU time, and the fraction of the machine's
    scalar and SIMD throughput (:func:`_peak`) it reaches; and the force
    evaluation alone, the shipped kernel beside the pair form (:func:`_force_forms`)."""
    from numba import njit

    from hamilton_orbits._kernels import nbody
    from hamilton_orbits._kernels.signatures import ACCEL_SIGNATURE
    from hamilton_orbits.integrators import radau15
    from hamilton_orbits.rhs import RHS

    @njit(ACCEL_SIGNATURE)
    def counting(r, v, gm, acc, p):  # pragma: no cover - compiled
        p[0] += 1.0
        nbody.newtonian(r, v, gm, acc)

    rng = np.random.default_rng(1)
    r, v, g = _disc(10, 0, rng)
    t = np.array([0.0, 200.0])
    count = RHS(counting, None, np.zeros(1), False, ("newtonian",))
    _, _, steps = radau15.run(count, r, v, g, t)
    rounds = (count.p[0] / steps - 1) / 7
    per_step = _cpu(lambda: radau15.run(rhs(), r, v, g, t), 0.3)[0] / steps
    force, rest = _radau15_flops(10, rounds)
    scalar, simd = _peak(False), _peak(True)
    achieved = (force + rest) / per_step / 1e9
    print(f"[10] one radau15 step, N = 10 disc (PRS23, tol 1e-9: {rounds:.2f} rounds a step): "
          f"{force + rest:.0f} flops ({force:.0f} in {1 + 7 * rounds:.1f} force evaluations), "
          f"{per_step * 1e6:.2f} us CPU -> {achieved:.2f} GFlop/s")
    print(f"     machine (one core, 8 dependent multiply-adds per element in L1): scalar "
          f"{scalar:.2f} GFlop/s, SIMD {simd:.2f} GFlop/s; reached {achieved / scalar:.0%} of "
          f"scalar, {achieved / simd:.0%} of SIMD")
    _force_forms(rng)


def _force_forms(rng) -> None:
    """The force evaluation alone: the shipped kernel (``nbody.newtonian``: from
    ``nbody.SIMD_FROM`` bodies on the SIMD form, every pair twice, vectorised over
    the bodies that receive, no sum reordered) beside the pair form it replaced
    there (pairs once, both bodies updated; copied here), CPU time, medians of
    interleaved rounds; the accelerations must be the same to the bit."""
    from numba import njit

    from hamilton_orbits._kernels import nbody

    @njit(error_model="numpy")
    def pairs_once(r, gm, acc):  # pragma: no cover - compiled
        n = r.shape[0]
        acc[:, :] = 0.0
        for i in range(n):
            xi, yi, zi, gi = r[i, 0], r[i, 1], r[i, 2], gm[i]
            ax, ay, az = acc[i, 0], acc[i, 1], acc[i, 2]
            for j in range(i + 1, n):
                dx, dy, dz = r[j, 0] - xi, r[j, 1] - yi, r[j, 2] - zi
                d2 = dx * dx + dy * dy + dz * dz
                inv3 = 1.0 / (d2 * np.sqrt(d2))
                fi, fj = gm[j] * inv3, gi * inv3
                ax += fi * dx
                ay += fi * dy
                az += fi * dz
                acc[j, 0] -= fj * dx
                acc[j, 1] -= fj * dy
                acc[j, 2] -= fj * dz
            acc[i, 0], acc[i, 1], acc[i, 2] = ax, ay, az

    @njit(error_model="numpy")
    def loop_pairs(r, gm, acc, reps):  # pragma: no cover - compiled
        for _ in range(reps):
            pairs_once(r, gm, acc)

    @njit(error_model="numpy")
    def loop_shipped(r, v, gm, acc, reps):  # pragma: no cover - compiled
        for _ in range(reps):
            nbody.newtonian(r, v, gm, acc)

    print(f"     the force evaluation alone (ns per pair, CPU, median of 7 interleaved rounds; "
          f"SIMD form from N = {nbody.SIMD_FROM}):")
    for n in (9, 10, 30, 100):
        r, v, g = _disc(n, 0, rng)
        g[1:] = rng.uniform(1e-7, 1e-6, n - 1)
        a1, a2 = np.empty_like(r), np.empty_like(r)
        reps = int(4e5 / n**2) + 1
        times: dict[str, list[float]] = {"pairs": [], "shipped": []}
        loop_pairs(r, g, a1, 1)
        loop_shipped(r, v, g, a2, 1)
        for _ in range(7):
            c0 = time.process_time()
            loop_pairs(r, g, a1, reps)
            times["pairs"].append(time.process_time() - c0)
            c0 = time.process_time()
            loop_shipped(r, v, g, a2, reps)
            times["shipped"].append(time.process_time() - c0)
        per = n * (n - 1) / 2 * reps / 1e9
        t_pairs, t_ship = np.median(times["pairs"]) / per, np.median(times["shipped"]) / per
        print(f"       N = {n:3d}: pair form {t_pairs:5.2f}, shipped {t_ship:5.2f}  "
              f"(x{t_pairs / t_ship:.2f}; same bits: {np.array_equal(a1, a2)})")


# ---------------------------------------------------------------------------
# wh against WHFast over a spread of discs


def _spread_disc(n: int, tight: bool, ecc: bool, rng):
    """A star (GM 1) and ``n - 1`` planets: GM log-uniform 1e-7 .. 1e-3, the
    innermost at a = 1 .. 2, the others outwards at ratios ``a_{i+1} / a_i`` of
    8-12 mutual Hill radii (``tight``) or 1.3-2.0 (N = 3) / reaching a = 10
    (N = 10) (wide), and never less than 1.1 times the ratio at which the orbits
    would cross; e uniform in 0 .. 0.3 (``ecc``) or 0 .. 0.02; inclinations
    below 0.05 rad; the other angles uniform.  Heliocentric elements made into
    inertial states by rebound (both sides start from the same floats).
    Returns ``r, v, gm, a, e, P_in`` (P_in the innermost period)."""
    import rebound

    k = n - 1
    gm = 10.0 ** rng.uniform(-7.0, -3.0, k)
    e = rng.uniform(0.0, 0.3 if ecc else 0.02, k)
    a = np.empty(k)
    a[0] = rng.uniform(1.0, 2.0)
    wide = 10.0 ** (math.log10(10.0 / a[0]) / max(1, k - 1))  # N = 10: reach a = 10
    for i in range(1, k):
        cross = 1.1 * (1.0 + e[i - 1]) / (1.0 - e[i])
        if tight:
            x = 0.5 * rng.uniform(8.0, 12.0) * ((gm[i - 1] + gm[i]) / 3.0) ** (1.0 / 3.0)
            ratio = (1.0 + x) / (1.0 - x)
        else:
            ratio = rng.uniform(1.3, 2.0) if k == 2 else wide
        a[i] = a[i - 1] * max(ratio, cross)
    sim = rebound.Simulation()
    sim.G = 1.0
    sim.add(m=1.0)
    for i in range(k):
        # the star fetched anew for every add (adding reallocates the particles)
        sim.add(m=float(gm[i]), a=float(a[i]), e=float(e[i]),
                inc=float(rng.uniform(0.0, 0.05)), Omega=float(rng.uniform(0, 2 * np.pi)),
                omega=float(rng.uniform(0, 2 * np.pi)), M=float(rng.uniform(0, 2 * np.pi)),
                primary=sim.particles[0])
    sim.move_to_com()
    r, v = reb_state(sim)
    g = np.concatenate([[1.0], gm])
    return r, v, g, a, e, 2.0 * np.pi * a[0] ** 1.5 / math.sqrt(1.0 + gm[0])


def spread_discs(quick: bool, seed: int = 11):
    """The discs of section [11]: for N = 3 and 10, every combination of tight /
    wide and near-circular / eccentric (three times each; once with ``quick``),
    with dt = P_in / K, K log-uniform in 20 .. 1000 (from the coarsest step a
    user would take to dt = 0.01 at a = 2).  Each disc's own generator (seeded
    from ``seed`` and its place), so that ``quick`` gives the first ones of the
    full list."""
    out = []
    reps = 1 if quick else 3
    for n in (3, 10):
        for rep in range(reps):
            for c, (tight, ecc) in enumerate(itertools.product((True, False), (False, True))):
                rng = np.random.default_rng([seed, n, rep, c])
                r, v, g, a, e, p_in = _spread_disc(n, tight, ecc, rng)
                per = 10.0 ** rng.uniform(math.log10(20.0), 3.0)
                out.append(dict(n=n, tight=tight, ecc=ecc, r=r, v=v, gm=g, a=a, e=e,
                                dt=p_in / per, per=per))
    return out


def _disc_pair(d):
    """``(ours, peer, n_steps)`` for one disc of :func:`spread_discs`: the same steps
    on both sides, ~10^6 pair evaluations (``N (N - 1) / 2`` a step)."""
    from hamilton_orbits.integrators import wh

    n = d["n"]
    n_steps = int(1e6 / (n * (n - 1) / 2))
    dt = d["dt"]
    t_end = n_steps * dt
    r, v, g = d["r"], d["v"], d["gm"]
    f = rhs()
    sim0 = to_rebound(r, v, g, "whfast")
    sim0.dt = dt
    sim0.integrator.coordinates = "democraticheliocentric"
    sim0.integrator.safe_mode = 0

    def ours():
        return wh.run(f, r, v, g, np.array([0.0, t_end]), dt=dt)

    def peer():
        sim = sim0.copy()
        # half a step short of t_end: rebound steps while its summed t is below
        # the target, which the rounding of n_steps sums of dt may leave it
        sim.integrate(t_end - 0.5 * dt, exact_finish_time=0)
        sim.synchronize()
        return sim

    return ours, peer, n_steps


def bench_discs(quick: bool, rounds: int) -> list[float]:
    """Section [11]; returns the per-disc ratios WHFast / ours."""
    discs = spread_discs(quick)
    print(f"[11] wh vs WHFast over {len(discs)} discs (democratic heliocentric, WHFast "
          f"safe_mode 0; CPU time, median of {rounds} interleaved per-round ratios; "
          "ratio = WHFast / ours)")
    print("     N  spacing  e max  a_in..a_out   log10 GM (min..max)   P_in/dt   steps"
          "      ours   WHFast (us/step)  ratio   |dE/E| ours")
    ratios = []
    for d in discs:
        ours, peer, n_steps = _disc_pair(d)
        ours()  # warm: the first call of a size loads its kernels
        peer()
        ts_o, ts_p = [], []
        for _ in range(rounds):
            t, (r, v, steps) = timed(ours)
            ts_o.append(t)
            t, sim = timed(peer)
            ts_p.append(t)
        if steps != n_steps or sim.steps_done != n_steps:
            print(f"     (steps differ: ours {steps}, WHFast {sim.steps_done}, asked {n_steps})")
        ts_o, ts_p = np.array(ts_o), np.array(ts_p)
        ratio = float(np.median(ts_p / ts_o))
        ratios.append(ratio)
        de = abs(energy(r[-1], v[-1], d["gm"]) / energy(d["r"], d["v"], d["gm"]) - 1)
        lg = np.log10(d["gm"][1:])
        print(f"    {d['n']:2d}  {'tight' if d['tight'] else 'wide':7s}  {d['e'].max():5.2f}"
              f"  {d['a'][0]:4.2f}..{d['a'][-1]:5.2f}   {lg.min():5.2f}..{lg.max():5.2f}"
              f"          {d['per']:6.1f}  {n_steps:6d}  {np.median(ts_o) / n_steps * 1e6:8.3f}"
              f"  {np.median(ts_p) / n_steps * 1e6:8.3f}          {ratio:5.2f}   {de:.1e}")
    q = np.array(ratios)
    print(f"    spread of the ratio: min {q.min():.2f}, median {np.median(q):.2f}, "
          f"max {q.max():.2f}" + "".join(
              f"; N = {n}: {q[[d['n'] == n for d in discs]].min():.2f}.."
              f"{q[[d['n'] == n for d in discs]].max():.2f}" for n in (3, 10)))
    return ratios


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="shorter spans, fewer sizes")
    parser.add_argument("--propagate-only", action="store_true", help="section [9] alone")
    parser.add_argument("--only", type=int, nargs="+", metavar="N",
                        help="these sections alone (after the warm-up [0])")
    args = parser.parse_args()
    quick = args.quick
    if args.propagate_only:
        bench_propagate(3 if quick else 7)
        return
    repeat = 3
    years, short = (100.0, 10.0) if quick else (1000.0, 100.0)
    sections = {
        1: lambda: bench_solar(years, repeat),
        2: lambda: bench_wh(years, repeat),
        3: lambda: bench_scaling(quick, repeat),
        4: lambda: bench_work_precision(years),
        5: lambda: bench_leapfrog(short, repeat),
        6: lambda: bench_effects_cost(short, repeat),
        7: lambda: bench_per_call(quick),
        8: lambda: bench_memory(quick),
        9: lambda: _propagate_on_two_threads(quick),
        10: lambda: bench_flops(quick),
        11: lambda: bench_discs(quick, 5 if quick else 7),
    }
    chosen = args.only if args.only else sorted(sections)
    unknown = sorted(set(chosen) - set(sections))
    if unknown:
        parser.error(f"no section {unknown}; the sections are 1 .. {max(sections)}")
    bench_warmup()
    for k in chosen:
        sections[k]()


def _propagate_on_two_threads(quick: bool) -> None:
    """Section [9] in a child process with two threads (the rest of the benchmark
    runs with ``NUMBA_NUM_THREADS=1`` for its one-thread figures)."""
    import os
    import subprocess
    import sys

    env = dict(os.environ, NUMBA_NUM_THREADS=str(max(2, os.cpu_count() or 2)))
    cmd = [sys.executable, __file__, "--propagate-only"] + (["--quick"] if quick else [])
    print(subprocess.run(cmd, env=env, capture_output=True, text=True, check=True).stdout,
          end="", flush=True)


if __name__ == "__main__":
    main()
