"""The console script answers --version, --help and runs the default demo."""

import subprocess
import sys

import hamilton_orbits
from hamilton_orbits.cli import main


def test_version(capsys):
    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"hamilton-orbits {hamilton_orbits.__version__}"


def test_default_demo_runs(capsys):
    assert main([]) == 0
    out = capsys.readouterr().out
    assert "ijk = Quaternion([-1.,  0.,  0.,  0.])" in out
    # the round-trip error the demo reports is a measured number, at rounding level
    err = float(out.rsplit("largest geodesic error", 1)[1].split()[0])
    assert err < 1e-14


def test_console_script_help():
    res = subprocess.run(
        [sys.executable, "-m", "hamilton_orbits.cli", "--help"],
        capture_output=True,
        text=True,
        check=True,
    )
    assert "usage: hamilton-orbits" in res.stdout
