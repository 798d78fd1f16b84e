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
