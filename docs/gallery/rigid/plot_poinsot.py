"""
Poinsot's construction of the free rigid body
=============================================

A free rigid body with moments 1 : 2 : 3 turns so that its inertia ellipsoid
rolls without slipping on a fixed plane, the invariable plane, perpendicular to
the angular momentum (Poinsot 1834).  The point of contact traces the polhode on
the ellipsoid and the herpolhode on the plane.  The motion comes from the exact
solution in Jacobi's elliptic functions (:func:`rigid.free_motion`; Jacobi 1849),
and :func:`rigid.plot_poinsot` draws both curves.
"""

# %%
# The body and its free motion
# ----------------------------
# Moments and angular velocity in plain numbers (any consistent units).
import matplotlib.pyplot as plt
import numpy as np

from rigid import RigidBody, free_parameters, plot_poinsot, poinsot

body = RigidBody([1.0, 2.0, 3.0], omega=[1.0, 0.3, 0.8])
par = free_parameters(body)
print(f"period of the angular velocity in the body: {par.period:.4f} (time units)")
paths = poinsot(body, np.linspace(0.0, 40.0, 4000))
print(f"distance of the invariable plane from the centre: {paths.distance:.6f} "
      f"(sqrt(2T)/|L|, Poinsot)")

# %%
# Polhode and herpolhode
# ----------------------
# The polhode closes on the ellipsoid after one period; the herpolhode on the
# plane in general does not close.  The ellipsoid's semi-axes are
# ``1 / sqrt(I)`` for the principal moments ``I``, so both curves are in units of
# ``(kg m^2)^(-1/2)`` (a body of plain numbers is in SI units; the figure's axes
# say so); the start of the contact point's path is marked on both.
fig = plot_poinsot(body, np.linspace(0.0, 40.0, 4000))
ax3d, ax2d = fig.axes
ax3d.plot(*paths.polhode[0], "o", color="k", ms=5)
ax2d.plot(*paths.herpolhode[0], "o", color="k", ms=5, label="start (t = 0)")
ax2d.legend(loc="lower left", fontsize=7)  # (inside: the figure keeps plot_poinsot's layout)
plt.show()
