"""The full hindcast of rigid.earth.prediction: five methods, two periods, timed.

Run ``PYTHONPATH=src python benchmarks/bench_pole_prediction.py [--out FILE]``.

Weekly start dates over the period assumed for Lei et al. 2023 (the 1st EOP PCC's
2005-10-01 .. 2008-03-01) and over 2016-01-01 .. 2024-01-01 (eight years), latency 1 day
(the newest datum is the day before each start; horizon h is h + 1 days after it).  Every
method, every start: the mean absolute error of x_p and y_p per horizon, the rms of the
2-D error, and the fraction of outcomes inside the method's own 1-sigma band.  Also the
same scores with the horizon counted from the newest datum (h - 1 days after the start),
the convention of a prediction whose first day follows the last observation.  The wall
time is that of the five methods over the eight-year period, one process.
"""

from __future__ import annotations

import argparse
import os
import time
from datetime import UTC, datetime
from pathlib import Path

import astropy.units as u
import numpy as np

from rigid.earth.prediction import METHODS, PAPER_PERIOD, RECENT_PERIOD, hindcast, weekly_starts
from rigid.earth.scene_pole_prediction import PUBLISHED, PUBLISHED_HORIZONS
from rigid.polar_motion import load_c04

HORIZONS = (10, 30, 90, 150, 270, 365)


def mae_table(scores: dict, published: bool, horizons=HORIZONS) -> list[str]:
    head = " | ".join(f"x {h}" for h in horizons) + " | " + " | ".join(
        f"y {h}" for h in horizons)
    lines = [f"| method | {head} |", "|---" * (1 + 2 * len(horizons)) + "|"]
    for m, s in scores.items():
        t = s.table
        vals = list(t["mae_x"].to_value(u.mas)) + list(t["mae_y"].to_value(u.mas))
        lines.append(f"| {m} | " + " | ".join(f"{v:.2f}" for v in vals) + " |")
    if published:
        for name, (px, py) in PUBLISHED.items():
            cells = []
            for series in (px, py):
                for h in HORIZONS:
                    cells.append(f"{series[PUBLISHED_HORIZONS.index(h)]:.2f}"
                                 if h in PUBLISHED_HORIZONS else "-")
            lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return lines


def coverage_table(scores: dict) -> list[str]:
    lines = ["| method | " + " | ".join(f"{h} d" for h in HORIZONS) + " |",
             "|---" * (1 + len(HORIZONS)) + "|"]
    for m, s in scores.items():
        t = s.table
        lines.append(f"| {m} | " + " | ".join(
            f"{cx:.2f}, {cy:.2f}" for cx, cy in zip(t["coverage_x"], t["coverage_y"],
                                                     strict=True)) + " |")
    return lines


def main(argv: list[str] | None = None) -> str:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="benchmarks/results/bench_pole_prediction.md")
    args = parser.parse_args(argv)
    record = load_c04()
    hindcast(record, weekly_starts("2019-01-01", "2019-01-15"), method="ls+ar")  # warm-up
    when = datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")
    lines = [f"# Pole prediction hindcasts ({when}, 2-core machine, load average "
             f"{os.getloadavg()[0]:.1f})", ""]
    for label, period in (("paper's period (assumed)", PAPER_PERIOD),
                          ("2016-2024", RECENT_PERIOD)):
        starts = weekly_starts(*period)
        begin = time.perf_counter()
        scores = {m: hindcast(record, starts, HORIZONS * u.day, m) for m in METHODS}
        wall = time.perf_counter() - begin
        late = {m: hindcast(record, starts, (np.array(HORIZONS) - 1) * u.day, m)
                for m in ("ls+ar", "ls+var", "liouville")}
        lines += [f"## {label}: weekly starts {period[0]} .. {period[1]} ({len(starts)} "
                  f"start dates), latency 1 d", "",
                  f"Five methods in {wall:.1f} s (one process; per method: "
                  + ", ".join(f"{m} {s.wall_time:.1f} s" for m, s in scores.items()) + ").",
                  "", "Mean absolute error (mas), horizon from the start date:", "",
                  *mae_table(scores, period == PAPER_PERIOD), "",
                  "Horizon counted from the newest datum instead (h - 1 days after the "
                  "start):", "", *mae_table(late, False), "",
                  "Fraction of outcomes within the method's own 1-sigma (x, y):", "",
                  *coverage_table(scores), ""]
    text = "\n".join(lines) + "\n"
    Path(args.out).write_text(text)
    print(text)
    return text


if __name__ == "__main__":
    main()
