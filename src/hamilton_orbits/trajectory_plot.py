"""The figure of a :class:`~hamilton_orbits.trajectory.Trajectory`: every body's
path about the primary (:func:`plot_trajectory`, ``Trajectory.plot()``).

What it draws: each body's positions relative to the primary (the most massive
body at the end of the run) in the chosen plane, a line through the outputs (dots
when they are too sparse for a line to follow the orbit), an open circle where
the body starts with an arrow along its first motion (along -v on a backward run:
the way the path is drawn, in the outputs' order), a filled dot where it ends,
and the primary as a cross at the origin.  A merge (``traj.events``) breaks the
kept body's line (no path joins its last output before the merge to the merged
body's first) and is marked with a red cross at the merged body's first output;
the absorbed body's path stops at its last output, with no end dot.  Every axis
names its origin and unit (au for a Quantity system, km where every path stays
within 0.01 au of the primary, the system's own length unit otherwise); the aspect
is equal, so that a circle looks like one; the legend is placed outside the axes
when there are more than a few bodies.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["AU_KM", "PLAIN_UNIT", "SMALL_EXTENT_AU", "plot_trajectory", "primary_index",
           "within_extent"]

_PLANES = {"xy": (0, 1), "xz": (0, 2), "yz": (1, 2)}


#: the unit an axis of a system of plain numbers names (its own, whatever it is)
PLAIN_UNIT = "the system's length unit"
#: a Quantity trajectory whose paths about the primary stay within this many au is
#: drawn in km (as the scenes' orbit figures are)
SMALL_EXTENT_AU = 0.01
#: km in an au (IAU 2012 Resolution B2: exactly 149 597 870 700 m)
AU_KM = 149_597_870.7


def plot_trajectory(traj: Any, plane: str = "xy", ax: Any = None) -> Any:
    """Draw ``traj``'s paths about its primary; returns the matplotlib Figure.

    Parameters
    ----------
    traj : Trajectory
    plane : {"xy", "xz", "yz"}
        The coordinate plane drawn.
    ax : matplotlib Axes, optional
        Draw into these axes (default: a new figure).

    Raises
    ------
    ValueError
        For an unknown ``plane``.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> from hamilton_orbits import Body, System, integrate
    >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
    ...             Body("earth", 3e-6, [1.0, 0, 0], [0, 1.0, 0])])
    >>> fig = integrate(s, np.linspace(0, 2 * np.pi, 100)).plot()
    >>> fig.axes[0].get_xlabel()
    "x from sun [the system's length unit]"
    """
    import matplotlib.pyplot as plt

    if plane not in _PLANES:
        raise ValueError(f"Expected `plane` to be one of {sorted(_PLANES)}, got {plane!r}")
    i, j = _PLANES[plane]
    r = np.asarray(getattr(traj.r, "value", traj.r))
    unit = traj.r.unit.to_string() if hasattr(traj.r, "unit") else None
    v = np.asarray(getattr(traj.v, "value", traj.v))
    primary = primary_index(traj)
    rel = r if primary is None else r - r[:, primary:primary + 1]
    vel = v[0] if primary is None else v[0] - v[0, primary]
    t = np.asarray(getattr(traj.t, "value", traj.t), dtype=float).ravel()
    if t.size > 1 and t[-1] < t[0]:  # a backward run: drawn along -v (the outputs' order)
        vel = -vel
    if unit is not None and within_extent(rel, SMALL_EXTENT_AU):  # (a satellite's orbit in
        # au: ticks of +-4 under an offset of 1e-5)
        rel, unit = rel * AU_KM, "km"
    if ax is None:  # (constrained: the legend beside the axes, past five bodies, is kept
        # within the figure; it was cut off by savefig)
        fig, ax = plt.subplots(figsize=(6.5 if len(traj.names) <= 5 else 8.0, 6),
                               layout="constrained")
    else:
        fig = ax.figure
    merges = _merges(traj, r)
    for k, name in enumerate(traj.names):
        if k != primary:
            breaks = [m for kept, _, m, _ in merges if kept == k]
            absorbed = any(gone == k for _, gone, _, _ in merges)
            _path(ax, rel[:, k, i], rel[:, k, j], (vel[k, i], vel[k, j]), name,
                  breaks, absorbed)
    for n, (kept, gone, m, when) in enumerate(merges):
        ax.plot(rel[m, kept, i], rel[m, kept, j], "X", color="crimson", ms=8, mec="k",
                mew=0.5, gid="merge", label=("merge (the merged body's first output)"
                                             if n == 0 else "_nolegend_"))
        ax.annotate(f"{traj.names[gone]} into {traj.names[kept]}, t = {when}",
                    (rel[m, kept, i], rel[m, kept, j]), xytext=(-8, 6),
                    textcoords="offset points", fontsize=7, color="crimson", ha="right")
    about = "the frame's origin" if primary is None else traj.names[primary]
    ax.plot([0.0], [0.0], "k+", ms=10, mew=1.5,
            label=about if primary is None else f"{about} (primary)")
    suffix = f" [{unit or PLAIN_UNIT}]"
    ax.set_xlabel(f"{'xyz'[i]} from {about}{suffix}")
    ax.set_ylabel(f"{'xyz'[j]} from {about}{suffix}")
    ax.set_aspect("equal", adjustable="datalim")
    t_unit = f" {traj.t.unit.to_string()}" if hasattr(traj.t, "unit") else (
        " (the system's time unit)")
    span = (f", t = {t[0]:.4g}{t_unit}" if t.size == 1 else
            f", t = {t[0]:.4g} \N{RIGHTWARDS ARROW} {t[-1]:.4g}{t_unit}"
            + (" (backwards)" if t[-1] < t[0] else "")) if t.size else ""
    ax.set_title(f"{traj.method}: paths about {about}{span}\n"
                 f"(open circle: start; dot: end)" + (
                     "\n(an absorbed body's path ends at its last output before the merge)"
                     if merges else ""), fontsize=10)
    if len(traj.names) > 5:
        ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8, frameon=False)
    else:
        ax.legend(loc="best", fontsize=8)
    return fig


def within_extent(rel: np.ndarray, extent: float) -> bool:
    """Whether every finite position of ``rel`` (n_t, n, 3) is within ``extent`` of
    the origin (and there is one).

    Examples
    --------
    >>> within_extent(np.array([[[3e-5, 0, 0], [np.nan, 0, 0]]]), SMALL_EXTENT_AU)
    True
    """
    dist = np.linalg.norm(rel, axis=-1)
    dist = dist[np.isfinite(dist)]
    return bool(dist.size) and float(dist.max()) <= extent


def primary_index(traj: Any) -> int | None:
    """The index of the most massive body at the end of the run (None for bodies in a
    field, none of which pulls: the frame's origin is theirs), which the figures
    draw the paths about.

    Examples
    --------
    >>> from hamilton_orbits import Body, System, integrate
    >>> s = System([Body("p", 1e-3, [1.0, 0, 0], [0, 1.0, 0]),
    ...             Body("sun", 1.0, [0, 0, 0], [0, 0, 0])])
    >>> primary_index(integrate(s, 1.0))
    1
    """
    try:
        final = traj.final
    except ValueError:
        return None
    gm = np.atleast_1d(final.as_arrays().gm)
    return int(traj.names.index(final.names[int(np.argmax(gm))]))


def _merges(traj: Any, r: np.ndarray) -> list[tuple[int, int, int, str]]:
    """The merges of ``traj.events``: (the body kept, the body absorbed, the first
    output after the merge, its time as text), the absorbed body the one of the pair
    whose positions end at that output (NaN after it)."""
    try:
        events = traj.events
    except (AttributeError, ValueError):
        return []
    names = list(traj.names)
    pairs = {f"{a}-{b}": (ka, kb) for ka, a in enumerate(names)
             for kb, b in enumerate(names) if ka != kb}
    t = np.asarray(getattr(traj.t, "value", traj.t), dtype=float)
    found = np.isfinite(r).all(axis=-1)  # (n_t, n)
    out = []
    for row in events:
        pair = pairs.get(str(row["bodies"]))
        if str(row["action"]) != "merge" or pair is None:
            continue
        time = row["time"]
        when = float(getattr(time, "value", time))
        ends = {}
        for k in pair:  # the output after each one's last
            last = np.flatnonzero(found[:, k])
            if last.size and last[-1] + 1 < len(t):
                ends[k] = int(last[-1]) + 1
        if not ends:
            continue
        gone = min(ends, key=lambda k: abs(t[ends[k]] - when))
        kept = pair[0] if gone == pair[1] else pair[1]
        unit = f" {time.unit.to_string()}" if hasattr(time, "unit") else ""
        out.append((kept, gone, ends[gone], f"{when:.4g}{unit}"))
    return out


def _path(ax: Any, x: np.ndarray, y: np.ndarray, v0: tuple[float, float], name: str,
          breaks: list[int] = (), absorbed: bool = False) -> None:
    """One body's path: a line (dots when the outputs are sparse), its start with an
    arrow along ``v0`` (its motion as drawn), and its end (none for a body absorbed in a merge:
    its path stops at its last output before it); the line broken (a NaN) before
    each output index of ``breaks``, the first after a merge that kept it."""
    ok = np.isfinite(x) & np.isfinite(y)  # a body an event took out ends there
    at = [int(np.count_nonzero(ok[:m])) for m in breaks]
    x, y = x[ok], y[ok]
    if x.size == 0:
        return
    steps = np.hypot(np.diff(x), np.diff(y))
    extent = max(float(np.ptp(x)), float(np.ptp(y)), float(np.hypot(x[0], y[0])), 1e-300)
    sparse = steps.size > 0 and float(np.median(steps)) > 0.2 * extent
    (line,) = ax.plot(np.insert(x, at, np.nan), np.insert(y, at, np.nan),
                      "." if sparse else "-", lw=0.9, ms=3, label=name)
    color = line.get_color()
    ax.plot(x[0], y[0], "o", color=color, mfc="none", ms=7)  # (its colour given: the
    # cycle then moves on by one a body, the same body the same colour in every figure)
    if not absorbed:
        ax.plot(x[-1], y[-1], "o", color=color, ms=4)
    speed = float(np.hypot(*v0))
    if speed > 0 and np.isfinite(speed):  # the direction of motion at the start
        d = 0.12 * extent / speed
        ax.annotate("", xy=(x[0] + v0[0] * d, y[0] + v0[1] * d), xytext=(x[0], y[0]),
                    arrowprops={"arrowstyle": "->", "color": color, "lw": 1.2})
