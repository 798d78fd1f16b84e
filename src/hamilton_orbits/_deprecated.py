"""Old import paths that keep working, with a ``DeprecationWarning`` naming the new one.

:func:`moved` makes the module-level ``__getattr__`` (PEP 562) of a module whose
public names moved elsewhere (all of them, for a module that became a shim), so
that the warning fires when a name is used, not when the old module is imported.
"""

from __future__ import annotations

import importlib
import warnings
from collections.abc import Callable, Mapping
from typing import Any

__all__ = ["moved"]


def moved(old: str, homes: Mapping[str, str]) -> Callable[[str], Any]:
    """The ``__getattr__`` of module ``old`` for the names in ``homes`` (name -> the
    module that holds it now): each use warns and returns the object itself.

    Examples
    --------
    >>> import warnings
    >>> getattr_ = moved("old.place", {"pi": "math"})
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     value = getattr_("pi")
    >>> round(value, 5), str(caught[0].message)
    (3.14159, 'old.place.pi moved to math.pi; import it from there')
    >>> getattr_("tau")
    Traceback (most recent call last):
    ...
    AttributeError: module 'old.place' has no attribute 'tau'
    """
    homes = dict(homes)

    def __getattr__(name: str) -> Any:
        home = homes.get(name)
        if home is None:
            raise AttributeError(f"module {old!r} has no attribute {name!r}")
        warnings.warn(f"{old}.{name} moved to {home}.{name}; import it from there",
                      DeprecationWarning, stacklevel=2)
        return getattr(importlib.import_module(home), name)

    return __getattr__
