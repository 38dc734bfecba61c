"""ρB from real TLE histories against NRLMSIS along the same orbits.

For CryoSat-2 (~720 km, 2010-2022) and Sentinel-3A (815 km, 2016-2022): 30-day windows, maneuvers
removed with abrupt's TLE maneuver detector; prints the correlation of log(ρB) with log(ρ_MSIS), the
robust scatter of log(ρB/ρ_MSIS) (1.4826·MAD), the implied B, the yearly means (the 2014 maximum and
the 2019-2020 minimum must show) and the run time of the ρB step alone (target < 10 s for ten years).
Writes docs/results/density_real.png.

    python benchmarks/bench_density_real.py

**Acceptance 3: real data** — `python benchmarks/bench_density_real.py` (output:
`docs/results/bench_density_real.txt`; 30-day windows, maneuvers from abrupt's TLE detector plus the orbit-rise
cut), against NRLMSIS 2.1 along the same SGP4 orbits:

* CryoSat-2 2010-2022 (720 km): sets: 4310; maneuvers detected: 120; windows used: 151 / 151; corr log ρ
  (Pearson / Spearman): 0.809 / 0.874; scatter of log(ρB/ρ_M): 0.32 (38 %); implied B (m²/kg): 0.0130
* Sentinel-3A 2016-2022 (815 km): sets: 2387; maneuvers detected: 54; windows used: 80 / 80; corr log ρ (Pearson
  / Spearman): 0.818 / 0.913; scatter of log(ρB/ρ_M): 0.13 (14 %); implied B (m²/kg): 0.0204

Yearly means (ρB/B̂ vs NRLMSIS, kg/m³), CryoSat-2: 2014 **2.60e-14** vs 3.13e-14 (maximum); 2019 **4.52e-15** vs
4.84e-15, 2020 5.84e-15 vs 5.29e-15 (minimum; 2018 4.55e-15); Sentinel-3A 2019 2.50e-15 vs 2.80e-15, 2020
2.67e-15 vs 3.00e-15 (minimum), 2022 8.03e-15 vs 7.74e-15 (abrupt's TLE maneuver detector, NRLMSIS interpolated
by splines). The 2014 maximum and 2019-2020 minimum show: `docs/results/density_real.png`. The outliers are the
commissioning months (CryoSat-2 2010, Sentinel-3A 2016: orbit acquisition). The shared data has Sentinel-3A from
2016 only. **Met.**
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pandas as pd

from abrupt.density.tle_drag import TleDragConfig, rho_b_from_history
from abrupt.readers.tle import read_tle
from abrupt.report.density import plot_density_bands

DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "tle"
OUT = Path(__file__).resolve().parents[1] / "docs" / "results" / "density_real.png"


def main() -> None:
    frames = []
    for name in ("CryoSat-2", "Sentinel-3A"):
        h = read_tle(DATA / f"{name}.tle")
        years = (h.elements["epoch_utc"].iloc[-1] - h.elements["epoch_utc"].iloc[0]).days / 365.25
        t0 = time.perf_counter()
        rho_b_from_history(h, TleDragConfig(interval_days=30.0), maneuvers="none")
        t_none = time.perf_counter() - t0
        t0 = time.perf_counter()
        fast = rho_b_from_history(h, TleDragConfig(interval_days=30.0), maneuvers="detect")
        t_detect = time.perf_counter() - t0
        res = rho_b_from_history(
            h, TleDragConfig(interval_days=30.0, with_model=True), maneuvers=fast.maneuver_epochs_utc, name=name
        )
        w = res.windows
        ok = (w["status"] == "ok") & (w["rho_b_per_m"] > 0)
        lk, lm = np.log(w["rho_b_per_m"][ok]), np.log(w["model_density_kg_m3"][ok])
        ratio = lk - lm
        mad = 1.4826 * float(np.median(np.abs(ratio - np.median(ratio))))
        print(f"== {name}: {len(h)} element sets, {years:.1f} years, {len(res.maneuver_epochs_utc)} maneuvers detected")
        print(
            f"   windows {len(w)}, used {int(ok.sum())}, rejected {int((~ok).sum())} "
            f"(negative decay {int((w['status'] == 'negative decay').sum())})"
        )
        print(
            f"   corr(log ρB, log ρ_MSIS) = {np.corrcoef(lk, lm)[0, 1]:.3f} (Pearson), "
            f"{pd.Series(lk.to_numpy()).corr(pd.Series(lm.to_numpy()), method='spearman'):.3f} (Spearman)"
        )
        print(
            f"   implied B = median(ρB/ρ_MSIS) = {np.exp(np.median(ratio)):.4f} m²/kg; "
            f"robust scatter of log ratio {mad:.2f} ({np.expm1(mad):.0%})"
        )
        yearly = w[ok].groupby(w[ok]["window_start_utc"].dt.year)[["rho_b_per_m", "model_density_kg_m3"]].mean()
        yearly["rho_b/B"] = yearly["rho_b_per_m"] / np.exp(np.median(ratio))
        print("   yearly mean density (kg/m³): year, ρB/B, NRLMSIS")
        for year, row in yearly.iterrows():
            print(f"     {year}  {row['rho_b/B']:.2e}  {row['model_density_kg_m3']:.2e}")
        print(
            f"   time ρB only: {t_none:.1f} s without detector, {t_detect:.1f} s with the maneuver detector "
            f"({years:.1f} years; target < 10 s for 10 years)"
        )
        frames.append(w)
    OUT.parent.mkdir(parents=True, exist_ok=True)
    plot_density_bands(
        pd.concat(frames, ignore_index=True),
        OUT,
        band_km=100.0,
        title="CryoSat-2 (700-800 km band) and Sentinel-3A (800-900 km): ρB/B̂ vs NRLMSIS 2.1",
    )
    print(f"plot: {OUT}")


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results("bench_density_real", variant({})):
        main()
