"""
Mercury's relativistic perihelion advance
=========================================

The bundled scene ``mercury-gr``: the Sun and Mercury alone, integrated with the
first post-Newtonian acceleration of a test body about the Sun (effect ``gr``;
the form of Anderson et al. 1975 that reboundx's ``gr`` uses).  Without other
planets the only precession left is Einstein's,
``6 pi GM / (c^2 a (1 - e^2))`` per orbit (Einstein 1915), 42.98 arcsec per
century for Mercury.  The scene fits the advance of the perihelion longitude
over a century and prints the fitted rate; its figure draws the rate beside
that value.
"""

# %%
# Run the scene
# -------------
import matplotlib.pyplot as plt

from hamilton_orbits import Scene

result = Scene.bundled("mercury-gr").run(progress=False)
print(result.summary())

# %%
# The figures
# -----------
# The perihelion longitude against time, with the fitted rate and the
# 42.98"/cy of general relativity.
figures = result.plot()
plt.show()
