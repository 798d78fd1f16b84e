"""Polar motion: the public facade over the Liouville pole, the C04 record and the fit.

One import for the concepts of Earth orientation, each in its own module of
``rigid.earth``:

* :mod:`rigid.earth.liouville`: the linearised Liouville equation solved exactly,
  :class:`LiouvillePole`, its effects (:data:`EFFECTS`, registered as
  ``"rotation"`` effects by :func:`register_effects` on import);
* ``rigid.earth.c04``: the IERS 20 C04 record, :func:`load_c04` ->
  :class:`PolarMotionRecord`, and the IERS 2010 mean pole
  :func:`iers2010_mean_pole`;
* ``rigid.earth.wobble_fit``: the Chandler and annual wobble fit :func:`fit_wobble` ->
  :class:`WobbleFit`, the :func:`periodogram`, and :func:`free_period`;
* ``rigid.earth.prediction``: where the pole will be, :func:`predict`, and how
  well that is done on data the model never saw, :func:`hindcast` (the methods
  themselves in ``rigid.earth.forecasters``).

Conventions (IERS): the pole is ``m = m1 + i m2`` with ``m1 = x_p``,
``m2 = -y_p``; a prograde term is ``exp(+i sigma t)``.

Examples
--------
>>> from rigid import polar_motion
>>> rec = polar_motion.load_c04()
>>> print(rec.time[0].iso[:10], len(rec) > 23000)
1962-01-01 True
"""

from __future__ import annotations

from rigid.earth.c04 import PolarMotionRecord, iers2010_mean_pole, load_c04
from rigid.earth.liouville import EFFECTS, LiouvillePole, free_period, register_effects
from rigid.earth.prediction import hindcast, predict
from rigid.earth.wobble_fit import WobbleFit, fit_wobble, periodogram

__all__ = [
    "EFFECTS",
    "LiouvillePole",
    "PolarMotionRecord",
    "WobbleFit",
    "fit_wobble",
    "free_period",
    "hindcast",
    "iers2010_mean_pole",
    "load_c04",
    "periodogram",
    "predict",
    "register_effects",
]
