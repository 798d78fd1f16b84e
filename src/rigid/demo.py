"""The rigid-body section of the ``hamilton-orbits`` demo (entry point
``hamilton_orbits.demos``: ``rigid``)."""

from __future__ import annotations

import astropy.units as u
import numpy as np

from rigid.body import RigidBody
from rigid.free import free_motion, free_parameters


def flip_demo() -> None:
    """Print the tennis-racket (Dzhanibekov) flip from the exact free motion.

    Examples
    --------
    >>> flip_demo()  # doctest: +ELLIPSIS
    Sylvester's free rigid body: the tennis-racket (Dzhanibekov) flip
    ...
    """
    print("Sylvester's free rigid body: the tennis-racket (Dzhanibekov) flip")
    body = RigidBody([1.0, 2.0, 3.0] * u.kg * u.m**2, omega=[1e-3, 2.0, 1e-3] * u.rad / u.s)
    par = free_parameters(body)
    half = par.flip_interval.to_value(u.s)
    print(f"  spin about the middle axis: the body flips every {half:.4f} s")
    t = np.arange(4) * par.flip_interval
    _, omega = free_motion(body, t)
    print(
        "  omega_2 [rad/s] after 0, 1, 2, 3 flip intervals:",
        np.round(omega[:, 1].to_value(u.rad / u.s), 9),
    )
