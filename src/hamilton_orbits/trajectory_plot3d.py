"""The interactive 3-D view of a :class:`~hamilton_orbits.trajectory.Trajectory`
(:func:`plot_trajectory3d`, ``Trajectory.plot3d()``), drawn with plotly.

What it draws: each chosen body's path as a line, an open circle where it
starts, a filled marker where it is at the last output, and the origin body (if
any) as a cross at the origin; a time slider (with play and pause buttons) moves
the markers along the paths.  The axes name their origin and unit, as
``Trajectory.plot()`` does, and keep the data's aspect (``aspectmode="data"``),
so that a circle looks like one.  plotly is an optional dependency (the
``plot3d`` extra: ``pip install 'hamilton-orbits[plot3d]'``).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from hamilton_orbits.trajectory_plot import (
    AU_KM,
    PLAIN_UNIT,
    SMALL_EXTENT_AU,
    primary_index,
    within_extent,
)

__all__ = ["MAX_FRAMES", "plot_trajectory3d"]

MAX_FRAMES = 200
"""The default largest number of slider steps (animation frames) of a figure."""

_ORIGINS = ("primary", "frame")


def plot_trajectory3d(traj: Any, bodies: Sequence[str] | None = None,
                      origin: str = "primary", unit: Any = None,
                      max_frames: int = MAX_FRAMES) -> Any:
    """An interactive 3-D figure of ``traj``'s paths with a time slider.

    Parameters
    ----------
    traj : Trajectory
    bodies : sequence of str, optional
        The bodies drawn, by name (default: all but the origin body).
    origin : str, default "primary"
        Where the axes start: ``"primary"`` (the most massive body at the end of
        the run, as ``Trajectory.plot()``), a body's name, or ``"frame"`` (the
        origin of the coordinates the system was integrated in).
    unit : str or astropy.units.Unit, optional
        The length unit of the axes, for a trajectory of Quantities (default:
        au, or km where every path stays within 0.01 au of the origin); a
        trajectory of plain floats has no unit to convert.
    max_frames : int, default 200
        The most slider steps: the outputs are subsampled evenly (the first and
        the last always kept) to at most this many animation frames, so that a
        figure of a long run stays small.  The lines always use every output.

    Returns
    -------
    plotly.graph_objects.Figure
        Per body three traces, in this order: its path (named after it), its
        start (``"<name> start"``) and its position (``"<name> now"``, at the last
        output; the frames move it).  Show it with ``fig.show()``, or save a
        page that works offline with ``fig.write_html(path, include_plotlyjs=True)``
        (about 5 MB, most of it plotly.js; add ``auto_play=False`` for the page to
        open at the last output rather than play the frames from the start).

    Raises
    ------
    ImportError
        Without plotly (install the ``plot3d`` extra).
    ValueError
        For an unknown body or origin, a unit on a trajectory of plain floats or
        one that is not a length, or ``max_frames`` below 2.

    Examples
    --------
    >>> from hamilton_orbits import Body, System, integrate
    >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
    ...             Body("earth", 3e-6, [1.0, 0, 0], [0, 1.0, 0])])
    >>> fig = integrate(s, np.linspace(0, 2 * np.pi, 500)).plot3d()
    >>> fig.layout.scene.xaxis.title.text
    "x from sun [the system's length unit]"
    >>> len(fig.frames)
    200
    """
    go = _plotly()
    names = tuple(traj.names)
    r, unit_name = _positions(traj, unit)
    centre = _centre(traj, origin)
    shown = _bodies(names, bodies, centre)
    if isinstance(max_frames, bool) or not isinstance(max_frames, (int, np.integer)) \
            or max_frames < 2:
        raise ValueError(f"Expected `max_frames` to be an integer >= 2, got {max_frames!r}")
    rel = r if centre is None else r - r[:, centre:centre + 1]
    if unit is None and unit_name is not None and within_extent(rel, SMALL_EXTENT_AU):
        rel, unit_name = rel * AU_KM, "km"  # (as Trajectory.plot: a satellite's in km)
    keep = np.unique(np.linspace(0, r.shape[0] - 1, min(r.shape[0], int(max_frames)))
                     .round().astype(int))
    fig = go.Figure(data=_traces(go, rel, names, shown, centre))
    fig.frames = [go.Frame(name=str(k), data=_markers(go, rel[k], names, shown),
                           traces=[3 * i + 2 for i in range(len(shown))]) for k in keep]
    _layout(fig, traj, names, centre, unit_name, keep)
    return fig


def _plotly() -> Any:
    try:
        import plotly.graph_objects as go
    except ImportError as err:  # pragma: no cover - exercised where plotly is absent
        raise ImportError(
            "Trajectory.plot3d needs plotly, an optional dependency: "
            "pip install 'hamilton-orbits[plot3d]' (or pip install plotly)") from err
    return go


def _positions(traj: Any, unit: Any) -> tuple[np.ndarray, str | None]:
    """The positions as floats in the chosen unit, and the unit's name (None for floats)."""
    if not hasattr(traj.r, "unit"):
        if unit is not None:
            raise ValueError(f"Expected `unit` to be None for a trajectory of plain floats "
                             f"(no unit to convert from), got {unit!r}")
        return np.asarray(traj.r, dtype=float), None
    import astropy.units as u

    try:
        target = traj.r.unit if unit is None else u.Unit(unit)
        r = traj.r.to_value(target)
    except (ValueError, TypeError, u.UnitsError) as err:
        raise ValueError(f"Expected `unit` to be a unit of length, got {unit!r}") from err
    return np.asarray(r, dtype=float), target.to_string()


def _centre(traj: Any, origin: str) -> int | None:
    """The index of the origin body, or None for the integration frame's origin."""
    if origin == "primary":
        return primary_index(traj)
    if origin == "frame":
        return None
    if isinstance(origin, str) and origin in traj.names:
        return int(traj.names.index(origin))
    raise ValueError(f"Expected `origin` to be one of {list(_ORIGINS)} or a body's name "
                     f"{list(traj.names)}, got {origin!r}")


def _bodies(names: tuple[str, ...], bodies: Sequence[str] | None,
            centre: int | None) -> list[int]:
    """The indices of the bodies drawn (default: all but the origin body)."""
    if bodies is None:
        return [k for k in range(len(names)) if k != centre]
    if isinstance(bodies, str):
        raise ValueError(f"Expected `bodies` to be a sequence of body names, got {bodies!r}")
    shown = []
    for i, name in enumerate(bodies):
        if name not in names:
            raise ValueError(f"Expected `bodies[{i}]` to be one of {list(names)}, "
                             f"got {name!r}")
        shown.append(names.index(name))
    if not shown:
        raise ValueError("Expected `bodies` to name at least one body, got []")
    return shown


_COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
            "#7f7f7f", "#bcbd22", "#17becf")


def _traces(go: Any, rel: np.ndarray, names: tuple[str, ...], shown: list[int],
            centre: int | None) -> list[Any]:
    """Path, start and position at the last output of each shown body; then the origin."""
    traces = []
    for k in shown:
        colour = _COLOURS[k % len(_COLOURS)]
        x, y, z = rel[:, k].T
        traces.append(go.Scatter3d(x=x, y=y, z=z, mode="lines", name=names[k],
                                   legendgroup=names[k], line={"color": colour, "width": 3},
                                   hoverinfo="name"))
        traces.append(go.Scatter3d(x=x[:1], y=y[:1], z=z[:1], mode="markers",
                                   name=f"{names[k]} start", legendgroup=names[k],
                                   showlegend=False, hoverinfo="name",
                                   marker={"symbol": "circle-open", "size": 6,
                                           "color": colour}))
        traces.extend(_markers(go, rel[-1], names, [k]))
    if centre is not None:
        traces.append(go.Scatter3d(x=[0.0], y=[0.0], z=[0.0], mode="markers",
                                   name=f"{names[centre]} (origin)", hoverinfo="name",
                                   marker={"symbol": "cross", "size": 5, "color": "black"}))
    return traces


def _markers(go: Any, row: np.ndarray, names: tuple[str, ...], shown: list[int]) -> list[Any]:
    """The shown bodies' markers at one output ``row`` (shape (n, 3)); the colours
    follow the order of ``names``, as the paths' do."""
    return [go.Scatter3d(x=row[k, :1], y=row[k, 1:2], z=row[k, 2:3], mode="markers",
                         name=f"{names[k]} now", legendgroup=names[k], showlegend=False,
                         hoverinfo="name",
                         marker={"size": 5, "color": _COLOURS[k % len(_COLOURS)]})
            for k in shown]


def _time_labels(traj: Any, keep: np.ndarray) -> list[str]:
    t = traj.t
    unit = f" {t.unit.to_string()}" if hasattr(t, "unit") else ""
    values = np.asarray(getattr(t, "value", t), dtype=float)
    return [f"{values[k]:.6g}{unit}" for k in keep]


def _layout(fig: Any, traj: Any, names: tuple[str, ...], centre: int | None,
            unit: str | None, keep: np.ndarray) -> None:
    """Axis titles (origin and unit), equal aspect, the slider and play/pause buttons."""
    where = " (integration frame)" if centre is None else f" from {names[centre]}"
    suffix = f" [{unit or PLAIN_UNIT}]"
    axes = {f"{c}axis": {"title": {"text": f"{c}{where}{suffix}"}} for c in "xyz"}
    animate = {"mode": "immediate", "frame": {"duration": 0, "redraw": True},
               "transition": {"duration": 0}}
    labels = _time_labels(traj, keep)
    steps = [{"method": "animate", "label": label, "args": [[str(k)], animate]}
             for k, label in zip(keep, labels, strict=True)]
    play = {"frame": {"duration": 40, "redraw": True}, "transition": {"duration": 0},
            "fromcurrent": True, "mode": "immediate"}
    fig.update_layout(
        scene={"aspectmode": "data", **axes},
        title={"text": f"{traj.method}: paths{where} (open circle: start)"},
        sliders=[{"active": len(steps) - 1, "steps": steps, "currentvalue": {"prefix": "t = "},
                  "x": 0.16, "len": 0.84, "pad": {"t": 30}}],
        updatemenus=[{"type": "buttons", "showactive": False, "x": 0.0, "y": 0.0,
                      "xanchor": "left", "yanchor": "top", "direction": "left",
                      "pad": {"t": 60, "r": 10},
                      "buttons": [{"label": "play", "method": "animate",
                                   "args": [None, play]},
                                  {"label": "pause", "method": "animate",
                                   "args": [[None], animate]}]}],
        margin={"l": 0, "r": 0, "t": 40, "b": 0},
    )
