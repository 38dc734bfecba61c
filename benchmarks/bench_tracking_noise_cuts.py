"""Leave-one-out check of the two constants of the tracking noise calibration
(``abrupt.detect.tracking.noise_scale``): the lower bound's width (``k`` standard errors; 2 in use) and
the misfit cut (``MISFIT_RATIO``, 2.5 in use).

Simulated thesis arcs (Case 1 orbit, Ascension, 5 orbits ≈ 0.37 day) in settings of true noise /
stated sigma ``s`` ∈ {1, 1.5, 2, 3, 5} and cadence {20, 60} s; in each, ``--seeds`` maneuver-free arcs
and as many arcs with a 0.002 m/s transverse apogee burn. Per arc, once: the noise measured on the orbit
fit (what ``calibrate_noise`` measures), its number of second differences n, and the largest GLRT
statistic T of the first scan with the stated sigmas. Sigmas multiplied by f divide every T by f²
(the weighted fit does not change), so for any width k the calibrated factor
f(k) = max(1, noise (1 − k · 1.166/√n)) gives the GLRT's outcome exactly without rerunning it:
an event when T / f(k)² exceeds the GLRT threshold for the budget (0.1/day). (The GLRT then confirms
by nonlinear refits; the linear scan's exceedance is what the calibration changes.)

* standard error: z = (noise/s − 1) / (1.166/√n) on arcs with s ≥ 1; its spread should be 1 if the
  stated standard error is right, and P(f(2) > s) about 2.3 %;
* leave-one-out over the ten settings: k is chosen on the nine others as the largest k in the grid
  (the most power) whose pooled false alarms per day stay at or below the stated rate; the held-out
  setting's false alarms (rate, Poisson interval) and burns found at that k are reported beside k = 2;
* misfit cut: total residual RMS / max(noise, 1) on the maneuver-free arcs, whose model is right;
  the largest value of the nine other settings × 1.5 against the held-out largest value, beside 2.5.
  Arcs whose model is wrong (the other side of the cut) are not simulated here.

    PYTHONPATH=src nice -n 10 python benchmarks/bench_tracking_noise_cuts.py [--seeds N]

Prints CPU time (the machine is shared).

The calibration's two constants, `python benchmarks/bench_tracking_noise_cuts.py`
---------------------------------------------------------------------------------

The lower bound's width (2 standard errors) and the misfit cut (2.5) of `calibrate_noise`, checked on simulated
thesis arcs with true noise 1, 1.5, 2, 3 and 5 × the stated sigmas at 20 s and 60 s cadence (ten settings, 16
maneuver-free and 16 arcs with a 0.002 m/s burn each, independent noise in each; the GLRT's first scan, whose
statistic scales exactly as 1/factor², so every width is evaluated on the same arcs; 58 s CPU). Written to
`docs/results/bench_tracking_noise_cuts.txt`.

* The stated standard error of the noise estimate (1.166/√n) is too small: the measured spread is 1.25 times it
  (all arcs; 1.0-1.6 by setting), so the "2σ" bound is nearer 1.6σ and lies above the true ratio on 4 % of arcs
  instead of 2.3 %.
* Width, all settings (in-sample): 0 false alarms in 59.7 maneuver-free days for every width up to 2 (142/160
  small burns found at 2, 133/160 at 0); 3 at 2.5, 5 at 3, 8 at 4 (0.13/day [0.06, 0.26]). Leave-one-out,
  choosing on nine settings the widest bound whose false alarms stay at or below the stated rate: widths 3-4 are
  chosen and the held-out settings give 7 false alarms in 59.7 days, 0.117/day [0.047, 0.242], above the stated
  0.1 (146/160 found), where 2 gives 0 [0, 0.062] (142/160). The width stays 2: it is the widest without a false
  alarm on any setting.
* Misfit cut: the residual RMS over the noise stays at or below 1.11 on every arc whose model is right, so 2.5
  refuses none of them (nor would a cut of 1.7, 1.5 times the largest of the other nine settings). How small a
  wrong model the cut still catches was not simulated; the cut stays 2.5.
"""

from __future__ import annotations

import argparse
import math
import time
from dataclasses import replace

import numpy as np

from abrupt import api
from abrupt.detect.tracking.glrt import glrt_scan, glrt_threshold_fit
from abrupt.detect.tracking.noise_scale import MAD_SCALE_SE, MISFIT_RATIO, residual_scales
from abrupt.model.orbit.batch_fit import fit_orbit
from abrupt.simulate.tle_own_null import poisson_interval

STATED_PER_DAY = 0.1
NOISE_RATIOS = (1.0, 1.5, 2.0, 3.0, 5.0)
CADENCES_S = (20.0, 60.0)
DV_MPS = 0.002
K_GRID = (0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 4.0)


def arc(s: float, cadence: float, dv: float, seed: int) -> dict[str, float]:
    """Noise, n, total RMS of the orbit fit, and the first GLRT scan's largest T over its threshold."""
    burns = (api.thesis_burn("apogee", "S", dv),) if dv > 0 else ()
    scenario = api.TrackingScenario(stations=(api.ascension(),), cadence_s=cadence, burns=burns, noise_scale=s)
    sim = api.simulate_tracking(scenario, seed=seed)
    data = api.TrackingArrays(sim.measurements, {}, epoch_utc=sim.epoch_utc)
    series = api.TrackingSeries(data, sim.initial_state, api.BatchFitConfig())
    scales = residual_scales(data, series.orbit_fit())
    # the GLRT's own fit: no outlier rejection while searching (as detect_maneuvers_glrt)
    fit = fit_orbit(data, series.orbit_fit().x0, config=replace(series.fit_config, outlier_sigma=None))
    step = series.orbit_period_s() / 120.0
    t0, t1 = float(data.t_s.min()), float(data.t_s.max())
    cand = np.arange(t0 + step, t1, step)
    thr = glrt_threshold_fit(cand.size, (t1 - t0) / 86400.0, api.FalseAlarmBudget(STATED_PER_DAY, "day")).value
    t_max = float(np.nanmax(glrt_scan(data, fit, cand).statistic))
    return {
        "s": s,
        "noise": scales.noise,
        "n": float(scales.n_differences),
        "total": scales.total,
        "t_over_thr": t_max / thr,
        "days": (t1 - t0) / 86400.0,
    }


def factor(noise: float, n: float, k: float) -> float:
    return max(1.0, noise * (1.0 - k * MAD_SCALE_SE / math.sqrt(n)))


def outcomes(arcs: list[dict[str, float]], k: float) -> tuple[int, float]:
    """Exceedances of the GLRT threshold with sigmas calibrated at width k, and the arcs' days."""
    hits = sum(int(a["t_over_thr"] / factor(a["noise"], a["n"], k) ** 2 > 1.0) for a in arcs)
    return hits, sum(a["days"] for a in arcs)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=16, help="arcs per setting and kind (default 16)")
    args = parser.parse_args()
    cpu0 = time.process_time()
    settings = [(s, c) for c in CADENCES_S for s in NOISE_RATIOS]
    # independent noise in every setting and kind (one seed each), so that held-out arcs are new data
    null = {st: [arc(*st, 0.0, 10_000 + 1000 * j + i) for i in range(args.seeds)] for j, st in enumerate(settings)}
    burn = {st: [arc(*st, DV_MPS, 50_000 + 1000 * j + i) for i in range(args.seeds)] for j, st in enumerate(settings)}
    print(
        f"{args.seeds} maneuver-free and {args.seeds} burn ({DV_MPS} m/s) arcs per setting; stated {STATED_PER_DAY}/day"
    )
    print("\nstandard error of the noise estimate (stated: 1.166/sqrt(n))")
    print(f"{'s':>5}{'cadence':>9}{'n (median)':>12}{'z mean':>8}{'z sd':>7}{'P(f(2) > s)':>13}")
    for st in settings:
        z = [(a["noise"] / a["s"] - 1.0) / (MAD_SCALE_SE / math.sqrt(a["n"])) for a in null[st] + burn[st]]
        over = np.mean([factor(a["noise"], a["n"], 2.0) > a["s"] for a in null[st] + burn[st]])
        n_med = np.median([a["n"] for a in null[st]])
        print(f"{st[0]:>5.1f}{st[1]:>8.0f}s{n_med:>12.0f}{np.mean(z):>8.2f}{np.std(z, ddof=1):>7.2f}{over:>13.2f}")
    print("\nleave-one-out width k of the lower bound (GLRT, first scan)")
    print(
        f"{'held out':<14}{'k':>5}{'false alarms':>14}{'days':>7}{'rate/day':>10}{'95 % interval':>17}"
        f"{'found':>8}   {'at k=2: fa':>10}{'found':>7}"
    )
    totals = {"loo": [0, 0.0, 0], "k2": [0, 0.0, 0]}
    for held in settings:
        train_null = [a for st in settings if st != held for a in null[st]]
        ok = [k for k in K_GRID if outcomes(train_null, k)[0] <= STATED_PER_DAY * outcomes(train_null, k)[1]]
        k_loo = max(ok) if ok else min(K_GRID)
        fa, days = outcomes(null[held], k_loo)
        found = outcomes(burn[held], k_loo)[0]
        fa2, _ = outcomes(null[held], 2.0)
        found2 = outcomes(burn[held], 2.0)[0]
        lo, hi = poisson_interval(fa, days)
        label = f"s={held[0]:g}, {held[1]:.0f} s"
        print(
            f"{label:<14}{k_loo:>5.1f}{fa:>14d}{days:>7.2f}{fa / days:>10.3f}{f'[{lo:.3f}, {hi:.3f}]':>17}"
            f"{found:>5d}/{len(burn[held]):<2d}{fa2:>11d}{found2:>5d}/{len(burn[held]):<2d}"
        )
        for key, (f, d, g) in (("loo", (fa, days, found)), ("k2", (fa2, days, found2))):
            totals[key][0] += f
            totals[key][1] += d
            totals[key][2] += g
    n_burn = sum(len(v) for v in burn.values())
    for key, label in (("loo", "held out, pooled"), ("k2", "k = 2, pooled")):
        f, d, g = totals[key]
        lo, hi = poisson_interval(int(f), d)
        print(f"{label:<19}{int(f):>14d}{d:>7.2f}{f / d:>10.3f}{f'[{lo:.3f}, {hi:.3f}]':>17}{int(g):>5d}/{n_burn}")
    print("\nevery width k on all settings (in-sample)")
    print(f"{'k':>5}{'false alarms':>14}{'days':>7}{'rate/day':>10}{'95 % interval':>17}{'found':>9}")
    all_null = [a for st in settings for a in null[st]]
    all_burn = [a for st in settings for a in burn[st]]
    for k in K_GRID:
        fa, days = outcomes(all_null, k)
        lo, hi = poisson_interval(fa, days)
        found = outcomes(all_burn, k)[0]
        interval = f"[{lo:.3f}, {hi:.3f}]"
        print(f"{k:>5.1f}{fa:>14d}{days:>7.2f}{fa / days:>10.3f}{interval:>17}{found:>5d}/{len(all_burn)}")
    z_all = [(a["noise"] / a["s"] - 1.0) / (MAD_SCALE_SE / math.sqrt(a["n"])) for a in all_null + all_burn]
    print(f"z over all arcs: sd {np.std(z_all, ddof=1):.2f} (1 if the stated standard error were right)")
    print(f"\nmisfit cut (in use {MISFIT_RATIO}): total RMS / max(noise, 1) on maneuver-free arcs (right model)")
    print(f"{'held out':<14}{'largest':>9}{'cut from others x1.5':>22}")
    for held in settings:
        ratio = max(a["total"] / max(a["noise"], 1.0) for a in null[held])
        others = max(a["total"] / max(a["noise"], 1.0) for st in settings if st != held for a in null[st])
        print(f"{f's={held[0]:g}, {held[1]:.0f} s':<14}{ratio:>9.3f}{1.5 * others:>22.3f}")
    print(f"\nCPU time {time.process_time() - cpu0:.0f} s")


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results("bench_tracking_noise_cuts", variant({"--seeds": "seeds"})):
        main()
