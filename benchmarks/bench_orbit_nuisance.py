"""Estimated nuisance parameters on the real arcs: post-fit residuals, whiteness
of the null and the estimates, with and without the nuisance states.

For each real SP3 arc in ../shared/data/sp3 (Sentinel-3A 9.1 days, Jason-1 9.9 days, 60 s) the default
detector (`orbit.glr`, auto tuning, EGM2008 40×40 + Sun/Moon) runs once as it is and once with
``nuisance=True`` (drag and SRP scale factors with NRLMSIS drag tabulated along the observed orbit, six
once-per-rev empirical accelerations in the orbit frame, all random walks), and optionally with the
position sigma overridden (``--sigma-pos-m``). Printed per run:

- post-fit RMS (measurement − forward a-posteriori state) of position and velocity, RMS of the smoothed
  Gauss-Markov acceleration;
- whiteness of the forward position innovations in the orbit frame: autocorrelation at lags 1, 2, 5, 10,
  30 and ~one orbit (100 samples), and the Ljung-Box statistic over 20 lags (χ²₂₀: 31.4 at 5 %);
- the GLR null against its law: c = median / χ²₃ median, and the 99.9 % quantile and maximum in units of c
  (χ²₃: 16.3 at 99.9 %);
- the end-of-arc nuisance estimates with 1σ.

    nice python benchmarks/bench_orbit_nuisance.py [--sigma-pos-m 0.001]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

import numpy as np
from scipy import stats

from abrupt.model.orbit import rtn_matrix
from abrupt.pipelines.orbit import detect_orbit
from abrupt.readers.sp3 import read_sp3

DATA = Path(__file__).resolve().parents[1].parent / "shared/data/sp3"
ARCS = {"Sentinel-3A": DATA / "ssas3a20.b18358.e19003.DG_.sp3", "Jason-1": DATA / "ssaja102.b03007.e03017.DGS.sp3"}
LAGS = (1, 2, 5, 10, 30, 100)


def autocorrelation(z: np.ndarray, lag: int) -> float:
    z = z - z.mean()
    return float(z[:-lag] @ z[lag:] / (z @ z))


def one_run(eph: Any, settings: dict[str, Any]) -> None:
    c0 = time.process_time()
    run = detect_orbit(eph, budget="1/week", **settings)
    cpu = time.process_time() - c0
    an = run.analysis
    s = run.summary
    ok = an.valid & np.isfinite(an.forward.innovation).all(axis=1)
    x = an.forward.x[ok]
    inn = an.forward.innovation[ok, :3]
    rtn = np.array([rtn_matrix(xx[:3], xx[3:6])[0].T @ d for xx, d in zip(x, inn, strict=True)])
    label = ", ".join(f"{k}={v}" for k, v in settings.items()) or "default"
    print(f"  [{label}] {len(run.events)} events, {cpu:.1f} s CPU")
    print(
        f"    post-fit RMS {1e3 * s['residual_rms_pos_m']:.2f} mm, {1e3 * s['residual_rms_vel_mps']:.3f} mm/s; "
        f"DMC RMS {s['dmc_accel_rms_mps2']:.3g} m/s²; σ_pos {1e3 * s['sigma_pos_m']:.2g} mm"
    )
    n = len(rtn)
    for i, axis in enumerate("RTN"):
        r = [autocorrelation(rtn[:, i], lag) for lag in LAGS]
        q = n * (n + 2) * sum(autocorrelation(rtn[:, i], k) ** 2 / (n - k) for k in range(1, 21))
        print(
            f"    innovation {axis}: RMS {1e3 * rtn[:, i].std():.2f} mm, ACF "
            + " ".join(f"{lag}:{v:+.2f}" for lag, v in zip(LAGS, r, strict=True))
            + f", Ljung-Box(20) {q:.0f}"
        )
    g = an.statistics["glr"]
    g = g[np.isfinite(g)]
    c = float(np.median(g)) / float(stats.chi2.median(3))
    print(
        f"    GLR null: c = {c:.3f}; q99.9/c = {np.quantile(g, 0.999) / c:.1f}, max/c = {g.max() / c:.1f} "
        f"(χ²₃: {stats.chi2.isf(1e-3, 3):.1f}); threshold {run.thresholds['glr'].value:.3g}"
    )
    for name, (value, sigma) in s.get("nuisance", {}).items():
        shown = 1.0 + value if name.endswith("scale") else value
        print(f"    {name:<11} {shown:+.3g} ± {sigma:.2g}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sigma-pos-m", type=float, default=None, help="also run with this position sigma")
    parser.add_argument("--arc", choices=["all", *ARCS], default="all")
    args = parser.parse_args()
    for label, path in ARCS.items():
        if args.arc not in ("all", label):
            continue
        eph = read_sp3(path).to_frame("GCRF")
        print(f"\n{label}: {path.name}, {len(eph)} epochs, {eph.seconds[-1] / 86400:.1f} days")
        runs: list[dict[str, Any]] = [{}, {"nuisance": True}]
        if args.sigma_pos_m is not None:
            runs += [{"sigma_pos_m": args.sigma_pos_m}, {"nuisance": True, "sigma_pos_m": args.sigma_pos_m}]
        for settings in runs:
            one_run(eph, settings)


if __name__ == "__main__":
    from _results import write_results

    with write_results("bench_orbit_nuisance"):
        main()
