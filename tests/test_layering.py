"""Architecture contracts from DESIGN.md, checked on the source.

- nothing in ``hamilton_orbits`` imports ``rigid`` (rigid registers itself);
- compiled kernels never import astropy (units stay at the boundary).
"""

import ast
import subprocess
import sys
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src"


def imported_modules(path: Path) -> set[str]:
    tree = ast.parse(path.read_text())
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module:
            names.add(node.module)
    return names


def test_hamilton_orbits_never_imports_rigid():
    offenders = [
        str(p.relative_to(SRC))
        for p in (SRC / "hamilton_orbits").rglob("*.py")
        if any(m == "rigid" or m.startswith("rigid.") for m in imported_modules(p))
    ]
    assert offenders == []
    code = (
        "import sys, hamilton_orbits, hamilton_orbits.cli, hamilton_orbits.orbit, "
        "hamilton_orbits.kepler, hamilton_orbits.conic; print('rigid' in sys.modules)"
    )
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert res.stdout.strip() == "False"


def test_kernels_do_not_import_astropy():
    kernels = list((SRC / "hamilton_orbits" / "_kernels").glob("*.py"))
    kernels += list((SRC / "rigid" / "_kernels").glob("*.py"))
    assert len(kernels) >= 5
    offenders = [
        str(p.relative_to(SRC))
        for p in kernels
        if any(m.split(".")[0] == "astropy" for m in imported_modules(p))
    ]
    assert offenders == []
