"""
The solar system, checked against rebound
=========================================

The bundled scene ``solar-system``: the Sun and the eight planets (the
Earth-Moon barycentre as one body) from their J2000 positions, integrated with
``radau15`` (Everhart 1985; Rein & Spiegel 2015) and, in the same run, with
rebound's IAS15 from the same initial state.  Here the scene's thousand years are
shortened to 20 so that the example runs in seconds; the cross-check table gives each
body's final position difference between the two codes, and the diagnostics
are Hamilton's integrals (energy, vis viva, and angular momentum, the law of
areas; Hamilton 1845, eqs. (D), (E)).
"""

# %%
# Run the scene
# -------------
# :meth:`hamilton_orbits.Scene.with_values` changes keys of a bundled scene
# exactly as ``--set`` does on the command line.
import matplotlib.pyplot as plt

from hamilton_orbits import Scene

scene = Scene.bundled("solar-system").with_values({"duration": "20 yr", "cadence": "10 d"})
result = scene.run(progress=False)
print(result.summary())

# %%
# The figures
# -----------
# The scene draws the orbits face-on in the J2000 ecliptic frame and the
# energy error (the law of vis viva, Hamilton's (E)), ours above rebound's; the
# angular momentum's (the law of areas, (D)) is among the run's diagnostics,
# ``result.diagnostics["angular_momentum_error"]``.
figures = result.plot()
plt.show()
