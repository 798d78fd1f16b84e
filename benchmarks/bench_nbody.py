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
4. Work-precision sweep on the solar system (100 years; 20 with --quick):
   every integrator present (radau15, wh in democratic-heliocentric and in
   Jacobi coordinates with the third-order corrector, and leapfrog / dop853 if
   the package has them) and rebound's IAS15, WHFast (the same two maps) and
   leapfrog, over tol or dt; error
   = max relative position difference against a reference (IAS15, default
   epsilon) and relative energy error, against wall time (the shortest of 3
   runs per setting).  Written to
   benchmarks/results/nbody_work_precision.{md,png}.
"""

from __future__ import annotations

import argparse
import importlib
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
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


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
    cases = [(3, 0), (10, 0), (100, 0), (1000, 0)]
    tests = [100, 1000, 10000, 100000]
    if quick:
        cases = cases[:3]
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
        # at least 50 steps, so that a call's fixed cost (input checks, setup:
        # ~0.2 ms for ours) does not pass for cost per step
        n_steps = int(max(50, min(5000, 2e6 / work / 20)))
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


def bench_work_precision(years: float) -> None:
    r0, v0, gm = solar_system()
    t_end = 8.0 * math.floor(years * 365.25 / 8.0)  # a multiple of every fixed dt below
    e0 = energy(r0, v0, gm)
    sim = to_rebound(r0, v0, gm, "ias15")
    sim.integrate(t_end, exact_finish_time=1)
    x_ref, _ = reb_state(sim)
    scale = np.linalg.norm(x_ref - x_ref[0], axis=1)
    scale[0] = np.linalg.norm(x_ref[0])
    print(f"[4] work-precision, solar system {years:g} years (reference: IAS15, epsilon 1e-9)")
    mods = _ours_modules()
    sweeps = {
        "radau15": ("tol", [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9]),
        "wh": ("dt", [8.0, 4.0, 2.0, 1.0, 0.5]),
        "wh-jacobi-c3": ("dt", [8.0, 4.0, 2.0, 1.0, 0.5]),
        "leapfrog": ("dt", [2.0, 1.0, 0.5, 0.25]),
        "dop853": ("tol", [1e-8, 1e-10, 1e-12]),
    }
    rows = []

    def record(code, method, par, value, secs, r, v):
        err = float(np.max(np.linalg.norm(r - x_ref, axis=1) / scale))
        de = abs(energy(r, v, gm) / e0 - 1)
        rows.append((code, method, par, value, secs, err, de))
        print(
            f"    {code:8s} {method:9s} {par}={value:<8g} {secs:8.3f} s   "
            f"pos err {err:8.1e}   |dE/E| {de:8.1e}"
        )

    if "wh" in mods:
        mods["wh-jacobi-c3"] = mods["wh"]
    for name, mod in mods.items():
        par, values = sweeps[name]
        for val in values:
            kw = {par: val}
            if name == "wh-jacobi-c3":
                kw.update(coordinates="jacobi", corrector=3)
            try:
                secs, (r, v, _) = timed_best(
                    lambda kw=kw, mod=mod: mod.run(rhs(), r0, v0, gm, np.array([0.0, t_end]), **kw)
                )
            except Exception as exc:  # a method that cannot do this setting: report
                print(f"    ours     {name:9s} {par}={val:g}: {type(exc).__name__}: {exc}")
                continue
            record("ours", name, par, val, secs, r[-1], v[-1])
    peers = {
        "ias15": ("epsilon", [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9]),
        "whfast": ("dt", [8.0, 4.0, 2.0, 1.0, 0.5]),
        "whfast-jacobi-c3": ("dt", [8.0, 4.0, 2.0, 1.0, 0.5]),
        "leapfrog": ("dt", [2.0, 1.0, 0.5, 0.25]),
    }
    for name, (par, values) in peers.items():
        for val in values:

            def peer(name=name, par=par, val=val):
                sim = to_rebound(r0, v0, gm, "whfast" if name.startswith("whfast") else name)
                if par == "epsilon":
                    sim.integrator.epsilon = val
                    sim.dt = 1.0
                    sim.integrate(t_end, exact_finish_time=1)
                else:
                    sim.dt = val
                    if name == "whfast":
                        sim.integrator.coordinates = "democraticheliocentric"
                        sim.integrator.safe_mode = 0
                    if name == "whfast-jacobi-c3":
                        sim.integrator.coordinates = "jacobi"
                        sim.integrator.safe_mode = 0
                        sim.integrator.corrector = 3
                    sim.integrate(t_end, exact_finish_time=0)
                    if name.startswith("whfast"):
                        sim.synchronize()
                return sim

            secs, s = timed_best(peer)
            x, w = reb_state(s)
            record("rebound", name, par, val, secs, x, w)
    RESULTS.mkdir(exist_ok=True)
    md = RESULTS / "nbody_work_precision.md"
    with md.open("w") as f:
        f.write(f"# Work-precision: solar system, {years:g} years (benchmarks/bench_nbody.py)\n\n")
        f.write("| code | method | parameter | wall time (s) | max rel. pos. error | |dE/E| |\n")
        f.write("|---|---|---|---|---|---|\n")
        for code, method, par, value, secs, err, de in rows:
            f.write(
                f"| {code} | {method} | {par}={value:g} | {secs:.3f} | {err:.1e} | {de:.1e} |\n"
            )
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print(f"    table: {md} (matplotlib not installed: no figure)")
        return
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    groups: dict[tuple[str, str], list] = {}
    for code, method, _, _, secs, err, de in rows:
        groups.setdefault((code, method), []).append((secs, err, de))
    for (code, method), pts in groups.items():
        # in sweep order (coarse to fine), not sorted by the (noisy) times
        ls = "-" if code == "ours" else "--"
        secs = [p[0] for p in pts]
        axes[0].loglog(
            secs, [max(p[1], 1e-17) for p in pts], ls, marker="o", label=f"{code} {method}"
        )
        axes[1].loglog(
            secs, [max(p[2], 1e-17) for p in pts], ls, marker="o", label=f"{code} {method}"
        )
    axes[0].set_ylabel("max relative position error vs IAS15")
    axes[1].set_ylabel("|relative energy error|")
    for ax in axes:
        ax.set_xlabel("wall time (s)")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle(f"Solar system, {years:g} years: what accuracy costs")
    fig.tight_layout()
    png = RESULTS / "nbody_work_precision.png"
    fig.savefig(png, dpi=120)
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="shorter spans, fewer sizes")
    args = parser.parse_args()
    quick = args.quick
    repeat = 3
    bench_warmup()
    bench_solar(100.0 if quick else 1000.0, repeat)
    bench_wh(100.0 if quick else 1000.0, repeat)
    bench_scaling(quick, repeat)
    bench_work_precision(20.0 if quick else 100.0)
    bench_leapfrog(10.0 if quick else 100.0, repeat)
    bench_effects_cost(10.0 if quick else 100.0, repeat)


if __name__ == "__main__":
    main()
