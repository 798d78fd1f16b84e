"""Integrate a :class:`~hamilton_orbits.nbody.System`: :func:`integrate`, :class:`Trajectory`.

Every trajectory carries Hamilton's integrals as diagnostics (Hamilton 1845,
equations (C), (D), (E)): the drift of the centre of mass, the relative error of
the total angular momentum (law of areas) and of the energy (vis viva).
"""

from __future__ import annotations

import importlib
import time as _time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import astropy.units as u
import numpy as np

from hamilton_orbits.effects import compile_rhs, get, normalize_effects
from hamilton_orbits.nbody import DAY, System, energy_gm_many
from hamilton_orbits.units import TIME, is_quantity

__all__ = ["INTEGRATORS", "Trajectory", "integrate", "integrator_module"]

INTEGRATORS = ("radau15", "wh", "leapfrog", "dop853")


def integrator_module(method: str) -> Any:
    """The module of integrator ``method`` (ValueError listing the known ones).

    Examples
    --------
    >>> integrator_module("leapfrog").NAME
    'leapfrog'
    """
    if method not in INTEGRATORS:
        raise ValueError(f"Unknown `method` {method!r}; known: {', '.join(INTEGRATORS)}")
    try:
        return importlib.import_module(f"hamilton_orbits.integrators.{method}")
    except ModuleNotFoundError as exc:  # pragma: no cover - only while a method is missing
        raise ValueError(f"Integrator {method!r} is not available in this build") from exc


def _accepting(velocity_dependent: bool) -> list[str]:
    out = []
    for name in INTEGRATORS:
        try:
            mod = integrator_module(name)
        except ValueError:
            continue
        if mod.ACCEPTS_VELOCITY_DEPENDENT or not velocity_dependent:
            out.append(name)
    return out


@dataclass(frozen=True, eq=False)
class Trajectory:
    """The states of a system at the output times, with Hamilton's integrals.

    Attributes
    ----------
    t : ndarray or Quantity, shape (n_t,)
        Output times (the first is the initial time).
    r, v : ndarray or Quantity, shape (n_t, n, 3)
        Positions and velocities (au, au/day for Quantity systems).
    names : tuple of str
    final : System
        The system at the last output time.
    energy_error : ndarray, shape (n_t,)
        ``(E(t) - E(0)) / |E(0)|`` (law of vis viva, (E)).
    angular_momentum_error : ndarray, shape (n_t,)
        ``|L(t) - L(0)| / |L(0)|`` (law of areas, (D)); absolute if ``L(0) = 0``.
    barycentre_drift : ndarray, shape (n_t,)
        ``|R(t) - R(0) - V(0) t| / s`` with ``s`` the largest distance from the
        initial centre of mass (law of the centre of gravity, (C)).
    steps : int
        Steps taken by the integrator.
    wall_time : float
        Seconds of wall-clock time for the integration (JIT compilation included
        on a first call).
    method : str
    effects : tuple of str
    """

    t: Any
    r: Any
    v: Any
    names: tuple[str, ...]
    final: System
    energy_error: np.ndarray
    angular_momentum_error: np.ndarray
    barycentre_drift: np.ndarray
    steps: int
    wall_time: float
    method: str
    effects: tuple[str, ...]

    def __repr__(self) -> str:
        return (
            f"Trajectory({len(self.names)} bodies, {len(self.energy_error)} outputs, "
            f"method={self.method!r}, effects={self.effects!r}, steps={self.steps}, "
            f"max |dE/E|={np.max(np.abs(self.energy_error)):.3g})"
        )


def _times(t: Any, quantity: bool) -> np.ndarray:
    if quantity and not is_quantity(t):
        raise ValueError(f"Expected `t` as a time Quantity for a Quantity system, got {t!r}")
    if not quantity and is_quantity(t):
        raise ValueError(f"Expected `t` as plain floats for a system of plain floats, got {t!r}")
    arr = np.atleast_1d(TIME("t", t, DAY if quantity else None)).astype(np.float64)
    if arr.ndim != 1:
        raise ValueError(f"Expected `t` to be a time or a 1-d array of times, got shape "
                         f"{arr.shape}")
    if arr.size == 1:
        if arr[0] == 0.0:
            raise ValueError("Expected `t` to be a nonzero end time, got 0")
        arr = np.array([0.0, arr[0]])
    elif arr[0] != 0.0:
        arr = np.concatenate(([0.0], arr))
    d = np.diff(arr)
    if not (np.all(d > 0) or np.all(d < 0)):
        k = int(np.argmax(~(d > 0))) if d[0] > 0 else int(np.argmax(~(d < 0)))
        raise ValueError(
            f"Expected `t` to be strictly monotonic (times after the start 0), got "
            f"{arr[k + 1]!r} after {arr[k]!r} at index {k + 1}"
        )
    return arr


def _diagnostics(system: System, r: np.ndarray, v: np.ndarray, t: np.ndarray):
    gm = system._gm
    e = energy_gm_many(r, v, gm)
    e0 = e[0]
    energy_error = (e - e0) / abs(e0) if e0 != 0 else e - e0
    h = np.einsum("j,tjk->tk", gm, np.cross(r, v))
    h0 = np.linalg.norm(h[0])
    dh = np.linalg.norm(h - h[0], axis=1)
    am_error = dh / h0 if h0 > 0 else dh
    total = gm.sum()
    rc = np.einsum("j,tjk->tk", gm, r) / total
    vc0 = gm @ v[0] / total
    scale = float(np.max(np.linalg.norm(r[0] - rc[0], axis=1)))
    drift = np.linalg.norm(rc - rc[0] - np.outer(t - t[0], vc0), axis=1)
    return energy_error, am_error, drift / (scale if scale > 0 else 1.0)


def _check_options(module: Any, method: str, options: dict[str, Any]) -> None:
    """Refuse an option the integrator's ``run`` does not take, listing those it does."""
    import inspect

    common = {"dt", "tol", "on_output"}
    takes = [name for name, p in inspect.signature(module.run).parameters.items()
             if p.kind is p.KEYWORD_ONLY and name not in common]
    for key, value in options.items():
        if key not in takes:
            raise ValueError(
                f"Unknown option `{key}` = {value!r} for method {method!r}; it takes: "
                + (", ".join(takes) if takes else "no options beyond dt and tol"))


def integrate(
    system: System,
    t: Any,
    method: str = "radau15",
    dt: Any = None,
    tol: float | None = None,
    effects: Sequence[str | Mapping[str, Any]] = (),
    progress: bool = False,
    on_output: Any = None,
    **options: Any,
) -> Trajectory:
    """Integrate Hamilton's equation (B) (plus the listed effects) for ``system``.

    Parameters
    ----------
    system : System
    t : Quantity or float or array_like
        An end time, or output times (monotonic; a start at 0 is added if missing).
        A time Quantity for a Quantity system, plain floats otherwise.
    method : {"radau15", "wh", "leapfrog", "dop853"}
        The integrator (see :mod:`hamilton_orbits.integrators`).
    dt : Quantity or float, optional
        A fixed step (``radau15``, ``wh``, ``leapfrog``) or a step cap (``dop853``).
    tol : float, optional
        The integrator's tolerance (adaptive methods) or the accuracy from which a
        fixed-step method chooses its step.
    effects : sequence of str or mapping
        Effects beyond Newtonian gravity: ``"gr"``, ``"gr_potential"``,
        ``{"name": "j2", "body": "earth"}``; see :mod:`hamilton_orbits.effects`.
    progress : bool
        Show a progress bar (tqdm, on stderr) over the output times.
    on_output : callable, optional
        ``on_output(i, steps)`` after output ``i`` (for scenes and interfaces).
    **options
        Options of the chosen integrator, e.g. for ``wh``
        ``coordinates="jacobi"`` and ``corrector=3`` (see its ``run``).  An option
        the method does not take raises ``ValueError`` listing those it takes.

    Returns
    -------
    Trajectory

    Raises
    ------
    ValueError
        For an unknown method or effect, a velocity-dependent effect given to a
        symplectic integrator (naming the effect and the integrators that accept
        it), or bad times.

    Examples
    --------
    >>> from hamilton_orbits import Body, System, integrate
    >>> import numpy as np
    >>> s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
    ...             Body("dust", 0.0, [1.0, 0, 0], [0, 1.0, 0])])
    >>> traj = integrate(s, 2 * np.pi, method="leapfrog", dt=2 * np.pi / 2000)
    >>> bool(np.allclose(traj.final["dust"].r, [1, 0, 0], atol=1e-4))
    True
    >>> jac = integrate(s, 2 * np.pi, method="wh", dt=0.1, coordinates="jacobi", corrector=3)
    >>> bool(np.allclose(jac.final["dust"].r, [1, 0, 0], atol=1e-12))  # a Kepler orbit: exact
    True
    >>> integrate(s, 1.0, method="leapfrog", dt=0.1, effects=["gr"])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: Effect 'gr' depends on velocities and integrator 'leapfrog' is symplectic...
    """
    if not isinstance(system, System):
        raise ValueError(f"Expected `system` to be a System, got {system!r}")
    module = integrator_module(method)
    _check_options(module, method, options)
    normal = normalize_effects(effects, "nbody")
    if not module.ACCEPTS_VELOCITY_DEPENDENT:
        for name, _ in normal:
            if get("nbody", name).velocity_dependent:
                raise ValueError(
                    f"Effect {name!r} depends on velocities and integrator {method!r} is "
                    f"symplectic; integrators that accept it: {', '.join(_accepting(True))}"
                    + (" (or use 'gr_potential')" if name == "gr" else "")
                )
    times = _times(t, system.quantity)
    step = None
    if dt is not None:
        step = float(TIME("dt", dt, DAY if system.quantity else None))
        if not (np.isfinite(step) and step > 0):
            raise ValueError(f"Expected `dt` > 0, got {step!r}")
    if tol is not None:
        tol = float(tol)
        if not (np.isfinite(tol) and tol > 0):
            raise ValueError(f"Expected `tol` > 0, got {tol!r}")
    sign = 1.0 if times[-1] > times[0] else -1.0
    rhs = compile_rhs(system, [dict(name=n, **dict(p)) for n, p in normal])

    bar = None
    if progress:
        try:
            from tqdm.auto import tqdm

            bar = tqdm(total=len(times) - 1, desc=f"{method}", unit="output", leave=False)
        except ImportError:  # pragma: no cover - tqdm is an optional extra
            bar = None

    def report(i: int, steps: int) -> None:
        if bar is not None:
            bar.update(1)
        if on_output is not None:
            on_output(i, steps)

    start = _time.perf_counter()
    r0 = np.array(system._r, dtype=np.float64)
    v0 = np.array(system._v, dtype=np.float64)
    gm = np.array(system._gm, dtype=np.float64)
    try:
        if sign > 0:
            r, v, steps = module.run(rhs, r0, v0, gm, times, dt=step, tol=tol, on_output=report,
                                     **options)
        else:
            # integrate backwards as forwards with the velocities reversed; exact for
            # conservative forces; velocity-dependent ones are odd in v: handled by
            # integrating in -t with the dispatcher on reversed velocities is not
            # generally valid, so refuse it.
            if rhs.velocity_dependent:
                raise ValueError("Backward integration with a velocity-dependent effect is not "
                                 "supported; integrate forwards from the final state")
            r, v, steps = module.run(rhs, r0, -v0, gm, -times, dt=step, tol=tol,
                                     on_output=report, **options)
            v = -v
    finally:
        if bar is not None:
            bar.close()
    wall = _time.perf_counter() - start
    if not (np.all(np.isfinite(r)) and np.all(np.isfinite(v))):
        bad = np.argwhere(~np.isfinite(r).all(axis=2) | ~np.isfinite(v).all(axis=2))[0]
        raise ValueError(
            f"The integration with {method!r} lost the state of body "
            f"{system.names[bad[1]]!r} at output {bad[0]} (t = {times[bad[0]]!r}): "
            "a collision or a step too long"
        )
    ee, ae, bd = _diagnostics(system, r, v, times)
    final = system.with_state(r[-1], v[-1])
    if system.quantity:
        t_out: Any = times * u.day
        r_out: Any = r * u.au
        v_out: Any = v * (u.au / u.day)
    else:
        t_out, r_out, v_out = times, r, v
    return Trajectory(
        t_out, r_out, v_out, system.names, final, ee, ae, bd, int(steps), wall, method,
        rhs.effects,
    )
