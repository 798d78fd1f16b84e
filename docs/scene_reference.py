"""The scene file reference, generated from the scene kinds' schemas at build time.

``reference_markdown()`` walks every registered scene kind's schema
(:class:`hamilton_orbits.scenes.base.SceneKind`) and writes one table per kind:
every key by its path in the file, what it takes (type, dimension and SI unit of
a value with a unit, the choices), whether it is required, and its default.  The
Sphinx extension writes it to ``scene_reference.md`` when the build starts, so the
page cannot fall behind the code (``tests/test_docs.py`` checks it names every key).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
PAGE = HERE / "scene_reference.md"

HEADER = """# Scene file reference

Generated from the schemas of the registered scene kinds when the documentation
is built (`docs/scene_reference.py`): every key of a scene file, what it takes,
whether it is required and its default.  How scenes are written and run, with
examples: [Scenes](scenes.md).  Every scene file also takes `kind`, `description`
and `effects` (see [Effects](effects.md)).  A value with a unit is a string such
as `"1.2 au"`; its dimension is checked when the file is read.
"""


def _what(f: Any) -> str:
    from hamilton_orbits import schema as S

    if isinstance(f, S.Quantity | S.Vector):
        kind = getattr(f, "kind", None)
        unit = f" [{kind.unit}]" if kind is not None and str(kind.unit) else ""
        size = f"{f.size} values of " if isinstance(f, S.Vector) else ""
        name = kind.name if kind is not None else "a value with a unit"
        return f"{size}{name}{unit}"
    if isinstance(f, S.Array):
        return "a list of " + (_what(f.item) if f.item is not None else "values")
    return f.type_name()


def rows(fields: Any, prefix: str = "") -> list[tuple[str, str, str, str]]:
    """``(key path, what it takes, required, default)`` of every key under ``fields``."""
    from hamilton_orbits import schema as S

    out: list[tuple[str, str, str, str]] = []
    for key, f in fields.items():
        path = f"{prefix}{key}"
        default = "" if f.default in (None, {}, []) else f"`{f.default!r}`"
        if isinstance(f, S.Table):
            what = "a table" + (" (open: other keys passed through)" if f.open else "")
            out.append((path, what, "yes" if f.required else "", default))
            out += rows(f.fields, path + ".")
        elif isinstance(f, S.Array) and isinstance(f.item, S.Table):
            out.append((path, "a list of tables", "yes" if f.required else "", default))
            out += rows(f.item.fields, path + "[].")
        else:
            out.append((path, _what(f), "yes" if f.required else "", default))
    return out


def reference_markdown() -> str:
    """The page, Markdown (MyST)."""
    from hamilton_orbits.scenes.base import registered_kinds

    parts = [HEADER]
    for name, kind in sorted(registered_kinds().items()):
        parts.append(f"\n## `kind = \"{name}\"`\n\n{kind.summary}\n")
        parts.append("| key | takes | required | default |\n|---|---|---|---|")
        for path, what, req, default in rows(kind.schema):
            what = what.replace("|", "\\|")
            parts.append(f"| `{path}` | {what} | {req} | {default} |")
    return "\n".join(parts) + "\n"


def _write(app: Any) -> None:
    text = reference_markdown()
    if not PAGE.exists() or PAGE.read_text() != text:
        PAGE.write_text(text)


def setup(app: Any) -> dict[str, Any]:
    app.connect("builder-inited", _write)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
