"""rigid: rigid-body attitude dynamics on the hamilton_orbits quaternion core.

Cayley (1843) and Sylvester (1866) made executable.  The curated public API.
"""


from rigid.body import RigidBody
from rigid.free import FreeParameters, free_motion, free_motion_arrays, free_parameters
from rigid.integrators import (
    BodyTorque,
    GravityGradientTorque,
    RigidTrajectory,
    SpaceTorque,
    integrate,
)

__all__: list[str] = [
    "BodyTorque",
    "FreeParameters",
    "GravityGradientTorque",
    "RigidBody",
    "RigidTrajectory",
    "SpaceTorque",
    "free_motion",
    "free_motion_arrays",
    "free_parameters",
    "integrate",
]
