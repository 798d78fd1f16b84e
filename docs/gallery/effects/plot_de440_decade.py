"""
The real sky: a decade against DE440
====================================

The bundled scene ``de440-century``, shortened to 10 years: DE440's own state
and masses at J2000, shipped with the package (Park, Folkner, Williams & Boggs
2021, AJ 161, 105), for the Sun, planets, Moon, Pluto and the 16 most massive
asteroids, integrated with DE440's physics: the Einstein-Infeld-Hoffmann
equations (1PN), the Sun's J2 and Lense-Thirring field, the Earth's zonal
harmonics and the Moon's figure, the lunar tides on the Earth and the
Kuiper-belt ring.  The positions are compared with DE440's own at the epochs
tabulated with the package; ``docs/de440_ladder.md`` shows what each piece
of physics buys.
"""

# %%
# Run the scene
# -------------
import matplotlib.pyplot as plt

from hamilton_orbits import Scene

scene = Scene.bundled("de440-century").with_values({"duration": "10 yr"})
result = scene.run(progress=False)
print(result.summary())

# %%
# The residuals, year by year
# ---------------------------
# The run's diagnostics hold each body's distance from DE440's position
# (heliocentric; the Moon's geocentric) at the yearly epochs of the shipped
# table, in the order of the residuals table.
import numpy as np  # noqa: E402

table = result.tables["residuals against DE440 (heliocentric; the Moon geocentric)"]
bodies = [row["body"] for row in table]
years = np.asarray(result.diagnostics["de440_years"])
km = np.asarray(result.diagnostics["de440_km"])
worst = int(np.argmax(km[-1]))
print(f"largest residual after {years[-1]:g} yr: {bodies[worst]}, {km[-1, worst]:.2f} km")

fig, ax = plt.subplots(figsize=(9, 5))
for k, name in enumerate(bodies):
    style = "--" if k >= 10 else "-"
    label = f"{name} (geocentric)" if name == "moon" else name
    ax.semilogy(years[1:], km[1:, k], style, marker="o", ms=3, label=label)
ax.set_xlabel("years after J2000 (TDB)")
ax.set_ylabel("|r - r_DE440| (km)")
ax.set_title("DE440's physics from DE440's J2000 state, against DE440")
ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8)
fig.tight_layout()
plt.show()
