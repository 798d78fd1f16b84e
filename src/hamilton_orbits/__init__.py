"""hamilton-orbits: celestial mechanics on Hamilton's quaternion core.

Where to start
--------------
- Two bodies: :class:`KeplerOrbit` (elements from a state and back, propagation,
  vectorised), :func:`solve_kepler`, :class:`Conic`.
- N bodies: build a :class:`System` of :class:`Body` objects (or
  ``System.solar_system`` / ``System.from_ephemeris``), then :func:`integrate` it,
  or make a :class:`Simulation` to run in legs, with effects and events; the
  result is a :class:`Trajectory` with Hamilton's integrals as error checks.
- Integrators: :class:`Radau15` (adaptive, default), :class:`WH` (Wisdom-Holman
  with correctors), :class:`Leapfrog`, :class:`DOP853`.
- Scene files (TOML) from Python: :class:`Scene` and its :class:`Result`; many
  runs at once: :class:`Ensemble`; long runs on disk: :class:`Archive`.
- Rotations: :class:`Quaternion`, :func:`slerp`.
- Checks against a peer code: :func:`crosscheck`; what to cite: :func:`cite`.

Public modules users import from: ``hamilton_orbits.integrators``,
``hamilton_orbits.effects``, ``hamilton_orbits.scenes``,
``hamilton_orbits.events``, ``hamilton_orbits.archive``, ``hamilton_orbits.schema``.
Everything not listed in ``__all__`` (and every module whose name starts with an
underscore) is private.  Rigid-body rotation is the sibling package ``rigid``.
The command line is ``hamilton-orbits`` (``python -m hamilton_orbits``).
"""

from typing import TYPE_CHECKING, Any

from hamilton_orbits.conic import Conic
from hamilton_orbits.kepler import ConvergenceError, solve_kepler
from hamilton_orbits.orbit import KeplerOrbit
from hamilton_orbits.quaternion import Quaternion, slerp

# numba and astropy are imported on first use, not here (hamilton_orbits._lazy);
# the first-compile notice is installed with the kernels (hamilton_orbits._kernels)

if TYPE_CHECKING:  # pragma: no cover
    from hamilton_orbits.archive import Archive
    from hamilton_orbits.citations import cite
    from hamilton_orbits.ensemble import Ensemble
    from hamilton_orbits.integrators.methods import DOP853, WH, Leapfrog, Radau15
    from hamilton_orbits.nbody import Body, System
    from hamilton_orbits.rebound_bridge import crosscheck
    from hamilton_orbits.scene import Result, Scene
    from hamilton_orbits.simulation import Simulation, integrate
    from hamilton_orbits.trajectory import Trajectory

# The n-body and scene names are imported on first use (PEP 562), so that
# ``import hamilton_orbits`` does not pull in their dependencies (tomllib,
# scipy.integrate, rebound, ...) nor importlib.metadata for the version.
_LAZY = {
    "Archive": "hamilton_orbits.archive",
    "Body": "hamilton_orbits.nbody",
    "cite": "hamilton_orbits.citations",
    "System": "hamilton_orbits.nbody",
    "crosscheck": "hamilton_orbits.rebound_bridge",
    "Ensemble": "hamilton_orbits.ensemble",
    "Result": "hamilton_orbits.scene",
    "Scene": "hamilton_orbits.scene",
    "Simulation": "hamilton_orbits.simulation",
    "Trajectory": "hamilton_orbits.trajectory",
    "integrate": "hamilton_orbits.simulation",
    "Radau15": "hamilton_orbits.integrators.methods",
    "WH": "hamilton_orbits.integrators.methods",
    "Leapfrog": "hamilton_orbits.integrators.methods",
    "DOP853": "hamilton_orbits.integrators.methods",
}


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("hamilton-orbits")
    except PackageNotFoundError:  # pragma: no cover - running from a source tree
        return "0.0.0+unknown"


def __getattr__(name: str) -> Any:
    if name == "__version__":
        value = _version()
    elif name in _LAZY:
        import importlib

        value = getattr(importlib.import_module(_LAZY[name]), name)
    else:
        raise AttributeError(f"module 'hamilton_orbits' has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


__all__ = [
    "DOP853",
    "WH",
    "Archive",
    "Body",
    "Conic",
    "ConvergenceError",
    "Ensemble",
    "KeplerOrbit",
    "Leapfrog",
    "Quaternion",
    "Radau15",
    "Result",
    "Scene",
    "Simulation",
    "System",
    "Trajectory",
    "__version__",
    "cite",
    "crosscheck",
    "integrate",
    "slerp",
    "solve_kepler",
]
