"""
Pole wander of a rigid Earth: the Euler period
==============================================

A century of the free wobble, integrated and exact.
The Earth of rigid.earth (IERS 2010 constants, EGM2008 triaxiality) spins at
OMEGA with its rotation axis 0.2 arcsec off the figure axis.  Euler's equations
are integrated with the fourth-order Lie-Poisson splitting (rigid.integrate,
"splitting4") for a century with daily output, and compared with the exact free
motion (rigid.free_motion) and with the linear theory: the pole turns prograde
about the figure axis once per Euler period

    T_E = 2 pi / (OMEGA sqrt((C - A)(C - B) / (A B)))  ~ 304.5 sidereal days,

far from the ~433 days observed (the Chandler wobble, see ``chandler_wobble.py``):
the Earth is not rigid.

Run: ``python examples/earth_pole/plot_pole_wander_rigid_earth.py [--out DIR] [--quick]``
(a few seconds; ``--quick`` integrates 10 years instead of 100); with ``--out`` it
writes ``DIR/pole_wander_rigid_earth.png`` and ``DIR/pole_wander_rigid_earth.txt``.
"""

# %%
# Integrate and solve
# -------------------
# :func:`rigid.earth.simulate_wobble` starts the rotation axis 0.2 arcsec off
# the figure axis, towards the least moment's axis A (14.93° W);
# ``method="splitting4"`` integrates Euler's equations, ``method="exact"``
# evaluates the free motion in Jacobi's elliptic functions.
import argparse
import time
from pathlib import Path

import astropy.units as u
import matplotlib.pyplot as plt
import numpy as np

from rigid import earth

parser = argparse.ArgumentParser(description="Pole wander of a rigid Earth")
parser.add_argument("--out", help="write pole_wander_rigid_earth.png and .txt here")
parser.add_argument("--quick", action="store_true", help="10 years instead of 100")
args = parser.parse_known_args()[0]
years = 10 if args.quick else 100
duration = years * u.yr

earth.simulate_wobble(2 * u.day, dt=3 * u.hour)  # compile the kernels outside the timing
t0 = time.perf_counter()
split = earth.simulate_wobble(duration, dt=3 * u.hour, method="splitting4")
t_split = time.perf_counter() - t0
t0 = time.perf_counter()
exact = earth.simulate_wobble(duration, method="exact")
t_exact = time.perf_counter() - t0

# %%
# The periods
# -----------
# The period fitted to each run beside the linear theory.
sidereal = (2 * np.pi * u.rad / earth.OMEGA).to(u.day)
t_e = earth.euler_period(triaxial=True)
p_split = split.period()
p_exact = exact.period()
diff = np.max(np.abs(split.m - exact.m)) * u.rad
a, b, c = earth.moments()

rows = [
    ("C / (M R^2)", f"{float((c / (earth.mass() * earth.R_EQ**2)).decompose()):.5f}", ""),
    ("(B - A) / C", f"{float((b - a) / c):.3e}", ""),
    ("Euler period, linear (triaxial)", f"{t_e.to_value(u.day):.6f}", "d"),
    ("Euler period in sidereal days", f"{float(t_e / sidereal):.6f}", "sidereal d"),
    ("Euler period, axisymmetric", f"{earth.euler_period().to_value(u.day):.6f}", "d"),
    ("period fitted, splitting4", f"{p_split.to_value(u.day):.6f}", "d"),
    ("period fitted, exact free motion", f"{p_exact.to_value(u.day):.6f}", "d"),
    ("max |m_split - m_exact|", f"{diff.to_value(u.uas):.3e}", "µas"),
    ("wobble amplitude", f"{np.max(np.abs(exact.m)) * 206264806.247:.3f}", "mas"),
    (f"wall time splitting4, {years} yr daily", f"{t_split:.3f}", "s"),
    (f"wall time exact, {years} yr daily", f"{t_exact:.3f}", "s"),
]
width = max(len(r[0]) for r in rows)
text = "\n".join(f"{name:<{width}}  {value:>14}  {unit}" for name, value, unit in rows)
print(text)

# %%
# The figure
# ----------
# Two Euler periods of the pole about the figure axis (the start is marked and
# the arrow gives its sense in these axes), and the integrator's departure from
# the exact motion over the whole run.
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 5))
n = int(2 * t_e.to_value(u.day))
ax1.plot(split.x[:n].to_value(u.mas), split.y[:n].to_value(u.mas), lw=1.5,
         label="splitting4")
ax1.plot(exact.x[:n:10].to_value(u.mas), exact.y[:n:10].to_value(u.mas), "k.", ms=3,
         label="exact free motion (every 10th day)")
x0, y0 = split.x[0].to_value(u.mas), split.y[0].to_value(u.mas)
ax1.plot(x0, y0, "o", color="C3", ms=7, label="start")
ax1.annotate("", xy=(split.x[15].to_value(u.mas), split.y[15].to_value(u.mas)), xytext=(x0, y0),
             arrowprops={"arrowstyle": "-|>", "color": "C3", "lw": 1.5})
ax1.set_xlabel("x_p, towards Greenwich (mas)")
ax1.set_ylabel("y_p, towards 90° W (mas)")
ax1.set_aspect("equal")
ax1.set_title(f"rigid-Earth pole, period {p_split.to_value(u.day):.2f} d")
ax1.legend(loc="center", fontsize=8)
ax2.semilogy(split.t[1:].to_value(u.yr), np.abs(split.m - exact.m)[1:] * 206264806247.1,
             lw=0.5)  # (from the first output after the start: 0 there, off a log axis)
ax2.set_xlabel("time since the start (yr)")
ax2.set_ylabel("|splitting - exact| (µas)")
ax2.set_title("integrator against the exact motion")
fig.tight_layout()
if args.out:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "pole_wander_rigid_earth.txt").write_text(text + "\n")
    fig.savefig(out / "pole_wander_rigid_earth.png", dpi=110)
plt.show()
