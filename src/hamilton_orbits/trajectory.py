"""The shape every trajectory shares: :class:`TrajectoryBase`.

An n-body :class:`~hamilton_orbits.simulation.Trajectory` and a rigid body's
``rigid.RigidTrajectory`` answer the same first questions the same way: at
which times (``t``), in how many steps (``steps``), in how much wall-clock time
(``wall_time``), with which method, and how well the integrals of the motion
were kept (``energy_error``, ``angular_momentum_error``: Hamilton's law of
vis viva (E) and of areas (D) for the n-body problem; Cayley's free-body
integrals of energy and of the angular momentum in space for a rigid body).

Units follow one rule in both packages: where the caller gave Quantities, the
results are Quantities (in the units documented by each subclass); where the
caller gave plain floats, they are plain floats in the caller's own units.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["TrajectoryBase", "relative_change"]


@dataclass(frozen=True, eq=False, kw_only=True)
class TrajectoryBase:
    """The attributes every trajectory has.

    Attributes
    ----------
    t : ndarray or Quantity, shape (n_t,)
        Output times; ``t[0]`` is the start.
    steps : int
        Steps taken by the integrator (0 for an exact solution).
    wall_time : float
        Seconds of wall-clock time of the integration proper (not the
        validation of the input, nor the wrapping of the output).
    method : str
        The integrator's name.
    energy_error : ndarray, shape (n_t,)
        Relative change of the energy integral from ``t[0]`` (see the subclass).
    angular_momentum_error : ndarray, shape (n_t,)
        Relative change of the angular momentum vector from ``t[0]``.

    Examples
    --------
    >>> import numpy as np
    >>> base = TrajectoryBase(t=np.array([0.0, 1.0]), steps=4, wall_time=0.0,
    ...                       method="exact", energy_error=np.zeros(2),
    ...                       angular_momentum_error=np.zeros(2))
    >>> base.n_outputs, base.steps
    (2, 4)
    """

    t: Any
    steps: int
    wall_time: float
    method: str
    energy_error: np.ndarray
    angular_momentum_error: np.ndarray

    @property
    def n_outputs(self) -> int:
        """The number of output times (``len(t)``)."""
        return int(np.shape(self.t)[0])


def relative_change(values: np.ndarray) -> np.ndarray:
    """``(x(t) - x(0)) / |x(0)|`` for scalars, ``|x(t) - x(0)| / |x(0)|`` for
    vectors (last axis), and the absolute change where ``x(0) = 0``.

    Parameters
    ----------
    values : ndarray, shape (n_t,) or (n_t, k)

    Examples
    --------
    >>> relative_change(np.array([2.0, 2.0, 3.0])).tolist()
    [0.0, 0.0, 0.5]
    >>> relative_change(np.array([[0.0, 2.0], [0.0, 2.0], [2.0, 2.0]])).tolist()
    [0.0, 0.0, 1.0]
    >>> relative_change(np.zeros(2)).tolist()
    [0.0, 0.0]
    """
    x = np.asarray(values, dtype=np.float64)
    if x.ndim == 1:
        scale = abs(x[0])
        d = x - x[0]
    else:
        scale = float(np.linalg.norm(x[0]))
        d = np.linalg.norm(x - x[0], axis=-1)
    return d / scale if scale > 0 else d
