"""The code base passes ruff with the configuration in pyproject.toml."""

import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_ruff_clean():
    ruff = shutil.which("ruff")
    if ruff is None:  # the test extra installs ruff; fail loudly rather than skip
        pytest.fail("ruff is not installed: pip install -e '.[test]'")
    res = subprocess.run(
        [ruff, "check", "src", "tests", "benchmarks", "examples", "tools"],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    assert res.returncode == 0, res.stdout + res.stderr
