"""The accuracy studies: benchmark machinery that measures the package against
references and peers, above every public entry point.

- :mod:`~hamilton_orbits.studies.report`: what accuracy costs in time (the
  work-precision report, ``hamilton-orbits report``), with its
  :mod:`~hamilton_orbits.studies.problems`, :mod:`~hamilton_orbits.studies.figures`
  and :mod:`~hamilton_orbits.studies.rows`;
- :mod:`~hamilton_orbits.studies.ladder`: the physics ladder against JPL's DE440;
- :mod:`~hamilton_orbits.studies.reference`: reference solutions (radau15 in
  double-double, cached on disk).

Nothing here is imported by ``import hamilton_orbits``.
"""
