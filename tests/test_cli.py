"""The console script answers --version, --help, runs scenes and the demo."""

import os
import subprocess
import sys
from pathlib import Path

import astropy.units as u
import numpy as np

import hamilton_orbits
from hamilton_orbits.cli import main


def test_version(capsys):
    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"hamilton-orbits {hamilton_orbits.__version__}"


def test_demo_runs(capsys):
    assert main(["demo"]) == 0
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


def test_python_dash_m_package_runs_the_cli():
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        [str(Path(hamilton_orbits.__file__).parents[1]), os.environ.get("PYTHONPATH", "")])}
    res = subprocess.run([sys.executable, "-m", "hamilton_orbits", "--version"],
                         capture_output=True, text=True, check=True, env=env)
    assert res.stdout.strip() == f"hamilton-orbits {hamilton_orbits.__version__}"


def test_scenes_listing(capsys):
    assert main(["scenes"]) == 0
    out = capsys.readouterr().out
    for name in ("solar-system", "mercury-gr", "leo-j2", "dzhanibekov"):
        assert name in out


def test_run_a_short_scene_writes_outputs(tmp_path, capsys):
    code = main(["run", "solar-system", "--set", "duration=2 yr", "--set", "cadence=0.5 yr",
                 "--out", str(tmp_path), "--no-progress"])
    assert code == 0
    out = capsys.readouterr().out
    assert "cross-check against rebound" in out
    for name in ("summary.md", "summary.json", "orbits.png", "energy_error.png"):
        assert (tmp_path / name).exists()
    # the cross-check is a measurement: ours and IAS15 agree far below the orbits' size
    import json

    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["metrics"]["max relative position difference"] < 1e-9


ESCAPE_SCENE = """\
kind = "nbody"
description = "escape remove"
duration = "400 d"
crosscheck = true
effects = []
[integrator]
method = "radau15"
[[bodies]]
name = "star"
gm = "1.32712440018e20 m3 / s2"
r = ["0 au", "0 au", "0 au"]
v = ["0 km/s", "0 km/s", "0 km/s"]
[[bodies]]
name = "planet"
gm = "1e14 m3/s2"
primary = "star"
a = "1 au"
e = 0.0
[[bodies]]
name = "rogue"
gm = "0 m3/s2"
primary = "star"
a = "-0.2 au"
e = 1.5
[[events]]
name = "escape"
distance = "5 au"
action = "remove"
[[analysis]]
name = "close_approach"
body = "rogue"
other = "planet"
"""


def test_a_scene_whose_escape_removes_a_body_saves_everything(tmp_path, capsys):
    """Issue 32, class 11: the run completed, then exited 1 having saved nothing."""
    path = tmp_path / "escape.toml"
    path.write_text(ESCAPE_SCENE)
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--no-progress"]) == 0
    text = capsys.readouterr().out
    assert "escape" in text and "remove" in text and "skipped: events changed" in text
    for name in ("summary.md", "summary.json", "orbits.png", "energy_error.png",
                 "states.nc", "final.bin"):
        assert (out / name).exists(), name


def test_the_states_file_says_its_bodies_its_time_origin_and_frame(tmp_path):
    """states.nc gave r and v anonymous dimensions and the names only as a comma-joined
    attribute (a name with a comma split in two); time had units "day" and no origin
    (which epoch? for the pole scene, which fit epoch?), the frame only in the summary;
    a rotation scene's seconds were stored as days, 291 of 1001 not converting back
    bit for bit; final.bin said t = 0 after the run.  Read here by xarray and rebound
    alone."""
    import rebound
    import xarray as xr

    from hamilton_orbits.scene import Scene

    out = tmp_path / "ss"
    assert main(["run", "solar-system", "--set", "duration=2 yr", "--set", "crosscheck=false",
                 "--out", str(out), "--no-progress"]) == 0
    with xr.open_dataset(out / "states.nc", engine="scipy") as ds:
        assert list(ds.body.values[:2]) == ["sun", "mercury"] and ds.r.dims == (
            "time", "body", "xyz") and ds.v.dims == ("time", "body", "xyz")
        assert ds.time.attrs["units"] == "d" and ds.time.values[-1] == 730.5
        assert ds.time.attrs["time_origin"].startswith("J2000, the epoch of the initial state")
        assert ds.attrs["frame"].startswith("J2000 mean ecliptic and equinox")
        r_end = ds.r.values[-1]
    final = rebound.Simulation(str(out / "final.bin"))
    assert final.t == 730.5 and final.particles[1].x == r_end[1, 0]
    spin = Scene.bundled("dzhanibekov", {"duration": "10 s"}).run(progress=False)
    spin.save(tmp_path / "spin")
    with xr.open_dataset(tmp_path / "spin" / "states.nc", engine="scipy") as ds:
        assert ds.time.attrs["units"] == "s"
        np.testing.assert_array_equal(ds.time.values, spin.times.to_value(u.s))


def test_a_scene_the_run_would_refuse_exits_2_before_running(tmp_path, capsys):
    """Issue 32, class 18: a pole-prediction start after the record, a collision without
    radii: refused at load (exit 2, as any bad scene), not after a run (exit 1)."""
    code = main(["run", "pole-prediction", "--set", "start=2040-01-01", "--set", "periods=[]",
                 "--out", str(tmp_path), "--no-progress"])
    assert code == 2
    assert "start: method 'persistence': expected the start date" in capsys.readouterr().err
    path = tmp_path / "merge.toml"
    path.write_text(ESCAPE_SCENE.replace('name = "escape"\ndistance = "5 au"\n'
                                         'action = "remove"', 'name = "collision"'))
    assert main(["run", str(path), "--no-progress"]) == 2
    assert "events[0]: no pair of bodies with radii has a massive body" in capsys.readouterr().err


def test_bad_scene_and_setting(capsys):
    assert main(["run", "no-such-scene", "--no-progress"]) == 2
    assert "no-such-scene" in capsys.readouterr().err
    assert main(["run", "solar-system", "--set", "duration=2 m", "--no-progress"]) == 2
    assert "duration" in capsys.readouterr().err


def test_setting_a_body_of_initial_solar_system_says_where_it_comes_from(capsys, tmp_path):
    """``--set bodies.mercury.e=0.5`` on ``mercury-gr`` said "bodies: expected a list,
    got {'mercury': {'e': 0.5}}"."""
    assert main(["run", "mercury-gr", "--set", "bodies.mercury.e=0.5", "--out",
                 str(tmp_path / "out"), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "bodies.mercury.e: no entry named 'mercury' in bodies" in err
    assert "[initial] solar_system" in err and "initial.solar_system.epoch" in err
    assert "expected a list" not in err and not (tmp_path / "out").exists()


def _cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "hamilton_orbits.cli", *args],
                          capture_output=True, text=True, cwd=cwd, timeout=600)


def test_cli_end_to_end_in_a_subprocess(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('kind = "nbody"\nduraton = "1 yr"\n')
    res = _cli("run", str(bad), "--no-progress")
    assert res.returncode == 2
    assert "bad.toml:2: duraton: unknown key" in res.stderr  # the file, the line, the key
    assert "Traceback" not in res.stderr
    res = _cli("run", "leo-j2", "--set", "duration=0.5 d", "--out", str(tmp_path / "leo"),
               "--no-progress")
    assert res.returncode == 0, res.stderr
    assert "simulated: 0.5 d" in res.stdout
    written = sorted(p.name for p in (tmp_path / "leo").iterdir())
    assert written == ["energy_error.png", "final.bin", "orbits.png", "states.nc",
                       "summary.json", "summary.md"]
    res = _cli("crosscheck", "dzhanibekov")
    assert res.returncode == 0, res.stderr
    assert "against the exact free motion" in res.stdout


def test_crosscheck_command_on_an_nbody_scene(capsys):
    assert main(["crosscheck", "leo-j2", "--set", "duration=0.2 d"]) == 0
    out = capsys.readouterr().out
    assert "rebound ias15 + reboundx" in out and "satellite" in out


SRC = str(Path(__file__).resolve().parents[1] / "src")


def _cli(*args: str, cwd: str | None = None) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=SRC)
    return subprocess.run([sys.executable, "-m", "hamilton_orbits.cli", *args], env=env,
                          cwd=cwd, capture_output=True, text=True, timeout=600)


def test_no_progress_before_any_command(tmp_path):
    """`hamilton-orbits --no-progress` parses (it was a flag of the subcommands only),
    also before a command; after one, as before."""
    for argv in (["--no-progress", "run", "leo-j2"], ["run", "leo-j2", "--no-progress"]):
        code = main([*argv, "--out", str(tmp_path), "--set", "duration=1 h"])
        assert code == 0, argv
    res = _cli("--no-progress", "--version")
    assert res.returncode == 0, res.stderr


def test_scene_listing_keeps_words_whole(capsys):
    from hamilton_orbits.scene import Scene

    assert main(["scenes"]) == 0
    out = capsys.readouterr().out
    words = set(out.split())
    for name, description in Scene.list_bundled():
        assert set(description.split()) <= words, name  # no word cut in two


def test_scene_listing_lists_every_registered_effect_by_the_kinds_taking_it(capsys):
    """docs/effects.md: "`hamilton-orbits scenes` lists what is registered"; it listed
    the bundled scenes' effects only (gr_potential, nongrav, semi_active never
    appeared).  Every registered effect is listed with its summary's first words,
    under the scene kinds that take it (not the free rigid body's, which takes none)."""
    from hamilton_orbits.effects.registry import get, known

    assert main(["scenes"]) == 0
    out = capsys.readouterr().out
    table = out[out.index("scene kinds"):].splitlines()
    a, b = table[0].index("effect"), table[0].index("what it adds")
    for kind in ("nbody", "rotation"):
        for name in known(kind):
            row = next(line for line in table if line[a:b].strip() == name)
            assert " ".join(get(kind, name).summary.split()[:3]) in row
    table = "\n".join(table)
    assert "polar_motion " in table and "pole_prediction" not in table and "rotation" not in table


def test_quoted_run_time_is_what_the_command_takes(tmp_path):
    """The listing quoted 3-4x the measured times.  The quoted time of a quick scene
    is the whole command's, warm, within a factor 3 either way.  Measured as the
    command's CPU time (user + system, the child process's own): on the idle machine
    the command is single-threaded and its wall time is its CPU time, and a machine
    loaded by other jobs stretches the wall clock (3x seen with five jobs on the 2
    cores) but not the work."""
    import resource

    from hamilton_orbits.scene import Scene

    quoted = float(Scene.bundled("leo-j2").spec["runtime"].strip("~ s"))
    assert _cli("run", "leo-j2", "--set", "duration=1 h", cwd=str(tmp_path)).returncode == 0
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    res = _cli("run", "leo-j2", cwd=str(tmp_path))
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    measured = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    assert res.returncode == 0, res.stderr
    assert measured / 3 < quoted < 3 * measured


def test_report_without_its_extra_names_it_without_a_traceback(monkeypatch, capsys,
                                                                tmp_path):
    monkeypatch.chdir(tmp_path)  # (the default output folder is made in the current one)
    monkeypatch.setitem(sys.modules, "mpmath", None)  # as if mpmath were not installed
    assert main(["report", "--quick", "--no-progress"]) == 1
    err = capsys.readouterr().err
    assert "pip install 'hamilton-orbits[report]'" in err
    assert "Traceback" not in err


def _subcommands():
    import argparse

    parser = None

    def capture(self, *a, **k):
        nonlocal parser
        parser = self
        raise SystemExit(0)

    from unittest import mock
    with mock.patch.object(argparse.ArgumentParser, "parse_args", capture):
        try:
            main([])
        except SystemExit:
            pass
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return parser, sub


def test_every_subcommand_and_option_has_a_help_text():
    parser, sub = _subcommands()
    assert set(sub.choices) >= {"run", "crosscheck", "ensemble", "report", "resume", "scenes",
                                "demo"}
    for name, command in sub.choices.items():
        assert command.description, f"`{name} --help` says nothing of what {name} does"
        for action in command._actions:
            assert action.help, f"{name} {action.option_strings or action.dest} has no help"
    for action in parser._actions:
        assert action.help, f"{action.option_strings or action.dest} has no help"


def test_subcommand_help_describes_it(capsys):
    import pytest

    for name, words in (("scenes", "list the bundled scenes"), ("demo", "rotation tour")):
        with pytest.raises(SystemExit):
            main([name, "--help"])
        assert words in capsys.readouterr().out
    with pytest.raises(SystemExit):
        main(["crosscheck", "--help"])
    assert "override one key" in capsys.readouterr().out


def test_ensemble_without_vary_names_the_option(capsys):
    assert main(["ensemble", "dzhanibekov"]) == 2
    err = capsys.readouterr().err
    assert "--vary" in err
    assert "`vary`" not in err and "members" not in err


def test_ensemble_says_its_members_write_no_archive(tmp_path, capsys):
    """A scene with ``[output] archive_every`` run as an ensemble: its members write
    no archive, and the command says so (once), not silently."""
    args = ["ensemble", "comet-encounter", "--vary", "duration=20 d,30 d", "--vary",
            "output.archive_every=3 d", "--out", str(tmp_path), "--no-progress"]
    assert main(args) == 0
    err = capsys.readouterr().err
    assert err.count("an ensemble's members write no archive") == 1
    assert not any(p.is_dir() for p in tmp_path.iterdir())  # (ensemble.csv, ensemble.md)


def test_command_lines_that_would_lose_a_value_are_refused(capsys):
    """A key given to two --vary used to keep the last values silently, and an empty
    --out wrote into the default folder: both exit 2 before anything runs."""
    assert main(["ensemble", "leo-j2", "--vary", "duration=0.5 d", "--vary",
                 "duration=0.2 d"]) == 2
    assert "'duration' is varied twice" in capsys.readouterr().err
    # (one value twice: two members of one name, shown as one column of the table)
    assert main(["ensemble", "leo-j2", "--vary", "duration=0.5 d,0.2 d,0.5 d"]) == 2
    assert "'0.5 d' is listed twice; give each value of 'duration' once" in (
        capsys.readouterr().err)
    assert main(["run", "leo-j2", "--out", ""]) == 2
    assert "--out '': an empty path" in capsys.readouterr().err


def test_a_ctrl_c_during_the_cross_check_keeps_the_finished_run(tmp_path, monkeypatch,
                                                                capsys):
    """rebound takes Ctrl-C over while it integrates (its own KeyboardInterrupt, past
    the command line's handler): a Ctrl-C during the cross-check of a finished run
    threw the whole run away (exit 130, no file written).  The run's files are
    written, the cross-check said skipped, and the exit is 130."""
    import hamilton_orbits

    def interrupted(*args, **kw):
        raise KeyboardInterrupt

    monkeypatch.setattr(hamilton_orbits, "crosscheck", interrupted)
    out = tmp_path / "out"
    code = main(["run", "comet-encounter", "--out", str(out), "--set", "duration=5 d",
                 "--set", "cadence=1 d", "--set", "crosscheck=true", "--no-progress"])
    printed = capsys.readouterr().out
    assert code == 130 and "skipped: interrupted (Ctrl-C)" in printed
    assert (out / "states.nc").exists() and (out / "summary.md").exists()


def test_a_first_ctrl_c_while_the_kernels_compile_stops_at_once(tmp_path, monkeypatch,
                                                                capsys):
    """The first Ctrl-C asks a run to stop at its next look (after a slice of steps):
    pressed while the kernels compiled (seconds on a cold cache, 14-21 s on a busy
    machine) it waited for the compilation and the first slice.  Nothing has run
    yet: it stops at once (exit 130), saying why.  The Ctrl-C is pressed as the
    run's first kernel starts compiling (numba's own event)."""
    import signal

    import numba
    from numba.core import event

    import rigid.scene
    from rigid._kernels import euler

    rigid.scene.register()

    class Press(event.Listener):
        def on_start(self, ev):
            if not pressed:
                pressed.append(1)
                signal.getsignal(signal.SIGINT)(signal.SIGINT, None)

        def on_end(self, ev):
            pass

    pressed = []
    # (the run's stepping kernel made anew, uncached: it compiles at the first call)
    monkeypatch.setattr(euler, "run_splitting", numba.njit(euler.run_splitting.py_func))
    with event.install_listener("numba:compile", Press()):
        code = main(["run", "dzhanibekov", "--out", str(tmp_path / "out"), "--no-progress"])
    err = capsys.readouterr().err
    assert pressed and code == 130, err
    assert "stopping (the kernels were compiling: nothing run yet)" in err


def test_a_reader_that_stops_reading_loses_no_file(tmp_path):
    """``hamilton-orbits run ... | head -3``: the summary was printed before the files
    were saved, and the broken pipe (the reader gone) ended the command with none
    written (exit 1, ``BrokenPipeError``).  The files are saved first, and a reader
    gone is no error.  Here the reader is gone from the start."""
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "hamilton_orbits", "run", "leo-j2",
                             "--set", "duration=1 h", "--out", str(out), "--no-progress"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdout.close()
    err = proc.stderr.read().decode()
    proc.stderr.close()
    assert proc.wait(timeout=300) == 0, err
    assert "BrokenPipe" not in err
    assert {"summary.md", "summary.json", "states.nc", "final.bin"} <= {
        p.name for p in out.iterdir()}


def test_a_run_without_matplotlib_writes_all_but_its_figures(tmp_path, monkeypatch, capsys):
    """matplotlib is an extra (``plot``): without it a run integrated, then failed
    to save (``ModuleNotFoundError``, exit 1), leaving no states file.  The states
    and summaries are written, the figures left out with the extra named."""
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # as if it were not installed
    out = tmp_path / "out"
    assert main(["run", "dzhanibekov", "--out", str(out), "--no-progress"]) == 0
    assert sorted(p.name for p in out.iterdir()) == ["states.nc", "summary.json",
                                                      "summary.md"]
    assert ("not written: figures: matplotlib is not installed (python -m pip install "
            "'hamilton-orbits[plot]')") in capsys.readouterr().err


def test_a_cross_check_of_effects_without_reboundx_names_the_extra(monkeypatch, capsys):
    """reboundx is an extra (``crosscheck``): without it the cross-check of a scene
    with effects ended in a bare ``No module named 'reboundx'``."""
    monkeypatch.setitem(sys.modules, "reboundx", None)  # as if it were not installed
    assert main(["--no-progress", "crosscheck", "leo-j2"]) == 1
    assert "python -m pip install 'hamilton-orbits[crosscheck]'" in capsys.readouterr().err


def test_set_puts_right_a_value_the_file_gets_wrong(tmp_path, capsys):
    """The file was checked before the ``--set`` overrides were applied: a value it
    gets wrong (``duration = "10"``, no unit) was refused at its line, whatever
    ``--set duration=...`` said.  The overrides are applied first, the scene then
    checked once; without them the file's line is still named."""
    scene = tmp_path / "cont.toml"
    scene.write_text('kind = "nbody"\ndescription = "x"\nduration = "10"\ncadence = "1 d"\n'
                     '[initial]\nsolar_system = { bodies = ["sun", "jupiter"] }\n')
    assert main(["run", str(scene), "--out", str(tmp_path / "a"), "--no-progress"]) == 2
    assert "cont.toml:3: duration: expected a time" in capsys.readouterr().err
    assert main(["run", str(scene), "--out", str(tmp_path / "b"), "--no-progress",
                 "--set", 'duration="20 d"']) == 0
    assert (tmp_path / "b" / "states.nc").exists()


def test_a_run_into_a_folder_of_an_earlier_run_names_the_files_it_did_not_write(
        tmp_path, capsys):
    """A rotation scene run into the folder of an n-body one left that run's
    figures and final.bin beside its own summary, as if they were its own, without
    a word.  Nothing is removed; the files this run did not write are named."""
    out = tmp_path / "out"
    assert main(["run", "leo-j2", "--set", "duration=1 h", "--out", str(out),
                 "--no-progress"]) == 0
    capsys.readouterr()
    assert main(["run", "dzhanibekov", "--out", str(out), "--no-progress"]) == 0
    assert (f"{out}/ also holds files this run did not write (an earlier run's?): "
            f"energy_error.png, final.bin, orbits.png") in capsys.readouterr().err
    assert (out / "final.bin").exists()


def test_a_folder_or_a_device_given_as_the_scene_is_named_as_such(tmp_path, capsys):
    """``run FOLDER`` said "no bundled scene of that name", as if a name were
    misspelt; a path that exists and is no file is named as what it is (exit 2,
    nothing run)."""
    assert main(["run", str(tmp_path), "--out", str(tmp_path / "out")]) == 2
    assert "a folder, not a scene file" in capsys.readouterr().err
    assert main(["run", "/dev/null", "--out", str(tmp_path / "out")]) == 2
    assert "not a regular file, not a scene file" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()
