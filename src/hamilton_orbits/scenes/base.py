"""What every scene kind shares: :class:`SceneKind`, the registry of kinds
(:data:`KINDS`, :func:`register_kind`, :func:`registered_kinds`), the limit on a scene's
output memory (:func:`check_output_size`) and :func:`format_table`.

Every kind registers through the entry-point group ``hamilton_orbits.scene_kinds``:
this package's ``nbody`` (:mod:`hamilton_orbits.scenes.nbody.kind`) as ``rigid``'s
``rotation``, so that this module imports no kind and ``hamilton_orbits`` never
imports ``rigid``.  :mod:`hamilton_orbits.scenes.result`,
:mod:`hamilton_orbits.scenes.scene` and every kind import this module.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from importlib.metadata import EntryPoint
from typing import Any

import astropy.units as u

from hamilton_orbits import schema as S
from hamilton_orbits._output_memory import OUTPUT_LIMIT, beyond_limit, format_size

__all__ = ["BUILT_IN", "GROUP", "KINDS", "OUTPUT_LIMIT", "SNAPSHOT_BYTES", "SceneKind",
           "check_archive_size", "check_output_size",
           "format_table", "format_value", "register_kind", "registered_kinds"]


@dataclass(frozen=True)
class SceneKind:
    """A kind of scene: its keys, its checks across keys, and how it runs.

    Parameters
    ----------
    name : str
        The ``kind = "..."`` value.
    summary : str
        One line for listings.
    schema : Mapping[str, schema.Field]
        The kind's keys (besides ``kind``, ``description`` and ``effects``).
    effect_kind : str
        Which effect registry the kind's ``effects`` come from.
    check : callable
        ``check(spec, problems)``: checks across keys (a body an effect names
        exists, the integrator accepts the effects), adding to ``problems``.
    run : callable
        ``run(scene, progress, stop) -> Result``; ``stop()`` is true once the
        user asked to stop (Ctrl-C): the run ends early and keeps what it has.
    crosscheck : callable or None
        ``crosscheck(scene) -> str``: the same scene in a peer code, tabled.
    takes_effects : bool
        Whether its scenes may list effects (False: its ``check`` refuses any;
        ``hamilton-orbits scenes`` then lists none for it).
    """

    name: str
    summary: str
    schema: Mapping[str, S.Field]
    effect_kind: str
    check: Callable[[dict, S.Problems], None]
    run: Callable[..., Any]
    crosscheck: Callable[[Any], str] | None = None
    takes_effects: bool = True


KINDS: dict[str, SceneKind] = {}


def register_kind(kind: SceneKind) -> SceneKind:
    """Register a scene kind: what the ``register`` function of each entry point of
    :data:`GROUP` calls (``nbody``'s, ``rigid``'s ``rotation``)."""
    KINDS[kind.name] = kind
    return kind


GROUP = "hamilton_orbits.scene_kinds"
"""The entry-point group of the scene kinds: ``name = "module:register"``."""

BUILT_IN = (EntryPoint(name="nbody", value="hamilton_orbits.scenes.nbody.kind:register",
                       group=GROUP),)
"""This package's kinds, as ``pyproject.toml`` declares them in :data:`GROUP`; loaded
from here where the installed metadata lacks them (a source tree run without
installing it, or installed before they were declared)."""

_LOADED = False


def registered_kinds() -> dict[str, SceneKind]:
    """The registered kinds by name (:data:`KINDS`), every entry point of
    :data:`GROUP` loaded and called on the first call: this package's ``nbody`` and
    the plug-ins' kinds (``rigid``'s ``rotation``) alike."""
    global _LOADED
    if not _LOADED:
        _LOADED = True
        from importlib.metadata import entry_points

        installed = entry_points(group=GROUP)
        missing = [ep for ep in BUILT_IN if ep.name not in installed.names]
        for ep in (*missing, *installed):
            ep.load()()
    return KINDS


def _at_least(value: Any) -> str:
    """A positive Quantity rounded up to 3 significant digits, as text: an interval
    suggested as the shortest that passes passes (rounded to nearest, "1.79e+03 s"
    was refused in its turn)."""
    x = float(value.value)
    step = 10.0 ** (math.floor(math.log10(x)) - 2)
    up = math.ceil(x / step) * step
    text = f"{up:.3g}"
    if float(text) < x:  # (the product rounded below: one more in the third digit)
        text = f"{up + step:.3g}"
    return f"{text} {value.unit.to_string()}"


def check_output_size(spec: Mapping[str, Any], problems: S.Problems, per_output: int,
                      what: str) -> None:
    """Refuse a ``duration`` / ``cadence`` whose outputs would exceed :data:`OUTPUT_LIMIT`.

    Parameters
    ----------
    spec : mapping
        A scene's checked keys, with ``duration`` and ``cadence`` (None: 1000 outputs).
    problems : schema.Problems
    per_output : int
        float64 values kept at each output (n-body: 6 per body).
    what : str
        What each output holds, for the message (``"2 bodies"``).
    """
    duration, cadence = spec.get("duration"), spec.get("cadence")
    if duration is None:
        return
    n = 1001.0 if cadence is None else math.ceil(
        float((duration / cadence).to_value(u.one)) - 1e-9) + 1.0
    nbytes = n * per_output * 8.0
    if nbytes <= OUTPUT_LIMIT:
        return
    # (n = duration / cadence + 1 outputs at most fit: the shortest cadence that keeps
    # them within the limit, the last output counted)
    fit = math.floor(OUTPUT_LIMIT / (per_output * 8.0)) - 1.0
    if fit < 1.0:  # (two outputs, the start and the end, do not fit)
        problems.add("cadence" if cadence is not None else "duration",
                     f"{n:.4g} outputs of {what} would take {beyond_limit(nbytes)} of "
                     f"memory, and the start and the end alone "
                     f"{format_size(2 * per_output * 8.0)}: fewer bodies")
        return
    shortest = (duration / fit).to(cadence.unit if cadence is not None else duration.unit)
    problems.add(
        "cadence" if cadence is not None else "duration",
        f"{n:.4g} outputs of {what} would take {beyond_limit(nbytes)} of memory: choose a "
        f"cadence of at least {_at_least(shortest)} or a shorter duration")


#: a generous bound on an archive snapshot's bytes per body (radau15's predictor
#: values and compensated sums, about 60 float64 a body; the variational equations'
#: tangent vectors add as much again), and per snapshot beside them
SNAPSHOT_BYTES = (1000, 4096)


def check_archive_size(spec: Mapping[str, Any], problems: S.Problems, bodies: int) -> None:
    """Refuse an ``[output] archive_every`` so short against ``duration`` that the
    archive would exceed :data:`OUTPUT_LIMIT` on disk (its snapshots of ``bodies``
    bodies, :data:`SNAPSHOT_BYTES` each at most), at loading, not after filling the
    disk."""
    every, duration = spec.get("output", {}).get("archive_every"), spec.get("duration")
    if every is None or duration is None:
        return
    n = float((duration / every).to_value(u.one)) + 1.0
    each = SNAPSHOT_BYTES[0] * max(bodies, 1) + SNAPSHOT_BYTES[1]
    if n * each <= OUTPUT_LIMIT:
        return
    fit = math.floor(OUTPUT_LIMIT / each) - 1.0  # (the snapshot at the start counted)
    if fit < 1.0:  # (two snapshots, the start's and one more, do not fit)
        problems.add("output.archive_every",
                     f"{n:.4g} snapshots of {bodies} bodies would take up to "
                     f"{beyond_limit(n * each)} on disk, and two snapshots alone "
                     f"{format_size(2 * each)}: no archive_every fits; leave it out")
        return
    shortest = (duration / fit).to(every.unit)
    problems.add("output.archive_every",
                 f"{n:.4g} snapshots of {bodies} bodies would take up to "
                 f"{beyond_limit(n * each)} "
                 f"on disk: choose an archive_every of at least {_at_least(shortest)}")


def format_value(value: Any) -> str:
    """A value as a table's cell shows it: 6 significant digits, a Quantity's unit."""
    if isinstance(value, u.Quantity):
        if value.isscalar:
            return f"{value.value:.6g} {value.unit:unicode}".strip()
        return str(value)
    if isinstance(value, float):
        return f"{value:.6g}"
    return str(value)


def format_table(rows: Sequence[Mapping[str, Any]]) -> str:
    """An aligned text table of ``rows`` (dicts with the same keys).

    Examples
    --------
    >>> print(format_table([{"body": "sun", "dr": 1e-12}, {"body": "earth", "dr": 2.5e-10}]))
    body   dr
    -----  -------
    sun    1e-12
    earth  2.5e-10
    """
    if not rows:
        return ""
    keys = list(rows[0])
    cells = [[format_value(r.get(k, "")) for k in keys] for r in rows]
    widths = [max(len(k), *(len(c[i]) for c in cells)) for i, k in enumerate(keys)]
    lines = ["  ".join(k.ljust(w) for k, w in zip(keys, widths, strict=True)).rstrip()]
    lines.append("  ".join("-" * w for w in widths))
    for c in cells:
        lines.append("  ".join(x.ljust(w) for x, w in zip(c, widths, strict=True)).rstrip())
    return "\n".join(lines)

