"""``hamilton-orbits report --quick``: files, a self-contained HTML page, a row per method."""

from __future__ import annotations

import base64
import math
from html.parser import HTMLParser

import pytest

from hamilton_orbits.studies.report import build_report

# The report is a study (every problem with every method and its peers, 12 s of the
# cold suite's 5 minutes on 2 cores): run with `python -m pytest -m slow`, as the
# gallery's long examples are.
pytestmark = pytest.mark.slow


def _tool(name: str):
    """A developer tool of ``tools/`` (not installed), imported from its file."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "tools" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(f"tools_{name}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


update_readme = _tool("update_readme").update_readme

# every method the report must cover (issue 11 item 2), as (problem, code, method)
EXPECTED = [
    ("two-body Kepler", "hamilton-orbits", "KeplerOrbit.propagate"),
    ("two-body Kepler", "rebound", "WHFast"),
    ("two-body Kepler", "scipy", "DOP853"),
    *[("solar system", "hamilton-orbits", m) for m in ("radau15", "wh", "leapfrog", "dop853")],
    *[("solar system", "rebound", m) for m in ("IAS15", "WHFast", "leapfrog",
                                                "WHFast (corrector 11)",
                                                "WHFast (corrector 17)")],
    *[("fidelity against DE440", code, rung) for code in
      ("hamilton-orbits radau15", "hamilton-orbits radau15 (the Moon)")
      for rung in ("newtonian", "gr", "eih", "sun_j2", "sun_lt", "figures", "tides",
                   "asteroids", "ring")],
    *[("free rigid body", "hamilton-orbits", m)
      for m in ("exact (free_motion)", "splitting2", "splitting4", "exact_kick", "rk4")],
    ("free rigid body", "scipy (rigid.integrate)", "dop853"),
    ("pole wander", "hamilton-orbits", "exact (free_motion)"),
    ("pole wander", "hamilton-orbits", "splitting4"),
    ("pole wander", "scipy (rigid.integrate)", "DOP853"),
]


class _Collect(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.imgs: list[str] = []
        self.external: list[str] = []
        self.cells: list[str] = []
        self._in_td = False

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "img":
            self.imgs.append(a.get("src") or "")
        for key in ("src", "href"):
            if key in a and tag != "img":
                self.external.append(a[key])
        self._in_td = tag == "td"

    def handle_endtag(self, tag):
        if tag == "td":
            self._in_td = False

    def handle_data(self, data):
        if self._in_td:
            self.cells.append(data)


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    out = tmp_path_factory.mktemp("report")
    return out, build_report(out, quick=True, progress=False)


def test_files_exist(report):
    out, files = report
    names = {f.name for f in files}
    assert {"report.md", "report.html"} <= names
    pngs = [f for f in files if f.suffix == ".png"]
    assert len(pngs) == 6  # one per problem, and all five in work_precision.png
    for f in files:
        assert f.parent == out and f.stat().st_size > 0
    for f in pngs:
        assert f.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_html_self_contained(report):
    out, files = report
    parser = _Collect()
    parser.feed((out / "report.html").read_text(encoding="utf-8"))
    parser.close()
    assert parser.external == []
    embedded = []
    for src in parser.imgs:
        assert src.startswith("data:image/png;base64,")
        embedded.append(base64.b64decode(src.split(",", 1)[1], validate=True))
    # every figure written is embedded, byte for byte
    assert sorted(embedded) == sorted(f.read_bytes() for f in files if f.suffix == ".png")


def _md_rows(out):
    rows = []
    for line in (out / "report.md").read_text(encoding="utf-8").splitlines():
        if line.startswith("| ") and not line.startswith("| problem"):
            cells = [c.strip() for c in line.strip("|").split(" | ")]
            rows.append(cells)
    return rows


def test_every_method_has_a_row_with_positive_time(report):
    out, _ = report
    rows = _md_rows(out)
    assert all(len(r) == 8 for r in rows)
    for problem, code, method in EXPECTED:
        mine = [r for r in rows if (r[0], r[1], r[2]) == (problem, code, method)]
        assert mine, (problem, code, method)
        for r in mine:
            t = float(r[7])
            assert math.isfinite(t) and t > 0, r
            err = float(r[4])
            assert math.isfinite(err) and err >= 0, r
            assert r[6], r  # the reference is stated


def test_accurate_methods_reach_their_reference(report):
    """Invariants the report must show: the exact solvers agree with their references.

    Our universal-variable propagation vs Kepler's equation in mpmath, and radau15 /
    IAS15 vs IAS15 at epsilon = 0: both well below 1e-9 relative (a double-precision
    solver over 10 periods / 10 years; the bound is loose because the error grows
    with the span, it is a sanity check that the pipeline compares like with like).
    """
    out, _ = report
    rows = _md_rows(out)
    kep = [float(r[4]) for r in rows if r[2] == "KeplerOrbit.propagate"]
    assert kep and max(kep) < 1e-9
    ias = [float(r[4]) for r in rows if r[0] == "solar system" and r[2] in ("radau15", "IAS15")]
    assert ias and max(ias) < 1e-9


def test_readme_section_from_the_report(report, tmp_path):
    """tools/update_readme.py rewrites only the generated section and copies the diagram."""
    out, _ = report
    readme = tmp_path / "README.md"
    readme.write_text("# title\n\nbefore\n<!-- report:begin (generated by `python "
                      "tools/update_readme.py`) -->\nold text\n<!-- report:end -->\nafter\n",
                      encoding="utf-8")
    update_readme(out, readme)
    text = readme.read_text(encoding="utf-8")
    assert text.startswith("# title\n\nbefore\n") and text.endswith("<!-- report:end -->\nafter\n")
    assert "old text" not in text
    png = tmp_path / "docs" / "work_precision.png"
    assert png.read_bytes() == (out / "work_precision.png").read_bytes()
    assert (tmp_path / "docs" / "work_precision.md").read_text(encoding="utf-8") == (
        out / "report.md").read_text(encoding="utf-8")
    assert "](docs/work_precision.png)" in text
    # every method of the study has its line, with its error and time
    for problem, code, method in EXPECTED:
        assert f"**{problem}**" in text
        assert f"| {code} | {method} | " in text, (code, method)
    # a second run replaces the section instead of adding one
    update_readme(out, readme)
    assert readme.read_text(encoding="utf-8") == text


def test_readme_without_markers_is_refused(report, tmp_path):
    out, _ = report
    readme = tmp_path / "README.md"
    readme.write_text("# no section\n", encoding="utf-8")
    with pytest.raises(ValueError, match=r"`readme` .* has no generated section"):
        update_readme(out, readme)
    with pytest.raises(ValueError, match=r"`readme` .* is not a file"):
        update_readme(out, tmp_path / "missing.md")


def test_units_and_notation_a_reader_can_trust(report):
    """micro-arcseconds as µas (not "uas"); one notation per numeric column (the
    wall time mixed 9.945e-06, 0.000176 and 1.908)."""
    import re

    out, _ = report
    page = (out / "report.html").read_text(encoding="utf-8")
    assert "µas" in page and "(uas)" not in page
    for r in _md_rows(out):
        assert re.fullmatch(r"\d\.\d{3}e[+-]\d\d", r[4]), r
        assert re.fullmatch(r"\d\.\d{3}e[+-]\d\d", r[7]), r


def test_every_peer_is_given_its_best_setting_and_says_so(report):
    """heyoka's tolerance is relative to the largest state component: tol = 1e-18 is
    its best setting for the solar system, and the report says how each code is set."""
    import importlib.util

    from hamilton_orbits.studies.report import SETTINGS

    out, _ = report
    text = (out / "report.md").read_text(encoding="utf-8")
    assert all(line in text for line in SETTINGS)
    rows = _md_rows(out)
    if importlib.util.find_spec("heyoka") is not None:
        hey = {r[3]: float(r[4]) for r in rows if r[1] == "heyoka"}
        assert "tol = 1e-18" in hey
        # 10 years at its best setting: as close to IAS15 at epsilon 0 as IAS15 itself
        # is at its default (both ~4e-13 at 10 years); 1e-11 is 25 times that
        assert hey["tol = 1e-18"] < 1e-11
    solar = [r for r in rows if r[0] == "solar system"]
    corrected = [float(r[4]) for r in solar if r[2] == "WHFast (corrector 11)"]
    plain = [float(r[4]) for r in solar if r[2] == "WHFast"]
    assert min(corrected) < min(plain) / 100  # the corrector is rebound's best map here
