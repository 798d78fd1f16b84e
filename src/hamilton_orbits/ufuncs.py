"""Array functions compiled on first use, and safe to build in several processes at once.

:func:`lazy_guvectorize` and :func:`lazy_vectorize` take ``numba.guvectorize``'s and
``numba.vectorize``'s arguments.  The (generalised) ufunc they make is built at its
first call, not when its module is imported, and with ``cache=True`` it is built by
one process at a time: numba caches a generalised ufunc as two files (the kernel
and its loop wrapper), and two processes compiling it at once from a cold cache
can leave a mismatched pair that makes every later call, in every later process,
die of a segmentation fault (numba issue #10128).  ``rigid``'s compiled Euler
equations and Cayley rates are built this way.  The code lives in the private
``hamilton_orbits._kernels._dispatch``; this module is its public name and
re-exports the very same objects.

Examples
--------
>>> import numpy as np
>>> from hamilton_orbits.ufuncs import lazy_guvectorize
>>> @lazy_guvectorize(["void(float64[:], float64[:])"], "(n)->()", cache=False)
... def total(x, out):
...     out[0] = x.sum()
>>> total
LazyUfunc(total, not built)
>>> total(np.arange(6.0).reshape(2, 3)).tolist()
[3.0, 12.0]
"""

from __future__ import annotations

from hamilton_orbits._kernels._dispatch import LazyUfunc, lazy_guvectorize, lazy_vectorize

__all__ = ["LazyUfunc", "lazy_guvectorize", "lazy_vectorize"]
