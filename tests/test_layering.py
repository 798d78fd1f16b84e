"""Architecture contracts from docs/design.md, checked on the source.

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


def _our_modules() -> dict[str, Path]:
    """Dotted module name -> file, for both packages."""
    out = {}
    for package in ("hamilton_orbits", "rigid"):
        for path in (SRC / package).rglob("*.py"):
            parts = list(path.relative_to(SRC).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            out[".".join(parts)] = path
    return out


def _import_graph() -> dict[str, set[str]]:
    """Every import between our modules, wherever it stands in the file (a
    function-level import hides a circle from the interpreter, not from us).
    ``from pkg import sub`` is an arrow to the submodule ``pkg.sub``; imports under
    ``if TYPE_CHECKING:`` are not run and are left out."""
    modules = _our_modules()
    graph: dict[str, set[str]] = {}
    for name, path in modules.items():
        tree = ast.parse(path.read_text())
        skip = {id(n) for node in ast.walk(tree) if isinstance(node, ast.If)
                and "TYPE_CHECKING" in ast.unparse(node.test) for n in ast.walk(node)}
        arrows: set[str] = set()
        for node in ast.walk(tree):
            if id(node) in skip:
                continue
            if isinstance(node, ast.Import):
                arrows.update(a.name for a in node.names if a.name in modules)
            elif isinstance(node, ast.ImportFrom) and node.module in modules:
                subs = [f"{node.module}.{a.name}" for a in node.names]
                found = [s for s in subs if s in modules]
                arrows.update(found)
                if len(found) < len(subs):
                    arrows.add(node.module)
        graph[name] = arrows - {name}
    return graph


def _circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components with more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    out: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def test_no_import_circle_in_either_package():
    graph = _import_graph()
    assert len(graph) > 40 and "hamilton_orbits.engine" in graph["hamilton_orbits.simulation"]
    assert _circles(graph) == []


def test_the_circle_finder_finds_a_circle():
    assert _circles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
