"""What the ``[[analysis]]`` entries of an ``nbody`` scene measure
(:data:`ANALYSIS_FUNCTIONS`): the perihelion advance, the nodal regression, the
closest approach, the residuals against DE440."""

from __future__ import annotations

import re

import astropy.units as u
import numpy as np

from hamilton_orbits.scenes.nbody.build import scene_frame
from hamilton_orbits.scenes.nbody.figures import plot_de440, plot_perihelion
from hamilton_orbits.scenes.result import Result


def _present(result: Result, system, *bodies: str) -> np.ndarray:
    """The output rows at which every one of ``bodies`` still exists: an event that
    removes a body, or merges it into another, leaves NaN in its rows after it."""
    names = list(system.names)
    r = result.states["r"].value[:, [names.index(b) for b in bodies]]
    return np.flatnonzero(np.all(np.isfinite(r), axis=(1, 2)))


def _relative_orbits(result: Result, system, body: str, primary: str, rows: np.ndarray,
                     equator: bool = False):
    """The orbits of ``body`` about ``primary`` at the output ``rows`` (``equator``: in
    axes whose z is the primary's pole, when it has one: inclination and node to its
    equator)."""
    from hamilton_orbits import KeplerOrbit

    names = list(system.names)
    i, j = names.index(body), names.index(primary)
    r = result.states["r"][rows, i] - result.states["r"][rows, j]
    v = result.states["v"][rows, i] - result.states["v"][rows, j]
    pole = getattr(system[primary], "pole", None) if equator else None
    if pole is not None:
        axes = _equator_axes(np.asarray(pole, dtype=float))
        r, v = r @ axes.T, v @ axes.T
    gm = system.gm
    mu = gm[i] + gm[j]
    return KeplerOrbit.from_state(r.to(u.km), v.to(u.km / u.s), mu.to(u.km**3 / u.s**2))


def _equator_axes(pole: np.ndarray) -> np.ndarray:
    """Rows: the axes x (the equator's ascending node on the frame's x-y plane, or
    the frame's x where the pole is its z), y and z (the pole) of a body's equator.

    Examples
    --------
    >>> _equator_axes(np.array([0.0, 0.0, 2.0])).tolist()
    [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    >>> bool(np.allclose(_equator_axes(np.array([0.0, 0.5, 1.0])) @ [0.0, 0.5, 1.0],
    ...                  [0.0, 0.0, np.hypot(0.5, 1.0)]))
    True
    """
    z = pole / np.linalg.norm(pole)
    node = np.cross([0.0, 0.0, 1.0], z)
    x = node / np.linalg.norm(node) if np.linalg.norm(node) > 1e-12 else np.array(
        [1.0, 0.0, 0.0])
    return np.array([x, np.cross(z, x), z])


def _rows_of(result: Result, system, key: str, *bodies: str, least: int = 2):
    """The rows where ``bodies`` all exist, or None (with a note under ``key``) when fewer
    than ``least`` do; a note too when a body left the run before its end."""
    rows = _present(result, system, *bodies)
    if rows.size < least:
        result.metrics[key] = (f"not measured: {' and '.join(bodies)} together at "
                               f"{rows.size} output(s) (removed or merged by an event)")
        return None
    if rows[-1] != len(result.times) - 1:
        result.metrics[f"{key}: measured up to"] = result.times[rows[-1]].to(u.yr)
    return rows


CENTURY = u.def_unit("century", 100 * u.yr)


def _rate(times: u.Quantity, angle: u.Quantity) -> u.Quantity:
    """Least-squares slope of an unwrapped angle against time."""
    y = np.unwrap(angle.to_value(u.rad))
    t = times.to_value(u.d)
    slope = np.polyfit(t - t.mean(), y, 1)[0]
    return slope * u.rad / u.d


def _perihelion_advance(result: Result, system, an: dict) -> None:
    primary = an.get("primary") or system.names[int(np.argmax(np.asarray(
        getattr(system.gm, "value", system.gm))))]
    key = f"perihelion advance of {an['body']}"
    rows = _rows_of(result, system, key, an["body"], primary)
    if rows is None:
        return
    orbits = _relative_orbits(result, system, an["body"], primary, rows)
    rate = _rate(result.times[rows], orbits.varpi).to(u.arcsec / CENTURY)
    result.metrics[key] = rate
    result.diagnostics["perihelion"] = {  # for the figure of the advance
        "body": an["body"], "times": result.times[rows],
        "varpi": np.unwrap(orbits.varpi.to_value(u.rad)) * u.rad, "rate": rate,
        "orbits": float(((result.times[rows[-1]] - result.times[rows[0]])
                         / np.atleast_1d(orbits.period)[0]).to_value(u.one)),
        "gr": any(e.get("name") == "gr" for e in result.scene.effects)}
    result.plotters.append(plot_perihelion)


def _nodal_regression(result: Result, system, an: dict) -> None:
    primary = an.get("primary") or system.names[0]
    key = f"nodal regression of {an['body']}"
    rows = _rows_of(result, system, key, an["body"], primary)
    if rows is None:
        return
    orbits = _relative_orbits(result, system, an["body"], primary, rows, equator=True)
    rate = _rate(result.times[rows], orbits.lan).to(u.deg / u.d)
    result.metrics[key] = rate  # (the node on the primary's equator, where it has a pole)
    prim = system[primary]
    j2 = getattr(prim, "j2", None)
    flattened = any(e["name"] in ("j2", "zonal") for e in result.scene.effects)
    if j2 is not None and getattr(prim, "radius", None) is not None and flattened:
        # first-order secular rate: dOmega/dt = -3/2 n J2 (R/p)^2 cos i (Vallado 4th ed. 9-41)
        o = orbits[0]
        j2v = float(getattr(j2, "value", j2))
        formula = (-1.5 * o.n * j2v * (prim.radius / o.p).to(u.one) ** 2 * np.cos(o.inc))
        formula = formula.to(u.deg / u.d)
        result.metrics["J2 first-order formula"] = formula
        result.metrics["ratio simulated / formula"] = float(rate / formula)


def _how_it_left(result: Result, row: int, *bodies: str) -> str:
    """Which of ``bodies`` left the run after output ``row``, and how (the events
    table's action), e.g. "comet was removed"."""
    names = list(result.states["names"])
    r = result.states["r"].to_value(u.au)[row + 1]
    gone = [b for b in bodies if not np.all(np.isfinite(r[names.index(b)]))] or list(bodies)
    actions = {str(e["action"]) for e in result.tables.get("events", [])
               if set(gone) & set(re.split(r"[\s,-]+", str(e["bodies"])))}
    verb = {"remove": "removed", "merge": "merged"}
    how = " or ".join(sorted(verb.get(a, a) for a in actions)) or "removed or merged"
    return f"{' and '.join(gone)} {'were' if len(gone) > 1 else 'was'} {how}"


def _close_approach(result: Result, system, an: dict) -> None:
    """Smallest distance between two bodies, refined between outputs.

    Around the closest sampled output the relative motion is taken as straight
    (``d + w t``) over at most half a cadence either side, which is accurate when
    the cadence is short beside the encounter's duration; the heliocentric (or
    ``primary``-centric) orbit of ``body`` before and after is reported too.
    """
    key = f"closest approach {an['body']}-{an['other']}"
    rows = _rows_of(result, system, key, an["body"], an["other"], least=1)
    if rows is None:
        return
    names = list(system.names)
    i, j = names.index(an["body"]), names.index(an["other"])
    r = result.states["r"].to_value(u.au)[rows]
    v = result.states["v"].to_value(u.au / u.d)[rows]
    t = result.times.to_value(u.d)[rows]
    d = r[:, i] - r[:, j]
    w = v[:, i] - v[:, j]
    dist = np.linalg.norm(d, axis=-1)
    k = int(np.argmin(dist))
    lo = 0.5 * (t[max(k - 1, 0)] - t[k])  # half-way to the neighbouring outputs,
    hi = 0.5 * (t[min(k + 1, len(t) - 1)] - t[k])  # never beyond the run's ends
    ww = float(w[k] @ w[k])
    tau = float(np.clip(-(d[k] @ w[k]) / ww, lo, hi)) if ww > 0 else 0.0
    closest = float(np.linalg.norm(d[k] + w[k] * tau))
    # the nearest output the last before a body left the run, still approaching: the
    # closest approach was never reached (its distance is the last one, not a minimum)
    reached = not (k == len(rows) - 1 and rows[-1] != len(result.times) - 1
                   and float(d[k] @ w[k]) < 0)
    ended = "" if reached else _how_it_left(result, rows[-1], an["body"], an["other"])
    if reached:
        result.metrics[key] = closest * u.au
    else:
        result.metrics[key] = (f"not reached: {closest:.6g} AU apart and closing at the "
                               f"last output before {ended}")
    result.metrics["at time"] = ((t[k] + tau) * u.d).to(u.yr)
    result.diagnostics["close_approach"] = {  # marked on the orbit figure
        "body": an["body"], "other": an["other"], "row": int(rows[k]),
        "distance": closest * u.au, "time": ((t[k] + tau) * u.d).to(u.yr),
        "reached": reached, "ended": ended}
    primary = an.get("primary")
    if primary:
        rows = _rows_of(result, system, f"{an['body']} orbit", an["body"], primary, least=1)
        if rows is None:
            return
        orbits = _relative_orbits(result, system, an["body"], primary, rows)
        for label, idx in (("before", 0), ("after", -1)):
            o = orbits[idx]
            # 1/a too: it is continuous through the parabola (a jumps from +inf to
            # -inf there, as a clone that escapes does), and q, finite for every conic
            result.metrics[f"{an['body']} orbit {label}: a"] = o.a.to(u.au)
            result.metrics[f"{an['body']} orbit {label}: 1/a"] = (1 / o.a).to(1 / u.au)
            result.metrics[f"{an['body']} orbit {label}: q"] = o.q.to(u.au)
            result.metrics[f"{an['body']} orbit {label}: e"] = float(o.e)


def _de440_residuals(result: Result, system, an: dict) -> None:
    """The positions against DE440's at the whole years from the start among the
    outputs, at the run's own dates (the start's epoch plus those years): km and
    arcsec per body (heliocentric; the Moon geocentric) at 10, 50 and 100 years
    (those reached) and at the last whole year, and a figure of the residual
    against time."""
    from hamilton_orbits import ephemeris as de
    from hamilton_orbits.studies.ladder import BODIES, residuals

    years = result.times.to_value(u.yr)  # Julian years of 365.25 d from the start
    whole = np.flatnonzero(np.abs(years - np.round(years)) < 1e-9)
    start = result.scene.spec["initial"].get("ephemeris")
    if start is None or len(whole) < 2:
        result.metrics["DE440 residuals"] = "need [initial] ephemeris and yearly outputs"
        return
    r = result.states["r"].to_value(u.au)[whole]
    yrs = np.round(years[whole]).astype(int)
    km, arcsec = residuals(system.names, r, yrs, frame=scene_frame(result.scene.spec),
                           start_jd=de.epoch_jd(start["epoch"]))
    result.diagnostics["de440_years"] = yrs
    result.diagnostics["de440_km"] = km
    # (a run shorter than 10 years, or ending between the marks, shows its end too:
    # a 2-year run's table had no column at all)
    marks = [y for y in (10, 50, 100) if y in yrs]
    marks += [] if int(yrs[-1]) in marks else [int(yrs[-1])]
    rows = []
    for k, body in enumerate(BODIES):
        row = {"body": body}
        for y in marks:
            i = int(np.flatnonzero(yrs == y)[0])
            row[f"{y} yr"] = f"{km[i, k]:.3g} km ({arcsec[i, k]:.2g}\")"
        rows.append(row)
    result.tables["residuals against DE440 (heliocentric; the Moon geocentric)"] = rows
    result.metrics["largest residual at the end"] = (
        f"{BODIES[int(np.argmax(km[-1]))]}: {km[-1].max():.3g} km")
    result.plotters.append(plot_de440)



ANALYSIS_FUNCTIONS = {
    "de440_residuals": _de440_residuals,
    "perihelion_advance": _perihelion_advance,
    "nodal_regression": _nodal_regression,
    "close_approach": _close_approach,
}

