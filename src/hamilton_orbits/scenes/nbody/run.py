"""The run of an ``nbody`` scene (:func:`run_scene`): the scene's
:class:`~hamilton_orbits.Simulation`, one call over the output times (a progress
bar over the whole run; Ctrl-C keeps what is done), and the
:class:`~hamilton_orbits.scenes.result.Result` made of its trajectory: Hamilton's
integrals, the events, MEGNO, the analyses, the cross-check and the figures."""

from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits import effects as _effects
from hamilton_orbits._progress import progress_bar
from hamilton_orbits._rebound import binary_of
from hamilton_orbits.checkpoint import holds_snapshots
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


def simulation(spec: dict, system: Any, archive: Any = None) -> Any:
    """The :class:`~hamilton_orbits.Simulation` of a validated ``nbody`` scene (writing
    its archive into ``archive`` when the scene asks for one)."""
    from hamilton_orbits import Simulation

    integ = spec["integrator"]
    options = {k: integ[k] for k in ("coordinates", "corrector", "max_steps")
               if integ[k] is not None}
    events = [{k: v for k, v in ev.items() if v is not None} for ev in spec["events"]]
    every = spec["output"]["archive_every"]
    if archive is not None and every is not None:
        options.update(archive=archive, every=every)
    return Simulation(system, integ["method"], dt=integ["dt"], tol=integ["tol"],
                      effects=spec["effects"], events=events,
                      variational=bool(spec["variational"]), **options)


def _compile_ahead(spec: dict) -> None:
    """On a first run, the stepping kernel of a radau15 scene compiled in a second
    process while this one compiles the right-hand side and the rest (the longer
    of the two instead of their sum: ``docs/design.md``, "First run")."""
    if spec["integrator"]["method"] != "radau15" or spec["variational"]:
        return
    from hamilton_orbits.integrators import radau15

    radau15.compile_ahead(bool(spec["events"]))


def resumable(folder: Any) -> bool:
    """True if archive ``folder`` holds snapshots (a run to resume; a segment of
    none, begun by a run killed before its first snapshot, is a run to begin again:
    :func:`~hamilton_orbits.checkpoint.holds_snapshots`)."""
    return folder is not None and holds_snapshots(Path(folder))


def run_scene(scene: Any, progress: bool = True, stop=lambda: False,
              archive: Any = None) -> Result:
    """Run a validated ``nbody`` scene (the kind's ``run``): its system and its
    :class:`~hamilton_orbits.Simulation`, one call over the output times, the
    analyses the scene asks for; ``stop()`` true (or Ctrl-C) ends the run early,
    keeping what is done.  With ``[output] archive_every`` the run writes an archive
    into ``archive``, and an archive holding a killed run's snapshots is resumed
    (the same result as the run never interrupted, its states to the bit)."""
    from hamilton_orbits import Simulation

    spec = scene.spec
    _compile_ahead(spec)
    system = build_system(spec)
    times = output_times(spec)
    bar = progress_bar(len(times) - 1, progress, "output")
    on_output = None if bar is None else (lambda i, steps: bar.update(1))
    resumed_from = None  # (the time a resumed run went on from)
    try:
        if spec["output"]["archive_every"] is not None and resumable(archive):
            sim = Simulation.load(archive)
            system = _as_the_run_read_it(system, sim.initial_system, spec)
            resumed_from = sim.t if isinstance(sim.t, u.Quantity) else sim.t * u.d
            traj = sim.resume(stop=stop, on_interrupt="keep", on_output=on_output)
        else:
            sim = simulation(spec, system, archive)
            traj = sim.integrate(times, stop=stop, on_interrupt="keep", on_output=on_output)
    finally:
        if bar is not None:
            bar.close()
    if len(traj.t) < 2 and getattr(traj, "stopped_by", None) is None:
        raise KeyboardInterrupt  # (a Ctrl-C before the first output; a stop at the start
        # by an event, a collision there, is the run's result)
    result = _result(scene, system, traj, sim.effects)
    result.resumed_from = resumed_from
    _events_into(result, traj)
    _chaos_into(result, traj)
    for an in spec["analysis"]:
        ANALYSIS_FUNCTIONS[an["name"]](result, system, an)
    if spec["crosscheck"] and result.complete:
        _crosscheck_into(result, system, traj, sim.effects)
    return result


def _as_the_run_read_it(system: Any, archived: Any, spec: dict) -> Any:
    """The system a resumed run began from: the archive's (the scene's starting
    state as the run read it).  Where the scene builds another now (its ``[initial]
    rebound`` file changed since the run began), that is said on stderr, and the
    archive's is the one the result and the cross-check are of."""
    now, then = system.as_arrays(), archived.as_arrays()
    same = tuple(system.names) == tuple(archived.names) and all(
        np.array_equal(getattr(now, k), getattr(then, k)) for k in ("r", "v", "gm"))
    if not same:
        source = spec["initial"].get("rebound")
        what = f"[initial] rebound file {source!r}" if source else "starting state"
        print(f"hamilton-orbits: the scene's {what} has changed since the run began; "
              f"resuming from the state the run began with (kept in its archive)",
              file=sys.stderr)
    return archived


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
    rebound's ``sim.megno()`` and ``sim.lyapunov()``), the trajectory's Lyapunov
    time (``1 / lyapunov`` where the run lasted that long; infinite otherwise,
    with a note saying so: a non-positive exponent is the slope of a levelled-off
    MEGNO, not the inverse of a time), and MEGNO over time as a diagnostic and a
    figure."""
    if traj.megno is None:
        return
    lyap = traj.lyapunov[-1].to(1 / u.yr)
    lyap_time = traj.lyapunov_time[-1].to(u.yr)
    result.diagnostics["megno"] = traj.megno
    result.metrics["MEGNO"] = float(traj.megno[-1])
    result.metrics["Lyapunov exponent"] = lyap
    result.metrics["Lyapunov time"] = lyap_time
    if not np.isfinite(lyap_time):
        span = (traj.t[-1] - traj.t[0]).to(u.yr)
        why = ("the exponent is not positive" if lyap.value <= 0
               else f"1 / exponent = {(1 / lyap).to_value(u.yr):.4g} yr is longer than the run")
        result.metrics["Lyapunov note"] = (
            f"no exponential growth measured over {span.value:.6g} yr ({why}): the orbit "
            "looks regular; a negative exponent is the slope of a MEGNO settling to its "
            "plateau, not the inverse of a time")
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
    actions = list(traj.events["action"]) if len(traj.events) else []
    merged, removed = "merge" in actions, "remove" in actions
    conserved = conserved and not merged and not removed
    if merged:
        what += " (not conserved: merges are inelastic)"
    if removed:
        what += " (not conserved: bodies were removed)"
    result.metrics["energy"] = what
    key = "max |relative energy error|" if conserved else "max |relative energy change|"
    change = np.abs(np.asarray(traj.energy_error, dtype=float))
    if not np.isfinite(change).all():  # (no NaN in the summary: the outputs it has)
        change = change[np.isfinite(change)]
        key += " (while it is defined)"
    if change.size:
        result.metrics[key] = float(np.max(change))
    _particles_into(result, traj, gm)
    frame = scene_frame(scene.spec)
    result.frame = frame_note(scene.spec, scene.data.get("initial"))
    result.time_origin = _time_origin(scene.spec)
    result.plotters.append(lambda res: plot_orbits(res, gm, frame))
    result.plotters.append(lambda res: plot_energy(res, what, conserved))

    def write_rebound(_result: Result, folder: Path) -> list[Path]:
        # rebound's binary (binary_of: its names read back right in this process
        # too), written whole and renamed into place (save_to_file takes only an
        # ASCII path, and appends to a file already there)
        path, tmp = folder / "final.bin", folder / f".final.bin.tmp-{os.getpid()}"
        try:
            final = traj.final.to_rebound()
            end = traj.t[-1]  # (rebound's t in days, as its states: it said 0 after 20 yr)
            final.t = float(end.to_value(u.day) if hasattr(end, "unit") else end)
            tmp.write_bytes(binary_of(final))
            os.replace(tmp, path)
        finally:
            tmp.unlink(missing_ok=True)
        return [path]

    result.writers.append(write_rebound)
    return result


def _time_origin(spec: dict) -> str:
    """What time 0 of an n-body scene is: the epoch of its initial state."""
    initial = spec.get("initial") or {}
    for key in ("solar_system", "ephemeris"):
        part = initial.get(key) or {}
        if part.get("epoch") is not None:
            return f"{part['epoch']}, the epoch of the initial state ([initial] {key})"
    return "the initial state (the scene names no epoch)"


def _particles_into(result: Result, traj: Any, gm: np.ndarray) -> None:
    """The test particles' own checks, which Hamilton's integrals leave out (the
    worst particle's, beside the massive bodies' energy), and the close approaches
    a fixed step was too long for (a count and a table; the run also warned)."""
    checks = traj.particle_check
    tp = [i for i, c in enumerate(checks) if c]
    if tp:
        _worst_particle_into(result, traj, gm, tp)
    _under_resolved_into(result, traj)


def _worst_particle_into(result: Result, traj: Any, gm: np.ndarray, tp: list[int]) -> None:
    """The largest change of a test particle's own check, and which particle."""
    checks = traj.particle_check
    err = np.abs(traj.particle_error[:, tp])
    worst = int(np.nanargmax(np.nanmax(err, axis=0))) if np.isfinite(err).any() else 0
    jacobi = checks[tp[0]] == "Jacobi constant"
    if jacobi or np.count_nonzero(gm > 0) == 1:  # conserved: its change is an error
        key = ("max |relative Jacobi constant error| of a test particle" if jacobi
               else "max |relative energy error| of a test particle")
    else:  # several massive bodies: how much they changed its orbit
        key = "max |relative change of a test particle's energy about its primary|"
    result.metrics[key] = float(np.nanmax(err)) if np.isfinite(err).any() else float("nan")
    result.metrics["test particle of largest change"] = (
        f"{traj.names[tp[worst]]} ({checks[tp[worst]]})")


def _under_resolved_into(result: Result, traj: Any) -> None:
    """The close approaches a fixed step was too long for: a count and a table."""
    table = traj.under_resolved
    if not len(table):
        return
    result.metrics["under-resolved encounters"] = len(table)
    result.tables["under-resolved encounters (a step too long: the orbit after each is not "
                  "to be trusted)"] = [
        {"particle": str(row["particle"]), "body": str(row["body"]),
         "time": row["time"].to(u.yr), "distance": row["distance"],
         "step / time scale": float(row["step"] / row["timescale"]),
         "1/a before": row["inv_a_before"], "1/a after": row["inv_a_after"],
         "e before": float(row["e_before"]), "e after": float(row["e_after"])}
        for row in table]


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
    try:
        table = crosscheck(system, None, method=traj.method, effects=effects, trajectory=traj)
    except KeyboardInterrupt:  # (rebound takes Ctrl-C over while it runs, whatever handler
        # was set: the run is done and kept, the cross-check skipped)
        result.metrics["cross-check against rebound"] = "skipped: interrupted (Ctrl-C)"
        result.interrupted = True
        return
    result.tables["cross-check against rebound: final position difference"] = table.rows
    codes = table.code_rows
    if result.resumed_from is not None:  # (ours: the part since the resume alone)
        since = f"since the resume at t = {result.resumed_from.to(u.yr):.6g} only"
        result.metrics["our wall time"] = since
        codes[0]["code"] += f" (steps and wall time {since}; rebound's: the whole run)"
    result.tables["cross-check against rebound: codes"] = codes
    result.diagnostics["rebound_energy_error"] = table.rebound_energy_error
    result.metrics["rebound wall time [s]"] = table.wall_time["rebound"]  # (as "wall time [s]")
    result.metrics["max relative position difference"] = float(
        table.relative_position_difference.max())
