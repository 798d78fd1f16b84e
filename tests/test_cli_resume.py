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
        out = {k: np.array(v[:]) for k, v in nc.variables.items()}
    return out


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    """Equal arrays, NaN equal to NaN in floats (the body names are characters)."""
    return np.array_equal(a, b, equal_nan=a.dtype.kind == "f")


def _pause_after_snapshots(count: int) -> None:
    """In the forked child: the archive writer sleeps once it has written ``count``
    snapshots, so that the parent's SIGKILL comes then, not after the run's end (a
    30-day run could end between two of the parent's looks: the test raced it)."""
    from hamilton_orbits.checkpoint import ArchiveWriter

    for name in ("write", "append", "refill"):
        real = getattr(ArchiveWriter, name)

        def paused(self, *args, _real=real, **kwargs):
            out = _real(self, *args, **kwargs)
            if self.count >= count:
                time.sleep(3600)  # (until killed)
            return out

        setattr(ArchiveWriter, name, paused)


def _kill_after_snapshots(pid: int, archive, count: int) -> None:
    """SIGKILL ``pid`` as soon as ``archive`` holds ``count`` snapshots."""
    while not archive.is_dir() or len(Archive(archive)) < count:
        if os.waitpid(pid, os.WNOHANG) != (0, 0):
            raise AssertionError("the run ended before it was killed")
        time.sleep(0.002)
    os.kill(pid, signal.SIGKILL)
    os.waitpid(pid, 0)


def _write_from_bin(folder) -> None:
    """``folder/from-bin.toml``: a 6-day scene starting from ``start.bin`` (a rebound
    binary of the Sun, Jupiter, Saturn and a comet), archived every 2 days."""
    (folder / "from-bin.toml").write_text(
        'kind = "nbody"\nduration = "6 d"\ncadence = "1 d"\ncrosscheck = false\n'
        '[initial]\nrebound = "start.bin"\nnames = ["sun", "jupiter", "saturn", "comet"]\n'
        '[output]\narchive_every = "2 d"\n', encoding="utf-8")


def _killed_at_its_end(out) -> None:
    """The run in ``out`` as if killed after its last snapshot, before its files were
    written: its archive's record without the mark a finished run leaves (a finished
    run is not resumed: "there is nothing to resume")."""
    import json

    record = out / "archive" / "scene.json"
    text = json.loads(record.read_text(encoding="utf-8"))
    assert text.pop("finished") is True
    record.write_text(json.dumps(text), encoding="utf-8")


def test_a_killed_scene_run_resumes_to_the_files_of_the_whole_run(tmp_path, capsys):
    assert main(["run", "comet-encounter", "--out", str(tmp_path / "whole"), *SETS]) == 0
    assert "hamilton-orbits resume" in capsys.readouterr().err  # says how to resume
    whole = _states(tmp_path / "whole")
    for count in (2, 7):  # of 11 snapshots (every 3 d of 30 d)
        out = tmp_path / f"killed{count}"
        pid = os.fork()
        if pid == 0:  # the child: the same command, killed part way
            try:
                _pause_after_snapshots(count)
                main(["run", "comet-encounter", "--out", str(out), *SETS])
            finally:
                os._exit(0)
        _kill_after_snapshots(pid, out / "archive", count)
        assert not (out / "states.nc").exists()  # killed before it ended
        assert main(["resume", str(out), "--no-progress"]) == 0
        resumed = _states(out)
        assert sorted(resumed) == sorted(whole)
        for name, values in whole.items():
            assert _same(resumed[name], values), name
        written = {p.name for p in out.iterdir()}
        assert {p.name for p in (tmp_path / "whole").iterdir()} <= written
        # the run went on from its last snapshot: not begun again from the start
        times = Archive(out / "archive").times
        assert np.all(np.diff(times) >= 0) and times.tolist().count(0.0) == 1, times


def test_run_refuses_a_folder_holding_an_earlier_run_s_archive(tmp_path, capsys):
    """Refused before anything runs: exit 2, as any bad command line (docs/scenes.md;
    it was 1, a failure during the run)."""
    assert main(["run", "comet-encounter", "--out", str(tmp_path), *SETS]) == 0
    _killed_at_its_end(tmp_path)
    assert main(["run", "comet-encounter", "--out", str(tmp_path), *SETS]) == 2
    assert "holds the snapshots of an earlier run: resume it" in capsys.readouterr().err


def test_resume_names_a_folder_without_an_archive(tmp_path, capsys):
    assert main(["resume", str(tmp_path)]) == 2
    assert "is not the output folder of a scene run with an archive" in (
        capsys.readouterr().err)


def test_a_run_whose_out_is_named_after_its_bundled_scene_resumes(tmp_path, monkeypatch,
                                                                  capsys):
    """``run comet-encounter --out comet-encounter``: the folder the run makes does not
    hide the bundled scene of its name (the archive used to record the folder as the
    scene's file, and resume failed: "cannot read the scene file (Is a directory)");
    resumed, the summary says its integration time is that since the resume."""
    monkeypatch.chdir(tmp_path)
    assert main(["run", "comet-encounter", "--out", "comet-encounter", *SETS]) == 0
    capsys.readouterr()
    _killed_at_its_end(tmp_path / "comet-encounter")
    assert main(["resume", "comet-encounter", "--no-progress"]) == 0
    assert "s of integration since the resume at t = 30 d" in capsys.readouterr().out
    assert main(["run", "comet-encounter", "--out", "other", *SETS]) == 0


def test_resume_runs_the_scene_as_the_run_read_it(tmp_path, capsys):
    """A scene file edited (or gone) after its run began: resume runs the scene the
    run read, kept in the archive, and says the file has changed (it used to read the
    file again: another duration, other bodies' names on the run's states)."""
    from importlib import resources

    text = (resources.files("hamilton_orbits") / "data" / "scenes" /
            "comet-encounter.toml").read_text(encoding="utf-8")
    scene = tmp_path / "my scene.toml"
    scene.write_text(text, encoding="utf-8")
    out = tmp_path / "out put"
    assert main(["run", str(scene), "--out", str(out), *SETS]) == 0
    assert f"hamilton-orbits resume '{out}'" in capsys.readouterr().err  # (quoted)
    whole = _states(out)
    scene.write_text(text.replace('duration = "', 'duration = "2 yr" # "'), encoding="utf-8")
    _killed_at_its_end(out)
    assert main(["resume", str(out), "--no-progress"]) == 0
    assert "has changed since the run began; resuming the scene as the run read it" in (
        capsys.readouterr().err)
    resumed = _states(out)
    assert all(_same(resumed[k], whole[k]) for k in whole)
    scene.unlink()
    _killed_at_its_end(out)
    assert main(["resume", str(out), "--no-progress"]) == 0


def test_an_archive_folder_that_cannot_be_made_is_refused_before_the_run(tmp_path, capsys):
    (tmp_path / "archive").write_text("a file where the archive goes")
    assert main(["run", "comet-encounter", "--out", str(tmp_path), *SETS]) == 2
    err = capsys.readouterr().err
    assert f"--out {tmp_path}: cannot write {tmp_path / 'archive'}" in err
    assert "nothing was run" in err and "Traceback" not in err


@pytest.mark.parametrize("value", ["-3 d", "3 m", "soon", "1e-3 s"])
def test_a_bad_archive_interval_is_a_bad_scene(value, capsys):
    sets = ["--set", f"output.archive_every={value}", "--set", "duration=1 d"]
    assert main(["run", "comet-encounter", *sets, "--no-progress"]) == 2
    assert "archive_every" in capsys.readouterr().err


def test_a_scene_reading_a_relative_file_resumes_from_another_folder(tmp_path, monkeypatch):
    """A scene whose ``[initial] rebound`` is a path relative to the folder the run
    began in resumes from anywhere (the archive keeps that folder; the resume used
    to fail: "no such file 'start.bin' (relative to ...)"), and the command leaves
    the working folder as it found it."""
    monkeypatch.chdir(tmp_path)
    assert main(["run", "comet-encounter", "--out", "first", *SETS]) == 0
    (tmp_path / "start.bin").write_bytes((tmp_path / "first" / "final.bin").read_bytes())
    _write_from_bin(tmp_path)
    assert main(["run", "from-bin.toml", "--out", "out", "--no-progress"]) == 0
    whole = _states(tmp_path / "out")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    _killed_at_its_end(tmp_path / "out")
    assert main(["resume", str(tmp_path / "out"), "--no-progress"]) == 0
    assert os.getcwd() == str(elsewhere)
    resumed = _states(tmp_path / "out")
    assert all(_same(resumed[k], whole[k]) for k in whole)


@pytest.mark.parametrize("text", ["{\"scene\": \"comet-encounter\", \"set\": [\"a", "", "{}",
                                  "[]", '{"scene": "mercury-gr", "set": [1]}',
                                  '{"scene": "mercury-gr", "text": 5}',
                                  '{"scene": "mercury-gr", "cwd": []}'])
def test_resume_of_a_damaged_scene_record_says_so_naming_it(tmp_path, capsys, text):
    """``archive/scene.json`` cut short (a run that could not write it whole) or not
    a run's record gave ``JSONDecodeError``, ``KeyError: 'scene'`` or an
    AttributeError (exit 1); it is named as damaged (exit 2), and the run's own
    writes it whole (under a temporary name, then renamed)."""
    (tmp_path / "archive").mkdir()
    (tmp_path / "archive" / "scene.json").write_text(text)
    assert main(["resume", str(tmp_path), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "archive/scene.json is damaged" in err and "hamilton-orbits run" in err


def test_resume_of_an_empty_path_names_outdir(capsys):
    """``resume ''`` named ``--out``, an option ``resume`` does not have."""
    assert main(["resume", ""]) == 2
    assert "OUTDIR '': an empty path" in capsys.readouterr().err


def test_ctrl_c_while_a_finished_run_is_saved_keeps_its_files(tmp_path, capsys):
    """A Ctrl-C while ``run`` writes the files of a finished run aborted the saving:
    exit 130 with only the summary written.  The first is kept until the files are
    written (exit 130, every file there); a second would abort."""
    from pathlib import Path
    from types import SimpleNamespace

    from hamilton_orbits import cli

    class Finished:  # (a Result's interface, as the command line reads it)
        complete, interrupted, not_saved = True, False, []

        def summary(self):
            return "summary"

        def save(self, folder):
            os.kill(os.getpid(), signal.SIGINT)  # (Ctrl-C, the moment saving begins)
            time.sleep(0.01)
            path = Path(folder) / "states.nc"
            path.write_text("states")
            return [path]

    code = cli._finish(SimpleNamespace(name="demo"), Finished(), tmp_path, None)
    assert code == cli.EXIT_INTERRUPTED and (tmp_path / "states.nc").read_text() == "states"
    captured = capsys.readouterr()
    assert "saving the run's files first" in captured.err and "wrote 1 files" in captured.out


def test_a_run_stopped_before_its_first_snapshot_is_resumed_and_may_be_run_again(
        tmp_path, monkeypatch, capsys):
    """A disk full at the first snapshot's record (a mocked ``pwrite``; a SIGKILL
    there leaves the same) leaves a segment of no snapshot: ``resume`` failed ("no
    readable snapshot") and ``run`` refused the folder ("holds the snapshots of an
    earlier run"), so that only deleting files by hand went on.  ``resume`` now runs
    the scene from its start, to the files of the run never stopped, and ``run``
    takes the folder again."""
    import errno

    from hamilton_orbits import segment

    assert main(["run", "comet-encounter", "--out", str(tmp_path / "whole"), *SETS]) == 0
    whole = _states(tmp_path / "whole")
    real = os.pwrite

    def full(fd, data, offset):
        raise OSError(errno.ENOSPC, "No space left on device")

    for out in (tmp_path / "resumed", tmp_path / "run-again"):
        monkeypatch.setattr(segment.os, "pwrite", full)
        assert main(["run", "comet-encounter", "--out", str(out), *SETS]) != 0
        monkeypatch.setattr(segment.os, "pwrite", real)
        assert "No space left on device" in capsys.readouterr().err
        assert len(Archive(out / "archive")) == 0 and list((out / "archive").glob("segment-*"))
    assert main(["resume", str(tmp_path / "resumed"), "--no-progress"]) == 0
    assert main(["run", "comet-encounter", "--out", str(tmp_path / "run-again"), *SETS]) == 0
    for out in (tmp_path / "resumed", tmp_path / "run-again"):
        resumed = _states(out)
        assert sorted(resumed) == sorted(whole)
        for name, values in whole.items():
            assert _same(resumed[name], values), name


def test_a_finished_run_is_not_taken_for_one_to_resume(tmp_path, capsys):
    """A run that finished left an archive that ``run`` refused as "the snapshots of
    an earlier run: resume it", and that ``resume`` ran again (rewriting every file,
    "0.00 s of integration since the resume at t = 30 d"; with ``archive_every``
    longer than the run, its whole span again).  Now ``run`` says the run finished
    and how to run into the folder again, and ``resume`` that there is nothing to
    resume; the files stay the finished run's.  And ``run`` of a scene with no
    ``archive_every`` into a folder holding a killed run's snapshots ran there (a
    later ``resume`` of the killed run then replaced its files, unsaid): it is
    refused, naming ``resume``."""
    out = tmp_path / "done"
    assert main(["run", "comet-encounter", "--out", str(out), *SETS]) == 0
    whole = (out / "states.nc").read_bytes()
    capsys.readouterr()
    assert main(["run", "comet-encounter", "--out", str(out), *SETS]) == 2
    err = capsys.readouterr().err
    assert "holds the archive of an earlier run, which finished" in err
    assert f"remove {out / 'archive'} to run into {out} again" in err and "resume" not in err
    assert main(["resume", str(out), "--no-progress"]) == 2
    assert f"the run in {out} finished" in capsys.readouterr().err
    assert (out / "states.nc").read_bytes() == whole
    _killed_at_its_end(out)  # (the same folder, as if killed after its last snapshot)
    assert main(["run", "leo-j2", "--set", "duration=1 d", "--out", str(out),
                 "--no-progress"]) == 2
    assert "holds the snapshots of an earlier run: resume it" in capsys.readouterr().err


def test_resume_begins_from_the_state_the_run_read(tmp_path, monkeypatch, capsys):
    """A scene whose ``[initial] rebound`` file changed after its run began was
    resumed with the system read again from the file: a body moved made the resume
    fail ("Expected `trajectory` to start from `system`'s state"), a mass changed
    gave a cross-check against another system.  The resume begins from the state
    the run began with (the archive's), says the file changed, and ends on the
    files of the run never interrupted."""
    import astropy.units as u

    from hamilton_orbits import Body, System

    monkeypatch.chdir(tmp_path)  # (a start as a run's final.bin is: to_rebound's binary)
    planets = System.from_ephemeris(bodies=["sun", "jupiter", "saturn"])
    sun = planets.bodies[0]  # (the comet: 1.3 au from the Sun, 30 km/s about it)
    comet = Body("comet", 0 * u.km**3 / u.s**2, [1.3, 0, 0] * u.au + sun.r,
                 [0, 30, 0] * u.km / u.s + sun.v)
    System([*planets.bodies, comet]).to_rebound().save_to_file(str(tmp_path / "start.bin"),
                                                               delete_file=True)
    start = (tmp_path / "start.bin").read_bytes()
    _write_from_bin(tmp_path)
    assert main(["run", "from-bin.toml", "--out", "out", "--no-progress"]) == 0
    whole = _states(tmp_path / "out")
    capsys.readouterr()
    import rebound

    moved = rebound.Simulation(start)  # (the comet moved by 0.5 au)
    moved.particles[3].x += 0.5
    moved.save_to_file(str(tmp_path / "start.bin"), delete_file=True)
    _killed_at_its_end(tmp_path / "out")
    assert main(["resume", "out", "--no-progress"]) == 0
    assert ("the scene's [initial] rebound file 'start.bin' has changed since the run began; "
            "resuming from the state the run began with") in capsys.readouterr().err
    resumed = _states(tmp_path / "out")
    assert all(_same(resumed[k], whole[k]) for k in whole)


def test_an_aborted_archived_run_says_how_to_resume(tmp_path, capsys):
    """A second Ctrl-C (the run aborted, no file written) printed only "interrupted
    (Ctrl-C)", though the archive was there and ``resume`` continues it."""
    from types import SimpleNamespace

    from hamilton_orbits import cli

    def aborted(**kwargs):
        raise KeyboardInterrupt

    scene = SimpleNamespace(name="demo", run=aborted)
    with pytest.raises(KeyboardInterrupt):
        cli._run_scene(scene, False, tmp_path / "out" / "archive")
    assert (f"its archive is {tmp_path / 'out' / 'archive'}/: continue the run with "
            f"hamilton-orbits resume {tmp_path / 'out'}") in capsys.readouterr().err


def test_a_resumed_run_s_codes_table_says_its_steps_and_wall_time_are_since_the_resume(
        tmp_path, capsys):
    """After a resume, the cross-check's table of codes put our steps and wall time
    since the resume (0.19 s for the last 100 yr of 1000) beside rebound's for the
    whole run (4.4 s), unsaid but in a metric apart."""
    import json

    out = tmp_path / "run"
    sets = [s if s != "crosscheck=false" else "crosscheck=true" for s in SETS]
    assert main(["run", "comet-encounter", "--out", str(out), *sets]) == 0
    _killed_at_its_end(out)
    capsys.readouterr()
    assert main(["resume", str(out), "--no-progress"]) == 0
    tables = json.loads((out / "summary.json").read_text(encoding="utf-8"))["tables"]
    ours, rebound = tables["cross-check against rebound: codes"]
    assert ours["code"].startswith("hamilton-orbits radau15 (steps and wall time since the "
                                   "resume at t = ")
    assert ours["code"].endswith("only; rebound's: the whole run)")
    assert rebound["code"].startswith("rebound")
