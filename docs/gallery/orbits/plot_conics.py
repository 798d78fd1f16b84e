"""
Every conic from one periapsis
==============================

Four comets pass the Sun at the same periapsis distance ``q = 0.5 au`` with
eccentricities 0.3 (ellipse), 0.8 (ellipse), 1 (parabola) and 1.5 (hyperbola).
Each is built with :meth:`hamilton_orbits.KeplerOrbit.from_elements` and moved
along its conic with :meth:`~hamilton_orbits.KeplerOrbit.propagate`, which uses
universal variables, so the same call works for all four (Battin 1999, §4.5).
The semi-latus rectum ``p = q (1 + e)`` is Hamilton's ``p`` (Hamilton 1847,
eq. 16), and the period of the bound orbits is Kepler's third law
``P = 2 pi sqrt(a^3 / GM)``.
"""

# %%
# The orbits
# ----------
# Lengths are in au and times in days, so the Sun's ``GM`` is the Gaussian
# gravitational constant squared.  One ``from_elements`` call builds all four
# orbits, starting at periapsis (true anomaly 0).
import matplotlib.pyplot as plt
import numpy as np

from hamilton_orbits import KeplerOrbit

GM_SUN = 0.01720209895**2  # au^3 / d^2 (IAU 1976 Gaussian constant)
ecc = np.array([0.3, 0.8, 1.0, 1.5])
orbits = KeplerOrbit.from_elements(q=np.full(4, 0.5), e=ecc, inc=np.zeros(4),
                                   lan=np.zeros(4), argp=np.zeros(4), mu=GM_SUN,
                                   nu=np.zeros(4))
for e, a, p, period in zip(ecc, orbits.a, orbits.p, orbits.period, strict=True):
    print(f"e = {e:3.1f}: a = {a:8.3f} au, p = {p:.3f} au, period = {period:9.2f} d")

# %%
# Moving along the conics
# -----------------------
# ``propagate`` broadcasts over times.  The ellipses are followed for one full
# period from apoapsis (half a period before periapsis), the open orbits from 200
# days before periapsis to 200 days after.  Every orbit moves counter-clockwise
# in this frame (its angular momentum is along +z); the energy is a constant of
# the motion and ``propagate`` keeps it to rounding.
fig, ax = plt.subplots(figsize=(7.5, 6))
worst = 0.0
for k, e in enumerate(ecc):
    one = orbits[k]
    half = 0.5 * float(one.period) if e < 1 else 200.0
    span = (-half, half)
    moved = one.propagate(np.linspace(*span, 500))
    r, _ = moved.state()
    if e != 1:
        worst = max(worst, float(np.max(np.abs(moved.energy / one.energy - 1))))
    kind = "ellipse, one period" if e < 1 else (
        "parabola, ±200 d" if e == 1 else "hyperbola, ±200 d")
    (line,) = ax.plot(r[:, 0], r[:, 1], label=f"e = {e:g} ({kind})")
    ax.plot(r[0, 0], r[0, 1], "o", color=line.get_color(), ms=6)
    arc = np.cumsum(np.linalg.norm(np.diff(r, axis=0), axis=1))
    ahead = int(np.searchsorted(arc, 0.4)) + 1  # the point 0.4 au along the arc
    ax.annotate("", xy=r[ahead, :2], xytext=r[0, :2],
                arrowprops={"arrowstyle": "-|>", "color": line.get_color(), "lw": 1.5})
print(f"largest relative change of the orbital energy along the arcs: {worst:.1e}")
ax.plot(0, 0, "*", color="orange", ms=14, label="Sun (focus)")
ax.plot([], [], "o", color="0.3", ms=6, label="start of each arc; arrow: direction")
ax.set_xlabel("x, heliocentric orbital-plane frame, towards periapsis (au)")
ax.set_ylabel("y, heliocentric orbital-plane frame (au)")
ax.set_aspect("equal")
ax.set_title("one periapsis distance, q = 0.5 au, four conics")
ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8)
fig.tight_layout()
plt.show()
