"""What a scene's run produced (:class:`Result`): its summary, figures, and the
files it saves (summary, figures, the states as netCDF)."""

from __future__ import annotations

import json
import math
import os
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits.scenes.base import format_table, format_value
from hamilton_orbits.units import time_quantity

__all__ = ["Result"]


@dataclass
class Result:
    """What a scene's run produced.

    Attributes
    ----------
    scene : hamilton_orbits.scene.Scene
    times : Quantity
        The output times.
    diagnostics : dict
        Named series on ``times`` (energy error, angular-momentum error, ...).
    metrics : dict
        Headline numbers (Quantities or floats), e.g. the perihelion advance.
    tables : dict
        Named tables (lists of row dicts), e.g. the per-body cross-check.
    states : dict
        Arrays to save (``names``, ``r``, ``v`` for n-body scenes).
    complete : bool
        False if the run was stopped early (Ctrl-C); what was done is kept.
    interrupted : bool
        True if a Ctrl-C cut what followed a complete run (the cross-check against
        rebound, then skipped); the run's results are kept.
    frame : str
        The axes of the states (and their origin), named in the summary.
    time_origin : str
        What time 0 of ``times`` is (an epoch, a fit's epoch, each prediction's
        start), written into ``states.nc``.
    wall_time : float
        Seconds of the integration proper: no compilation (see ``compile_time``).
    resumed_from : Quantity or None
        The simulation time a resumed run went on from (``hamilton-orbits
        resume``): ``wall_time`` is then that of the part after it alone.
    compile_time : float
        Seconds spent compiling kernels during the run (numba's compile events;
        0 when everything came from the cache), apart from ``wall_time``.
    compile_count : int
        How many kernels were compiled during the run.
    compiled : list of (str, float)
        Which kernels were compiled (``module.function``, with the functions it
        calls) and the seconds of each, in order.
    units : dict
        The unit system the times and states are held in (``{"time": u.d,
        "length": u.au, ...}``): the arrays are the run's own floats, wrapped as
        Quantities without a copy; what reads them as floats in these units gets
        the same memory back.
    """

    scene: Any
    times: u.Quantity
    diagnostics: dict[str, Any] = field(default_factory=dict)
    metrics: dict[str, Any] = field(default_factory=dict)
    tables: dict[str, list[dict]] = field(default_factory=dict)
    states: dict[str, Any] = field(default_factory=dict)
    wall_time: float = 0.0
    resumed_from: Any = None
    complete: bool = True
    interrupted: bool = False
    frame: str = ""
    time_origin: str = ""
    compile_time: float = 0.0
    compile_count: int = 0
    compiled: list[tuple[str, float]] = field(default_factory=list)
    units: dict[str, Any] = field(default_factory=dict)
    plotters: list[Callable[[Result], Any]] = field(default_factory=list, repr=False)
    #: what :meth:`save` could not write, and why (figures without matplotlib)
    not_saved: list[str] = field(default_factory=list, repr=False)
    writers: list[Callable[[Result, Path], list[Path]]] = field(default_factory=list,
                                                                repr=False)

    def __repr__(self) -> str:  # a few lines: names and sizes, not the arrays
        n = len(self.times)
        span = f"{format_value(self.times[-1] - self.times[0])}" if n else "no time"
        return (f"Result(scene {self.scene.name!r}, {n} outputs over {span}, "
                f"complete={self.complete}; diagnostics: {', '.join(self.diagnostics) or 'none'}"
                f"; {len(self.metrics)} metrics (see .summary()); tables: "
                f"{', '.join(self.tables) or 'none'}; states: {', '.join(self.states) or 'none'})")

    def summary(self) -> str:
        """The summary table as text (what the command prints)."""
        s = self.scene
        lines = [f"scene {s.name} ({s.kind}): {s.spec.get('description', '').strip()}"]
        if s.changed:  # (the description is the file's: what was set since, said)
            lines.append("set since the scene's file: " + ", ".join(
                f"{k} = {v}" for k, v in s.changed.items()))
        effects = ", ".join(e["name"] for e in s.effects) or "none"
        lines.append(f"effects: {effects}")
        if self.frame:
            lines.append(f"frame: {self.frame}")
        if not self.complete:
            lines.append("STOPPED EARLY: the results cover the part that was run")
        span = self.times[-1] - self.times[0] if len(self.times) else 0 * u.d
        asked = s.spec.get("duration")
        if isinstance(asked, u.Quantity) and asked.unit.physical_type == "time":
            span = span.to(asked.unit)
        elif span > 1 * u.yr:
            span = span.to(u.yr)
        since = ("" if self.resumed_from is None else
                 f" since the resume at t = {format_value(self.resumed_from.to(span.unit))}")
        lines.append(f"simulated: {format_value(span)} in {self.wall_time:.2f} s of integration"
                     f"{since} (compilation apart)")
        if self.compile_count:
            from hamilton_orbits.firstrun import describe  # numba: only once compiled

            what = f" ({describe(self.compiled)})" if self.compiled else ""
            lines.append(f"compiled: {self.compile_count} numba kernels in "
                         f"{self.compile_time:.2f} s{what}; first run only: cached for later "
                         "runs")
        else:
            lines.append("compiled: nothing (every kernel loaded from numba's cache)")
        if self.metrics:
            lines.append("")
            rows = [{"quantity": k, "value": v} for k, v in self.metrics.items()]
            lines.append(format_table(rows))
        for title, rows in self.tables.items():
            lines.append("")
            lines.append(title)
            lines.append(format_table(rows))
        return "\n".join(lines)

    def plot(self) -> list:
        """The scene's figures (matplotlib), one per plotter."""
        try:
            import matplotlib

            matplotlib.use("Agg", force=False)
        except ImportError as exc:  # pragma: no cover - depends on the install
            raise ImportError(
                "figures need matplotlib: python -m pip install 'hamilton-orbits[plot]'"
            ) from exc
        return [p(self) for p in self.plotters]

    def _json(self) -> dict:
        def conv(v: Any) -> Any:
            v = time_quantity(v)  # (a TimeDelta set in Python: the Quantity in days)
            if isinstance(v, u.Quantity):  # (a non-finite value as a string: strict JSON)
                return {"value": conv(v.value.tolist()) if np.ndim(v) == 0 else
                        [conv(x) for x in v.value.tolist()], "unit": str(v.unit)}
            if isinstance(v, np.ndarray):
                return v.tolist()
            if isinstance(v, list | tuple):  # (a value set as a list or a table: each
                return [conv(x) for x in v]  # TimeDelta or Quantity in it with its unit)
            if isinstance(v, dict):
                return {k: conv(x) for k, x in v.items()}
            if isinstance(v, float) and not math.isfinite(v):
                return str(v)
            if isinstance(v, np.floating | np.integer):
                return v.item()
            time = sys.modules.get("astropy.time")  # (an effect's epoch as a Time: its ISO
            if time is not None and isinstance(v, time.Time):  # text and scale)
                return {"time": np.asarray(v.isot).tolist(), "scale": v.scale}
            return v

        return {
            "scene": self.scene.name,
            "kind": self.scene.kind,
            "description": self.scene.spec.get("description", ""),
            "set": {k: conv(v) for k, v in self.scene.changed.items()},
            "effects": [{k: conv(v) for k, v in e.items()} for e in self.scene.effects],
            "complete": self.complete,
            "frame": self.frame,
            "wall_time_s": self.wall_time,
            "resumed_from": None if self.resumed_from is None else conv(self.resumed_from),
            "compile_time_s": self.compile_time,
            "compile_count": self.compile_count,
            "metrics": {k: conv(v) for k, v in self.metrics.items()},
            "tables": {k: [{c: conv(x) for c, x in r.items()} for r in rows]
                       for k, rows in self.tables.items()},
        }

    def save(self, directory: str | Path) -> list[Path]:
        """Write the summary (Markdown, JSON), the figures (PNG) and the states (netCDF).

        A scene kind may add files (n-body scenes: the final state as a rebound
        binary, ``final.bin``).  Returns the paths written.  The states file is
        netCDF-3 (scipy's writer), which xarray, netCDF4 and ``ncdump`` read.  The
        figures need matplotlib (the ``plot`` extra): without it they are left out,
        the rest written, and :attr:`not_saved` says so.

        Parameters
        ----------
        directory : str or Path
            The folder to write into (made, with its parents, if missing).

        Returns
        -------
        list of Path
            The files written.

        Raises
        ------
        FileExistsError
            For a ``directory`` that is a file (the message names the path);
            nothing is written.
        """
        out = Path(directory)
        try:
            out.mkdir(parents=True, exist_ok=True)
        except FileExistsError as exc:  # (a file of its name: os.mkdir says "File exists")
            raise FileExistsError(
                f"Expected `directory` to be a folder, got {str(out)!r}, a file: give a "
                "folder to write the results into (made if missing), or move the file"
            ) from exc
        written = []
        md = out / "summary.md"
        md.write_text(f"# {self.scene.name}\n\n```\n{self.summary()}\n```\n", encoding="utf-8")
        written.append(md)
        js = out / "summary.json"
        js.write_text(json.dumps(self._json(), indent=2, default=str) + "\n",  # (any other
                      encoding="utf-8")  # value as its text, not a failure after the run)
        written.append(js)
        written.extend(self._save_states(out))
        for writer in self.writers:
            written.extend(writer(self, out))
        self.not_saved = []
        if self.plotters and not _can_draw():
            # (an extra: the states and summaries are written all the same, last
            # the figures, each run's own)
            self.not_saved.append("figures: matplotlib is not installed (python -m pip "
                                  "install 'hamilton-orbits[plot]')")
        elif self.plotters:
            import matplotlib.pyplot as plt

            for i, fig in enumerate(self.plot()):
                name = fig.get_label() or f"figure{i + 1}"
                path = out / f"{name}.png"
                fig.savefig(path, dpi=110, bbox_inches="tight")
                plt.close(fig)
                written.append(path)
        return written

    def _save_states(self, out: Path) -> list[Path]:
        """``states.nc``, written whole under a temporary name and then renamed (a
        write that fails leaves no torn file); its text attributes UTF-8 (scipy's
        writer took only ASCII: a scene named ``mé`` lost its files)."""
        path = out / "states.nc"
        tmp = out / f".states.nc.tmp-{os.getpid()}"
        try:
            self._write_states(tmp)
            os.replace(tmp, path)
        finally:
            tmp.unlink(missing_ok=True)
        return [path]

    def _write_states(self, path: Path) -> None:
        from scipy.io import netcdf_file

        t = np.asarray(self.times.value, dtype=float)  # (the run's own floats and unit)
        with netcdf_file(path, "w") as f:
            f.title = _utf8(f"hamilton-orbits scene {self.scene.name}")
            if self.frame:
                f.frame = _utf8(self.frame)
            f.createDimension("time", len(t))
            var = f.createVariable("time", "d", ("time",))
            var[:] = t
            var.units = _utf8(str(self.times.unit))
            if self.time_origin:
                var.time_origin = _utf8(self.time_origin)
            names = self.states.get("names")
            if names is not None:
                _write_names(f, [str(n) for n in names])
            for name, series in self.diagnostics.items():
                if isinstance(series, dict):  # what a figure marks, not a time series
                    continue
                arr = np.asarray(getattr(series, "value", series), dtype=float)
                if arr.shape != t.shape:
                    continue
                var = f.createVariable(name, "d", ("time",))
                var[:] = arr
                var.units = _utf8(str(getattr(series, "unit", "")))
            for name, value in self.states.items():
                arr = np.asarray(getattr(value, "value", value))
                if arr.dtype.kind not in "fi" or arr.ndim == 0:
                    continue
                dims = ["time"] + [f"{name}_dim{k}" for k in range(1, arr.ndim)]
                if arr.shape[0] != len(t):
                    continue
                if names is not None and arr.ndim == 3 and arr.shape[1:] == (len(names), 3):
                    dims[1:] = ["body", "xyz"]  # (shared with the names, as to_xarray has)
                for k in range(1, arr.ndim):
                    if dims[k] not in f.dimensions:
                        f.createDimension(dims[k], arr.shape[k])
                var = f.createVariable(name, "d", tuple(dims))
                var[:] = arr
                var.units = _utf8(str(getattr(value, "unit", "")))
            if names is not None:  # (kept beside the variable: files read it so far)
                f.bodies = _utf8(",".join(str(n) for n in names))


def _write_names(f: Any, names: list[str]) -> None:
    """The body names as the coordinate variable ``body`` (UTF-8 characters, as
    xarray decodes them to strings), on the dimension ``body``; ``xyz`` too."""
    data = [n.encode("utf-8") for n in names]
    width = max([1] + [len(b) for b in data])
    f.createDimension("body", len(names))
    f.createDimension("xyz", 3)
    f.createDimension("name_length", width)
    var = f.createVariable("body", "c", ("body", "name_length"))
    if data:
        var[:] = np.array([np.frombuffer(b.ljust(width, b"\0"), dtype="S1") for b in data])
    var._Encoding = "utf-8"


def _utf8(text: str) -> bytes:
    """A text attribute of a netCDF-3 file: its UTF-8 bytes (``char``, as netCDF-C
    writes text; xarray reads it back as the ``str``)."""
    return text.encode("utf-8")


def _can_draw() -> bool:
    """Whether matplotlib (the ``plot`` extra) imports."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return False
    return True
