"""
Cayley's integrals under four rigid-body integrators
====================================================

A free rigid body keeps its kinetic energy ``T`` and its angular momentum in
space, ``L_s = q (A p, B q, C r) q^-1``, Cayley's integrals ``(g, g', g'')``
(Cayley 1843).  A body with moments 1 : 2 : 3 spun near its middle axis (so it
flips, as in the Dzhanibekov example) is integrated for 200 time units with the
same step by four methods of :func:`rigid.integrate`: classical Runge-Kutta on
the quaternion (``rk4``) and on Cayley's parameters ``(lambda, mu, nu)`` with
re-centring (``cayley_rk4``, see ``rigid.rodrigues``), the fourth-order
Lie-Poisson splitting (``splitting4``; McLachlan 1993) and the exact free flow
with kicks (``exact_kick``).  The splitting keeps the angular momentum in
space to rounding and its energy error bounded, oscillating with the flips;
``exact_kick`` keeps both near rounding; the two Runge-Kutta methods err by
orders of magnitude more, whether on the quaternion or on Cayley's parameters.
"""

# %%
# The body and the runs
# ---------------------
# Plain numbers: moments and angular velocity in any consistent units, times in
# the matching unit (here called "time units").
import matplotlib.pyplot as plt
import numpy as np

from rigid import RigidBody, integrate

body = RigidBody([1.0, 2.0, 3.0], omega=[0.05, 1.0, 0.05])
t = np.linspace(0.0, 200.0, 801)
runs = {m: integrate(body, t, method=m, dt=0.05)
        for m in ("rk4", "cayley_rk4", "splitting4", "exact_kick")}
for name, tr in runs.items():
    print(f"{name:11s} max |dT/T| = {np.max(np.abs(tr.energy_error)):.1e}, "
          f"max |dL/L| = {np.max(np.abs(tr.angular_momentum_error)):.1e}, "
          f"steps {tr.steps}, re-centrings {tr.n_recentre}")

# %%
# The integrals against time
# --------------------------
# Errors of exactly 0 (to the last bit) cannot be drawn on a log axis: they are
# left out (the line breaks there; the legend counts them), not drawn at an
# invented floor.  rk4 and cayley_rk4 conserve T alike (their curves lie on each
# other): cayley_rk4 is drawn dashed over rk4.
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.5), sharey=True)
dashes = {"cayley_rk4": "--"}
for name, tr in runs.items():
    for ax, err in ((ax1, tr.energy_error), (ax2, tr.angular_momentum_error)):
        err = np.abs(np.asarray(err, dtype=float))[1:]  # (after the start, 0 by definition)
        zeros = int(np.count_nonzero(err == 0))
        ax.semilogy(tr.t[1:], np.where(err > 0, err, np.nan), lw=1, ls=dashes.get(name, "-"),
                    label=name + (f" ({zeros} exact zeros left out)" if zeros else ""))
ax1.set_ylabel("relative error (dimensionless)")
ax1.set_title("kinetic energy T")
ax2.set_title("angular momentum in space (Cayley's g, g', g'')")
for ax in (ax1, ax2):
    ax.set_xlabel("time (time units; step 0.05)")
for ax in (ax1, ax2):
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), fontsize=7, ncol=2,
              frameon=False)
fig.tight_layout()
plt.show()
