"""Numba-compiled rigid-body kernels on plain floats.  Nothing here imports astropy."""
