"""
The outer solar system in 3-D, interactive
==========================================

:meth:`hamilton_orbits.Trajectory.plot3d` draws a trajectory as an interactive
plotly figure: the orbits, each body's start, and the bodies at an output chosen
with the time slider (drag it, or press play).  The Sun, Jupiter, Saturn, Uranus and
Neptune at J2000 from astropy's built-in ephemeris (ERFA's ``plan94``, offline; within
2e-3 au of JPL's DE440, which ``System.from_ephemeris`` gives) for one orbit of
Neptune with ``radau15``; the axes are the J2000 ecliptic ones, centred on the Sun.
The figure needs the ``plot3d`` extra (plotly); the page embeds plotly.js, so it
works offline.  :meth:`~hamilton_orbits.Trajectory.plot` draws the same run with
matplotlib for print.
"""

# %%
# Integrate
# ---------
import astropy.units as u
import numpy as np

from hamilton_orbits import System, integrate

system = System.solar_system("J2000", bodies=["sun", "jupiter", "saturn", "uranus", "neptune"],
                             frame="ecliptic")
traj = integrate(system, np.linspace(0.0, 165.0, 661) * u.yr, method="radau15")
print(f"{traj.steps} steps; largest |relative energy error| "
      f"{np.max(np.abs(traj.energy_error)):.1e}")

# %%
# The static view (matplotlib)
# ----------------------------
fig2d = traj.plot()

# %%
# The interactive view (plotly)
# -----------------------------
# ``plot3d`` returns a ``plotly.graph_objects.Figure``: in Jupyter it displays itself;
# ``fig.write_html("orbits.html", include_plotlyjs=True)`` makes a file that opens
# in any browser without a network.  Here it is embedded in the page as that HTML.
fig = traj.plot3d(origin="sun", max_frames=60)


class Embedded:
    """The figure as self-contained HTML (plotly.js inline, no download)."""

    def __init__(self, figure):
        self.figure = figure

    def _repr_html_(self):
        return self.figure.to_html(full_html=False, include_plotlyjs=True,
                                   auto_play=False)


Embedded(fig)
