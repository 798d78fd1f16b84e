"""The ``pole_prediction`` scene kind: where will the pole be next year?

Registered beside ``polar_motion`` by :func:`rigid.earth.scene_polar_motion.register`.
The prediction methods of :mod:`rigid.earth.prediction` are run from one start date (the
prediction fan, against the record that followed) and hindcast from weekly start dates
over one or more periods, scored like the EOP prediction comparison campaigns (mean
absolute error per horizon, and how often the outcome falls inside the method's own
1-sigma band), beside the published C04-only results of Lei et al. 2023.  Keys
(``docs/scenes.md``)::

    kind = "pole_prediction"
    start = "2019-01-01"          # the fan's start date (0h UTC)
    horizon = "365 d"
    methods = ["persistence", "ls", "ls+ar", "ls+var", "liouville"]
    periods = ["2005-10-01..2008-03-01", "2016-01-01..2024-01-01"]   # weekly starts
    latency = "1 d"

Nothing downloads: the IERS 20 C04 record ships with astropy-iers-data.
"""

from __future__ import annotations

import datetime
import time
import warnings
from dataclasses import dataclass
from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits import schema as S
from hamilton_orbits.scene import Result, Scene, SceneKind, register_kind
from hamilton_orbits.units import TIME

#: Lei et al. 2023 (Artificial Satellites 58, 42), table of mean absolute errors (mas),
#: predictions from the C04 series; horizons 10, 30, 150, 270, 365 d
PUBLISHED_HORIZONS = (10, 30, 150, 270, 365)
PUBLISHED = {
    "LS+AR (Lei et al. 2023)": ((2.93, 7.71, 21.83, 24.57, 30.86),
                                (1.94, 5.43, 21.90, 24.04, 27.90)),
    "WLS+VAR (Lei et al. 2023)": ((2.87, 7.03, 13.97, 18.47, 20.52),
                                  (1.81, 4.41, 15.41, 21.17, 21.82)),
}
TABLE_HORIZONS = (10, 30, 90, 150, 270, 365)
_METHODS = ("persistence", "ls", "ls+ar", "ls+var", "liouville")

@dataclass
class _Date(S.String):
    """A date: a string, or a TOML date (``start = 2019-01-01``, ``--set start=2019-01-01``)."""

    def check(self, value: Any, path: str, problems: S.Problems) -> Any:
        if isinstance(value, datetime.date) and not isinstance(value, datetime.datetime):
            value = value.isoformat()
        return super().check(value, path, problems)


SCHEMA: dict[str, S.Field] = {
    "start": _Date(default="2019-01-01"),
    "horizon": S.Quantity(kind=TIME, default="365 d", positive=True),
    "methods": S.Array(item=S.Choice(choices=_METHODS), default=list(_METHODS)),
    "periods": S.Array(item=S.String(), default=["2005-10-01..2008-03-01",
                                                 "2016-01-01..2024-01-01"]),
    "latency": S.Quantity(kind=TIME, default="1 d", positive=True),
}


def _check(spec: dict, problems: S.Problems) -> None:
    from erfa import ErfaWarning

    for i, eff in enumerate(spec.get("effects", ())):  # (accepted, then never read)
        problems.add(f"effects[{i}]", f"a pole prediction takes no effects: its methods "
                                      f"are its `methods` (got {eff['name']!r})")
    with warnings.catch_warnings():  # a date past the leap-second table: "dubious year"
        warnings.simplefilter("ignore", ErfaWarning)
        _check_keys(spec, problems)
        if not problems:
            _check_against_the_record(spec, problems)


def _check_keys(spec: dict, problems: S.Problems) -> None:
    from astropy.time import Time

    for i, text in enumerate(spec["periods"]):
        parts = text.split("..") if isinstance(text, str) else []
        try:
            first, last = (Time(p.strip(), scale="utc") for p in parts)
            ok = len(parts) == 2 and last > first
        except ValueError:
            ok = False
        if not ok:
            problems.add(f"periods[{i}]", f'expected "YYYY-MM-DD..YYYY-MM-DD", the first '
                                          f'date before the second, got {text!r}')
    try:
        Time(spec["start"], scale="utc")
    except ValueError:
        problems.add("start", f'expected a date "YYYY-MM-DD", got {spec["start"]!r}')
    if not spec["methods"]:
        problems.add("methods", f"expected at least one of {', '.join(_METHODS)}")
    for key in ("horizon", "latency"):
        days = float(spec[key].to_value(u.day))
        if days != round(days):
            problems.add(key, f"expected whole days, got {spec[key]}")


def _check_against_the_record(spec: dict, problems: S.Problems) -> None:
    """The start and the periods within the record (with each method's history before
    them), the horizon within each method's reach: what the run would refuse."""
    from astropy.time import Time

    from rigid.earth.c04 import load_c04
    from rigid.earth.prediction import check_inputs, weekly_starts

    record = load_c04()
    horizon = [spec["horizon"].to_value(u.day)] * u.day
    trials = [("start", Time([spec["start"]], scale="utc"))]
    for i, text in enumerate(spec["periods"]):
        trials.append((f"periods[{i}]", weekly_starts(*(p.strip() for p in text.split("..")))))
    said = set()
    for method in spec["methods"]:
        for key, starts in trials:
            try:
                check_inputs(record, starts, horizon, method, latency=spec["latency"])
            except ValueError as exc:
                starts_text = ("expected the start date" if key == "start"
                               else "expected the weekly start dates")
                text = (str(exc).replace("horizons", "horizon")
                        .replace("Expected `starts`", starts_text))
                where = "horizon" if "`horizon`" in text else (
                    "latency" if "`latency`" in text else key)
                if (where, method) not in said:
                    said.add((where, method))
                    problems.add(where, f"method {method!r}: {text[0].lower()}{text[1:]}")


def _run(scene: Scene, progress: bool = True, stop=lambda: False) -> Result:
    from astropy.time import Time

    from rigid.earth.c04 import load_c04
    from rigid.earth.prediction import hindcast, predict, weekly_starts

    spec = scene.spec
    begin = time.perf_counter()
    record = load_c04()
    start = Time(spec["start"], scale="utc")
    horizon = spec["horizon"].to(u.day)
    fans = {m: predict(record, at=start, horizon=horizon, method=m, latency=spec["latency"])
            for m in spec["methods"]}
    dense = np.arange(0, int(horizon.to_value(u.day)) + 1) * u.day
    scores: dict[str, dict[str, Any]] = {}
    for text in spec["periods"]:
        first, last = (p.strip() for p in text.split(".."))
        starts = weekly_starts(first, last)
        scores[text] = {m: hindcast(record, starts, dense, m, latency=spec["latency"])
                        for m in spec["methods"]}
        if stop():
            break
    wall = time.perf_counter() - begin
    result = Result(scene=scene, times=dense, wall_time=wall,
                    complete=len(scores) == len(spec["periods"]),  # (stopped: the periods
                    # hindcast kept, the run said incomplete)
                    time_origin="each prediction's start: the time is its horizon")
    for i, by_method in enumerate(scores.values()):  # the MAE curves, saved to states.nc
        for method, score in by_method.items():
            key = method.replace("+", "_")
            result.diagnostics[f"mae_x_{key}_period{i + 1}"] = score.table["mae_x"]
            result.diagnostics[f"mae_y_{key}_period{i + 1}"] = score.table["mae_y"]
    result.metrics["fan start date (newest datum)"] = (
        f"{start.iso[:10]} ({next(iter(fans.values())).newest_datum.iso[:10]})")
    result.metrics["latency"] = spec["latency"].to(u.day)
    for text, by_method in scores.items():
        n = len(next(iter(by_method.values())).starts)
        hind = sum(s.wall_time for s in by_method.values())
        result.metrics[f"hindcast {text}"] = f"{n} weekly starts, {hind:.1f} s for all methods"
    _tables(result, scores)
    result.plotters.append(lambda r: _plot_fan(r, record, fans, start))
    if scores:  # (no period scored, periods = []: the fan alone, no empty grid of figures)
        result.plotters.extend([lambda r: _plot_mae(r, scores),
                                lambda r: _plot_coverage(r, scores)])
    return result


def _tables(result: Result, scores: dict) -> None:
    """MAE (x, y) and coverage per method and horizon, the published rows beside them."""
    cols = [h for h in TABLE_HORIZONS if h < len(result.times)]
    for text, by_method in scores.items():
        rows = []
        for method, score in by_method.items():
            t = score.table
            row: dict[str, Any] = {"method": method}
            for h in cols:
                row[f"x {h} d"] = float(t["mae_x"][h].to_value(u.mas))
            for h in cols:
                row[f"y {h} d"] = float(t["mae_y"][h].to_value(u.mas))
            rows.append(row)
        if text.startswith("2005-10-01"):
            for name, (px, py) in PUBLISHED.items():
                row = {"method": name}
                for h in cols:
                    k = PUBLISHED_HORIZONS.index(h) if h in PUBLISHED_HORIZONS else None
                    row[f"x {h} d"] = px[k] if k is not None else "-"
                for h in cols:
                    k = PUBLISHED_HORIZONS.index(h) if h in PUBLISHED_HORIZONS else None
                    row[f"y {h} d"] = py[k] if k is not None else "-"
                rows.append(row)
        result.tables[f"MAE (mas), weekly starts {text}"] = rows
        result.tables[f"1-sigma coverage (x, y), weekly starts {text}"] = [
            {"method": method, **{f"{h} d": "{:.2f}, {:.2f}".format(
                float(s.table["coverage_x"][h]), float(s.table["coverage_y"][h]))
                for h in cols}} for method, s in by_method.items()]


_COLOURS = {"persistence": "0.5", "ls": "tab:orange", "ls+ar": "tab:green",
            "ls+var": "tab:purple", "liouville": "tab:blue"}


def _plot_fan(result: Result, record: Any, fans: dict, start: Any):
    """The predictions from the start date, with their 1-sigma bands, over the record."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 1, figsize=(10, 8), sharex=True)
    days = record.time.utc.mjd - start.utc.mjd
    span = (days >= -365) & (days <= len(result.times) + 30)
    for ax, coord in zip(axes, ("x", "y"), strict=True):
        ax.plot(days[span], getattr(record, coord)[span].to_value(u.mas), "k", lw=1.2,
                label="IERS 20 C04 (observed)")
        for method, pred in fans.items():
            d = pred.t.utc.mjd - start.utc.mjd
            mid = getattr(pred, coord).to_value(u.mas)
            sig = getattr(pred, f"sigma_{coord}").to_value(u.mas)
            ax.plot(d, mid, color=_COLOURS[method], lw=1.2, label=method)
            if method in ("liouville", "ls+ar"):
                ax.fill_between(d, mid - sig, mid + sig, color=_COLOURS[method], alpha=0.15,
                                lw=0, label=f"{method} 1-sigma")
        ax.axvline(0, color="k", ls=":", lw=0.8)
        ax.set_ylabel(f"{coord}_p (mas; CIP in the ITRS, IERS convention)")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8, ncol=3, loc="best")
    axes[1].set_xlabel(f"time from the start {start.utc.iso[:16]} UTC (days of UTC, as the IERS "
                       "C04 record's MJD; data before it only) [d]")
    axes[0].set_title(f"{result.scene.name}: the prediction fan from {start.iso[:10]} "
                      "against the record that followed")
    fig.tight_layout()
    fig.set_label("prediction_fan")  # the file name Result.save gives it
    return fig


def _plot_mae(result: Result, scores: dict):
    """MAE against horizon for every method and period, the published rows as markers."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(len(scores), 2, figsize=(12, 4.2 * len(scores)), squeeze=False)
    for row, (text, by_method) in enumerate(scores.items()):
        for col, coord in enumerate(("x", "y")):
            ax = axes[row, col]
            top = 0.0
            for method, score in by_method.items():
                t = score.table
                mae = t[f"mae_{coord}"].to_value(u.mas)
                label = method
                if method == "persistence" and len(by_method) > 1:
                    label += " (beyond the top where it is off the axis)"  # (not everywhere:
                    # in 2016-2024 it comes back into view)
                else:
                    top = max(top, float(np.nanmax(mae)))
                ax.plot(t["horizon"].to_value(u.day), mae, color=_COLOURS[method], lw=1.4,
                        label=label)
            if text.startswith("2005-10-01"):
                for (name, values), marker in zip(PUBLISHED.items(), ("s", "D"), strict=True):
                    ax.plot(PUBLISHED_HORIZONS, values[col], marker, color="k", ms=6,
                            mfc="none" if marker == "s" else "k", label=name)
                    top = max(top, max(values[col]))
            n = len(next(iter(by_method.values())).starts)
            ax.set_title(f"{coord}_p: weekly starts {text} ({n} start dates)")
            ax.set_xlabel("horizon, time after the start date [d]")
            ax.set_ylabel(f"mean absolute error of {coord}_p (mas)")
            ax.set_ylim(0, 1.15 * top if top > 0 else None)
            ax.grid(alpha=0.3)
    found = {}  # one legend under the panels, off the data (each method once)
    for ax in axes.flat:
        for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
            found.setdefault(label, handle)
    fig.legend(list(found.values()), list(found), fontsize=8, loc="lower center", ncol=4)
    fig.suptitle(f"{result.scene.name}: hindcast error against horizon (IERS 20 C04)")
    fig.tight_layout(rect=(0, 0.06, 1, 1))
    fig.set_label("mae_vs_horizon")  # the file name Result.save gives it
    return fig


def _plot_coverage(result: Result, scores: dict):
    """Fraction of outcomes within each method's own 1-sigma band."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(scores), figsize=(6 * len(scores), 5.2), squeeze=False)
    for ax, (text, by_method) in zip(axes[0], scores.items(), strict=True):
        for method, score in by_method.items():
            t = score.table
            h = t["horizon"].to_value(u.day)
            cover = 0.5 * (np.asarray(t["coverage_x"]) + np.asarray(t["coverage_y"]))
            ax.plot(h, cover, color=_COLOURS[method], lw=1.4, label=method)
        ax.axhline(0.683, color="k", ls="--", lw=1, label="68.3% (Gaussian 1-sigma)")
        ax.axhspan(0.60, 0.75, color="k", alpha=0.06, label="60-75% target")
        ax.set_ylim(0, 1)
        ax.set_xlabel("horizon, time after the start date [d]")
        ax.set_ylabel("fraction of outcomes within 1-sigma (mean of x_p, y_p)")
        ax.set_title(f"band coverage, weekly starts {text}")
        ax.grid(alpha=0.3)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, fontsize=8, loc="lower center", ncol=4)
    fig.tight_layout(rect=(0, 0.12, 1, 1))
    fig.set_label("coverage")  # the file name Result.save gives it
    return fig


KIND = SceneKind(
    name="pole_prediction",
    summary="polar-motion prediction methods and their hindcasts against the IERS record",
    schema=SCHEMA,
    effect_kind="rotation",
    check=_check,
    run=_run,
    takes_effects=False,  # (_check refuses any)
)


def register() -> None:
    """Register the ``pole_prediction`` scene kind."""
    register_kind(KIND)
