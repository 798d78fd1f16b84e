"""
The Chandler wobble in the IERS 20 C04 record, against the rigid and elastic Earth.
===================================================================================

The observed pole since 1962 (astropy-iers-data, read offline) is fitted with a
linear trend, a prograde Chandler term and prograde and retrograde annual terms
(rigid.polar_motion.fit_wobble, periods fitted nonlinearly).  The periodogram
shows the Chandler line at ~433 d, far from the rigid-Earth Euler period of
~304 d (rigid.earth.euler_period) and next to the annual line.  The linear
Liouville pole (rigid.polar_motion.LiouvillePole) with the effects "elastic"
(the fitted Chandler period), "damping" (Q = 179, Wilson & Vicente 1990,
Geophys. J. Int. 102, 29) and "annual_excitation" (the forcing that produces the
fitted annual terms, chi = m (sigma_c - w) / sigma_c) is started from the data
and run against them; without a stochastic excitation its Chandler term decays,
while the observed one is re-excited (and collapsed after 2010, see the
amplitude per decade).

Writes <out>/chandler_wobble.png and <out>/chandler_wobble.txt.
Run: python examples/earth_pole/chandler_wobble.py [out_dir] [--quick]
(--quick uses 1980-2010 and a coarser periodogram).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import astropy.units as u
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from rigid import earth
from rigid.polar_motion import LiouvillePole, fit_wobble, load_c04, periodogram

Q_CITED = 179.0  # Wilson & Vicente 1990 (68% range about 74-789)


def main(argv: list[str] | None = None) -> str:
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument("out", nargs="?", default=str(Path(__file__).resolve().parents[1] / "out"),
                        help="output directory (default examples/out)")
    parser.add_argument("--quick", action="store_true", help="1980-2010, coarser spectrum")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    record = load_c04()
    start, end = (1980, 2010) if args.quick else (None, None)
    fit = fit_wobble(record, start, end)
    rec = record.select(start, end)

    # the Liouville model: elastic (fitted period) + damping (cited Q) + annual excitation
    t = rec.time.mjd - fit.epoch.mjd
    sig = 2 * np.pi / fit.chandler_period.to_value(u.day) * (1 + 0.5j / Q_CITED)
    w_a = 2 * np.pi / fit.annual_period.to_value(u.day)
    c_p = fit.annual_amplitude * np.exp(1j * fit.annual_phase.to_value(u.rad))
    c_r = fit.annual_retrograde_amplitude * np.exp(1j * fit.annual_retrograde_phase.to_value(
        u.rad))
    model = LiouvillePole(
        ("elastic", "damping", "annual_excitation"),
        chandler_period=fit.chandler_period, Q=Q_CITED, annual_period=fit.annual_period,
        annual_prograde=c_p * (sig - w_a) / sig, annual_retrograde=c_r * (sig + w_a) / sig,
    )
    trend = fit.mean_pole + fit.drift * (t * u.day).to(u.yr)
    m_obs = rec.m.to(u.mas) - trend
    m_model = model.solve(t * u.day, m_obs[0])

    n_f = 301 if args.quick else 1501
    pg = periodogram(rec, np.linspace(-1.5, 1.5, n_f) / u.yr)

    table = fit.amplitude_by_decade
    rows = [
        ("window", f"{fit.start.iso[:10]} .. {fit.end.iso[:10]}", ""),
        ("Euler period (rigid, axisymmetric)", f"{earth.euler_period().to_value(u.day):.2f}",
         "d"),
        ("Chandler period", f"{fit.chandler_period.to_value(u.day):.2f} +- "
         f"{fit.chandler_period_error.to_value(u.day):.2f}", "d"),
        ("  formal error (uncorrelated residuals)",
         f"{fit.chandler_period_error_formal.to_value(u.day):.3f}", "d"),
        ("annual period", f"{fit.annual_period.to_value(u.day):.2f} +- "
         f"{fit.annual_period_error.to_value(u.day):.2f}", "d"),
        ("Chandler amplitude / phase", f"{fit.chandler_amplitude.to_value(u.mas):.1f} / "
         f"{fit.chandler_phase.to_value(u.deg):.1f}", "mas / deg"),
        ("annual prograde amplitude / phase", f"{fit.annual_amplitude.to_value(u.mas):.1f} / "
         f"{fit.annual_phase.to_value(u.deg):.1f}", "mas / deg"),
        ("annual retrograde amplitude / phase",
         f"{fit.annual_retrograde_amplitude.to_value(u.mas):.1f} / "
         f"{fit.annual_retrograde_phase.to_value(u.deg):.1f}", "mas / deg"),
        ("rms residual (per component)", f"{fit.rms_residual.to_value(u.mas):.1f}", "mas"),
        ("effective k2 for this period", f"{effective_k2(fit.chandler_period):.4f}", ""),
        ("Q (line width; see caveat)", f"{fit.q_estimate:.0f}", ""),
    ]
    width = max(len(r[0]) for r in rows)
    lines = [f"{n:<{width}}  {v:>22}  {un}" for n, v, un in rows]
    lines.append("")
    lines.append("decade  Chandler amplitude (mas)  annual amplitude (mas)")
    for row in table:
        lines.append(f"{row['decade']:>6}  {row['chandler_amplitude'].to_value(u.mas):>24.1f}"
                     f"  {row['annual_amplitude'].to_value(u.mas):>22.1f}")
    lines.append("")
    lines.append("Q caveat: " + fit.q_caveat)
    text = "\n".join(lines)
    (out / "chandler_wobble.txt").write_text(text + "\n")

    fig, axes = plt.subplots(2, 2, figsize=(12, 9))
    ax = axes[0, 0]
    ax.plot(rec.x.to_value(u.mas), rec.y.to_value(u.mas), lw=0.3)
    ax.set_xlabel("x_p, terrestrial axes, towards Greenwich (mas)")
    ax.set_ylabel("y_p, terrestrial axes, towards 90° W (mas)")
    ax.set_aspect("equal")
    ax.set_title("observed pole, IERS 20 C04")
    ax = axes[0, 1]
    ax.plot(pg["frequency"].to_value(1 / u.yr), pg["amplitude"].to_value(u.mas), lw=0.8)
    for period, label, style in (
        (earth.euler_period(), "Euler (rigid)", "k:"),
        (fit.chandler_period, "Chandler", "r--"),
        (fit.annual_period, "annual", "g--"),
        (-fit.annual_period, "annual retro.", "g:"),
    ):
        f = (1 / period).to_value(1 / u.yr)
        ax.axvline(f, color=style[0], ls=style[1:], lw=1, label=label)
    ax.set_xlabel("frequency (cycles/yr; > 0 prograde)")
    ax.set_ylabel("amplitude (mas)")
    ax.set_title("periodogram")
    ax.legend(fontsize=8)
    ax = axes[1, 0]
    years = fit.epoch.jyear + t / 365.25
    ax.plot(years, m_obs.real.to_value(u.mas), lw=0.5, label="observed (trend removed)")
    ax.plot(years, m_model.real.to_value(u.mas), lw=0.8,
            label=f"Liouville: elastic + damping (Q = {Q_CITED:.0f}) + annual")
    ax.set_xlabel("year")
    ax.set_ylabel("m1 = x_p, towards Greenwich (mas)")
    ax.legend(fontsize=8, loc="lower left")
    ax.set_title("linear Liouville model against the data")
    ax = axes[1, 1]
    ax.bar(table["decade"] + 5, table["chandler_amplitude"].to_value(u.mas), width=8,
           label="Chandler")
    ax.plot(table["decade"] + 5, table["annual_amplitude"].to_value(u.mas), "go-",
            label="annual (prograde)")
    ax.set_xlabel("decade")
    ax.set_ylabel("amplitude (mas)")
    ax.set_title("amplitude per decade")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "chandler_wobble.png", dpi=110)
    plt.close(fig)
    print(text)
    return text


def effective_k2(period: u.Quantity) -> float:
    """The k2 of sigma_c = sigma_E (1 - k2/k_s) that gives ``period``."""
    ks = float(earth.secular_love_number())
    return ks * (1.0 - float(earth.euler_period() / period))


if __name__ == "__main__":
    main()
