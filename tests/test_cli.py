"""The console script answers --version, --help and runs the default demo."""

import subprocess
import sys

import numpy as np

import hamilton_orbits
from hamilton_orbits.cli import main


def test_version(capsys):
    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"hamilton-orbits {hamilton_orbits.__version__}"


def test_default_demo_runs(capsys):
    assert main([]) == 0
    out = capsys.readouterr().out
    assert "ijk = Quaternion([-1.0, 0.0, 0.0, 0.0])" in out
    # the round-trip error the demo reports is a measured number, at rounding level
    err = float(out.rsplit("largest geodesic error", 1)[1].split()[0])
    assert err < 1e-14
    # seven propagation steps of P/7 return to the start: |r| ~ 1.1e10 mm, so
    # 1e-3 mm is 1e-13 relative (the round-off of seven universal-variable steps)
    back = float(out.split("is back within", 1)[1].split()[0])
    assert back < 1e-3
    # the exact free motion flips the middle-axis spin every flip interval
    flips = out.split("flip intervals:", 1)[1].split("]")[0].strip(" [")
    np.testing.assert_allclose([float(x) for x in flips.split()], [2.0, -2.0, 2.0, -2.0])


def test_console_script_help():
    res = subprocess.run(
        [sys.executable, "-m", "hamilton_orbits.cli", "--help"],
        capture_output=True,
        text=True,
        check=True,
    )
    assert "usage: hamilton-orbits" in res.stdout
