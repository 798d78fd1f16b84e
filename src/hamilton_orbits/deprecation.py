"""Old import paths that keep working, with a ``DeprecationWarning`` naming the new one.

A module whose public names moved elsewhere answers for them from its module-level
``__getattr__`` (PEP 562), so that the warning fires when a name is used, not when
the old module is imported: :func:`moved_name` for some names of a module that
stays, :func:`forward` for a whole module that became a shim::

    def __getattr__(name: str) -> Any:
        return moved_name(__name__, {"old_name": "hamilton_orbits.new_module"}, name)

    __getattr__ = forward(__name__, "rigid.earth.c04")   # every public name

Public: both packages' old paths use it (the core they share).
"""

from __future__ import annotations

import importlib
import warnings
from collections.abc import Callable, Mapping
from typing import Any

__all__ = ["forward", "moved_name"]


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


def forward(old: str, *new: str) -> Callable[[str], Any]:
    """A module ``__getattr__`` for the deprecated path ``old`` that serves the public
    names of the modules ``new`` (the first that has the name), warning on each use
    (:func:`moved_name`'s message); ``__all__`` is the first new module's.

    Examples
    --------
    >>> import warnings
    >>> getattr_ = forward("old.place", "math")
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     value = getattr_("pi")
    >>> round(value, 5), str(caught[0].message)
    (3.14159, 'old.place.pi moved to math.pi; import it from there')
    >>> getattr_("_private")
    Traceback (most recent call last):
    ...
    AttributeError: module 'old.place' has no attribute '_private'
    """

    def __getattr__(name: str) -> Any:
        if name == "__all__":
            warnings.warn(f"{old} moved to {new[0]}; import from there", DeprecationWarning,
                          stacklevel=2)
            return list(importlib.import_module(new[0]).__all__)
        if not name.startswith("_"):
            for path in new:
                if hasattr(importlib.import_module(path), name):
                    return moved_name(old, {name: path}, name)
        raise AttributeError(f"module {old!r} has no attribute {name!r}")

    return __getattr__
