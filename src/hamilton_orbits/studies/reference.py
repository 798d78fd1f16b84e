"""Reference solutions precise enough to judge errors of 1e-12: radau15 in
double-double, at two step sequences, cached on disk.

:func:`reference` integrates a Newtonian system with
``radau15.run(..., precision="double-double")`` at a fixed step ``dt`` and at
``2 dt`` (side by side on two threads: the kernel releases the GIL), and keeps
both: the run at ``dt`` is the reference, and its distance from the run at
``2 dt`` bounds its own error from above (the truncation error of the
15th-order scheme falls as ``dt^16``, so the run at ``dt`` is some 6e4 times
closer to the true solution than the difference says; rounding, at 1e-32, is
out of the picture).  Double-precision integrators cannot do this: two IAS15
runs at 0.25- and 0.5-day steps differ by 4.4e-11 after 1000 years of the solar
system, the floor of what a double-precision reference can resolve.

The result is cached in the user's cache folder (``reference/`` beside the
right-hand sides, :func:`hamilton_orbits.rhs.cache_dir`), keyed by the problem
(the initial state, the GMs, the output times, ``dt``) and the kernel's source,
so the cost (about 0.5 ms a step: 5 minutes of CPU for 1000 years of the solar
system at 1 day) is paid once.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
import time
import warnings
import zipfile
from collections.abc import Mapping
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["Reference", "reference"]

_VERSION = "hamilton-orbits reference v1"


@dataclass(frozen=True)
class Reference:
    """What :func:`reference` returns.

    Attributes
    ----------
    r, v : ndarray, shape (n_t, n, 3)
        The states at the output times from the run at ``dt``.
    r_check, v_check : ndarray, shape (n_t, n, 3)
        The same from the run at ``2 dt``: ``|r - r_check|`` bounds the reference's
        own error (from above, by far).
    dt : float
    seconds : float
        CPU-bound wall time of the two runs when they were computed (0 if read from
        the cache).
    cached : bool
        Read from the cache.
    """

    r: np.ndarray
    v: np.ndarray
    r_check: np.ndarray
    v_check: np.ndarray
    dt: float
    seconds: float
    cached: bool


def _key(r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, t_out: np.ndarray, dt: float) -> str:
    from hamilton_orbits._kernels import radau15_dd

    h = hashlib.sha256(_VERSION.encode())
    for arr in (r0, v0, gm, t_out, np.array([dt])):
        h.update(np.ascontiguousarray(arr, dtype=np.float64).tobytes())
    h.update(Path(radau15_dd.__file__).read_bytes())
    return h.hexdigest()[:24]


def reference(r0: np.ndarray, v0: np.ndarray, gm: np.ndarray, t_out: np.ndarray,
              dt: float = 1.0, *, cache: bool = True) -> Reference:
    """The double-double radau15 solution at ``t_out`` (``t_out[0]`` the start), at
    steps ``dt`` and ``2 dt``, from the cache if it was computed before.

    Parameters
    ----------
    r0, v0 : array_like, shape (n, 3)
    gm : array_like, shape (n,)
        In one consistent unit system (e.g. au, day, au^3/day^2).
    t_out : array_like, shape (n_t,)
        Increasing output times.
    dt : float
        The reference's step (the check runs at ``2 dt``).
    cache : bool
        Read and write the cache (``False``: compute, keep nothing).

    Returns
    -------
    Reference

    Raises
    ------
    ValueError
        For bad input, naming the argument, index and value (non-finite values,
        shapes, negative ``gm``, two bodies at one position, ``t_out`` not
        increasing, ``dt <= 0``).

    Warns
    -----
    RuntimeWarning
        When the cached file cannot be read (it names the file); the reference is
        then computed again and the file replaced.

    Examples
    --------
    >>> r0 = np.array([[0.0, 0, 0], [1.0, 0, 0]]); v0 = np.array([[0.0, 0, 0], [0, 1.0, 0]])
    >>> ref = reference(r0, v0, np.array([1.0, 0.0]), np.array([0.0, 2 * np.pi]), 0.1,
    ...                 cache=False)
    >>> bool(np.abs(ref.r[-1] - r0).max() < 1e-14), bool(np.abs(ref.r - ref.r_check).max() < 1e-14)
    (True, True)
    """
    from hamilton_orbits.integrators import _setup, radau15
    from hamilton_orbits.rhs import cache_dir, newtonian_rhs

    arrays = list(_setup.check_inputs(r0, v0, gm, t_out))
    dt = _setup.check_dt_tol(dt, None)[0]
    if dt is None:
        raise ValueError("Expected `dt` > 0, got None")
    folder = cache_dir("reference") if cache else None
    path = folder / f"{_key(*arrays, dt)}.npz" if folder is not None else None
    if path is not None and path.exists():
        found = _read(path, (len(arrays[3]), *arrays[0].shape), dt)
        if found is not None:
            return found
    rhs = newtonian_rhs()
    r0, v0, gm, t_out = arrays
    radau15.run(rhs, r0, v0, gm, t_out[:1].repeat(2) + [0.0, dt], dt=dt,
                precision="double-double")  # load (or compile) the kernel in this thread
    start = time.perf_counter()
    with ThreadPoolExecutor(2) as pool:
        runs = list(pool.map(lambda h: radau15.run(rhs, r0, v0, gm, t_out, dt=h,
                                                   precision="double-double"),
                             (float(dt), 2.0 * float(dt))))
    seconds = time.perf_counter() - start
    (r, v, _), (rc, vc, _) = runs
    if path is not None:
        _write(path, r=r, v=v, r_check=rc, v_check=vc)
    return Reference(r, v, rc, vc, dt, seconds, False)


def _read(path: Path, shape: tuple[int, ...], dt: float) -> Reference | None:
    """The cached reference in ``path``, or None (with a warning naming the file and
    what is wrong) when the file cannot be read as one of the expected ``shape``
    (cut short by a full disk or a killed writer, overwritten): it is then computed
    again and replaced."""
    try:
        with open(path, "rb") as f:  # closed here whatever np.load makes of it
            z = np.load(f)
            if not isinstance(z, Mapping):
                raise ValueError("not an .npz archive")
            found = [np.array(z[key]) for key in ("r", "v", "r_check", "v_check")]
        bad = [a.shape for a in found if a.shape != shape or a.dtype != np.float64]
        if bad:
            raise ValueError(f"arrays of shape {bad[0]}, expected {shape} float64")
    except (OSError, EOFError, KeyError, ValueError, zipfile.BadZipFile) as exc:
        warnings.warn(f"The cached reference {path} is damaged ({type(exc).__name__}: "
                      f"{exc}); computing it again", RuntimeWarning, stacklevel=3)
        return None
    return Reference(*found, dt, 0.0, True)


def _write(path: Path, **arrays: np.ndarray) -> None:
    """Write ``arrays`` to ``path`` through a temporary file of its own in the same
    folder (two writers never share one), renamed into place in one step."""
    fd, tmp = tempfile.mkstemp(prefix=path.stem + ".", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        with open(tmp, "wb") as f:
            np.savez(f, **arrays)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
