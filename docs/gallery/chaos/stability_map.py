"""
A MEGNO stability map: a Saturn-mass planet beside Jupiter over a grid of (a, e).
=================================================================================

Each cell is the bundled scene ``stability-map`` (the Sun and Jupiter at J2000 and
a planet of Saturn's mass, coplanar with Jupiter) with the planet's semi-major
axis and eccentricity set, run with ``variational = true``: MEGNO <Y> (2 on a
quasi-periodic orbit, growing on a chaotic one) and the Lyapunov time come from the
variational equations.  The cells run through ``hamilton_orbits.Ensemble``: a
local pool of processes, or a Dask cluster (``--dask``, a LocalCluster on this
machine; give ``--scheduler tcp://...`` for a running one).  The same map is run
with general relativity (``gr_potential``: the Nobili-Roxburgh potential, the
form of GR the symplectic ``wh`` integrator takes) to show where GR changes the
verdict.

Writes <out>/stability_map.png (the two maps, how much GR moves MEGNO and the
cells whose verdict it changes) and <out>/stability_map.csv (one row per cell
and model).
Run::

    python examples/chaos/stability_map.py [out_dir] [--n 64] [--orbits 10000] [--dask]
    python examples/chaos/stability_map.py [out_dir] --quick      (8 x 8, 200 orbits)
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from hamilton_orbits import Ensemble, Scene

P_JUPITER_YR = 11.8558  # Jupiter's period at J2000 (two-body, about the Sun)
A_JUPITER_AU = 5.2010
CHAOTIC = 4.0  # MEGNO above this: called chaotic (2: quasi-periodic)


def run_map(n_a: int, n_e: int, orbits: float, effects: list, client=None,
            workers: int | None = None):
    """MEGNO over the grid (a, e) for one model; (a, e, megno, lyapunov time, wall)."""
    a = np.linspace(7.0, 10.0, n_a)
    e = np.linspace(0.0, 0.5, n_e)
    years = orbits * P_JUPITER_YR
    scene = Scene.bundled("stability-map").with_values({
        "duration": f"{years} yr", "cadence": f"{years / 4} yr", "effects": effects})
    ens = Ensemble(scene, vary={"bodies.planet.a": [f"{float(x)!r} au" for x in a],
                                "bodies.planet.e": [float(x) for x in e]})
    start = time.perf_counter()
    table = ens.run(client=client, workers=workers, progress=True)
    wall = time.perf_counter() - start
    megno = table["MEGNO"].to_numpy(dtype=float).reshape(n_a, n_e).T
    lyap = table["Lyapunov time [yr]"].to_numpy(dtype=float).reshape(n_a, n_e).T
    return a, e, megno, lyap, wall, table


def _resonances(ax) -> None:
    """Mark the nominal mean-motion resonances with Jupiter (p:q, a = a_J (p/q)^(2/3))."""
    for p, q in ((5, 3), (2, 1), (7, 3), (5, 2)):
        a = A_JUPITER_AU * (p / q) ** (2.0 / 3.0)
        ax.axvline(a, color="white", lw=0.6, ls="--", alpha=0.8)
        ax.text(a, 1.0, f"{p}:{q}", ha="center", va="bottom", fontsize=7,
                transform=ax.get_xaxis_transform())


def plot(a, e, maps: dict, out: Path, orbits: float) -> Path:
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.6), constrained_layout=True)
    cmap = plt.get_cmap("RdYlBu_r").with_extremes(bad="0.6")  # failed cells
    for ax, (title, megno) in zip(axes[:2], maps.items(), strict=True):
        mesh = ax.pcolormesh(a, e, np.clip(megno, 1.8, CHAOTIC + 1), cmap=cmap,
                             shading="nearest", vmin=1.8, vmax=CHAOTIC + 1)
        _resonances(ax)
        ax.set_xlabel("semi-major axis a [au]")
        ax.set_ylabel("eccentricity e (dimensionless)")
        ax.set_title(title, pad=14)
        fig.colorbar(mesh, ax=ax,
                     label=f"MEGNO <Y> (2: quasi-periodic; clipped to 1.8 .. {CHAOTIC + 1:g})")
    newton, gr = maps.values()
    same = gr == newton  # (exact zeros: no log; shown apart, not at a floor)
    diff = np.log10(np.where(same, np.nan, np.abs(gr - newton)))
    mesh = axes[2].pcolormesh(a, e, diff, cmap="viridis", shading="nearest", vmin=-10, vmax=2)
    axes[2].set_facecolor("0.85")  # (the cells where GR changed MEGNO not at all)
    flipped = np.argwhere((newton > CHAOTIC) != (gr > CHAOTIC))
    aa, ee = np.meshgrid(a, e)
    if len(flipped):  # (an empty entry drew a red x for "0 cells")
        axes[2].plot(aa[tuple(flipped.T)], ee[tuple(flipped.T)], "x", color="red", ms=5,
                     label=f"verdict changed (MEGNO {CHAOTIC:g} threshold): "
                           f"{len(flipped)} cells")
    axes[2].set_title(f"what GR changes\n(grey: unchanged or failed, {int(np.sum(same))} "
                      f"cells; "
                      f"verdict changed: {len(flipped)} cells)", pad=14, fontsize=9)
    _resonances(axes[2])
    axes[2].set_xlabel("semi-major axis a [au]")
    axes[2].set_ylabel("eccentricity e (dimensionless)")
    if len(flipped):
        axes[2].legend(loc="lower left", fontsize=7, framealpha=0.9)
    fig.colorbar(mesh, ax=axes[2],
                 label="log10 |MEGNO with GR - MEGNO Newtonian| (dimensionless)")
    fig.suptitle(f"Sun, Jupiter and a Saturn-mass planet: MEGNO after {orbits:g} orbits of "
                 "Jupiter (hamilton-orbits wh, variational equations, Ensemble)")
    path = out / "stability_map.png"
    fig.savefig(path, dpi=110)
    return path


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument("out", nargs="?", default=str(Path(__file__).resolve().parents[1] / "out"))
    parser.add_argument("--n", type=int, default=64, help="cells along a and along e")
    parser.add_argument("--orbits", type=float, default=1e4, help="orbits of Jupiter")
    parser.add_argument("--quick", action="store_true", help="8 x 8 cells, 200 orbits")
    parser.add_argument("--dask", action="store_true", help="a Dask LocalCluster")
    parser.add_argument("--scheduler", help="a running Dask scheduler's address")
    parser.add_argument("--workers", type=int, help="local processes (default: all cores)")
    args = parser.parse_args(argv)
    n, orbits = (8, 200.0) if args.quick else (args.n, args.orbits)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    client = None
    if args.dask or args.scheduler:
        from dask.distributed import Client, LocalCluster

        client = Client(args.scheduler) if args.scheduler else Client(LocalCluster(
            n_workers=args.workers or None, threads_per_worker=1, processes=True))
    maps, tables, walls = {}, [], {}
    for label, effects in (("Newtonian", []), ("with GR (gr_potential)", ["gr_potential"])):
        a, e, megno, _, wall, table = run_map(n, n, orbits, effects, client, args.workers)
        maps[f"MEGNO, {label}"] = megno
        walls[label] = wall
        table["model"] = label
        tables.append(table)
        chaotic = np.nanmean(megno > CHAOTIC)
        print(f"{label:24s} {n} x {n} cells, {orbits:g} orbits: {wall:8.1f} s wall, "
              f"{table.attrs['failures']} failed, chaotic (MEGNO > {CHAOTIC:g}): "
              f"{100 * chaotic:.1f}%, median MEGNO of the regular cells "
              f"{np.nanmedian(np.where(megno <= CHAOTIC, megno, np.nan)):.4f}")
    if client is not None:
        client.close()
    import pandas as pd

    pd.concat(tables).to_csv(out / "stability_map.csv", index=False)
    newton, gr = maps.values()
    changed = int(np.sum((newton > CHAOTIC) != (gr > CHAOTIC)))
    print(f"cells whose verdict GR changes: {changed} of {n * n}")
    print(f"wrote {plot(a, e, maps, out, orbits)}")


if __name__ == "__main__":
    main()
