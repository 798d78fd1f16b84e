"""Modules imported on first use, so that ``import hamilton_orbits`` stays light.

numba (with the compiled kernels) and astropy each take about half a second to
import.  A bare ``import hamilton_orbits`` needs neither: numba is imported when
a kernel is first called, astropy when a Quantity comes in (a caller that has
not imported astropy cannot have passed one; see :func:`hamilton_orbits.units.is_quantity`).

:class:`LazyModule` stands for a module in the namespace of the module that
uses it.  On the first attribute access it imports the module and puts it in
that namespace under its own name, so every later access is an ordinary global
lookup (no proxy in the hot path, and monkeypatching the real module works).
"""

from __future__ import annotations

import importlib
from types import ModuleType
from typing import Any


class LazyModule:
    """Module ``name``, imported on first attribute access and then bound as
    ``namespace[alias]`` (the caller's ``globals()``).

    Examples
    --------
    >>> ns = {}
    >>> ns["m"] = LazyModule("math", ns, "m")
    >>> ns["m"]
    LazyModule('math', not imported)
    >>> ns["m"].pi
    3.141592653589793
    >>> ns["m"]  # doctest: +ELLIPSIS
    <module 'math' ...>
    """

    __slots__ = ("_lazy_alias", "_lazy_name", "_lazy_namespace")

    def __init__(self, name: str, namespace: dict[str, Any], alias: str) -> None:
        self._lazy_name = name
        self._lazy_namespace = namespace
        self._lazy_alias = alias

    def _load(self) -> ModuleType:
        module = importlib.import_module(self._lazy_name)  # thread-safe (import lock)
        if self._lazy_namespace.get(self._lazy_alias) is self:
            self._lazy_namespace[self._lazy_alias] = module
        return module

    def __getattr__(self, attr: str) -> Any:
        if attr.startswith("_lazy_"):
            raise AttributeError(attr)
        return getattr(self._load(), attr)

    def __dir__(self) -> list[str]:
        return dir(self._load())

    def __repr__(self) -> str:
        return f"LazyModule({self._lazy_name!r}, not imported)"
