"""The physics ladder against JPL's DE440: residuals per rung and body, and wall time.

    PYTHONPATH=src python benchmarks/bench_de440_ladder.py [--years 100] [--repeat 3]
    PYTHONPATH=src python benchmarks/bench_de440_ladder.py --pole-of-date

With ``--pole-of-date``: the ``tides`` and top rungs with ``zonal`` and
``earth_tides`` about the Earth's pole fixed at J2000's and as they are, about its
pole of date (``pole = "IAU2006"``, the IAU 2006 precession), their residuals side
by side (``benchmarks/results/de440_ladder_pole_of_date.md``).

Every rung (:data:`hamilton_orbits.studies.ladder.RUNGS`) starts from DE440's own state at
J2000 (ICRF), integrates with ``radau15`` for 100 years and compares heliocentric
positions (the Moon: geocentric) with DE440's, every Julian year.  Prints the table
of residuals after 10, 50 and 100 years (km, and arcsec as seen from the Sun; the
Moon from the Earth) and the wall time (median of ``--repeat`` runs, the compile
of each right-hand side excluded), and writes ``benchmarks/results/de440_ladder.md``
and ``de440_ladder.png`` (residual against time, one line per rung, one panel per
body, km, log scale).  Nothing is fitted: see ``docs/de440_ladder.md``.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from hamilton_orbits.studies import ladder  # noqa: E402

RESULTS = ROOT / "benchmarks" / "results"
GOALS_KM = {"mercury": 1, "venus": 1, "earth-moon-barycenter": 3, "mars": 3, "jupiter": 5,
            "saturn": 20, "uranus": 20, "neptune": 100, "moon": 20}
SHORT = {"earth-moon-barycenter": "EMB"}


def run(years: int, repeat: int) -> list[ladder.RungResult]:
    """Every rung ``repeat`` times, the repeats interleaved (all rungs, then all
    again) so that a change of load on the shared machine falls on every rung."""
    runs: dict[str, list[ladder.RungResult]] = {r.name: [] for r in ladder.RUNGS}
    for k in range(repeat):
        for rung in ladder.RUNGS:
            res = ladder.run_rung(rung, years)
            runs[rung.name].append(res)
            print(f"  [{k + 1}/{repeat}] {rung.name:10s} {res.wall_time:6.2f} s  "
                  f"{res.steps} steps", flush=True)
    out = []
    for rung in ladder.RUNGS:
        first = runs[rung.name][0]
        walls = sorted(r.wall_time for r in runs[rung.name])
        out.append(ladder.RungResult(first.rung, first.years, first.names, first.km,
                                     first.arcsec, walls[len(walls) // 2], first.steps))
    return out


def table(results: list[ladder.RungResult], years: int) -> str:
    names = results[0].names
    marks = [y for y in (10, 50, 100) if y <= years]
    head = "| rung | yr | " + " | ".join(SHORT.get(n, n.capitalize()) for n in names)
    lines = [head + " | wall s | x Newton |",
             "|" + "---|" * (len(names) + 4)]
    newton = results[0].wall_time
    for res in results:
        for y in marks:
            cells = " | ".join(f"{res.km[y, k]:.3g} km / {res.arcsec[y, k]:.2g}\""
                               for k in range(len(names)))
            wall = f"{res.wall_time:.2f} | {res.wall_time / newton:.1f}" if y == marks[-1] \
                else " | "
            lines.append(f"| {res.rung.name} | {y} | {cells} | {wall} |")
    return "\n".join(lines)


def goals(results: list[ladder.RungResult], years: int) -> str:
    top = results[-1]
    rows = ["| body | goal (km) | top rung (km) | best rung (km) | met |", "|---|---|---|---|---|"]
    for name, goal in GOALS_KM.items():
        k = top.names.index(name)
        best = min(results, key=lambda r: r.km[years, k])
        value = top.km[years, k]
        rows.append(f"| {SHORT.get(name, name)} | {goal} | {value:.3g} | "
                    f"{best.km[years, k]:.3g} ({best.rung.name}) | "
                    f"{'yes' if value <= goal else 'no'} |")
    ratio = top.wall_time / results[0].wall_time
    rows.append(f"| wall time | 3x Newton | {ratio:.1f}x | | {'yes' if ratio <= 3 else 'no'} |")
    return "\n".join(rows)


def plot(results: list[ladder.RungResult], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = results[0].names
    fig, axes = plt.subplots(3, 4, figsize=(16, 10), sharex=True)
    for k, name in enumerate(names):
        ax = axes.flat[k]
        for res in results:
            ax.semilogy(res.years[1:], np.maximum(res.km[1:, k], 1e-3), label=res.rung.name)
        if name in GOALS_KM:
            ax.axhline(GOALS_KM[name], color="k", ls=":", lw=1)
        frame = "geocentric" if name == "moon" else "heliocentric"
        ax.set_title(f"{SHORT.get(name, name)} ({frame})")
        ax.set_ylabel("|r - r_DE440| (km, ICRF)")
        ax.grid(True, which="both", alpha=0.3)
    axes.flat[-1].axis("off")
    handles, labels = axes.flat[0].get_legend_handles_labels()
    axes.flat[-1].legend(handles, labels, loc="center", title="rung (dotted: goal)")
    for ax in axes[-1]:
        ax.set_xlabel("years from J2000 (TDB)")
    fig.suptitle("Residual against JPL DE440 from DE440's J2000 state, radau15")
    fig.tight_layout()
    fig.savefig(path, dpi=90)


def fixed_pole(rung: ladder.Rung) -> ladder.Rung:
    """``rung`` with the Earth's figure and tides about its pole of J2000 (fixed)."""
    effects = tuple(e["name"] if isinstance(e, dict) and e.get("pole") == "IAU2006" else e
                    for e in rung.effects)
    return ladder.Rung(f"{rung.name}, J2000's pole", rung.asteroids, effects)


def pole_of_date(years: int) -> str:
    """The tides and top rungs with the Earth's pole fixed and of date: residuals
    (km) at 10, 50 and ``years`` years and the largest at any whole year."""
    marks = [y for y in (10, 50, years) if y <= years]
    rows = ["| rung | " + " | ".join(f"{y} yr" for y in marks) + " | largest (year) |",
            "|---|" + "---|" * (len(marks) + 1)]
    out = {}
    for base in (ladder.RUNGS[6], ladder.RUNGS[-1]):
        for rung in (fixed_pole(base), base):
            res = ladder.run_rung(rung, years)
            out[rung.name] = res
            print(f"  {rung.name:28s} {res.wall_time:6.2f} s", flush=True)
    for name in BODIES_SHOWN:
        rows.append(f"| **{SHORT.get(name, name)}** |" + " |" * (len(marks) + 1))
        for rung_name, res in out.items():
            k = res.names.index(name)
            worst = int(np.argmax(res.km[:, k]))
            rows.append(f"| {rung_name} | " + " | ".join(f"{res.km[y, k]:.3g}" for y in marks)
                        + f" | {res.km[worst, k]:.3g} ({worst}) |")
    return "\n".join(rows)


BODIES_SHOWN = ("moon", "earth-moon-barycenter", "mercury", "venus", "mars")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--years", type=int, default=100)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--pole-of-date", action="store_true",
                        help="the tides and top rungs, the Earth's pole fixed and of date")
    args = parser.parse_args(argv)
    if args.pole_of_date:
        text = pole_of_date(args.years)
        print(text)
        stamp = datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")
        RESULTS.mkdir(parents=True, exist_ok=True)
        (RESULTS / "de440_ladder_pole_of_date.md").write_text(
            f"# DE440 ladder: the Earth's pole fixed and of date ({stamp})\n\n"
            f"`PYTHONPATH=src python benchmarks/bench_de440_ladder.py --pole-of-date --years "
            f"{args.years}`.  Residuals against DE440, km (heliocentric; the Moon "
            "geocentric), from DE440's J2000 state; `zonal` and `earth_tides` about J2000's "
            "pole, or about the IAU 2006 pole of each time.\n\n" + text + "\n")
        return 0
    print(f"DE440 ladder: {args.years} years, {args.repeat} timed run(s) per rung")
    results = run(args.years, args.repeat)
    text = table(results, args.years)
    summary = goals(results, args.years)
    print(text)
    print(summary)
    RESULTS.mkdir(parents=True, exist_ok=True)
    stamp = datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")
    md = (
        f"# DE440 ladder ({stamp})\n\n"
        f"`PYTHONPATH=src python benchmarks/bench_de440_ladder.py --years {args.years} "
        f"--repeat {args.repeat}` on {platform.machine()}, {os.cpu_count()} shared cores "
        "(other jobs running: wall times are medians, compile excluded).\n\n"
        "Residual of the simulated position against DE440's, heliocentric (the Moon: "
        "geocentric), ICRF, km and arcsec as seen from the Sun (the Moon: from the "
        "Earth); EMB is the barycentre of the simulated Earth and Moon.  Start: DE440's "
        "barycentric state at J2000 (TDB); integrator radau15 (PRS23 step control). "
        "See docs/de440_ladder.md for what each rung adds and why some bodies move "
        "away.\n\n" + text + "\n\n## Goals (after 100 years)\n\n" + summary + "\n\n"
        "![residuals](de440_ladder.png)\n"
    )
    (RESULTS / "de440_ladder.md").write_text(md)
    plot(results, RESULTS / "de440_ladder.png")
    print(f"wrote {RESULTS / 'de440_ladder.md'} and de440_ladder.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
