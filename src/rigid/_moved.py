"""The old module paths of ``rigid`` that moved (issue 30): a forwarding ``__getattr__``.

Earth orientation moved into :mod:`rigid.earth` (``rigid.c04`` is now
``rigid.earth.c04``, ...).  Each old path stays importable as a thin module whose
``__getattr__`` is made by :func:`forward`: a public name taken from it comes from
the new module, with a :class:`DeprecationWarning` that names the new path.
"""

from __future__ import annotations

import importlib
import warnings
from collections.abc import Callable
from typing import Any


def forward(old: str, *new: str) -> Callable[[str], Any]:
    """A module ``__getattr__`` for the deprecated path ``old`` that serves the public
    names of the modules ``new`` (the first that has the name), warning on each use.

    Examples
    --------
    >>> import warnings
    >>> getattr_ = forward("rigid.wobble", "rigid.earth.wobble_fit")
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     fit = getattr_("fit_wobble")
    >>> print(fit.__module__)
    rigid.earth.wobble_fit
    >>> print(caught[0].category.__name__, caught[0].message)
    DeprecationWarning rigid.wobble is deprecated: import fit_wobble from rigid.earth.wobble_fit
    """

    def __getattr__(name: str) -> Any:
        if name == "__all__":
            names = importlib.import_module(new[0]).__all__
        elif name.startswith("_"):
            raise AttributeError(f"module {old!r} has no attribute {name!r}")
        else:
            for path in new:
                module = importlib.import_module(path)
                if hasattr(module, name):
                    warnings.warn(f"{old} is deprecated: import {name} from {path}",
                                  DeprecationWarning, stacklevel=2)
                    return getattr(module, name)
            raise AttributeError(f"module {old!r} has no attribute {name!r}")
        warnings.warn(f"{old} is deprecated: use {new[0]}", DeprecationWarning, stacklevel=2)
        return list(names)

    return __getattr__
