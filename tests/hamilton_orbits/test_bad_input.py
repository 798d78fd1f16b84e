"""Bad input, refused at its root (issue 20, deliverable 3).

Every reproducer of the issue's n-body, scene, CLI and ensemble surfaces is here,
as a named-error test (the exception type and the start of the message a user now
gets) or a no-hang test (a subprocess with a timeout).  The rigid / pole
reproducers are in ``tests/rigid/test_bad_input_rigid.py`` (not
``test_bad_input.py``: pytest imports test modules by their base name, and a
``tests/rigid/__init__.py`` would shadow the ``rigid`` package).

Conventions checked: bad input raises ``ValueError`` (or astropy's
``UnitConversionError``) naming the argument, the index and the value; a scene
raises ``SceneError`` listing its problems as ``file:LINE: key: message``; no
command prints a traceback (2: bad scene or command line, 1: a failure during
the run, in one line).
"""

from __future__ import annotations

import math
import os
import re
import subprocess
import sys
import time

import astropy.units as u
import numpy as np
import pytest
from astropy.time import Time

from hamilton_orbits import Body, Ensemble, Scene, System, crosscheck, firstrun, integrate
from hamilton_orbits._outdir import LOCK_NAME, FolderError, OutputFolder
from hamilton_orbits.effects import normalize_effects
from hamilton_orbits.scene import OUTPUT_LIMIT, SceneError
from hamilton_orbits.schema import key_lines


def floats():
    """A system of plain floats (G = 1) with an oblate planet."""
    return System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                   Body("p", 1e-3, [1, 0, 0], [0, 1, 0], radius=0.01, j2=1e-3)])


def quantities():
    """A system of Quantities with an oblate Earth."""
    return System([
        Body("earth", 398600.4418 * u.km**3 / u.s**2, [0, 0, 0] * u.km, [0, 0, 0] * u.km / u.s,
             radius=6378.1366 * u.km, j2=1.0826359e-3),
        Body("sat", 0 * u.km**3 / u.s**2, [7000, 0, 0] * u.km, [0, 7.546, 0] * u.km / u.s),
    ])


def _cli(*args, timeout=300, cwd=None, code=None):
    """The command in a subprocess (``code``: Python run before ``main`` instead)."""
    if code is None:
        cmd = [sys.executable, "-m", "hamilton_orbits.cli", *args]
    else:
        cmd = [sys.executable, "-c", code + "\nimport sys\nfrom hamilton_orbits.cli import main\n"
               f"sys.exit(main({list(args)!r}))"]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, cwd=cwd)


def _no_traceback(res):
    assert "Traceback" not in res.stderr, res.stderr
    assert res.stderr.startswith("hamilton-orbits: "), res.stderr


# ---------------------------------------------------------------- silently wrong


def test_a_plain_j2_radius_on_a_quantity_system_is_refused_not_read_as_au():
    with pytest.raises(ValueError, match=r"Effect 'j2': expected `radius` as a Quantity \(a "
                                         r"length.*got the plain number 6378.0"):
        integrate(quantities(), 1 * u.min, effects=[{"name": "j2", "body": "earth",
                                                     "radius": 6378.0}])


def test_effect_quantities_follow_one_rule_both_ways():
    """A Quantity where the system is of plain floats is refused, not dropped."""
    with pytest.raises(ValueError, match=r"Effect 'gr': expected `c` as a plain number in the "
                                         r"units of the system .*the Quantity 300000.0 km / s"):
        integrate(floats(), 1.0, effects=[{"name": "gr", "c": 3e5 * u.km / u.s}])
    with pytest.raises(ValueError, match=r"Effect 'j2': expected `radius` as a plain number"):
        integrate(floats(), 1.0, effects=[{"name": "j2", "body": "p", "radius": 1 * u.km}])
    with pytest.raises(u.UnitConversionError, match=r"Effect 'gr': Expected `c` to be a speed"):
        integrate(quantities(), 1 * u.min, effects=[{"name": "gr", "c": 3 * u.km}])


def test_an_effect_quantity_reaches_rebound_in_the_system_units():
    """reboundx takes the effect's parameters from the effect's own builder: a Quantity
    radius in the mapping is converted (it raised a TypeError before)."""
    table = crosscheck(quantities(), 10 * u.min, method="dop853", tol=1e-12,
                       effects=[{"name": "j2", "body": "earth", "radius": 6378.1366 * u.km}])
    assert table.relative_position_difference.max() < 1e-9


@pytest.mark.parametrize("epoch", ["J1000000", Time(1e6, format="jyear", scale="tdb"),
                                   "2101-01-01", "1899-06-01",
                                   # (TT, far out: ERFA's error from TT to TDB came first)
                                   Time(1e8, format="jyear"), Time(2150.0, format="jyear")])
def test_solar_system_refuses_epochs_outside_the_ephemeris_span(epoch):
    # the year 1e6 put the Earth 100 au from the Sun (ERFA's epv00 holds 1900-2100)
    with pytest.raises(ValueError, match=r"Expected `epoch` within 1900-2100 \(the span of "
                                         r"ERFA's epv00"):
        System.solar_system(epoch)


def test_solar_system_takes_epochs_inside_the_span():
    """A TT time in the span gave ERFA's "dubious year" of UTC's leap seconds (an
    error under the suite's warnings), which TT to TDB does not need."""
    for epoch in ("1900-06-01", "2099-06-01", Time(2050.0, format="jyear")):
        s = System.solar_system(epoch, bodies=["sun", "earth"])
        d = np.linalg.norm((s.r[1] - s.r[0]).to_value(u.au))
        assert 0.98 < d < 1.02


@pytest.mark.parametrize(("pole", "expected"), [
    ([1e308, 1e308, 0], [2**-0.5, 2**-0.5, 0.0]),  # stored (0, 0, 0) before: overflow
    ([1e-320, 0, 0], [1.0, 0.0, 0.0]),              # a subnormal is still a direction
    ([0, -3e-300, 4e-300], [0.0, -0.6, 0.8]),
])
def test_a_pole_is_normalised_with_scaling(pole, expected):
    body = Body("x", 1.0, [0, 0, 0], [0, 0, 0], pole=pole)
    np.testing.assert_allclose(body.pole, expected, rtol=1e-15)


def test_only_a_true_zero_pole_is_refused():
    with pytest.raises(ValueError, match=r"Body 'x': expected `pole` to be nonzero, got "
                                         r"\[0.0, 0.0, 0.0\]"):
        Body("x", 1.0, [0, 0, 0], [0, 0, 0], pole=[0, 0, 0])


def test_crosscheck_refuses_a_trajectory_of_another_system():
    s = floats()
    other = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                    Body("q", 1e-3, [1, 0, 0], [0, 1, 0])])
    moved = s.with_state(s.as_arrays().r + [[0, 0, 0], [0.1, 0, 0]], s.as_arrays().v)
    with pytest.raises(ValueError, match=r"Expected `trajectory` of the bodies \['sun', 'p'\]"):
        crosscheck(s, None, trajectory=integrate(other, 0.1, method="dop853"))
    with pytest.raises(ValueError, match=r"start from `system`'s state; body 'p' starts "
                                         r"elsewhere"):
        crosscheck(s, None, trajectory=integrate(moved, 0.1, method="dop853"))


def test_an_empty_list_of_solar_system_bodies_is_an_error():
    """Decision: ``bodies = []`` is a mistake (no bodies from the ephemeris is said by
    leaving ``solar_system`` out), never "all nine" as before."""
    with pytest.raises(ValueError, match=r"Expected `bodies` to name at least one body, got "
                                         r"an empty list \(leave it out"):
        System.solar_system(bodies=[])
    with pytest.raises(SceneError, match=r"initial.solar_system.bodies: expected `bodies` to "
                                         r"name at least one body"):
        Scene.from_dict({"kind": "nbody", "duration": "1 d",
                         "initial": {"solar_system": {"bodies": []}}})


# ---------------------------------------------------------------- lost work


def test_a_cadence_that_would_fill_memory_is_refused_at_loading():
    with pytest.raises(SceneError) as info:
        Scene.from_dict({"kind": "nbody", "duration": "1 yr", "cadence": "1e-9 d",
                         "initial": {"solar_system": {}}})
    (problem,) = info.value.problems
    assert problem.startswith("<dict>: cadence: 3.653e+11 outputs of 9 bodies would take ")
    assert "beyond the limit of 1 GiB of memory: choose a cadence of at least" in problem
    assert OUTPUT_LIMIT == 2**30


@pytest.mark.parametrize(("key", "value", "duration"), [
    ("cadence", "1e-5 d", "10 yr"), ("cadence", "1e-6 d", "3 yr"),
    ("output.archive_every", "1e-9 s", "10 yr"), ("output.archive_every", "1e-9 s", "3 yr"),
])
def test_the_shortest_interval_a_size_refusal_suggests_passes(key, value, duration):
    """The interval a size refusal suggested was rounded to nearest and its count
    left out the output (or snapshot) at the start: "choose an archive_every of at
    least 1.79e+03 s", and 1.79e+03 s was refused in its turn ("1 GiB, beyond the
    limit of 1 GiB").  The suggestion is rounded up from the count that fits, and
    passes."""
    from hamilton_orbits.cli import _load_scene

    with pytest.raises(SceneError) as info:
        _load_scene("mercury-gr", [f"duration={duration}", f"{key}={value}"])
    (problem,) = info.value.problems
    shortest = re.search(r"of at least (\S+ \S+)", problem).group(1)
    _load_scene("mercury-gr", [f"duration={duration}", f"{key}={shortest}"])
    digits = shortest.split()[0]  # (and the interval one step shorter in its 3rd digit fails)
    mantissa, _, exponent = digits.partition("e")
    lower = f"{float(mantissa) - 10.0 ** (math.floor(math.log10(float(mantissa))) - 2):.3g}"
    with pytest.raises(SceneError):
        _load_scene("mercury-gr", [f"duration={duration}",
                                   f"{key}={lower}{'e' + exponent if exponent else ''} "
                                   f"{shortest.split()[1]}"])


def test_a_cadence_that_would_fill_memory_does_not_hang_the_command(tmp_path):
    scene = tmp_path / "tiny.toml"
    scene.write_text('kind = "nbody"\nduration = "1 yr"\ncadence = "1e-9 d"\n'
                     '[initial]\nsolar_system = { epoch = "J2000" }\n')
    res = _cli("run", str(scene), "--out", str(tmp_path / "out"), "--no-progress", timeout=120)
    assert res.returncode == 2
    _no_traceback(res)
    assert f"{scene}:3: cadence: " in res.stderr
    assert not (tmp_path / "out").exists()


def test_out_naming_a_file_is_refused_before_the_run(tmp_path):
    target = tmp_path / "results.txt"
    target.write_text("not a folder")
    res = _cli("run", "leo-j2", "--out", str(target), "--no-progress")
    assert res.returncode == 2
    _no_traceback(res)
    assert f"--out {target}: is a file, not a folder; nothing was run" in res.stderr
    assert res.stdout == ""  # nothing simulated, no summary


def test_a_folder_another_live_run_writes_into_is_refused(tmp_path):
    (tmp_path / LOCK_NAME).write_text(f"{os.getpid()} {os.uname().nodename}\n")
    res = _cli("run", "leo-j2", "--out", str(tmp_path), "--no-progress")
    assert res.returncode == 2
    _no_traceback(res)
    assert f"another run (PID {os.getpid()} on " in res.stderr
    assert (tmp_path / LOCK_NAME).exists()  # the other run's lock stays


def test_the_lock_is_taken_released_and_taken_over_when_stale(tmp_path):
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True)
    lock = tmp_path / LOCK_NAME
    lock.write_text(f"{int(dead.stdout)} {os.uname().nodename}\n")  # a run that has ended
    with OutputFolder(tmp_path):
        assert lock.read_text().split()[0] == str(os.getpid())
        with pytest.raises(FolderError, match=rf"another run of this same process \(PID "
                                              rf"{os.getpid()}"), \
                OutputFolder(tmp_path):
            pass
    assert not lock.exists()
    lock.write_text("1234 elsewhere\n")  # another machine: its liveness is unknown
    with pytest.raises(FolderError, match=r"PID 1234 on elsewhere.*delete .*lock"):
        OutputFolder(tmp_path).__enter__()


def test_two_runs_that_find_one_stale_lock_at_once_do_not_both_take_it(tmp_path,
                                                                      monkeypatch):
    """Two claims (threads; each its own claim) find the lock of a run that has
    ended at once; the second judges it after the first took it over (the second
    held back 50 ms where it can be): one claim holds the folder and the other is
    refused, its lock the holder's.  (Before, the second removed the first's new
    lock as the stale one, and both held the folder.)"""
    import threading

    from hamilton_orbits import _outdir

    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True)
    lock = tmp_path / LOCK_NAME
    lock.write_text(f"{int(dead.stdout)} {os.uname().nodename}\n")
    met, order, real = threading.Barrier(2), [], _outdir._alive

    def judged_together(pid):
        try:
            met.wait(timeout=0.3)  # (reached at once where nothing holds one back)
        except threading.BrokenBarrierError:
            pass
        order.append(threading.get_ident())
        if order.index(threading.get_ident()) == 1:
            time.sleep(0.05)
        return real(pid)

    monkeypatch.setattr(_outdir, "_alive", judged_together)
    claims = [OutputFolder(tmp_path, "archive") for _ in range(2)]
    outcome = {}

    def claim(k):
        try:
            outcome[k] = claims[k].__enter__()
        except FolderError as exc:
            outcome[k] = exc

    threads = [threading.Thread(target=claim, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    held = [k for k in range(2) if isinstance(outcome[k], OutputFolder)]
    assert len(held) == 1, outcome
    refused = outcome[1 - held[0]]
    assert isinstance(refused, FolderError) and "same process" in str(refused)
    assert lock.read_text() == claims[held[0]]._mine
    claims[held[0]].__exit__(None, None, None)
    assert not lock.exists() and [p.name for p in tmp_path.iterdir()] == []


def test_a_lock_of_this_pid_that_no_claim_here_holds_is_a_former_processs(tmp_path):
    """A container restarted with the same PID and host (PID 1 of a pod, its volume
    kept) finds the lock its former process left: this PID, but no claim of this
    process holds it, so it is taken over (it was refused as "another run of this
    same process", for ever); a lock one of this process's claims holds is still
    refused."""
    lock = tmp_path / LOCK_NAME
    for text in (f"{os.getpid()} {os.uname().nodename}\n",
                 f"{os.getpid()} {os.uname().nodename} 987654\n"):
        lock.write_text(text)
        with OutputFolder(tmp_path) as folder:
            assert lock.read_text() == folder._mine
            with pytest.raises(FolderError, match=r"another run of this same process"):
                OutputFolder(tmp_path).__enter__()
        assert not lock.exists()


def test_the_lock_of_an_ended_process_not_yet_collected_is_taken_over(tmp_path):
    """A process that has ended but whose parent has not collected it (a zombie)
    still answers ``kill(pid, 0)``; its lock was refused as a live run's."""
    pid = os.fork()
    if pid == 0:
        os._exit(0)
    try:
        deadline = time.monotonic() + 5.0
        while time.monotonic() < deadline:  # (until it has ended, uncollected)
            with open(f"/proc/{pid}/stat", "rb") as fh:
                if fh.read().rsplit(b")", 1)[1].split()[0] == b"Z":
                    break
            time.sleep(0.001)
        (tmp_path / LOCK_NAME).write_text(f"{pid} {os.uname().nodename}\n")
        with OutputFolder(tmp_path) as folder:
            assert (tmp_path / LOCK_NAME).read_text() == folder._mine
    finally:
        os.waitpid(pid, 0)


@pytest.mark.parametrize("text", ["99999999999999999999 here\n", "\u00b2 here\n", "\n",
                                  "12 \n"])
def test_a_lock_whose_text_is_no_locks_is_refused_naming_the_folder(tmp_path, text):
    """A lock whose text holds no PID this host could have (too large a number, a
    superscript digit, nothing) is an unknown run's: refused naming the folder and
    the lock to delete (it raised OverflowError, or a ValueError of int())."""
    (tmp_path / LOCK_NAME).write_text(text.replace("here", os.uname().nodename))
    with pytest.raises(FolderError, match=r"another run \((an unknown run|PID 12 on \?)\) is "
                                          r"writing into this folder.*delete .*lock"):
        OutputFolder(tmp_path).__enter__()


def test_an_output_folder_that_cannot_be_created_is_refused(tmp_path):
    (tmp_path / "file").write_text("x")
    with pytest.raises(FolderError, match=r"cannot create the folder"):
        OutputFolder(tmp_path / "file" / "below").__enter__()


# ---------------------------------------------------------------- bare exceptions


@pytest.mark.parametrize("data", [None, 3, ["kind", "nbody"], "kind = 'nbody'"])
def test_scene_from_something_not_a_mapping(data):
    with pytest.raises(SceneError, match=r"<dict>: expected a mapping shaped like a scene file"):
        Scene.from_dict(data)


def test_ensemble_members_and_vary_of_the_wrong_type():
    scene = Scene.bundled("dzhanibekov")
    with pytest.raises(ValueError, match=r"Expected `members` to be a list of mappings .*got 3"):
        Ensemble(scene, members=3)
    with pytest.raises(ValueError, match=r"Expected `members` to hold mappings .*got 3 at index 1"):
        Ensemble(scene, members=[{"duration": "1 s"}, 3])
    with pytest.raises(ValueError, match=r"Expected `vary` to be a mapping"):
        Ensemble(scene, vary=["duration"])


def test_ensemble_run_refuses_an_address_for_a_client():
    ens = Ensemble(Scene.bundled("dzhanibekov"), vary={"duration": ["1 s"]})
    with pytest.raises(ValueError, match=r"Expected `client` to be a dask.distributed.Client, "
                                         r"got 'tcp://1.2.3.4:8786'; connect first"):
        ens.run(client="tcp://1.2.3.4:8786", progress=False)
    with pytest.raises(ValueError, match=r"Expected `workers` to be a number of processes >= 1"):
        ens.run(workers=0, progress=False)


def test_ensemble_refuses_a_member_that_only_the_run_used_to_refuse():
    with pytest.raises(ValueError, match=r"(?s)Member 1 .* initial.solar_system.epoch: expected "
                                         r"`epoch` to be a time"):
        Ensemble(Scene.bundled("comet-encounter"),
                 members=[{"duration": "1 d"}, {"initial.solar_system.epoch": "not a date"}])


@pytest.mark.parametrize(("params", "pattern"), [
    ({"name": "j2", "body": "p", "j2": [1e-3, 2e-3]},
     r"Effect 'j2': expected `j2` to be one number, got \[0.001, 0.002\] \(shape \(2,\)\)"),
    ({"name": "j2", "body": "p", "radius": [0.1, 0.2]},
     r"Effect 'j2': expected `radius` to be one number"),
    ({"name": "gr", "c": [1.0, 2.0]}, r"Effect 'gr': expected `c` to be one number"),
    ({"name": "j2", "body": ["p"]}, r"Effect 'j2': expected `body` to be the name of a body, "
                                    r"got \['p'\]"),
    ({"name": "j2", "body": "p", "j2": "x"}, r"Effect 'j2': Expected `j2` to be numeric, "
                                             r"got 'x'"),
    ({"name": "gr", "c": {1, 2}}, r"Effect 'gr': Expected `c` to be numeric"),
])
def test_a_list_or_a_string_as_an_effect_parameter(params, pattern):
    with pytest.raises(ValueError, match=pattern):
        integrate(floats(), 0.1, method="dop853", effects=[params])


def test_from_rebound_of_something_else():
    with pytest.raises(ValueError, match=r"Expected `sim` to be a rebound.Simulation, got 'x'"):
        System.from_rebound("x")


def test_a_binary_scene_file(tmp_path):
    path = tmp_path / "scene.toml"
    path.write_bytes(bytes(range(256)))
    with pytest.raises(SceneError, match=rf"{re.escape(str(path))}: not a scene file: not "
                                         r"text in UTF-8 \(byte 0x80 at offset 128\)"):
        Scene.from_toml(path)
    res = _cli("run", str(path), "--no-progress")
    assert res.returncode == 2
    _no_traceback(res)


@pytest.mark.parametrize(("key", "pattern"), [
    ("bodies[7].gm", r"leo-j2.toml: bodies\[7\].gm: bodies has 2 entries \(indices 0 to 1\); "
                     r"\[7\] is beyond it"),
    ("duration.x", r"leo-j2.toml: duration.x: duration is a value \('10 d'\), not a table: it "
                   r"has no key 'x'"),
    ("bodies[x].gm", r"leo-j2.toml: bodies\[x\].gm: expected a number in \[...\], got \[x\] \(a "
                     r"table in a list is addressed by its name"),
    ("integrator[0]", r"leo-j2.toml: integrator\[0\]: integrator is a table, not a list"),
    ("bodies.pluto.gm", r"leo-j2.toml: bodies.pluto.gm: no entry named 'pluto' in bodies"),
    ("a..b", r"leo-j2.toml: a..b: cannot read the key path"),
    ("analysis[3].body", r"analysis has 1 entries .*\[3\] is beyond it"),
])
def test_set_paths_that_lead_nowhere(key, pattern):
    with pytest.raises(SceneError, match=pattern):
        Scene.bundled("leo-j2").with_values({key: "1"})


def test_set_paths_that_lead_nowhere_on_the_command_line():
    res = _cli("run", "leo-j2", "--set", "bodies[7].gm=1 km3/s2", "--no-progress")
    assert res.returncode == 2
    _no_traceback(res)
    assert "bodies[7].gm: bodies has 2 entries" in res.stderr


@pytest.mark.parametrize("tol", ["1.5", "1"])
def test_a_scene_tolerance_of_one_or_more_is_refused_on_loading(tmp_path, tol):
    """A scene that loads does not fail at run time for a reason its file holds
    (docs/scenes.md): ``integrator.tol = 1.5`` loaded, then the run failed (exit 1)
    on integrate's "Expected tol in (0, 1)"."""
    with pytest.raises(SceneError, match=rf"integrator.tol: expected a number < 1.0, got "
                                         rf"{tol}"):
        Scene.bundled("leo-j2").with_values({"integrator.tol": tol})
    res = _cli("run", "leo-j2", "--set", f"integrator.tol={tol}", "--no-progress",
               "--out", str(tmp_path / "out"))
    assert res.returncode == 2
    _no_traceback(res)


def test_a_quantity_tolerance_names_tol():  # fixed in simulation.integrate by the lead
    with pytest.raises(u.UnitConversionError,
                       match=r"Expected `tol` to be dimensionless, got 1e-09 s"):
        integrate(quantities(), 1 * u.min, tol=1e-9 * u.s)


def test_a_string_tolerance_names_tol():  # was "could not convert string to float: 'x'"
    with pytest.raises(ValueError, match=r"Expected `tol` to be numeric, got 'x'"):
        integrate(floats(), 0.1, tol="x")


def test_an_array_tolerance_names_tol():
    with pytest.raises(ValueError, match=r"Expected `tol` to be one number, got shape \(2,\)"):
        integrate(floats(), 0.1, tol=[1e-9, 1e-8])


def test_an_array_step_names_dt():
    with pytest.raises(ValueError, match=r"Expected `dt` to be one number, got shape \(2,\)"):
        integrate(floats(), 0.1, method="leapfrog", dt=[0.1, 0.2])


def test_a_failure_during_a_run_is_one_line_and_exit_1(tmp_path):
    boom = ("import hamilton_orbits.engine as engine\n"
            "def advance(*args, **kwargs):\n"
            "    raise ValueError('the step underflowed\\n  at t = 1.5 d')\n"
            "engine.Propagation.advance = advance\n")
    res = _cli("run", "leo-j2", "--out", str(tmp_path), "--no-progress", code=boom)
    assert res.returncode == 1
    _no_traceback(res)
    # (the first-use notice comes before it where a kernel of the run is not yet
    # cached: this test run first, or alone, from a cold cache)
    lines = [line for line in res.stderr.splitlines() if line != firstrun.NOTICE]
    assert lines == ["hamilton-orbits: the run of leo-j2 failed: ValueError: the step "
                     "underflowed at t = 1.5 d"]
    assert not (tmp_path / LOCK_NAME).exists()  # released


# ------------------------------------------- scenes that used to fail at run time

GOOD = """\
kind = "nbody"
description = "bad input, one edit at a time"
duration = "0.2 d"
cadence = "1 h"
effects = []

[integrator]
method = "radau15"

[initial]
solar_system = { epoch = "J2000", bodies = ["sun", "earth", "moon"] }

[[bodies]]
name = "satellite"
gm = "0 km3/s2"
primary = "earth"
a = "7000 km"
e = 0.001
inc = "51.6 deg"

[[analysis]]
name = "close_approach"
body = "satellite"
other = "moon"
"""

# (case, (old, new), key, the text of the line the problem points at, regex of the message)
SCENES = [
    ("negative gm", ('gm = "0 km3/s2"', 'gm = "-1 km3/s2"'), "bodies[0].gm", "gm =",
     r"expected a value >= 0, got '-1 km3/s2'"),
    ("e = 2 with a > 0", ("e = 0.001", "e = 2"), "bodies[0].a", 'a = "7000 km"',
     r"expected a < 0 for a hyperbola \(e = 2 > 1\), got a = '7000 km'"),
    ("e < 0", ("e = 0.001", "e = -0.1"), "bodies[0].e", "e = -0.1",
     r"expected a value >= 0, got -0.1"),
    ("a = 0", ('a = "7000 km"', 'a = "0 km"'), "bodies[0].a", "a = ",
     r"expected a nonzero value, got '0 km'"),
    ("a < 0 with e < 1", ('a = "7000 km"', 'a = "-7000 km"'), "bodies[0].a", "a = ",
     r"expected a > 0 for an ellipse \(e = 0.001 < 1\)"),
    ("e = 1 with a", ("e = 0.001", "e = 1"), "bodies[0].a", "a = ",
     r"a parabola \(e = 1\) has no finite `a`: give `p` or `q`"),
    ("an empty name", ('name = "satellite"', 'name = ""'), "bodies[0].name", 'name = ""',
     r"expected a non-empty string, got ''"),
    ("a zero pole", ('inc = "51.6 deg"', 'inc = "51.6 deg"\npole = [0, 0, 0]'),
     "bodies[0].pole", "pole =", r"expected a nonzero direction, got \[0, 0, 0\]"),
    ("a duplicated effect", ("effects = []", 'effects = ["gr", "gr"]'), "effects[1]",
     "effects =", r"effect 'gr' is listed twice \(first at effects\[0\]\)"),
    ("j2 without a body", ("effects = []", 'effects = ["j2"]'), "effects[0].body", "effects =",
     r"Effect 'j2' needs the `body` whose oblateness acts"),
    ("j2 on a body without radius",
     ("effects = []", 'effects = [{ name = "j2", body = "earth" }]'), "effects[0]",
     "effects =", r"Effect 'j2': body 'earth' has no j2 and no radius"),
    ("a c without a unit", ("effects = []", 'effects = [{ name = "gr", c = 10065.3 }]'),
     "effects[0].c", "effects =", r'expected a speed \(m / s\) with its unit'),
    ("a c of another dimension", ("effects = []", 'effects = [{ name = "gr", c = "3 km" }]'),
     "effects[0].c", "effects =", r"expected a speed \(a unit convertible to m / s\)"),
    ("leapfrog without dt", ('method = "radau15"', 'method = "leapfrog"'), "integrator.dt",
     "[integrator]", r"missing: method 'leapfrog' takes a fixed step `dt`"),
    ("an unparsable epoch", ('epoch = "J2000"', 'epoch = "next tuesday"'),
     "initial.solar_system.epoch", "solar_system =",
     r"expected `epoch` to be a time .*got 'next tuesday'"),
    ("an epoch beyond the ephemeris", ('epoch = "J2000"', 'epoch = "2500-01-01"'),
     "initial.solar_system.epoch", "solar_system =", r"expected `epoch` within 1900-2100"),
    ("duplicate bodies", ('"sun", "earth", "moon"', '"sun", "earth", "moon", "earth"'),
     "initial.solar_system.bodies", "solar_system =",
     r"expected `bodies` to name each body once, got 'earth' at indices 1 and 3"),
    ("the Earth with the Earth-Moon barycentre",
     ('"sun", "earth", "moon"', '"sun", "earth", "moon", "earth-moon-barycenter"'),
     "initial.solar_system.bodies", "solar_system =",
     r"expected either 'earth-moon-barycenter' or 'earth' and 'moon'"),
    ("close_approach without other", ('other = "moon"\n', ""), "analysis[0].other",
     "[[analysis]]", r"missing: analysis 'close_approach' needs `other`"),
    ("close_approach of a body with itself", ('other = "moon"', 'other = "satellite"'),
     "analysis[0].other", "other =", r"expected a body other than `body` \('satellite'\)"),
    ("a cadence beyond memory", ('cadence = "1 h"', 'cadence = "1e-12 d"'), "cadence",
     "cadence =", r"outputs of 4 bodies would take .* beyond the limit of 1 GiB"),
]


def _line_of(text: str, marker: str) -> int:
    return next(k for k, line in enumerate(text.splitlines(), 1) if line.startswith(marker))


@pytest.mark.parametrize(("case", "edit", "key", "marker", "pattern"), SCENES,
                         ids=[c[0] for c in SCENES])
def test_scenes_fail_at_loading_with_file_line_and_key(tmp_path, case, edit, key, marker,
                                                       pattern):
    text = GOOD.replace(*edit, 1)
    assert text != GOOD
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(SceneError) as info:
        Scene.from_toml(path)
    where = f"{path}:{_line_of(text, marker)}: {key}: "
    found = [p for p in info.value.problems if p.startswith(where)]
    assert found, (where, info.value.problems)
    assert re.search(pattern, found[0]), found[0]


def test_the_good_scene_runs():
    path_free = Scene.from_dict(__import__("tomllib").loads(GOOD))
    result = path_free.run(progress=False)
    assert result.complete


def test_a_bad_scene_exits_2_naming_file_line_and_key(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(GOOD.replace('gm = "0 km3/s2"', 'gm = "-1 km3/s2"'))
    res = _cli("run", str(path), "--no-progress", "--out", str(tmp_path / "out"))
    assert res.returncode == 2
    _no_traceback(res)
    assert f"{path}:15: bodies[0].gm: expected a value >= 0, got '-1 km3/s2'" in res.stderr
    assert not (tmp_path / "out").exists()  # nothing ran, no folder


def test_gr_takes_c_as_a_quantity_string():
    scene = Scene.from_dict({
        "kind": "nbody", "duration": "10 d", "effects": [{"name": "gr", "c": "299792.458 km/s"}],
        "initial": {"solar_system": {"bodies": ["sun", "mercury"]}}})
    assert scene.effects[0]["c"] == 299792.458 * u.km / u.s
    result = scene.run(progress=False)
    assert result.complete
    assert '"c": {' in __import__("json").dumps(result._json())  # saved as value and unit


def test_a_value_set_after_loading_has_no_line(tmp_path):
    path = tmp_path / "good.toml"
    path.write_text(GOOD)
    scene = Scene.from_toml(path)
    with pytest.raises(SceneError) as info:
        scene.with_values({"bodies.satellite.gm": "-1 km3/s2"})
    assert info.value.problems == [
        f"{path}: bodies[0].gm: expected a value >= 0, got '-1 km3/s2'"]
    with pytest.raises(SceneError) as info:  # a key the override did not touch keeps its line
        scene.with_values({"bodies.satellite.e": 2})
    assert info.value.problems[0].startswith(f"{path}:17: bodies[0].a: ")


def test_key_lines_follow_strings_comments_and_inline_tables():
    text = ('kind = "nbody"  # a [comment] = 1\n'
            'description = """line [1] = 2\n{ x = 3 }\n"""\n'
            'effects = [\n  "gr",  # c = 3\n  { name = "j2", body = "earth" },\n]\n'
            "'quoted.key' = 1\n"
            "[initial.solar_system]\nepoch = 2000-01-01 12:00:00\nbodies = [[1], [2]]\n"
            "[[bodies]]\nname = 'a'\n[[bodies]]\nname = 'b'\n")
    __import__("tomllib").loads(text)  # valid TOML
    lines = key_lines(text)
    assert lines[("description",)] == 2
    assert lines[("effects",)] == 5
    assert lines[("effects", 0)] == 6
    assert lines[("effects", 1, "body")] == 7
    assert lines[("quoted.key",)] == 9
    assert lines[("initial", "solar_system", "epoch")] == 11
    assert lines[("initial", "solar_system", "bodies", 1)] == 12
    assert lines[("bodies", 1, "name")] == 16
    assert ("x",) not in lines and ("line [1]",) not in lines


# ---------------------------------------------------------------- unclear messages


def test_strings_where_numbers_go_name_the_argument():
    with pytest.raises(ValueError, match=r"Expected `G` to be numeric, got 'x'"):
        System([Body("a", 1.0, [0, 0, 0], [0, 0, 0])], G="x")
    with pytest.raises(u.UnitConversionError, match=r"Expected `G` to be dimensionless"):
        System([Body("a", 1.0, [0, 0, 0], [0, 0, 0])], G=6.674e-11 * u.m**3 / u.kg / u.s**2)
    with pytest.raises(ValueError, match=r"Body 'a': expected `j2` to be numeric, got 'x'"):
        Body("a", 1.0, [0, 0, 0], [0, 0, 0], j2="x")
    with pytest.raises(ValueError, match=r"Body 'a': expected `j2` to be one number, got "
                                         r"shape \(2,\)"):
        Body("a", 1.0, [0, 0, 0], [0, 0, 0], j2=[1e-3, 2e-3])
    with pytest.raises(ValueError, match=r"Body 'a': expected `gm` >= 0, got -1.0 km3 / s2"):
        Body("a", -1.0 * u.km**3 / u.s**2, [0, 0, 0] * u.km, [0, 0, 0] * u.km / u.s)


def test_solar_system_bodies_takes_one_name_and_refuses_what_is_not_a_name():
    assert System.solar_system(bodies="Sun").names == ("sun",)  # read "s" before
    with pytest.raises(ValueError, match=r"Expected `bodies` to hold names, got 3 at index 1"):
        System.solar_system(bodies=["sun", 3])
    with pytest.raises(ValueError, match=r"Unknown solar-system body 'pluto' at index 1 of "
                                         r"`bodies`"):
        System.solar_system(bodies=["sun", "pluto"])
    with pytest.raises(ValueError, match=r"Expected `bodies` to be a list of names, got 3"):
        System.solar_system(bodies=3)


def test_a_duplicated_effect_names_both_indices():
    with pytest.raises(ValueError, match=r"Effect 'gr' is listed twice \(at indices 0 and 2\)"):
        normalize_effects(["gr", {"name": "j2", "body": "earth"}, {"name": "gr"}])


# ---------------------------------------------------------------- Ctrl-C in one interval


@pytest.mark.parametrize(("method", "kw"), [("radau15", {}), ("wh", {"dt": 0.1}),
                                             ("leapfrog", {"dt": 0.1})])
def test_stop_is_seen_inside_one_long_output_interval(method, kw):
    """A run with a single output interval used to run to its end whatever stop()
    said: the drivers now ask between slices of steps, and the engine keeps what
    was reached (here the start alone)."""
    from hamilton_orbits import engine
    from hamilton_orbits.rhs import newtonian_rhs

    r0 = np.array([[0.0, 0, 0], [1.0, 0, 0]])
    v0 = np.array([[0.0, 0, 0], [0, 1.0, 0]])
    asked = []

    def stop() -> bool:
        asked.append(1)
        return True

    out = engine.run(r0, v0, np.array([1.0, 0.0]), np.array([0.0, 1e7]), newtonian_rhs(),
                     method, stop=stop, **kw)
    assert not out.complete and len(out.t) == 1 and asked == [1]
    assert out.steps == 0  # no output reached: the steps of the cut interval are not counted


def test_ctrl_c_in_a_one_interval_run_stops_it_promptly(tmp_path):
    """The reproducer: Ctrl-C printed "stopping" and then ran to the end.  Now the run
    ends within a slice of steps (exit 130, nothing reached beyond the start)."""
    import signal
    import time

    cmd = [sys.executable, "-m", "hamilton_orbits.cli", "run", "leo-j2", "--no-progress",
           "--set", 'duration="100000 d"', "--set", 'cadence="100000 d"',
           "--out", str(tmp_path / "out")]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    lock = tmp_path / "out" / LOCK_NAME  # taken after the imports and the scene's checks
    deadline = time.perf_counter() + 120.0
    while not lock.exists() and proc.poll() is None and time.perf_counter() < deadline:
        time.sleep(0.05)
    assert lock.exists(), proc.communicate(timeout=120)[1]
    time.sleep(1.5)  # the kernels loaded (or compiling, on a cold cache) and into the run
    start = time.perf_counter()
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert time.perf_counter() - start < 30.0, err
    assert proc.returncode == 130 and "stopping" in err, err


def _pair_with_radii():
    return System([Body("a", 1.0, [0, 0, 0], [0, 0, 0], radius=0.01),
                   Body("b", 1e-3, [1.0, 0, 0], [0, 1.0, 0], radius=0.01)])


@pytest.mark.parametrize(("kw", "pattern"), [
    (dict(t=True), r"Expected `t` to be a time or an array of times, got True"),
    (dict(t=1.0, on_output=3), r"Expected `on_output` to be callable or None, got 3"),
    (dict(t=1.0, stop="soon"), r"Expected `stop` to be callable or None, got 'soon'"),
])
def test_integrate_refuses_a_bool_time_or_a_callback_that_is_not_one(kw, pattern):
    """``t=True`` used to run to t = 1; a callback that is not callable failed with
    a bare TypeError after the first output, the run gone on to it."""
    from hamilton_orbits import Simulation

    sim = Simulation(_pair_with_radii())
    with pytest.raises(ValueError, match=pattern):
        sim.integrate(**kw)
    assert sim.t == 0.0 and sim.steps == 0


def test_a_simulation_takes_no_effects_as_none_and_refuses_events_with_variational_at_once():
    """``effects=None`` is no effect (as ``events=None``; it was a bare TypeError);
    the variational equations with events are refused when the simulation is made,
    not at its first ``integrate``."""
    from hamilton_orbits import Simulation

    assert Simulation(_pair_with_radii(), effects=None).integrate(1.0).t.tolist() == [0.0, 1.0]
    with pytest.raises(ValueError, match=r"variational equations are integrated without "
                                         r"events"):
        Simulation(_pair_with_radii(), variational=True, events=["collision"])


@pytest.mark.parametrize(("events", "pattern"), [
    (["collision", {"name": "collision", "action": "merge"}],
     r"Event at index 1 \('collision'\) watches a-b as the event at index 0 does"),
    ([{"name": "escape", "distance": 5.0}, {"name": "escape", "distance": 5.0}],
     r"Event at index 1 \('escape'\) watches b as the event at index 0 does"),
])
def test_an_event_of_a_body_or_pair_listed_twice_is_refused(events, pattern):
    """Duplicate effects were refused, duplicate events taken: a pair's collision
    recorded as a stop and a merge, every escape recorded twice.  Two thresholds of
    one close encounter stay allowed."""
    from hamilton_orbits import Simulation

    with pytest.raises(ValueError, match=pattern):
        Simulation(_pair_with_radii(), events=events)
    Simulation(_pair_with_radii(), events=[{"name": "close_encounter", "distance": 0.5},
                                           {"name": "close_encounter", "distance": 0.3}])


@pytest.mark.parametrize(("what", "args"), [
    ("quaternion", (["1", "0", "0", "0"],)),
    ("state", (["1", "0", "0"], [0.0, 1.0, 0.0], 1.0)),
    ("state", ([1.0, 0.0, 0.0], [False, True, False], 1.0)),
])
def test_numeric_strings_and_bools_are_not_numbers(what, args):
    """``as_float_array`` converted ``"1"`` and ``True`` silently (NumPy does)."""
    from hamilton_orbits import KeplerOrbit, Quaternion

    make = Quaternion if what == "quaternion" else KeplerOrbit.from_state
    with pytest.raises(ValueError, match=r"to be numeric, got"):
        make(*args)


def test_a_list_holding_quantities_or_bools_is_refused_naming_the_index():
    """A list of Quantities (``[0, 0, 360 * u.deg / u.s]``) raised numpy's bare
    ``TypeError: only dimensionless scalar quantities can be converted``; a bool in
    a list of floats was read as 1.0 (``e=[0.1, True]``: a radial orbit), where a
    bool alone is refused.  Both are refused naming the argument and the index."""
    from hamilton_orbits import KeplerOrbit
    from rigid import RigidBody

    with pytest.raises(ValueError, match=r"Expected `omega` to be plain numbers or one "
                                          r"Quantity array, got the Quantity 360.0 deg / s at "
                                          r"index 2 in a list \(u.Quantity"):
        RigidBody([1.0, 2.0, 3.0], omega=[0.0, 0.0, 360 * u.deg / u.s])
    with pytest.raises(ValueError, match=r"`r` to be plain numbers .* at index \(1, 0\)"):
        Body("b", 0.0, [[1.0], [2.0 * u.au]], [0, 1, 0])  # (nested: the index in each)
    with pytest.raises(ValueError, match=r"Expected `e` to be numeric, got True at index 1"):
        KeplerOrbit.from_elements(a=1.0, e=[0.1, True], inc=0.0, lan=0.0, argp=0.0, nu=0.0,
                                  mu=1.0)
    with pytest.raises(ValueError, match=r"Expected `omega` to be numeric, got True at index 2"):
        RigidBody([1.0, 2.0, 3.0], omega=[0.0, 0.0, True])
    assert RigidBody([1.0, 2.0, 3.0], omega=(0.0, 1, 2.5)).omega.tolist() == [0.0, 1.0, 2.5]
    # None in a list or an object array was read as nan ("got nan at index 1")
    from hamilton_orbits import solve_kepler

    with pytest.raises(ValueError, match=r"Expected `M` to be numeric, got None at index 1"):
        solve_kepler(np.array([1.0, None]), 0.5)
    with pytest.raises(ValueError, match=r"`e` to be numeric, got None at index \(0, 1\)"):
        solve_kepler(1.0, [[0.1, None]])


def test_a_ragged_list_is_refused_naming_the_argument_and_index():
    """A ragged ``r`` raised numpy's "setting an array element with a sequence",
    naming nothing."""
    from hamilton_orbits import KeplerOrbit, solve_kepler

    with pytest.raises(ValueError, match=r"^Expected `r` to be a regular array \(rows of one "
                                          r"length\), got \[1.0, 0\] at index 1, which has 2 "
                                          r"entries, where index 0 has 3 entries$"):
        KeplerOrbit.from_state([[1.0, 0, 0], [1.0, 0]], [0, 1.0, 0], 1.0)
    with pytest.raises(ValueError, match=r"`M` .*got 2.0 at index 1, which is a number, "
                                          r"where index 0 has 1 entry$"):
        solve_kepler([[1.0], 2.0], 0.5)
    with pytest.raises(ValueError, match=r"`v` .*got \[0.0\] at index \(0, 1\), which has 1 "
                                          r"entry, where index \(0, 0\) has 2 entries$"):
        KeplerOrbit.from_state([1.0, 0, 0], [[[0.0, 1.0], [0.0]]], 1.0)


@pytest.mark.parametrize("bodies", [5, Body("a", 1.0, [0, 0, 0], [0, 0, 0])])
def test_a_system_of_something_not_a_list_of_bodies_is_refused(bodies):
    """``System(5)`` raised ``TypeError: 'int' object is not iterable``."""
    with pytest.raises(ValueError, match=r"Expected `bodies` to be a list of Body objects"):
        System(bodies)


def test_every_wall_as_a_time_quantity_or_a_numpy_number_is_taken(tmp_path):
    """``every_wall`` (wall-clock seconds) given as ``np.float32(1.0)`` or ``2 * u.s``
    was refused as "Expected `every_wall` > 0 and finite", which it was; a time
    Quantity is converted to seconds, a NumPy number taken as a float, and a
    length refused by name."""
    from hamilton_orbits import Simulation

    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("p", 1e-5, [1, 0, 0], [0, 1, 0])])
    for k, (given, seconds) in enumerate([(np.float32(1.5), 1.5), (2 * u.s, 2.0),
                                          (0.5 * u.min, 30.0), (np.int64(3), 3.0)]):
        sim = Simulation(s, archive=tmp_path / str(k), every_wall=given)
        assert sim._archive.every_wall == seconds and type(sim._archive.every_wall) is float
    with pytest.raises(u.UnitConversionError, match=r"Expected `every_wall` to be a time"):
        Simulation(s, archive=tmp_path / "m", every_wall=1 * u.m)


@pytest.mark.parametrize(("kw", "pattern"), [
    (dict(a=[1, 2, -3] * u.au, e=0.1, inc=10 * u.deg),
     r"Expected `a` > 0 for e < 1 \(a and e inconsistent\), got -3.0 AU at index 2"),
    (dict(a=1 * u.au, e=0.1, inc=[10, 190] * u.deg),
     r"Expected `inc` in \[0, pi\] rad, got 190.0 deg at index 1"),
    (dict(q=-1 * u.au, e=0.1, inc=10 * u.deg), r"Expected `q` > 0, got -1.0 AU$"),
    (dict(q=1 * u.au, e=0.1, inc=10 * u.deg, mu=[1.0, -2.0] * u.au**3 / u.day**2),
     r"Expected `mu` > 0, got -2.0 AU3 / d2 at index 1"),
])
def test_element_errors_quote_the_value_as_written(kw, pattern):
    """The values were quoted in the internal units without a unit ("got
    -448793612.09999996 at index 2" for -3 au; 3.3161255787892263 for 190 deg; a
    `mu` in au^3/day^2 in km^3/s^2)."""
    from hamilton_orbits import KeplerOrbit

    kw = {"mu": 1.32712440018e11 * u.km**3 / u.s**2, **kw}
    with pytest.raises(ValueError, match=pattern):
        KeplerOrbit.from_elements(**kw, lan=0 * u.deg, argp=0 * u.deg, M=0 * u.deg)


def test_a_crosscheck_of_a_trajectory_of_other_effects_or_end_is_refused():
    """``crosscheck(system, t, trajectory=traj)`` of a gr trajectory, effects not
    repeated, compared it with Newton's law in rebound (a "disagreement" of 1e-4
    for 1e-10), and a trajectory ending at 50 yr checked "to 100 yr" ran to 50."""
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("p", 1e-3, [1.0, 0, 0], [0, 1.0, 0])])
    gr = [{"name": "gr", "c": 1e4}]
    traj = integrate(s, 2.0, method="dop853", effects=gr)
    with pytest.raises(ValueError, match=r"Expected `effects` to be those of `trajectory` "
                                         r"\(\[\{'name': 'gr', 'c': 10000.0\}\]\), got \[\]: "
                                         r"rebound would integrate"):
        crosscheck(s, 2.0, trajectory=traj)
    with pytest.raises(ValueError, match=r"Expected `t` to be the end of `trajectory` "
                                         r"\(2.0\), got 4.0"):
        crosscheck(s, 4.0, effects=gr, trajectory=traj)
    assert crosscheck(s, 2.0, effects=gr, trajectory=traj).relative_position_difference.max() \
        < 1e-9


def test_a_crosscheck_of_a_trajectory_of_other_effect_parameters_is_refused():
    """A trajectory of gr at c = 100 checked with gr at c = 10 was taken: a relative
    difference of 1.6 reported as a disagreement.  The parameters are compared where
    the trajectory holds them (``Trajectory.effect_set``); the order of the list
    does not matter."""
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("p", 1e-3, [1.0, 0, 0], [0, 1.0, 0])])
    traj = integrate(s, 2.0, method="dop853", effects=[{"name": "gr", "c": 100.0}])
    assert traj.effect_set.as_list() == [{"name": "gr", "c": 100.0}]
    with pytest.raises(ValueError, match=r"Expected `effects` to be those of `trajectory` "
                                         r"\(\[\{'name': 'gr', 'c': 100.0\}\]\), got "
                                         r"\[\{'name': 'gr', 'c': 10.0\}\]"):
        crosscheck(s, 2.0, effects=[{"name": "gr", "c": 10.0}], trajectory=traj)


def test_a_crosscheck_compares_the_physics_of_the_effects_not_how_they_were_written():
    """The trajectory's effects were compared with the ones given as a set of their
    items: parameters that are lists (``zonal``'s ``j``, ``eih``'s ``sources``) raised
    ``TypeError: unhashable type: 'list'``, and ``c`` given as its default value
    (299792.458 km/s) was refused as "other physics" beside ``gr`` with no ``c``.
    They are compared as the parameter vectors the run integrates (to 8 eps); an
    effect reboundx has no counterpart for is refused by name first."""
    s = System.from_ephemeris(bodies=["sun", "mercury"])
    traj = integrate(s, 10 * u.d, effects=[{"name": "gr", "c": 299792.458 * u.km / u.s}])
    assert crosscheck(s, 10 * u.d, trajectory=traj, effects=["gr"]) is not None
    with pytest.raises(ValueError, match=r"Expected `effects` to be those of `trajectory`"):
        crosscheck(s, 10 * u.d, trajectory=traj,
                   effects=[{"name": "gr", "c": 299792.0 * u.km / u.s}])
    three = System.from_ephemeris(bodies=["sun", "earth", "moon"])
    with pytest.raises(ValueError, match=r"Effect 'zonal' has no reboundx counterpart"):
        crosscheck(three, 1 * u.d, effects=[{"name": "zonal", "j": [1.08e-3]}])


def test_a_size_refusal_where_no_interval_fits_says_so():
    """Where one snapshot (or the start's and end's outputs) already exceeds half the
    limit, the shortest interval that fits is none: the suggestion divided by a
    count of 0 or less raised OverflowError (600 000 bodies) or "math domain error"
    (2 000 000).  It says no interval fits."""
    from hamilton_orbits import schema as S
    from hamilton_orbits.scenes.base import check_archive_size, check_output_size

    for bodies in (600_000, 2_000_000):
        problems = S.Problems("x")
        check_archive_size({"duration": 10 * u.yr, "output": {"archive_every": 1 * u.yr}},
                           problems, bodies)
        assert "no archive_every fits; leave it out" in problems.items[0]
    problems = S.Problems("x")
    check_output_size({"duration": 10 * u.yr, "cadence": 1 * u.yr}, problems, 6 * 30_000_000,
                      "30e6 bodies")
    assert "the start and the end alone 2.68 GiB: fewer bodies" in problems.items[0]


def test_a_crosscheck_rebound_cannot_run_is_refused_before_our_run(monkeypatch):
    """``crosscheck(system, t, effects=["eih"])`` integrated the whole run, then
    refused the effect; it is refused first (now ``eih`` is cross-checked against
    reboundx's ``gr_full``: an ``eih`` it cannot run, of PPN beta 2)."""
    from hamilton_orbits import simulation

    def never(*args, **kwargs):
        raise AssertionError("integrated before the refusal")

    monkeypatch.setattr(simulation, "integrate", never)
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("p", 1e-3, [1.0, 0, 0], [0, 1.0, 0])])
    with pytest.raises(ValueError, match=r"Effect 'eih': reboundx's gr_full is general "
                                         r"relativity .* leave `beta` at 1, got 2.0"):
        crosscheck(s, 1.0, effects=[{"name": "eih", "c": 1e4, "beta": 2.0}])


def test_small_refusals_name_the_argument():
    """``Scene.bundled(None)`` raised a TypeError from inside difflib;
    ``System.from_rebound(sim, names="xyz")`` took the string as the names 'x', 'y',
    'z'; ``covariance.propagate`` with an ``stm`` of the wrong shape or a list said
    "cannot reshape array of size 108" or "'list' object has no attribute 'shape'"."""
    from hamilton_orbits import Scene
    from hamilton_orbits.covariance import propagate
    from hamilton_orbits.scene import SceneError

    with pytest.raises(SceneError, match=r"expected a bundled scene's name \(a string\)"):
        Scene.bundled(None)
    s = System([Body("a", 1.0, [0, 0, 0], [0, 0, 0]), Body("b", 1e-3, [1, 0, 0], [0, 1, 0]),
                Body("c", 0.0, [2, 0, 0], [0, 0.7, 0])])
    with pytest.raises(ValueError, match=r"Expected `names` to be a list of 3 names, got the "
                                         r"string 'xyz'"):
        System.from_rebound(s.to_rebound(), names="xyz")
    with pytest.raises(ValueError, match=r"Expected `stm` of shape \(n_t, 12, 12\) for n = 2 "
                                         r"bodies, got \(12, 12\)"):
        propagate(np.eye(12), np.eye(6), 2)
    with pytest.raises(ValueError, match=r"Expected `stm` of shape \(n_t, 12, 12\) .*got \(1, 3\)"):
        propagate([[1.0, 2.0, 3.0]], np.eye(6), 2)
    with pytest.raises(ValueError, match=r"Expected `n` to be a number of bodies >= 1, got 2.5"):
        propagate(np.stack([np.eye(12)] * 3), np.eye(6), 2.5)
    assert propagate(np.stack([np.eye(12)] * 3), np.eye(6), 2).shape == (3, 2, 6, 6)
