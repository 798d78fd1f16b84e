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
    """MEGNO against time (``variational = true``)."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4))
    t = result.times.to_value(u.yr)
    ax.plot(t, result.diagnostics["megno"], lw=0.8, label="MEGNO <Y>")
    ax.axhline(2.0, color="0.6", lw=0.6, ls=":", label="2 (quasi-periodic)")
    ax.set_xlabel("time [yr]")
    ax.set_ylabel("MEGNO <Y> (dimensionless)")
    ax.set_title(f"{result.scene.name}: MEGNO")
    ax.legend()
    fig.set_label("megno")  # the file name Result.save gives it
    return fig



def plot_de440(result: Result):
    """The position residuals against DE440 against time, one line a body."""
    import matplotlib.pyplot as plt

    from hamilton_orbits.studies.ladder import BODIES

    fig, ax = plt.subplots(figsize=(7, 4.5))
    years = result.diagnostics["de440_years"]
    km = result.diagnostics["de440_km"]
    colors = plt.cm.tab20(np.arange(len(BODIES)) / len(BODIES))
    for k, body in enumerate(BODIES):
        moon = body == "moon"
        ax.semilogy(years[1:], np.maximum(km[1:, k], 1e-6), lw=1.4 if moon else 1,
                    ls="--" if moon else "-", color="k" if moon else colors[k],
                    label="moon (from the earth)" if moon else body)
    ax.set_xlabel("time from J2000 [yr]")
    ax.set_ylabel("position residual against DE440 [km]")
    ax.set_title(f"{result.scene.name}: heliocentric residuals (the Moon geocentric), ICRS")
    ax.legend(fontsize=7, ncol=2)
    fig.set_label("de440_residuals")  # the file name Result.save gives it
    return fig



def orbit_view(names: list[str], gm: np.ndarray, r: np.ndarray) -> dict[str, Any]:
    """What the orbit figure draws: positions relative to the primary (the most
    massive body), in km below 0.01 au of extent and au above, and the bodies of an
    inner panel (those inside the largest gap, by a factor 2.5 or more, in the
    bodies' largest distances from the primary, when the outermost is 5 times
    farther).

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
    reach = np.linalg.norm(rel, axis=-1).max(axis=0)
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
    return {"primary": names[k], "rel": rel * scale, "unit": unit, "inner": inner,
            "reach": reach * scale, "scale": scale, "index": k}


def _coarse(cadence: float, r: np.ndarray, v: np.ndarray, mu: float) -> bool:
    """True if the outputs are more than a 36th of the two-body period apart (10
    degrees of mean anomaly: a line would draw chords, or, at a cadence near the
    period, a short stroke where the orbit is): then dots are drawn."""
    energy = 0.5 * float(v @ v) - mu / float(np.linalg.norm(r))
    if not energy < 0:
        return False
    period = 2 * np.pi * np.sqrt((-mu / (2 * energy)) ** 3 / mu)
    return bool(cadence > period / 36)


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


def _draw_orbits(ax: Any, view: dict, names: list[str], frame: str) -> None:
    primary = view["primary"]
    for k, name in enumerate(view["names"]):
        if name not in names or name == primary:
            continue
        xy = view["rel"][:, k, :2]
        if not _coarse(view["cadence"], view["rel0"][k], view["vrel0"][k], view["mu"][k]):
            ax.plot(xy[:, 0], xy[:, 1], lw=0.7, label=name)
            continue
        # outputs too far apart for a line: a dot per output, and the osculating
        # two-body orbit of the first output as a thin line to read them against
        (dots,) = ax.plot(xy[:, 0], xy[:, 1], ".", ms=1.2,
                          label=f"{name} (a dot every {view['cadence_text']})")
        ellipse = osculating_ellipse(view["rel0"][k], view["vrel0"][k], view["mu"][k])
        if ellipse is not None:
            ax.plot(ellipse[:, 0], ellipse[:, 1], lw=0.4, color=dots.get_color(), alpha=0.8)
    ax.plot([0.0], [0.0], "o", color="orange", mec="k", mew=0.4, ms=6,
            label=f"{primary} (origin)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(axis_label("x", view["unit"], frame, primary), fontsize=8)
    ax.set_ylabel(axis_label("y", view["unit"], frame, primary), fontsize=8)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.09), ncol=2,
              frameon=False)


def plot_orbits(result: Result, gm: np.ndarray, frame: str):
    """The orbits about the primary, projected on the frame's x-y plane; an inner
    panel where the inner bodies would be a blob beside the outer ones."""
    import matplotlib.pyplot as plt

    names = list(result.states["names"])
    view = orbit_view(names, gm, result.states["r"].to_value(u.au))
    view["names"] = names
    k = view["index"]
    v0 = result.states["v"][0].to_value(u.au / u.d)
    view["rel0"] = view["rel"][0]  # in the figure's unit; velocities and mu to match
    view["vrel0"] = (v0 - v0[k]) * view["scale"]
    view["mu"] = (gm + gm[k]) * view["scale"] ** 3
    view["cadence"] = float(np.median(np.diff(result.times.to_value(u.d))))
    cadence = view["cadence"] * u.d
    unit = u.yr if cadence >= 100 * u.d else u.d if cadence >= 1 * u.d else u.min
    view["cadence_text"] = f"{cadence.to_value(unit):.3g} {unit}"
    panels = [names] + ([view["inner"]] if view["inner"] else [])
    fig, axes = plt.subplots(1, len(panels), figsize=(6.2 * len(panels), 7.2), squeeze=False)
    for ax, shown in zip(axes[0], panels, strict=True):
        _draw_orbits(ax, view, shown, frame)
    axes[0, 0].set_title(f"{result.scene.name}: orbits about {view['primary']}, "
                         f"projected on the frame's x-y plane", fontsize=10)
    if view["inner"]:
        axes[0, 1].set_title(f"inner bodies: {', '.join(view['inner'])}", fontsize=10)
    fig.tight_layout()
    fig.set_label("orbits")  # the file name Result.save gives it
    return fig


def plot_energy(result: Result, what: str, conserved: bool):
    """The relative energy error against time (log scale).  Exact zeros (the
    energy came back bit for bit) have no place on a log axis: they are counted
    in the legend, not drawn at an invented floor."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 4.2))
    span = result.times[-1] - result.times[0]
    t_unit = u.yr if span > 1 * u.yr else u.d
    t = result.times.to_value(t_unit)
    series = [("hamilton-orbits", result.diagnostics["energy_error"], {})]
    peer = result.diagnostics.get("rebound_energy_error")
    if peer is not None:
        series.append(("rebound IAS15", peer, {"alpha": 0.6}))
    for label, values, style in series:
        err = np.abs(np.asarray(values[1:], dtype=float))
        nonzero = err > 0
        zeros = int(np.count_nonzero(~nonzero))
        note = f" ({zeros} of {len(err)} outputs exactly 0, not drawn)" if zeros else ""
        ax.semilogy(t[1:][nonzero], err[nonzero], ".", ms=2, label=label + note, **style)
    eps = np.finfo(float).eps
    ax.axhline(eps, color="0.5", lw=0.7, ls=":", label=f"machine epsilon {eps:.1e}")
    if not ax.has_data() or not np.any(np.abs(result.diagnostics["energy_error"]) > 0):
        ax.set_ylim(eps / 100, eps * 100)
    ax.set_xlabel(f"time since the start [{t_unit}]")
    ax.set_ylabel("|relative energy error|" if conserved else "|relative energy change|")
    title = "energy error" if conserved else "energy change (not an error: not conserved)"
    ax.set_title(f"{result.scene.name}: {title}\nof {what}", fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.set_label("energy_error")  # the file name Result.save gives it
    return fig

