"""Rigid-Earth pole wander, a century with daily output: splitting, exact, DOP853.

Run ``python benchmarks/bench_pole.py`` (``--quick``: 10 years, fewer repeats).
One process, one body (rigid.earth.rigid_body(0.2 arcsec), triaxial), daily
output over the whole span:

- ``exact``: the exact free motion (rigid.free_motion, vectorised over the days),
  the reference;
- ``splitting4`` (Blanes-Moan S6 on the Casimir-shifted split, exact for an
  axisymmetric body, so only the tiny triaxiality is split) at steps of 1 day,
  6 h and 1 h; ``splitting4y`` (Yoshida) at 10 min and ``splitting2`` (the plain
  T1 + T2 + T3 split) at 1 h and 1 min (rigid.integrate).  The plain split errs
  by O((OMEGA h)^2) of the spin energy, which dwarfs the wobble's share
  (~ m^2 H ~ 1e-15): at 1 h it loses the pole entirely;
- scipy ``solve_ivp`` DOP853 on Euler's equations plus the quaternion
  kinematics with a compiled right-hand side (rigid.integrate, method
  ``"dop853"``) at rtol 1e-9 and 1e-12.

Accuracy is measured against the exact motion at every day: the pole error
max |m - m_exact| (uas; the wobble is 0.2 arcsec) and the attitude error (the
geodesic angle between the attitudes, rad, which also carries the error of the
~36525 turns of the spin).  Wall times are medians of several repeats (a run
over 5 s is not repeated); ratios are DOP853 time / our time.
"""

from __future__ import annotations

import argparse
import time

import astropy.units as u
import numpy as np

from hamilton_orbits import Quaternion
from rigid import earth, free_motion, integrate
from rigid.earth import pole_path

RAD_TO_UAS = (1 * u.rad).to_value(u.uas)


def median_time(fn, repeat: int):
    times = []
    res = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        res = fn()
        times.append(time.perf_counter() - t0)
        if times[-1] > 5.0:
            break
    return float(np.median(times)), res, len(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="10 years, 3 repeats")
    args = parser.parse_args()
    years = 10 if args.quick else 100
    repeat = 3 if args.quick else 5
    body = earth.rigid_body(0.2 * u.arcsec)
    n_days = round(years * 365.25)
    t_days = np.arange(n_days + 1) * 86400.0 * u.s
    hour = 3600.0 * u.s

    # warm up the compiled kernels
    free_motion(body, t_days[:3])
    for method in ("splitting4", "splitting2", "splitting4y"):
        integrate(body, [24.0] * hour, dt=hour, method=method)
    integrate(body, [1.0] * hour, method="dop853")

    t_ex, (q_ex, w_ex), n_ex = median_time(lambda: free_motion(body, t_days), repeat)
    m_ex = pole_path(w_ex)

    def accuracy(q, w):
        dm = float(np.max(np.abs(pole_path(w) - m_ex))) * RAD_TO_UAS
        da = float(np.max(Quaternion(q).rotation_distance(q_ex)))
        return dm, da

    rows = [("exact free motion", "-", t_ex, n_ex, 0.0, 0.0)]
    cases = [("splitting4", 86400.0), ("splitting4", 21600.0), ("splitting4", 3600.0),
             ("splitting4y", 600.0), ("splitting2", 3600.0), ("splitting2", 60.0)]
    for method, dt in cases:
        t, tr, n = median_time(
            lambda method=method, dt=dt: integrate(body, t_days, dt=dt * u.s, method=method),
            repeat)
        dm, da = accuracy(tr.attitude.as_array(), np.asarray(tr.omega))
        rows.append((method, f"dt = {dt / 60:g} min", t, n, dm, da))
    dop = []
    for rtol in (1e-9, 1e-12):
        t, tr, n = median_time(
            lambda rtol=rtol: integrate(body, t_days, method="dop853", tol=rtol),
            1 if rtol < 1e-10 else repeat)
        dm, da = accuracy(tr.attitude.as_array(), np.asarray(tr.omega))
        rows.append(("DOP853", f"rtol = {rtol:g}", t, n, dm, da))
        dop.append((rtol, t, dm, da))

    print(f"Rigid-Earth wobble, {years} yr with daily output ({n_days + 1} epochs), "
          f"wobble 0.2 arcsec, triaxial Earth (IERS 2010 + EGM2008)")
    print(f"Euler period (linear): {earth.euler_period(triaxial=True):.6f}")
    print()
    print(f"{'method':<18} {'step / tol':<14} {'wall (s)':>10} {'repeats':>7} "
          f"{'pole err (uas)':>15} {'attitude err (rad)':>19}")
    for name, setting, t, n, dm, da in rows:
        print(f"{name:<18} {setting:<14} {t:>10.4f} {n:>7d} {dm:>15.3e} {da:>19.3e}")
    print()
    print("ratios (DOP853 wall time / our wall time):")
    for rtol, t_dop, dm_dop, da_dop in dop:
        for name, setting, t, _, dm, da in rows:
            if name == "DOP853":
                continue
            cmp = ("more accurate in both" if dm <= dm_dop and da <= da_dop else
                   "less accurate in both" if dm > dm_dop and da > da_dop else
                   "attitude " + ("better" if da <= da_dop else "worse") + ", pole "
                   + ("better" if dm <= dm_dop else "worse"))
            print(f"  DOP853 rtol {rtol:g} / {name} {setting}: {t_dop / t:8.1f}  "
                  f"({cmp} than that DOP853 run)")
    for name, setting, t, _, _, _ in rows[1:]:
        if name != "DOP853":
            print(f"  {name} {setting} / exact: {t / t_ex:.2f} (exact is the reference)")


if __name__ == "__main__":
    main()
