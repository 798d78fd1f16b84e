"""The runnable studies in examples/<section>/ run and report what they claim.

Each example is run as a user would (a subprocess); the assertions read its
printed summary, so an example that rots (or whose numbers drift) fails here.
"""

import re
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def run(name: str, *args: str) -> str:
    res = subprocess.run(
        [sys.executable, str(EXAMPLES / name), *args],
        capture_output=True,
        text=True,
        check=True,
        timeout=300,
    )
    return res.stdout


def test_dzhanibekov_flip(tmp_path):
    """The slope of T/2 against -ln(1 - m) approaches 1/lambda (DLMF 19.12.1)."""
    out = run("rigid/plot_dzhanibekov_flip.py", "--out", str(tmp_path))
    slope, inv_lam = map(float, re.search(r"([\d.]+) s; 1/lambda = ([\d.]+) s", out).groups())
    assert abs(slope - inv_lam) <= 1e-5 * inv_lam
    # the exact interval agrees with DOP853 where DOP853 is reliable (1 - m >= 2e-5)
    rows = re.findall(r"^\s*\S+\s+(\S+)\s+\S+\s+\S+\s+(\S+)$", out, flags=re.M)
    diffs = {float(one_minus_m): float(d) for one_minus_m, d in rows}
    assert all(d < 1e-10 for m1, d in diffs.items() if m1 >= 2e-5)
    assert (tmp_path / "dzhanibekov_flip.png").stat().st_size > 10_000


def test_elements_crosscheck_quick(tmp_path):
    """The cross-check against rebound runs and names cases rebound cannot do (its
    table written into the test's own folder, not the checkout's)."""
    out = run("nbody/elements_crosscheck.py", "--quick", "--out", str(tmp_path))
    assert (tmp_path / "elements_crosscheck.txt").read_text().strip() == out.strip()
    # random orbits: no NaN on our side, and a, e agree with rebound to rounding
    assert re.search(r"NaN: rebound \d+, ours 0\b", out)
    lines = out.splitlines()
    head = lines.index(next(x for x in lines if x.strip().startswith("a ")))
    da, de = map(float, lines[head + 1].split()[:2])
    assert da < 1e-12 and de < 1e-12
    # the hard cases where rebound returns NaN (radial orbits among them) are listed
    nan_rows = [x for x in lines if "radial bound" in x and " nan " in f" {x} "]
    assert nan_rows


def test_pole_wander_rigid_earth_quick(tmp_path):
    """The integrated rigid-Earth wobble has the linear Euler period (~304.5 sidereal d)."""
    out = run("earth_pole/plot_pole_wander_rigid_earth.py", "--out", str(tmp_path), "--quick")
    value = {m[0].strip(): float(m[1]) for m in re.findall(r"^(.+?)\s{2,}([-\d.e+]+)\s", out,
                                                           flags=re.M)}
    t_e = value["Euler period, linear (triaxial)"]
    assert abs(value["period fitted, splitting4"] / t_e - 1) < 1e-9
    assert abs(value["period fitted, exact free motion"] / t_e - 1) < 1e-9
    assert 304.4 < float(re.search(r"([\d.]+)\s+sidereal d", out).group(1)) < 304.5
    assert (tmp_path / "pole_wander_rigid_earth.png").stat().st_size > 10_000


def test_chandler_wobble_quick(tmp_path):
    """The fitted Chandler period is within the published 430-436 d (Wilson & Vicente 1990)."""
    out = run("earth_pole/chandler_wobble.py", str(tmp_path), "--quick")
    t_c = float(re.search(r"^Chandler period\s+([\d.]+) \+- ([\d.]+)\s+d", out,
                          flags=re.M).group(1))
    assert 430 < t_c < 436
    assert "Q caveat" in out
    assert (tmp_path / "chandler_wobble.png").stat().st_size > 10_000
    assert (tmp_path / "chandler_wobble.txt").read_text().startswith("window")


@pytest.mark.slow  # four clones in worker processes: ~40 s on a loaded 2-core machine
def test_ensemble_comet_clones_quick(tmp_path):
    """Every clone runs; the encounter scatters 1/a (some clones escape: 1/a < 0),
    reported as 1/a, which is smooth through the parabola, not as a, which jumps
    through +-infinity there."""
    out = run("ensembles/ensemble_comet_clones.py", str(tmp_path), "--quick")
    assert "4 clones, 0 failed" in out
    rows = re.findall(r"^\s+(0\.999\d+)\s+([\d.]+)\s+(-?[\d.]+)\s+([\d.]+)\s+(bound|escapes)",
                      out, flags=re.M)
    assert len(rows) == 4
    assert all(0.02 < float(c) < 0.04 for _, c, _, _, _ in rows)
    inv_a = [float(x) for _, _, x, _, _ in rows]
    assert len({round(x, 5) for x in inv_a}) == 4
    assert all((x > 0) == (kind == "bound") for x, (*_, kind) in zip(inv_a, rows, strict=True))
    # the encounter lifts the perihelion from 0.01 au to 0.07-0.09 au (16 clones)
    assert all(0.05 < float(q) < 0.12 for _, _, _, q, _ in rows)
    assert (tmp_path / "comet_clones.png").stat().st_size > 10_000


@pytest.mark.slow  # 2 x 64 cells in worker processes: ~15 s on a loaded 2-core machine
def test_stability_map_quick(tmp_path):
    """The MEGNO map runs (8 x 8 cells, both models), finds regular and chaotic
    cells, and draws its figure."""
    out = run("chaos/stability_map.py", str(tmp_path), "--quick")
    rows = re.findall(r"(\d+) failed, chaotic \(MEGNO > 4\): ([\d.]+)%, median MEGNO of the "
                      r"regular cells ([\d.]+)", out)
    assert len(rows) == 2
    for failed, chaotic, regular in rows:
        assert int(failed) == 0 and 10 < float(chaotic) < 90 and abs(float(regular) - 2) < 0.1
    assert (tmp_path / "stability_map.png").stat().st_size > 30_000


@pytest.mark.slow  # a study (126 weekly hindcasts of five methods, in a subprocess): 9 s of
# the cold suite's 5 minutes; predict and hindcast are tested in tests/rigid
def test_pole_prediction_quick(tmp_path):
    """The hindcast tables carry every method beside the published rows; figures written."""
    out = run("earth_pole/pole_prediction.py", str(tmp_path), "--quick")
    assert "126 weekly starts" in out
    for name in ("persistence", "ls+ar", "ls+var", "liouville", "WLS+VAR (Lei et al. 2023)"):
        assert re.search(rf"^{re.escape(name)}\s+[\d.]+", out, flags=re.M), name
    assert re.search(r"at or below in \d+ of 10 cells", out)
    for png in ("prediction_fan", "mae_vs_horizon", "coverage"):
        assert (tmp_path / f"{png}.png").stat().st_size > 10_000
    assert (tmp_path / "pole_prediction.txt").read_text().startswith("scene pole-prediction")


def test_comet_encounter_colours_a_body_alike_and_its_legend_hides_no_data(monkeypatch):
    """The legend covered the comet - Jupiter curve after closest approach, and blue
    was the comet - Sun distance in one panel and Jupiter in the other."""
    import runpy

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    monkeypatch.setattr(plt, "show", lambda *a, **k: None)
    runpy.run_path(str(EXAMPLES / "events" / "plot_comet_encounter.py"), run_name="__main__")
    fig = plt.figure(plt.get_fignums()[-1])
    ax1, ax2 = fig.axes
    colour = {ln.get_label(): matplotlib.colors.to_hex(ln.get_color())
              for ax in (ax1, ax2) for ln in ax.get_lines()}
    assert colour["comet - Jupiter"] == colour["Jupiter"]
    assert colour["comet - Sun"] == colour["Sun"] != colour["comet"]
    assert colour["comet"] not in (colour["Jupiter"], colour["Sun"])
    fig.canvas.draw()
    legend = ax1.get_legend().get_window_extent()
    assert legend.y1 <= ax1.get_window_extent().y0  # below the axes, over no data
    plt.close("all")
