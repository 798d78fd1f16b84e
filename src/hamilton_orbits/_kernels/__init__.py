"""Numba-compiled kernels on plain floats.  Nothing here imports astropy."""
