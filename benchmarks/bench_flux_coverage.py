"""Coverage and bias of the flux inference on simulated fleets (issue: flux inference, acceptance 1 and 3).

Fleets of 10 Fermi-like spacecraft (4000 kg; examples/spacecraft/fermi_like.toml) at 550 km / 28.5° for
one year, nadir pointing (ΔH direction known in the orbit frame), ΔH90 = 10 mN·m·s, 0.01 false alarms per
day, 90 % of each day analysed. Truths: debris scale 1, 0.3 and 3 × NASA-90/91, β = 1 and 3, Grün
meteoroids at scale 1. Events are drawn from a template with its own Monte Carlo seed; the fit uses another.

Fits per fleet:
  A  meteoroid scale fixed at 1 (Grün taken as known): debris scale and β free;
  B  β fixed at its truth: both scales free (the flux measurement when the MEF is known); besides the ML
     estimates the linear fixed-weight ones that ``flux infer`` reports with β known, with their
     score-type intervals (:mod:`abrupt.flux.linear`; coverage over all ``--bias-reps`` fleets: closed form);
  C  everything free (the degenerate case: reported, β is not expected to be bounded);
  D  as B, |ΔH| only (no direction): the debris/meteoroid split without direction (acceptance 3).

Printed per truth, fit, parameter and point estimate: coverage of the 90 % profile-likelihood intervals
(target 85-95 %, the first ``--reps`` fleets), the bias of the mean estimate (target within 5 %) with its
Monte Carlo standard error over ``--bias-reps`` fleets (point estimates only for the fleets past
``--reps``), the median bias, and a verdict:

The mean is a control-variate estimate (with the plain mean and its s.e. beside it): each fleet's counts
per (direction class, |ΔH| bin) minus their exact expectation under the simulator (computed from the draw
template's own Monte Carlo draws and the false alarms' logistic sizes, ``exact_cells``), weighted as the
score of (s_debris, s_meteoroid, β) at the truth. These controls have expectation exactly 0 whatever their
weights, so the regression-adjusted mean (the intercept of estimate ~ 1 + controls) has the plain mean's
expectation, with the first-order sampling noise (θ̂ − θ ≈ I⁻¹U) removed: 2-4 times smaller standard errors
for the same fleets. The verdict: "met" when bias ± 2 s.e. lies inside ±0.05, "exceeds" when
it lies wholly outside, else "not resolved" (the run's Monte Carlo error cannot tell). Point estimates:
"MLE" (bounded at s >= 0, the one quoted with its interval), "signed" (scales free to go below 0: no
pile-up at the bound) and "corrected" (the signed MLE with β corrected for its Cox-Snell first-order bias
and the scales re-maximised at the corrected β; equal to "signed" when β is fixed) and, for fit A, "Firth"
(the Jeffreys-penalised maximum in (ln s, ln β), :mod:`abrupt.flux.firth`). Everything is
simulated: tuning and scoring are on the same simulator, which is the point of the test (does the
statistics deliver what it states?).

Run: ``nice -n 10 python benchmarks/bench_flux_coverage.py --beta 1 --bias-reps 2000`` and ``... --beta 3
--bias-reps 1000``; the held-out truths (not looked at while choosing the estimator): ``... --beta 2
--scales 0.5 2 --bias-reps 1000``. About 0.13 s of CPU per fleet, 0.3 s with intervals. ``--reps 0
--free-reps 0``: point estimates only (fits A and B; file suffix ``_points``, ``_worst`` with ``--scales 0.3``).
``--known-beta``: fit B alone (β known; file suffix ``_known``): bias of the ML, signed and linear scales,
coverage of the profile intervals (first ``--reps`` fleets) and of the linear intervals (all fleets), e.g.
``... --known-beta --beta 1 --reps 200 --bias-reps 1000`` (and ``--beta 3``; ``--beta 2 --scales 0.5 2``).
About 0.08 s of CPU per fleet, 0.2 s with the profile intervals.
``--fallback``: fit B alone at all eight truths (file suffix ``_fallback``): per truth, how often the linear
scales fall outside the physical range and what reporting the ML estimate (with its profile interval) in
their place does to the reported estimate's bias and coverage, for two rules: fall back when a linear scale is
below 0 (or outside its own interval), and fall back only when a scale's score interval clipped at 0 is empty
(a negative linear estimate is then quoted, unbiased, beside its interval [0, upper end]). "reported − linear"
is the fallback's own shift of the mean (paired on the same fleets). E.g. ``... --fallback --reps 0
--bias-reps 500``.

**Acceptance 1 — coverage and bias.** Coverage: `nice -n 10 python benchmarks/bench_flux_coverage.py --beta 1
--bias-reps 2000` and `--beta 3 --bias-reps 1000`; held out: `--beta 2 --scales 0.5 2 --bias-reps 1000`
(`docs/results/bench_flux_coverage_beta{1,3,2_heldout}.txt`). Bias, point estimates only (the same fleets and
more, with the Jeffreys-penalised estimate): `... --beta 1 --scales 0.3 --reps 0 --free-reps 0 --bias-reps 4000`
(the worst truth), `... --beta 1 --scales 1 3 --reps 0 --free-reps 0 --bias-reps 2000`, `... --beta 3 --reps 0
--free-reps 0 --bias-reps 1000`, held out `... --beta 2 --scales 0.5 2 --reps 0 --free-reps 0 --bias-reps 1000`
(`docs/results/bench_flux_coverage_beta1_points_worst.txt`, `..._beta1_points.txt`, `..._beta3_points.txt`,
`..._beta2_heldout_points.txt`). Fleet: 10 Fermi-like spacecraft × 1 year, 550 km / 28.5°, ΔH90 = 10 mN·m·s,
0.01 false alarms/day, 90 % analysed; 47-192 detections per fleet, about 33 of them false alarms. Coverage from
the first 200 fleets of each truth (with profile intervals), the bias from 4 000 fleets at the worst truth (s_d
= 0.3, β = 1), 2 000 for the other two at β = 1 and 1 000 at β = 3 and for the held-out truths (the first 2 000
/ 1 000 are the fleets of the coverage runs; past the 500th, seeds no other truth uses). Everything is simulated
(the draw template and the fit template have different Monte Carlo seeds); this checks that the statistics
deliver what they state. CPU: 0.15-0.16 s per fleet for fits A and B with all four point estimates (the
Jeffreys-penalised one adds about 0.03 s), 157-162 s per truth of 1 000 fleets, on 2 cores at a load average of
6-11.

**Control variates.** With 5-10 detections of a population per fleet, one fleet's estimate scatters by 40-150 %,
so a plain mean of even 2 000 fleets is uncertain by 1-3 %, too much to place a 5 % bound. The benchmark
therefore reports the control-variate mean: each fleet's counts per (direction class, |ΔH| bin) minus their
exact expectation under the simulator (summed over the draw template's own Monte Carlo draws and the false
alarms' logistic sizes, `exact_cells`), weighted as the score of (s_debris, s_meteoroid, β) at the truth. A
control has expectation exactly 0 whatever its weights (E n = μ in every cell; the printed mean count per fleet
matches the exact expectation within its noise for every truth), so the regression-adjusted mean (the intercept
of estimate ~ 1 + controls) has the plain mean's expectation, with the first-order sampling noise (θ̂ − θ ≈
I⁻¹U) taken out: standard errors 2-10 times smaller for the same fleets. The plain mean and its s.e. are printed
beside it and agree with it within the plain s.e. The verdict per row is **"met" only when bias ± 2 s.e. lies
inside ±5 %**, "exceeds" when it lies wholly outside, else "not resolved".

Mean bias of the control-variate mean ± its s.e. (per truth; the plain means and medians are in the result
files); **bold**: the bias the run places outside ±5 % or cannot place inside it.

* A: s_m fixed at 1 (Grün prior): parameter, estimate: β, ML; coverage of 90 % intervals (200 fleets): 0.915,
  0.935, 0.925 / 0.885, 0.905, 0.855 / held out 0.880, 0.910; β = 1 (s_d = 1, 0.3, 3), 2 000, 4 000, 2 000
  fleets: +0.0 ± 0.5, **−6.8 ± 0.3**, +3.0 ± 0.6 %; β = 3 (s_d = 1, 0.3, 3), 1 000 fleets: −2.3 ± 0.2, −2.5 ±
  0.2, −2.8 ± 0.3 %; held out β = 2 (s_d = 0.5, 2), 1 000 fleets: −3.5 ± 0.3, −3.2 ± 0.4 %
* A: parameter, estimate: β, signed ML; β = 1 (s_d = 1, 0.3, 3), 2 000, 4 000, 2 000 fleets: +0.6 ± 0.5, **+4.9
  ± 0.4**, +3.0 ± 0.6 %; β = 3 (s_d = 1, 0.3, 3), 1 000 fleets: −2.3 ± 0.2, −1.0 ± 0.2, −2.8 ± 0.3 %; held out β
  = 2 (s_d = 0.5, 2), 1 000 fleets: −2.6 ± 0.3, −3.2 ± 0.4 %
* A: parameter, estimate: **β, bias-corrected (Cox-Snell, reported)**; β = 1 (s_d = 1, 0.3, 3), 2 000, 4 000, 2
  000 fleets: +1.9 ± 0.5, **+7.9 ± 0.4**, +0.4 ± 0.6 %; β = 3 (s_d = 1, 0.3, 3), 1 000 fleets: −2.1 ± 0.2, −0.7
  ± 0.2, −3.3 ± 0.4 %; held out β = 2 (s_d = 0.5, 2), 1 000 fleets: −1.8 ± 0.3, −3.7 ± 0.4 %
* A: parameter, estimate: β, Jeffreys-penalised in (ln s, ln β) (`penalised=True`); β = 1 (s_d = 1, 0.3, 3), 2
  000, 4 000, 2 000 fleets: **+22.1 ± 0.2**, −0.1 ± 0.1, **+41.7 ± 0.4** %; β = 3 (s_d = 1, 0.3, 3), 1 000
  fleets: +0.9 ± 0.2, **−7.9 ± 0.2**, **+6.8 ± 0.3** %; held out β = 2 (s_d = 0.5, 2), 1 000 fleets: −2.5 ± 0.2,
  **+11.4 ± 0.3** %
* A: parameter, estimate: s_debris, ML: mean (median); coverage of 90 % intervals (200 fleets): 0.895, 0.935,
  0.915 / 0.895, 0.915, 0.860 / held out 0.905, 0.880; β = 1 (s_d = 1, 0.3, 3), 2 000, 4 000, 2 000 fleets: +135
  (+6), +199 (+7), +116 (+6) %; β = 3 (s_d = 1, 0.3, 3), 1 000 fleets: +38 (+2), +47 (−1), +52 (+1) %; held out
  β = 2 (s_d = 0.5, 2), 1 000 fleets: +102 (+1), +86 (+4) %
* A: parameter, estimate: s_debris, bias-corrected: mean (median); β = 1 (s_d = 1, 0.3, 3), 2 000, 4 000, 2 000
  fleets: +170 (0), +191 (−4), +183 (+6) %; β = 3 (s_d = 1, 0.3, 3), 1 000 fleets: +51 (+2), +47 (−2), +82 (+1)
  %; held out β = 2 (s_d = 0.5, 2), 1 000 fleets: +122 (−1), +140 (+2) %
* A: parameter, estimate: s_debris, Jeffreys-penalised: mean ± s.e.; β = 1 (s_d = 1, 0.3, 3), 2 000, 4 000, 2
  000 fleets: −1.2 ± 0.8, +56.9 ± 0.6, −4.9 ± 1.5 %; β = 3 (s_d = 1, 0.3, 3), 1 000 fleets: +15.2 ± 1.0, +57.3 ±
  1.4, +13.4 ± 3.0 %; held out β = 2 (s_d = 0.5, 2), 1 000 fleets: +33.3 ± 1.2, +8.3 ± 1.6 %
* A: parameter, estimate: expected debris detections s_debris·T_d(β), ML; coverage of 90 % intervals (200
  fleets): —; β = 1 (s_d = 1, 0.3, 3), 2 000, 4 000, 2 000 fleets: −2.5 ± 0.2, **+6.0 ± 0.5**, −1.6 ± 0.1 %; β =
  3 (s_d = 1, 0.3, 3), 1 000 fleets: +0.5 ± 0.1, +4.0 ± 0.6, −0.2 ± 0.1 %; held out β = 2 (s_d = 0.5, 2), 1 000
  fleets: +1.7 ± 0.4, +0.0 ± 0.1 %
* B: β known: parameter, estimate: s_debris, ML (bounded); coverage of 90 % intervals (200 fleets): 0.900,
  0.950, 0.965 / 0.900, 0.915, 0.900 / held out 0.920, 0.895; β = 1 (s_d = 1, 0.3, 3), 2 000, 4 000, 2 000
  fleets: −0.1 ± 0.2, **+11.2 ± 0.6**, −0.2 ± 0.1 %; β = 3 (s_d = 1, 0.3, 3), 1 000 fleets: +0.4 ± 0.1, +3.6 ±
  0.5, −0.2 ± 0.0 %; held out β = 2 (s_d = 0.5, 2), 1 000 fleets: +1.7 ± 0.4, −0.1 ± 0.1 %
* B: parameter, estimate: **s_debris, bias-corrected (= signed)**; β = 1 (s_d = 1, 0.3, 3), 2 000, 4 000, 2 000
  fleets: +1.1 ± 0.3, **−6.8 ± 1.1**, −0.0 ± 0.1 %; β = 3 (s_d = 1, 0.3, 3), 1 000 fleets: +0.4 ± 0.1, −0.4 ±
  0.5, −0.2 ± 0.0 %; held out β = 2 (s_d = 0.5, 2), 1 000 fleets: +0.4 ± 0.4, −0.1 ± 0.1 %
* B: parameter, estimate: s_meteoroid, ML (bounded); coverage of 90 % intervals (200 fleets): 0.920, 0.940,
  0.955 / 0.905, 0.910, 0.880 / held out 0.890, 0.920; β = 1 (s_d = 1, 0.3, 3), 2 000, 4 000, 2 000 fleets:
  **+5.1 ± 0.5**, +0.5 ± 0.4, **+8.8 ± 0.6** %; β = 3 (s_d = 1, 0.3, 3), 1 000 fleets: −1.7 ± 0.2, −1.2 ± 0.2,
  −1.9 ± 0.1 %; held out β = 2 (s_d = 0.5, 2), 1 000 fleets: −1.8 ± 0.3, −1.1 ± 0.2 %
* B: parameter, estimate: **s_meteoroid, bias-corrected (= signed)**; β = 1 (s_d = 1, 0.3, 3), 2 000, 4 000, 2
  000 fleets: **−5.1 ± 0.7**, +0.7 ± 0.7, −2.2 ± 0.5 %; β = 3 (s_d = 1, 0.3, 3), 1 000 fleets: −1.8 ± 0.2, −0.4
  ± 0.2, −2.1 ± 0.1 %; held out β = 2 (s_d = 0.5, 2), 1 000 fleets: −1.6 ± 0.3, −1.9 ± 0.2 %
* B: parameter, estimate: **s_debris, linear (reported with β known)**: see *Fit B with β known* below; coverage
  of 90 % intervals (200 fleets): 0.900-0.912 / 0.888-0.905 / held out 0.896, 0.899; β = 1 (s_d = 1, 0.3, 3), 2
  000, 4 000, 2 000 fleets: +0.3 ± 0.1, +1.0 ± 1.1, −0.1 ± 0.2 %; β = 3 (s_d = 1, 0.3, 3), 1 000 fleets: +0.4 ±
  0.0, +2.9 ± 0.6, −0.2 ± 0.1 %; held out β = 2 (s_d = 0.5, 2), 1 000 fleets: +0.9 ± 0.3, +0.0 ± 0.1 %
* B: parameter, estimate: **s_meteoroid, linear (reported with β known)**; coverage of 90 % intervals (200
  fleets): 0.887-0.923 / 0.894-0.904 / held out 0.907, 0.904; β = 1 (s_d = 1, 0.3, 3), 2 000, 4 000, 2 000
  fleets: −0.8 ± 0.1, −1.1 ± 0.6, +0.9 ± 0.9 %; β = 3 (s_d = 1, 0.3, 3), 1 000 fleets: −1.2 ± 0.1, −1.3 ± 0.2,
  −1.1 ± 0.3 %; held out β = 2 (s_d = 0.5, 2), 1 000 fleets: −1.2 ± 0.2, −0.9 ± 0.3 %
* C: all free (10 fleets each): parameter, estimate: all; coverage of 90 % intervals (200 fleets): 0.9-1.00, the
  β interval is the whole grid 0.1-100; β = 1 (s_d = 1, 0.3, 3), 2 000, 4 000, 2 000 fleets: not meaningful: β
  is not identified

**Coverage**: every truth and parameter of fits A and B, the held-out ones included, is within 85-95 % except
fit B at β = 1, s_d = 3 (0.965 and 0.955: over-coverage, conservative). Unchanged from the earlier runs (the
same 200 fleets).

**Fit B with β known: the reported linear scales** (`nice -n 10 python benchmarks/bench_flux_coverage.py
--known-beta --beta 1 --reps 200 --bias-reps 1000`, the same with `--beta 3`, held out `--known-beta --beta 2
--scales 0.5 2 --reps 200 --bias-reps 1000`; `docs/results/bench_flux_coverage_beta{1,3,2_heldout}_known.txt`).
The first 1 000 fleets of each truth of the runs above (same seeds), fitted with fit B alone on the current
forward model (spectrum-weighted bin efficiency; the rows of the table above, except the linear ones, were
measured before it). Coverage of the linear score interval, the one `flux infer` reports with β fixed, over all
1 000 fleets (binomial s.e. 0.009); of the ML profile interval over the first 200 (s.e. 0.021). Bias:
control-variate mean ± s.e.; width: median 90 % interval width / truth; spread: standard deviation of the
estimate / truth (from the printed plain s.e. × √1000). The held-out truths (β = 2) were not used to design the
estimator. CPU: 84-101 s per truth of 1 000 fleets with 200 profile-interval fits (12.3 CPU-minutes for the
eight), at a load of 2-6.

* 1, 1: s_debris, linear: bias: **+0.3 ± 0.1 %**; coverage: 0.912; width (ML profile): 1.50 (1.39); s_meteoroid,
  linear: bias: **−0.8 ± 0.1 %**; coverage: 0.915; width (ML profile): 2.95 (2.60); ML bounded bias, s_d / s_m:
  −0.3 ± 0.3 / +5.3 ± 0.7 %; signed ML bias, s_d / s_m: +0.6 ± 0.4 / −3.3 ± 1.0 %; ML profile coverage, s_d /
  s_m: 0.900 / 0.920; spread, linear (signed ML), s_d / s_m: 0.44 (0.47) / 0.92 (1.04)
* 0.3, 1: s_debris, linear: bias: **+1.0 ± 1.1 %**; coverage: 0.900; width (ML profile): 3.48 (2.97);
  s_meteoroid, linear: bias: **−1.1 ± 0.6 %**; coverage: 0.923; width (ML profile): 2.83 (2.13); ML bounded
  bias, s_d / s_m: +10.5 ± 1.2 / +0.4 ± 0.8 %; signed ML bias, s_d / s_m: −7.4 ± 2.1 / +1.4 ± 1.4 %; ML profile
  coverage, s_d / s_m: 0.950 / 0.940; spread, linear (signed ML), s_d / s_m: 1.14 (1.52) / 0.82 (1.08)
* 3, 1: s_debris, linear: bias: **−0.1 ± 0.2 %**; coverage: 0.904; width (ML profile): 0.73 (0.69); s_meteoroid,
  linear: bias: **+0.9 ± 0.9 %**; coverage: 0.887; width (ML profile): 3.33 (2.95); ML bounded bias, s_d / s_m:
  −0.1 ± 0.1 / +10.4 ± 0.8 %; signed ML bias, s_d / s_m: +0.1 ± 0.1 / −1.7 ± 0.7 %; ML profile coverage, s_d /
  s_m: 0.965 / 0.955; spread, linear (signed ML), s_d / s_m: 0.22 (0.22) / 1.14 (1.17)
* 1, 3: s_debris, linear: bias: **+0.4 ± 0.0 %**; coverage: 0.888; width (ML profile): 0.94 (0.93); s_meteoroid,
  linear: bias: **−1.2 ± 0.1 %**; coverage: 0.894; width (ML profile): 1.30 (1.27); ML bounded bias, s_d / s_m:
  +0.5 ± 0.1 / −1.3 ± 0.2 %; signed ML bias, s_d / s_m: +0.5 ± 0.1 / −1.3 ± 0.2 %; ML profile coverage, s_d /
  s_m: 0.900 / 0.905; spread, linear (signed ML), s_d / s_m: 0.28 (0.28) / 0.38 (0.41)
* 0.3, 3: s_debris, linear: bias: **+2.9 ± 0.6 %**; coverage: 0.905; width (ML profile): 2.35 (2.13);
  s_meteoroid, linear: bias: **−1.3 ± 0.2 %**; coverage: 0.904; width (ML profile): 1.22 (1.12); ML bounded
  bias, s_d / s_m: +3.5 ± 0.5 / −0.7 ± 0.2 %; signed ML bias, s_d / s_m: −0.5 ± 0.5 / +0.1 ± 0.2 %; ML profile
  coverage, s_d / s_m: 0.915 / 0.915; spread, linear (signed ML), s_d / s_m: 0.76 (0.79) / 0.38 (0.38)
* 3, 3: s_debris, linear: bias: **−0.2 ± 0.1 %**; coverage: 0.894; width (ML profile): 0.44 (0.43); s_meteoroid,
  linear: bias: **−1.1 ± 0.3 %**; coverage: 0.894; width (ML profile): 1.51 (1.46); ML bounded bias, s_d / s_m:
  −0.1 ± 0.0 / −1.3 ± 0.1 %; signed ML bias, s_d / s_m: −0.1 ± 0.0 / −1.5 ± 0.1 %; ML profile coverage, s_d /
  s_m: 0.900 / 0.875; spread, linear (signed ML), s_d / s_m: 0.13 (0.13) / 0.44 (0.44)
* 0.5, 2 (held out): s_debris, linear: bias: **+0.9 ± 0.3 %**; coverage: 0.896; width (ML profile): 1.86 (1.79);
  s_meteoroid, linear: bias: **−1.2 ± 0.2 %**; coverage: 0.907; width (ML profile): 1.69 (1.58); ML bounded
  bias, s_d / s_m: +1.7 ± 0.4 / −1.4 ± 0.3 %; signed ML bias, s_d / s_m: +0.4 ± 0.4 / −1.2 ± 0.3 %; ML profile
  coverage, s_d / s_m: 0.920 / 0.890; spread, linear (signed ML), s_d / s_m: 0.57 (0.60) / 0.51 (0.51)
* 2, 2 (held out): s_debris, linear: bias: **+0.0 ± 0.1 %**; coverage: 0.899; width (ML profile): 0.68 (0.67);
  s_meteoroid, linear: bias: **−0.9 ± 0.3 %**; coverage: 0.904; width (ML profile): 1.93 (1.83); ML bounded
  bias, s_d / s_m: +0.0 ± 0.1 / −0.5 ± 0.2 %; signed ML bias, s_d / s_m: +0.1 ± 0.1 / −1.3 ± 0.2 %; ML profile
  coverage, s_d / s_m: 0.900 / 0.920; spread, linear (signed ML), s_d / s_m: 0.22 (0.19) / 0.57 (0.57)

**The linear scales meet acceptance 1 at every truth**: the mean within ±5 % beyond 2 s.e. for both scales at
all eight truths (16 of 16 pairs, held out included; −1.3 to +2.9 %), where on the same fleets the bounded ML
exceeds it at two pairs and leaves one unresolved and the signed ML leaves two unresolved (all at β = 1); and
their 90 % intervals cover in 0.887-0.923 of 1 000 fleets at every truth and scale. Given the fit's cells the
estimate is exactly unbiased, so what remains in its mean is the fit model's difference from the simulator's
(template Monte Carlo, smoothing: the Asimov shift; about −1 % on s_meteoroid, +2.9 ± 0.6 % on s_debris at s_d =
0.3, β = 3), not the estimator's. Their price is the interval width: the score interval is 1-33 % wider in
median than the ML profile interval (widest at s_d = 0.3, β = 1, where the profile interval adapts its width to
each data set and over-covers), although the linear estimate's own spread is equal to or smaller than the signed
ML's (1.14 against 1.52 for s_debris at s_d = 0.3). The ML profile intervals stay in the output as diagnostics,
with coverage 0.875-0.965 on these runs.

**When the linear scales are out of range** (`nice -n 10 python benchmarks/bench_flux_coverage.py --fallback
--reps 0 --bias-reps 500`, `docs/results/bench_flux_coverage_fallback.txt`; fit B at the eight truths, the first
500 fleets of each, the same seeds as above; 332 s of CPU for the 4 000 fleets at a load of 2-6). An unbiased
estimate of a small scale goes below 0 in a share of data sets. `flux infer` used to report the ML estimates
(with their profile intervals) whenever a linear scale was below 0; that replaces exactly the low tail of the
estimate by values ≥ 0 and so lifts the reported mean. Measured per truth: the share of fleets that fell back,
the **shift of the reported mean by the fallback** (reported − linear, paired on the same fleets), the reported
estimate's control-variate bias and the coverage of the reported 90 % interval (the score interval, or the
profile interval where it fell back); binomial s.e. of a share ≤ 0.021, of a coverage 0.013:

* 1, 1: before: falls back: 66/500 (13.2 %); shift by the fallback: s_m **+4.8 ± 0.8 %**; reported bias s_d /
  s_m: −0.1 ± 0.2 / +4.3 ± 0.7 %; coverage s_d / s_m: 0.938 / 0.902; now: falls back: 2/500; reported bias s_d /
  s_m: +0.1 ± 0.1 / −0.1 ± 0.4 %; coverage s_d / s_m: 0.916 / 0.906
* 0.3, 1: before: falls back: 162/500 (32.4 %); shift by the fallback: s_d **+13.0 ± 1.8 %**; reported bias s_d
  / s_m: **+14.3 ± 1.8** / −2.0 ± 1.1 %; coverage s_d / s_m: 0.934 / 0.942; now: falls back: 3/500; reported
  bias s_d / s_m: −0.2 ± 1.7 / −0.4 ± 1.0 %; coverage s_d / s_m: 0.904 / 0.918
* 3, 1: before: falls back: 92/500 (18.4 %); shift by the fallback: s_m **+11.8 ± 1.4 %**; reported bias s_d /
  s_m: −0.4 ± 0.2 / **+11.6 ± 1.4** %; coverage s_d / s_m: 0.942 / 0.920; now: falls back: 2/500; reported bias
  s_d / s_m: +0.0 ± 0.2 / +0.7 ± 1.4 %; coverage s_d / s_m: 0.920 / 0.898
* 1, 3: before: falls back: 2/500 (0.4 %); shift by the fallback: +0.1 ± 0.1 %; reported bias s_d / s_m: +0.4 ±
  0.1 / −1.1 ± 0.1 %; coverage s_d / s_m: 0.892 / 0.896; now: falls back: 0; reported bias s_d / s_m: +0.5 ± 0.1
  / −1.2 ± 0.1 %; coverage s_d / s_m: 0.892 / 0.896
* 0.3, 3: before: falls back: 37/500 (7.4 %); shift by the fallback: s_d **+3.1 ± 0.6 %**; reported bias s_d /
  s_m: +6.3 ± 0.9 / −1.7 ± 0.3 %; coverage s_d / s_m: 0.900 / 0.920; now: falls back: 0; reported bias s_d /
  s_m: +3.4 ± 0.9 / −1.4 ± 0.3 %; coverage s_d / s_m: 0.912 / 0.912
* 3, 3: before: falls back: 5/500 (1.0 %); shift by the fallback: s_m +0.2 ± 0.1 %; reported bias s_d / s_m:
  −0.1 ± 0.1 / −1.3 ± 0.5 %; coverage s_d / s_m: 0.900 / 0.890; now: falls back: 0; reported bias s_d / s_m:
  −0.0 ± 0.1 / −1.5 ± 0.5 %; coverage s_d / s_m: 0.900 / 0.890
* 0.5, 2 (held out): before: falls back: 22/500 (4.4 %); shift by the fallback: s_d +0.9 ± 0.3 %; reported bias
  s_d / s_m: +1.8 ± 0.5 / −1.3 ± 0.3 %; coverage s_d / s_m: 0.902 / 0.922; now: falls back: 0; reported bias s_d
  / s_m: +1.0 ± 0.4 / −1.3 ± 0.3 %; coverage s_d / s_m: 0.910 / 0.916
* 2, 2 (held out): before: falls back: 14/500 (2.8 %); shift by the fallback: s_m +0.6 ± 0.2 %; reported bias
  s_d / s_m: −0.1 ± 0.1 / −0.0 ± 0.4 %; coverage s_d / s_m: 0.906 / 0.912; now: falls back: 0; reported bias s_d
  / s_m: −0.1 ± 0.1 / −0.7 ± 0.4 %; coverage s_d / s_m: 0.906 / 0.910

**The fallback biased the reported estimate at the low truths**: by +13 % (debris scale at s_d = 0.3, β = 1,
where a third of the fleets fell back), +12 % and +5 % (meteoroid scale at s_d = 3 and 1, β = 1, where the
debris take most of the events and the meteoroid estimate scatters by 92-114 %), +3 % (debris at s_d = 0.3, β =
3); two reported scales then exceeded ±5 % and two more were not resolved, where the linear estimate met it at
three of these four (the fourth, the debris scale at s_d = 0.3, β = 3, is itself +3.4 ± 0.9 % on these fleets).
Its intervals over-covered there (0.934-0.942). **Now** (`in_physical_range`, `FitResult.reported`) a negative
linear estimate is reported as it is, with its interval clipped at 0 ([0, upper end]: the scales ≥ 0 the data
allow; a note says so), the way a negative signal estimate is reported beside a bounded interval; the ML
estimate replaces it only when a scale's score interval holds no scale above 0 (the flight-like archive's free
fit, 10³ × the models). At these truths that happens in 0-3 of 500 fleets (0-0.6 %), the fallback shifts no mean
by more than +0.8 ± 0.6 %, the reported bias is the linear estimator's (within ±5 % beyond 2 s.e. at every truth
and scale except the debris scale at s_d = 0.3, β = 3, +3.4 ± 0.9 %, not resolved on 500 fleets and met on 1
000: +2.9 ± 0.6 %, the template share above) and the coverage is 0.890-0.920. The run was made with the
library's earlier rule, which the file's "library rule agrees" lines confirm (500 of 500 fleets at every truth);
both rules are computed by the benchmark itself from each fleet's linear estimates and intervals. Test
(`tests/test_flux_linear.py`,
`test_quoting_negative_linear_scales_keeps_the_reported_estimate_unbiased_and_covering`; 300 Poisson data sets
of 3 spacecraft-years, a linear scale below 0 in 47 %: the earlier rule lifts the reported debris mean by about
+20 % and its intervals cover 0.967 / 0.960; the rule now keeps both means at the truth within 4 s.e. and the
coverage at 0.913 / 0.907).

**Bias of the reported bias-corrected estimates** (the point estimates to average or combine with β free; with β
known the linear ones above; the ML ones stay the centre of the profile intervals):

* **β (fit A)**: within ±5 % beyond the Monte Carlo noise in **7 of 8 truths** (held out included; −3.7 to +1.9
  %). **Not at s_d = 0.3, β = 1: +7.9 ± 0.4 %** (4 000 fleets), where the ML β is −6.8 ± 0.3 % low: the
  first-order correction over-corrects by about as much as the bias it removes (the meteoroid signal there is
  9.4 detections on 32.8 false alarms, β̂ scatters by 70 %, and the O(1/n²) terms the correction ignores are as
  large as the O(1/n) one). The signed ML β (+4.9 ± 0.4 %) is not shown inside either.
* **The Jeffreys-penalised β (Firth, in (ln s, ln β)) does not replace it.** At that worst truth it is unbiased
  (−0.1 ± 0.1 %, 4 000 fleets; the ridge benchmark's −0.5 ± 2.1 % on 300 other fleets reproduced), but put
  through all eight truths it **exceeds ±5 % at five**: +22.1 ± 0.2 % (s_d = 1, β = 1), +41.7 ± 0.4 % (s_d = 3,
  β = 1), −7.9 ± 0.2 % and +6.8 ± 0.3 % (s_d = 0.3 and 3, β = 3) and, held out, +11.4 ± 0.3 % (s_d = 2, β = 2);
  it meets the bound at three (−0.1, +0.9, −2.5 %). The independent grid implementation of the ridge benchmark
  gives the same at s_d = 1, β = 1 (+24 ± 5 %, median +17 %, 100 fleets: `ABRUPT_RESULTS=0 nice python
  benchmarks/bench_flux_ridge.py --debris-scale 1 --reps 100`, a check not kept as a result file), so the bias
  is the estimator's, not the code's. The penalty ½ ln det I pulls towards where the information is large; with
  more debris detections that is towards larger β (where the debris carry β-information through the curvature),
  and the pull is not the O(1/n) bias term except where one population alone carries β (the canonical case of
  *Point estimates*). It therefore stays a simulation-study option (`fit(..., penalised=True)`,
  `penalised_estimates`), off the CLI and the report; the reported bias-corrected β stays Cox-Snell. Its debris
  scale (−4.9 to +57 %) is closer than the others' (+38 to +199 %) but meets ±5 % at one truth only (−1.2 ± 0.8
  %, s_d = 1, β = 1).
* **flux scales with β known (fit B)**: **the reported linear scales meet the bound at all 16 truth × parameter
  pairs** (*Fit B with β known* above). The ML ones, before the linear estimator was added and the bin
  efficiency weighted (the reason for it): the bias-corrected (= signed) estimates are within ±5 % beyond noise
  in **14 of 16 truth × parameter pairs** (held out included; none exceeds); **not resolved in 2, both at β =
  1**: s_debris at s_d = 0.3 (−6.8 ± 1.1 % on 4 000 fleets, −7.1 ± 1.5 % on the first 2 000: 5.1 expected debris
  detections per fleet, a single fleet's estimate scatters by 150 %; if the bias is −6.8 %, placing it outside
  ±5 % needs s.e. ≤ 0.9 %, about 6 000 fleets, 15 CPU-minutes more than this round had) and s_meteoroid at s_d =
  1 (−5.1 ± 0.7 %, 2 000 fleets: a bias this close to the bound cannot be placed on either side without an s.e.
  of a few 0.01 %, some 10⁵-10⁶ fleets; not run). The bounded ML estimates exceed the bound where a population's
  estimate piles up at 0 (+11.2 % debris at s_d = 0.3, +5.1 and +8.8 % meteoroid): the signed estimate is the
  one to average.
* **Why the known-β scales miss at those two truths: the estimator, not the template** (`nice -n 10 python
  benchmarks/bench_flux_asimov.py`, `docs/results/bench_flux_asimov.txt`, 277 s CPU at a load of 5-9; tests
  `tests/test_flux_asimov.py`). Candidates: (a) the fit template's error, (b) the optimiser, its grid or the
  positivity bound, (c) the false-alarm model. (1) *Asimov fits* (the exact expected counts fitted as data):
  with the simulator's exact cells the fit returns the truth to 10⁻⁴ %; with the fit template's cells (another
  seed, 400 000 draws) it is off by **+1.2 % (s_debris) and −1.0 % (s_meteoroid) at s_d = 0.3, β = 1**, +0.3 /
  −0.8 % at s_d = 1, −0.0 / −0.0 % at s_d = 3 (β = 3: up to +1.7 / −1.5 %). This template share does not shrink
  steadily with the template's draws (100 000: −0.2 / +1.0 %; 1 600 000: +0.3 / −0.2 % at the worst truth),
  since the draw template's own 400 000 draws are the reference; the forward model's smoothing and bin
  efficiency, measured on the draw seed's own template, add −0.04 to +0.13 % (with the plain bin-mean efficiency
  before the spectrum weighting −0.3 to −0.7 % to s_meteoroid, and the fit-template shifts up to +1.8 / −2.0 %).
  So (a) explains at most 2 %, and at s_d = 0.3 its sign is opposite to the −6.8 % seen. (2) *Fleets drawn as
  Poisson counts per (class, |ΔH| bin) cell* (the study's cells, 20 000 per truth, β = 1), fitted with the
  **exact** cells, so no template error at all: the signed ML is still biased, **s_debris −10.8 ± 1.2 % at s_d =
  0.3 and s_meteoroid −5.1 ± 0.8 % at s_d = 1** (−2.2 ± 0.8 % at s_d = 3), the same as the fleet benchmark's
  −6.8 ± 1.1 % and −5.1 ± 0.7 % within its noise (with the template's cells: −8.7 ± 1.1 % and −5.9 ± 0.8 %). The
  Cox-Snell O(1/n) term is exactly zero for a mean linear in the parameters, but with 5 debris (or 9 meteoroid)
  detections on 33 false alarms the higher-order terms are not small: the signed ML is a non-linear function of
  the counts whose spread is 110-160 %, and its mean is not its first-order value. (b) is not the cause either:
  this cell-space fit is an independent Newton solver on the exact likelihood (converged to a gradient of
  10⁻¹³), and the Asimov fit with β free lands within 0.4 % of β on the library's 161-point grid (0.1 % on a
  fine grid; within 1.1 % with the fit template). (c) is not: the false-alarms' expected total in the fit equals
  the simulator's to 10⁻¹³ (32.850 per fleet; both take each bin's share from the same logistic CDF). (3) *An
  exactly unbiased alternative*: the linear estimator with fixed weights, s̃ = I₀⁻¹ Σ_i a_i (n_i − B_i)/μ_i(θ₀)
  with θ₀ the published model (s = 1), has E s̃ = s for any θ₀ when the cells a_i are exact; measured, −0.4 ±
  0.8 % and −0.2 ± 0.7 % at those two truths (with the template's cells: +1.3 ± 0.8 % and −1.0 ± 0.7 %, the
  Asimov shift), and a smaller spread than the signed ML where the counts are few (1.19 against 1.64 at s_d =
  0.3). It is in the library, `abrupt.flux.linear.linear_estimates(lik, fixed)` on a likelihood at the known β
  (per-day cells, so fleets of unequal days are exact; test: fed the expected counts of two spacecraft analysed
  40 % and 100 % of each day with false alarms in the bins, it returns the truth to 10⁻⁹ for any θ₀), now the
  scales `fit` and `flux infer` report with β fixed (*Point estimates*, item 5; all eight truths in *Fit B with
  β known* below). On the benchmark's own event-level fleets (1 000 per truth, β = 1, the coverage run's first
  seeds, control-variate means) it is **within ±5 % beyond 2 s.e. at all three truths for both scales** (table
  rows above), where the library's signed ML on the same fleets gives −8.8 ± 2.2 % (s_debris, s_d = 0.3) and
  −2.5 ± 1.0 % (s_meteoroid, s_d = 1); its remaining −0.7 and −1.0 % on s_meteoroid at s_d = 1 and 0.3 (−1.2 and
  −1.4 % before the spectrum-weighted bin efficiency) is the fit template's Asimov shift. Not run: a larger
  template to remove the ~1 % template share. The same higher-order cause is plausible for fit A's β (the
  Cox-Snell β's +7.9 % at s_d = 0.3, β = 1): its Asimov fit is within −0.7 % of β with the fit template, so the
  template does not explain it either.
* **debris scale with β from the meteoroids (fit A)**: **not met, and no estimator tried can meet it** (+38 % to
  +199 % for the ML mean, its median within −1 to +7 %; the Jeffreys-penalised one −4.9 to +57 %): see *The
  debris scale on the β ridge* above for the estimators compared, the Cramér-Rao figures and the 150-300
  analysed spacecraft-years a 5 % mean would need. Quote its median, or the identified product, the expected
  debris detections (within ±5 % beyond noise in 6 of 8 truths, −2.5 to +1.7 %; not resolved at s_d = 0.3: +6.0
  ± 0.5 % at β = 1 on 4 000 fleets, +4.0 ± 0.6 % at β = 3), or measure β independently and use fit B. `flux
  infer` names this identified quantity for every fit with β free (the line `identified with beta free`, the
  HTML table's rows `expected … detections s·T(β) (identified)`, `expected_events` and the fit's `notes` in the
  JSON) and states these simulated figures in the result's notes.

**What causes the ML bias** (`nice python benchmarks/bench_flux_bias_checks.py`,
`docs/results/bench_flux_bias_checks.txt`):

1. *Not the forward model.* Its expected detections per population and direction class equal the exact sum over
   the simulator's own draws to within 0.15 % (same Monte Carlo seed; 0.2-0.4 % with the plain bin-mean
   efficiency before the spectrum weighting) and −0.1 to +0.5 % (the draw seed of the benchmark; 0.3-0.9 %
   before), at β = 1 and 3; the template noise of 400 000 draws is therefore below 1 %.
2. *Small samples.* The same truth (s_d = 0.3, β = 1) on fleets ten times larger (100 spacecraft-years, 60
   fleets) gives an ML β bias of −1.1 ± 2.7 % (median +0.5 %), against −8.3 ± 4.0 % for another 200
   ten-spacecraft fleets: the bias shrinks like 1/n, as the MLE's does, and the first-order correction above
   removes it at 10 spacecraft-years.
3. *The bound at 0* of the scales (truncation bias of the bounded ML estimate), removed by the signed estimate.
4. *Division by β* (fit A's debris scale), above: a property of the quantity, not of the estimator.

**Acceptance 3 — direction term**: median 90 % interval width of the meteoroid scale (β known), with direction
(fit B) / |ΔH| only (fit D): 2.59/3.50, 2.12/2.51, 2.93/5.06 (β = 1; s_debris = 1, 0.3, 3) and 1.27/2.08,
1.11/1.48, 1.45/2.90 (β = 3; same result files): the direction narrows the split in all six truths, by 16-50 %;
the |ΔH|-only intervals over-cover (0.930-0.990). On an Asimov data set with synthetic power laws the width
halves (0.80 vs 1.73, a test).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
from numpy.typing import NDArray

from abrupt.flux.exposure import DAYS_PER_YEAR, logistic_efficiency
from abrupt.flux.forward import (
    DIRECTION_CLASSES,
    POPULATIONS,
    ForwardConfig,
    OrbitCase,
    Template,
    build_template,
    direction_class,
    with_seed,
)
from abrupt.flux.inference import Likelihood, fit, prepare
from abrupt.simulate.population import FleetSpec, draw_population, fleet_exposure

ROOT = Path(__file__).resolve().parent.parent


def control_variate_mean(y: NDArray[np.float64], controls: NDArray[np.float64] | None) -> tuple[float, float]:
    """Mean of y and its Monte Carlo standard error, with control variates of known mean 0 (rows × k): the
    intercept of the least-squares fit y ~ 1 + controls, whose expectation is E[y] whatever the
    coefficients, and the spread of the residuals / √n. Without controls: the plain mean and s.d./√n."""
    n = y.size
    if controls is None or n <= controls.shape[1] + 2:
        return float(y.mean()), float(y.std(ddof=1) / math.sqrt(n)) if n > 1 else math.nan
    design = np.column_stack([np.ones(n), controls])
    coef, *_ = np.linalg.lstsq(design, y, rcond=None)
    resid = y - design @ coef
    return float(coef[0]), float(np.sqrt(resid @ resid / (n - design.shape[1])) / math.sqrt(n))


def interval_stats(
    rows: list[dict[str, float]],
    name: str,
    truth: float,
    estimate: str = "hat",
    controls: NDArray[np.float64] | None = None,
) -> tuple[float, float, float, float, float, float, float, int]:
    """(coverage of the rows with intervals, mean estimate / truth − 1 over all rows, its Monte Carlo standard
    error, the plain mean's bias and standard error, median estimate / truth − 1, median interval width /
    truth, number of rows with intervals). With ``controls`` (per row, known mean 0) the mean is the
    control-variate estimate (same expectation, less Monte Carlo noise)."""
    est = np.array([r[f"{name}_{estimate}"] for r in rows])
    with_iv = [r for r in rows if f"{name}_lo" in r]
    lo = np.array([r[f"{name}_lo"] for r in with_iv])
    hi = np.array([r[f"{name}_hi"] for r in with_iv])
    cover = float(np.mean((lo <= truth) & (truth <= hi))) if with_iv else math.nan
    if estimate in ("lin", "rneg", "rempty"):  # the linear (or reported) estimate's own interval, every fleet
        with_iv = rows
        lo = np.array([r[f"{name}_{estimate}_lo"] for r in rows])
        hi = np.array([r[f"{name}_{estimate}_hi"] for r in rows])
        cover = float(np.mean((lo <= truth) & (truth <= hi)))
    mean, se = control_variate_mean(est / truth, None if controls is None else controls[: est.size])
    plain_mean, plain_se = control_variate_mean(est / truth, None)
    return (
        cover,
        mean - 1,
        se,
        plain_mean - 1,
        plain_se,
        float(np.median(est) / truth - 1),
        float(np.median(hi - lo) / truth) if with_iv else math.nan,
        len(with_iv),
    )


def verdict(bias: float, se: float, target: float = 0.05) -> str:
    """'met' when the whole ±2 s.e. band of the bias lies within ±target; 'exceeds' when it lies wholly
    outside; else 'not resolved' (the run's Monte Carlo error cannot tell)."""
    if abs(bias) + 2.0 * se <= target:
        return "met"
    return "exceeds" if abs(bias) - 2.0 * se > target else "not resolved"


ESTIMATORS = {"hat": "MLE", "signed": "signed", "corr": "corrected", "firth": "Firth", "lin": "linear"}
# the reported estimate of a fit with β known (linear, else ML with its profile interval) under two rules
ESTIMATORS |= {"rneg": "rep.neg", "rempty": "rep.empty"}
FREE_B = ("debris_scale", "meteoroid_scale")


def negative_rule(row: dict[str, float]) -> bool:
    """Linear estimates quoted when every free scale is >= 0 and inside its non-degenerate interval (else ML)."""
    return all(
        row[f"{p}_lin"] >= 0 and row[f"{p}_lin_lo"] <= row[f"{p}_lin"] <= row[f"{p}_lin_hi"] > row[f"{p}_lin_lo"]
        for p in FREE_B
    )


def empty_rule(row: dict[str, float]) -> bool:
    """Linear estimates quoted (a negative one too) when every free scale's interval, clipped at 0, is not empty
    or degenerate (upper end above its lower end >= 0); else ML."""
    return all(row[f"{p}_lin_hi"] > row[f"{p}_lin_lo"] for p in FREE_B)


def add_reported(row: dict[str, float]) -> None:
    """The reported estimate and interval of a fit-B row under both rules (``rneg``, ``rempty``)."""
    for key, rule in (("rneg", negative_rule), ("rempty", empty_rule)):
        use_lin = rule(row)
        row[f"in_{key}"] = float(use_lin)
        for p in FREE_B:
            src = "lin" if use_lin else "hat"
            row[f"{p}_{key}"] = row[f"{p}_{src}"]
            ml = "" if f"{p}_lo" in row else "_fb"  # ML intervals of a fleet past --reps: its fallback refit
            lo, hi = (f"{p}_lin_lo", f"{p}_lin_hi") if use_lin else (f"{p}{ml}_lo", f"{p}{ml}_hi")
            row[f"{p}_{key}_lo"], row[f"{p}_{key}_hi"] = row[lo], row[hi]


def fit_known_beta(data, beta: float, intervals: bool, fallback: bool) -> dict[str, float]:  # type: ignore[no-untyped-def]
    """Fit B; with ``fallback`` also the reported estimates, refitting with the ML profile intervals the fleets
    whose linear estimates fall outside the physical range (the ML interval is then the reported one)."""
    row = one_fit(data, {"beta": beta}, intervals=intervals)
    if fallback:
        if not intervals and not (negative_rule(row) and empty_rule(row)):
            refit = one_fit(data, {"beta": beta}, intervals=True)
            row |= {f"{p}_fb_{end}": refit[f"{p}_{end}"] for p in FREE_B for end in ("lo", "hi")}
        add_reported(row)
    return row


def fallback_summary(rows: list[dict[str, float]], truth: dict[str, float], controls: NDArray[np.float64]) -> None:
    """Per truth: how often each rule falls back to the ML estimate, and the reported estimate's bias and coverage."""
    n = len(rows)
    lib = sum(r["in_library"] for r in rows)
    rules = (("rneg", "a linear scale < 0 (or outside its interval)"), ("rempty", "an interval empty at s >= 0"))
    for key, text in rules:
        k = n - int(sum(r[f"in_{key}"] for r in rows))
        same = sum(r[f"in_{key}"] == r["in_library"] for r in rows)
        print(
            f"{'':>22} fallback to ML when {text}: linear outside the physical range in {k} of {n} fleets "
            f"({k / n:.3f} ± {math.sqrt(max(k * (n - k), 1) / n) / n:.3f}); library rule agrees on {same} of {n}"
        )
        for p in FREE_B:
            neg = sum(r[f"{p}_lin"] < 0 for r in rows)
            cov, bias, se, *_ = interval_stats(rows, p, truth[p], key, controls)
            shift = np.array([r[f"{p}_{key}"] - r[f"{p}_lin"] for r in rows]) / truth[p]  # what the fallback adds
            print(
                f"{'':>22}   {p}: linear < 0 in {neg} of {n}; reported estimate's bias {bias:+.3f} ± {se:.3f} "
                f"({verdict(bias, se)}), coverage {cov:.3f}; reported − linear {shift.mean():+.3f} ± "
                f"{shift.std(ddof=1) / math.sqrt(n):.3f}"
            )
    print(f"{'':>22} library (flux infer) quotes the linear estimates in {lib:.0f} of {n} fleets")


def exact_cells(exposure, templates: dict[OrbitCase, Template], beta: float) -> NDArray[np.float64]:  # type: ignore[no-untyped-def]
    """Exact expected detections of ``draw_population`` per (source, direction class, |ΔH| bin) on a one-curve
    fleet, (3, C, K): for each population at unit scale, f/365.25 · Σ_i rate_i ε(β|ΔH_i|) over its own draws
    falling in the cell; for the false alarms Σ f b times the logistic size distribution's share of the bin,
    a third per class (isotropic directions)."""
    (tpl,) = templates.values()
    edges = tpl.config.edges_Nms
    n_cls, n_bins = len(DIRECTION_CLASSES), edges.size - 1
    f_years = float(exposure["analysed_fraction"].sum()) / DAYS_PER_YEAR
    x50, k, emax = (float(exposure[c].iloc[0]) for c in ("dH50_Nms", "efficiency_slope", "efficiency_max"))
    out = np.zeros((3, n_cls, n_bins))
    for p, pop in enumerate(POPULATIONS):
        smp = tpl.samples[pop]
        vec = beta * smp["dH_vec"]
        mag = np.linalg.norm(vec, axis=1)
        kbin = np.searchsorted(edges, mag, side="right") - 1
        use = (mag >= 1e-3 * x50) & (kbin >= 0) & (kbin < n_bins)
        w = f_years * smp["rate"][use] * logistic_efficiency(mag[use], x50, k, emax)
        out[p] = np.bincount(
            direction_class(vec[use]) * n_bins + kbin[use], weights=w, minlength=n_cls * n_bins
        ).reshape(n_cls, n_bins)
    cdf = logistic_efficiency(edges, x50, k, 1.0)
    fa = float((exposure["analysed_fraction"] * exposure["false_alarms_per_day"]).sum())
    out[2] = fa * np.diff(cdf)[None, :] / n_cls
    return out


def score_controls(
    cells: NDArray[np.float64], truth: dict[str, float], up: NDArray[np.float64], down: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Weights (3, C·K) of Σ_cells (n − μ) w: the score of (s_debris, s_meteoroid, β) at the truth with the
    simulator's exact cell means μ. Any fixed weights give a control of mean exactly 0 (E n = μ per cell);
    the score's are the ones most correlated with the estimates (θ̂ − θ ≈ I⁻¹ U to first order)."""
    s = np.array([truth["debris_scale"], truth["meteoroid_scale"], 1.0])
    mu = np.einsum("p,pck->ck", s, cells).ravel()
    d_beta = (np.einsum("p,pck->ck", s, up) - np.einsum("p,pck->ck", s, down)).ravel() / (2 * 0.05 * truth["beta"])
    safe = np.where(mu > 0, mu, 1.0)
    return np.stack([cells[0].ravel() / safe, cells[1].ravel() / safe, d_beta / safe]) * (mu > 0)


def one_fit(data, fixed, lik=None, intervals=True) -> dict[str, float]:  # type: ignore[no-untyped-def]
    res = fit(data, fixed=fixed, confidence=0.9, likelihood=lik, intervals=intervals, penalised=True)
    out = {"debris_detections_hat": res.expected_events["debris"], "in_library": float(res.linear_in_range())}
    for p, v in res.linear_estimates.items():  # β known: the reported linear estimate and its interval
        out[f"{p}_lin"] = v
        out[f"{p}_lin_lo"], out[f"{p}_lin_hi"] = res.linear_intervals.get(p, (v, v))
    for p, v in res.estimates.items():
        out[f"{p}_hat"] = v
        out[f"{p}_signed"] = res.signed_estimates.get(p, v)
        out[f"{p}_corr"] = res.corrected_estimates.get(p, v)
        out[f"{p}_firth"] = res.penalised_estimates.get(p, v)
        if intervals:
            lo, hi = res.intervals.get(p, (v, v))
            out[f"{p}_lo"], out[f"{p}_hi"] = lo, hi
    return out


def study_fleet() -> FleetSpec:
    """The acceptance study's fleet: 10 Fermi-like spacecraft for one year, a logistic detection efficiency
    (ΔH50 ≈ 5.8 mN·m·s, slope 4), 0.01 false alarms a day, 90 % of each day analysed."""
    return FleetSpec(
        str(ROOT / "examples" / "spacecraft" / "fermi_like.toml"),
        n_spacecraft=10,
        years=1.0,
        dH50_Nms=0.01 * np.exp(-np.log(9.0) / 4.0),
        efficiency_slope=4.0,
        false_alarms_per_day=0.01,
        analysed_fraction=0.9,
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--reps", type=int, default=200, help="fleets with profile intervals (coverage)")
    parser.add_argument("--bias-reps", type=int, default=1000, help="fleets for the bias (point estimates)")
    parser.add_argument("--free-reps", type=int, default=10, help="repetitions of the all-free fit C")
    parser.add_argument("--draws", type=int, default=400_000)
    parser.add_argument("--beta", type=float, action="append", help="truth β (repeatable; default 1 and 3)")
    parser.add_argument("--scales", type=float, nargs="+", default=[1.0, 0.3, 3.0], help="truth debris scales")
    parser.add_argument("--known-beta", action="store_true", help="fit B alone (β known): ML and linear scales")
    parser.add_argument(
        "--fallback",
        action="store_true",
        help="fit B alone at all eight truths (unless --beta is given): how often the linear scales fall outside "
        "the physical range and the reported estimate's bias and coverage",
    )
    args = parser.parse_args()
    args.known_beta = args.known_beta or args.fallback
    if args.fallback and not args.beta:
        eight = ((1.0, (1.0, 0.3, 3.0)), (3.0, (1.0, 0.3, 3.0)), (2.0, (0.5, 2.0)))  # the last two held out
        truths = [(b, s) for b, scales in eight for s in scales]
    else:
        truths = [(b, s) for b in args.beta or (1.0, 3.0) for s in args.scales]
    spec = study_fleet()
    t0 = time.perf_counter()
    cfg = ForwardConfig(n_draws=args.draws)
    fit_tpl = {spec.case: build_template(spec.case, cfg)}
    draw_tpl = {spec.case: build_template(spec.case, with_seed(cfg, 1000))}
    exposure = fleet_exposure(spec)
    print(f"templates built in {time.perf_counter() - t0:.1f} s ({args.draws} draws per population, 2 seeds)")
    print(
        f"{'truth':>22} {'fit':>3} {'param':>16} {'estimate':>9} {'coverage':>9} {'mean bias':>10} {'± s.e.':>7} "
        f"{'plain mean':>11} {'± s.e.':>7} "
        f"{'median bias':>12} {'width':>6} {'n':>5}  verdict"
    )
    summary = []
    n_all = max(args.reps, args.bias_reps)
    for beta, s_d in truths:
        truth = {"debris_scale": s_d, "meteoroid_scale": 1.0, "beta": beta}
        rows: dict[str, list[dict[str, float]]] = {"A": [], "B": [], "C": [], "D": []}
        n_events: list[int] = []
        counts: list[NDArray[np.int64]] = []
        cells = exact_cells(exposure, draw_tpl, beta)
        weights = score_controls(
            cells,
            truth,
            exact_cells(exposure, draw_tpl, beta * math.exp(0.05)),
            exact_cells(exposure, draw_tpl, beta * math.exp(-0.05)),
        )
        n_bins = cells.shape[2]
        mu_cells = np.einsum("p,pck->ck", np.array([s_d, 1.0, 1.0]), cells).ravel()  # at the truth
        t1, c1 = time.perf_counter(), time.process_time()
        for rep in range(n_all):
            # the first 500 fleets as before; past them seeds that no other truth uses
            seed = 10_000 * int(beta) + 100 * int(10 * s_d) + rep
            if rep >= 500:
                seed = 10_000_000 * int(beta) + 100_000 * int(10 * s_d) + rep
            ev = draw_population(exposure, draw_tpl, truth, seed=seed)
            n_events.append(len(ev))
            data = prepare(exposure, ev, fit_tpl)
            counts.append(np.bincount(data.event_class * n_bins + data.event_bin, minlength=mu_cells.size))
            iv = rep < args.reps
            if not args.known_beta:
                rows["A"].append(one_fit(data, {"meteoroid_scale": 1.0}, intervals=iv))
            rows["B"].append(fit_known_beta(data, beta, iv, args.fallback))
            if iv and not args.known_beta:
                rows["D"].append(one_fit(prepare(exposure, ev, fit_tpl, use_direction=False), {"beta": beta}))
            if rep < args.free_reps and not args.known_beta:
                rows["C"].append(one_fit(data, {}, Likelihood(data)))
            if rep == 0:  # expected debris detections of the truth (what s_debris·β^α measures)
                truth_det = s_d * float(Likelihood(data, np.array([beta])).totals[0, 0])
        label = f"s_d={s_d:g} s_m=1 beta={beta:g}"
        controls = (np.array(counts) - mu_cells) @ weights.T  # the score at the truth: exact mean 0
        for key, params, estimators in (
            ("A", ("beta", "debris_scale"), ("hat", "signed", "corr", "firth")),
            ("B", ("debris_scale", "meteoroid_scale"), ("hat", "signed", "corr", "lin")),
            ("D", ("debris_scale", "meteoroid_scale"), ("hat",)),
            ("C", ("debris_scale", "meteoroid_scale", "beta"), ("hat",)),
        ):
            for p in params:
                for est in estimators:
                    if not rows[key]:
                        continue
                    cov, bias, se, pbias, pse, mbias, width, _ = interval_stats(rows[key], p, truth[p], est, controls)
                    v = verdict(bias, se) if key in "AB" else ""
                    summary.append((label, key, p, ESTIMATORS[est], cov, bias, mbias, width, se, v))
                    print(
                        f"{label:>22} {key:>3} {p:>16} {ESTIMATORS[est]:>9} {cov:9.3f} {bias:+10.3f} {se:7.3f} "
                        f"{pbias:+11.3f} {pse:7.3f} {mbias:+12.3f} {width:6.2f} {len(rows[key]):5d}  {v}"
                    )
        if args.fallback:
            fallback_summary(rows["B"], truth, controls)
        if rows["A"]:
            det = np.array([r["debris_detections_hat"] for r in rows["A"]])
            bias, se = control_variate_mean(det / truth_det, controls)
            bias -= 1
            v = verdict(bias, se)
            print(
                f"{label:>22} {'A':>3} {'debris detect.':>16} {'MLE':>9} {'':>9} {bias:+10.3f} {se:7.3f} "
                f"{np.median(det) / truth_det - 1:+12.3f}  (truth {truth_det:.1f}: s_debris·β^α) {v}"
            )
            summary.append((label, "A*", "debris_detections", "MLE", math.nan, bias, 0.0, 0.0, se, v))
        floor = np.mean([r["beta_hat"] < 0.11 for r in rows["A"]]) if rows["A"] else math.nan
        print(
            f"{'':>22} detections per fleet in the fit's bins: mean {np.sum(counts) / len(counts):.2f}, exact "
            f"expectation {mu_cells.sum():.2f}; control variates: the score at the truth (exact mean 0)"
        )
        print(
            f"{'':>22} events per fleet: mean {np.mean(n_events):.1f}; fit A beta at the grid floor in "
            f"{floor:.3f} of fleets; {n_all} fleets ({args.reps} with intervals) in "
            f"{time.perf_counter() - t1:.1f} s wall, {time.process_time() - c1:.1f} s CPU"
        )
    print(
        f"\nTargets: coverage 0.85-0.95 (90 % intervals, {args.reps} fleets; linear intervals: all {n_all}); mean "
        f"bias within ±0.05 ({n_all} fleets): 'met' when bias ± 2 s.e. lies inside ±0.05."
    )
    covs = [x[4] for x in summary if x[1] == "B" and x[3] == "linear"]
    if covs:
        se = math.sqrt(0.09 / n_all)
        print(f"fit B, linear intervals: coverage range {min(covs):.3f}-{max(covs):.3f} (binomial s.e. {se:.3f})")
    for key in ("A", "B", "D"):
        covs = [x[4] for x in summary if x[1] == key and x[3] == "MLE" and not math.isnan(x[4])]
        if not covs:
            continue
        print(f"fit {key}: coverage range {min(covs):.3f}-{max(covs):.3f} over {len(covs)} (truth, parameter) pairs")
    for key in ("A", "B", "A*"):
        for p in ("beta", "debris_scale", "meteoroid_scale", "debris_detections"):
            for est in ESTIMATORS.values():
                got = [x[9] for x in summary if x[1] == key and x[2] == p and x[3] == est]
                if got:
                    tally = {v: got.count(v) for v in ("met", "not resolved", "exceeds")}
                    text = ", ".join(f"{k} {v}" for k, v in tally.items())
                    print(f"fit {key}, {p}, {est}: mean bias {text} (of {len(got)} truths)")
    widths = {(x[0], x[1]): x[7] for x in summary if x[2] == "meteoroid_scale" and x[1] in "BD" and x[3] == "MLE"}
    if not args.reps or args.known_beta:
        return
    print("\nAcceptance 3: median 90 % interval width of the meteoroid scale, with direction (B) / |ΔH| only (D):")
    for label in dict.fromkeys(k[0] for k in widths):
        print(f"  {label}: {widths[(label, 'B')]:.2f} / {widths[(label, 'D')]:.2f}")


if __name__ == "__main__":
    from _results import variant, write_results

    # --reps 0: point estimates only (the coverage files keep the intervals); --scales 0.3: the worst truth alone
    names = {"--beta=1": "beta1", "--beta=3": "beta3", "--beta=2": "beta2_heldout", "--reps=0": "points"}
    names["--scales=0.3"] = "worst"
    names["--known-beta"] = "known"
    if "--fallback" in sys.argv:  # its own file, whatever --reps
        names = {"--fallback": "fallback"}
    with write_results("bench_flux_coverage", variant(names)):
        main()
