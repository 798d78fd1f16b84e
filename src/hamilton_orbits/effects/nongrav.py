"""The effect ``nongrav``: comets' and asteroids' non-gravitational accelerations.

Marsden, Sekanina & Yeomans (1973), AJ 78, 211, eq. (1)-(2): a body's acceleration
relative to the centre (the Sun) ``g(r) (A1 r^ + A2 t^ + A3 n^)``, radial,
transverse (in the orbit's plane, along the motion) and normal (along ``r x v``),
with ``g(r) = alpha (r / r0)^-m (1 + (r / r0)^n)^-k``.  The default ``g`` is the
asteroid form of JPL's small-body solutions, ``(1 au / r)^2`` (``alpha = 1``,
``r0 = 1 au``, ``m = 2``, ``n = k = 0``), the form of a Yarkovsky ``A2``; the
comet form of the paper (water-ice sublimation) is ``alpha = 0.1112620426``,
``r0 = 2.808 au``, ``m = 2.15``, ``n = 5.093``, ``k = 4.6142``
(:data:`COMET_G`).  Nothing acts back on the centre (the momentum leaves with the
gas or the photons), so the system's energy and momentum are not conserved.

Kernel :func:`~hamilton_orbits._kernels.nongrav.nongrav`; no analytic Jacobian
(the variational equations differentiate the kernel by compiled central
differences, :mod:`hamilton_orbits.rhs`); velocity dependent.  ``p = [centre,
m, then per body: index, A1, A2, A3, alpha, r0, m, n, k]``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from hamilton_orbits._kernels.nongrav import nongrav
from hamilton_orbits.effects.parameters import body_index, parameter_array
from hamilton_orbits.effects.registry import EffectSpec
from hamilton_orbits.units import ACCELERATION, DIMENSIONLESS, LENGTH

__all__ = ["COMET_G", "SPECS"]

#: Marsden, Sekanina & Yeomans (1973), eq. (2): g(r) of water-ice sublimation,
#: normalised to g(1 au) = 1
COMET_G = {"alpha": 0.1112620426, "r0": 2.808, "m": 2.15, "n": 5.093, "k": 4.6142}
MSY_1973 = "Marsden, Sekanina & Yeomans (1973), AJ 78, 211, eq. (1)-(2)"


def _bodies(system: Any, params: Mapping[str, Any]) -> list[int]:
    names = params.get("body")
    if names is None:
        raise ValueError("Effect 'nongrav': expected `body`, the body (or a list of the "
                         "bodies) it acts on")
    names = [names] if isinstance(names, str) else list(names)
    if not names:
        raise ValueError("Effect 'nongrav': expected `body`, the body (or a list of the "
                         "bodies) it acts on, got an empty list")
    out = [body_index(system, {"body": n}, "body", "", "nongrav") for n in names]
    for k, b in enumerate(out):
        if out.index(b) != k:
            raise ValueError(f"Effect 'nongrav': expected each body once in `body`, got "
                             f"{names[k]!r} twice (at indices {out.index(b)} and {k})")
    return out


#: the largest ``m``: ``(r / r0)^-m`` overflows to infinity (and ``g`` with it, NaN with
#: an ``A`` of zero) within ``10^(-308.25 / m) r0`` of the centre; with m <= 100 only
#: within 8.3e-4 r0 (inside the Sun for r0 = 1 au), where the fitted forms (m = 2 of
#: the asteroids' A2, 2.15 of the comets', Marsden et al. 1973) have no meaning anyway
M_MAX = 100.0

#: the parameters of each body's row beside its index: (name, kind, default, check)
_ROW = (("A1", ACCELERATION, 0.0, ""), ("A2", ACCELERATION, 0.0, ""),
        ("A3", ACCELERATION, 0.0, ""), ("alpha", DIMENSIONLESS, 1.0, "positive"),
        ("r0", LENGTH, 1.0, "positive"),  # (1 au; 1 in the units of plain floats)
        ("m", DIMENSIONLESS, 2.0, "exponent"), ("n", DIMENSIONLESS, 0.0, "nonnegative"),
        ("k", DIMENSIONLESS, 0.0, "nonnegative"))


def _rows(system: Any, params: Mapping[str, Any], n: int) -> np.ndarray:
    """Each of ``n`` bodies' A1, A2, A3, alpha, r0, m, n, k, (n, 8), in the system's
    units: every parameter one value for all, or a list of one per body."""
    out = np.empty((n, len(_ROW)))
    for j, (key, kind, default, check) in enumerate(_ROW):
        value = parameter_array(system, params, key, "nongrav", kind)
        value = np.float64(default) if value is None else value
        if value.shape not in ((), (n,)):
            raise ValueError(f"Effect 'nongrav': expected `{key}` to be one value or {n} "
                             f"(one per body), got {params[key]!r}")
        out[:, j] = value
        bad = (out[:, j] <= 0) if check == "positive" else (
            out[:, j] < 0) if check == "nonnegative" else ~(
            (out[:, j] >= 0) & (out[:, j] <= M_MAX)) if check == "exponent" else np.zeros(
            n, bool)
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            need = {"positive": "> 0", "nonnegative": ">= 0"}.get(
                check, f"within [0, {M_MAX:g}] (the (r / r0)^-m of g(r) overflows within "
                       f"10^(-308.25 / m) r0 of the centre: within r0 / 2 for m >= 1024)")
            raise ValueError(f"Effect 'nongrav': expected `{key}` {need}, got "
                             f"{params[key]!r} (body {k})")
    return out


def _params_nongrav(system: Any, params: Mapping[str, Any]) -> np.ndarray:
    centre = body_index(system, params, "centre", "sun", "nongrav")
    bodies = _bodies(system, params)
    if centre in bodies:
        raise ValueError(f"Effect 'nongrav': the centre {system.names[centre]!r} cannot be "
                         f"one of the bodies it acts on")
    rows = _rows(system, params, len(bodies))
    table = np.column_stack([np.asarray(bodies, dtype=np.float64), rows])
    return np.array([centre, len(bodies), *table.ravel()], dtype=np.float64)


SPECS = (
    EffectSpec(
        name="nongrav", kind="nbody",
        summary="non-gravitational accelerations A1, A2, A3 g(r) of comets and asteroids "
                "(Marsden, Sekanina & Yeomans 1973)",
        velocity_dependent=True,
        parameters={"body": "the body it acts on (a list of them outside scenes)",
                    "A1": "radial acceleration at r0, an acceleration (default 0)",
                    "A2": "transverse acceleration at r0 (default 0)",
                    "A3": "normal acceleration at r0 (default 0)",
                    "centre": "default 'sun'",
                    "alpha": "g's scale, default 1", "r0": "a length, default 1 au",
                    "m": "default 2", "n": "default 0",
                    "k": "default 0 (A1 ... k: one value, or a list of one per body)"},
        kernel=nongrav, params=_params_nongrav,
        parameter_kinds={"A1": ACCELERATION, "A2": ACCELERATION, "A3": ACCELERATION,
                         "r0": LENGTH, "alpha": DIMENSIONLESS, "m": DIMENSIONLESS,
                         "n": DIMENSIONLESS, "k": DIMENSIONLESS},
        name_parameters=("body", "centre"),
        reference=MSY_1973,
    ),
)
