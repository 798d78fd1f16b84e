"""hamilton-orbits: celestial mechanics on Hamilton's quaternion core.

The curated public API.  Everything not listed in ``__all__`` is private.
"""

from importlib.metadata import PackageNotFoundError, version

from hamilton_orbits.conic import Conic
from hamilton_orbits.kepler import ConvergenceError, solve_kepler
from hamilton_orbits.orbit import KeplerOrbit
from hamilton_orbits.quaternion import Quaternion, slerp
from hamilton_orbits.scene import Result, Scene

try:
    __version__ = version("hamilton-orbits")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0.0.0+unknown"

__all__ = [
    "Conic",
    "ConvergenceError",
    "KeplerOrbit",
    "Quaternion",
    "Result",
    "Scene",
    "__version__",
    "slerp",
    "solve_kepler",
]
