"""Sphinx configuration of the hamilton-orbits documentation.

Build (from the repository root, with the ``docs`` extra installed)::

    python -m sphinx -W --keep-going -n -b html docs docs/_build/html

Nothing is fetched at build time (no intersphinx): names of numpy, astropy and
the standard library that cannot be resolved without it are listed in
``nitpick_ignore_regex``; every name of this package must resolve.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
sys.path.insert(0, str(Path(__file__).resolve().parent))
os.environ.setdefault("MPLBACKEND", "Agg")

project = "hamilton-orbits"
author = "The hamilton-orbits developers"
copyright = "2026, The hamilton-orbits developers"

try:
    from importlib.metadata import version as _version

    release = _version("hamilton-orbits")
except Exception:  # pragma: no cover - a tree without the package installed
    release = "0.1.0"
version = release

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "sphinx_copybutton",
    "sphinx_gallery.gen_gallery",
    "scene_reference",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "**.ipynb_checkpoints"]
templates_path = ["_templates"]

myst_enable_extensions = ["dollarmath", "colon_fence", "deflist"]
myst_heading_anchors = 3
suppress_warnings = ["myst.header"]

autosummary_generate = True
autosummary_imported_members = True
autodoc_default_options = {"members": True, "inherited-members": False}
autodoc_typehints = "none"  # numpydoc's Parameters sections carry the types
autodoc_member_order = "bysource"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_validation_checks: set[str] = set()

# nitpicky: every cross-reference must resolve.  Without intersphinx (nothing is
# downloaded at build time) the other projects' names cannot; they are listed
# here, never ours.
nitpicky = True
nitpick_ignore_regex = [
    (r"py:.*", r"(numpy|np|astropy|u|matplotlib|plt|scipy|numba|dask|xarray|pandas|rebound)"
     r"(\..*)?"),
    (r"py:.*", r"(collections|typing|pathlib|os|datetime|enum|dataclasses|types|io|abc)"
     r"(\..*)?"),
    (r"py:.*", r"(ndarray|Quantity|Time|Figure|Axes|Dataset|array_like|array-like|optional|"
     r"callable|Callable|Sequence|Mapping|Iterable|Iterator|Any|Path|PathLike|Self|"
     r"float64|int64|ArrayLike|NDArray|function|object|None|bool|int|float|str|dict|list|"
     r"tuple|complex|bytes|type|Exception|ValueError|TypeError|KeyError)"),
]

# The gallery: examples/<section>/plot_*.py are run and their figures shown; the
# other scripts of examples/ are rendered without running (slow, or they start
# worker processes).  Its output (docs/gallery/) is kept in the repository with
# each example's checksum, so that a build re-runs only the examples that changed:
# CI builds the site without running any.
_SECTIONS = ("orbits", "nbody", "effects", "events", "chaos", "ensembles", "accuracy",
             "rigid", "earth_pole")
sphinx_gallery_conf = {
    "examples_dirs": "../examples",
    "gallery_dirs": "gallery",
    "filename_pattern": r"/plot_",
    "ignore_pattern": r"(__init__|/out/)",
    "subsection_order": [f"../examples/{s}" for s in _SECTIONS
                         if (ROOT / "examples" / s).is_dir()],
    "within_subsection_order": "FileNameSortKey",
    "download_all_examples": False,
    "remove_config_comments": True,
    "matplotlib_animations": False,
    "image_scrapers": ("matplotlib",),
    "run_stale_examples": False,
    "show_memory": False,
}

html_theme = "pydata_sphinx_theme"
html_title = "hamilton-orbits"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "footer_start": ["copyright"],
    "footer_end": [],
}
# without a default mode pydata-sphinx-theme 0.16 logs a console error on a first
# visit ("Got invalid theme mode"), which the browser test counts as a broken page
html_context = {"default_mode": "auto"}
html_static_path: list[str] = []
html_last_updated_fmt = None
