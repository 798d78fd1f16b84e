"""The ``rigid`` problems of ``hamilton-orbits report``: the free rigid body and the
rigid-Earth pole wander (entry point ``hamilton_orbits.report_problems``).

See :mod:`hamilton_orbits.studies.report` for the measures and the output.
"""

from __future__ import annotations

from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits.studies.report import Row, log, timed


def problems() -> list[tuple[str, Any]]:
    """The report problems ``rigid`` adds, as ``(slug, function(quick, progress))``."""
    return [("rigid_body", _rigid), ("pole_wander", _pole)]


def _rigid(quick: bool, progress: bool) -> list[Row]:
    from hamilton_orbits import Quaternion, Scene
    from hamilton_orbits.ensemble import Ensemble
    from rigid import RigidBody, free_motion, integrate

    name = "free rigid body"
    measure = "max attitude angle to reference (rad)"
    reference = "rigid.free_motion (exact, Jacobi elliptic functions)"
    # the bundled Dzhanibekov scene: moments 1, 2, 3 kg m^2, spin 2 rad/s about the
    # middle axis, output every 0.01 s; its runs measure the attitude error against
    # the exact free motion at every output
    scene = Scene.bundled("dzhanibekov")
    duration = 20.0 if quick else 60.0
    scene = scene.with_values({"duration": f"{duration:g} s"})
    methods = ["splitting2", "splitting4", "exact_kick", "rk4"]
    dts = ["0.05 s", "0.01 s"] if quick else ["0.1 s", "0.05 s", "0.02 s", "0.01 s", "0.005 s"]
    # warm-up (compile / load the kernels), then the sweep one member at a time
    # (workers=1) so that members do not share cores and their wall times compare
    Ensemble(scene.with_values({"duration": "1 s"}),
             vary={"integrator.method": methods}).run(progress=False, workers=1)
    table = Ensemble(scene, vary={"integrator.method": methods, "integrator.dt": dts}).run(
        progress=progress, workers=1)
    rows = []
    col = "max attitude error vs exact [rad]"
    for rec in table.to_dict("records"):
        if rec.get("error") is not None:
            raise RuntimeError(f"ensemble member {rec} failed: {rec['error']}")
        rows.append(Row(name, "hamilton-orbits", rec["integrator.method"],
                        f"dt = {rec['integrator.dt']}", float(rec[col]), measure, reference,
                        float(rec["wall time [s]"])))

    # the same body, span and outputs, directly: the reference itself and scipy DOP853
    body = RigidBody([1.0, 2.0, 3.0], omega=[0.001, 2.0, 0.001])
    n_out = round(duration / 0.01) + 1
    t = np.linspace(0.0, duration, n_out)
    wt, (q_ref, _) = timed(lambda: free_motion(body, t))
    rows.insert(0, Row(name, "hamilton-orbits", "exact (free_motion)", f"{n_out} epochs", 0.0,
                       measure, reference + " (is the reference)", wt))

    def err(tr: Any) -> float:
        return float(np.max(Quaternion(tr.attitude.as_array()).rotation_distance(q_ref)))

    integrate(body, [1.0], method="dop853")
    for tol in (1e-6, 1e-9, 1e-12):
        wt, tr = timed(lambda tol=tol: integrate(body, t, method="dop853", tol=tol))
        rows.append(Row(name, "scipy (rigid.integrate)", "dop853", f"rtol = {tol:g}", err(tr),
                        measure, reference, wt))
    log(progress, f"{name}: {len(rows)} rows")
    return rows


# --------------------------------------------------------------------------- 4. pole wander
def _pole(quick: bool, progress: bool) -> list[Row]:

    from rigid import earth, free_motion, integrate
    from rigid.earth import pole_path

    name = "pole wander"
    years = 10 if quick else 100
    measure = "max |m - m_ref| (µas)"
    reference = "rigid.free_motion (exact), daily"
    rad_to_uas = (1 * u.rad).to_value(u.uas)
    body = earth.rigid_body(0.2 * u.arcsec)
    n_days = round(years * 365.25)
    t_days = np.arange(n_days + 1) * 86400.0 * u.s
    hour = 3600.0 * u.s
    free_motion(body, t_days[:3])
    integrate(body, [24.0] * hour, dt=hour, method="splitting4")
    integrate(body, [1.0] * hour, method="dop853")

    wt, (_, w_ex) = timed(lambda: free_motion(body, t_days))
    m_ex = pole_path(w_ex)

    def err(tr: Any) -> float:
        return float(np.max(np.abs(pole_path(np.asarray(tr.omega)) - m_ex))) * rad_to_uas

    rows = [Row(name, "hamilton-orbits", "exact (free_motion)", f"{n_days + 1} days", 0.0,
                measure, reference + " (is the reference)", wt)]
    for dt_h in (24.0, 6.0) if quick else (24.0, 6.0, 1.0):
        wt, tr = timed(lambda dt_h=dt_h: integrate(body, t_days, dt=dt_h * hour,
                                                    method="splitting4"))
        rows.append(Row(name, "hamilton-orbits", "splitting4", f"dt = {dt_h:g} h", err(tr),
                        measure, reference, wt))
    for tol in (1e-9,) if quick else (1e-9, 1e-12):
        wt, tr = timed(lambda tol=tol: integrate(body, t_days, method="dop853", tol=tol), 1)
        rows.append(Row(name, "scipy (rigid.integrate)", "DOP853", f"rtol = {tol:g}", err(tr),
                        measure, reference, wt))
    log(progress, f"{name}: {len(rows)} rows")
    return rows


# --------------------------------------------------------------------------- output
