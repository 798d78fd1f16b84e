"""Deprecated path of the physics ladder against DE440, now :mod:`hamilton_orbits.studies.ladder`.

Each name used from here warns (``DeprecationWarning``) and is the object of the new
module.
"""

from typing import Any

from hamilton_orbits.deprecation import moved_name

# served by __getattr__ below, each with its warning
__all__ = ["BODIES", "RUNGS", "Rung", "RungResult", "residuals", "run_rung"]  # noqa: F822


def __getattr__(name: str) -> Any:
    return moved_name(__name__, dict.fromkeys(__all__, "hamilton_orbits.studies.ladder"), name)
