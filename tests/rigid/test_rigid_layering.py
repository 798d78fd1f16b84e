"""rigid stands on hamilton_orbits' public modules only (issue 30).

The compiled quaternion building blocks that rigid's kernels inline have a public name,
``hamilton_orbits.quaternion_kernels``, which re-exports the very objects of the private
``hamilton_orbits._kernels.quaternion``.
"""

from __future__ import annotations

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[2] / "src"


def _private_hamilton_imports(path: Path) -> list[str]:
    out = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
        else:
            continue
        for name in names:
            parts = name.split(".")
            if parts[0] == "hamilton_orbits" and any(p.startswith("_") for p in parts[1:]):
                out.append(f"{path.relative_to(SRC)}:{node.lineno}: {name}")
    return out


def test_rigid_imports_no_private_module_or_name_of_hamilton_orbits():
    files = sorted((SRC / "rigid").rglob("*.py"))
    assert len(files) > 30
    assert [hit for p in files for hit in _private_hamilton_imports(p)] == []


def test_the_public_quaternion_kernels_are_the_private_ones():
    from hamilton_orbits import quaternion_kernels
    from hamilton_orbits._kernels import quaternion

    assert quaternion_kernels.__all__ == ["qmul", "qrot"]
    assert quaternion_kernels.qmul is quaternion.qmul
    assert quaternion_kernels.qrot is quaternion.qrot
