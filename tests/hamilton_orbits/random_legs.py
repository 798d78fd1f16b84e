"""Random legs of fixed-step runs for the tests of the close-approach check.

Import with ``from random_legs import random_leg`` (tests/hamilton_orbits is on the
path, as for ``hard_cases``).
"""

from __future__ import annotations

import numpy as np

from hamilton_orbits.integrals import ENCOUNTER_STEP_FRACTION

__all__ = ["random_leg"]


def random_leg(rng: np.random.Generator) -> tuple:
    """``r``, ``v`` (n_t, n, 3), ``gm`` (n,), ``t`` (n_t,), ``step`` and ``fraction``
    of a random leg: 2 to 6 bodies (test particles, bodies as light as
    ``integrals.LIGHT`` and massive ones, one of GM 1), 2 to 5 outputs, distances
    from 1e-3 to 3 so that close pairs pass between outputs, steps from 1e-4 to
    0.3."""
    n, n_t = int(rng.integers(2, 7)), int(rng.integers(2, 6))
    gm = rng.choice([0.0, 1e-12, 1e-5, 1e-3, 1.0], size=n)
    gm[rng.integers(n)] = 1.0
    r = rng.normal(size=(n_t, n, 3)) * 10.0 ** rng.uniform(-3, 0.5)
    v = rng.normal(size=(n_t, n, 3))
    t = np.cumsum(rng.uniform(0.01, 0.5, n_t)) - 0.01
    step = float(10.0 ** rng.uniform(-4, -0.5))
    fraction = float(rng.choice([ENCOUNTER_STEP_FRACTION, 1.0 / 3.0]))
    return r, v, gm, t, step, fraction
