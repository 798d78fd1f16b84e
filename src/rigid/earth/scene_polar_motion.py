"""The ``polar_motion`` scene kind: the Liouville pole against the IERS C04 record.

Registered by :func:`rigid.scene.register` (entry point
``hamilton_orbits.scene_kinds``).  The observed pole (IERS 20 C04, shipped with
astropy-iers-data, read offline) is fitted with a trend, the Chandler and the
annual terms (:func:`rigid.earth.wobble_fit.fit_wobble`); the linearised Liouville
equation with exactly the listed ``"rotation"`` effects
(:class:`rigid.earth.liouville.LiouvillePole`) is started from the first observed
pole and run against the record.  Keys (``docs/scenes.md``)::

    kind = "polar_motion"
    start = 1962          # decimal years (optional, default: the whole record)
    end = 2026
    effects = ["elastic", { name = "damping", Q = 179 }, "annual_excitation"]

Parameters of the effects that the scene does not give come from the fit:
``chandler_period`` for ``"elastic"`` (unless ``k2`` is given) and the annual
excitation that produces the fitted annual terms, ``chi = m (sigma_c - w) /
sigma_c`` with the model's own ``sigma_c`` (from ``k2``, the period given or
fitted, or Euler's without ``"elastic"``), for ``"annual_excitation"``.
"""

from __future__ import annotations

import textwrap
import time
from types import SimpleNamespace
from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits import schema as S
from hamilton_orbits.scene import Result, Scene, SceneKind, format_table, register_kind

SCHEMA: dict[str, S.Field] = {
    "start": S.Number(minimum=1962),
    "end": S.Number(minimum=1962),
}


def _check(spec: dict, problems: S.Problems) -> None:
    from rigid.earth.c04 import load_c04

    start, end = spec["start"], spec["end"]
    if start is not None and end is not None and not end - start >= 6:
        problems.add("end", f"expected at least 6 years after start = {start}, got {end}"
                     " (the Chandler and annual terms beat over 6.4 years)")
    record = load_c04()
    for key, value in (("start", start), ("end", end)):
        if value is not None:
            try:  # the record's own check: a window beyond it is refused, not cut short
                record.select(**{key: value})
            except ValueError as exc:
                msg = str(exc)
                problems.add(key, "e" + msg[1:] if msg.startswith("Expected") else msg)
    names = [e["name"] for e in spec["effects"]]
    if "damping" in names:
        damping = spec["effects"][names.index("damping")]
        if "Q" not in damping:
            problems.add(f"effects[{names.index('damping')}].Q",
                         "missing: the effect 'damping' needs a quality factor Q")
    if not problems:  # (the model built as the run builds it, on a fit's stand-in:
        try:  # what it would refuse fails loading, not the run)
            _model(spec, _STAND_IN)
        except ValueError as exc:
            problems.add("effects", str(exc))


#: the fitted values :func:`_model` takes where the scene gives none (its check's
#: stand-in for the fit of the record, which loading does not make)
_STAND_IN = SimpleNamespace(chandler_period=433.0 * u.day, annual_period=365.25 * u.day,
                            annual_amplitude=0.0, annual_phase=0.0 * u.rad,
                            annual_retrograde_amplitude=0.0,
                            annual_retrograde_phase=0.0 * u.rad)


def _model(spec: dict, fit: Any):
    from rigid.earth.liouville import LiouvillePole

    names = tuple(e["name"] for e in spec["effects"]) or ("free",)
    params: dict[str, Any] = {}
    for e in spec["effects"]:
        params.update({k: v for k, v in e.items() if k != "name"})
    if "elastic" in names and "k2" not in params and "chandler_period" not in params:
        params["chandler_period"] = fit.chandler_period
    if "annual_excitation" in names and "annual_prograde" not in params:
        # the model's own sigma_c (from k2, a period, or Euler's when not elastic), of
        # the model without its excitation: the fit's period gave another forced term
        sig = LiouvillePole(names, **params, annual_prograde=0.0).sigma
        w_a = 2 * np.pi / fit.annual_period.to_value(u.day)
        c_p = fit.annual_amplitude * np.exp(1j * fit.annual_phase.to_value(u.rad))
        c_r = fit.annual_retrograde_amplitude * np.exp(
            1j * fit.annual_retrograde_phase.to_value(u.rad))
        params.update(annual_period=fit.annual_period, annual_prograde=c_p * (sig - w_a) / sig,
                      annual_retrograde=c_r * (sig + w_a) / sig)
    return LiouvillePole(names, **params)


def _run(scene: Scene, progress: bool = True, stop=lambda: False) -> Result:
    from rigid.earth.c04 import load_c04
    from rigid.earth.constants import euler_period, secular_love_number
    from rigid.earth.wobble_fit import fit_wobble

    spec = scene.spec
    start_wall = time.perf_counter()
    record = load_c04()
    fit = fit_wobble(record, spec["start"], spec["end"])
    rec = record.select(spec["start"], spec["end"])
    t = (rec.time.mjd - fit.epoch.mjd) * u.day
    trend = fit.mean_pole + fit.drift * t.to(u.yr)
    m_obs = rec.m.to(u.mas) - trend
    model = _model(spec, fit)
    m_model = model.solve(t, m_obs[0]).to(u.mas)
    wall = time.perf_counter() - start_wall
    diff = np.abs(m_model - m_obs)
    first = t <= t[0] + 2 * u.yr
    result = Result(
        scene=scene,
        times=t,
        diagnostics={
            "observed_m1": m_obs.real, "observed_m2": m_obs.imag,
            "model_m1": m_model.real, "model_m2": m_model.imag,
        },
        states={"x_p": rec.x.to(u.mas), "y_p": rec.y.to(u.mas)},
        wall_time=wall,
        time_origin=f"the fit epoch {fit.epoch.utc.iso[:16]} UTC (MJD {fit.epoch.utc.mjd:.2f}, "
                    "the window's middle)",
    )
    ks = float(secular_love_number())
    t_e = euler_period()
    res = result.metrics
    res["window"] = f"{fit.start.iso[:10]} .. {fit.end.iso[:10]}"
    res["Euler period (rigid Earth)"] = t_e.to(u.day)
    res["Chandler period (fit)"] = fit.chandler_period.to(u.day)
    res["  uncertainty (correlated residuals)"] = fit.chandler_period_error.to(u.day)
    res["annual period (fit)"] = fit.annual_period.to(u.day)
    res["Chandler amplitude"] = fit.chandler_amplitude.to(u.mas)
    res["annual amplitude (prograde)"] = fit.annual_amplitude.to(u.mas)
    res["effective k2 = k_s (1 - T_E / T_C)"] = float(
        ks * (1 - (t_e / fit.chandler_period).to_value(u.one)))
    res["rms residual of the fit (per component)"] = fit.rms_residual.to(u.mas)
    res["model period"] = (model.period * u.day)
    res["|model - observed|, first 2 years (rms)"] = np.sqrt(np.mean(diff[first] ** 2))
    res["|model - observed|, whole window (rms)"] = np.sqrt(np.mean(diff**2))
    res["Q from the line width (see caveat)"] = float(fit.q_estimate)
    result.tables["amplitude by decade"] = [
        {"decade": row["decade"], "Chandler (mas)": float(row["chandler_amplitude"].to_value(
            u.mas)), "annual (mas)": float(row["annual_amplitude"].to_value(u.mas))}
        for row in fit.amplitude_by_decade
    ]
    result.tables["caveat"] = [  # what "see caveat" points at
        {"Q from the line width": line} for line in textwrap.wrap(fit.q_caveat, 88)]
    result.frame = ("pole coordinates on the terrestrial axes (IERS: x_p towards Greenwich, "
                    "y_p towards 90° W)")
    result.plotters.append(_plot)
    return result


def _plot(result: Result):
    import matplotlib.pyplot as plt

    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(12, 5.6))
    x = result.states["x_p"].to_value(u.mas)
    y = result.states["y_p"].to_value(u.mas)
    (path,) = ax.plot(x, y, lw=0.3, label="pole path")
    # where the path starts and which way the pole moves
    ax.plot(x[:1], y[:1], "o", ms=6, mfc=path.get_color(), mec="k", gid="start",
            label=f"start ({result.scene.spec.get('start')}); arrow: the next 20 days")
    k = min(20, len(x) - 1)
    ax.annotate("", xy=(x[k], y[k]), xytext=(x[0], y[0]), gid="direction",
                arrowprops={"arrowstyle": "-|>", "color": "k", "lw": 1.0})
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2,
              frameon=False)
    # IERS pole coordinates (IERS Conventions 2010, ch. 5): terrestrial axes, x_p
    # towards the Greenwich meridian, y_p towards 90 degrees west
    ax.set_xlabel("x_p, terrestrial axes, towards Greenwich [mas]")
    ax.set_ylabel("y_p, terrestrial axes, towards 90° W [mas]")
    ax.set_title("observed pole, IERS 20 C04")
    years = result.times.to_value(u.yr)
    ax2.plot(years, result.diagnostics["observed_m1"].to_value(u.mas), lw=0.5,
             label="observed m1 (trend removed)")
    ax2.plot(years, result.diagnostics["model_m1"].to_value(u.mas), lw=0.8,
             label="Liouville model")
    ax2.set_xlabel(f"time from {result.time_origin.split(' (')[0]} [yr]")
    ax2.set_ylabel("m1 = x_p, towards Greenwich [mas]")
    ax2.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2,
               frameon=False)
    ax2.set_title(f"{result.scene.name}: model against the record")
    fig.tight_layout()
    fig.set_label("pole")  # the file name Result.save gives it
    return fig


def _crosscheck(scene: Scene) -> str:
    """The exact Liouville solution against scipy's DOP853 on the same model."""
    from scipy.integrate import solve_ivp

    from rigid.earth.c04 import load_c04
    from rigid.earth.wobble_fit import fit_wobble

    spec = scene.spec
    record = load_c04()
    fit = fit_wobble(record, spec["start"], spec["end"])
    model = _model(spec, fit)
    t = np.linspace(0.0, 3650.0, 3651)
    m0 = (0.1 + 0.05j) * u.arcsec.to(u.rad)  # model.rhs works in radians and days
    exact = model.solve(t * u.day, m0 * u.rad).to_value(u.rad)

    def rhs(tt: float, y: np.ndarray) -> np.ndarray:
        d = complex(model.rhs(tt, complex(y[0], y[1])))
        return np.array([d.real, d.imag])

    sol = solve_ivp(rhs, (t[0], t[-1]), [m0.real, m0.imag], method="DOP853", t_eval=t,
                    rtol=1e-12, atol=1e-20)
    num = sol.y[0] + 1j * sol.y[1]
    to_mas = u.rad.to(u.mas)
    rows = [{"over": "10 years, daily", "max |exact - DOP853| (mas)":
             float(np.max(np.abs(exact - num)) * to_mas), "max |m| (mas)":
             float(np.max(np.abs(exact)) * to_mas)}]
    return (f"{scene.name}: exact Liouville solution against scipy DOP853 (rtol 1e-12)\n"
            + format_table(rows))


KIND = SceneKind(
    name="polar_motion",
    summary="the linearised Liouville pole with the listed effects against the IERS record",
    schema=SCHEMA,
    effect_kind="rotation",
    check=_check,
    run=_run,
    crosscheck=_crosscheck,
)


def register() -> None:
    """Register the ``polar_motion`` scene kind (and, beside it, ``pole_prediction``)."""
    register_kind(KIND)
    # issue 25: the prediction scenes live in their own module, registered with this kind
    from rigid.earth import scene_pole_prediction

    scene_pole_prediction.register()
