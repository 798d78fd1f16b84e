"""The work-precision report's figures: error against wall time on log-log axes,
one diagram per problem (:func:`problem_figure`) and all problems in one
(:func:`summary_figure`, the diagram the README shows).
"""

from __future__ import annotations

import textwrap
from pathlib import Path
from typing import Any

from hamilton_orbits.studies.rows import Row

__all__ = ["problem_figure", "summary_figure"]


def problem_figure(rows: list[Row], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 6.5))
    _draw(ax, rows)
    fig.tight_layout()
    fig.savefig(path, dpi=100, bbox_inches="tight")
    plt.close(fig)


def summary_figure(rows: list[Row], path: Path, title: str) -> None:
    """All problems of the report in one figure (the diagram the README shows)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    problems = list(dict.fromkeys(r.problem for r in rows))
    ncol = 2
    nrow = (len(problems) + ncol - 1) // ncol
    fig, axes = plt.subplots(nrow, ncol, figsize=(12, 6.4 * nrow), squeeze=False)
    for ax, problem in zip(axes.ravel()[: len(problems)], problems, strict=True):
        _draw(ax, [r for r in rows if r.problem == problem])
    for ax in axes.ravel()[len(problems):]:
        ax.set_visible(False)
    fig.tight_layout(rect=(0.0, 0.0, 1.0, 0.98))  # the title's row kept free
    fig.suptitle(f"What accuracy costs in time: error against wall time ({title})", y=0.995)
    fig.savefig(path, dpi=90, bbox_inches="tight")
    plt.close(fig)


def _draw(ax: Any, rows: list[Row]) -> None:
    groups: dict[tuple[str, str], list[Row]] = {}
    for r in rows:
        if r.error > 0:  # the reference itself (error 0) has no place on a log axis
            groups.setdefault((r.code, r.method), []).append(r)
    import matplotlib

    colours = matplotlib.colormaps["tab20"].colors  # 20 distinct: a problem has up to ~12 lines
    for k, ((code, method), rs) in enumerate(groups.items()):
        rs = sorted(rs, key=lambda r: r.wall_time)
        ours = code.split(" ")[0] == "hamilton-orbits"  # ("hamilton-orbits radau15" too)
        ax.loglog([r.wall_time for r in rs], [r.error for r in rs], "-o" if ours else "--s",
                  color=colours[(2 * k) % 20 if k < 10 else (2 * k + 1) % 20],
                  label=f"{method} ({code})")
    first = next((r for r in rows if r.error > 0), rows[0])  # not the reference's own row
    ax.set_xlabel("wall time (s)")
    # a long measure (the DE440 rung's) wrapped, not run into the legend below
    ax.set_ylabel("\n".join(textwrap.wrap(first.error_measure, 50)))
    ax.set_title(f"{first.problem}: error vs wall time\nreference: {first.reference}",
                 fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    for axis in (ax.xaxis, ax.yaxis):
        _minor_labels(axis)
    # below the axes: inside, a dozen entries hid the points they name
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2,
              frameon=False)


def _minor_labels(axis: Any) -> None:
    """Minor tick labels where the axis's view holds fewer than two powers of ten (one
    label, or none, on a log axis spanning about a decade): at 2 and 5 times a power
    of ten, at every minor tick over less than half a decade; none otherwise (every
    minor label overlapped on long spans)."""
    import math

    from matplotlib.ticker import FuncFormatter, NullFormatter

    lo, hi = sorted(axis.get_view_interval())
    if lo <= 0 or math.floor(math.log10(hi)) - math.ceil(math.log10(lo)) + 1 >= 2:
        axis.set_minor_formatter(NullFormatter())
        return

    def label(x: float, _pos: Any = None) -> str:
        e = math.floor(math.log10(x) + 1e-9)
        m = round(x / 10.0**e)
        return rf"$\mathdefault{{{m}\times10^{{{e}}}}}$" if m in shown else ""

    shown = range(1, 10) if math.log10(hi / lo) < 0.5 else (2, 5)

    axis.set_minor_formatter(FuncFormatter(label))
