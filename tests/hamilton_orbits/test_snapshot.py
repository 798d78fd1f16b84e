"""One snapshot file: exact values, readable without this package, damage detected.

A snapshot that is truncated, has a flipped byte, is missing, or is another
program's file must be a SnapshotError naming the path, never data; a folder that
cannot be written is a SnapshotError at the write, naming the path.
"""

from __future__ import annotations

import os
import re
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.io import netcdf_file

from hamilton_orbits import Body, Simulation, System
from hamilton_orbits._saving import RestartWarning
from hamilton_orbits.snapshot import FORMAT_VERSION, SnapshotError, read, write

DATA = Path(__file__).parent / "data"


def _arrays() -> dict[str, np.ndarray]:
    rng = np.random.default_rng(3)
    return {"r": rng.normal(size=(4, 3)) * 10.0 ** rng.integers(-300, 300, size=(4, 3)),
            "t": np.float64(np.pi), "steps": np.array([2**52 + 1, -3], dtype=np.int64),
            "mask": np.array([True, False, True]), "none": np.zeros((0, 7)),
            "special": np.array([np.nan, np.inf, -np.inf, -0.0, 5e-324])}


def test_values_come_back_exactly_with_their_types(tmp_path):
    arrays = _arrays()
    write(tmp_path / "a.nc", {"x": 0.1, "inf": float("inf"), "s": "ü"}, arrays)
    meta, back = read(tmp_path / "a.nc")
    assert meta == {"x": 0.1, "inf": float("inf"), "s": "ü"}
    for name, a in arrays.items():
        b = back[name]
        assert b.dtype == np.asarray(a).dtype and b.shape == np.shape(a), name
        assert np.array_equal(b, a, equal_nan=True) and (np.signbit(b) == np.signbit(a)).all()


def test_a_snapshot_reads_without_this_package(tmp_path):
    """Any netCDF reader sees t, r, v, gm with units (here scipy's own, alone)."""
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("p", 1e-3, [1, 0, 0], [0, 1, 0])])
    sim = Simulation(s, method="wh", dt=0.01)
    sim.integrate(1.0)
    sim.save(tmp_path / "s.nc")
    with netcdf_file(tmp_path / "s.nc", "r", mmap=False) as nc:
        assert nc.variables["r"].dimensions == ("body", "xyz")
        r = np.array(nc.variables["r"][:], dtype=np.float64)
        t = float(nc.variables["t"][()])
        assert int(nc.format_version) == FORMAT_VERSION
    np.testing.assert_array_equal(r, sim.system.as_arrays().r)
    assert t == 1.0


def _saved(tmp_path: Path) -> Path:
    path = tmp_path / "s.nc"
    write(path, {"kind": "test"}, _arrays())
    return path


def test_a_truncated_file_is_refused_naming_it(tmp_path):
    path = _saved(tmp_path)
    data = path.read_bytes()
    for cut in (len(data) - 8, len(data) // 2, 40, 3):
        path.write_bytes(data[:cut])
        with pytest.raises(SnapshotError, match=str(path)):
            read(path)


def test_every_flipped_byte_is_found(tmp_path):
    path = _saved(tmp_path)
    data = bytearray(path.read_bytes())
    missed = []
    for k in range(len(data)):
        damaged = bytearray(data)
        damaged[k] ^= 0x10
        path.write_bytes(bytes(damaged))
        try:
            read(path)
        except SnapshotError as exc:
            assert str(path) in str(exc)
        else:
            missed.append(k)
    # a flip is harmless only in padding, which netCDF-3 leaves between the header
    # and the data and after short variables (never read as values)
    path.write_bytes(bytes(data))
    meta, arrays = read(path)
    for k in missed:
        damaged = bytearray(data)
        damaged[k] ^= 0x10
        path.write_bytes(bytes(damaged))
        assert read(path)[0] == meta and all(
            np.array_equal(a, arrays[n], equal_nan=True) for n, a in read(path)[1].items())


def test_a_missing_or_foreign_file_is_refused(tmp_path):
    with pytest.raises(SnapshotError, match=r"no snapshot file .*gone.nc"):
        read(tmp_path / "gone.nc")
    (tmp_path / "text.nc").write_text("hello")
    with pytest.raises(SnapshotError, match=r"text.nc cannot be read as a snapshot"):
        read(tmp_path / "text.nc")
    with netcdf_file(tmp_path / "other.nc", "w") as nc:  # a netCDF file of another program
        nc.createDimension("x", 2)
        nc.createVariable("x", "d", ("x",))[:] = [1.0, 2.0]
    with pytest.raises(SnapshotError, match=r"other.nc is not a hamilton-orbits snapshot"):
        read(tmp_path / "other.nc")


def test_a_read_only_folder_is_refused_at_the_write(tmp_path, monkeypatch):
    """As the operating system refuses it (mocked: the tests may run as root, whom
    a read-only mode does not stop): the file opened in that folder refused."""
    real_open = os.open

    def refused(path, flags, *args, **kwargs):
        if "ro" in Path(path).parts:
            raise PermissionError(13, "Permission denied", str(path))
        return real_open(path, flags, *args, **kwargs)

    monkeypatch.setattr(os, "open", refused)
    with pytest.raises(SnapshotError, match=r"cannot write the snapshot .*ro/s.nc: Permission "
                                            r"denied"):
        write(tmp_path / "ro" / "s.nc", {}, _arrays())


def test_a_full_disk_is_refused_and_leaves_no_file(tmp_path, monkeypatch):
    real_fsync = os.fsync

    def full(fd: int) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "fsync", full)
    with pytest.raises(SnapshotError, match=r"cannot write the snapshot .*s.nc: No space left"):
        write(tmp_path / "s.nc", {}, _arrays())
    monkeypatch.setattr(os, "fsync", real_fsync)
    assert list(tmp_path.iterdir()) == []


def test_a_later_format_version_is_refused(tmp_path):
    path = _saved(tmp_path)
    data = path.read_bytes()
    with netcdf_file(path, "a", mmap=False) as nc:
        nc.format_version = FORMAT_VERSION + 1
    with pytest.raises(SnapshotError, match=rf"format version {FORMAT_VERSION + 1}; this "
                                            rf"version .* reads up to {FORMAT_VERSION}"):
        read(path)
    path.write_bytes(data)


def test_the_first_format_is_read_by_this_version():
    """``data/snapshot-v1.nc`` was written by format 1 (tools/make_snapshot_fixture.py):
    a planet on a Kepler ellipse (a = 1, e = 0.3) about a star of GM 1 integrated by
    wh to t = 10.  Its state must read, and continue."""
    from hamilton_orbits import KeplerOrbit

    path = DATA / "snapshot-v1.nc"
    meta, _ = read(path)
    assert meta["method"]["name"] == "wh"
    with warnings.catch_warnings():
        # a later version with other integrator internals continues from the state
        # (RestartWarning, tested in test_restart.py): what must last is the state
        warnings.simplefilter("ignore", RestartWarning)
        sim = Simulation.load(path)
    assert sim.t == 10.0
    # wh is exact on a test particle's Kepler orbit (a single Kepler drift per step),
    # so the state agrees with the ellipse to rounding (Murray & Dermott 1999, 2.4)
    orbit = KeplerOrbit.from_elements(a=1.0, e=0.3, inc=0.2, lan=0.5, argp=1.0, nu=0.0, mu=1.0)
    r, _ = orbit.propagate(10.0).state()
    np.testing.assert_allclose(sim.system["planet"].r, r, rtol=0, atol=1e-12)
    sim.integrate(12.0)
    r12, _ = orbit.propagate(12.0).state()
    np.testing.assert_allclose(sim.system["planet"].r, r12, rtol=0, atol=1e-12)


def test_the_second_format_is_read_by_this_version():
    """``data/snapshot-v2.nc`` was written by format 2 (tools/make_snapshot_fixture.py):
    the same planet integrated by dop853 (tol 1e-12) to t = 10, its infinite
    ``max_step`` written as strict JSON.  It must read (the infinity back as a
    float) and continue."""
    import json

    from hamilton_orbits import KeplerOrbit

    path = DATA / "snapshot-v2.nc"
    with netcdf_file(path, "r", mmap=False) as nc:
        assert int(nc.format_version) == 2
        text = nc.meta.decode()

    def refuse(constant: str) -> None:
        raise AssertionError(f"not strict JSON: {constant}")

    json.loads(text, parse_constant=refuse)
    meta, _ = read(path)
    assert meta["method"]["name"] == "dop853"
    assert '"$float": "inf"' in text and _infinities(meta) >= 1
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RestartWarning)
        sim = Simulation.load(path)
    assert sim.t == 10.0
    # dop853 at tol 1e-12 on a test particle's Kepler orbit: the state within 1e-9
    # of the ellipse (the method's error over 1.6 orbits, not a rounding bound)
    orbit = KeplerOrbit.from_elements(a=1.0, e=0.3, inc=0.2, lan=0.5, argp=1.0, nu=0.0, mu=1.0)
    for t in (10.0, 12.0):
        if t > sim.t:
            sim.integrate(t)
        r, _ = orbit.propagate(t).state()
        np.testing.assert_allclose(sim.system["planet"].r, r, rtol=0, atol=1e-9)


def _infinities(x: object) -> int:
    if isinstance(x, float):
        return int(x == float("inf"))
    if isinstance(x, dict):
        return sum(_infinities(v) for v in x.values())
    if isinstance(x, list):
        return sum(_infinities(v) for v in x)
    return 0


def _refused(constant: str) -> None:
    raise AssertionError(f"not strict JSON: {constant}")


def test_a_saved_file_holds_strict_json_and_continues_bit_for_bit(tmp_path):
    """dop853's state holds ``max_step = inf``: format 1 wrote it as a bare
    ``Infinity`` in ``meta``, which a strict JSON reader (JavaScript's, jq, Rust's
    serde_json) refuses, so the file was not readable without Python.  Now every
    saved ``meta`` is strict JSON, the infinity tagged, read back as the float,
    and the loaded simulation continues on the bits of the run never saved."""
    import json

    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                Body("p", 1e-3, [1.0, 0, 0], [0, 1.0, 0.1]),
                Body("q", 1e-4, [0, 2.0, 0], [-0.7, 0, 0])])
    for method, var in (("dop853", False), ("radau15", False), ("wh", False),
                        ("leapfrog", False), ("radau15", True)):  # (MEGNO's lyapunov_time:
        # inf until it is measured)
        kw = {"dt": 0.01} if method in ("wh", "leapfrog") else {}
        sim = Simulation(s, method=method, variational=var, **kw)
        sim.integrate(1.0)
        path = tmp_path / f"{method}-{var}.nc"
        sim.save(path)
        with netcdf_file(path, "r", mmap=False) as nc:
            text = nc.meta.decode()

        json.loads(text, parse_constant=_refused)
        loaded = Simulation.load(path)
        sim.integrate(2.0)
        loaded.integrate(2.0)
        np.testing.assert_array_equal(loaded.system.r, sim.system.r)
        np.testing.assert_array_equal(loaded.system.v, sim.system.v)


def test_an_archived_snapshot_reads_back_as_the_snapshot_saved_alone(tmp_path):
    """What the archive stores in shared and per-snapshot parts (the state's numbers
    split from its layout) reads back as exactly what a snapshot saved alone holds,
    among them snapshots where the layout changed (a merge: a new segment) and
    snapshots of later legs in the same segment."""
    from hamilton_orbits.checkpoint import snapshot_at

    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]),
                Body("a", 1e-3, [1.0, 0, 0], [0, 1.0, 0], radius=1e-3),
                Body("b", 1e-3, [1.003, 0, 0], [-0.01, 1.0, 0], radius=1e-3)])  # (they
    # meet at t ~ 0.1, in the first call: bodies that touch at the start merge there,
    # before its first snapshot)
    sim = Simulation(s, method="radau15", events=[{"name": "collision", "action": "merge"}],
                     archive=tmp_path / "run", every=0.5)
    for k, t in enumerate((0.5, 1.0, 2.0, 3.0)):
        sim.integrate(t)
        sim.save(tmp_path / f"alone-{k}.nc")
        meta, arrays = read(tmp_path / f"alone-{k}.nc")
        _, archived_meta, archived = snapshot_at(tmp_path / "run", sim._archive.count - 1)
        # what only an archived snapshot has; and "started", which integrate sets
        # when it returns, after the leg's last snapshot
        keep = {"leg", "number", "archive", "started"}
        assert {k: v for k, v in archived_meta.items() if k not in keep} == {
            k: v for k, v in meta.items() if k not in keep}
        for name, a in arrays.items():
            np.testing.assert_array_equal(archived[name], a, strict=True)
    # a segment goes on across the legs and begins where what they share changed (the
    # merge's layout; "started", which the first call's end sets): more than one,
    # fewer than the legs
    assert 1 < len(list((tmp_path / "run").glob("segment-*.nc"))) < 4


def test_a_segment_loaded_as_a_snapshot_points_to_its_folder(tmp_path):
    """``Simulation.load(".../segment-000000.nc")`` was refused as "not a hamilton-orbits
    snapshot (format 'hamilton-orbits archive segment')", the way to load it unsaid."""
    s = System([Body("sun", 1.0, [0, 0, 0], [0, 0, 0]), Body("p", 1e-5, [1.0, 0, 0], [0, 1.0, 0])])
    Simulation(s, archive=tmp_path / "run", every=0.5).integrate(1.0)
    folder = str(tmp_path / "run")
    with pytest.raises(SnapshotError, match=r"segment-000000.nc is not a hamilton-orbits snapshot "
                                            r".*: load the folder instead, Simulation.load\("
                                            + re.escape(repr(folder)) + r"\) \(its last"):
        Simulation.load(tmp_path / "run" / "segment-000000.nc")
    assert Simulation.load(folder).t == 1.0
