"""Numba-compiled kernels on plain floats.  Nothing here imports astropy.

Importing any kernel module imports numba; the public modules import them on
first use (:mod:`hamilton_orbits._lazy`).  The one-line notice on stderr while
kernels compile for the first time is installed here, before any kernel exists.
"""

from hamilton_orbits.firstrun import install as _install_compile_notice

_install_compile_notice()
