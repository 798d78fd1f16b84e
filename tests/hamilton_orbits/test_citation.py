"""hamilton_orbits.cite (BibTeX for a run's methods) and CITATION.cff."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

import hamilton_orbits
from hamilton_orbits import Body, Simulation, System, cite, integrate

ROOT = Path(__file__).resolve().parents[2]
#: the fields each entry type must have (BibTeX's required fields; @software as biblatex)
REQUIRED = {
    "article": {"author", "title", "journal", "year"},
    "inproceedings": {"author", "title", "booktitle", "year"},
    "book": {"author", "title", "publisher", "year"},
    "software": {"author", "title", "year"},
}


def _system() -> System:
    return System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                   Body("planet", 1e-3, [1.0, 0, 0], [0, 1.0, 0]),
                   Body("outer", 1e-4, [2.0, 0, 0], [0, 0.7, 0.05])])


def _entries(bib: str) -> list[tuple[str, str, set[str]]]:
    """(type, key, field names) of each entry, checking each is BibTeX-shaped."""
    out = []
    for block in bib.strip().split("\n\n"):
        assert block.count("{") == block.count("}"), block
        depth = 0
        for ch in block:  # never closes more than it opened
            depth += {"{": 1, "}": -1}.get(ch, 0)
            assert depth >= 0, block
        head = re.match(r"@(\w+)\{([A-Za-z0-9_]+),\n", block)
        assert head, block
        fields = set(re.findall(r"^\s+([a-z]+) = [{\"0-9]", block, flags=re.M))
        kind = head.group(1)
        assert REQUIRED[kind] <= fields, (head.group(2), REQUIRED[kind] - fields)
        assert block.endswith("}")
        out.append((kind, head.group(2), fields))
    return out


def _keys(bib: str) -> list[str]:
    return [key for _, key, _ in _entries(bib)]


def test_package_alone():
    bib = cite()
    assert _keys(bib) == ["hamilton_orbits", "hamilton1845"]
    assert f"version = {{{hamilton_orbits.__version__}}}" in bib


def test_radau15_run():
    traj = integrate(_system(), 1.0, method="radau15")
    keys = _keys(cite(traj))
    # (its default step rule is Pham, Rein & Spiegel's: it was not cited)
    assert keys == ["hamilton_orbits", "hamilton1845", "everhart1985", "rein2015ias15",
                    "pham2024"]
    assert _keys(cite(Simulation(_system()))) == keys
    assert _keys(cite("radau15")) == keys
    assert "pham2024" not in _keys(cite(Simulation(_system(), criterion="global")))
    assert "pham2024" not in _keys(cite(Simulation(_system(), dt=0.01)))  # (no step rule)


def test_the_default_wh_cites_its_democratic_heliocentric_splitting():
    """wh's default coordinates are Duncan, Levison & Lee's (1998): not cited."""
    keys = _keys(cite(integrate(_system(), 1.0, method="wh", dt=0.01)))
    assert keys[2:] == ["wisdom1991", "duncan1998"]
    assert "duncan1998" not in _keys(cite(Simulation(_system(), method="wh", dt=0.01,
                                                     coordinates="jacobi")))


def test_wh_with_corrector_and_gr_potential():
    sim = Simulation(_system(), method="wh", dt=0.01, coordinates="jacobi", corrector=11,
                     effects=[{"name": "gr_potential", "c": 10065.32}])
    sim.integrate(0.1)
    keys = _keys(cite(sim))
    assert keys == ["hamilton_orbits", "hamilton1845", "wisdom1991", "wisdom1996",
                    "rein2015whfast", "nobili1986"]
    # the same from a name, the corrector given (and the default coordinates' paper)
    assert _keys(cite("wh", ["gr_potential"], corrector=11)) == [
        "hamilton_orbits", "hamilton1845", "wisdom1991", "duncan1998", "wisdom1996",
        "rein2015whfast", "nobili1986"]
    # without a corrector: the map only
    assert "wisdom1996" not in _keys(cite("wh", ["gr_potential"]))


def test_variational_run():
    traj = integrate(_system(), 1.0, method="wh", dt=0.01, variational=True)
    keys = _keys(cite(traj))
    assert keys[-1] == "cincotta2000" and "wisdom1991" in keys
    sim = Simulation(_system(), method="radau15", variational=True)
    assert _keys(cite(sim))[-1] == "cincotta2000"
    assert "cincotta2000" not in _keys(cite(integrate(_system(), 1.0, method="wh", dt=0.01)))


@pytest.mark.parametrize(("args", "kw", "expected"), [
    (("dop853",), {}, ["hairer1993"]),
    (("leapfrog",), {}, ["verlet1967"]),
    (("radau15", ["gr", {"name": "j2", "body": "sun"}]), {}, ["anderson1975", "tamayo2020"]),
    (("radau15", ["eih"]), {}, ["park2021"]),
    (("radau15",), {"ephemeris": True}, ["park2021"]),
    (("radau15", [{"name": "nongrav", "A2": 1e-12}]), {}, ["marsden1973"]),
])
def test_other_methods_and_effects(args, kw, expected):
    keys = _keys(cite(*args, **kw))
    assert keys[:2] == ["hamilton_orbits", "hamilton1845"]
    assert all(k in keys for k in expected)
    assert len(keys) == len(set(keys))


def test_every_entry_is_bibtex_shaped():
    from hamilton_orbits.citations import ENTRIES

    for key, entry in ENTRIES.items():
        ((_, parsed, _),) = _entries(entry)
        assert parsed == key
        doi = re.search(r"doi = \{([^}]*)\}", entry)
        assert doi is None or doi.group(1).startswith("10.")


def test_unknown_method_refused():
    with pytest.raises(ValueError, match="Expected a method"):
        cite("rk4")


def test_citation_cff():
    text = (ROOT / "CITATION.cff").read_text()
    try:
        import yaml
    except ImportError:  # pragma: no cover - a parse check of the top-level keys only
        data = dict(re.findall(r"^([a-z-]+): \"?([^\"\n]*)\"?$", text, flags=re.M))
    else:
        data = yaml.safe_load(text)
    for key in ("cff-version", "message", "title", "authors", "version", "date-released",
                "license"):
        assert key in data, key
    assert str(data["cff-version"]) == "1.2.0"
    assert str(data["version"]) == hamilton_orbits.__version__
    assert data["license"] == "BSD-3-Clause"
    if isinstance(data.get("references"), list):
        years = sorted(int(r["year"]) for r in data["references"])
        assert years == [1843, 1847, 1866]  # Cayley, Hamilton (read 1845), Sylvester
