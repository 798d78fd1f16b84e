"""Old import paths that keep working, with a ``DeprecationWarning`` naming the new one.

A module whose public names moved elsewhere (all of them, for a module that became
a shim) answers for them from its module-level ``__getattr__`` (PEP 562) with
:func:`moved_name`, so that the warning fires when a name is used, not when the
old module is imported::

    def __getattr__(name: str) -> Any:
        return moved_name(__name__, {"old_name": "hamilton_orbits.new_module"}, name)
"""

from __future__ import annotations

import importlib
import warnings
from collections.abc import Mapping
from typing import Any

__all__ = ["moved_name"]


def moved_name(old: str, homes: Mapping[str, str], name: str) -> Any:
    """The object ``name`` asked of module ``old``, from the module ``homes[name]`` that
    holds it now, with a ``DeprecationWarning`` at the line that asked (the caller of
    ``old``'s ``__getattr__``); an ``AttributeError`` for a name not in ``homes``.

    Examples
    --------
    >>> import warnings
    >>> def __getattr__(name):
    ...     return moved_name("old.place", {"pi": "math"}, name)
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     value = __getattr__("pi")
    >>> round(value, 5), str(caught[0].message)
    (3.14159, 'old.place.pi moved to math.pi; import it from there')
    >>> __getattr__("tau")
    Traceback (most recent call last):
    ...
    AttributeError: module 'old.place' has no attribute 'tau'
    """
    home = homes.get(name)
    if home is None:
        raise AttributeError(f"module {old!r} has no attribute {name!r}")
    warnings.warn(f"{old}.{name} moved to {home}.{name}; import it from there",
                  DeprecationWarning, stacklevel=3)
    return getattr(importlib.import_module(home), name)
