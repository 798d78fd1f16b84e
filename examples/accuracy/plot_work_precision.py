"""
Error against cost on an eccentric orbit
========================================

A test particle on a Kepler orbit of eccentricity 0.5 about a star (G = GM = 1,
period 2 pi) is followed for 20 orbits by each integrator: the leapfrog and the
Wisdom-Holman map (fixed steps; second order, Wisdom & Holman 1991),
``radau15`` (15th order, Everhart 1985, adaptive; Rein & Spiegel 2015) and
``dop853`` (8th order, Hairer, Nørsett & Wanner 1993, adaptive).  The exact
answer is the Kepler solution (:meth:`hamilton_orbits.KeplerOrbit.propagate`),
so the error is the true one, not an estimate.  The cost is the wall time of the
integration proper and the number of steps.
"""

# %%
# The orbit and the exact answer
# ------------------------------
import matplotlib.pyplot as plt
import numpy as np

from hamilton_orbits import Body, KeplerOrbit, Simulation, System

orbit = KeplerOrbit.from_elements(a=1.0, e=0.5, inc=0.0, lan=0.0, argp=0.0, nu=0.0, mu=1.0)
r0, v0 = orbit.state()
system = System([Body("star", 1.0, [0, 0, 0], [0, 0, 0]),
                 Body("particle", 0.0, r0, v0)])
t_end = 20 * 2 * np.pi
r_exact, _ = orbit.propagate(t_end).state()


def run(method: str, **options) -> tuple[float, float, int]:
    """(wall time in s, position error in units of a, steps) of one run."""
    traj = Simulation(system, method=method, **options).integrate(t_end)
    error = float(np.linalg.norm(traj.r[-1, 1] - traj.r[-1, 0] - r_exact))
    return traj.wall_time, error, traj.steps


# %%
# Sweep the step or the tolerance
# -------------------------------
# Fixed-step methods take steps from 1/50 to 1/3000 of an orbit; the adaptive
# ones tolerances from 1e-4 to 1e-14.  The first run of each method compiles its
# kernel, so it is run once before the sweep.
runs = {
    "leapfrog": ("leapfrog", [{"dt": 2 * np.pi / n} for n in (50, 150, 500, 1500, 3000)]),
    "wh": ("wh", [{"dt": 2 * np.pi / n} for n in (50, 150, 500, 1500, 3000)]),
    "radau15": ("radau15", [{"tol": t} for t in (1e-4, 1e-6, 1e-8, 1e-10)]),
    "dop853": ("dop853", [{"tol": t} for t in (1e-6, 1e-8, 1e-10, 1e-12, 1e-14)]),
}
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.5))
for label, (method, options) in runs.items():
    run(method, **options[0])  # compile outside the timing
    points = np.array([run(method, **o) for o in options])
    best = points[np.argmin(points[:, 1])]
    print(f"{label:9s} smallest error {best[1]:.1e} a in {best[0]:.3f} s, {int(best[2])} steps")
    ax1.loglog(points[:, 0], points[:, 1], "o-", label=label)
    ax2.loglog(points[:, 2], points[:, 1], "o-", label=label)
ax1.set_xlabel("wall time of the integration (s)")
ax2.set_xlabel("steps (count)")
for ax in (ax1, ax2):
    ax.set_ylabel("final position error (units of a)")
    ax.grid(True, which="major", lw=0.3)
ax2.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8)
fig.suptitle("20 orbits, e = 0.5: error against cost (exact answer: Kepler's equation)")
fig.tight_layout()
plt.show()
