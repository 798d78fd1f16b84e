"""
The Pythagorean three-body problem
==================================

Burrau's problem (Burrau 1913; Szebehely & Peters 1967, AJ 72, 876): three
bodies of masses 3, 4 and 5 start at rest at the corners of a right triangle
with sides 3, 4 and 5, each opposite the side of its own length (G = 1).  They
fall together and pass through a sequence of close binary encounters until,
near t = 60, the lightest body is ejected and the other two leave as a binary
(Szebehely & Peters 1967).  The first 15 time units already hold the close approaches that
make it a classic test of an adaptive integrator; ``radau15`` (Everhart 1985,
with the step control of Rein & Spiegel 2015) shortens its step through each,
and :meth:`hamilton_orbits.Trajectory.plot` draws the paths.
"""

# %%
# The system
# ----------
# Units: G = 1; lengths, masses and times in the problem's own units.
import matplotlib.pyplot as plt
import numpy as np

from hamilton_orbits import Body, Simulation, System

system = System([Body("m3", 3.0, [1.0, 3.0, 0.0], [0.0, 0.0, 0.0]),
                 Body("m4", 4.0, [-2.0, -1.0, 0.0], [0.0, 0.0, 0.0]),
                 Body("m5", 5.0, [1.0, -1.0, 0.0], [0.0, 0.0, 0.0])], G=1.0)

# %%
# Integrate
# ---------
traj = Simulation(system, method="radau15").integrate(np.linspace(0.0, 15.0, 3001))
d = np.linalg.norm(traj.r[:, :, None] - traj.r[:, None, :], axis=-1)
closest = min(d[:, i, j].min() for i, j in ((0, 1), (0, 2), (1, 2)))
print(f"{traj.steps} steps; closest approach of any pair at the outputs: {closest:.2e}")
print(f"largest |relative energy error| {np.max(np.abs(traj.energy_error)):.1e}, "
      f"angular momentum (absolute, L = 0) {np.max(np.abs(traj.angular_momentum_error)):.1e}")

# %%
# The paths
# ---------
# ``Trajectory.plot`` draws the paths about the most massive body, with each
# start and end (the bodies start at rest, so there is no direction to show at
# the start); the axes here are in the problem's length unit.
fig = traj.plot()
ax = fig.axes[0]
ax.set_xlabel("x from m5 (length unit of the problem, G = 1)")
_ = ax.set_ylabel("y from m5 (length unit of the problem, G = 1)")

# %%
# The same paths about the centre of mass (which stays at the origin: the
# total momentum is 0), with an arrow at the end of each path for the
# direction of motion there.
fig, ax = plt.subplots(figsize=(6.5, 6))
for k, name in enumerate(traj.names):
    (line,) = ax.plot(traj.r[:, k, 0], traj.r[:, k, 1], lw=0.8, label=f"{name} (mass {k + 3})")
    ax.plot(*traj.r[0, k, :2], "o", color=line.get_color(), mfc="none", ms=7)
    ax.annotate("", xy=traj.r[-1, k, :2], xytext=traj.r[-40, k, :2],
                arrowprops={"arrowstyle": "-|>", "color": line.get_color()})
ax.plot([], [], "o", color="0.3", mfc="none", label="start (at rest)")
ax.set_xlabel("x, barycentric (length unit of the problem)")
ax.set_ylabel("y, barycentric (length unit of the problem)")
ax.set_aspect("equal")
ax.set_title("t = 0 to 15 (radau15)")
ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8)
fig.tight_layout()
plt.show()
