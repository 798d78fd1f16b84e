"""
MEGNO: a regular and a chaotic orbit beside Jupiter
===================================================

A planet of Saturn's mass beside Jupiter (both about the Sun, coplanar), at
three starting semi-major axes.  The variational equations are integrated beside
the orbits (``variational=True``) with ``radau15`` (Everhart 1985; Rein &
Spiegel 2015), whose adaptive step also resolves the close approaches to Jupiter
that a chaotic orbit makes, and give MEGNO, the mean exponential growth of nearby orbits
(Cincotta & Simó 2000): its running mean ``<Y>(t)`` tends to 2 on a
quasi-periodic orbit and grows like ``lambda t / 2`` on a chaotic one, where
``lambda`` is the Lyapunov exponent.  The whole map of such cells is
``stability_map.py`` in this section.
"""

# %%
# The systems
# -----------
# Units: G = 1, masses in solar masses, lengths in au; the time unit is then
# 1/(2 pi) yr.  Jupiter starts on a circle at 5.2 au, the planet at
# eccentricity 0.05 on the opposite side.
import matplotlib
import matplotlib.pyplot as plt
import numpy as np

from hamilton_orbits import Body, Simulation, System

M_JUPITER, M_SATURN = 9.548e-4, 2.859e-4  # solar masses (DE440's system masses, GM/GM_sun)
A_JUPITER = 5.2
P_JUPITER = 2 * np.pi * np.sqrt(A_JUPITER**3 / (1 + M_JUPITER))  # time units


def system(a: float, e: float = 0.05) -> System:
    """Sun, Jupiter and the planet at apocentre (speed from vis viva)."""
    r = a * (1 + e)
    v = np.sqrt((1 + M_SATURN) * (2 / r - 1 / a))
    vj = np.sqrt((1 + M_JUPITER) / A_JUPITER)
    return System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                   Body("jupiter", M_JUPITER, [A_JUPITER, 0, 0], [0, vj, 0]),
                   Body("planet", M_SATURN, [-r, 0, 0], [0, -v, 0])], G=1.0)


# %%
# Integrate with the variational equations
# ----------------------------------------
# 500 orbits of Jupiter, 400 outputs.  The energy error shows that the
# integration stays accurate on the chaotic orbit too: its MEGNO is the
# dynamics, not the integrator's error.
n_orbits = 500
times = np.linspace(0, n_orbits * P_JUPITER, 401)
fig, ax = plt.subplots(figsize=(8, 4.5))
styles = {6.6: "-", 7.6: "--", 9.5: ":"}  # (two regular curves lie on each other)
for a in (6.6, 7.6, 9.5):
    sim = Simulation(system(a), method="radau15", variational=True)
    traj = sim.integrate(times)
    verdict = "chaotic" if traj.megno[-1] > 4 else "regular"
    print(f"a = {a} au: MEGNO after {n_orbits} orbits of Jupiter = {traj.megno[-1]:.3f} "
          f"({verdict}); energy error {np.max(np.abs(traj.energy_error)):.1e}")
    ax.semilogy(times[1:] / P_JUPITER, traj.megno[1:], ls=styles[a], lw=1.6,
                label=f"a = {a} au ({verdict})")
ax.axhline(2.0, color="0.4", ls="-", lw=0.8, label="2: quasi-periodic limit")
ax.yaxis.set_major_locator(matplotlib.ticker.LogLocator(subs=(1.0, 2.0, 5.0)))
ax.yaxis.set_major_formatter(matplotlib.ticker.ScalarFormatter())  # (2, 5, 10: no 2x10^0)
ax.yaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
ax.set_xlabel("time (orbits of Jupiter)")
ax.set_ylabel("MEGNO <Y> (dimensionless, log scale)")
ax.set_title("Saturn-mass planet beside Jupiter, e = 0.05 (radau15, variational equations)")
ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8)
fig.tight_layout()
plt.show()
