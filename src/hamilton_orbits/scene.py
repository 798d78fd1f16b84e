"""Scenes: a file says what to simulate and which effects; ``run`` does it.

The public path of the scene objects, which live by concept in
:mod:`hamilton_orbits.scenes`: :class:`Scene` and :class:`SceneError`
(:mod:`~hamilton_orbits.scenes.scene`), :class:`Result`
(:mod:`~hamilton_orbits.scenes.result`), and for the kinds :class:`SceneKind`,
:func:`register_kind`, :data:`KINDS`, :data:`OUTPUT_LIMIT`,
:func:`check_output_size` and :func:`format_table`
(:mod:`~hamilton_orbits.scenes.base`).  ``docs/scenes.md`` documents the format.

Examples
--------
>>> from hamilton_orbits.scene import Scene
>>> Scene.bundled("mercury-gr").kind
'nbody'
"""

from __future__ import annotations

from hamilton_orbits.scenes.base import (
    KINDS,
    OUTPUT_LIMIT,
    SceneKind,
    check_output_size,
    format_table,
    register_kind,
)
from hamilton_orbits.scenes.result import Result
from hamilton_orbits.scenes.scene import Scene, SceneError

__all__ = ["KINDS", "OUTPUT_LIMIT", "Result", "Scene", "SceneError", "SceneKind",
           "check_output_size", "format_table", "register_kind"]
