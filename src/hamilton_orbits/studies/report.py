"""The work-precision report: what accuracy costs in time, ours beside the peers.

:func:`build_report` runs four problems in one process, sweeps each method's step
or tolerance, measures the error against a stated reference and the wall time,
and writes one log-log diagram (error against wall time) per problem, a
Markdown table (``report.md``) and one self-contained HTML page (``report.html``,
figures embedded as base64 data URIs).

Problems
--------
1. Two-body Kepler propagation (mu = 1, a = 2, e = 0.5, output at many epochs
   over 10 periods): ours (``KeplerOrbit.propagate``, one batch call), rebound
   WHFast (one test particle: the Kepler drift only) over dt, scipy DOP853 over
   rtol.  Reference: Kepler's equation solved in mpmath at 40 digits.
2. The solar system (Sun + 8 planets, ``System.solar_system("J2000")``), 10 years
   (quick) or 1000 years: ours (radau15; wh in democratic-heliocentric and in
   Jacobi coordinates, the latter also with the correctors of order 3, 11, 17;
   leapfrog; dop853) and rebound
   (IAS15, WHFast in its default Jacobi coordinates, also with the correctors
   of order 11 and 17, and in the democratic-heliocentric coordinates our
   ``wh`` uses, leapfrog) and, where it
   is installed, heyoka's adaptive Taylor integrator.  Reference: our radau15
   in double-double arithmetic at 1-day steps (:mod:`hamilton_orbits.studies.reference`,
   computed once and cached), whose own uncertainty, its distance from the same
   at 2-day steps in the same measure, is stated with it (a double-precision
   reference, IAS15 at ``epsilon = 0``, cannot resolve errors below ~4e-11
   after 1000 years: two step sizes differ by that much).  Error: max over
   planets of the final heliocentric position difference over the heliocentric
   distance.
3. Fidelity against DE440 (:mod:`hamilton_orbits.studies.ladder`): each rung of the
   physics ladder from DE440's J2000 state for 10 years (quick) or 100 years;
   error: the largest planetary residual against DE440 as an angle seen from
   the Sun (and the Moon's, seen from the Earth); see ``docs/de440_ladder.md``.
4. Free rigid body (the bundled ``dzhanibekov`` scene: moments 1, 2, 3, spin
   about the intermediate axis), 20 s (quick) or 60 s, output every 0.01 s:
   splitting2, splitting4, exact_kick, rk4 over dt as an :class:`Ensemble` of
   the scene (``vary={"integrator.method": ..., "integrator.dt": ...}``, run one
   member at a time); scipy DOP853 (``rigid.integrate(method="dop853")``) over
   rtol directly.  Reference: ``rigid.free_motion`` (exact, Jacobi elliptic
   functions).  Error: max attitude geodesic angle (rad).
5. Rigid-Earth pole wander (``rigid.earth.rigid_body(0.2 arcsec)``), 10 years
   (quick) or 100 years, daily output: splitting4 over dt, scipy DOP853 (via
   ``rigid.integrate(method="dop853")``) over rtol.  Reference: the exact free
   motion.  Error: max pole offset difference (µas, micro-arcseconds).

Wall times are the shortest of a few repeats (one run if it exceeds 2 s); the
kernels are compiled before timing.

Problems 1-3 are in :mod:`hamilton_orbits.studies.problems`, 4 and 5 come from
``rigid`` through the entry point group ``hamilton_orbits.report_problems`` (a
callable returning ``(slug, problem)`` pairs, each problem a function
``(quick, progress) -> list[Row]`` built with :class:`Row`, :func:`timed` and
:func:`log`, re-exported here from :mod:`hamilton_orbits.studies.rows`); the
figures are drawn by :mod:`hamilton_orbits.studies.figures`.
"""

from __future__ import annotations

import base64
import html
import json
import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from hamilton_orbits.studies.figures import problem_figure, summary_figure
from hamilton_orbits.studies.problems import (
    SETTINGS,
    de440_problem,
    kepler_problem,
    solar_system_problem,
)
from hamilton_orbits.studies.rows import Row, fmt_time, log, timed

__all__ = ["SETTINGS", "Row", "build_report", "fmt_time", "log", "timed"]


def _table(rows: list[Row]) -> list[list[str]]:
    out = []
    for r in rows:
        # one notation per column: 9.945e-06 beside 1.908e+00, not beside 0.000176
        out.append([r.problem, r.code, r.method, r.parameter, f"{r.error:.3e}",
                    r.error_measure, r.reference, f"{r.wall_time:.3e}"])
    return out


_HEADER = ["problem", "code", "method", "parameter", "error", "error measure", "reference",
           "wall time (s)"]


def _registered_problems() -> list[tuple[str, Callable[[bool, bool], list[Row]]]]:
    """Problems other packages add (``rigid``: the free body and the pole wander)
    through the entry point group ``hamilton_orbits.report_problems``, so that
    ``hamilton_orbits`` never imports them."""
    from importlib.metadata import entry_points

    out: list[tuple[str, Callable[[bool, bool], list[Row]]]] = []
    for ep in sorted(entry_points(group="hamilton_orbits.report_problems"),
                     key=lambda e: e.name):
        out.extend(ep.load()())
    return out


def build_report(out_dir: Any, quick: bool = False, progress: bool = True) -> list[Path]:
    """Run the work-precision study and write PNGs, ``report.md`` and ``report.html``.

    Parameters
    ----------
    out_dir : str or path-like
        Directory for the outputs (created if missing).
    quick : bool, optional
        Short spans and few settings (well under two minutes on 2 cores).
    progress : bool, optional
        Print a line per finished problem / setting.

    Returns
    -------
    list of Path
        The files written: one PNG per problem, ``work_precision.png`` (all
        problems in one figure), ``report.md``, ``report.json`` (the rows and
        the date, mode and core count) and ``report.html``.

    Raises
    ------
    ImportError
        Without matplotlib, mpmath or pandas (the ``[report]`` extra).

    Examples
    --------
    >>> from hamilton_orbits.studies.report import build_report
    >>> callable(build_report)
    True
    """
    try:
        import matplotlib  # noqa: F401
        import mpmath  # noqa: F401
        import pandas  # noqa: F401
    except ImportError as exc:
        raise ImportError(
            f"The report needs {exc.name}: pip install 'hamilton-orbits[report]'"
        ) from exc
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    problems = [("kepler", kepler_problem), ("solar_system", solar_system_problem),
                ("de440", de440_problem), *_registered_problems()]
    all_rows: list[Row] = []
    files: list[Path] = []
    figures: list[tuple[str, Path]] = []
    t_start = time.perf_counter()
    for slug, fn in problems:
        log(progress, f"problem {slug} ...")
        rows = fn(quick, progress)
        all_rows.extend(rows)
        png = out / f"{slug}.png"
        problem_figure(rows, png)
        files.append(png)
        figures.append((rows[0].problem, png))
    total = time.perf_counter() - t_start
    stamp = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    cores = os.cpu_count()
    mode = "quick" if quick else "full"
    intro = (f"Work-precision report ({mode}), {stamp}, {cores} cores, "
             f"total {total:.1f} s. Wall time: shortest of up to 3 runs, same process.")
    table = _table(all_rows)
    summary_png = out / "work_precision.png"
    summary_figure(all_rows, summary_png, f"{mode} report, {stamp}, {cores} cores")
    figures.insert(0, ("All problems", summary_png))

    md = ["# What accuracy costs in time", "", intro, "", "How each code is set:", "",
          *[f"- {line}" for line in SETTINGS], "",
          "| " + " | ".join(_HEADER) + " |", "|" + "---|" * len(_HEADER)]
    md += ["| " + " | ".join(c.replace("|", "\\|") for c in row) + " |" for row in table]
    md.append("")
    for title, png in figures:
        md += [f"![{title}]({png.name})", ""]
    md_path = out / "report.md"
    md_path.write_text("\n".join(md), encoding="utf-8")
    meta = {"mode": mode, "date": stamp, "cores": cores, "total_seconds": total}
    json_path = out / "report.json"
    json_path.write_text(json.dumps({"meta": meta, "rows": [vars(r) for r in all_rows]},
                                    indent=1), encoding="utf-8")

    h = ["<!DOCTYPE html>", "<html><head><meta charset=\"utf-8\">",
         "<title>hamilton-orbits work-precision report</title>",
         "<style>body{font-family:sans-serif;margin:2em}table{border-collapse:collapse}"
         "td,th{border:1px solid #aaa;padding:2px 6px;font-size:12px}</style>",
         "</head><body>", "<h1>What accuracy costs in time</h1>",
         f"<p>{html.escape(intro)}</p>", "<p>How each code is set:</p><ul>",
         *[f"<li>{html.escape(line)}</li>" for line in SETTINGS], "</ul>", "<table>",
         "<tr>" + "".join(f"<th>{html.escape(c)}</th>" for c in _HEADER) + "</tr>"]
    h += ["<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in row) + "</tr>" for row in table]
    h.append("</table>")
    for title, png in figures:
        data = base64.b64encode(png.read_bytes()).decode("ascii")
        h += [f"<h2>{html.escape(title)}</h2>",
              f"<img alt=\"{html.escape(title)}\" src=\"data:image/png;base64,{data}\">"]
    h.append("</body></html>")
    html_path = out / "report.html"
    html_path.write_text("\n".join(h), encoding="utf-8")
    files += [summary_png, md_path, json_path, html_path]
    log(progress, f"wrote {out} in {total:.1f} s")
    return files
