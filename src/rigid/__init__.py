"""rigid: rigid-body attitude dynamics on the hamilton_orbits quaternion core.

Cayley (1843) and Sylvester (1866) made executable.  The curated public API.
"""


from rigid import earth, polar_motion  # noqa: F401  (submodules: rigid.earth, ...)
from rigid.body import BodySI, RigidBody
from rigid.free import (
    FreeMotion,
    FreeParameters,
    free_motion,
    free_motion_arrays,
    free_parameters,
)
from rigid.integrators import (
    BodyTorque,
    GravityGradientTorque,
    RigidTrajectory,
    SpaceTorque,
    integrate,
)
from rigid.poinsot import PoinsotPaths, plot_poinsot, poinsot
from rigid.sylvester import confocal, confocal_rotation, contrafocal, disk_equivalent, time_between

__all__: list[str] = [
    "BodySI",
    "BodyTorque",
    "FreeMotion",
    "FreeParameters",
    "GravityGradientTorque",
    "PoinsotPaths",
    "RigidBody",
    "RigidTrajectory",
    "SpaceTorque",
    "confocal",
    "confocal_rotation",
    "contrafocal",
    "disk_equivalent",
    "free_motion",
    "free_motion_arrays",
    "free_parameters",
    "integrate",
    "plot_poinsot",
    "poinsot",
    "time_between",
]
