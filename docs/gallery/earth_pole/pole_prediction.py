"""
Where will the pole be next year?  Prediction methods hindcast against the IERS record.
=======================================================================================

Runs the bundled scene ``pole-prediction`` (rigid.earth.scene_pole_prediction): five methods
of rigid.earth.prediction (persistence, least-squares harmonics "ls", "ls+ar", "ls+var" and
the Liouville equation with a stochastic excitation, "liouville") predict the pole from
2019-01-01, and are hindcast from weekly start dates over the period assumed for Lei et
al. (2023, Artificial Satellites 58, 42; the 1st EOP PCC's Oct 2005 - Mar 2008) and over
2016-2024, each from the IERS 20 C04 record before its start date only (latency 1 day).

Writes <out>/prediction_fan.png (the fan from 2019-01-01 against the record that followed),
<out>/mae_vs_horizon.png (mean absolute error against horizon, the published LS+AR and
WLS+VAR rows beside them), <out>/coverage.png (fraction of outcomes inside each method's
own 1-sigma band) and <out>/pole_prediction.txt (the tables).
Run: python examples/earth_pole/pole_prediction.py [out_dir] [--quick]
(--quick: the paper's period only).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from hamilton_orbits import Scene
from rigid.earth.scene_pole_prediction import PUBLISHED, PUBLISHED_HORIZONS


def verdict(result) -> list[str]:
    """Where "liouville" stands against the best published C04-only row (WLS+VAR)."""
    key = next((k for k in result.tables if k.startswith("MAE") and "2005-10-01" in k), None)
    if key is None:
        return []
    rows = {r["method"]: r for r in result.tables[key]}
    best_x, best_y = PUBLISHED["WLS+VAR (Lei et al. 2023)"]
    lines, wins = [], 0
    for coord, best in (("x", best_x), ("y", best_y)):
        for h, b in zip(PUBLISHED_HORIZONS, best, strict=True):
            ours = rows["liouville"][f"{coord} {h} d"]
            wins += ours <= b
            lines.append(f"  {coord} {h:3d} d: liouville {ours:6.2f} mas, WLS+VAR {b:6.2f} mas"
                         f"  {'at or below' if ours <= b else 'above'}")
    head = (f"liouville against WLS+VAR (Lei et al. 2023), paper's period: at or below in "
            f"{wins} of {len(lines)} cells")
    return [head, *lines]


def main(argv: list[str] | None = None) -> str:
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument("out", nargs="?", default=str(Path(__file__).resolve().parents[1] / "out"),
                        help="output directory (default examples/out)")
    parser.add_argument("--quick", action="store_true", help="the paper's period only")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    scene = Scene.bundled("pole-prediction")
    if args.quick:
        scene = scene.with_values({"periods": ["2005-10-01..2008-03-01"]})
    result = scene.run(progress=False)
    for fig in result.plot():
        fig.savefig(out / f"{fig.get_label()}.png", dpi=110, bbox_inches="tight")
        plt.close(fig)
    text = "\n".join([result.summary(), "", *verdict(result)])
    (out / "pole_prediction.txt").write_text(text + "\n")
    print(text)
    return text


if __name__ == "__main__":
    main()
