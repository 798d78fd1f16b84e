"""The documentation site's sources: the API reference covers every public name, the
scene file reference is generated from the schemas and names every key.

The site itself is built by ``.ci/run`` with warnings as errors
(``python -m sphinx -W --keep-going -n -b html docs docs/_build/html``).
"""

import importlib
import re
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parents[1] / "docs"


def _documented() -> set[tuple[str, str]]:
    """``(module, name)`` of every autosummary entry of the API index."""
    text = (DOCS / "api" / "index.rst").read_text()
    out, module, listing = set(), None, False
    for line in text.splitlines():
        m = re.match(r"\.\. currentmodule:: (\S+)", line)
        if m:
            module = m.group(1)
        elif line.startswith(".. "):
            listing = line.startswith(".. autosummary::")
        elif listing and re.match(r"   [A-Za-z_]\w*$", line) and module is not None:
            out.add((module, line.strip()))
    return out


def test_api_reference_lists_every_public_name_of_both_packages():
    documented = _documented()
    for package in ("hamilton_orbits", "rigid"):
        public = {n for n in importlib.import_module(package).__all__ if not n.startswith("__")}
        missing = {n for n in public if (package, n) not in documented}
        assert not missing, f"{package}: not in docs/api/index.rst: {sorted(missing)}"


def test_every_documented_name_exists():
    for module, name in _documented():
        assert hasattr(importlib.import_module(module), name), (module, name)


def test_scene_reference_names_every_key_of_every_kind():
    sys.path.insert(0, str(DOCS))
    try:
        import scene_reference
    finally:
        sys.path.remove(str(DOCS))
    from hamilton_orbits.scenes.base import registered_kinds

    page = scene_reference.reference_markdown()
    kinds = registered_kinds()
    assert {"nbody", "rotation"} <= set(kinds)
    for name, kind in kinds.items():
        assert f'`kind = "{name}"`' in page
        for path, _, _, _ in scene_reference.rows(kind.schema):
            assert f"| `{path}` |" in page, path
    # the key the old hand-written page missed (issue 34)
    assert "| `initial.ephemeris.bodies` |" in page
    assert "| `initial.ephemeris.epoch` |" in page


def test_every_note_is_in_a_toctree():
    index = (DOCS / "index.md").read_text()
    notes = {p.stem for p in DOCS.glob("*.md")} - {"index", "changelog", "scene_reference"}
    listed = set(re.findall(r"^([a-z_0-9/]+)$", index, flags=re.M))
    assert notes <= listed, sorted(notes - listed)
