"""Earth orientation: the Earth as a rigid body, its observed pole, and the pole's future.

``rigid.earth`` itself is the Earth as a rigid body (issue 9; the names of
:mod:`rigid.earth.constants` and :mod:`rigid.earth.free_wobble`): the IERS 2010
constants as Quantities (``GM``, ``R_EQ``, ``OMEGA``, ``J2``, ``H``, ``C22_BAR``,
``S22_BAR``), :func:`mass`, :func:`moments`, :func:`euler_period`,
:func:`secular_love_number`, :func:`chandler_period`, :func:`rigid_body`, and the
simulated free wobble (:func:`simulate_wobble`, :class:`PolePath`,
:func:`pole_path`).

One module per concept of Earth orientation (the public facade over the polar
motion ones is :mod:`rigid.polar_motion`):

========================================  ==================================================
:mod:`rigid.earth.constants`              cited constants, moments, Euler / Chandler periods
:mod:`rigid.earth.free_wobble`            the rigid Earth's free wobble, integrated or exact
:mod:`rigid.earth.c04`                    the IERS 20 C04 record, the IERS 2010 mean pole
:mod:`rigid.earth.wobble_fit`             the Chandler and annual wobble fit, periodogram
:mod:`rigid.earth.liouville`              the linearised Liouville pole and its effects
:mod:`rigid.earth.ar_models`              vector autoregressions (fit, forecast, errors)
:mod:`rigid.earth.forecasters`            the five prediction methods on plain floats
:mod:`rigid.earth.prediction`             ``predict`` and ``hindcast`` on the C04 record
:mod:`rigid.earth.scene_polar_motion`     the ``polar_motion`` scene kind
:mod:`rigid.earth.scene_pole_prediction`  the ``pole_prediction`` scene kind
========================================  ==================================================

Imports run one way: the constants stand on :mod:`rigid.body` only; the record,
the fit, the Liouville pole and the prediction stand on the constants and on
each other from the bottom up (``c04`` < ``wobble_fit`` < ``liouville``;
``ar_models`` < ``forecasters`` < ``prediction``); nothing here imports
:mod:`rigid.polar_motion`, which imports them.

Examples
--------
>>> from rigid import earth
>>> print(f"{earth.euler_period():.2f}", f"{earth.chandler_period(0.28):.1f}")
303.62 d 432.8 d
"""

from __future__ import annotations

from rigid.earth.constants import (
    C22_BAR,
    GM,
    J2,
    OMEGA,
    R_EQ,
    S22_BAR,
    H,
    chandler_period,
    euler_period,
    mass,
    moments,
    rigid_body,
    secular_love_number,
)
from rigid.earth.free_wobble import PolePath, pole_path, simulate_wobble

__all__ = [
    "C22_BAR",
    "GM",
    "J2",
    "OMEGA",
    "R_EQ",
    "S22_BAR",
    "H",
    "PolePath",
    "chandler_period",
    "euler_period",
    "mass",
    "moments",
    "pole_path",
    "rigid_body",
    "secular_love_number",
    "simulate_wobble",
]
