"""Clones of a near-parabolic comet past Jupiter: an ensemble of one scene.

The bundled scene ``comet-encounter`` (q = 0.01 au, e = 0.9999, then 0.03 au past
Jupiter) is run for clones whose eccentricity differs by a few 1e-6: the
perihelion time shifts by hours, Jupiter is met at a different distance, and the
semi-major axis after the encounter scatters.  The members run in parallel
(hamilton_orbits.Ensemble; a Dask client can be given instead of the local pool).

Writes <out>/comet_clones.png and <out>/comet_clones.csv.
Run: python examples/ensemble_comet_clones.py [out_dir] [--quick]
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
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?", default=str(Path(__file__).parent / "out"))
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
    a_after = table["comet orbit after: a [AU]"]
    print(f"{len(table)} clones, {table.attrs['failures']} failed")
    print(f"{'e':>12}  {'closest (au)':>12}  {'a after (au)':>12}  {'wall (s)':>8}")
    for k in range(len(table)):
        print(f"{table['bodies.comet.e'][k]:12.8f}  {closest[k]:12.5f}  {a_after[k]:12.3f}"
              f"  {table['wall time [s]'][k]:8.2f}")

    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    de = (table["bodies.comet.e"] - 0.9999) * 1e6
    ax.plot(de, closest, "o-")
    ax.set_xlabel("e - 0.9999 [1e-6]")
    ax.set_ylabel("closest approach to Jupiter [au]")
    ax2.plot(de, a_after, "o-")
    ax2.axhline(100.0, color="0.5", ls=":", label="a before, e = 0.9999")
    ax2.set_xlabel("e - 0.9999 [1e-6]")
    ax2.set_ylabel("semi-major axis after [au]")
    ax2.legend()
    fig.suptitle("comet clones past Jupiter (hamilton-orbits Ensemble, radau15)")
    fig.savefig(out / "comet_clones.png", dpi=110, bbox_inches="tight")
    print(f"wrote {out / 'comet_clones.png'}")


if __name__ == "__main__":
    main()
