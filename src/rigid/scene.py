"""The ``rotation`` scene kind: a rigid body (or the Earth) and its free motion.

``rigid`` registers this kind with :mod:`hamilton_orbits.scene` through the
entry point ``hamilton_orbits.scene_kinds: rotation``, so ``hamilton_orbits``
never imports ``rigid``.  Keys (``docs/scenes.md``)::

    kind = "rotation"
    duration = "60 s"
    cadence = "0.01 s"

    [body]
    moments = ["1 kg m2", "2 kg m2", "3 kg m2"]
    omega = ["0.001 rad/s", "2 rad/s", "0.001 rad/s"]

    [integrator]
    method = "splitting4"
    dt = "1 ms"

    [[analysis]]
    name = "flip_time"

Every run is checked against the exact torque-free motion
(:func:`rigid.free_motion`), so the summary states the integrator's error.
"""

from __future__ import annotations

import time
from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits import schema as S
from hamilton_orbits.scene import Result, Scene, SceneKind, check_output_size, register_kind
from hamilton_orbits.units import ANGLE, ANGULAR_SPEED, DIMENSIONLESS, INERTIA, TIME

ANALYSES = {
    "flip_time": "interval between reversals of the middle-axis spin, beside 2 K(m) / lambda",
    "wobble_period": "period of the rotation axis about the figure axis, beside Euler's period",
}
PRESETS = ("earth",)


def _methods() -> tuple[str, ...]:
    from rigid.integrators import METHODS

    return tuple(METHODS)


SCHEMA: dict[str, S.Field] = {
    "duration": S.Quantity(kind=TIME, required=True, positive=True),
    "cadence": S.Quantity(kind=TIME, positive=True),
    "body": S.Table(
        required=True,
        fields={
            "preset": S.Choice(choices=PRESETS),
            "wobble": S.Quantity(kind=ANGLE),
            "moments": S.Vector(kind=INERTIA),
            "omega": S.Vector(kind=ANGULAR_SPEED),
            "attitude": S.Vector(kind=DIMENSIONLESS, size=4),
        },
    ),
    "integrator": S.Table(
        default={},
        fields={
            "method": S.Choice(choices=_methods, default="splitting4"),
            "dt": S.Quantity(kind=TIME, positive=True),
        },
    ),
    "analysis": S.Array(
        default=[],
        item=S.Table(fields={"name": S.Choice(choices=tuple(ANALYSES), required=True)}),
    ),
}


def _check(spec: dict, problems: S.Problems) -> None:
    body = spec["body"]
    if body["preset"] is None:
        for key in ("moments", "omega"):
            if body[key] is None:
                problems.add(f"body.{key}", "missing: required unless `preset` is given")
        if body["wobble"] is not None:
            problems.add("body.wobble", 'only the preset "earth" takes a wobble')
    else:
        for key in ("moments", "omega", "attitude"):
            if body[key] is not None:
                problems.add(f"body.{key}", f"the preset {body['preset']!r} sets it; remove it")
    method = spec["integrator"]["method"]
    if method != "dop853" and spec["integrator"]["dt"] is None:
        problems.add("integrator.dt", f"missing: the method {method!r} takes a fixed step")
    for i, eff in enumerate(spec["effects"]):
        problems.add(f"effects[{i}]", f"the free rigid body takes no effects (got {eff['name']!r})")
    # kept per output: the attitude and angular velocity, integrated and exact, 4 diagnostics
    check_output_size(spec, problems, 2 * (4 + 3) + 4, "a rigid body")
    if not problems:  # (built as the run builds it: what it would refuse fails loading)
        try:
            build_body(spec)
        except ValueError as exc:
            problems.add("body", str(exc))


def build_body(spec: dict):
    """The :class:`~rigid.RigidBody` a validated rotation scene starts from."""
    from rigid import RigidBody

    body = spec["body"]
    if body["preset"] == "earth":
        from rigid import earth

        wobble = body["wobble"] if body["wobble"] is not None else 0.2 * u.arcsec
        return earth.rigid_body(wobble=wobble)
    kw: dict[str, Any] = {"omega": body["omega"]}
    if body["attitude"] is not None:
        kw["attitude"] = body["attitude"].to_value(u.one)
    return RigidBody(body["moments"], **kw)


def _si(x: Any, unit: u.UnitBase) -> np.ndarray:
    return np.asarray(x.to_value(unit) if isinstance(x, u.Quantity) else x, dtype=float)


def _run(scene: Scene, progress: bool = True, stop=lambda: False) -> Result:
    from hamilton_orbits.firstrun import compile_seconds
    from rigid import free_motion, free_parameters, integrate

    spec = scene.spec
    body = build_body(spec)
    duration = spec["duration"].to(u.s)
    cadence = spec["cadence"].to(u.s) if spec["cadence"] is not None else duration / 1000
    n_out = int(np.ceil((duration / cadence).to_value(u.one) - 1e-9)) + 1
    integ = spec["integrator"]
    kw: dict[str, Any] = {"method": integ["method"], "progress": progress}
    if integ["dt"] is not None:
        kw["dt"] = integ["dt"].to(u.s)
    compiled = compile_seconds()
    start = time.perf_counter()
    traj = integrate(body, np.linspace(0.0 * duration, duration, n_out), stop=stop, **kw)
    if len(traj.t) < 2:  # (stopped before its first output: nothing to keep)
        raise KeyboardInterrupt
    # the integration proper: the kernels' first-run compilation is reported apart
    wall = time.perf_counter() - start - (compile_seconds() - compiled)
    t = traj.t.to(u.s) if isinstance(traj.t, u.Quantity) else traj.t * u.s
    attitude, omega_exact = free_motion(body, t)
    omega = _si(traj.omega, u.rad / u.s)
    omega_ex = _si(omega_exact, u.rad / u.s)
    scale = np.max(np.linalg.norm(omega_ex, axis=-1))
    moments = _si(body.moments, u.kg * u.m**2)
    energy = 0.5 * np.sum(moments * omega**2, axis=-1)
    ang = np.linalg.norm(moments * omega, axis=-1)
    rest = not scale > 0  # (a body at rest: the changes themselves, not relative ones)
    diag = {
        "attitude_error": attitude.rotation_distance(traj.attitude) * u.rad,
        "omega_error": (np.linalg.norm(omega - omega_ex, axis=-1)
                        * (u.rad / u.s if rest else 1.0 / scale)),
        "energy_error": (energy - energy[0]) * u.J if rest else (energy - energy[0]) / energy[0],
        "angular_momentum_error": ((ang - ang[0]) * (u.J * u.s) if rest
                                   else (ang - ang[0]) / ang[0]),
    }
    result = Result(
        scene=scene,
        times=t,
        diagnostics=diag,
        states={"omega": omega * u.rad / u.s,
                "attitude": traj.attitude.as_array()},
        wall_time=wall,
        complete=len(t) == n_out,
        time_origin="the start of the run",
    )
    result.metrics["integrator"] = integ["method"]
    result.metrics["max attitude error vs exact"] = np.max(diag["attitude_error"]).to(u.rad)
    if rest:
        result.metrics["max |omega error| (a body at rest)"] = np.max(diag["omega_error"])
        result.metrics["max |energy change| (a body at rest)"] = np.max(
            np.abs(diag["energy_error"]))
    else:
        result.metrics["max |omega error| / |omega|"] = float(np.max(diag["omega_error"]))
        result.metrics["max |relative energy error|"] = float(np.max(np.abs(
            diag["energy_error"])))
    par = free_parameters(body)
    for an in spec["analysis"]:
        if an["name"] == "flip_time":
            _flip_time(result, omega[:, int(np.argsort(moments)[1])], t, par)
        elif an["name"] == "wobble_period":
            _wobble_period(result, omega, t, par, spec)
    result.frame = ("angular velocity on the body's principal axes; attitude: body axes "
                    "to the space (inertial) axes")
    result.plotters.append(_plot_omega)
    return result


def _flip_time(result: Result, w2: np.ndarray, t: u.Quantity, par) -> None:
    """Mean interval between sign changes of the middle-axis spin ``w2`` (the axis of
    the middle moment, wherever it is; linear interpolation)."""
    ts = t.to_value(u.s)
    k = np.flatnonzero(np.sign(w2[1:]) != np.sign(w2[:-1]))
    crossings = ts[k] - w2[k] * (ts[k + 1] - ts[k]) / (w2[k + 1] - w2[k])
    flip = u.Quantity(par.flip_interval, u.s)  # a Quantity for Quantity bodies, else SI
    result.metrics["exact flip interval 2K(m)/lambda"] = flip
    if _too_sparse(result, "simulated flip interval", ts, flip.to_value(u.s), "flips", "s"):
        return
    if crossings.size >= 2:
        measured = np.mean(np.diff(crossings))
        result.metrics["simulated flip interval"] = measured * u.s
        result.metrics["simulated/exact flip interval - 1"] = float(
            measured / flip.to_value(u.s) - 1.0)
    else:
        result.metrics["simulated flip interval"] = "fewer than two flips in the run"


def _too_sparse(result: Result, name: str, ts: np.ndarray, interval: float, what: str,
                unit: str) -> bool:
    """Whether outputs at times ``ts`` are too far apart to time sign changes
    ``interval`` apart (both in ``unit``) by their zero crossings: more than a
    quarter of it (they alias: a run right to 1e-7 rad gave a flip interval 100% to
    880% off); the metric ``name`` then says so."""
    gap = float(np.max(np.diff(ts))) if ts.size > 1 else 0.0
    if not gap > interval / 4:
        return False
    result.metrics[name] = (f"outputs {gap:.6g} {unit} apart cannot time {what} "
                            f"{interval:.6g} {unit} apart (give a cadence of at most a "
                            f"quarter of it)")
    return True


def _wobble_period(result: Result, omega: np.ndarray, t: u.Quantity, par, spec) -> None:
    """Period of the spin axis about the figure axis in the body frame.

    From the upward zero crossings of the spin about the first axis that is not
    the one the path circles (``par.polar_axis``; linear interpolation between
    outputs): the path is an ellipse for a triaxial body, so its polar angle does
    not advance uniformly, but it crosses each axis once per period.
    """
    ts = t.to_value(u.d)
    period = u.Quantity(par.period, u.s).to_value(u.d)
    if _too_sparse(result, "simulated wobble period", ts, period, "turns", "d"):
        return
    w1 = omega[:, 1 if par.polar_axis == 0 else 0]
    k = np.flatnonzero((w1[:-1] < 0) & (w1[1:] >= 0))
    if k.size < 2:
        result.metrics["simulated wobble period"] = "less than one full turn in the run"
        return
    crossings = ts[k] - w1[k] * (ts[k + 1] - ts[k]) / (w1[k + 1] - w1[k])
    measured = (crossings[-1] - crossings[0]) / (crossings.size - 1) * u.d
    result.metrics["simulated wobble period"] = measured
    result.metrics["exact free-motion period"] = u.Quantity(par.period, u.s).to(u.d)
    if spec["body"]["preset"] == "earth":
        from rigid import earth

        result.metrics["Euler period (triaxial)"] = earth.euler_period(triaxial=True).to(u.d)


def _time_axis(t: u.Quantity) -> tuple[np.ndarray, str]:
    """Times in s, d or yr, whichever reads best for the span."""
    span = (t[-1] - t[0]).to(u.s)
    unit = u.yr if span > 2 * u.yr else u.d if span > 2 * u.d else u.s
    return t.to_value(unit), unit.to_string()


def _plot_omega(result: Result):
    """The body-frame angular velocity, or, when the spin about one axis is 100 times
    the rest (the Earth), the rotation axis's offset from that axis, which is what
    moves; and the attitude error against the exact motion."""
    import matplotlib.pyplot as plt

    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(7.5, 6.2), sharex=True)
    t, t_unit = _time_axis(result.times)
    w = result.states["omega"].to_value(u.rad / u.s)
    k = int(np.argmax(np.abs(w[0])))
    others = [i for i in range(3) if i != k]
    if np.abs(w[:, k]).min() > 100 * np.abs(w[:, others]).max():
        norm = np.linalg.norm(w, axis=-1)
        for i in others:
            offset = (w[:, i] / norm * u.rad).to_value(u.mas)
            ax.plot(t, offset, lw=0.8, label=f"omega_{i + 1} / |omega|")
        ax.set_ylabel(f"rotation axis off body axis {k + 1},\nbody (principal) axes [mas]",
                      fontsize=9)
    else:
        for i in range(3):
            ax.plot(t, w[:, i], lw=0.8, label=f"omega_{i + 1}")
        ax.set_ylabel("angular velocity,\nbody (principal) axes [rad/s]", fontsize=9)
    ax.legend(fontsize=8, loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=3,
              frameon=False)  # above the axes, off the data
    err = result.diagnostics["attitude_error"].to_value(u.rad)[1:]
    shown = err > 0  # an exact zero has no place on a log axis: not drawn
    ax2.semilogy(t[1:][shown], err[shown], lw=0.8)
    if not shown.any():  # (a body at rest, or exact throughout: said, not an empty frame)
        ax2.set_yscale("linear")
        ax2.set_yticks([])
        ax2.text(0.5, 0.5, "0 at every output", transform=ax2.transAxes, ha="center",
                 va="center", fontsize=9)
    ax2.set_ylabel("attitude error vs the exact\nmotion (angle) [rad]", fontsize=9)
    ax2.set_xlabel(f"time since the start [{t_unit}]")
    fig.suptitle(f"{result.scene.name}: {result.metrics.get('integrator', '')} against the "
                 "exact free motion", fontsize=10)
    fig.tight_layout()
    fig.set_label("spin")  # the file name Result.save gives it
    return fig


def _crosscheck(scene: Scene) -> str:
    from hamilton_orbits.scene import format_table

    result = _run(scene, progress=False)
    rows = [
        {"diagnostic": k, "max": result.metrics[k]}
        for k in ("max attitude error vs exact", "max |omega error| / |omega|",
                  "max |relative energy error|")
    ]
    return f"{scene.name}: against the exact free motion (rigid.free_motion)\n" + format_table(
        rows
    )


KIND = SceneKind(
    name="rotation",
    summary="a rigid body (or the Earth) turning freely, checked against the exact motion",
    schema=SCHEMA,
    effect_kind="rotation",
    check=_check,
    run=_run,
    crosscheck=_crosscheck,
    takes_effects=False,  # (the free body: _check refuses any)
)


def register() -> None:
    """Register the ``rotation`` and ``polar_motion`` scene kinds (entry point).

    The Earth-orientation kinds live in :mod:`rigid.earth.scene_polar_motion`
    (which registers ``pole_prediction`` beside ``polar_motion``).
    """
    from rigid.earth import scene_polar_motion

    register_kind(KIND)
    scene_polar_motion.register()
