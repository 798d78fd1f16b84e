"""The ``nbody`` scene kind, one concept per module.

- :mod:`~hamilton_orbits.scenes.nbody.schema`: the keys of an n-body scene;
- :mod:`~hamilton_orbits.scenes.nbody.check`: the checks across keys;
- :mod:`~hamilton_orbits.scenes.nbody.build`: the :class:`~hamilton_orbits.nbody.System`
  a scene starts from;
- :mod:`~hamilton_orbits.scenes.nbody.run`: the run, and the
  :class:`~hamilton_orbits.scenes.result.Result` it makes;
- :mod:`~hamilton_orbits.scenes.nbody.analyses`: what ``[[analysis]]`` entries measure;
- :mod:`~hamilton_orbits.scenes.nbody.figures`: the figures;
- :mod:`~hamilton_orbits.scenes.nbody.kind`: the kind itself, registered through
  the entry point ``hamilton_orbits.scene_kinds: nbody``.

The keys are documented in ``docs/scenes.md``.
"""
