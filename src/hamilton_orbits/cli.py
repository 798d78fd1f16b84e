"""The ``hamilton-orbits`` command.

::

    hamilton-orbits [--no-progress]      # runs the default bundled scene (solar-system)
    hamilton-orbits run [SCENE|FILE] [--out DIR] [--set KEY=VALUE ...] [--no-progress]
    hamilton-orbits resume OUTDIR        # a killed run of a scene with [output] archive_every
    hamilton-orbits crosscheck [SCENE|FILE]
    hamilton-orbits scenes               # the bundled scenes, their effects, run time
    hamilton-orbits demo                 # the quaternion tour

``run`` prints the scene's summary table and writes its folder (``summary.md``,
``summary.json``, PNG figures, ``states.nc``), named in the output.  Exit codes:
0 on success; 2 for a bad scene (every problem is listed, with file, line and
key) or a bad command line (an ``--out`` that is a file, cannot be written, or
is being written by another live run): nothing is simulated; 1 for a failure
during the run, in one line; 130 after Ctrl-C (what was done is kept and saved).
No command prints a traceback: every error is one ``hamilton-orbits: ...``
message on stderr.

The output folder is checked and claimed before the run (a lock file holding the
run's PID, ``.hamilton-orbits.lock``, removed at the end): two runs never write
into one folder at once, and a run never learns at the end that it cannot save.

``demo`` shows Hamilton's quaternion algebra and a rotation round trip, Hamilton's
two-body integrals on a textbook orbit, then the demo sections that other packages
register under the entry-point group ``hamilton_orbits.demos`` (``rigid`` adds the
flip of a free rigid body), so that ``hamilton_orbits`` never imports ``rigid``
itself (docs/design.md).
"""

from __future__ import annotations

import argparse
import contextlib
import os
import shlex
import sys
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np


def _demo() -> int:
    import astropy.units as u

    from hamilton_orbits import KeplerOrbit, Quaternion

    print("hamilton-orbits: Hamilton's quaternions (1845), Cayley's rotations (1843)")
    i, j, k = Quaternion.from_array(np.eye(4)[1:])
    print(f"  i^2 = {i * i!r}")
    print(f"  ijk = {i * j * k!r}")
    alpha = Quaternion.from_vector([1.0, 2.0, 2.0])
    beta = Quaternion.from_vector([0.0, 3.0, 4.0])
    print(f"  alpha beta = -alpha.beta + alpha x beta = {alpha * beta!r}")
    q = Quaternion.from_axis_angle([1.0, 1.0, 1.0], 2.0 * np.pi / 3.0)
    print("  a third of a turn about (1, 1, 1) permutes the axes:")
    print("    q i q^-1 =", np.round(q.rotate([1.0, 0.0, 0.0]), 15) + 0.0)
    g = q.as_gibbs()
    print("  Cayley's (lambda, mu, nu) = tan(theta/2) axis =", np.round(g, 15))
    rng = np.random.default_rng(1845)
    qs = Quaternion.from_array(rng.normal(size=(1_000_000, 4))).unit()
    back = Quaternion.from_rotation_matrix(qs.as_rotation_matrix())
    print(
        "  10^6 random rotations -> matrices -> quaternions: largest geodesic error "
        f"{qs.rotation_distance(back).max():.2e} rad"
    )

    print("\nHamilton's two-body integrals (Vallado, 4th ed., Example 2-5 state):")
    r = [6524.834, 6862.875, 6448.296] * u.km
    v = [4.901327, 5.533756, -1.976341] * u.km / u.s
    orbit = KeplerOrbit.from_state(r, v, 398600.4418 * u.km**3 / u.s**2)
    print(f"  a = {orbit.a:.3f}, e = {float(orbit.e):.6f}, p = {orbit.p:.3f}")
    print(
        f"  inc = {orbit.inc.to(u.deg):.3f}, lan = {orbit.lan.to(u.deg):.3f}, "
        f"argp = {orbit.argp.to(u.deg):.3f}, nu = {orbit.nu.to(u.deg):.3f}"
    )
    eps = orbit.hamilton_epsilon
    print(f"  Hamilton's epsilon (eq. 13, towards apoapsis) = {np.round(eps, 6)}")
    later = orbit
    for _ in range(7):  # seven steps of a seventh of a period, by universal variables
        later = later.propagate(orbit.period / 7)
    r1, _ = later.state()
    print(
        f"  after 7 steps of P/7 (P = {orbit.period.to(u.h):.4f}) the body is back "
        f"within {np.linalg.norm((r1 - r).to_value(u.mm)):.3g} mm"
    )

    from importlib.metadata import entry_points

    for ep in sorted(entry_points(group="hamilton_orbits.demos"), key=lambda e: e.name):
        print()
        ep.load()()
    return 0


DEFAULT_SCENE = "solar-system"
EXIT_OK, EXIT_FAILED, EXIT_BAD_SCENE, EXIT_INTERRUPTED = 0, 1, 2, 130


class _CommandError(Exception):
    """A failure the command explains itself (its message is the whole line)."""


def _error(message: str) -> None:
    print(f"hamilton-orbits: {message}", file=sys.stderr)


def _one_line(exc: BaseException) -> str:
    """An exception as one line: its type and its message, whitespace collapsed."""
    text = " ".join(str(exc).split())
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def _scene_file(ref: str):
    """The scene file ``ref`` names (a path ending in ``.toml``, or a file that
    exists), or None for a bundled scene's name (a folder of that name, such as the
    run's own ``--out``, does not hide it)."""
    from pathlib import Path

    path = Path(ref)
    return path if ref.endswith(".toml") or path.is_file() else None


def _load_scene(ref: str, sets: Sequence[str], text: str | None = None):
    """A scene from a bundled name or a file path (``text``: the text it had, as an
    archived run recorded it), with ``--set`` overrides applied."""
    from hamilton_orbits.scene import Scene

    # (the overrides applied before the scene is checked: a value the file gets wrong
    # may be set right on the command line)
    values = _set_values(ref, sets)
    if text is not None:
        return Scene.from_text(text, ref, values)
    if _scene_file(ref) is not None:
        return Scene.from_toml(ref, values)
    _not_a_scene_file(ref)
    return Scene.bundled(ref, values)


def _not_a_scene_file(ref: str) -> None:
    """Refuse a path that exists but is not a file (a folder, a device) and names
    no bundled scene, saying what it is: "no bundled scene of that name" misled."""
    from pathlib import Path

    from hamilton_orbits.scene import Scene, SceneError

    path = Path(ref)
    if ref in dict(Scene.list_bundled()) or not path.exists():
        return
    what = "a folder" if path.is_dir() else "not a regular file"
    raise SceneError([f"{ref}: {what}, not a scene file (a .toml file) nor a bundled "
                      "scene's name (`hamilton-orbits scenes` lists them)"])


def _set_values(ref: str, sets: Sequence[str]) -> dict[str, str]:
    """The ``--set KEY=VALUE`` overrides ``sets`` as a mapping."""
    from hamilton_orbits.scene import SceneError

    values = {}
    for item in sets:
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise SceneError([f"{ref}: --set {item!r}: expected KEY=VALUE"])
        values[key.strip()] = value.strip()
    return values


def _wrap(text: str, width: int) -> list[str]:
    """``text`` in lines of at most ``width`` characters, broken between words."""
    import textwrap

    return textwrap.wrap(" ".join(text.split()), width) or [""]


def _list_scenes() -> int:
    from hamilton_orbits.scene import Scene, format_table

    rows = []
    for name, description in Scene.list_bundled():
        scene = Scene.bundled(name)
        lines = _wrap(description, 58)
        rows.append(
            {
                "scene": name + (" (default)" if name == DEFAULT_SCENE else ""),
                "kind": scene.kind,
                "effects": ", ".join(e["name"] for e in scene.effects) or "none",
                "run time": scene.spec.get("runtime") or "?",
                "description": lines[0],
            }
        )
        rows += [{"scene": "", "kind": "", "effects": "", "run time": "", "description": line}
                 for line in lines[1:]]
    print(format_table(rows))
    print("\nrun time: the whole command, warm (kernels cached), on a 2-core machine; the "
          "first run\non a machine adds the one-time compilation of the kernels it uses (its "
          "summary says\nwhich and how long; the main job's is measured by "
          "benchmarks/bench_first_run.py)")
    print("\n" + format_table(_effect_rows()))
    print("\neffects: what a scene's `effects = [...]` may list, by the kinds of scene that "
          "take\nthem (docs/effects.md gives every parameter, its unit and its default)")
    return EXIT_OK


def _effect_rows() -> list[dict[str, str]]:
    """A row per registered effect: the scene kinds that take it, its name, its
    summary (the kinds registered by the bundled scenes' packages)."""
    import hamilton_orbits.effects  # noqa: F401  (registers the built-in effects)
    from hamilton_orbits.effects.registry import get, known
    from hamilton_orbits.scenes.base import KINDS

    groups: dict[str, list[str]] = {}
    for kind in sorted(KINDS.values(), key=lambda k: k.name):
        if kind.takes_effects:
            groups.setdefault(kind.effect_kind, []).append(kind.name)
    rows = []
    for effect_kind, scene_kinds in groups.items():
        label = ", ".join(scene_kinds)
        for name in known(effect_kind):
            lines = _wrap(get(effect_kind, name).summary, 64)
            rows.append({"scene kinds": label, "effect": name, "what it adds": lines[0]})
            rows += [{"scene kinds": "", "effect": "", "what it adds": line}
                     for line in lines[1:]]
            label = ""
    return rows


def _run(ref: str, out: str | None, sets: Sequence[str], progress: bool) -> int:
    from pathlib import Path

    from hamilton_orbits._outdir import OutputFolder

    _compile_ahead(ref, sets)
    scene = _load_scene(ref, sets)
    folder = Path(out) if out else Path("hamilton-orbits-output") / scene.name
    with OutputFolder(folder, "--out" if out else "output folder"):
        archive = _archive_for(scene, folder, ref, sets)
        result = _run_scene(scene, progress, archive)
        return _finish(scene, result, folder, archive)


def _compile_ahead(ref: str, sets: Sequence[str]) -> None:
    """Before the scene loads (its imports take a second or two), the stepping kernel
    of a radau15 ``nbody`` scene sent to compile in a second process on a first run,
    from the scene's own text (the run itself sends it when this cannot tell)."""
    import tomllib

    try:
        raw = tomllib.loads(_scene_text(_scene_file(ref), ref).removeprefix("\ufeff"))
        method = raw.get("integrator", {}).get("method")
        for item in sets:
            key, _, value = item.partition("=")
            if key.strip() == "integrator.method":
                method = value.strip().strip("\"'")
        if (raw.get("kind", "nbody") != "nbody" or method != "radau15"
                or raw.get("variational")):
            return
    except Exception:  # (a scene that does not read: its load says why, next)
        return
    from hamilton_orbits.integrators import radau15

    radau15.compile_ahead(bool(raw.get("events")))


def _archive_for(scene, folder, ref: str, sets: Sequence[str]):
    """The archive folder of a scene run with ``[output] archive_every`` (None
    without), the scene's source recorded in it for ``hamilton-orbits resume``."""
    import json
    from pathlib import Path

    from hamilton_orbits._outdir import FolderError
    from hamilton_orbits.checkpoint import holds_snapshots

    every = scene.spec.get("output", {}).get("archive_every")
    archive = Path(folder) / "archive"
    resume = f"hamilton-orbits resume {shlex.quote(str(folder))}"
    if holds_snapshots(archive):  # (also for a scene that archives nothing: its files
        # would be taken by a resume of the earlier run)
        if _finished(archive):
            raise _CommandError(f"{archive} holds the archive of an earlier run, which "
                                f"finished (its results are in {folder}/): choose another "
                                f"--out, or remove {archive} to run into {folder} again")
        raise _CommandError(f"{archive} holds the snapshots of an earlier run: resume it "
                            f"({resume}) or choose another --out")
    if every is None:
        return None
    file = _scene_file(ref)
    source = ref if file is None else str(file.resolve())
    record = {"scene": source, "set": list(sets), "text": _scene_text(file, ref),
              "cwd": os.getcwd()}  # (where the scene's relative paths were read)
    try:  # (the scene's text kept, written whole: a resume runs the scene this run ran)
        archive.mkdir(parents=True, exist_ok=True)
        part = archive / f".scene.json.tmp-{os.getpid()}"
        part.write_text(json.dumps(record), encoding="utf-8")
        os.replace(part, archive / "scene.json")
    except OSError as exc:
        raise FolderError(f"--out {folder}: cannot write {archive} "
                          f"({exc.strerror or exc}); nothing was run") from None
    print(f"archiving every {every} to {archive}/ (a killed run resumes with: {resume})",
          file=sys.stderr)
    return archive


#: the key of ``archive/scene.json`` that says the run finished (its files written)
_FINISHED = "finished"


def _finished(archive) -> bool:
    """Whether the scene run that wrote the archive folder ``archive`` finished (its
    ``scene.json`` says so: written when the run's files were)."""
    import json

    try:
        record = json.loads((archive / "scene.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False
    return isinstance(record, dict) and record.get(_FINISHED) is True


def _mark_finished(archive) -> None:
    """Say in ``archive/scene.json`` that the run finished (rewritten whole; a failure
    to write it only leaves the run resumable, as before)."""
    import json

    record_path = archive / "scene.json"
    try:
        record = json.loads(record_path.read_text(encoding="utf-8"))
        record[_FINISHED] = True
        part = archive / f".scene.json.tmp-{os.getpid()}"
        part.write_text(json.dumps(record), encoding="utf-8")
        os.replace(part, record_path)
    except (OSError, ValueError, TypeError):
        return


def _scene_text(file, ref: str) -> str:
    """The text of the scene file ``file``, or of the bundled scene ``ref``."""
    from importlib import resources

    path = file or resources.files("hamilton_orbits") / "data" / "scenes" / f"{ref}.toml"
    return path.read_text(encoding="utf-8")


def _resume(out: str, progress: bool) -> int:
    """Resume the killed run of the scene whose output folder is ``out``."""
    import json
    from pathlib import Path

    from hamilton_orbits._outdir import OutputFolder

    folder = Path(out)
    record = folder / "archive" / "scene.json"
    if not record.is_file():
        raise _CommandError(f"{folder} is not the output folder of a scene run with an "
                            f"archive (no {record})")
    try:
        source = json.loads(record.read_text(encoding="utf-8"))
        if not (isinstance(source, dict) and isinstance(source.get("scene"), str)
                and isinstance(source.get("set", []), list)
                and all(isinstance(x, str) for x in source.get("set", []))
                and isinstance(source.get("text", ""), (str, type(None)))
                and isinstance(source.get("cwd", ""), (str, type(None)))):
            raise ValueError("not the record of a run")
    except (OSError, ValueError) as exc:  # (JSONDecodeError and UnicodeDecodeError too)
        raise _CommandError(f"{record} is damaged ({_one_line(exc)}): the run's scene cannot "
                            f"be read; start it again with hamilton-orbits run") from None
    if source.get(_FINISHED) is True:
        raise _CommandError(f"the run in {folder} finished (its results are in {folder}/): "
                            f"there is nothing to resume")
    text = source.get("text")  # (the scene as the run ran it; none in older archives)
    file = _scene_file(source["scene"])
    if text is not None and file is not None and file.is_file() and \
            file.read_text(encoding="utf-8") != text:
        print(f"hamilton-orbits: {file} has changed since the run began; resuming the "
              f"scene as the run read it (kept in {record})", file=sys.stderr)
    here, there = os.getcwd(), source.get("cwd")
    folder = folder.resolve()  # (the scene's relative paths read where the run read them)
    try:
        if there is not None and os.path.isdir(there):
            os.chdir(there)
        scene = _load_scene(source["scene"], source.get("set", []), text)
        with OutputFolder(folder, "output folder"):
            result = _run_scene(scene, progress, folder / "archive")
            return _finish(scene, result, folder, folder / "archive")
    finally:
        os.chdir(here)


def _finish(scene, result, folder, archive) -> int:
    """Print the summary, save the result into ``folder`` (a Ctrl-C meanwhile kept
    until the files are written: a finished run is not thrown away); the exit code."""
    if result is None:
        return EXIT_FAILED
    with _ctrl_c("saving the run's files first (Ctrl-C again to abort)") as caught:
        try:  # (saved before the summary is printed: a reader that stops reading, as
            paths = result.save(folder)  # `| head` does, loses no file)
        except Exception as exc:
            _say(result.summary())
            _error(f"the run of {scene.name} ended but saving into {folder}/ failed: "
                   f"{_one_line(exc)}")
            return EXIT_FAILED
        _say(result.summary())
        _say(f"\nwrote {len(paths)} files to {folder}/: {', '.join(p.name for p in paths)}")
        for what in result.not_saved:
            print(f"hamilton-orbits: not written: {what}", file=sys.stderr)
        _earlier_files(folder, paths)
    if not result.complete and archive is not None:
        _say(f"the run was interrupted; its archive is {archive}/: continue it with "
             f"hamilton-orbits resume {shlex.quote(str(folder))}")
    done = result.complete and not caught and not result.interrupted
    if done and archive is not None:
        _mark_finished(archive)
    return EXIT_OK if done else EXIT_INTERRUPTED


def _earlier_files(folder: Path, written: list[Path]) -> None:
    """Say which files of ``folder`` this run did not write (an earlier run's figures
    beside this one's summary read as this run's); none is removed."""
    names = {p.name for p in written}
    try:
        other = sorted(p.name for p in Path(folder).iterdir()
                       if p.is_file() and not p.name.startswith(".") and p.name not in names)
    except OSError:
        return
    if other:
        print(f"hamilton-orbits: {folder}/ also holds files this run did not write (an "
              f"earlier run's?): {', '.join(other)}", file=sys.stderr)


def _say(text: str) -> None:
    """Print ``text`` on stdout; a reader gone (``| head`` done, ``less`` quit: a
    broken pipe) is no error, and the rest of the output goes nowhere."""
    try:
        print(text, flush=True)
    except BrokenPipeError:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())  # (Python's flush at exit then finds none)
        os.close(devnull)


@contextlib.contextmanager
def _ctrl_c(saying: str) -> Iterator[list[int]]:
    """Within it, the first Ctrl-C noted in the list it gives (and ``saying`` said on
    stderr), the work going on; a second aborts (KeyboardInterrupt, held as the
    drivers hold Ctrl-C: ``hamilton_orbits.integrators._held``)."""
    import signal

    from hamilton_orbits.firstrun import compiling
    from hamilton_orbits.integrators._held import HELD

    caught: list[int] = []

    def on_sigint(signum, frame):
        if caught:
            HELD.interrupt()
            return
        caught.append(signum)
        if compiling():  # (nothing run yet, and the compilation takes seconds)
            print("\nhamilton-orbits: stopping (the kernels were compiling: nothing run "
                  "yet)", file=sys.stderr)
            raise KeyboardInterrupt
        print(f"\nhamilton-orbits: {saying}", file=sys.stderr)

    try:
        previous = signal.signal(signal.SIGINT, on_sigint)
    except ValueError:  # not the main thread: leave Ctrl-C alone
        previous = None
    try:
        yield caught
    finally:
        if previous is not None:
            signal.signal(signal.SIGINT, previous)


def _run_scene(scene, progress: bool, archive=None):
    """Run ``scene`` with Ctrl-C handled (the first stops the run soon and keeps what
    it reached, the second aborts);
    None (after one line on stderr) if the run failed."""
    with _ctrl_c("stopping (within a few thousand steps; what was reached is kept; Ctrl-C "
                 "again to abort)") as interrupted:
        try:
            return scene.run(progress=progress and sys.stderr.isatty(),
                             stop=lambda: bool(interrupted), archive=archive)
        except KeyboardInterrupt:  # (aborted: no file written, the archive kept)
            if archive is not None:
                print(f"hamilton-orbits: its archive is {archive}/: continue the run with "
                      f"hamilton-orbits resume {shlex.quote(str(archive.parent))}",
                      file=sys.stderr)
            raise
        except Exception as exc:
            _error(f"the run of {scene.name} failed: {_one_line(exc)}")
            return None


def _crosscheck(ref: str, sets: Sequence[str]) -> int:
    scene = _load_scene(ref, sets)
    try:
        print(scene.crosscheck())
    except Exception as exc:
        _error(f"the cross-check of {scene.name} failed: {_one_line(exc)}")
        return EXIT_FAILED
    return EXIT_OK


def _split_values(text: str) -> list[str]:
    """``"1e-8,1e-10"`` -> two values; commas inside ``[...]``, ``{...}`` (a TOML
    inline table) or quotes do not split."""
    out, depth, quote, cur = [], 0, "", []
    for ch in text:
        if quote:
            quote = "" if ch == quote else quote
        elif ch in "\"'":
            quote = ch
        elif ch in "[{":
            depth += 1
        elif ch in "]}":
            depth -= 1
        elif ch == "," and depth == 0:
            out.append("".join(cur).strip())
            cur = []
            continue
        cur.append(ch)
    out.append("".join(cur).strip())
    return [v for v in out if v]


def _ensemble(ref: str, varies: Sequence[str], dask: str | None, out: str | None,
              progress: bool) -> int:
    from pathlib import Path

    from hamilton_orbits._outdir import OutputFolder
    from hamilton_orbits.ensemble import Ensemble
    from hamilton_orbits.scene import SceneError

    vary: dict[str, list[str]] = {}
    scene = _load_scene(ref, [])
    for item in varies:
        key, sep, values = item.partition("=")
        if not sep or not key.strip() or not _split_values(values):
            raise SceneError([f"{scene.source}: --vary {item!r}: expected KEY=V1,V2,..."])
        if key.strip() in vary:  # (the later would replace the earlier silently)
            raise SceneError([f"{scene.source}: --vary {item!r}: {key.strip()!r} is varied "
                              f"twice; give its values in one --vary KEY=V1,V2,..."])
        listed = _split_values(values)
        twice = sorted({v for v in listed if listed.count(v) > 1})
        if twice:  # (two members of one name: one column of the table for both)
            raise SceneError([f"{scene.source}: --vary {item!r}: {twice[0]!r} is listed "
                              f"twice; give each value of {key.strip()!r} once"])
        vary[key.strip()] = listed
    if not vary:  # name the command-line option, not Ensemble's Python arguments
        raise SceneError([f"{scene.source}: ensemble needs at least one --vary KEY=V1,V2,... "
                          "(the values of a key to run)"])
    try:
        ens = Ensemble(scene, vary=vary)
    except ValueError as exc:  # a member that is not a valid scene, named
        _error(str(exc))
        return EXIT_BAD_SCENE
    folder = Path(out) if out else Path("hamilton-orbits-output") / f"{scene.name}-ensemble"
    if scene.spec.get("output", {}).get("archive_every") is not None or \
            "output.archive_every" in vary:
        print("an ensemble's members write no archive: [output] archive_every is for "
              "`hamilton-orbits run` (one scene, resumed with `hamilton-orbits resume`)",
              file=sys.stderr)
    with OutputFolder(folder, "--out" if out else "output folder"):
        client, cluster = _dask_client(dask) if dask else (None, None)
        try:
            df = ens.run(client=client, progress=progress and sys.stderr.isatty())
        finally:
            if client is not None:
                client.close()
            if cluster is not None:  # (a client does not close the cluster it was given:
                cluster.close()  # its worker processes outlived the command in-process)
        _write_ensemble(scene, df, folder, list(vary))
    return EXIT_OK if df.attrs["failures"] == 0 else EXIT_FAILED


def _dask_client(address: str):
    """A Dask client on ``address`` and the cluster made for it (``"local"``: one on
    this machine, to close after the client; None for a scheduler's address)."""
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise _CommandError("--dask needs Dask: pip install 'hamilton-orbits[dask]'") from None
    try:
        if address != "local":
            return Client(address), None
        cluster = LocalCluster()
        try:
            return Client(cluster), cluster
        except BaseException:
            cluster.close()
            raise
    except (OSError, ValueError, TypeError) as exc:
        raise _CommandError(f"--dask {address}: cannot connect to the scheduler "
                           f"({_one_line(exc)})") from None


def _write_ensemble(scene, df, folder, varied: Sequence[str]) -> None:
    from hamilton_orbits.scene import format_table

    rows = df.to_dict("records")
    print(f"ensemble of {scene.name}: {len(df)} members, {df.attrs['failures']} failed")
    print(ensemble_table(rows, varied))
    df.to_csv(folder / "ensemble.csv", index=False)
    (folder / "ensemble.md").write_text(
        f"# Ensemble of {scene.name}\n\n```\n{format_table(rows)}\n```\n", encoding="utf-8")
    print(f"\nwrote ensemble.csv, ensemble.md to {folder}/")


def _all_equal(values: list[object]) -> bool:
    """Whether the values are all equal (NaN equal to NaN: a quantity no member has)."""
    def same(a: object, b: object) -> bool:
        nan = isinstance(a, float) and isinstance(b, float) and a != a and b != b
        return nan or bool(a == b)

    return all(same(values[0], v) for v in values[1:])


def ensemble_table(rows: Sequence[dict], varied: Sequence[str]) -> str:
    """An ensemble's rows for the terminal: what is the same for every member said
    once, the ``complete`` and ``error`` columns only where a member stopped or
    failed, numbers to 4 digits, and one column per member (a row per quantity)
    for up to 6 members, so that the table stays within a terminal's width.

    Examples
    --------
    >>> rows = [{"dt": "1 ms", "err [rad]": 1.234567e-12, "T [s]": 14.966, "error": None},
    ...         {"dt": "2 ms", "err [rad]": 2.5e-11, "T [s]": 14.966, "error": None}]
    >>> print(ensemble_table(rows, ["dt"]))
    quantity   dt = 1 ms  dt = 2 ms
    ---------  ---------  ---------
    err [rad]  1.235e-12  2.5e-11
    <BLANKLINE>
    the same for every member:
      T [s] = 14.97
    """
    from hamilton_orbits.scene import format_table

    def fmt(value: object) -> str:
        if isinstance(value, float):
            return f"{value:.4g}"
        return str(value)

    keys = [k for k in rows[0] if k not in varied]
    failed = [i for i, r in enumerate(rows) if r.get("error") is not None]
    shown, same = [], []
    for key in keys:
        if key == "error" and not failed:
            continue
        if key == "complete" and all(r.get(key) is True for r in rows):
            continue
        # (the same values, not the same 4 digits: a flip interval 1.3e-9 apart was
        # said the same for every member beside its relative difference, which varied)
        if len(rows) > 1 and _all_equal([r.get(key) for r in rows]) \
                and key not in ("error", "complete"):
            same.append(f"{key} = {fmt(rows[0].get(key))}")
        else:
            shown.append(key)
    names = [", ".join(f"{k} = {r[k]}" for k in varied) or f"member {i}"
             for i, r in enumerate(rows)]
    if len(rows) <= 6:
        table = [{"quantity": key, **{n: fmt(r.get(key)) for n, r in zip(names, rows,
                                                                        strict=True)}}
                 for key in shown]
    else:
        table = [{**{k: r[k] for k in varied}, **{k: fmt(r.get(k)) for k in shown}}
                 for r in rows]
    out = [format_table(table)] if table else []
    if same:
        out.append("\nthe same for every member:")
        out += [f"  {item}" for item in same]
    out += [f"member {i} ({names[i]}) failed: {rows[i]['error']}" for i in failed]
    return "\n".join(out)


def _report(quick: bool, out: str | None, progress: bool) -> int:
    from hamilton_orbits._outdir import OutputFolder
    from hamilton_orbits.studies.report import build_report

    folder = out if out else "hamilton-orbits-output/report"
    with OutputFolder(folder, "--out" if out else "output folder"):
        try:
            files = build_report(folder, quick=quick, progress=progress)
        except ImportError as exc:  # the [report] extra is missing: say which, no traceback
            print(f"hamilton-orbits: {exc}", file=sys.stderr)
            return EXIT_FAILED
    print("wrote " + ", ".join(f.name for f in files) + f" to {folder}/")
    return EXIT_OK


def _command(sub: Any, name: str, help: str) -> argparse.ArgumentParser:
    """A subcommand whose ``--help`` says what it does (its help line as description)."""
    return sub.add_parser(name, help=help, description=help)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``hamilton-orbits`` console script.

    Examples
    --------
    >>> main(["--version"])  # doctest: +ELLIPSIS
    hamilton-orbits ...
    0
    """
    from hamilton_orbits import __version__

    parser = argparse.ArgumentParser(
        prog="hamilton-orbits",
        description=(
            "Celestial mechanics and rigid-body rotation on Hamilton's quaternions. "
            f"With no command, runs the default scene ({DEFAULT_SCENE})."
        ),
    )
    parser.add_argument("--version", action="store_true", help="print the version and exit")
    parser.add_argument("--no-progress", dest="quiet", action="store_true",
                        help="no progress bar (with no command, or before any command)")
    sub = parser.add_subparsers(dest="command",
                                help="what to do (`COMMAND --help` for its options)")
    run = _command(sub, "run", help="run a scene and write its folder")
    run.add_argument("scene", nargs="?", default=DEFAULT_SCENE, help="bundled name or TOML file")
    run.add_argument("--out", help="output folder (default hamilton-orbits-output/SCENE)")
    run.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                     help='override one key, e.g. --set duration="100 yr" (repeatable)')
    run.add_argument("--no-progress", action="store_true", help="no progress bar")
    cc = _command(sub, "crosscheck", help="run a scene here and in rebound/reboundx; differences")
    cc.add_argument("scene", nargs="?", default=DEFAULT_SCENE, help="bundled name or TOML file")
    cc.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help='override one key, e.g. --set duration="100 yr" (repeatable)')
    en = _command(sub, "ensemble", help="run a grid of variations of a scene in parallel")
    en.add_argument("scene", help="bundled name or TOML file")
    en.add_argument("--vary", action="append", default=[], metavar="KEY=V1,V2,...",
                    help="values of one key (repeatable: the grid of all combinations)")
    en.add_argument("--dask", metavar="ADDRESS|local", help="run on a Dask cluster")
    en.add_argument("--out", help="output folder (default hamilton-orbits-output/SCENE-ensemble)")
    en.add_argument("--no-progress", action="store_true", help="no progress bar")
    rp = _command(sub, "report", help="the work-precision report: error against wall time")
    rp.add_argument("--quick", action="store_true", help="short spans, few settings (~1 min)")
    rp.add_argument("--out", help="output folder (default hamilton-orbits-output/report)")
    rp.add_argument("--no-progress", action="store_true", help="no progress lines")
    rs = _command(sub, "resume", help="resume a killed scene run from its archive "
                                     "([output] archive_every)")
    rs.add_argument("out", help="the output folder of the run")
    rs.add_argument("--no-progress", action="store_true", help="no progress bar")
    _command(sub, "scenes", help="list the bundled scenes")
    _command(sub, "demo", help="the quaternion / rotation tour")
    args = parser.parse_args(argv)
    if args.version:
        print(f"hamilton-orbits {__version__}")
        return EXIT_OK
    return _guarded(args)


def _guarded(args: argparse.Namespace) -> int:
    """Run the command; every error becomes one line on stderr and an exit code."""
    try:  # (a Ctrl-C as the package is imported: one line too)
        from hamilton_orbits._outdir import FolderError
        from hamilton_orbits.scene import SceneError
    except KeyboardInterrupt:
        _error("interrupted (Ctrl-C)")
        return EXIT_INTERRUPTED
    try:
        return _dispatch(args)
    except SceneError as exc:  # every problem, with file, line and key
        _error(str(exc))
        return EXIT_BAD_SCENE
    except FolderError as exc:
        _error(str(exc))
        return EXIT_BAD_SCENE
    except _CommandError as exc:  # (a bad command line: nothing was run)
        _error(str(exc))
        return EXIT_BAD_SCENE
    except KeyboardInterrupt:  # a second Ctrl-C, or one before any output
        _error("interrupted (Ctrl-C)")
        return EXIT_INTERRUPTED
    except Exception as exc:
        _error(_one_line(exc))
        return EXIT_FAILED


def _dispatch(args: argparse.Namespace) -> int:
    if getattr(args, "out", None) is not None and not str(args.out).strip():
        if args.command == "resume":
            raise _CommandError(f"OUTDIR {args.out!r}: an empty path (give the output "
                                f"folder of the run to resume)")
        raise _CommandError(f"--out {args.out!r}: an empty path (give a folder, or leave "
                            f"--out out for the default)")
    progress = not (args.quiet or getattr(args, "no_progress", False))
    if args.command == "demo":
        return _demo()
    if args.command == "scenes":
        return _list_scenes()
    if args.command == "report":
        return _report(args.quick, args.out, progress=progress)
    if args.command == "ensemble":
        return _ensemble(args.scene, args.vary, args.dask, args.out, progress=progress)
    if args.command == "crosscheck":
        return _crosscheck(args.scene, args.set)
    if args.command == "run":
        return _run(args.scene, args.out, args.set, progress=progress)
    if args.command == "resume":
        return _resume(args.out, progress=progress)
    return _run(DEFAULT_SCENE, None, [], progress=progress)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
