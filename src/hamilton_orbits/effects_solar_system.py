"""The solar-system effects of JPL's ephemerides: EIH, figures, tides, the Kuiper belt.

Registered in :mod:`hamilton_orbits.effects` (from :data:`SPECS`) as ``"nbody"``
effects, each computed only when listed:

``eih``
    The Einstein-Infeld-Hoffmann equations for every body (Newtonian gravity plus
    its first post-Newtonian correction, PPN beta = gamma = 1 as DE440 has them),
    replacing Newtonian gravity; do not list ``gr`` with it.  Moyer (2003), eq.
    4-26; Park et al. (2021), eq. 1.
``zonal``
    Zonal harmonics of one body about its pole; for the Earth (default) DE440's
    ``RE``, ``J2E``, ``J3E``, ``J4E``, acting on every other body (the Moon above all).
``moon_figure``
    The Moon's degree-2 figure (DE440's ``AM``, ``J2M``, ``C22M``) in principal axes
    from the Earth-Moon geometry and Cassini's laws, acting on every other body.
``earth_tides``
    The tides the Moon and the Sun raise on the Earth acting on the Moon, DE440's
    constant-time-lag model (``K2E0..2``, ``TAUE0..2``, ``TAUER1..2``): it gives the
    Moon its secular deceleration.
``kuiper_ring``
    The Kuiper belt as DE440 models it: a ring of radius 44 au in the ecliptic,
    centred on the Sun, of the total GM of DE440's 36 ring masses (``MA8201`` ...
    ``MA8236``).

Variational equations (``variational=True``): ``zonal`` and ``lense_thirring``
have analytic Jacobians (:mod:`hamilton_orbits._kernels.jacobians`); ``eih``,
``moon_figure``, ``earth_tides`` and ``kuiper_ring`` are differentiated by compiled
central differences of their own kernels along each tangent vector (about 1e-10
relative; see :class:`~hamilton_orbits.effects.EffectSpec`), which is what the
time allowed: their analytic Jacobians (EIH's is three pages of terms, the Moon's
frame and the tides' delays are nested functions of the state) are left for later.

The Sun's J2 is the existing ``j2`` effect (``{"name": "j2", "body": "sun"}``):
:meth:`~hamilton_orbits.nbody.System.from_ephemeris` gives the Sun DE440's
``J2SUN`` and ``ASUN`` about its IAU pole.

Parameters that name bodies take their names; defaults need a DE440 system
(:meth:`~hamilton_orbits.nbody.System.from_ephemeris`, Quantity units au, day).
Effects that need the ecliptic or the Sun's pole take ``frame`` (``"icrs"`` or
``"ecliptic"``), the frame of the system's axes; by default it is recognised from
the Sun's pole that ``from_ephemeris`` sets, else ``"icrs"``.

References
----------
T. D. Moyer, *Formulation for Observed and Computed Values of Deep Space Network
Data Types for Navigation*, JPL DESCANSO monograph 2 (2003), eq. 4-26.
R. S. Park, W. M. Folkner, J. G. Williams, D. H. Boggs, AJ 161, 105 (2021).
W. M. Folkner, J. G. Williams, D. H. Boggs, R. S. Park, P. Kuchynka, "The Planetary
and Lunar Ephemerides DE430 and DE431", IPN Progress Report 42-196 (2014), eq. 32.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from hamilton_orbits import ephemeris as de
from hamilton_orbits._kernels import figures as _figures
from hamilton_orbits._kernels import jacobians as _jacobians
from hamilton_orbits._kernels import relativity as _relativity

__all__ = [
    "EARTH_ROTATION_RATE",
    "KUIPER_RING_RADIUS_AU",
    "MOON_EQUATOR_INCLINATION_DEG",
    "SPECS",
    "eih_energy",
    "kuiper_ring_gm",
    "sun_spin",
]

# IERS Conventions 2010, table 1.1: the Earth's nominal mean angular velocity, rad/s
EARTH_ROTATION_RATE = 7.292115e-5
# Park et al. (2021), section 3: DE440's Kuiper-belt ring, 36 point masses at 44 au
KUIPER_RING_RADIUS_AU = 44.0
# The mean inclination of the lunar equator to the ecliptic, I = 1.5424 deg
# (Cassini's third law; the IAU lunar rotation model, Archinal et al. 2018, and
# Eckhardt 1981's I = 1 deg 32' 33")
MOON_EQUATOR_INCLINATION_DEG = 1.5424


def _index(system: Any, params: Mapping[str, Any], key: str, default: str,
           effect: str) -> int:
    name = params.get(key, default)
    if name not in system.names:
        raise ValueError(
            f"Effect {effect!r}: `{key}` names body {name!r}, which is not in the system; "
            f"bodies: {', '.join(system.names)}"
        )
    return system.names.index(name)


def _require_de440_units(system: Any, params: Mapping[str, Any], effect: str,
                         keys: tuple[str, ...]) -> None:
    """Defaults are DE440's constants in au and days: a plain-float system must give
    every length and time itself."""
    if system.quantity:
        return
    missing = [k for k in keys if k not in params]
    if missing:
        raise ValueError(
            f"Effect {effect!r}: a system of plain floats needs {', '.join(missing)} in "
            "its own units (the defaults are DE440's in au and days)"
        )


def _floats(name: str, value: Any, size: int | None, effect: str) -> np.ndarray:
    arr = np.atleast_1d(np.asarray(value, dtype=float))
    if arr.ndim != 1 or (size is not None and arr.shape[0] != size) or not np.all(
            np.isfinite(arr)):
        raise ValueError(f"Effect {effect!r}: expected `{name}` to be "
                         f"{size or 'some'} finite number(s), got {value!r}")
    return arr


def _unit_vector(name: str, value: Any, effect: str) -> np.ndarray:
    k = _floats(name, value, 3, effect)
    norm = float(np.linalg.norm(k))
    if not norm > 0:
        raise ValueError(f"Effect {effect!r}: expected `{name}` to be nonzero, got {value!r}")
    return k / norm


def _frame(system: Any, params: Mapping[str, Any], effect: str) -> str:
    """The frame of the system's axes: ``params["frame"]``, else recognised from the
    Sun's pole that :meth:`System.from_ephemeris` sets (IAU pole in that frame), else
    ``"icrs"``."""
    frame = params.get("frame")
    if frame is None:
        frame = "icrs"
        if "sun" in system.names and system["sun"].pole is not None:
            pole = np.array(system["sun"].pole)
            if np.allclose(pole, de.sun_pole("ecliptic"), rtol=0, atol=1e-12):
                frame = "ecliptic"
    if frame not in ("icrs", "ecliptic"):
        raise ValueError(f"Effect {effect!r}: expected `frame` 'icrs' or 'ecliptic', "
                         f"got {frame!r}")
    return frame


def _c_au_per_day() -> float:
    return de.constant("CLIGHT") * 86400.0 / de.constant("AU")


def _params_eih(system: Any, params: Mapping[str, Any]) -> np.ndarray:
    _require_de440_units(system, params, "eih", ("c",))
    c = float(params.get("c", _c_au_per_day()))
    beta = float(params.get("beta", de.constant("BETA")))
    gamma = float(params.get("gamma", de.constant("GAMMA")))
    if not (np.isfinite(c) and c > 0 and np.isfinite(beta) and np.isfinite(gamma)):
        raise ValueError(f"Effect 'eih': expected c > 0 and finite beta, gamma; got "
                         f"{c!r}, {beta!r}, {gamma!r}")
    sources: list[int] = []
    if "sources" in params:
        names = params["sources"]
        if isinstance(names, str) or not all(isinstance(x, str) for x in names):
            raise ValueError(f"Effect 'eih': expected `sources` to be a list of body names, "
                             f"got {names!r}")
        sources = [_index(system, {"sources": x}, "sources", "", "eih") for x in names]
        if not sources:
            raise ValueError("Effect 'eih': `sources` is empty")
    return np.array([c, beta, gamma, *sources], dtype=float)


def _pole(system: Any, b: int, params: Mapping[str, Any], effect: str) -> np.ndarray:
    if "pole" in params:
        return _unit_vector("pole", params["pole"], effect)
    pole = system.bodies[b].pole
    if pole is not None:
        return np.array(pole)
    return de.frame_rotation(_frame(system, params, effect)) @ [0.0, 0.0, 1.0]


def _params_zonal(system: Any, params: Mapping[str, Any]) -> np.ndarray:
    b = _index(system, params, "body", "earth", "zonal")
    if system.names[b] != "earth" or not system.quantity:
        for key in ("j", "radius"):
            if key not in params:
                raise ValueError(f"Effect 'zonal': body {system.names[b]!r} needs `{key}` "
                                 "(DE440's defaults are the Earth's, in au)")
    j = _floats("j", params.get("j", [de.constant(f"J{n}E") for n in (2, 3, 4)]), None,
                "zonal")
    radius = float(params.get("radius", de.constant("RE") / de.constant("AU")))
    if not radius > 0:
        raise ValueError(f"Effect 'zonal': expected `radius` > 0, got {radius!r}")
    return np.array([b, radius, *_pole(system, b, params, "zonal"), *j])


def _params_moon_figure(system: Any, params: Mapping[str, Any]) -> np.ndarray:
    m = _index(system, params, "moon", "moon", "moon_figure")
    e = _index(system, params, "earth", "earth", "moon_figure")
    _require_de440_units(system, params, "moon_figure", ("radius",))
    radius = float(params.get("radius", de.constant("AM") / de.constant("AU")))
    j2 = float(params.get("j2", de.constant("J2M")))
    c22 = float(params.get("c22", de.constant("C22M")))
    inc = np.deg2rad(float(params.get("inclination_deg", MOON_EQUATOR_INCLINATION_DEG)))
    pole = de.ecliptic_pole(_frame(system, params, "moon_figure"))
    return np.array([m, e, radius, j2, c22, *pole, inc])


def _params_earth_tides(system: Any, params: Mapping[str, Any]) -> np.ndarray:
    e = _index(system, params, "earth", "earth", "earth_tides")
    m = _index(system, params, "moon", "moon", "earth_tides")
    _require_de440_units(system, params, "earth_tides", ("radius", "omega", "tau"))
    sun_name = params.get("sun", "sun")
    sun = system.names.index(sun_name) if sun_name in system.names else -1
    radius = float(params.get("radius", de.constant("RE") / de.constant("AU")))
    omega = float(params.get("omega", EARTH_ROTATION_RATE * 86400.0))
    k2 = _floats("k2", params.get("k2", [de.constant(f"K2E{j}") for j in range(3)]), 3,
                 "earth_tides")
    tau = _floats("tau", params.get("tau", [de.constant(k) for k in (
        "TAUE0", "TAUE1", "TAUE2", "TAUER1", "TAUER2")]), 5, "earth_tides")
    pole = _pole(system, e, params, "earth_tides")
    return np.array([e, m, sun, radius, omega, *pole, *k2, *tau])


def kuiper_ring_gm() -> float:
    """The GM of DE440's Kuiper-belt ring: the sum of its 36 ring masses, au^3/day^2.

    Examples
    --------
    >>> round(kuiper_ring_gm() / de.constant("GMS") / 3.0034896e-6, 4)  # Earth masses
    0.0224
    """
    c = de.constants()
    return float(sum(c[f"MA{8200 + k}"] for k in range(1, 37)))


def _params_kuiper_ring(system: Any, params: Mapping[str, Any]) -> np.ndarray:
    b = _index(system, params, "centre", "sun", "kuiper_ring")
    _require_de440_units(system, params, "kuiper_ring", ("gm", "radius"))
    big_m = float(params.get("gm", kuiper_ring_gm()))
    radius = float(params.get("radius", KUIPER_RING_RADIUS_AU))
    if not (big_m >= 0 and radius > 0):
        raise ValueError(f"Effect 'kuiper_ring': expected gm >= 0 and radius > 0, got "
                         f"{big_m!r}, {radius!r}")
    normal = (_unit_vector("normal", params["normal"], "kuiper_ring") if "normal" in params
              else de.ecliptic_pole(_frame(system, params, "kuiper_ring")))
    return np.array([b, big_m, radius, *normal])


def sun_spin(frame: str = "icrs") -> np.ndarray:
    """The Sun's spin angular momentum per unit mass (au^2/day) from DE440's constants.

    ``MOISUN * ASUN^2 * OMGSUN`` (moment-of-inertia factor, radius, rotation rate in
    rad/day) along the Sun's IAU pole in ``frame``.

    Examples
    --------
    >>> round(float(np.linalg.norm(sun_spin())) * 1e7, 3)  # au^2/day
    3.689
    """
    radius = de.constant("ASUN") / de.constant("AU")
    size = de.constant("MOISUN") * radius**2 * de.constant("OMGSUN")
    return size * de.sun_pole(frame)


def _params_lense_thirring(system: Any, params: Mapping[str, Any]) -> np.ndarray:
    b = _index(system, params, "body", "sun", "lense_thirring")
    _require_de440_units(system, params, "lense_thirring", ("c", "spin"))
    if system.names[b] != "sun" and "spin" not in params:
        raise ValueError("Effect 'lense_thirring': a body other than the Sun needs `spin`")
    spin = (_floats("spin", params["spin"], 3, "lense_thirring") if "spin" in params
            else sun_spin(_frame(system, params, "lense_thirring")))
    c = float(params.get("c", _c_au_per_day()))
    gamma = float(params.get("gamma", de.constant("GAMMA")))
    return np.array([b, c, gamma, *spin])


_PARK = "Park et al. (2021), AJ 161, 105"
SPECS: tuple[dict[str, Any], ...] = (
    {
        "name": "eih", "kind": "nbody",
        "summary": "Einstein-Infeld-Hoffmann 1PN n-body gravity (replaces Newtonian; radau15)",
        "velocity_dependent": True, "replaces_newtonian": True,
        "parameters": {"c": "speed of light (default DE440's CLIGHT in au/day)",
                       "beta": "PPN beta (default DE440's, 1)",
                       "gamma": "PPN gamma (default DE440's, 1)",
                       "sources": "bodies whose 1PN field is computed (default every "
                                  "massive body; the others act by Newton's law)"},
        "kernel": _relativity.eih, "params": _params_eih,
        "reference": f"Moyer (2003), DESCANSO monograph 2, eq. 4-26; {_PARK}",
    },
    {
        "name": "lense_thirring", "kind": "nbody",
        "summary": "the Sun's gravitomagnetic (Lense-Thirring) field, DE440's spin",
        "velocity_dependent": True,
        "parameters": {"body": "default 'sun'",
                       "spin": "angular momentum per unit mass (default DE440's "
                               "MOISUN ASUN^2 OMGSUN about the IAU pole)",
                       "c": "default DE440's CLIGHT", "gamma": "default DE440's GAMMA",
                       "frame": "'icrs' or 'ecliptic' (default: from the Sun's pole)"},
        "kernel": _relativity.lense_thirring, "params": _params_lense_thirring,
        "jacobian": _jacobians.lense_thirring_jvp,
        "reference": f"IERS Conventions (2010), eq. 10.12; {_PARK}",
    },
    {
        "name": "zonal", "kind": "nbody",
        "summary": "zonal harmonics J2..Jn of one body (default the Earth's J2, J3, J4)",
        "parameters": {"body": "the body (default 'earth')",
                       "j": "[J2, J3, ...] (default DE440's J2E, J3E, J4E)",
                       "radius": "reference radius (default DE440's RE)",
                       "pole": "pole vector (default the Body's pole)",
                       "frame": "'icrs' or 'ecliptic' (pole default without a Body pole)"},
        "kernel": _figures.zonal_field, "params": _params_zonal,
        "jacobian": _jacobians.zonal_field_jvp,
        "reference": f"Moyer (1971), JPL TR 32-1527, eqs. 173-174; {_PARK}",
    },
    {
        "name": "moon_figure", "kind": "nbody",
        "summary": "the Moon's J2 and C22 in axes from Cassini's laws, on every other body",
        # its axes follow the orbit normal, from the Earth-Moon relative velocity
        "velocity_dependent": True,
        "parameters": {"moon": "default 'moon'", "earth": "default 'earth'",
                       "radius": "default DE440's AM", "j2": "default DE440's J2M",
                       "c22": "default DE440's C22M",
                       "inclination_deg": "lunar equator to ecliptic (default 1.5424)",
                       "frame": "'icrs' or 'ecliptic' (default: from the Sun's pole)"},
        "kernel": _figures.moon_figure, "params": _params_moon_figure,
        "reference": f"Folkner et al. (2014), IPN PR 42-196, eq. 28; {_PARK}",
    },
    {
        "name": "earth_tides", "kind": "nbody",
        "summary": "tides raised on the Earth by the Moon and Sun acting on the Moon (DE440)",
        "velocity_dependent": True,
        "parameters": {"earth": "default 'earth'", "moon": "default 'moon'",
                       "sun": "tide raiser besides the Moon (default 'sun' if present)",
                       "radius": "default DE440's RE", "omega": "Earth's rotation rate",
                       "k2": "[k20, k21, k22] (default DE440's K2E0..2)",
                       "tau": "[TAUE0, TAUE1, TAUE2, TAUER1, TAUER2] (default DE440's)",
                       "pole": "Earth's pole (default the Body's pole)",
                       "frame": "'icrs' or 'ecliptic' (pole default without a Body pole)"},
        "kernel": _figures.earth_tides, "params": _params_earth_tides,
        "reference": f"Folkner et al. (2014), IPN PR 42-196, eq. 32; {_PARK}",
    },
    {
        "name": "kuiper_ring", "kind": "nbody",
        "summary": "the Kuiper belt as DE440's ring (44 au, ecliptic, centred on the Sun)",
        "parameters": {"centre": "default 'sun'", "gm": "default DE440's 36 ring masses",
                       "radius": "default 44 au", "normal": "default the ecliptic pole",
                       "frame": "'icrs' or 'ecliptic' (default: from the Sun's pole)"},
        "kernel": _figures.ring_field, "params": _params_kuiper_ring,
        "reference": f"{_PARK}, section 3 (ring masses MA8201..MA8236)",
    },
)


def eih_energy(r: np.ndarray, v: np.ndarray, gm: np.ndarray, c: float) -> float:
    """The conserved energy of the EIH equations, in gm units (G times the energy).

    The Einstein-Infeld-Hoffmann Lagrangian (Landau & Lifshitz, *The Classical
    Theory of Fields*, eq. 106.17) gives, with ``n_ab`` the unit vector from b to a,

        E = sum_a gm_a v_a^2 / 2 + 3/(8 c^2) sum_a gm_a v_a^4
            - 1/2 sum_{a != b} gm_a gm_b / r_ab
            + 1/c^2 sum_{a != b} gm_a gm_b / r_ab
                  [3 v_a^2 / 2 - (7 v_a . v_b + (v_a . n_ab)(v_b . n_ab)) / 4]
            + 1/(2 c^2) sum_a sum_{b != a} sum_{k != a} gm_a gm_b gm_k / (r_ab r_ak),

    which the EIH accelerations of the ``eih`` effect (PPN beta = gamma = 1) conserve
    up to second post-Newtonian order.

    Parameters
    ----------
    r, v : ndarray, shape (n, 3)
    gm : ndarray, shape (n,)
    c : float
        The speed of light in the same units.

    Examples
    --------
    >>> r = np.array([[0.0, 0, 0], [1.0, 0, 0]])
    >>> v = np.array([[0.0, 0, 0], [0.0, 1.0, 0]])
    >>> eih_energy(r, v, np.array([1.0, 0.0]), 1e8)  # a test particle adds nothing
    0.0
    """
    r = np.asarray(r, dtype=float)
    v = np.asarray(v, dtype=float)
    gm = np.asarray(gm, dtype=float)
    c2 = float(c) ** 2
    d = r[:, None, :] - r[None, :, :]  # r_a - r_b
    dist = np.sqrt(np.einsum("abk,abk->ab", d, d))
    np.fill_diagonal(dist, np.inf)
    inv = 1.0 / dist
    n = d * inv[:, :, None]
    v2 = np.einsum("ak,ak->a", v, v)
    gg = gm[:, None] * gm[None, :] * inv
    vv = v @ v.T
    van = np.einsum("abk,ak->ab", n, v)  # v_a . n_ab
    vbn = np.einsum("abk,bk->ab", n, v)  # v_b . n_ab
    pair = np.sum(gg * (1.5 * v2[:, None] - 0.25 * (7.0 * vv + van * vbn))) / c2
    phi = (gm[None, :] * inv).sum(axis=1)  # sum_{b != a} gm_b / r_ab
    triple = np.sum(gm * phi * phi) / (2.0 * c2)
    newton = 0.5 * np.sum(gm * v2) - 0.5 * np.sum(gg)
    return float(newton + 3.0 / (8.0 * c2) * np.sum(gm * v2 * v2) + pair + triple)
