"""
A low Earth orbit regressing under J2
=====================================

The bundled scene ``leo-j2``: a satellite in low Earth orbit about an oblate
Earth (effect ``j2``, the second zonal harmonic of the geopotential).  Its
orbital plane turns about the Earth's axis: the node regresses at the
first-order rate ``dOmega/dt = -3/2 n J2 (R/p)^2 cos i`` (Vallado 2013, eq. 9-41),
which the scene prints beside the rate the integration gives.
"""

# %%
# Run the scene
# -------------
import matplotlib.pyplot as plt

from hamilton_orbits import Scene

result = Scene.bundled("leo-j2").run(progress=False)
print(result.summary())

# %%
# The figures
# -----------
figures = result.plot()
plt.show()
