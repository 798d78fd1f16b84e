"""The run of an ``nbody`` scene (:func:`run_scene`): the scene's
:class:`~hamilton_orbits.Simulation`, one call over the output times (a progress
bar over the whole run; Ctrl-C keeps what is done), and the
:class:`~hamilton_orbits.scenes.result.Result` made of its trajectory: Hamilton's
integrals, the events, MEGNO, the analyses, the cross-check and the figures."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits import effects as _effects
from hamilton_orbits._progress import progress_bar
from hamilton_orbits.scenes.nbody.analyses import ANALYSIS_FUNCTIONS
from hamilton_orbits.scenes.nbody.build import (
    build_system,
    frame_note,
    output_times,
    scene_frame,
)
from hamilton_orbits.scenes.nbody.figures import plot_energy, plot_megno, plot_orbits
from hamilton_orbits.scenes.result import Result

#: The unit system of an ``nbody`` scene's states and times.
UNITS = {"time": u.d, "length": u.au, "speed": u.au / u.d}


def simulation(spec: dict, system: Any) -> Any:
    """The :class:`~hamilton_orbits.Simulation` of a validated ``nbody`` scene."""
    from hamilton_orbits import Simulation

    integ = spec["integrator"]
    options = {k: integ[k] for k in ("coordinates", "corrector") if integ[k] is not None}
    events = [{k: v for k, v in ev.items() if v is not None} for ev in spec["events"]]
    return Simulation(system, integ["method"], dt=integ["dt"], tol=integ["tol"],
                      effects=spec["effects"], events=events,
                      variational=bool(spec["variational"]), **options)


def run_scene(scene: Any, progress: bool = True, stop=lambda: False) -> Result:
    """Run a validated ``nbody`` scene (the kind's ``run``): its system and its
    :class:`~hamilton_orbits.Simulation`, one call over the output times, the
    analyses the scene asks for; ``stop()`` true (or Ctrl-C) ends the run early,
    keeping what is done."""
    spec = scene.spec
    system = build_system(spec)
    sim = simulation(spec, system)
    times = output_times(spec)
    bar = progress_bar(len(times) - 1, progress, "output")
    try:
        traj = sim.integrate(times, stop=stop, on_interrupt="keep",
                             on_output=None if bar is None else (lambda i, steps: bar.update(1)))
    finally:
        if bar is not None:
            bar.close()
    if len(traj.t) < 2:
        raise KeyboardInterrupt
    result = _result(scene, system, traj, sim.effects)
    _events_into(result, traj)
    _chaos_into(result, traj)
    for an in spec["analysis"]:
        ANALYSIS_FUNCTIONS[an["name"]](result, system, an)
    if spec["crosscheck"] and result.complete:
        _crosscheck_into(result, system, traj, sim.effects)
    return result


def _events_into(result: Result, traj: Any) -> None:
    """The events found: a table, their count, the first of each kind (what an
    ``Ensemble`` row carries), and what stopped the run."""
    if not result.scene.spec["events"]:
        return
    table, stopped = traj.events, traj.stopped_by
    result.metrics["events found"] = len(table)
    for name in dict.fromkeys(table["name"]):
        first = table[table["name"] == name][0]
        result.metrics[f"first {name} at"] = first["time"].to(u.yr)
        result.metrics[f"first {name} bodies"] = str(first["bodies"])
    if stopped is not None:
        result.metrics["stopped by"] = f"{stopped['name']} of {stopped['bodies']}"
    result.tables["events"] = [
        {"event": str(row["name"]), "time": row["time"].to(u.yr), "bodies": str(row["bodies"]),
         "distance": row["distance"], "speed": row["speed"].to(u.km / u.s),
         "action": str(row["action"])} for row in table]


def _chaos_into(result: Result, traj: Any) -> None:
    """With ``variational = true``: MEGNO and the Lyapunov exponent at the end (as
    rebound's ``sim.megno()`` and ``sim.lyapunov()``), the Lyapunov time
    ``1 / lyapunov`` (infinite when the exponent is not positive: no exponential
    growth measured), and MEGNO over time as a diagnostic and a figure."""
    if traj.megno is None:
        return
    lyap = traj.lyapunov[-1]
    result.diagnostics["megno"] = traj.megno
    result.metrics["MEGNO"] = float(traj.megno[-1])
    result.metrics["Lyapunov exponent"] = lyap.to(1 / u.yr)
    result.metrics["Lyapunov time"] = (1 / lyap).to(u.yr) if lyap.value > 0 else np.inf * u.yr
    result.plotters.append(plot_megno)


def _result(scene: Any, system: Any, traj: Any, effects: Any) -> Result:
    """The :class:`Result` of the scene's trajectory: states, Hamilton's integrals,
    figures, and the final state as a rebound binary (the states are the
    trajectory's arrays, wrapped in their units, not copied)."""
    gm = system.as_arrays().gm
    result = Result(
        scene=scene,
        times=traj.t,
        diagnostics={"energy_error": traj.energy_error,
                     "angular_momentum_error": traj.angular_momentum_error,
                     "barycentre_drift": traj.barycentre_drift},
        states={"names": list(system.names), "r": traj.r, "v": traj.v},
        wall_time=traj.wall_time,
        complete=traj.complete,
        units=UNITS,
    )
    result.metrics["integrator"] = traj.method
    result.metrics["steps"] = traj.steps
    what = _effects.energy_label(gm, effects, system.names)
    conserved = _effects.effect_energy(system, effects, traj.r.value[:1],
                                       traj.v.value[:1]) is not None
    result.metrics["energy"] = what
    key = "max |relative energy error|" if conserved else "max |relative energy change|"
    result.metrics[key] = float(np.max(np.abs(traj.energy_error)))
    frame = scene_frame(scene.spec)
    result.frame = frame_note(scene.spec)
    result.plotters.append(lambda res: plot_orbits(res, gm, frame))
    result.plotters.append(lambda res: plot_energy(res, what, conserved))

    def write_rebound(_result: Result, folder: Path) -> list[Path]:
        path = folder / "final.bin"
        if path.exists():
            path.unlink()  # rebound appends to an existing archive
        traj.final.to_rebound().save_to_file(str(path))
        return [path]

    result.writers.append(write_rebound)
    return result


def _crosscheck_into(result: Result, system: Any, traj: Any, effects: Any) -> None:
    """Integrate the same initial state with rebound (IAS15) at the same output times."""
    from hamilton_orbits import crosscheck

    changed = [str(a) for a in traj.events["action"] if str(a) in ("remove", "merge")] \
        if traj.events is not None and len(traj.events) else []
    if changed:  # rebound would integrate the starting bodies, none removed or merged
        result.metrics["cross-check against rebound"] = (
            f"skipped: events changed the bodies ({', '.join(dict.fromkeys(changed))}), "
            "which rebound's run of the starting state does not")
        return
    table = crosscheck(system, None, method=traj.method, effects=effects, trajectory=traj)
    result.tables["cross-check against rebound: final position difference"] = table.rows
    result.tables["cross-check against rebound: codes"] = table.code_rows
    result.diagnostics["rebound_energy_error"] = table.rebound_energy_error
    result.metrics["rebound wall time (s)"] = table.wall_time["rebound"]
    result.metrics["max relative position difference"] = float(
        table.relative_position_difference.max())
