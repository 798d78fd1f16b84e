"""
A sungrazing comet and a close encounter with Jupiter
=====================================================

The bundled scene ``comet-encounter``: a comet with eccentricity 0.9999 passes
perihelion at 0.01 au, then comes within a few hundredths of an au of Jupiter.
Both are hard cases for a fixed-step integrator; ``radau15`` (Everhart 1985,
with the step control of Rein & Spiegel 2015) shortens its steps at each, and the
scene's events table gives the time and distance of the encounter.  The run is
cross-checked against rebound's IAS15 from the same state.
"""

# %%
# Run the scene
# -------------
import matplotlib.pyplot as plt

from hamilton_orbits import Scene

result = Scene.bundled("comet-encounter").run(progress=False)
print(result.summary())

# %%
# The figures
# -----------
# The orbits about the Sun, with the encounter marked, and the errors of the
# integrals through perihelion and the encounter.
figures = result.plot()
plt.show()

# %%
# The encounter, marked
# ---------------------
# From the run's states: the comet's distance from Jupiter and from the Sun
# against time, and the orbits about the Sun with each body's start, its
# direction of motion and the point of closest approach.
import astropy.units as u  # noqa: E402
import numpy as np  # noqa: E402

names = list(result.states["names"])
r = np.asarray(result.states["r"].to_value(u.au) if hasattr(result.states["r"], "unit")
               else result.states["r"])
t = result.times.to_value(u.yr)
sun, jup, comet = names.index("sun"), names.index("jupiter"), names.index("comet")
d_jup = np.linalg.norm(r[:, comet] - r[:, jup], axis=1)
d_sun = np.linalg.norm(r[:, comet] - r[:, sun], axis=1)
t_ca = result.metrics["at time"].to_value(u.yr)
d_ca = result.metrics["closest approach comet-jupiter"].to_value(u.au)
print(f"closest approach to Jupiter: {d_ca:.4f} au at t = {t_ca:.4f} yr; "
      f"perihelion {d_sun.min():.4f} au at t = {t[np.argmin(d_sun)]:.4f} yr (outputs)")
# the perihelion distance itself: the comet's two-body orbit about the Sun at the
# start (the 6-hour outputs pass perihelion twice as far out)
from astropy.constants import GM_sun  # noqa: E402

from hamilton_orbits import KeplerOrbit  # noqa: E402

v = np.asarray(result.states["v"].to_value(u.au / u.day))
q = KeplerOrbit.from_state(r[0, comet] - r[0, sun], v[0, comet] - v[0, sun],
                           GM_sun.to_value(u.au**3 / u.day**2)).q
print(f"perihelion distance q of the two-body orbit at the start: {q:.4f} au")

# One colour a body in both panels: the Sun orange, Jupiter blue, the comet green;
# a distance from the comet takes the colour of the body it is measured to.
COLOURS = {"Sun": "C1", "Jupiter": "C0", "comet": "C2"}
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 5.6))
ax1.semilogy(t, d_sun, color=COLOURS["Sun"], label="comet - Sun")
ax1.semilogy(t, d_jup, color=COLOURS["Jupiter"], label="comet - Jupiter")
ax1.plot(t_ca, d_ca, "v", color="C3", ms=8, label=f"closest approach, {d_ca:.3f} au")
ax1.axhline(q, color=COLOURS["Sun"], ls=":", lw=1,
            label=f"perihelion q = {q:.3f} au (between\nthe 6-hour outputs drawn)")
ax1.set_xlabel("time since the start (yr)")
ax1.set_ylabel("distance (au)")
ax1.set_title(f"perihelion at q = {q:.2f} au, then Jupiter")
# below the axes: inside, it covered the comet - Jupiter curve after the encounter
ax1.legend(loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2, fontsize=8,
           frameon=False)
i_ca = int(np.argmin(np.abs(t - t_ca)))
for k, name in ((jup, "Jupiter"), (comet, "comet")):
    xy = r[:, k, :2] - r[:, sun, :2]
    (line,) = ax2.plot(xy[:, 0], xy[:, 1], lw=1, color=COLOURS[name], label=name)
    ax2.plot(*xy[0], "o", color=line.get_color(), ms=6)
    step = xy[1] - xy[0]  # (an arrow of one length for both: Jupiter's 40 outputs
    size = 0.08 * float(np.ptp(r[:, :, :2]))  # were too short to be seen)
    ax2.annotate("", xy=xy[0] + size * step / np.hypot(*step), xytext=xy[0],
                 arrowprops={"arrowstyle": "-|>", "color": line.get_color()})
ax2.plot(*(r[i_ca, comet, :2] - r[i_ca, sun, :2]), "v", color="C3", ms=8,
         label="closest approach")
ax2.plot(0, 0, "*", color=COLOURS["Sun"], ms=12, label="Sun")
ax2.plot([], [], "o", color="0.3", label="start; arrow: direction")
ax2.set_xlabel("x from the Sun, ICRS axes (au)")
ax2.set_ylabel("y from the Sun, ICRS axes (au)")
ax2.set_aspect("equal")
ax2.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8)
fig.tight_layout()
plt.show()
