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
# plane in general does not close.  The ellipsoid ``x . I x = 1`` has semi-axes
# ``1 / sqrt(I)`` for the principal moments ``I``; the figure's coordinates are
# multiplied by ``sqrt(C)``, ``C`` the largest moment (3 here, in whatever units
# the numbers are in), so that they are free of units and of order one.  The
# middle panel is the polhode seen along the axis it goes round, framed on
# itself; the first time's point is marked on every panel.
fig = plot_poinsot(body, np.linspace(0.0, 40.0, 4000))
plt.show()
