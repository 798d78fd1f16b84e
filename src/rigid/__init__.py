"""rigid: rigid-body attitude dynamics on the hamilton_orbits quaternion core.

Cayley (1843) and Sylvester (1866) made executable.

Where to start
--------------
- A body: :class:`RigidBody` (principal moments; :func:`disk_equivalent`).
- Torque-free motion in closed form: :func:`free_motion` (and
  :func:`free_motion_arrays`, :func:`free_parameters`, :class:`FreeMotion`,
  :class:`FreeParameters`, :func:`time_between`); Poinsot's construction:
  :func:`poinsot`, :class:`PoinsotPaths`, :func:`plot_poinsot`;
  Sylvester's confocal quadrics: :func:`confocal`, :func:`contrafocal`,
  :func:`confocal_rotation`.
- Numerical integration with torques: :func:`integrate` with
  :class:`BodyTorque`, :class:`SpaceTorque`, :class:`GravityGradientTorque`
  (or :class:`BodySI` units); the result is a :class:`RigidTrajectory`.

The Earth's pole (polar motion, the Chandler wobble, prediction) is in
``rigid.polar_motion`` and ``rigid.earth``.  Everything not listed in
``__all__`` is private.
"""


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


def __getattr__(name: str):
    """``rigid.earth`` and ``rigid.polar_motion`` imported on first use: ``import
    rigid`` (which every ``hamilton-orbits`` command's scene-kind lookup does) leaves
    out the polar-motion record, its fit and its predictions (astropy tables)."""
    import importlib

    if name == "earth":
        return importlib.import_module("rigid.earth")
    if name == "polar_motion":
        return importlib.import_module("rigid.polar_motion")
    raise AttributeError(f"module 'rigid' has no attribute {name!r}")
