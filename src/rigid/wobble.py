"""Deprecated path (issue 30): moved to :mod:`rigid.earth.wobble_fit`.

Importing a name from here still works and warns (DeprecationWarning) with the new path.
"""

from hamilton_orbits.deprecation import forward

__getattr__ = forward(__name__, "rigid.earth.wobble_fit")
