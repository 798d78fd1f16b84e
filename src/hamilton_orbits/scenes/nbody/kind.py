"""The ``nbody`` scene kind (:data:`KIND`): bodies under Hamilton's equation (B)
and the listed effects.  :func:`register` adds it to the registry; the registry
calls it through the entry point ``hamilton_orbits.scene_kinds: nbody``, as it
calls every kind's."""

from __future__ import annotations

from typing import Any

from hamilton_orbits.scenes.base import SceneKind, format_table, register_kind
from hamilton_orbits.scenes.nbody.build import build_system
from hamilton_orbits.scenes.nbody.check import check
from hamilton_orbits.scenes.nbody.run import run_scene
from hamilton_orbits.scenes.nbody.schema import SCHEMA


def _crosscheck(scene: Any) -> str:
    from hamilton_orbits import crosscheck

    spec = scene.spec
    system = build_system(spec)
    integ = spec["integrator"]
    table = crosscheck(system, spec["duration"], method=integ["method"],
                       effects=list(spec["effects"]))
    return (
        f"{scene.name}: hamilton-orbits {integ['method']} against {table.peer}, "
        f"{spec['duration']}\n\n{format_table(table.rows)}\n\n{format_table(table.code_rows)}"
    )


KIND = SceneKind(
    name="nbody",
    summary="bodies under Hamilton's equation (B) and the listed effects",
    schema=SCHEMA,
    effect_kind="nbody",
    check=check,
    run=run_scene,
    crosscheck=_crosscheck,
)


def register() -> None:
    """Register the ``nbody`` kind (the entry point ``hamilton_orbits.scene_kinds: nbody``)."""
    register_kind(KIND)
