"""The figures of an ``nbody`` scene: the orbits (:func:`plot_orbits`), the energy
error, MEGNO and the residuals against DE440, and what the orbit figure draws
(:func:`orbit_view`, :func:`osculating_ellipse`, :func:`axis_label`)."""

from __future__ import annotations

from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits.frames import frame_label
from hamilton_orbits.scenes.result import Result


def plot_megno(result: Result):
    """MEGNO against time (``variational = true``), from the first output after the
    start: MEGNO's value at t = 0 is its initial value (0, by definition), not a
    measurement, and drawn it made a spike from 0 at the start."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.4))
    t = result.times.to_value(u.yr)
    after = t != 0  # (the outputs after the start)
    megno = np.asarray(result.diagnostics["megno"], dtype=float)[after]
    ax.plot(t[after], megno, lw=0.8, label="MEGNO <Y> (from the first output after t = 0)")
    ax.axhline(2.0, color="0.6", lw=0.6, ls=":", label="2 (quasi-periodic)")
    ax.set_xlabel("time [yr]")
    ax.set_ylabel("MEGNO <Y> (dimensionless)")
    ax.set_title(f"{result.scene.name}: MEGNO")
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2,
              frameon=False)
    fig.tight_layout()
    fig.set_label("megno")  # the file name Result.save gives it
    return fig



def plot_de440(result: Result):
    """The position residuals against DE440 against time, a body's points each
    (the samples are yearly: joined by lines, the orbits' periods alias into slow
    wiggles that look like residual oscillations)."""
    import matplotlib.pyplot as plt

    from hamilton_orbits.studies.ladder import BODIES

    fig, ax = plt.subplots(figsize=(9.5, 4.8))
    years = result.diagnostics["de440_years"]
    km = result.diagnostics["de440_km"]
    colors = plt.cm.tab10(np.arange(10) / 10)
    markers = "osD^v<>PX*h"
    for k, body in enumerate(BODIES):
        moon = body == "moon"
        ax.semilogy(years[1:], np.maximum(km[1:, k], 1e-6), ls="none",
                    marker=markers[k % len(markers)], ms=4 if moon else 3,
                    mfc="none" if k >= 10 else None, color="k" if moon else colors[k % 10],
                    label="moon (from the earth)" if moon else body)
    epoch = str(result.scene.spec["initial"]["ephemeris"]["epoch"])
    start = "J2000" if epoch.strip().upper() == "J2000" else f"the start, {epoch} TDB"
    ax.set_xlabel(f"time from {start} [yr]")
    ax.set_ylabel("position residual against DE440 [km]")
    # (distances: the same on any axes, so no frame is named)
    ax.set_title(f"{result.scene.name}: heliocentric residuals (the Moon geocentric), "
                 "sampled once a year")
    ax.legend(fontsize=7, ncol=2, loc="upper left", bbox_to_anchor=(1.01, 1.0),
              frameon=False)
    fig.tight_layout()
    fig.set_label("de440_residuals")  # the file name Result.save gives it
    return fig



GR_MERCURY = 42.98  # arcsec per century: 6 pi GM / (c^2 a (1 - e^2)) per orbit (REFERENCES.md)


FIT_ORBITS = 2  # orbits run, at least, for the least-squares line to be drawn as a fit


def plot_perihelion(result: Result):
    """The advance of the longitude of perihelion against time (the osculating
    two-body orbit at each output, drawn as points: it swings within each orbit,
    ~0.08" for Mercury, and a line through thousands of outputs was a solid block
    over the fit), the least-squares line whose slope is the scene's rate (above
    the points; not drawn, and the figure says why, over fewer than
    :data:`FIT_ORBITS` orbits or 3 outputs: two points make no fit), and, for
    Mercury with ``gr``, the relativistic 42.98"/cy."""
    import matplotlib.pyplot as plt

    per = result.diagnostics["perihelion"]
    t = per["times"].to_value(u.yr)
    adv = (per["varpi"] - per["varpi"][0]).to_value(u.arcsec)
    rate = per["rate"].to_value(u.arcsec / (100 * u.yr)) / 100  # arcsec per year
    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(7.5, 6.4), sharex=True,
                                  height_ratios=(2, 1))
    orbits = per.get("orbits", np.inf)
    fitted = len(t) >= 3 and orbits >= FIT_ORBITS
    fit = adv.mean() + rate * (t - t.mean()) if fitted else adv
    dense = len(t) > 2000  # (pale small points, the lines over them seen)
    points = dict(ls="none", marker=".", ms=1 if dense else 4, color="C0",
                  alpha=0.35 if dense else 1.0, zorder=1)
    lines = [(adv, points, f"{per['body']}: osculating perihelion longitude at each output")]
    if fitted:
        lines.append((fit, dict(lw=1.6, color="C3", ls="--", zorder=3),
                      f"least-squares fit: {rate * 100:.2f}\"/century (the scene's rate)"))
    if per["body"] == "mercury" and per["gr"]:
        lines.append((GR_MERCURY / 100 * (t - t[0]),
                      dict(lw=1.6, color="k", ls=":", zorder=3),
                      f"general relativity: {GR_MERCURY}\"/century (Einstein 1915; "
                      "REFERENCES.md)"))
    for y, style, label in lines:
        ax.plot(t, y, label=label, **style)
        if fitted:
            ax2.plot(t, y - fit, **style)
    ax.set_ylabel("advance of the longitude of\nperihelion since the start [arcsec]",
                  fontsize=9)
    ax2.set_xlabel("time since the start [yr]")
    if fitted:
        ax2.set_ylabel("minus the fit [arcsec]", fontsize=9)
    else:
        ax2.set_ylabel("(no fit)", fontsize=9)
        ax2.set_yticks([])
        ax2.text(0.5, 0.5, f"too few orbits run for a fit: {orbits:.3g} orbit(s), "
                 f"{len(t)} outputs\n(a rate needs at least {FIT_ORBITS} orbits: the "
                 "osculating perihelion swings within each)", ha="center", va="center",
                 fontsize=9, transform=ax2.transAxes)
    ax.set_title(f"{result.scene.name}: perihelion advance of {per['body']}", fontsize=10)
    legend = ax2.legend(*ax.get_legend_handles_labels(), fontsize=7, loc="upper center",
                        bbox_to_anchor=(0.5, -0.32), ncol=1, frameon=False)
    for handle in legend.legend_handles:
        if handle.get_marker() == ".":
            handle.set_markersize(5)
            handle.set_alpha(1.0)
    fig.tight_layout()
    fig.set_label("perihelion")  # the file name Result.save gives it
    return fig


def orbit_view(names: list[str], gm: np.ndarray, r: np.ndarray) -> dict[str, Any]:
    """What the orbit figure draws: positions relative to the primary (the most
    massive body), in km below 0.01 au of extent and au above (the outputs where a
    body exists: NaN after a removal or a merge is left out), and the bodies of an
    inner panel (those inside the largest gap, by a factor 2.5 or more, in the
    bodies' largest distances from the primary, when the outermost is 5 times
    farther; without such a gap, when the outermost is 20 times farther than the
    innermost, those within an eighth of its distance).

    Parameters
    ----------
    names : list of str, (n,)
    gm : ndarray, (n,)
    r : ndarray, (n_t, n, 3)
        Positions in au.

    Examples
    --------
    >>> r = np.zeros((2, 3, 3)); r[:, 1, 0] = 1.0; r[:, 2, 0] = 30.0
    >>> view = orbit_view(["sun", "earth", "neptune"], np.array([1.0, 3e-6, 5e-5]), r)
    >>> view["primary"], view["unit"], view["inner"]
    ('sun', 'au', ['earth'])
    """
    k = int(np.argmax(gm))
    rel = r - r[:, k:k + 1]
    # (NaN where a body was removed or merged: fmax skips it, 0 for a body never there)
    reach = np.fmax.reduce(np.linalg.norm(rel, axis=-1), axis=0, initial=0.0)
    others = [i for i in range(len(names)) if i != k]
    unit = "au" if reach.max(initial=0.0) > 0.01 else "km"
    scale = 1.0 if unit == "au" else (1 * u.au).to_value(u.km)
    inner: list[str] = []
    if len(others) > 1:
        order = sorted(others, key=lambda i: reach[i])
        dist = np.maximum(reach[order], 1e-300)
        ratios = dist[1:] / dist[:-1]
        cut = int(np.argmax(ratios))
        if ratios[cut] >= 2.5 and dist[-1] >= 5 * dist[cut]:
            inner = [names[i] for i in order[:cut + 1]]
        elif dist[-1] >= 20 * dist[0]:  # no gap, a wide spread: the inner eighth
            inner = [names[i] for i, d in zip(order, dist, strict=True) if d < dist[-1] / 8]
    return {"primary": names[k], "rel": rel * scale, "unit": unit, "inner": inner,
            "reach": reach * scale, "scale": scale, "index": k}


def axis_label(axis: str, unit: str, frame: str, primary: str) -> str:
    """A position axis's label: the axis, the origin, the frame and the unit.

    Examples
    --------
    >>> axis_label("x", "au", "ecliptic", "sun")
    'x from sun, J2000 mean ecliptic and equinox [au]'
    """
    return f"{axis} from {primary}, {frame_label(frame)} [{unit}]"


def osculating_ellipse(r: np.ndarray, v: np.ndarray, mu: float, n: int = 361
                       ) -> np.ndarray | None:
    """Points of the two-body ellipse through the state ``r``, ``v`` (relative to the
    primary, ``mu`` = G (m_primary + m)), shape (n, 3); None unless 0 <= e < 0.95.

    ``r(E) = a (cos E - e) P + a sqrt(1 - e^2) sin E Q`` with ``P`` towards the
    periapsis (the modern eccentricity vector) and ``Q = h x P / |h|``.

    Examples
    --------
    >>> pts = osculating_ellipse(np.array([1.0, 0, 0]), np.array([0, 1.0, 0]), 1.0, 5)
    >>> np.round(pts[:, :2], 12).tolist()
    [[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [-0.0, -1.0], [1.0, -0.0]]
    """
    h = np.cross(r, v)
    dist = float(np.linalg.norm(r))
    ecc = np.cross(v, h) / mu - r / dist
    e = float(np.linalg.norm(ecc))
    energy = 0.5 * float(v @ v) - mu / dist
    if not (energy < 0 and e < 0.95 and np.linalg.norm(h) > 0):
        return None
    a = -mu / (2 * energy)
    p_hat = ecc / e if e > 1e-12 else r / dist
    q_hat = np.cross(h, p_hat) / np.linalg.norm(h)
    big_e = np.linspace(0.0, 2 * np.pi, n)[:, None]
    return a * (np.cos(big_e) - e) * p_hat + a * np.sqrt(1 - e * e) * np.sin(big_e) * q_hat


# a body's colour (the unnamed rest are grey, so no grey here)
PALETTE = ("C0", "C1", "C2", "C3", "C4", "C5", "C6", "C8", "C9", "navy", "darkgoldenrod",
           "teal")
PER_ORBIT = 90  # points drawn per revolution, at least (60 read as an ellipse; 90 leave
#                room for projection and eccentricity)


def _period(r: np.ndarray, v: np.ndarray, mu: float) -> float:
    """The two-body period of the state (inf when unbound), shape (n,) from (n, 3)."""
    energy = 0.5 * np.einsum("ij,ij->i", v, v) - mu / np.linalg.norm(r, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        a = -mu / (2 * energy)
        return np.where(energy < 0, 2 * np.pi * np.sqrt(np.abs(a) ** 3 / mu), np.inf)


def _turn(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The angle between rows of ``a`` and ``b``, in revolutions."""
    with np.errstate(divide="ignore", invalid="ignore"):
        cos = np.einsum("ij,ij->i", a, b) / (np.linalg.norm(a, axis=-1)
                                             * np.linalg.norm(b, axis=-1))
    return np.nan_to_num(np.arccos(np.clip(cos, -1, 1))) / (2 * np.pi)


def refined_track(t: np.ndarray, r: np.ndarray, v: np.ndarray, mu: float
                  ) -> tuple[np.ndarray, bool]:
    """The track drawn for a body: its outputs, and, between outputs further apart
    than a 90th of an orbit (in time, or in the angle turned in space or as
    projected on x-y), the two-body (Kepler) motion from the earlier output
    (at most one revolution of it; a NaN breaks the line where a whole revolution
    is drawn, instead of a chord to the next output).  Returns the points (m, 3)
    and whether any arc was inserted.

    Examples
    --------
    >>> t = np.array([0.0, 2 * np.pi]); r = np.array([[1.0, 0, 0]] * 2)
    >>> v = np.array([[0, 1.0, 0]] * 2)
    >>> pts, refined = refined_track(t, r, v, 1.0)
    >>> refined, len(pts) >= 60
    (True, True)
    """
    ok = np.all(np.isfinite(r), axis=-1) & np.all(np.isfinite(v), axis=-1)
    if len(t) < 2 or not ok.all() or mu <= 0:
        return r, False
    dt = np.diff(t)
    period = _period(r[:-1], v[:-1], mu)
    swept = np.where(np.isfinite(period), np.minimum(dt / period, 1.0), 0.0)
    angle = np.maximum(_turn(r[:-1], r[1:]), _turn(r[:-1, :2], r[1:, :2]))  # as drawn too
    # the fastest turn, at periapsis, is (1 + e)^2 / (1 - e^2)^(3/2) times the mean
    h = np.cross(r[:-1], v[:-1])
    e = np.linalg.norm(np.cross(v[:-1], h) / mu - r[:-1] / np.linalg.norm(
        r[:-1], axis=-1)[:, None], axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        peak = np.where(e < 1, (1 + e) ** 2 / np.abs(1 - e * e) ** 1.5, 1.0)
    n_sub = np.ceil(PER_ORBIT * np.maximum(swept * peak, angle)).astype(int)
    n_sub = np.minimum(n_sub, 5000)
    if n_sub.max(initial=1) <= 1:
        return r, False
    return _with_arcs(r, v, mu, dt, period, n_sub), True


def _with_arcs(r: np.ndarray, v: np.ndarray, mu: float, dt: np.ndarray,
               period: np.ndarray, n_sub: np.ndarray) -> np.ndarray:
    """The outputs ``r`` with ``n_sub[i] - 1`` points of the two-body arc from output
    ``i`` inserted after it where ``n_sub[i] > 1`` (over ``min(dt[i], period[i])``,
    :func:`_arcs`), then a NaN row after a whole revolution (its first point
    repeated before it) or after an arc that ends away from the next output (its
    end before it)."""
    sub = n_sub > 1
    k = np.where(sub, n_sub - 1, 0)  # the arc's points between the two ends
    whole = sub & (dt >= period)
    arcs = np.flatnonzero(sub)
    pts, ends = _arcs(r[arcs], v[arcs], mu, np.minimum(dt, period)[arcs], n_sub[arcs])
    part = ~whole[arcs]  # (the arcs that end before a revolution: is the end away?)
    nxt = r[arcs[part] + 1]
    away = np.zeros(len(arcs), bool)
    away[part] = np.maximum(_turn(ends[part], nxt), _turn(ends[part, :2], nxt[:, :2])) > (
        1 / PER_ORBIT)
    closed = whole.astype(int)
    closed[arcs[away]] = 1  # (a point and a NaN row after the arc)
    start = np.concatenate([[0], np.cumsum(1 + k + 2 * closed)])
    out = np.empty((start[-1] + 1, 3))
    out[start[:-1]] = r[:-1]
    at = np.repeat(arcs, k[arcs])
    j = np.arange(len(at)) - np.repeat(np.cumsum(k[arcs]) - k[arcs], k[arcs])  # 0 ... k - 1
    out[start[at] + 1 + j] = pts
    last = start[:-1] + 1 + k  # (after the arc)
    shut = np.flatnonzero(whole)
    out[last[shut]] = r[shut]
    out[last[arcs[away]]] = ends[away]
    out[last[closed == 1] + 1] = np.nan
    out[-1] = r[-1]
    return out


def _arcs(r: np.ndarray, v: np.ndarray, mu: float, span: np.ndarray, n: np.ndarray
          ) -> tuple[np.ndarray, np.ndarray]:
    """The two-body motion from each state ``r[i], v[i]`` over ``span[i]``: its
    ``n[i] - 1`` points strictly inside (one arc after another), and each arc's end.

    A bound orbit of ``e < 0.95`` (every planet's) is drawn on its ellipse at equal
    steps of the eccentric anomaly (:func:`_on_ellipse`: no compiled kernel to wait
    for on a first run); a steep or unbound one by the universal Kepler solver at
    equal steps of time (:func:`hamilton_orbits.kepler.propagate`)."""
    h = np.cross(r, v)
    e = np.linalg.norm(np.cross(v, h) / mu - r / np.linalg.norm(r, axis=-1)[:, None], axis=-1)
    energy = 0.5 * np.einsum("ij,ij->i", v, v) - mu / np.linalg.norm(r, axis=-1)
    ellipse = (energy < 0) & (e < 0.95) & (np.linalg.norm(h, axis=-1) > 0)
    row = np.repeat(np.arange(len(n)), n)  # (each point's arc; the last of each its end)
    frac = (np.arange(len(row)) - np.repeat(np.cumsum(n) - n, n) + 1) / n[row]
    out = np.empty((len(row), 3))
    pick = ellipse[row]
    if pick.any():
        local = (np.cumsum(ellipse) - 1)[row[pick]]  # (the arc among the elliptic ones)
        out[pick] = _on_ellipse(r[ellipse], v[ellipse], mu, span[ellipse], frac[pick], local)
    if not pick.all():
        from hamilton_orbits.kepler import propagate

        rest = row[~pick]
        out[~pick] = propagate(r[rest], v[rest], mu, frac[~pick] * span[rest],
                               threads=False)[0]
    last = np.cumsum(n) - 1
    inner = np.ones(len(row), bool)
    inner[last] = False
    return out[inner], out[last]


def _on_ellipse(r: np.ndarray, v: np.ndarray, mu: float, span: np.ndarray,
                frac: np.ndarray, row: np.ndarray) -> np.ndarray:
    """Points of the two-body motion from the bound states ``r, v`` (``e < 0.95``)
    over ``span``: at the fractions ``frac`` of each arc's change of the eccentric
    anomaly ``E`` (point ``j`` on arc ``row[j]``), on ``r(E) = a (cos E - e) P +
    a sqrt(1 - e^2) sin E Q`` (as :func:`osculating_ellipse`); the arc's end from
    Kepler's equation ``E - e sin E = E0 - e sin E0 + sqrt(mu / a^3) span`` by
    Newton's method (from ``M + e sin M``: converged to rounding within 30 steps for
    ``e < 0.95``)."""
    h = np.cross(r, v)
    dist = np.linalg.norm(r, axis=-1)
    ecc = np.cross(v, h) / mu - r / dist[:, None]
    e = np.linalg.norm(ecc, axis=-1)
    a = -mu / (2 * (0.5 * np.einsum("ij,ij->i", v, v) - mu / dist))
    round_ = (e <= 1e-12)[:, None]  # (a circle: P towards the state)
    p_hat = np.where(round_, r / dist[:, None], ecc / np.where(round_[:, 0], 1.0, e)[:, None])
    q_hat = np.cross(h, p_hat) / np.linalg.norm(h, axis=-1)[:, None]
    b = a * np.sqrt(1 - e * e)
    e0 = np.arctan2(np.einsum("ij,ij->i", r, q_hat) / b, np.einsum("ij,ij->i", r, p_hat) / a + e)
    m1 = e0 - e * np.sin(e0) + np.sqrt(mu / a**3) * span
    e1 = m1 + e * np.sin(m1)
    for _ in range(30):
        e1 = e1 - (e1 - e * np.sin(e1) - m1) / (1 - e * np.cos(e1))
    big_e = (e0[row] + frac * (e1 - e0)[row])[:, None]
    return (a[row, None] * (np.cos(big_e) - e[row, None]) * p_hat[row]
            + b[row, None] * np.sin(big_e) * q_hat[row])


def _labelled(view: dict, shown: list[str], most: int = 12) -> list[str]:
    """The bodies the legend names: all, or the ``most - 1`` most massive and the
    rest in one grey entry."""
    bodies = [n for n in shown if n != view["primary"]]
    if len(bodies) <= most:
        return bodies
    gm = {n: view["gm"][view["names"].index(n)] for n in bodies}
    heavy = sorted(bodies, key=lambda n: -gm[n])[:most - 1]
    return [n for n in bodies if n in heavy]  # in the system's order


def _host(view: dict, k: int) -> str | None:
    """The body other than the primary inside whose Hill sphere body ``k`` starts,
    if any (the Moon's host is the Earth)."""
    p = view["index"]
    r0 = view["rel"][0]
    for j, name in enumerate(view["names"]):
        if j in (k, p) or view["gm"][j] <= view["gm"][k]:
            continue
        hill = np.linalg.norm(r0[j]) * (view["gm"][j] / (3 * view["gm"][p])) ** (1 / 3)
        if np.linalg.norm(r0[k] - r0[j]) < hill:
            return name
    return None


def _draw_ends(ax: Any, view: dict, k: int, color: Any) -> None:
    """For a body that goes round more than 20 times: the two-body orbits at its
    first (bold) and last (dashed) outputs, over the pale track."""
    for row, style in ((0, "-"), (-1, "--")):
        r, v, mu = view["rel"][row, k], view["vrel"][row, k], view["mu"][k]
        period = _period(r[None], v[None], mu)
        if not np.isfinite(period[0]):
            continue
        inner, end = _arcs(r[None], v[None], mu, period, np.array([PER_ORBIT * 2]))
        pts = np.vstack([r, inner, end])
        ax.plot(pts[:, 0], pts[:, 1], lw=1.3, color=color, ls=style, gid="ends",
                label="_nolegend_")


def _track(view: dict, k: int) -> tuple[np.ndarray, bool]:
    """:func:`refined_track` of body ``k`` over each run of outputs where it exists,
    split too at a merge that kept it (``view["merges"]``: no line, nor Kepler arc
    from the state before, to the merged body's first output), the runs joined by
    a NaN row."""
    r, v, t = view["rel"][:, k], view["vrel"][:, k], view["t"]
    here = np.all(np.isfinite(r), axis=-1) & np.all(np.isfinite(v), axis=-1)
    cut = np.zeros(len(t), bool)
    cut[1:] = here[1:] != here[:-1]
    for kept, _, m, _ in view.get("merges", ()):
        if kept == k:
            cut[m] = True
    parts, refined = [], False
    for rows in np.split(np.arange(len(t)), np.flatnonzero(cut)):
        if rows.size and here[rows[0]]:
            pts, more = refined_track(t[rows], r[rows], v[rows], view["mu"][k])
            parts += [pts, np.full((1, 3), np.nan)]
            refined |= more
    return (np.vstack(parts[:-1]) if parts else r[:0]), refined


def _merges(result: Result, names: list[str], r: np.ndarray) -> list:
    """The merges of the run's events table: (the body kept, the body absorbed, the
    first output after the merge, its time as text), the absorbed body the one of
    the pair whose positions end at that output."""
    pairs = {f"{a}-{b}": (ka, kb) for ka, a in enumerate(names)
             for kb, b in enumerate(names) if ka != kb}
    t = result.times.to_value(u.yr)
    found = np.all(np.isfinite(r), axis=-1)
    out = []
    for row in result.tables.get("events", []):
        pair = pairs.get(str(row["bodies"]))
        if str(row["action"]) != "merge" or pair is None:
            continue
        when = row["time"].to_value(u.yr)
        ends = {}
        for k in pair:
            present = np.flatnonzero(found[:, k])
            if present.size and present[-1] + 1 < len(t):
                ends[k] = int(present[-1]) + 1
        if ends:
            gone = min(ends, key=lambda k: abs(t[ends[k]] - when))
            kept = pair[0] if gone == pair[1] else pair[1]
            out.append((kept, gone, ends[gone], f"{when:.3g} yr"))
    return out


def _draw_merges(ax: Any, view: dict, shown: list[str]) -> list:
    """A red cross at the merged body's first output after each merge (its line is
    broken there: :func:`_track`)."""
    handles = []
    for kept, gone, m, when in view.get("merges", ()):
        if view["names"][kept] in shown and kept != view["index"]:
            x, y = view["rel"][m, kept, :2]
            (h,) = ax.plot([x], [y], "X", ms=9, color="crimson", mec="k", mew=0.5,
                           gid="merge", label=f"merge: {view['names'][gone]} into "
                           f"{view['names'][kept]} at {when}\n(the merged body's first output)")
            handles.append(h)
    return handles


def _draw_body(ax: Any, view: dict, k: int, color: Any, label: str | None) -> set[str]:
    """One body's track, its start marker and an arrow along its first velocity;
    what was drawn: "dots" if its outputs are drawn as dots on Kepler arcs, "arcs"
    if Kepler arcs are drawn only between some outputs (near periapsis), "ends" if
    its first and last orbits are drawn bold over a pale track."""
    host = _host(view, k)
    period = _period(view["rel"][:1, k], view["vrel"][:1, k], view["mu"][k])[0]
    many = host is None and (view["t"][-1] - view["t"][0]) > 20 * period
    if host is not None:  # a moon: its two-body orbit about the primary means nothing
        ax.plot(view["rel"][:, k, 0], view["rel"][:, k, 1], ".", ms=2, color=color,
                label=f"{label}: the outputs (it goes round {host})" if label
                else "_nolegend_")
        pts, refined = view["rel"][:, k], False
    else:
        pts, refined = _track(view, k)
        ax.plot(pts[:, 0], pts[:, 1], lw=0.6 if refined else 0.8, color=color,
                alpha=0.3 if many else 1.0, label=label or "_nolegend_")
    dots = refined and np.mean(np.diff(view["t"])) > period / PER_ORBIT  # sparse outputs
    if dots:
        ax.plot(view["rel"][:, k, 0], view["rel"][:, k, 1], ".", ms=1.5, color=color,
                alpha=0.3 if many else 1.0, gid="outputs", label="_nolegend_")
    if many:
        _draw_ends(ax, view, k, color)
    x0, y0 = view["rel"][0, k, :2]
    ax.plot([x0], [y0], "o", ms=5, mfc=color, mec="k", mew=0.6, gid="start",
            label="_nolegend_")
    vel = view["vrel"][0, k, :2]
    if np.hypot(*vel) > 0:
        d = vel / np.hypot(*vel) * 0.07 * view["extent"]
        ax.annotate("", xy=(x0 + d[0], y0 + d[1]), xytext=(x0, y0), gid="direction",
                    arrowprops={"arrowstyle": "-|>", "color": color, "lw": 1.0,
                                "shrinkA": 0, "shrinkB": 0})
    return {"dots" if dots else "arcs" if refined else "", "ends" if many else ""}


def _draw_encounter(ax: Any, view: dict, shown: list[str]) -> list:
    """A star at each body of the closest approach (the scene's ``close_approach``
    analysis), at the output nearest to it."""
    enc = view.get("encounter")
    if not enc or enc["body"] not in shown:
        return []
    handles = []
    for name, marker in ((enc["body"], "*"), (enc["other"], "P")):
        if name in shown and name != view["primary"]:
            x, y = view["rel"][enc["row"], view["names"].index(name), :2]
            label = (f"{name} at {enc['what']}" if name == enc["body"] or enc["reached"]
                     else f"{name} at that output")
            if name == enc["body"]:
                label += f" ({enc['text']})" if enc["reached"] else f"\n({enc['text']})"
            (h,) = ax.plot([x], [y], marker, ms=11, mfc="none", mec="crimson", mew=1.2,
                           gid="encounter", label=label)
            handles.append(h)
    return handles


def _draw_orbits(ax: Any, view: dict, shown: list[str], frame: str) -> None:
    from matplotlib.lines import Line2D

    primary = view["primary"]
    named = [n for n in view["named"] if n in shown]
    rest = [n for n in shown if n != primary and n not in named]
    drawn = set()
    for name in [n for n in shown if n != primary]:
        k = view["names"].index(name)
        color = PALETTE[view["named"].index(name) % len(PALETTE)] if name in named else "0.55"
        drawn |= _draw_body(ax, view, k, color, name if name in named else None)
    handles = [h for h in ax.get_lines() if not h.get_label().startswith("_")]
    if rest:
        handles.append(Line2D([], [], color="0.55", lw=0.6, label=(
            f"{len(rest)} more: {', '.join(rest[:3])}, ..." if len(rest) > 3
            else ", ".join(rest))))
    handles += _draw_encounter(ax, view, shown)
    handles += _draw_merges(ax, view, shown)
    (sun,) = ax.plot([0.0], [0.0], "o", color="orange", mec="k", mew=0.4, ms=6,
                     label=f"{primary} (origin)")
    handles.append(sun)
    handles.append(Line2D([], [], marker="o", ls="none", mfc="w", mec="k",
                          label="start (t = 0); arrow: direction of motion"))
    if "ends" in drawn:  # (a handle of each style: one solid line said both)
        handles.append(Line2D([], [], color="k", lw=1.3, label=(
            "the two-body orbit at the first output\n(pale: the whole track)")))
        handles.append(Line2D([], [], color="k", lw=1.3, ls="--",
                              label="the two-body orbit at the last output"))
    if "dots" in drawn:
        handles.append(Line2D([], [], color="k", lw=0.6, marker=".", ms=3, label=(
            f"dots: the outputs (every {view['cadence_text']}), more\nthan a {PER_ORBIT}th "
            "of an orbit apart: the line\nis the two-body (Kepler) orbit\nfrom each "
            "output to the next")))
    elif "arcs" in drawn:
        handles.append(Line2D([], [], color="k", lw=0.6, label=(
            f"where outputs (every {view['cadence_text']}) are more than\na {PER_ORBIT}th "
            "of an orbit apart (near periapsis),\nthe line is the two-body (Kepler) orbit "
            "\nfrom each output to the next")))
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(axis_label("x", view["unit"], frame, primary), fontsize=8)
    ax.set_ylabel(axis_label("y", view["unit"], frame, primary), fontsize=8)
    legend = ax.legend(handles=handles, fontsize=7, loc="upper center",
                       bbox_to_anchor=(0.5, -0.09), ncol=2, frameon=False)
    for handle in legend.legend_handles:
        handle.set_alpha(1.0)  # a pale track has a legend entry in full colour


def _orbit_data(result: Result, gm: np.ndarray) -> dict:
    """:func:`orbit_view` with the velocities, times, GMs and cadence the figure needs."""
    names = list(result.states["names"])
    view = orbit_view(names, gm, result.states["r"].to_value(u.au))
    k = view["index"]
    v = result.states["v"].to_value(u.au / u.d)
    view.update(names=names, gm=np.asarray(gm, dtype=float),
                vrel=(v - v[:, k:k + 1]) * view["scale"],  # in the figure's unit per day
                mu=(gm + gm[k]) * view["scale"] ** 3, t=result.times.to_value(u.d))
    cadence = float(np.median(np.diff(view["t"]))) * u.d if len(view["t"]) > 1 else 0 * u.d
    unit = (u.yr if cadence >= 100 * u.d else u.d if cadence >= 1 * u.d
            else u.h if cadence >= 1 * u.h else u.min)
    view["cadence_text"] = f"{cadence.to_value(unit):.3g} {unit}"
    view["merges"] = _merges(result, names, view["rel"])
    enc = result.diagnostics.get("close_approach")
    if enc is not None:
        text = f"{enc['distance'].to_value(u.au):.3g} au at {enc['time'].to_value(u.yr):.3g} yr"
        reached = enc.get("reached", True)
        if not reached:  # (closing at the last output before a body left the run)
            text = (f"{enc['distance'].to_value(u.au):.3g} au from {enc['other']} at "
                    f"{enc['time'].to_value(u.yr):.3g} yr,\nstill closing: the closest "
                    "approach was not reached")
        view["encounter"] = {**enc, "text": text, "reached": reached, "what": (
            "the closest approach" if reached else f"the last output before {enc['ended']}")}
    return view


def _draw_flyby(ax: Any, view: dict, frame: str) -> None:
    """The closest approach seen from the body passed: the track within 10 times
    the closest distance, refined with the two-body motion about that body."""
    from matplotlib.lines import Line2D

    enc = view["encounter"]
    i, j = view["names"].index(enc["body"]), view["names"].index(enc["other"])
    d = view["rel"][:, i] - view["rel"][:, j]
    w = view["vrel"][:, i] - view["vrel"][:, j]
    near = np.flatnonzero(np.linalg.norm(d, axis=-1) <= 10 * enc["distance"].to_value(u.au)
                          * (1 * u.au).to_value(view["unit"]))
    rows = np.arange(near.min(), near.max() + 1)
    mu = (view["gm"][i] + view["gm"][j]) * view["scale"] ** 3
    sub = dict(view, t=view["t"][rows], rel=d[rows][:, None], vrel=w[rows][:, None],
               mu=np.array([mu]), extent=np.abs(d[rows, :2]).max(), merges=[])
    color = PALETTE[view["named"].index(enc["body"]) % len(PALETTE)]
    _draw_body(ax, sub, 0, color, f"{enc['body']}, from {enc['other']}")
    x, y = d[enc["row"], :2]
    ax.plot([x], [y], "*", ms=11, mfc="none", mec="crimson", mew=1.2, gid="encounter",
            label=(f"the output nearest the closest approach ({enc['text']})"
                   if enc["reached"] else f"{enc['what']}\n({enc['text']})"))
    ax.plot([0.0], [0.0], "P", color="0.3", ms=8, label=f"{enc['other']} (origin)")
    handles = ax.get_lines()
    handles = [h for h in handles if not h.get_label().startswith("_")] + [
        Line2D([], [], marker="o", ls="none", mfc="w", mec="k",
               label=f"{enc['body']} {view['t'][rows[0]] / 365.25:.3g} yr after the start;"
                     " arrow: its motion")]
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(axis_label("x", view["unit"], frame, enc["other"]), fontsize=8)
    ax.set_ylabel(axis_label("y", view["unit"], frame, enc["other"]), fontsize=8)
    ax.legend(handles=handles, fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.09),
              ncol=1, frameon=False)
    ax.set_title(f"the encounter, about {enc['other']}", fontsize=10)


def plot_orbits(result: Result, gm: np.ndarray, frame: str):
    """The orbits about the primary, projected on the frame's x-y plane, each with a
    marker where it starts and an arrow along its first velocity; an inner panel
    where the inner bodies would be a blob beside the outer ones.  Between outputs
    further apart than a 90th of an orbit the two-body orbit from each output is
    drawn (:func:`refined_track`), and the legend says so."""
    import matplotlib.pyplot as plt

    view = _orbit_data(result, gm)
    names = view["names"]
    panels = [names] + ([view["inner"] + [view["primary"]]] if view["inner"] else [])
    view["named"] = _labelled(view, names)
    flyby = "encounter" in view and view["encounter"]["other"] in names
    fig, axes = plt.subplots(1, len(panels) + flyby, figsize=(6.2 * (len(panels) + flyby), 7.6),
                             squeeze=False)
    if flyby:
        _draw_flyby(axes[0, -1], view, frame)
    for ax, shown in zip(axes[0], panels, strict=False):
        view["extent"] = max(view["reach"][names.index(n)] for n in shown)
        _draw_orbits(ax, view, shown, frame)
    axes[0, 0].set_title(f"{result.scene.name}: orbits about {view['primary']}, "
                         f"projected on the frame's x-y plane", fontsize=10)
    if view["inner"]:
        inner = view["inner"]
        axes[0, 1].set_title(f"inner bodies: {', '.join(inner)}" if len(inner) <= 6 else
                             f"the {len(inner)} inner bodies (within "
                             f"{max(view['reach'][names.index(n)] for n in inner):.2g} "
                             f"{view['unit']})", fontsize=10)
    fig.tight_layout()
    fig.set_label("orbits")  # the file name Result.save gives it
    return fig


def plot_energy(result: Result, what: str, conserved: bool):
    """The relative energy error against time (log scale).  Exact zeros (the
    energy came back bit for bit) have no place on a log axis: they are counted
    in the legend, not drawn at an invented floor.  An energy not conserved (the
    effects change it) is drawn signed on a linear axis: its absolute value on a
    log axis made each change of sign a deep dip, which looked like structure.
    rebound's errors, beside, are drawn in a panel of their own below ours (on one
    axis its points covered ours: both sit on the same few levels of rounding)."""
    import matplotlib.pyplot as plt

    span = result.times[-1] - result.times[0]
    t_unit = u.yr if span > 1 * u.yr else u.d
    t = result.times.to_value(t_unit)
    series = [("hamilton-orbits", result.diagnostics["energy_error"], {})]
    peer = result.diagnostics.get("rebound_energy_error")
    if not conserved:
        fig, ax = plt.subplots(figsize=(7.5, 4.8))
        if peer is not None:
            series.append(("rebound IAS15", peer, {"marker": "x", "ms": 3, "alpha": 0.7}))
        return _energy_change(fig, ax, result, t, t_unit, series, what)
    if peer is None:
        fig, ax = plt.subplots(figsize=(7.5, 4.8))
        axes = [ax]
    else:
        fig, axes = plt.subplots(2, 1, figsize=(7.5, 6.4), sharex=True)  # (not sharey: a
        # panel of exact zeros alone would set the other's limits, hiding its points)
        series.append(("rebound IAS15", peer, {"color": "C1"}))
    for ax, (label, values, style) in zip(axes, series, strict=True):
        _log_errors(ax, t, np.abs(np.asarray(values[1:], dtype=float)), label, style)
        ax.set_ylabel("|relative energy error|\n(dimensionless)")
    return _energy_frame(fig, axes[-1], result, t_unit, "energy error", what, top=axes[0])


def _log_errors(ax: Any, t: np.ndarray, err: np.ndarray, label: str, style: dict) -> None:
    """One series of errors >= 0 on a log axis, its exact zeros counted in the legend
    (not drawn at an invented floor); machine epsilon marked where they come near."""
    nonzero = err > 0
    zeros = int(np.count_nonzero(~nonzero))
    note = f" ({zeros} of {len(err)} outputs exactly 0, not drawn)" if zeros else ""
    ax.semilogy(t[1:][nonzero], err[nonzero], ls="none", marker=".", ms=2, label=label + note,
                **style)
    eps = np.finfo(float).eps
    top = float(np.max(err[nonzero])) if nonzero.any() else 0.0
    if top < 1e3 * eps:  # the line only where the data come near it
        ax.axhline(eps, color="0.5", lw=0.7, ls=":", label=f"machine epsilon {eps:.1e}")
    if not nonzero.any():
        ax.set_ylim(eps / 100, eps * 100)


def _energy_change(fig: Any, ax: Any, result: Result, t: np.ndarray, t_unit: Any,
                   series: list, what: str) -> Any:
    """:func:`plot_energy` of an energy the effects change: signed, linear axis, the
    values in units of a power of ten the axis's label names (matplotlib's "1e-9"
    above the axis, apart from its label, was easily missed)."""
    changes = [np.asarray(values[1:], dtype=float) for _, values, _ in series]
    finite = np.abs(np.concatenate(changes))
    finite = finite[np.isfinite(finite) & (finite > 0)]
    power = int(np.floor(np.log10(finite.max()))) if finite.size else 0
    power = power if not -3 <= power <= 3 else 0
    for (label, _, style), change in zip(series, changes, strict=True):
        style = {"marker": ".", "ms": 2, **style}
        ax.plot(t[1:], change / 10.0**power, ls="none", label=label, **style)
    ax.axhline(0.0, color="0.5", lw=0.7)
    ax.ticklabel_format(axis="y", style="plain", useOffset=False)
    scale = f" [$10^{{{power}}}$]" if power else ""
    ax.set_ylabel(f"relative energy change, signed{scale}\n(dimensionless)")
    return _energy_frame(fig, ax, result, t_unit,
                         "energy change (not an error: not conserved)", what)


def _energy_frame(fig: Any, ax: Any, result: Result, t_unit: Any, title: str,
                  what: str, top: Any = None) -> Any:
    """The energy figure's time axis (``ax``, the lowest), title (on ``top``, the
    highest axis), one legend of every axis's series below, and file name."""
    ax.set_xlabel(f"time since the start [{t_unit}]")
    (top or ax).set_title(f"{result.scene.name}: {title}\nof {what}", fontsize=9)
    entries: dict[str, Any] = {}
    for each in fig.axes:
        for handle, label in zip(*each.get_legend_handles_labels(), strict=True):
            entries.setdefault(label, handle)  # (machine epsilon once)
    fig.legend(list(entries.values()), list(entries), fontsize=7, loc="lower center", ncol=2,
               frameon=False)
    fig.tight_layout(rect=(0, 0.03 + 0.025 * ((len(entries) + 1) // 2), 1, 1))
    fig.set_label("energy_error")  # the file name Result.save gives it
    return fig

