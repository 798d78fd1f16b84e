"""
Clones of a near-parabolic comet past Jupiter: an ensemble of one scene.
========================================================================

The bundled scene ``comet-encounter`` (q = 0.01 au, e = 0.9999, then 0.03 au past
Jupiter) is run for clones whose eccentricity differs by a few 1e-6: the
perihelion time shifts by hours, Jupiter is met at a different distance, and the
orbit after the encounter scatters: its 1/a (the binding energy; a itself jumps
through infinity where a clone goes from bound to escaping).  The members run in
parallel (hamilton_orbits.Ensemble; a Dask client can be given instead of the
local pool).

Writes <out>/comet_clones.png and <out>/comet_clones.csv.
Run: python examples/ensembles/ensemble_comet_clones.py [out_dir] [--quick]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from hamilton_orbits import Ensemble, Scene


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument("out", nargs="?", default=str(Path(__file__).resolve().parents[1] / "out"))
    parser.add_argument("--quick", action="store_true", help="4 clones instead of 16")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    n = 4 if args.quick else 16
    e = 0.9999 + np.linspace(-4e-6, 4e-6, n)
    scene = Scene.bundled("comet-encounter").with_values({"crosscheck": False,
                                                          "cadence": "0.5 d"})
    table = Ensemble(scene, vary={"bodies.comet.e": [float(x) for x in e]}).run()
    table.to_csv(out / "comet_clones.csv", index=False)

    closest = table["closest approach comet-jupiter [AU]"]
    # 1/a, not a: an escaped clone's a is negative, and a clone near the parabola
    # sends a through +-infinity; 1/a (the binding energy, -2 E / mu) is smooth
    inv_a = table["comet orbit after: 1/a [1 / AU]"]
    inv_a0 = table["comet orbit before: 1/a [1 / AU]"]  # (1 - e) / q: each clone its own
    q_after = table["comet orbit after: q [AU]"]
    print(f"{len(table)} clones, {table.attrs['failures']} failed")
    print(f"{'e':>12}  {'closest (au)':>12}  {'1/a after (1/au)':>16}  {'q after (au)':>12}"
          f"  {'orbit after':>11}  {'wall (s)':>8}")
    for k in range(len(table)):
        kind = "bound" if inv_a[k] > 0 else "escapes"
        print(f"{table['bodies.comet.e'][k]:12.8f}  {closest[k]:12.5f}  {inv_a[k]:16.6f}  "
              f"{q_after[k]:12.6f}  {kind:>11}  {table['wall time [s]'][k]:8.2f}")

    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    de = (table["bodies.comet.e"] - 0.9999) * 1e6
    ax.plot(de, closest, "o-")
    ax.set_xlabel("e before - 0.9999 [1e-6]")
    ax.set_ylabel("closest approach to Jupiter [au]")
    ax2.plot(de, inv_a, "o-", label="after the encounter")
    ax2.plot(de, inv_a0, ":", color="0.4", label="before: (1 - e) / q, a = 96-104 au")
    ax2.axhline(0.0, color="k", lw=0.6)
    ax2.text(de.iloc[0], 0.0, " parabola: below escapes, above bound", va="bottom", fontsize=8)
    ax2.set_xlabel("e before - 0.9999 [1e-6]")
    ax2.set_ylabel("1/a about the Sun [1/au]")
    ax2.legend(fontsize=8)
    fig.suptitle("comet clones past Jupiter (hamilton-orbits Ensemble, radau15)")
    fig.tight_layout()
    fig.savefig(out / "comet_clones.png", dpi=110, bbox_inches="tight")
    print(f"wrote {out / 'comet_clones.png'}")


if __name__ == "__main__":
    main()
