"""The progress bar of the scene runs and ensembles (:func:`progress_bar`)."""

from __future__ import annotations

from typing import Any

from hamilton_orbits.validation import as_flag


def progress_bar(total: int, enabled: bool, unit: str) -> Any:
    """A tqdm bar on stderr counting ``total`` of ``unit`` ("output", "member"),
    quiet when stderr is not a terminal; None when not ``enabled`` or without tqdm
    (the ``[progress]`` extra).  ``enabled`` is the caller's ``progress``: anything
    but True or False is refused by that name (``"no"`` was true)."""
    import sys

    if not as_flag("progress", enabled):
        return None
    try:
        from tqdm import tqdm
    except ImportError:  # pragma: no cover - tqdm is in the [progress] extra
        return None
    return tqdm(total=total, unit=unit, disable=not sys.stderr.isatty(), leave=False)
