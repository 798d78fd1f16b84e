"""rigid.polar_motion is a facade over the Earth-orientation modules of rigid.earth (issues 19, 30).

Outside code calls ``polar_motion.load_c04()`` and friends and the
``hamilton_orbits.effects`` entry point names ``rigid.polar_motion:register_effects``:
the facade keeps exactly its names, now served by ``rigid.earth.liouville``,
``rigid.earth.c04``, ``rigid.earth.wobble_fit`` and ``rigid.earth.prediction``.  And no
module of ``rigid`` imports another in a circle, function-level imports included
(earth <-> polar_motion was one).
"""

from __future__ import annotations

import ast
import importlib
import importlib.metadata
from pathlib import Path

from rigid import polar_motion
from rigid.earth import c04, liouville, prediction, wobble_fit

SRC = Path(__file__).resolve().parents[2] / "src"

# the facade's names before the split (issue 19): exactly these, no more
FACADE = [
    "EFFECTS",
    "LiouvillePole",
    "PolarMotionRecord",
    "WobbleFit",
    "fit_wobble",
    "free_period",
    "hindcast",
    "iers2010_mean_pole",
    "load_c04",
    "periodogram",
    "predict",
    "register_effects",
]


def test_facade_names_are_the_concept_modules_objects():
    assert sorted(polar_motion.__all__) == FACADE
    home = {"EFFECTS": liouville, "LiouvillePole": liouville, "register_effects": liouville,
            "PolarMotionRecord": c04, "load_c04": c04, "iers2010_mean_pole": c04,
            "WobbleFit": wobble_fit, "fit_wobble": wobble_fit, "periodogram": wobble_fit,
            "free_period": wobble_fit, "predict": prediction, "hindcast": prediction}
    for name in FACADE:
        assert getattr(polar_motion, name) is getattr(home[name], name), name
    assert liouville.free_period is wobble_fit.free_period


def test_entry_point_still_registers_the_rotation_effects():
    (ep,) = [e for e in importlib.metadata.entry_points(group="hamilton_orbits.effects")
             if e.name == "rigid"]
    assert ep.value == "rigid.polar_motion:register_effects"
    register = ep.load()
    assert register is liouville.register_effects
    register()
    from hamilton_orbits import effects

    assert set(liouville.EFFECTS) <= set(effects.known("rotation"))
    assert effects.get("rotation", "damping").build(Q=100).q_inv == 0.01


def _rigid_imports(path: Path, modules: set[str]) -> set[str]:
    """The rigid modules ``path`` imports anywhere (function bodies included)."""
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module:
            names = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
        else:
            continue
        out.update(n for n in names if n in modules)
    return out


def test_no_import_circle_in_rigid():
    files = {".".join(p.relative_to(SRC).with_suffix("").parts): p
             for p in (SRC / "rigid").rglob("*.py")}
    files = {k.removesuffix(".__init__"): p for k, p in files.items()}
    graph = {m: _rigid_imports(p, set(files)) - {m} for m, p in files.items()}
    graph["rigid"] = set()  # the package's own imports are its curated API, not a layer
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(m: str) -> None:
        state[m] = 1
        stack.append(m)
        for n in sorted(graph[m]):
            assert state.get(n) != 1, " -> ".join([*stack[stack.index(n):], n])
            if n not in state:
                visit(n)
        stack.pop()
        state[m] = 2

    for m in sorted(graph):
        if m not in state:
            visit(m)
    earth = {"rigid.earth", "rigid.earth.constants", "rigid.earth.liouville",
             "rigid.earth.wobble_fit", "rigid.earth.prediction"}
    assert earth <= set(graph)
    # the constants stand below the Liouville pole, which takes its defaults from them
    assert "rigid.earth.constants" in graph["rigid.earth.liouville"]
    assert not graph["rigid.earth.constants"] & earth
    # nothing in rigid.earth imports the facade (or the old paths) that stands on it
    olds = {f"rigid.{m}" for m in ("polar_motion", "c04", "liouville", "wobble", "ar_models",
                                   "pole_prediction", "scene_polar", "scene_prediction")}
    for name in (m for m in graph if m.startswith("rigid.earth")):
        assert not graph[name] & olds, name
    assert importlib.import_module("rigid.earth.free_wobble").free_period is wobble_fit.free_period
