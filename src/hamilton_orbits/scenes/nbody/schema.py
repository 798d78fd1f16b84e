"""The keys of an ``nbody`` scene (``docs/scenes.md``): :data:`SCHEMA`, a body's
keys :data:`BODY`, the integrators, bodies and analyses a scene may name."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from hamilton_orbits import schema as S
from hamilton_orbits.frames import FRAMES
from hamilton_orbits.units import ANGLE, DIMENSIONLESS, GM, LENGTH, SPEED, TIME

METHODS = ("radau15", "wh", "leapfrog", "dop853")
SOLAR_SYSTEM = (
    "sun", "mercury", "venus", "earth-moon-barycenter", "earth", "moon", "mars", "jupiter",
    "saturn", "uranus", "neptune",
)
ANALYSES = {
    "perihelion_advance": "secular rate of the longitude of perihelion of `body` about `primary`",
    "nodal_regression": "secular rate of the node of `body` about `primary`, beside the J2 formula",
    "close_approach": "the smallest distance between `body` and `other`, and when",
    "de440_residuals": "the positions against JPL's DE440 at whole years from the start, "
                       "at the run's own dates (needs [initial] ephemeris)",
}
# the keys of each analysis besides its name: (required, optional)
ANALYSIS_KEYS = {
    "perihelion_advance": (("body",), ("primary",)),
    "nodal_regression": (("body",), ("primary",)),
    "close_approach": (("body", "other"), ("primary",)),
    "de440_residuals": ((), ()),
}




ANGLE_KEYS = ("inc", "lan", "argp", "M", "nu")
BODY = S.Table(
    fields={
        "name": S.String(required=True, nonempty=True),
        "gm": S.Quantity(kind=GM, nonnegative=True),
        "r": S.Vector(kind=LENGTH),
        "v": S.Vector(kind=SPEED),
        "primary": S.String(),
        "a": S.Quantity(kind=LENGTH, nonzero=True),
        "p": S.Quantity(kind=LENGTH, positive=True),
        "q": S.Quantity(kind=LENGTH, positive=True),
        "e": S.Quantity(kind=DIMENSIONLESS, nonnegative=True),
        **{k: S.Quantity(kind=ANGLE) for k in ANGLE_KEYS},
        "radius": S.Quantity(kind=LENGTH, positive=True),
        "j2": S.Quantity(kind=DIMENSIONLESS),
        "pole": S.Vector(kind=DIMENSIONLESS, nonzero=True),
    }
)

@dataclass
class _EventDistance(S.Field):
    """An event's distance: a length (``"0.1 au"``) or ``{hill = k}``."""

    def check(self, value: Any, path: str, problems: S.Problems) -> Any:
        if isinstance(value, dict):
            k = value.get("hill")
            if set(value) != {"hill"} or isinstance(k, bool) or not isinstance(k, int | float) \
                    or not k > 0:
                problems.add(path, f"expected a length or {{hill = k}} with k > 0, got {value!r}")
                return None
            return {"hill": float(k)}
        return S.Quantity(kind=LENGTH, positive=True).check(value, path, problems)

    def type_name(self) -> str:
        return 'a length ("0.1 au") or {hill = k}'


SCHEMA: dict[str, S.Field] = {
    "duration": S.Quantity(kind=TIME, required=True, positive=True),
    "cadence": S.Quantity(kind=TIME, positive=True),
    "crosscheck": S.Bool(default=False),
    # the variational equations: MEGNO and the Lyapunov time in the summary
    "variational": S.Bool(default=False),
    # an archive written while the scene runs (docs/archive.md): a killed run resumes
    # with ``hamilton-orbits resume OUTDIR``
    "output": S.Table(default={}, fields={
        "archive_every": S.Quantity(kind=TIME, positive=True),
    }),
    "integrator": S.Table(
        default={},
        fields={
            "method": S.Choice(choices=METHODS, default="radau15"),
            "tol": S.Number(positive=True, below=1.0),  # (a relative tolerance)
            "dt": S.Quantity(kind=TIME, positive=True),
            # options of ``wh`` (integrate(..., coordinates=, corrector=))
            "coordinates": S.Choice(choices=("democratic_heliocentric", "jacobi")),
            "corrector": S.Number(integer=True, minimum=0),
            # (every method's: the steps one run may take, the refusal's "pass
            # max_steps=... to go on" from a scene)
            "max_steps": S.Number(integer=True, minimum=1),
        },
    ),
    "initial": S.Table(
        default={},
        fields={
            "solar_system": S.Table(
                fields={
                    "epoch": S.String(default="J2000"),
                    "bodies": S.Array(item=S.Choice(choices=SOLAR_SYSTEM)),
                    "origin": S.Choice(choices=("barycenter", "barycentre", "ssb"),
                                      default="barycenter"),
                }
            ),
            "ephemeris": S.Table(
                fields={
                    "epoch": S.String(default="J2000"),
                    "bodies": S.Array(item=S.String()),
                }
            ),
            "rebound": S.String(),
            "names": S.Array(item=S.String()),
            # the axes of every state and element of the scene (hamilton_orbits.frames)
            "frame": S.Choice(choices=tuple(FRAMES), default="icrs"),
        },
    ),
    "bodies": S.Array(item=BODY, default=[]),
    "events": S.Array(item=S.Table(fields={
        "name": S.Choice(choices=("close_encounter", "collision", "escape"), required=True),
        "bodies": S.Array(item=S.String()),
        "distance": _EventDistance(),
        "action": S.Choice(choices=("record", "stop", "merge", "remove")),
    }), default=[]),
    "analysis": S.Array(
        default=[],
        item=S.Table(
            fields={
                "name": S.Choice(choices=tuple(ANALYSES), required=True),
                "body": S.String(),
                "primary": S.String(),
                "other": S.String(),
            }
        ),
    ),
}
