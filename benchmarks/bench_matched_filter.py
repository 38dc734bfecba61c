"""Matched-filter reproduction (Bennett 2022 §2.4.1, spec §3.1-3.4) and detection-power curves.

Prints, beside the thesis targets:

1. the wavelets (largest unsaturated strike per axis) and the analytic filter-output noise;
2. thresholds at alpha = 1e-4 by the thesis ROC / likelihood-ratio (Neyman-Pearson) procedure, with
   30 mg (attitude) and 40 mg (rate) strike distributions, beside a Gaussian fit;
3. Acceptance 2: detection rate of 60 mg strikes by the attitude filter and 80 mg by the rate filter,
   about body x and in random directions;
4. Table 2.3: mean / sd error of the wavelet-bank size estimate (MMSE, RSSE, MAE, cubic) over
   correctly detected strikes of random size (1-100 mg) and direction;
5. Acceptance 3: probability of detection vs |dH| (random directions) at one false alarm per day of
   10 Hz telemetry, for the attitude and rate filters, the GLRT on attitude + rate ("combined") and
   the GLRT on attitude + rate + wheel speeds with a 200-sample baseline ("joint"), with the 90% point.

Both rate-noise settings are run: 2e-4 rad/s (Table 2.1) and 4e-5 rad/s (spec §3.6, SPRT-consistent).

    python benchmarks/bench_matched_filter.py --quick      # about a minute
    python benchmarks/bench_matched_filter.py              # 1000-run studies

Measured figures
----------------

All from `python benchmarks/bench_matched_filter.py` (1000-run studies, about 7 min on one core; `--quick` about
1 min with 100-200 runs, output `docs/results/bench_matched_filter_quick.txt`). Thesis spacecraft, gains K = 480
N·m, P = 1080 N·m·s, 10 Hz telemetry, attitude telemetry noise 7e-5, wheel 0.25 rad/s, and both rate-noise
settings: 2e-4 rad/s (Table 2.1) and 4e-5 rad/s (the value the thesis's thresholds imply; attitude-simulator.md,
Telemetry). Strikes at a random time, random directions unless stated; event-free statistics from 8 h of
simulated telemetry.

**Event-free output sd [N·m·s]** (measured vs white-noise analytic): attitude 0.0225/0.0223/0.0226 vs 0.0225;
rate at 2e-4: 0.163/0.150/0.176 vs 0.164/0.150/0.176; rate at 4e-5: 0.0326/0.0299/0.0353 vs
0.0327/0.0299/0.0353.

**Thresholds at α = 1e-4 (two-sided, per axis, x/y/z) [N·m·s]**

* attitude: Neyman-Pearson (KDE ROC/LRT): 0.096 / 0.090 / 0.098; Gaussian fit: 0.088 / 0.087 / 0.088; as mg
  about the axis: 12 / 11 / 12
* rate, 2e-4: Neyman-Pearson (KDE ROC/LRT): 0.660 / 0.580 / 0.691; Gaussian fit: 0.635 / 0.582 / 0.686; as mg
  about the axis: 83 / 73 / 86
* rate, 4e-5: Neyman-Pearson (KDE ROC/LRT): 0.132 / 0.116 / 0.137; Gaussian fit: 0.127 / 0.117 / 0.137; as mg
  about the axis: 17 / 15 / 17

The KDE-based Neyman-Pearson value sits slightly above the Gaussian one (the kernel widens the tail); the
likelihood ratio τ is ≈ 0 where the 30/40 mg strike distribution lies far above the threshold, which is the case
for our filters except the rate filter at 2e-4.

**Acceptance 2: detection at α = 1e-4** (1000 runs each; ± is the 95% interval)

* attitude MF, 60 mg about x: Table 2.1 (rate 2e-4): 100.0%; rate 4e-5 (implied by the thesis thresholds):
  100.0%; target: ≥ 90%
* attitude MF, 60 mg random direction: Table 2.1 (rate 2e-4): 100.0%; rate 4e-5 (implied by the thesis
  thresholds): 100.0%; target: ≥ 90%
* rate MF, 80 mg about x: Table 2.1 (rate 2e-4): 55.8% ± 3.1; rate 4e-5 (implied by the thesis thresholds):
  100.0%; target: ≥ 90%
* rate MF, 80 mg random direction: Table 2.1 (rate 2e-4): 42.0% ± 3.1; rate 4e-5 (implied by the thesis
  thresholds): 100.0%; target: ≥ 90%

The rate-filter result at Table 2.1's 2e-4 rad/s is not a shortfall of the implementation: the filter's output
sd is then 0.15-0.18 N·m·s per axis (analytic, and measured), so its α = 1e-4 threshold is 3.9 sd ≈ 0.58-0.69
N·m·s, i.e. 73-86 mg about the axis; an 80 mg strike sits at the threshold and is found about half the time. The
thesis's "consistently detects > 80 mg" therefore needs the lower rate noise, which is independent support for
the reconciliation in attitude-simulator.md (Telemetry) that the thesis simulations used ≈ 4e-5 rad/s. Our
attitude filter is stronger than the thesis's (it reaches 90% at about 25 mg, not 60 mg); the thesis gives no
detail (normalisation, exact noise) that would explain its weaker figure.

**Table 2.3: size error of the bank estimate** (estimated − true |ΔH| in mg, mean ± sd; strikes of 1-100 mg in
random directions, correctly detected only; 1000 runs)

* MMSE: attitude, rate-noise 2e-4 run: +0.51 ± 3.1; attitude, 4e-5 run: +0.25 ± 3.0; attitude, thesis: +1.4 ±
  8.7; rate, 2e-4: +25.3 ± 17.5; rate, 4e-5: +1.49 ± 4.2; rate, thesis: −4.46 ± 13.1
* RSSE: attitude, rate-noise 2e-4 run: +0.51 ± 3.1; attitude, 4e-5 run: +0.25 ± 3.0; attitude, thesis: +1.4 ±
  8.7; rate, 2e-4: +25.3 ± 17.5; rate, 4e-5: +1.49 ± 4.2; rate, thesis: −4.46 ± 13.1
* MAE: attitude, rate-noise 2e-4 run: +0.72 ± 3.7; attitude, 4e-5 run: +0.26 ± 3.7; attitude, thesis: +2.0 ±
  10.9; rate, 2e-4: +26.1 ± 20.9; rate, 4e-5: +1.65 ± 5.1; rate, thesis: −2.95 ± 14.3
* cubic: attitude, rate-noise 2e-4 run: +0.54 ± 3.3; attitude, 4e-5 run: +0.39 ± 3.1; attitude, thesis: +1.5 ±
  9.1; rate, 2e-4: +25.9 ± 18.9; rate, 4e-5: +1.69 ± 4.5; rate, thesis: −4.50 ± 13.2
* least squares (filter amplitude, ours): attitude, rate-noise 2e-4 run: +0.56 ± 2.9; attitude, 4e-5 run: +0.38
  ± 2.9; attitude, thesis: —; rate, 2e-4: +27.2 ± 17.9; rate, 4e-5: +1.56 ± 4.1; rate, thesis: —
* detected: attitude, rate-noise 2e-4 run: 867/1000; attitude, 4e-5 run: 876/1000; rate, 2e-4: 183/1000; rate,
  4e-5: 834/1000

MMSE and RSSE agree exactly, as in the thesis. At 2e-4 rad/s the rate filter finds only the strikes that noise
pushed over the threshold (183/1000), hence the positive bias (selection, not estimator bias); at 4e-5 it is
unbiased to within 2 mg.

**Acceptance 3: P_D vs |ΔH| at one false alarm per day of 10 Hz telemetry** (random directions, 300 runs per
size; 90% point by linear interpolation). Thresholds: per-axis Gaussian fits at p_fa/3 each; GLRTs the larger of
χ²(3) = 30.36 and the Gamma fit of 8 h of event-free T.

Table 2.1 rate noise (2e-4 rad/s):

* attitude: ΔH: 0; [mg]: 0; 2.5: 0; 3: 0; 3.5: 0; 4: 0.7; 5: 1.3; 7.5: 31.0; 10: 84.3; 15: 100; 20: 100; 30:
  100; 40: 100; 60: 100; 80: 23.6 mg = 0.189 N·m·s
* rate: ΔH: 0; [mg]: 0; 2.5: 0; 3: 0; 3.5: 0; 4: 0; 5: 0; 7.5: 0; 10: 0; 15: 0; 20: 0.3; 30: 1.3; 40: 10.3; 60:
  28.0; 80: not reached by 100 mg
* combined: ΔH: 0; [mg]: 0; 2.5: 0; 3: 0; 3.5: 0.3; 4: 0.7; 5: 5.3; 7.5: 57.7; 10: 96.7; 15: 100; 20: 100; 30:
  100; 40: 100; 60: 100; 80: 19.1 mg = 0.153 N·m·s
* joint: ΔH: 47.0; [mg]: 77.0; 2.5: 91.3; 3: 98.0; 3.5: 100; 4: 100; 5: 100; 7.5: 100; 10: 100; 15: 100; 20:
  100; 30: 100; 40: 100; 60: 100; 80: 3.5 mg = 0.028 N·m·s

Spec §3.6 rate noise (4e-5 rad/s):

* attitude: ΔH: 0; [mg]: 0; 2.5: 0; 3: 0; 3.5: 0.3; 4: 0; 5: 1.7; 7.5: 32.0; 10: 81.7; 15: 100; 20: 100; 30:
  100; 40: 100; 60: 100; 80: 24.5 mg = 0.196 N·m·s
* rate: ΔH: 0; [mg]: 0; 2.5: 0; 3: 0; 3.5: 0; 4: 0; 5: 0.7; 7.5: 6.7; 10: 25.0; 15: 87.7; 20: 100; 30: 100; 40:
  100; 60: 100; 80: 31.9 mg = 0.255 N·m·s
* combined: ΔH: 0; [mg]: 0; 2.5: 0; 3: 0.3; 3.5: 0.3; 4: 3.7; 5: 18.0; 7.5: 89.0; 10: 100; 15: 100; 20: 100; 30:
  100; 40: 100; 60: 100; 80: 15.5 mg = 0.124 N·m·s
* joint: ΔH: 43.0; [mg]: 76.7; 2.5: 92.7; 3: 98.3; 3.5: 99.7; 4: 100; 5: 100; 7.5: 100; 10: 100; 15: 100; 20:
  100; 30: 100; 40: 100; 60: 100; 80: 3.4 mg = 0.027 N·m·s

Thresholds at one false alarm per day: attitude 0.114/0.113/0.115 N·m·s per axis, rate 0.166/0.152/0.179 (4e-5)
or 0.83/0.76/0.89 (2e-4); T: χ²(3) 30.36, Gamma fits 30.4-30.8 (combined) and 32.6-32.7 (joint, used). No
exceedance of any of them in 7.9 h of event-free output (0.33 expected).

The joint filter reaches the Acceptance-3 target (90% at ≤ 0.04 N·m·s) even with Table 2.1's rate noise, because
it weighs each channel by its own noise rather than summing the rate noise into H.

**Speed** (`throughput()` at the end of the benchmark, one 250-tap filter, one core of a shared machine): batch
7.0e6 samples/s over 1e7 samples; streaming in 1e5-sample chunks 1.9e7 samples/s over a 1e8-sample stream,
traced memory peak flat at 5.7 MB from the first fifth of the stream to the end.
"""

from __future__ import annotations

import argparse
import time
from typing import Any

import numpy as np
from scipy import stats

from abrupt.detect.attitude.matched_filter import (
    NMS_PER_MG,
    CombinedFilter,
    WaveletSet,
    analytic_output_sd,
    attitude_error_vector,
    build_wavelets,
    chi2_threshold,
    estimate_strike_size,
    fit_matched_filter_thresholds,
    matched_filter_bank_statistics,
)
from abrupt.model.attitude_dynamics import AttitudeSimConfig, Strike, simulate_attitude_batch
from abrupt.model.spacecraft import bundled_spacecraft_path, load_spacecraft
from abrupt.thresholds import FalseAlarmBudget, fit_threshold, neyman_pearson_threshold

RATE_HZ = 10.0
TOL = 10  # detection must peak within +-1 s of the strike sample
KINDS = ("attitude", "rate")
JOINT_BASELINE = 200  # samples of pre-strike baseline for the joint filter (the thesis pre-window)


def _random_directions(rng: np.random.Generator, n: int) -> np.ndarray:
    v = rng.normal(size=(n, 3))
    return np.asarray(v / np.linalg.norm(v, axis=1, keepdims=True))


class Study:
    """Simulated telemetry and filter outputs for one noise setting."""

    def __init__(self, sc: Any, wav: WaveletSet, rate_noise: float) -> None:
        self.sc, self.wav, self.rate_noise = sc, wav, rate_noise
        self.sd6 = np.array([7e-5] * 3 + [rate_noise] * 3)
        self.combined = CombinedFilter.from_wavelets(wav, self.sd6)
        n_wheels = wav.wheel.shape[2]
        self.joint = CombinedFilter.from_wavelets(wav, np.concatenate([self.sd6, [0.25] * n_wheels]), use_wheels=True)

    def _config(self, duration_s: float) -> AttitudeSimConfig:
        return AttitudeSimConfig(
            duration_s=duration_s, telemetry_rate_hz=RATE_HZ, telemetry_noise_rate_rad_s=self.rate_noise
        )

    def stats(self, q: np.ndarray, w: np.ndarray, wheels: np.ndarray) -> dict[str, np.ndarray]:
        att = attitude_error_vector(q, np.array([1.0, 0.0, 0.0, 0.0]))
        t_stat, _ = self.combined.statistic(np.column_stack([att, w]))
        t_joint, _ = self.joint.statistic(np.column_stack([att, w, wheels]), baseline_samples=JOINT_BASELINE)
        return {
            "joint": t_joint,
            "attitude": matched_filter_bank_statistics("attitude", att, self.wav),
            "rate": matched_filter_bank_statistics("rate", w, self.wav),
            "combined": t_stat,
            "att_channels": att,
            "rate_channels": w,
        }

    def null(self, runs: int, duration_s: float, seed: int) -> dict[str, np.ndarray]:
        out = simulate_attitude_batch(
            self.sc, self._config(duration_s), [[] for _ in range(runs)], [seed + r for r in range(runs)]
        )
        parts: dict[str, list[np.ndarray]] = {"attitude": [], "rate": [], "combined": [], "joint": []}
        for r in range(runs):
            s = self.stats(out["q_BN"][r], out["omega_B_rad_s"][r], out["wheel_speed_rad_s"][r])
            for k in parts:
                v = s[k]
                parts[k].append(v[np.all(np.isfinite(v.reshape(v.shape[0], -1)), axis=1)])
        return {k: np.concatenate(v) for k, v in parts.items()}

    def strikes(self, dh_b: np.ndarray, seed: int) -> list[dict[str, Any]]:
        """One 60 s run per strike (rows of dh_b, N·m·s body), strike at a random time in 25-30 s."""
        rng = np.random.default_rng(seed)
        times = rng.uniform(25.0, 30.0, size=dh_b.shape[0])
        strikes = [
            [Strike(float(t), (float(d[0]), float(d[1]), float(d[2])))] for t, d in zip(times, dh_b, strict=True)
        ]
        out = simulate_attitude_batch(
            self.sc, self._config(60.0), strikes, [seed * 100_000 + r for r in range(len(strikes))]
        )
        res = []
        for r, t in enumerate(times):
            k0 = int(np.floor(t * RATE_HZ + 1e-9))  # sample at or just before the strike
            s = self.stats(out["q_BN"][r], out["omega_B_rad_s"][r], out["wheel_speed_rad_s"][r])
            s["k0"] = np.array(k0)
            res.append(s)
        return res


def _peak(stat: np.ndarray, thr: np.ndarray | float, k0: int) -> tuple[int, float]:
    """Index and largest statistic/threshold ratio within +-TOL samples of k0."""
    lo, hi = max(0, k0 - TOL), k0 + TOL + 1
    seg = stat[lo:hi]
    ratio = np.abs(seg) / thr if seg.ndim == 1 else (np.abs(seg) / thr).max(axis=1)
    ratio = np.where(np.isfinite(ratio), ratio, -np.inf)
    i = int(np.argmax(ratio))
    return lo + i, float(ratio[i])


def _p90(sizes: np.ndarray, pd_: np.ndarray) -> float:
    above = np.flatnonzero(pd_ >= 0.9)
    if above.size == 0:
        return float("nan")
    i = int(above[0])
    if i == 0:
        return float(sizes[0])
    return float(np.interp(0.9, [pd_[i - 1], pd_[i]], [sizes[i - 1], sizes[i]]))


def run(quick: bool) -> None:
    t_start = time.time()
    sc = load_spacecraft(bundled_spacecraft_path("thesis"))
    wav = build_wavelets(sc, sample_rate_hz=RATE_HZ)
    print("== Wavelets (Bennett 2022 §2.4.1.1): largest unsaturated strike per body axis, 25 s at 10 Hz ==")
    for a in range(3):
        print(
            f"  axis {'xyz'[a]}: dH = {wav.dH_Nms[a]:.3f} N·m·s ({wav.dH_Nms[a] / NMS_PER_MG:.0f} mg); "
            f"peak rate {np.abs(wav.rate[a][:, a]).max():.3e} rad/s, "
            f"peak q_vec {np.abs(wav.attitude[a][:, a]).max():.3e}"
        )
    print("  spec §2.1: largest unsaturated x strike about 80-90 mg")

    null_runs, null_dur = (4, 900.0) if quick else (16, 1800.0)
    n_thr = 100 if quick else 1000
    n_fixed = 100 if quick else 1000
    n_size = 200 if quick else 1000
    n_curve = 60 if quick else 300
    rng = np.random.default_rng(2022)

    for rate_noise, label in (
        (2e-4, "Table 2.1 rate noise 2e-4 rad/s"),
        (4e-5, "spec §3.6 rate noise 4e-5 rad/s"),
    ):
        print(f"\n######## {label} ########")
        st = Study(sc, wav, rate_noise)
        null = st.null(null_runs, null_dur, seed=11)
        n_null = null["attitude"].shape[0]
        print(f"event-free filter output: {n_null} samples per axis ({n_null / RATE_HZ / 3600:.1f} h)")
        for kind in KINDS:
            sd_emp = np.std(null[kind], axis=0)
            noise = 7e-5 if kind == "attitude" else rate_noise
            sd_an = [
                analytic_output_sd(wav.wavelet(kind, a), noise, dH_wavelet_Nms=float(wav.dH_Nms[a])) for a in range(3)
            ]  # type: ignore[arg-type]
            print(
                f"  {kind:8s} output sd [N·m·s] measured {np.round(sd_emp, 4)} "
                f"vs white-noise analytic {np.round(sd_an, 4)}"
            )

        # ---- thresholds at alpha = 1e-4 (thesis ROC / LRT procedure, §2.4.1.2) ----
        alpha = 1e-4
        thr_np: dict[str, np.ndarray] = {}
        print(f"\n-- thresholds at alpha = {alpha:g} per sample per axis (two-sided) [N·m·s] --")
        for kind, mg in (("attitude", 30.0), ("rate", 40.0)):
            vals, taus, gauss = [], [], []
            for a in range(3):
                runs = st.strikes(np.tile(np.eye(3)[a] * mg * NMS_PER_MG, (n_thr // 3 + 1, 1)), seed=100 + a)
                peaks = [abs(r[kind][_peak(r[kind][:, a], 1.0, int(r["k0"]))[0], a]) for r in runs]
                x0 = null[kind][:, a]
                y, tau = neyman_pearson_threshold(np.concatenate([x0, -x0]), peaks, alpha / 2)
                g = fit_threshold(np.concatenate([x0, -x0]), p_fa=alpha / 2, method="gaussian").value
                vals.append(y)
                taus.append(tau)
                gauss.append(g)
            thr_np[kind] = np.array(vals)
            emp = [float(np.mean(np.abs(null[kind][:, a]) > vals[a])) for a in range(3)]
            print(
                f"  {kind:8s} ({mg:.0f} mg H1): Neyman-Pearson y_thresh {np.round(vals, 4)} "
                f"(tau {np.round(taus, 2)}); Gaussian fit {np.round(gauss, 4)}"
            )
            print(
                f"           = {np.round(np.array(vals) / NMS_PER_MG, 1)} mg about each axis; "
                f"empirical P_FA on the event-free output {np.array(emp)}"
            )

        # ---- Acceptance 2: P_D of 60 mg (attitude) and 80 mg (rate) ----
        print("\n-- Acceptance 2: detection at alpha = 1e-4 (target >= 90%) --")
        for kind, mg in (("attitude", 60.0), ("rate", 80.0)):
            for dname, dirs in (
                ("about x", np.tile([1.0, 0.0, 0.0], (n_fixed, 1))),
                ("random", _random_directions(rng, n_fixed)),
            ):
                runs = st.strikes(dirs * mg * NMS_PER_MG, seed=int(rng.integers(1 << 30)))
                hits = [_peak(r[kind], thr_np[kind], int(r["k0"]))[1] > 1.0 for r in runs]
                p = float(np.mean(hits))
                ci = 1.96 * np.sqrt(max(p * (1 - p), 1e-12) / len(hits))
                print(
                    f"  {kind:8s} MF, {mg:.0f} mg {dname:8s}: P_D = {100 * p:5.1f}% +- {100 * ci:.1f} "
                    f"({len(hits)} runs)  {'MET' if p >= 0.9 else 'NOT MET'}"
                )

        # ---- Table 2.3: size estimation over random sizes/directions, detected strikes only ----
        print("\n-- Table 2.3: wavelet-bank size error [mg] (estimated - true |dH|), detected strikes only --")
        mg_true = rng.uniform(1.0, 100.0, size=n_size)
        dirs = _random_directions(rng, n_size)
        runs = st.strikes(dirs * (mg_true * NMS_PER_MG)[:, None], seed=int(rng.integers(1 << 30)))
        thesis = {
            "attitude": {"mmse": (1.4, 8.7), "rsse": (1.4, 8.7), "mae": (2.0, 10.9), "cubic": (1.5, 9.1)},
            "rate": {
                "mmse": (-4.46, 13.1),
                "rsse": (-4.46, 13.1),
                "mae": (-2.95, 14.3),
                "cubic": (-4.50, 13.2),
            },
        }
        L = wav.length
        for kind in KINDS:
            ch_key = "att_channels" if kind == "attitude" else "rate_channels"
            errs: dict[str, list[float]] = {m: [] for m in ("mmse", "rsse", "mae", "cubic", "least-squares")}
            det = 0
            for r, m_true in zip(runs, mg_true, strict=True):
                i, ratio = _peak(r[kind], thr_np[kind], int(r["k0"]))
                if ratio <= 1.0:
                    continue
                det += 1
                seg = r[ch_key][i : i + L]
                for metric in ("mmse", "rsse", "mae", "cubic"):
                    est = estimate_strike_size(kind, seg, wav, metric=metric)  # type: ignore[arg-type]
                    errs[metric].append(np.linalg.norm(est) / NMS_PER_MG - m_true)
                errs["least-squares"].append(np.linalg.norm(r[kind][i]) / NMS_PER_MG - m_true)
            big = 60.0 if kind == "attitude" else 80.0
            sel = mg_true > big
            hit = [_peak(r[kind], thr_np[kind], int(r["k0"]))[1] > 1.0 for r, ok in zip(runs, sel, strict=True) if ok]
            print(
                f"  {kind} ({det}/{n_size} detected; of the strikes > {big:.0f} mg: "
                f"{100 * np.mean(hit):.1f}% of {len(hit)}):"
            )
            for metric, e in errs.items():
                ref = thesis[kind].get(metric)
                ref_s = f"thesis {ref[0]:+.2f} / {ref[1]:.1f}" if ref else "(not in thesis)"
                if e:
                    print(f"    {metric:13s} mean {np.mean(e):+6.2f} mg  sd {np.std(e):5.1f} mg   | {ref_s}")

        # ---- Acceptance 3: power curves at one false alarm per day ----
        p_day = FalseAlarmBudget(1.0).per_sample(RATE_HZ)
        thr_day = {
            k: np.array(
                [
                    t.value
                    for t in fit_matched_filter_thresholds(
                        null[k], budget=FalseAlarmBudget(1.0), sample_rate_hz=RATE_HZ, method="gaussian"
                    )
                ]
            )
            for k in KINDS
        }
        t_chi = chi2_threshold(budget=FalseAlarmBudget(1.0), sample_rate_hz=RATE_HZ)
        t_gam = fit_threshold(null["combined"], p_fa=p_day, method="gamma").value
        thr_day["combined"] = np.array(max(t_chi.value, t_gam))
        t_joint = fit_threshold(null["joint"], p_fa=p_day, method="gamma").value
        thr_day["joint"] = np.array(max(t_chi.value, t_joint))
        print(f"\n-- Acceptance 3: P_D vs |dH|, random directions, 1 false alarm/day at 10 Hz (p_fa {p_day:.3g}) --")
        print(
            f"  thresholds: attitude {np.round(thr_day['attitude'], 4)} N·m·s, "
            f"rate {np.round(thr_day['rate'], 4)} N·m·s "
            f"(per axis, p_fa/3 each); GLRT on T: chi2(3) {t_chi.value:.2f}, gamma fit of the null "
            f"combined {t_gam:.2f}, joint {t_joint:.2f} (the larger of chi2 and fit is used)"
        )
        for k in ("combined", "joint"):
            v = null[k]
            for p in (1e-3, 1e-4):
                tg = fit_threshold(v, p_fa=p, method="gamma").value
                tc = float(stats.chi2.isf(p, 3))
                print(
                    f"  Q-check {k:8s} at p_fa {p:g}: empirical exceedance of gamma-fit threshold "
                    f"{np.mean(v > tg):.2e}, of chi2(3) threshold {np.mean(v > tc):.2e}"
                )
        for k in ("attitude", "rate", "combined", "joint"):
            thr = thr_day[k]
            v = null[k]
            exceed = int(np.sum((np.abs(v) / thr).max(axis=1) > 1.0)) if v.ndim == 2 else int(np.sum(v > thr))
            print(
                f"  null check {k:8s}: {exceed} exceedances in {v.shape[0]} samples (expected {v.shape[0] * p_day:.2f})"
            )
        sizes_mg = np.array([2.5, 3.0, 3.5, 4.0, 5.0, 7.5, 10.0, 15.0, 20.0, 30.0, 40.0, 60.0, 80.0, 100.0])
        curves: dict[str, list[float]] = {"attitude": [], "rate": [], "combined": [], "joint": []}
        for mg in sizes_mg:
            runs = st.strikes(_random_directions(rng, n_curve) * mg * NMS_PER_MG, seed=int(rng.integers(1 << 30)))
            for k in curves:
                curves[k].append(float(np.mean([_peak(r[k], thr_day[k], int(r["k0"]))[1] > 1.0 for r in runs])))
        print("  |dH| [mg]      " + " ".join(f"{m:6.1f}" for m in sizes_mg))
        print("  |dH| [N·m·s]   " + " ".join(f"{m * NMS_PER_MG:6.3f}" for m in sizes_mg))
        for k, c in curves.items():
            p90 = _p90(sizes_mg, np.array(c))
            print(
                f"  {k:13s}  "
                + " ".join(f"{100 * x:6.1f}" for x in c)
                + f"   90% at {p90:.1f} mg = {p90 * NMS_PER_MG:.3f} N·m·s"
            )
        print(f"  ({n_curve} runs per size; target for the best detector overall: 90% at <= 0.04 N·m·s)")
    print(f"\nelapsed {time.time() - t_start:.0f} s")


def throughput(n_samples: int) -> None:
    """Batch and streaming speed of one 250-tap filter, and the streaming memory peak (tracemalloc)."""
    import tracemalloc

    from abrupt.detect.attitude.matched_filter import MatchedFilterStream, matched_filter_statistic

    rng = np.random.default_rng(0)
    s = np.exp(-np.arange(250) / 30.0)
    x = rng.normal(size=min(n_samples, 10_000_000))
    t0 = time.perf_counter()
    matched_filter_statistic(x, s)
    t_batch = time.perf_counter() - t0
    chunk = 100_000
    block = rng.normal(size=chunk)
    stream = MatchedFilterStream(s)
    tracemalloc.start()
    t0 = time.perf_counter()
    peaks = []
    for i in range(n_samples // chunk):
        stream.update(block)
        if i % max(1, (n_samples // chunk) // 5) == 0:
            peaks.append(tracemalloc.get_traced_memory()[1] / 1e6)
    t_stream = time.perf_counter() - t0
    tracemalloc.stop()
    print("\n== Throughput (250-tap filter, one core) ==")
    print(f"  batch: {x.size / t_batch:.3g} samples/s over {x.size:.0e} samples")
    print(
        f"  streaming in {chunk}-sample chunks: {n_samples / t_stream:.3g} samples/s "
        f"over {n_samples:.0e} samples; "
        f"traced memory peak along the stream [MB]: {np.round(peaks, 2)}"
    )


def timing_calibration(runs: int) -> None:
    """Joint filter through detect_strikes: strike-time error over the reported time_sigma_s."""
    from abrupt.detect.attitude.matched_filter import detect_strikes

    sc = load_spacecraft(bundled_spacecraft_path("thesis"))
    wav = build_wavelets(sc, sample_rate_hz=RATE_HZ, bank_size=4)
    rng = np.random.default_rng(7)
    print("\n== Strike time of the joint filter (detect_strikes, refine_strike), rate noise 4e-5 ==")
    for mg in (5.0, 20.0):
        dirs = _random_directions(rng, runs)
        strikes = [[Strike(60.0, (float(d[0]), float(d[1]), float(d[2])))] for d in dirs * mg * NMS_PER_MG]
        out = simulate_attitude_batch(sc, AttitudeSimConfig(duration_s=120.0), strikes, list(range(runs)))
        z, err = [], []
        for r in range(runs):
            det, _ = detect_strikes(
                out["t_s"],
                out["q_BN"][r],
                out["omega_B_rad_s"][r],
                wav,
                kinds=("joint",),
                wheel_speed_rad_s=out["wheel_speed_rad_s"][r],
                baseline_samples=200,
            )
            if len(det) == 1:
                err.append(float(det["time"].iloc[0]) - 60.0)
                z.append(err[-1] / float(det["time_sigma_s"].iloc[0]))
        print(
            f"  {mg:4.0f} mg: {len(z)}/{runs} single detections, "
            f"rms time error {np.sqrt(np.mean(np.square(err))):.2f} s, "
            f"rms (error / time_sigma_s) {np.sqrt(np.mean(np.square(z))):.2f} (1 = calibrated)"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="short run (fewer Monte Carlo runs)")
    args = parser.parse_args()
    run(args.quick)
    timing_calibration(30 if args.quick else 100)
    throughput(10_000_000 if args.quick else 100_000_000)


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results("bench_matched_filter", variant({"--quick": "quick"})):
        main()
