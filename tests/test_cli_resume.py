"""``hamilton-orbits resume OUTDIR``: a scene run killed (SIGKILL) at any moment and
resumed ends with the files of the run that was never interrupted, its states to
the bit (``[output] archive_every``, docs/archive.md)."""

from __future__ import annotations

import os
import signal
import time

import numpy as np
import pytest
from scipy.io import netcdf_file

from hamilton_orbits import Archive
from hamilton_orbits.cli import main

SETS = ["--set", "duration=30 d", "--set", "cadence=0.5 d", "--set", "crosscheck=false",
        "--set", "output.archive_every=3 d", "--no-progress"]


def _states(folder) -> dict[str, np.ndarray]:
    with netcdf_file(folder / "states.nc", "r", mmap=False) as nc:
        return {k: np.array(v[:]) for k, v in nc.variables.items()}


def _kill_after_snapshots(pid: int, archive, count: int) -> None:
    """SIGKILL ``pid`` as soon as ``archive`` holds ``count`` snapshots."""
    while not archive.is_dir() or len(Archive(archive)) < count:
        if os.waitpid(pid, os.WNOHANG) != (0, 0):
            raise AssertionError("the run ended before it was killed")
        time.sleep(0.002)
    os.kill(pid, signal.SIGKILL)
    os.waitpid(pid, 0)


def test_a_killed_scene_run_resumes_to_the_files_of_the_whole_run(tmp_path, capsys):
    assert main(["run", "comet-encounter", "--out", str(tmp_path / "whole"), *SETS]) == 0
    assert "hamilton-orbits resume" in capsys.readouterr().err  # says how to resume
    whole = _states(tmp_path / "whole")
    for count in (2, 7):  # of 11 snapshots (every 3 d of 30 d)
        out = tmp_path / f"killed{count}"
        pid = os.fork()
        if pid == 0:  # the child: the same command, killed part way
            try:
                main(["run", "comet-encounter", "--out", str(out), *SETS])
            finally:
                os._exit(0)
        _kill_after_snapshots(pid, out / "archive", count)
        assert not (out / "states.nc").exists()  # killed before it ended
        assert main(["resume", str(out), "--no-progress"]) == 0
        resumed = _states(out)
        assert sorted(resumed) == sorted(whole)
        for name, values in whole.items():
            assert np.array_equal(resumed[name], values, equal_nan=True), name
        written = {p.name for p in out.iterdir()}
        assert {p.name for p in (tmp_path / "whole").iterdir()} <= written
        # the run went on from its last snapshot: not begun again from the start
        times = Archive(out / "archive").times
        assert np.all(np.diff(times) >= 0) and times.tolist().count(0.0) == 1, times


def test_run_refuses_a_folder_holding_an_earlier_run_s_archive(tmp_path, capsys):
    assert main(["run", "comet-encounter", "--out", str(tmp_path), *SETS]) == 0
    assert main(["run", "comet-encounter", "--out", str(tmp_path), *SETS]) == 1
    assert "holds the snapshots of an earlier run: resume it" in capsys.readouterr().err


def test_resume_names_a_folder_without_an_archive(tmp_path, capsys):
    assert main(["resume", str(tmp_path)]) == 1
    assert "is not the output folder of a scene run with an archive" in (
        capsys.readouterr().err)


@pytest.mark.parametrize("value", ["-3 d", "3 m", "soon"])
def test_a_bad_archive_interval_is_a_bad_scene(value, capsys):
    sets = ["--set", f"output.archive_every={value}", "--set", "duration=1 d"]
    assert main(["run", "comet-encounter", *sets, "--no-progress"]) == 2
    assert "archive_every" in capsys.readouterr().err
