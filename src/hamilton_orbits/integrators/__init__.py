"""N-body integrators on the compiled right-hand side of :mod:`hamilton_orbits.effects`.

Each integrator is a module with

- ``NAME`` (``"leapfrog"``, ``"wh"``, ``"radau15"``, ``"dop853"``);
- ``ACCEPTS_VELOCITY_DEPENDENT`` (bool): symplectic maps refuse velocity-dependent
  effects;
- ``run(rhs, r0, v0, gm, t_out, *, dt=None, tol=None, on_output=None)``
  returning ``(r, v, steps)``: ``rhs`` an :class:`~hamilton_orbits.effects.RHS`;
  ``r0``, ``v0`` float64 (n, 3) and ``gm`` (n,) in the internal units;
  ``t_out`` an increasing float64 array of output times with ``t_out[0]`` the
  initial time (row 0 of the output is the initial state); ``r``, ``v`` of shape
  (len(t_out), n, 3); ``steps`` the number of steps taken.  ``on_output(i,
  steps)`` is called from Python after output ``i`` is reached (progress bars).

The stepping itself is one compiled call per output interval; Python only loops
over output times.
"""
