"""Scenes, one concept per module.

- :mod:`~hamilton_orbits.scenes.scene`: :class:`~hamilton_orbits.scenes.scene.Scene`
  (a TOML file or a mapping in, validated; overrides) and ``SceneError``;
- :mod:`~hamilton_orbits.scenes.base`: what every kind shares: ``SceneKind``, the
  registry filled through the entry-point group ``hamilton_orbits.scene_kinds``,
  the output-memory limit, ``format_table``;
- :mod:`~hamilton_orbits.scenes.result`: ``Result``, what a run produced;
- :mod:`~hamilton_orbits.scenes.nbody`: the ``nbody`` kind (schema, checks, the
  system, the run, analyses, figures).

The public path is :mod:`hamilton_orbits.scene` (and ``hamilton_orbits.Scene``).
"""
