"""
Error against cost with a perturbed eccentric orbit
===================================================

A test particle on an orbit of eccentricity 0.5 about a star (G = GM = 1, period
2 pi), perturbed by a planet of a thousandth of the star's mass on a circle
at 3 length units, is followed for 20 orbits by each integrator: the leapfrog
and the Wisdom-Holman map (fixed steps, second order; Wisdom & Holman 1991),
``radau15`` (15th order, adaptive; Everhart 1985, Rein & Spiegel 2015) and
``dop853`` (8th order, adaptive; Hairer, Nørsett & Wanner 1993).  The error is
the final position against a reference run that none of them is: ``radau15`` in
double-double arithmetic with a fixed step of 1/800 of the particle's orbit
(``precision="double-double"``), whose own error, the difference to the same run
at twice the step, is the floor below which an error is not resolved; the cost
is the integration's wall time and its number of steps.  Without the planet the
Wisdom-Holman map would be exact (its drift is the Kepler flow), so the
perturbation is what it is measured on.
"""

# %%
# The system and the reference
# ----------------------------
import matplotlib.pyplot as plt
import numpy as np

from hamilton_orbits import Body, KeplerOrbit, Simulation, System

orbit = KeplerOrbit.from_elements(a=1.0, e=0.5, inc=0.0, lan=0.0, argp=0.0, nu=0.0, mu=1.0)
r0, v0 = orbit.state()
system = System([Body("star", 1.0, [0, 0, 0], [0, 0, 0]),
                 Body("planet", 1e-3, [-3.0, 0, 0], [0, -np.sqrt(1.001 / 3.0), 0]),
                 Body("particle", 0.0, r0, v0)])
t_end = 20 * 2 * np.pi


def reference_run(per_orbit: int) -> np.ndarray:
    """The particle's final position by radau15 in double-double, fixed steps."""
    sim = Simulation(system, precision="double-double", dt=2 * np.pi / per_orbit)
    return sim.integrate(t_end).r[-1, 2]


reference = reference_run(800)
floor = float(np.linalg.norm(reference - reference_run(400)))
print(f"reference: double-double radau15 at 800 and 400 steps an orbit differ by "
      f"{floor:.1e} (length units); errors below this are not resolved")


def run(method: str, **options) -> tuple[float, float, int]:
    """(wall time in s, final position error, steps) of one run."""
    traj = Simulation(system, method=method, **options).integrate(t_end)
    return traj.wall_time, float(np.linalg.norm(traj.r[-1, 2] - reference)), traj.steps


# %%
# Sweep the step or the tolerance
# -------------------------------
# Fixed-step methods take steps from 1/50 to 1/3000 of the particle's orbit;
# radau15 tolerances from 1e-2 to 1e-6 (its error reaches 1e-10 there) and dop853
# from 1e-6 to 1e-14.  The first run of each
# method compiles its kernel, so each is run once before the sweep.
runs = {
    "leapfrog": ("leapfrog", [{"dt": 2 * np.pi / n} for n in (50, 150, 500, 1500, 3000)]),
    "wh": ("wh", [{"dt": 2 * np.pi / n} for n in (50, 150, 500, 1500, 3000)]),
    "radau15": ("radau15", [{"tol": t} for t in (1e-2, 1e-3, 1e-4, 1e-6)]),
    "dop853": ("dop853", [{"tol": t} for t in (1e-6, 1e-8, 1e-10, 1e-12, 1e-14)]),
}
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.5))
for label, (method, options) in runs.items():
    run(method, **options[0])  # compile outside the timing
    points = np.array([run(method, **o) for o in options])
    best = points[np.argmin(points[:, 1])]
    print(f"{label:9s} smallest error {best[1]:.1e} in {best[0]:.3f} s, {int(best[2])} steps")
    ax1.loglog(points[:, 0], points[:, 1], "o-", label=label)
    ax2.loglog(points[:, 2], points[:, 1], "o-", label=label)
ax1.set_xlabel("wall time of the integration (s)")
ax2.set_xlabel("steps (count)")
for ax in (ax1, ax2):
    ax.axhline(floor, color="k", ls=":", lw=1,
               label="the reference's own error\n(double-double, dt vs 2 dt)")
    ax.set_ylabel("final position error (length units, a = 1)")
    ax.grid(True, which="major", lw=0.3)
ax2.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8)
fig.suptitle("20 orbits, e = 0.5, perturbed: error against cost")
fig.tight_layout()
plt.show()
