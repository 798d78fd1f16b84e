"""hamilton-orbits: celestial mechanics on Hamilton's quaternion core.

The curated public API.  Everything not listed in ``__all__`` is private.
"""

from importlib.metadata import PackageNotFoundError, version

from hamilton_orbits.conic import Conic
from hamilton_orbits.ensemble import Ensemble
from hamilton_orbits.kepler import ConvergenceError, solve_kepler
from hamilton_orbits.nbody import Body, System
from hamilton_orbits.orbit import KeplerOrbit
from hamilton_orbits.quaternion import Quaternion, slerp
from hamilton_orbits.rebound_bridge import crosscheck
from hamilton_orbits.scene import Result, Scene
from hamilton_orbits.simulation import Trajectory, integrate

try:
    __version__ = version("hamilton-orbits")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0.0.0+unknown"

__all__ = [
    "Body",
    "Conic",
    "ConvergenceError",
    "Ensemble",
    "KeplerOrbit",
    "Quaternion",
    "Result",
    "Scene",
    "System",
    "Trajectory",
    "__version__",
    "crosscheck",
    "integrate",
    "slerp",
    "solve_kepler",
]
