"""The run of an ``nbody`` scene (:func:`run_scene`): one engine call over the
output times (a progress bar over the whole run; Ctrl-C keeps what is done), and
the :class:`~hamilton_orbits.scenes.result.Result` made of it: Hamilton's
integrals, the events, MEGNO, the analyses, the cross-check and the figures."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits import effects as _effects
from hamilton_orbits._progress import progress_bar
from hamilton_orbits.scenes.nbody.analyses import ANALYSIS_FUNCTIONS
from hamilton_orbits.scenes.nbody.build import build_system, frame_note, scene_frame
from hamilton_orbits.scenes.nbody.figures import plot_energy, plot_megno, plot_orbits
from hamilton_orbits.scenes.result import Result


def _times(spec: dict) -> u.Quantity:
    duration = spec["duration"].to(u.d)
    cadence = spec["cadence"].to(u.d) if spec["cadence"] is not None else duration / 1000
    n = max(1, int(np.ceil((duration / cadence).to_value(u.one) - 1e-9)))
    t = np.minimum(np.arange(n + 1) * cadence.value, duration.value)
    return t * u.d


def _integrator_args(spec: dict) -> tuple[str, dict[str, Any]]:
    """The method and the engine's keyword arguments (internal units: days)."""
    integ = spec["integrator"]
    kw: dict[str, Any] = {
        "tol": integ["tol"],
        "dt": None if integ["dt"] is None else float(integ["dt"].to_value(u.d)),
        "options": {k: integ[k] for k in ("coordinates", "corrector") if integ[k] is not None},
    }
    return integ["method"], kw


def run_scene(scene: Any, progress: bool = True, stop=lambda: False) -> Result:
    """Run a validated ``nbody`` scene (the kind's ``run``): the system built, one
    engine call over the output times, the analyses the scene asks for; ``stop()``
    true ends the run early, keeping what is done."""
    from hamilton_orbits import engine
    from hamilton_orbits.rhs import compile_rhs
    from hamilton_orbits.simulation import check_method, event_log

    spec = scene.spec
    system = build_system(spec)
    t_all = _times(spec).to_value(u.d)
    method, kw = _integrator_args(spec)
    effects = check_method(method, spec["effects"], kw["options"])
    tangent = None
    if spec["variational"]:
        from hamilton_orbits.integrators._tangent import Tangent

        tangent = Tangent(len(system.names), len(t_all))
    rhs = compile_rhs(system, effects, variational=tangent is not None)
    log = event_log(system, [{k: v for k, v in ev.items() if v is not None}
                             for ev in spec["events"]])
    arrays = system.as_arrays()
    bar = progress_bar(len(t_all) - 1, progress, "output")
    try:
        out = without_compilation(lambda: engine.run(
            arrays.r, arrays.v, arrays.gm, t_all, rhs, method, stop=stop,
            on_output=None if bar is None else (lambda i, steps: bar.update(1)), events=log,
            variational=tangent, **kw))
    finally:
        if bar is not None:
            bar.close()
    if len(out.t) < 2:
        raise KeyboardInterrupt
    result = _result(scene, system, out, method, effects)
    _events_into(result, system, out)
    _chaos_into(result, out)
    for an in spec["analysis"]:
        ANALYSIS_FUNCTIONS[an["name"]](result, system, an)
    if spec["crosscheck"] and result.complete:
        _crosscheck_into(result, system, out, method, effects)
    return result


def _events_into(result: Result, system, out) -> None:
    """The events found: a table, their count, the first of each kind (what an
    ``Ensemble`` row carries), and what stopped the run."""
    from hamilton_orbits.simulation import event_table

    if out.events is None:
        return
    table, stopped = event_table(out.events, system, u.yr)
    result.metrics["events found"] = len(table)
    for name in dict.fromkeys(table["name"]):
        first = table[table["name"] == name][0]
        result.metrics[f"first {name} at"] = first["time"]
        result.metrics[f"first {name} bodies"] = str(first["bodies"])
    if stopped is not None:
        result.metrics["stopped by"] = f"{stopped['name']} of {stopped['bodies']}"
    result.tables["events"] = [
        {"event": str(row["name"]), "time": row["time"], "bodies": str(row["bodies"]),
         "distance": row["distance"], "speed": row["speed"].to(u.km / u.s),
         "action": str(row["action"])} for row in table]


def without_compilation(run: Any) -> Any:
    """``run()`` (an engine call), its ``wall_time`` less the numba compilation that
    happened inside it (the integration proper: a first run compiles the stepping
    kernels on their first call)."""
    import dataclasses

    from hamilton_orbits.firstrun import compile_seconds

    before = compile_seconds()
    out = run()
    compiled = compile_seconds() - before
    return dataclasses.replace(out, wall_time=max(out.wall_time - compiled, 0.0))


def _chaos_into(result: Result, out) -> None:
    """With ``variational = true``: MEGNO and the Lyapunov exponent at the end (as
    rebound's ``sim.megno()`` and ``sim.lyapunov()``), the Lyapunov time
    ``1 / lyapunov`` (infinite when the exponent is not positive: no exponential
    growth measured), and MEGNO over time as a diagnostic and a figure."""
    tan = out.variational
    if tan is None:
        return
    k = len(out.t)
    megno = tan.megno[:k]
    lyap = float(tan.lyapunov[k - 1]) / u.d
    result.diagnostics["megno"] = megno.copy()
    result.metrics["MEGNO"] = float(megno[-1])
    result.metrics["Lyapunov exponent"] = lyap.to(1 / u.yr)
    result.metrics["Lyapunov time"] = (1 / lyap).to(u.yr) if lyap.value > 0 else np.inf * u.yr
    result.plotters.append(plot_megno)



def _result(scene: Any, system, out, method: str, effects) -> Result:
    """The :class:`Result` of an engine run: states, Hamilton's integrals, figures,
    and the final state as a rebound binary."""
    from hamilton_orbits.integrals import integral_errors

    gm = system.as_arrays().gm.copy()
    extra = _effects.effect_energy(system, effects, out.r, out.v)
    energy, ang, drift = integral_errors(out.r, out.v, gm, out.t, extra)
    result = Result(
        scene=scene,
        times=out.t * u.d,
        diagnostics={"energy_error": energy, "angular_momentum_error": ang,
                     "barycentre_drift": drift},
        states={"names": list(system.names), "r": out.r * u.au, "v": out.v * (u.au / u.d)},
        wall_time=out.wall_time,
        complete=out.complete,
    )
    result.metrics["integrator"] = method
    result.metrics["steps"] = out.steps
    what = _effects.energy_label(gm, effects, system.names)
    conserved = extra is not None
    result.metrics["energy"] = what
    key = "max |relative energy error|" if conserved else "max |relative energy change|"
    result.metrics[key] = float(np.max(np.abs(energy)))
    frame = scene_frame(scene.spec)
    result.frame = frame_note(scene.spec)
    result.plotters.append(lambda res: plot_orbits(res, gm, frame))
    result.plotters.append(lambda res: plot_energy(res, what, conserved))
    final = system.with_state(out.r[-1], out.v[-1])

    def write_rebound(_result: Result, folder: Path) -> list[Path]:
        path = folder / "final.bin"
        if path.exists():
            path.unlink()  # rebound appends to an existing archive
        final.to_rebound().save_to_file(str(path))
        return [path]

    result.writers.append(write_rebound)
    return result



def _crosscheck_into(result: Result, system, out, method: str, effects) -> None:
    """Integrate the same initial state with rebound (IAS15) at the same output times."""
    from hamilton_orbits import crosscheck
    from hamilton_orbits.simulation import make_trajectory

    traj = make_trajectory(system, out, u.d, method, ("newtonian", *effects.names), effects)
    table = crosscheck(system, None, method=method, effects=effects, trajectory=traj)
    result.tables["cross-check against rebound: final position difference"] = table.rows
    result.tables["cross-check against rebound: codes"] = table.code_rows
    result.diagnostics["rebound_energy_error"] = table.rebound_energy_error
    result.metrics["rebound wall time (s)"] = table.wall_time["rebound"]
    result.metrics["max relative position difference"] = float(
        table.relative_position_difference.max())
