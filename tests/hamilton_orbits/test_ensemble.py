"""Ensembles: a grid of scene variations, locally and on Dask, with failures kept."""

from __future__ import annotations

import math
import sys

import pytest

from hamilton_orbits import Ensemble, Scene
from hamilton_orbits.cli import _split_values, main

pd = pytest.importorskip("pandas")


def comet() -> Scene:
    return Scene.bundled("comet-encounter").with_values(
        {"duration": "0.05 yr", "cadence": "1 d", "crosscheck": False})


def numeric(df):
    return df.drop(columns=["wall time [s]"]).to_dict("records")


def same_rows(a, b):
    assert len(a) == len(b)
    for ra, rb in zip(a, b, strict=True):
        assert ra.keys() == rb.keys()
        for k in ra:
            x, y = ra[k], rb[k]
            if isinstance(x, float) and math.isnan(x):
                assert isinstance(y, float) and math.isnan(y)
            else:
                assert x == y, (k, x, y)  # bit for bit


def test_grid_local_and_on_an_in_process_dask_cluster_agree_bit_for_bit():
    distributed = pytest.importorskip("dask.distributed")
    ens = Ensemble(comet(), vary={"integrator.tol": [1e-9, 1e-6]})
    local = ens.run(progress=False)
    assert list(local["integrator.tol"]) == [1e-9, 1e-6]
    assert local.attrs["failures"] == 0
    assert (local["steps"] > 0).all()
    # a looser tolerance takes fewer steps
    assert local["steps"][1] < local["steps"][0]
    with distributed.LocalCluster(processes=False, n_workers=1, threads_per_worker=1,
                                  dashboard_address=":0") as cluster, \
            distributed.Client(cluster) as client:
        remote = ens.run(client=client, progress=False)
    same_rows(numeric(local), numeric(remote))


def test_a_failing_member_leaves_the_others():
    ens = Ensemble(comet(), members=[{"integrator.tol": 1e-9}, {"integrator.tol": 1e-9},
                                     {"integrator.tol": 1e-8}])
    # a bad epoch is refused when the ensemble is built (issue 20): put it in afterwards,
    # to stand for a member that fails in its worker
    ens.members[1] = {"initial.solar_system.epoch": "not a date"}
    df = ens.run(progress=False, workers=1)
    assert df.attrs["failures"] == 1
    assert df["error"].isna().tolist() == [True, False, True]
    assert "not a date" in df["error"][1]
    # (None for the members that ran, as documented: pandas made it a string column's
    # NaN; the flags True and False, not True and NaN)
    assert df["error"][0] is None and df["error"][2] is None
    assert df["complete"].tolist() == [True, False, True] and df["complete"].dtype == bool
    assert df["steps"][0] > 0 and df["steps"][2] > 0
    # a count stays an integer where a member failed (it became 2274.0 in the CSV)
    assert str(df["steps"].dtype) == "Int64" and df["steps"].isna().tolist() == [
        False, True, False]
    assert df.to_csv(index=False).splitlines()[1].split(",")[
        list(df.columns).index("steps")] == str(df["steps"][0])


def test_members_with_under_resolved_approaches_are_warned_of_once():
    """Every member whose fixed step was too long for a close approach warned on its
    own (a stability map of 64 cells warned 4 times, each a paragraph, from the
    workers): the members' warnings are counted in their rows, and the ensemble
    warns once, with how many members."""
    from hamilton_orbits.integrals import UnderResolvedEncounterWarning

    leapfrog = {"integrator.method": "leapfrog", "integrator.dt": "1 d"}
    ens = Ensemble(comet(), members=[leapfrog, {"integrator.method": "radau15"}, leapfrog])
    with pytest.warns(UnderResolvedEncounterWarning) as caught:
        df = ens.run(progress=False, workers=1)
    assert len(caught) == 1
    assert str(caught[0].message).startswith("2 of 3 members crossed close approaches")
    assert list(df["under-resolved encounters"].fillna(0)) == [1, 0, 1]


def test_invalid_members_are_refused_before_anything_runs():
    with pytest.raises(ValueError, match=r"Member 1 .*integrator.dt"):
        Ensemble(Scene.bundled("dzhanibekov"), vary={"integrator.dt": ["1 ms", "bogus"]})
    with pytest.raises(ValueError, match=r"vary\['duration'\]"):
        Ensemble(Scene.bundled("dzhanibekov"), vary={"duration": []})
    with pytest.raises(ValueError, match=r"`scene`"):
        Ensemble("dzhanibekov", vary={"duration": ["1 s"]})


def test_vary_values_split_outside_brackets():
    assert _split_values('1e-8, 1e-10') == ["1e-8", "1e-10"]
    assert _split_values('["1 rad/s", "2 rad/s"],["3 rad/s", "4 rad/s"]') == [
        '["1 rad/s", "2 rad/s"]', '["3 rad/s", "4 rad/s"]']
    # (a TOML inline table was cut at its inner comma, as `run --set` takes it whole)
    assert _split_values('{method = "wh", dt = "120 d"},{method = "radau15"}') == [
        '{method = "wh", dt = "120 d"}', '{method = "radau15"}']


def test_ensemble_command(tmp_path, capsys):
    code = main(["ensemble", "dzhanibekov", "--vary", "duration=40 s,60 s", "--out",
                 str(tmp_path), "--no-progress"])
    assert code == 0
    df = pd.read_csv(tmp_path / "ensemble.csv")
    assert list(df["duration"]) == ["40 s", "60 s"]
    exact = df["exact flip interval 2K(m)/lambda [s]"]
    assert (abs(df["simulated flip interval [s]"] / exact - 1) < 1e-8).all()
    assert main(["ensemble", "dzhanibekov", "--vary", "duration"]) == 2


def test_the_dask_local_cluster_of_the_command_is_closed(monkeypatch, tmp_path):
    """``--dask local`` closed its client, not the cluster made for it: called
    in-process (a notebook, a script), each call left the cluster's workers behind
    (2 processes, 420 MB, 7 threads, 32 descriptors a call).  (The cluster here is
    an in-process one: the closing, not the processes.)"""
    distributed = pytest.importorskip("dask.distributed")
    made = []

    class Cluster(distributed.LocalCluster):
        def __init__(self):
            super().__init__(processes=False, n_workers=1, threads_per_worker=1,
                             dashboard_address=":0")
            made.append(self)

    monkeypatch.setattr(distributed, "LocalCluster", Cluster)
    code = main(["ensemble", "dzhanibekov", "--vary", "duration=40 s", "--dask", "local",
                 "--out", str(tmp_path), "--no-progress"])
    assert code == 0 and len(made) == 1 and made[0].status.name == "closed"


def test_dask_option_without_dask_names_the_extra(monkeypatch, capsys, tmp_path):
    """Dask is an extra: without it `--dask` says which one to install (None in
    sys.modules makes the import fail as if the package were absent).  (Run in the
    test's own folder: the default output folder is made in the current one.)"""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setitem(sys.modules, "dask.distributed", None)
    code = main(["ensemble", "dzhanibekov", "--vary", "duration=40 s", "--dask", "local",
                 "--no-progress"])
    assert code != 0
    assert "pip install 'hamilton-orbits[dask]'" in capsys.readouterr().err


def test_ensemble_command_table_fits_a_terminal(tmp_path, capsys):
    """The table was 330 characters wide with an `error None` column: now one column
    per member, what every member shares said once, no error column unless one
    failed."""
    code = main(["ensemble", "dzhanibekov", "--vary", "integrator.dt=1 ms,2 ms,4 ms",
                 "--out", str(tmp_path), "--no-progress"])
    assert code == 0
    out = capsys.readouterr().out
    table = out.split("failed\n", 1)[1].split("\nwrote", 1)[0]
    assert max(len(line) for line in table.splitlines()) <= 100
    assert "None" not in table and "error" not in table.split("\n", 1)[0]
    assert "the same for every member:\n  exact flip interval" in table
    # the simulated interval differs (by 1e-9 of it) from member to member: it was said
    # the same for every member, its 4 digits being so, beside a row "relative
    # difference" that varied and named no quantity
    shared = table.split("the same for every member:", 1)[1]
    assert "simulated flip interval" not in shared
    assert "\nsimulated/exact flip interval - 1 " in table


def test_a_ctrl_c_ends_a_serial_ensemble(monkeypatch):
    """A member run in this process keeps what it reached on Ctrl-C (as a scene's run
    does): a serial ensemble then took the cut member as a row (``complete`` False,
    its metrics from part of the run, no error) and ran the next ones.  The Ctrl-C
    ends the ensemble, as it does a pool of workers."""
    import signal

    from hamilton_orbits._kernels import radau15 as kernels

    calls = []

    def wrapped(real):
        def kernel(*args):
            out = real(*args)
            calls.append(1)
            if len(calls) == 3:  # (in the first member: Python's handler, as CPython runs
                signal.getsignal(signal.SIGINT)(signal.SIGINT, None)  # it after the call)
            return out
        return kernel

    ens = Ensemble(comet(), members=[{"integrator.tol": 1e-9}] * 3)
    for name in ("advance", "advance_watched"):
        monkeypatch.setattr(kernels, name, wrapped(getattr(kernels, name)))
    with pytest.raises(KeyboardInterrupt):
        ens.run(progress=False, workers=1)
    assert len(calls) == 3  # (no member after it ran)


def test_a_ctrl_c_cancels_the_members_a_pool_has_not_begun(monkeypatch):
    """A Ctrl-C in a pool's ensemble left its other members queued: the workers ran
    them all for nothing, and the next ensemble waited behind them."""
    import concurrent.futures
    import threading

    from hamilton_orbits import ensemble

    ran, lock = [], threading.Lock()

    def member(data, source, values):
        with lock:
            ran.append(values)
        if len(ran) == 1:
            raise KeyboardInterrupt  # (as the first member's worker sees the Ctrl-C)
        return {"error": None, "complete": True}

    pool = concurrent.futures.ThreadPoolExecutor(max_workers=1)
    monkeypatch.setattr(ensemble, "run_member", member)
    monkeypatch.setattr(ensemble, "_pool", lambda n: pool)
    ens = Ensemble(comet(), members=[{"integrator.tol": 1e-9}] * 10)
    with pytest.raises(KeyboardInterrupt):
        ens.run(progress=False, workers=2)
    pool.shutdown(wait=True)
    assert len(ran) <= 2  # (the first, and at most the one the worker had taken)


def test_a_local_ensemble_without_pandas_names_its_own_extra(monkeypatch, tmp_path, capsys):
    """Ensemble tables need pandas, which only the Dask extra brought: the message
    sent a user who runs on this machine to install Dask.  pandas is the
    ``ensemble`` extra's."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setitem(sys.modules, "pandas", None)  # as if it were not installed
    code = main(["ensemble", "dzhanibekov", "--vary", "duration=40 s", "--no-progress"])
    assert code != 0
    assert "pip install 'hamilton-orbits[ensemble]'" in capsys.readouterr().err


def test_a_pool_that_lost_a_worker_is_replaced_and_one_pool_is_kept(monkeypatch):
    """A kept pool one of whose workers was killed (the out-of-memory killer) made
    every later ensemble of as many workers fail with BrokenProcessPool until Python
    restarted; pools of 2, 3 and 4 workers were all kept (11 processes, 1.9 GB).
    A pool broken before any member ended is replaced and the run begun again on
    the new one; one that breaks later fails that run, saying so, and the next
    starts a new one; a new count shuts the other pool down.  (The
    pools here are of threads, the members stand-ins: the logic, not the spawn.)"""
    import concurrent.futures
    from concurrent.futures.process import BrokenProcessPool

    from hamilton_orbits import ensemble

    made, broken = [], set()

    class Pool(concurrent.futures.ThreadPoolExecutor):
        def __init__(self, max_workers, mp_context=None):
            super().__init__(max_workers=max_workers)
            made.append(self)

        def submit(self, fn, *args):
            if self in broken:
                raise BrokenProcessPool("A process in the process pool was terminated")
            return super().submit(fn, *args)

    late = []

    def member(data, source, values):
        if values.get("integrator.tol") == 1e-8 and not late:  # (a worker killed while
            late.append(1)  # idle, seen by the pool only as the run's members fail)
            raise BrokenProcessPool("A process in the process pool was terminated")
        if values.get("integrator.tol") == 1e-7:  # (this member's worker is killed)
            broken.add(made[-1])
            raise BrokenProcessPool("A process in the process pool was terminated")
        return {"error": None, "complete": True}

    monkeypatch.setattr(concurrent.futures, "ProcessPoolExecutor", Pool)
    monkeypatch.setattr(ensemble, "run_member", member)
    monkeypatch.setattr(ensemble, "_POOLS", {})
    ens = Ensemble(comet(), members=[{"integrator.tol": 1e-9}] * 3)
    assert len(ens.run(progress=False, workers=2)) == 3 and len(made) == 1
    broken.add(made[0])  # (a worker killed while the pool waited)
    assert len(ens.run(progress=False, workers=2)) == 3 and len(made) == 2
    assert list(ensemble._POOLS) == [2] and ensemble._POOLS[2] is made[1]
    dying = Ensemble(comet(), members=[{"integrator.tol": 1e-9}, {"integrator.tol": 1e-7}])
    with pytest.raises(BrokenProcessPool, match=r"a worker process of the ensemble's pool "
                                                 r"of 2 ended abruptly .* the next run starts "
                                                 r"a new pool"):
        dying.run(progress=False, workers=2)
    assert ensemble._POOLS == {}
    assert len(ens.run(progress=False, workers=2)) == 3 and ensemble._POOLS[2] is made[-1]
    two = made[-1]
    again = Ensemble(comet(), members=[{"integrator.tol": 1e-8}])  # (one: no row before)
    assert len(again.run(progress=False, workers=2)) == 1 and late == [1]  # (begun again)
    assert ensemble._POOLS[2] is made[-1] and made[-1] is not two
    two = made[-1]
    assert len(ens.run(progress=False, workers=3)) == 3 and list(ensemble._POOLS) == [3]
    assert two._shutdown  # (the pool of 2 shut down: one pool's processes at a time)
    for pool in made:
        pool.shutdown(wait=True)



def test_runs_at_once_keep_their_pools_and_a_new_pool_broken_is_not_run_again(monkeypatch):
    """A run needing a pool of another size shut the kept one down while another
    thread's ensemble ran on it: that run's queued members were cancelled unseen and
    it waited for ever.  A pool in use is kept.  And a pool this run made and its own
    members broke (its worker killed: out of memory) ran the whole ensemble again,
    for the same failure; only a pool kept from before is replaced and run again."""
    import concurrent.futures
    import threading
    import time
    from concurrent.futures.process import BrokenProcessPool

    from hamilton_orbits import ensemble

    class Pool(concurrent.futures.ThreadPoolExecutor):
        def __init__(self, max_workers, mp_context=None):
            super().__init__(max_workers=max_workers)

    calls = []

    def member(data, source, values):
        calls.append(values.get("integrator.tol"))
        if values.get("integrator.tol") == 1e-7:
            raise BrokenProcessPool("A process in the process pool was terminated")
        time.sleep(0.05 if values.get("integrator.tol") == 1e-9 else 0.0)
        return {"error": None, "complete": True}

    monkeypatch.setattr(concurrent.futures, "ProcessPoolExecutor", Pool)
    monkeypatch.setattr(ensemble, "run_member", member)
    monkeypatch.setattr(ensemble, "_POOLS", {})
    monkeypatch.setattr(ensemble, "_IN_USE", {})
    slow = Ensemble(comet(), members=[{"integrator.tol": 1e-9}] * 12)
    done = []
    first = threading.Thread(target=lambda: done.append(len(slow.run(progress=False,
                                                                      workers=2))))
    first.start()
    time.sleep(0.1)  # (the first run is on its pool of 2)
    quick = Ensemble(comet(), members=[{"integrator.tol": 1e-8}] * 3)
    assert len(quick.run(progress=False, workers=3)) == 3
    first.join(timeout=20)
    assert not first.is_alive() and done == [12]
    calls.clear()
    ensemble._drop(2)
    with pytest.raises(BrokenProcessPool, match="ended abruptly"):
        Ensemble(comet(), members=[{"integrator.tol": 1e-7}]).run(progress=False, workers=2)
    assert calls == [1e-7]  # (once: the pool was this run's own)
    for n in list(ensemble._POOLS):
        ensemble._drop(n)


def test_a_member_stopped_at_its_start_by_a_collision_keeps_its_row_and_the_others():
    """A member starting inside the Earth (a collision, "stop", at t = 0) ended with
    one row, which the scene took for a Ctrl-C before the first output: the whole
    ensemble was interrupted (exit 130; on an in-process Dask client it hung).  Its
    row says the collision, and the others are kept."""
    from hamilton_orbits.ensemble import run_member

    scene = Scene.bundled("leo-j2").with_values({
        "duration": "0.5 d", "cadence": "30 min", "bodies.satellite.radius": "1 km",
        "events": [{"name": "collision", "bodies": ["earth", "satellite"], "action": "stop"}]})
    row = run_member(scene.data, scene.source, {"bodies.satellite.a": "6000 km"})
    assert row["error"] is None and row["first collision bodies"] == "earth-satellite"
    assert row["first collision at [yr]"] == 0.0
    table = Ensemble(scene, vary={"bodies.satellite.a": ["7000 km", "6000 km"]}).run(
        workers=1, progress=False)
    assert list(table["complete"]) == [True, True] and table["error"].isna().all()
    assert table["events found"].tolist() == [0, 1]


def test_members_in_threads_leave_the_warning_filters_as_they_were(monkeypatch):
    """Each member silenced the warning with ``warnings.catch_warnings``, which saves
    and restores the process's filters: two members overlapping in threads (Dask's)
    restored each other's, and the warning was ignored for good after the ensemble
    (its own summary, and every later run of the session).  Held here so that they
    overlap that way every time: A begins, B begins, A ends, B ends."""
    import threading
    import warnings

    from hamilton_orbits.ensemble import run_member
    from hamilton_orbits.integrals import UnderResolvedEncounterWarning

    real_run = Scene.run
    entered = {"A": threading.Event(), "B": threading.Event()}
    release = {"A": threading.Event(), "B": threading.Event()}
    rows = {}

    def held(self, *args, **kwargs):
        name = threading.current_thread().name
        entered[name].set()
        release[name].wait(60)
        return real_run(self, *args, **kwargs)

    monkeypatch.setattr(Scene, "run", held)
    scene = comet()
    leapfrog = {"integrator.method": "leapfrog", "integrator.dt": "1 d"}
    threads = {name: threading.Thread(name=name, target=lambda n=name: rows.setdefault(
        n, run_member(scene.data, scene.source, leapfrog))) for name in "AB"}
    before = list(warnings.filters)
    for name in "AB":
        threads[name].start()
        assert entered[name].wait(60)
    for name in "AB":
        release[name].set()
        threads[name].join(120)
    assert warnings.filters == before
    assert [rows[n]["under-resolved encounters"] for n in "AB"] == [1, 1]
    assert not any(f[2] is UnderResolvedEncounterWarning for f in warnings.filters)


NO_GUARD = """from hamilton_orbits import Ensemble, Scene
Ensemble(Scene.bundled("mercury-gr"), vary={"duration": ["10 d", "20 d"]}).run(
    progress=False, workers=2)
"""


def test_a_script_without_the_main_guard_is_named_as_the_cause(tmp_path):
    """A script running an ensemble at module level, not under ``if __name__ ==
    "__main__":``, failed with "a worker ... ended abruptly (killed: out of
    memory?)": each worker (spawned) ran the script again and died starting a pool
    of its own.  The message names the script's line and the guard."""
    import subprocess

    script = tmp_path / "noguard.py"
    script.write_text(NO_GUARD)
    res = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                         timeout=600, cwd=tmp_path)
    assert res.returncode == 1
    last = res.stderr.strip().splitlines()[-1]
    assert last.startswith("concurrent.futures.process.BrokenProcessPool: ")
    assert f"the script calls this run at {script}:2 outside an `if __name__ == " in last
    assert "spawn method" in last and "out of memory" not in last


def test_the_main_guard_is_found_where_it_stands():
    """The guard's test in either order and quoting, nested in a block; a line
    outside it, or a script that cannot be parsed (nothing claimed), is told apart."""
    from hamilton_orbits.ensemble import _in_main_guard

    code = ("import x\nx.run()\nif __name__ == '__main__':\n    x.run()\n"
            "try:\n    if \"__main__\" == __name__:\n        x.run()\nexcept OSError:\n"
            "    x.run()\n")
    assert [_in_main_guard(code, k) for k in (2, 4, 7, 9)] == [False, True, True, False]
    assert _in_main_guard("if (:\n", 1)
