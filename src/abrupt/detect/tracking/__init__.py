r"""Maneuver detectors on ground tracking: the batch GLR test and Kaderali's Ψ/K filter
(Kaderali 2021).

Command line
------------

The diagnostics (`--diagnostics-out`) carry each series' threshold, the GLRT's too (its χ²₃ level for the
budget, split over the candidate epochs) also when nothing exceeds it; the fit summary (`--fit-out`) holds it as
`glrt_threshold`, and `report tracking` draws it in the T(τ) panel.

`detect tracking` options: `--method both|kaderali|glrt`, `--false-alarms RATE` (both detectors; `0.1/day` by
default, also `1/week`, `2/year`; `--false-alarms-per-day` is an alias), `--psi-threshold`/`--eta-threshold`
(thesis Ψ_th, η_th), `--mask DEG` (elevation mask; the thesis's reproducibility hinges on it),
`--estimate-biases`, `--estimate-acceleration`, `--refraction`, `--max-maneuvers`, `--kaderali-threshold
simulated|chi2`. Events have the event columns of the README; `tracking.glrt` fills `time_sigma_s`, `dv_r_mps`,
`dv_t_mps`, `dv_n_mps`, `dv_mps` and adds `dv_sigma_mps`, `dv_{r,t,n}_sigma_mps`, and for cross-track burns
`alternative_time_utc`/`alternative_dv_mps` (see Limitations). `tracking.kaderali_k` reports K_max as the
statistic, Δv from the calibration fit (default: the thesis's apogee transverse log fit) with `dv_sigma_mps`,
`dv_calibration_status` and the thesis's `direction_heuristic`.

**Stated sigmas are checked against the data.** Both detectors threshold residuals divided by the set-up's
sigmas, so sigmas stated k times too small would make every statistic k² times too large. At the start of
`detect`, each detector (`tracking.glrt`, `tracking.kaderali_k`, however it is called: command line,
`abrupt.api`, the registry) measures the data's own noise on the maneuver-free fit (`calibrate_noise`, kept on
the series, so the second detector of a run reuses it and a calibrated series is never scaled again): the robust
scale (1.4826 × MAD / √6) of second differences of consecutive whitened residuals of one station and measurement
type within a pass (`abrupt.detect.tracking.noise_scale`; smooth signatures such as a maneuver's or a force
model's offset and trend within a pass cancel in them). When that noise is above the stated sigmas, every sigma
is multiplied by its lower 2σ bound (never by less than 1) before either detector thresholds; the fit summary's
`noise` block, the printed `noise:` line and each detector's diagnostics (`extra["noise"]`) give the measured
ratio and the factor. A thesis arc simulated with 3× or 5× the stated noise gives no event (with the stated
sigmas: 3 GLRT and 5 Kaderali false events at 4×), and a 10 cm/s burn in it is still found
(`tests/test_tracking_noise_scale.py`). When the post-fit residuals, impulses included, stay more than 2.5 times
above both the stated sigmas and the measured noise, the set-up's model is not the data's (force model,
stations, frames) and the command refuses with one line naming the file and the weighted RMS instead of
reporting impulses: e.g. the simulated LAGEOS-1 day of `docs/formats.md` with a 20×20 field in its set-up while
the simulation has J2 + Sun + Moon: `post-fit weighted RMS 3.61 with 3 impulse(s), against a noise level of
0.0605 stated sigmas` (before, exit 0 and 3 + 3 impulses). W3B's noise is 0.08 of its stated sigmas, so its
sigmas stay as stated and its result below is unchanged. Called from the Python API, the detectors do not refuse
but return that line in `DetectionResult.warnings` (both detectors judge the maneuver-aware fit, impulses
included; `tracking.kaderali_k` started with `start="orbit_fit"` gives no such warning, since the plain orbit
fit of an arc with a burn in it is expected not to fit).

The report draws Ψ (log) and K against time with the detection threshold, the GLRT statistic T(τ) over candidate
epochs, and detected (orange dashed) and true (black dotted) maneuvers.

Inputs
------

* CCSDS TDM (KVN): Reader: `abrupt.readers.tdm.read_tdm` / `write_tdm`; Notes: RANGE (km; round-trip paths
  halved), ANGLE_1/ANGLE_2 (AZEL, deg), DOPPLER_INSTANTANEOUS (km/s); TIME_SYSTEM UTC/TAI/GPS/TT → UTC;
  `YYYY-DDD` epochs; unused keywords (RECEIVE_FREQ …) skipped and counted
* Orekit text `.aer`: Reader: `abrupt.readers.aer.read_aer`; Notes: `DATE RANGE
* Orekit OD input `.in`: Reader: `abrupt.readers.orekit_od_input.read_od_input`; Notes: `orbit.date`, cartesian
  or keplerian a-priori orbit (EME2000), `ground.station.*[k]` (lat/lon/alt, sigmas, range bias and whether it
  is estimated, range tropospheric correction, refraction), ellipsoid, force model (`central.body.degree/order`
  > 2 → EGM2008 field, 2 → J2; Sun/Moon; `solar.radiation.pressure` with `cr`, `area`; `drag` with `cd`, `area`;
  `mass`; `drag.cd.estimated` / `solar.radiation.pressure.cr.estimated` → scale factors estimated); abrupt
  extension keys `abrupt.earth.rotation`, `abrupt.mu`

Bad input (each has a test in `tests/test_tracking_readers.py`): malformed lines, non-numbers, wrong value
counts, unparseable dates, unsupported types/units, implausible values (wrong units: negative range, elevation >
90°, km where m expected), unknown stations (reader and array builder), truncated TDM (no DATA_STOP /
META_STOP), conflicting duplicates → `InputError` naming file:line:column and the reason. Out-of-order lines
(sorted) and identical duplicates (dropped) are counted repairs in the `RepairLog` and printed by the CLI.

Ranges in the wrong unit (`abrupt.model.implied_orbit`, run by `pipelines.tracking.read_tracking_arrays` once
the set-up's stations are known): a station's ranges with its angles are positions, two positions of a pass a
velocity, and vis-viva bounds the speed of every Earth satellite at radius r between the apogee speed of an
orbit grazing the surface, √(2μR_E/(r(r+R_E))), and the escape speed √(2μ/r). A station whose median speed ratio
lies beyond either bound by more than three standard errors is an `InputError` naming the file, column `range`
and the station. W3B's real arc passes (each station's implied speeds within 3 % of vis-viva on the set-up's
a-priori transfer orbit); its ranges ×0.1 imply 0.06-0.11 of the least speed, ×10 13-20 times the escape speed
(`tests/test_implied_orbit.py`). Velocity baselines come from the station's stated sigmas (noise at most 5 % of
the circular speed): sigmas stated far (≳ 10×) below the real noise could make a pass look faster than escape. A
station without angles gives no speed; every station's ranges are also held against the set-up's a-priori orbit
(two-body; the fit linearises around it): a median ratio of measured to predicted range beyond a factor of two
is refused as a unit error or an a-priori of another satellite (W3B's ranges: within 0.11 % over the 15.8-hour
arc; before this check range-only ranges ×0.1 ended in `need at least 10 finite event-free samples to fit a
threshold`).

Method
------

**Frames and measurements** (`abrupt.model.tracking_measurements`, `abrupt.model.stations`). Site vector from
geodetic coordinates (Kaderali Eq. 3.12), SEZ rotation (Eq. 3.15), ECI→ECEF as C3(θ) with Ċ = ω_E dC3/dθ
(Kaderali 2021, with a sign erratum fixed), azimuth atan2(ρ_E, −ρ_S) from North (Kaderali 2021, corrected),
range-rate with Earth rotation, and the full analytic H (checked against finite differences). Earth orientation:
`simple` (θ = θ₀ + ω_E t, the thesis convention) or `iers` (ERFA IAU 2006/2000A c2t06a with astropy's bundled
UT1−UTC; checked against astropy GCRS→ITRS to < 300 m at 42 000 km, polar motion neglected). Elevations can be
corrected for refraction (Bennett 1982).

**Truth** (`abrupt.model.orbit`, `abrupt.simulate.tracking`). Cowell two-body with finite constant-acceleration
burns in R/S/W, fixed in inertial space at onset (thesis §4.1; `rotating` option), DOP853 with break-points at
every burn edge (Kaderali 2021, corrected), optional J2 and analytic Sun/Moon (Vallado Alg. 29/31).

**Kaderali EKF** (`abrupt.detect.tracking.kaderali`). Appendix A steps 1–16 with the typos fixed: RK4 state +
STM (Eqs. 3.3–3.4) between processed epochs (across gaps in one step), Ψ (Eq. 3.24), Joseph update, P̂ ← 10 P̂
if Ψ > Ψ_th and tr P̂ < η_th, Q from Table 3.1 (literal: Q = 0 below Ψ = 10⁵), K (Eq. 3.26). Thesis units are
converted at the boundary (km² → m²; η_th compared with tr P̂ in km units). **Starting state.** The registered
detector (command line `--method both` and `--method kaderali`, the Python API, the registry alike) starts the
filter from the GLRT's maneuver-aware fit: the state at the arc's start fitted with the impulses the GLRT finds
(one search per series, shared with `tracking.glrt`). The fit of the whole arc as one orbit
(`KaderaliManeuverDetector(start="orbit_fit")`) is bent by a burn later in the arc towards the post-burn orbit:
on a simulated thesis arc with a 0.1 m/s apogee burn (the first burn arc of `bench_tracking_false_alarms.py`)
its starting position is 1.3 km off the truth (maneuver-aware fit: 4.7 m), the pass before the burn has whitened
residuals of RMS 41 (0.92), and the filter raises that pass (Ψ 8929 against a threshold of 63; maneuver-aware
start: 10.5), an event more than 30 min before the burn on every such arc. Characterisation: the five thesis
models with R² and adjusted R² (Kaderali 2021 ch. 4), inversion with monotonicity and floor checks, and a
delta-method Δv uncertainty . Events: runs of Ψ above a detection threshold, reported at their K_max. The
threshold is set for the requested false alarms per day from event-free simulations of the same data set (same
epochs, stations, measurement types and sigmas, orbit from the fit; 8 runs, generalised-Pareto tail via
`abrupt.thresholds.fit_threshold`; test: an independent null arc exceeds it at the budgeted per-sample rate), or
(`--kaderali-threshold chi2`) the χ²_m quantile, which is too low because Ψ of this filter is heavier-tailed
than χ² (1°-mask null K_max reaches 40 dB in 10 % of arcs).

**GLRT** (`abrupt.detect.tracking.glrt` on the fit of `abrupt.model.orbit.batch_fit`). (1) Weighted Gauss-Newton
fit of the state at t0, per-station range (and for real data az/el) biases, an optional constant acceleration
and known impulses; outliers > 6σ dropped from the 3rd iteration (not while searching for maneuvers, so a
maneuver is never rejected as outliers). (2) For each candidate epoch τ (period/120 grid) the linearised model r
= J₀δp + J_v(τ)Δv + w with J_v(τ) = W H Φ(t,t0) Φ(τ,t0)⁻¹ [0;I] C_RSW(τ) for t > τ; T(τ) =
r̃ᵀJ̃_v(J̃_vᵀJ̃_v)⁻¹J̃_vᵀr̃ (projected orthogonally to J₀) is χ²₃ under "no maneuver" (Willsky & Jones 1976).
(3) If max T exceeds the χ²₃ threshold for the false-alarm budget (Bonferroni over candidates), the epoch is
chosen coarse to fine: one nonlinear refit at the candidate of largest T, then Gauss-Newton steps of the
epoch itself from that refit's variational matrices (moving the impulse by δτ changes the state after it by
δτ [−Δv; Ċ_RSW Δv_RSW]; Montenbruck & Gill 2000 §7.2), each confirmed by one refit; the statistic reported is
the nonlinear likelihood ratio χ²(without) − χ²(with); Δv and its covariance come from the joint fit; the
epoch uncertainty is 1/√(Fisher information of τ), the other parameters free. Repeats for further maneuvers.
The laser detector's epoch search spends at most 12 nonlinear refits per arc and detection allowed
(`glrt.RefitBudget`, shared by its re-weighting rounds); once spent, epochs stay where the scan and the refits so far
put them and one warning line names the arc and the candidates left unrefined.

Real tracking: Eutelsat W3B
---------------------------

`abrupt detect tracking W3B.aer --setup od_test_W3.in --fit-out fit.json` (the Orekit W3B test case files; about
15 s). The fit uses the set-up file's own model, as Orekit does: EGM2008 to degree and order 20, Sun and Moon,
solar radiation pressure (C_R 2, 13.12 m², 1000 kg, conical shadow), exponential-atmosphere drag with its scale
estimated (`drag.cd.estimated = true`), **two-way light time** for the ranges and downleg light time for the
angles (Orekit's `Range(station, twoWay=true)` and `AngularAzEl`), the Saastamoinen tropospheric delay with the
Chao mapping in the standard atmosphere (`range.tropospheric.correction = true`), refraction-corrected
elevations, per-station range and az/el biases and a constant acceleration (the leak).

* range bias CastleRock (km, incl. 5.969 on-board): this fit: 17.348 ± 0.073; Orekit batch LS: 17.243; Orekit
  Kalman (extended / unscented): 17.258 / 17.302
* Fucino: this fit: 19.433 ± 0.022; Orekit batch LS: 19.437; Orekit Kalman (extended / unscented): 19.451 /
  19.431
* Kumsan: this fit: 19.504 ± 0.020; Orekit batch LS: 19.482; Orekit Kalman (extended / unscented): 19.472 /
  19.485
* Pretoria: this fit: 19.476 ± 0.090; Orekit batch LS: 19.563; Orekit Kalman (extended / unscented): 19.578 /
  19.503
* Uralla: this fit: 19.405 ± 0.070; Orekit batch LS: 19.419; Orekit Kalman (extended / unscented): 19.411 /
  19.387
* C_D (a priori 2): this fit: 0.21 ± 0.04; Orekit batch LS: −0.22; Orekit Kalman (extended / unscented): 0.19 /
  −0.02
* leak acceleration (m/s²): this fit: 7.2 × 10⁻⁶ ± 0.4 × 10⁻⁶ (constant); Orekit batch LS: 8.0 × 10⁻⁶ + 3.1 ×
  10⁻¹⁰ t; Orekit Kalman (extended / unscented): 6.0 × 10⁻⁶ + 1.8 × 10⁻¹⁰ t / 6.0 × 10⁻⁶ + 1.6 × 10⁻¹⁰ t

Every station's bias is within 1.5 of our σ of Orekit's batch value (test
`test_w3b_real_tracking_fit_estimates_biases_and_an_unmodelled_acceleration` asserts 3σ). Weighted RMS 0.54 on
all 860 observations (set-up sigmas 20 m, 0.02°). The acceleration points 11.6° from the anti-Sun direction: a
steady push far above nominal radiation pressure, as the provenance notes (W3B leaked propellant). Orekit's
numbers are from its `KalmanNumericalOrbitDeterminationTest.testW3B*` (which quotes the batch values); Orekit
models the leak as a first-degree polynomial in time, abrupt as a constant.

What each model term did to the biases (differences from Orekit's batch values, km; Castle/Fucino/
Kumsan/Pretoria/Uralla): the earlier J2 + Sun + Moon instantaneous model +0.71/−0.43/+0.29/−1.06/−0.26; adding
light time +0.22/−0.03/+0.10/−0.38/−0.07; plus the 20×20 field and SRP +0.10/0.00/+0.06/−0.25/0.00; plus
troposphere +0.08/0.00/+0.05/−0.25/−0.01; plus drag with its scale estimated (the perigee is at 213 km)
+0.10/0.00/+0.02/−0.09/−0.02. Light time was the largest single error: a GTO near apogee is 0.13 light-seconds
away and moves its range by up to 3 km/s.

**Events.** With this model neither detector declares anything (`--method both`, and `--method kaderali` alone,
which starts from the same maneuver-aware fit): the GLRT's largest statistic stays below its threshold and
Kaderali's K test is quiet. A model without light time and drag declares a 1.7 m/s "impulse" at 17:15 UTC and
two to six K peaks: the impulse absorbs perigee drag and the light-time error. No operator history exists for
this arc, so the quiet result cannot be confirmed either, but it is what Orekit's fits, which need no impulse,
imply. Kaderali's EKF runs on measurements reduced by the fit's model (light time, troposphere, time biases
subtracted on the fitted trajectory) with the fitted scale factors, so that its instantaneous model and the fit
see the same data.

Laser ranging (ILRS CRD, SINEX): `abrupt detect laser`
------------------------------------------------------

::

    abrupt detect laser lageos1.npt --apriori lageos1.cpf --out laser.csv \
        --false-alarms 0.1/day [--sinex ilrs.snx] [--without troposphere ...] [--fit-out fit.json]

**The a-priori orbit is required** (`--apriori`: a CPF prediction from the ILRS data centres, any OEM/SP3 that
covers the ranges, or TLE/3LE/OMM element sets): the fit linearises the ranges about it and a few normal points
cannot start an orbit of their own. Element sets are propagated by SGP4 (the set nearest each arc's start, at
most 30 days away; TEME to GCRF with ERFA, within 5 m of astropy's) and, since they are hundreds of metres to
kilometres off, first fitted to the arc's own ranges over a short arc (6, 12, 24, 48 h: the state only; the
growth stops before a span that leaves more than 1 m, i.e. one holding a maneuver) before detection
(`abrupt.pipelines.laser_apriori`); `--fit-out` reports each arc's SGP4 offset and short-arc RMS. On a simulated
LAGEOS day from a TLE 9 km off at its epoch (50 km and 20 m/s at the first range two hours later) the fitted
state is within 9 mm and 6 µm/s of the truth and the run is as quiet as from a precise a-priori; over two days a
(3, 8, −5) mm/s burn is found at its time with its ΔV within 20 % (`tests/test_laser_apriori_elements.py`). The
shared `lageos1-test.npt` (2021, stations 1893 and 7839) has no CPF at hand, so `abrupt detect laser` on it
stops at the a-priori check after resolving its stations from the bundled file; the doc test runs this command
on a simulated day of LAGEOS-1 normal points instead.

**Station coordinates come with abrupt**: without `--sinex`, the ILRS SLRF2014 positions and velocities of all
179 SLR stations (release 2020-04-28; `abrupt/data/ilrs/`, Apache-2.0 via Orekit's test resources, provenance
and licence beside the file; `abrupt.readers.sinex.bundled_ilrs_sinex()`) are used. A station the file lacks
(e.g. `9998` in Orekit's `lageos2_201802.npt.v2C`) stops the run with a one-line error that names it and says to
pass a SINEX file holding it with `--sinex FILE`. The SINEX reader takes real files as they are: accented names
in free-text blocks (read as Latin-1) and open-ended epochs written with day `000` (`30:000:00000`).

Laser ranges are millimetre-precise, so every modelling shortcut becomes the detector's noise. Each two-way
range is **reduced** to an instantaneous geometric range at its bounce epoch (`abrupt.model.range_reduction`),
with terms that can be switched off one by one (`--without`):

* light time: model: two legs solved iteratively (3 iterations, converges by v/c per step); source: Montenbruck
  & Gill 2000 §6.2; size for LAGEOS (simulated, max / RMS over a day): 82 m / 44 m
* troposphere: model: Mendes-Pavlis zenith delay + FCULa mapping (laser); Saastamoinen + Chao (radio); source:
  IERS Conventions 2010 §9.2; size for LAGEOS (simulated, max / RMS over a day): 7.0 m / 4.3 m
* plate motion: model: SINEX position + velocity × (t − t₀); source: SINEX 2.02; size for LAGEOS (simulated, max
  / RMS over a day): 0.56 m / 0.19 m (9 years at a few cm/yr)
* eccentricity: model: SINEX `SITE/ECCENTRICITY` (UNE) rotated to ECEF; source: SINEX 2.02; size for LAGEOS
  (simulated, max / RMS over a day): 0.47 m / 0.24 m
* solid tides: model: degree 2 and 3 in-phase displacement, step 1; source: IERS Conventions 2010 §7.1.1; size
  for LAGEOS (simulated, max / RMS over a day): 0.13 m / 0.07 m
* Shapiro delay: model: (2GM/c²) ln((r₁+r₂+ρ)/(r₁+r₂−ρ)) per leg; source: IERS Conventions 2010 Eq. 11.17; size
  for LAGEOS (simulated, max / RMS over a day): 1.5 cm / 0.8 cm

Sizes from `tests/test_laser_ranging.py` (the same numbers are asserted there as physical ranges). The
meteorology of each range comes from the CRD `20` records (pressure, temperature, humidity); a range without one
uses the standard atmosphere at the station height, counted as a repair. Ranges the station already corrected
for the troposphere (CRD `H4`) get no further delay. CRD epochs are moved to the receive time from their epoch
event (0 receive, 1 bounce, 2 transmit). The satellite's centre-of-mass offset (LAGEOS 0.251 m) and station
system biases are absorbed by the per-station range biases the fit estimates.

**Force model.** `abrupt detect laser` fits real data with the one orbit model of `abrupt.model.orbit`: the
EGM2008 field to degree and order 20 (`--gravity-degree`; LEO satellites such as Stella need more), Sun, Moon,
and solar radiation pressure with a conical shadow whose scale factor is estimated per arc (a-priori C_R·A/m
from `--area-to-mass`, default LAGEOS-1's); `--drag` adds exponential-atmosphere drag with an estimated scale.
The command-line test simulates a day of LAGEOS ranging with this model in the truth and 20 % more radiation
pressure than the a priori: the fitted SRP scale comes out within 0.1 of 1.2 and the day stays quiet. The
month-long simulations below keep the simpler J2 + Sun + Moon model in both truth and filter
(`SlrScenario.force`).

The orbit and per-station biases are fitted by weighted least squares; each station's sigma is then scaled by
the RMS of its own normalised post-fit residuals (never below the stated normal-point precision), so that the
GLRT threshold accounts for what the models leave unexplained. The out-of-view GLRT (above) scans for impulses
at the stated budget; after a detection, the ranges are reduced again on the trajectory with the impulse and the
scan is repeated. These steps are the registered detector `tracking.laser_glrt`
(`abrupt.detect.tracking.laser`), which reads a `LaserRangingSeries` (the ranges not yet reduced, with the sites
and the range model); its events carry that name. It is not `tracking.glrt`: the scan is the same, but the data
it scans are re-reduced and re-weighted between scans. The command prints the post-fit RMS, the sigma scale and
the range bias of every station.

**Long files are fitted in arcs.** A file longer than `--arc-days` (default 7, the ILRS analysis arc for LAGEOS)
is cut into equal overlapping arcs sharing one day (`abrupt.pipelines.laser_ranging.detect_laser_ranging_arcs`).
Each arc starts from the a-priori ephemeris where it covers the arc epoch, otherwise from the previous arc's
fitted trajectory (impulses included). Each arc owns its span up to the middle of its overlaps and reports only
detections in the part it owns, so a maneuver near an arc end is judged by the arc with data on both sides, and
is never reported twice. Each arc's budget is scaled by owned/arc length, so the campaign keeps the stated rate
per day. The filter integrates with an eighth-order fixed-step Runge-Kutta (Dormand-Prince's 8th-order solution,
12 stages) at 60 s: over 30 days of a LAGEOS orbit it stays within 2-5 mm of DOP853 at rtol 1e-13, where RK4
needs 5 s steps (RK4 at 60 s is metres off; `tests/test_tracking_model.py`).

**Epoch refinement.** The Gauss-Newton steps of the epoch bring it to the minimum of the nonlinear χ²(τ)
(within a tenth of its 1σ, 1/√c with c the curvature of χ²(τ): Δχ² = 1). With millimetre ranging
a 2 s epoch error leaves Δv·δτ ≈ 2 cm for 1 cm/s; without the refinement the GLRT absorbs that residue with a
second, spurious "impulse" of 0.03 mm/s next to every real maneuver.

The simulator `abrupt.simulate.slr` produces LAGEOS-like campaigns (four ILRS-like stations, two-minute normal
points, 20° mask, half of the passes tracked, per-pass meteorology, station biases) with every term above in the
truth, integrated with DOP853 at rtol 1e-13. Measured with `python benchmarks/bench_slr_lageos.py --days 30
--runs 10` (3 mm normal points, 0.1 false alarms/day, nothing tuned on these runs):

* maneuver-free months: 1 false alarm in 10 simulated months (per month: 0,0,0,0,0,0,0,0,1,0), 0.003/day against
  the 0.1/day budget; post-fit RMS 3.0-3.3 mm per station for 3.0 mm noise;
* 1 cm/s maneuvers in random directions at random times, one per simulated month: **found in 10 of 10 months**
  (runs 0-4 `--runs 5 --first-run 0`, runs 5-9 `--runs 5 --first-run 5`) with |ΔV| within 0.05 %, epochs within
  0.1 s, no other alarm;
* 3-day arcs: 0 false alarms in 6 days; 1 cm/s found 2/2 with |ΔV| errors of 0.1 % and epoch errors of 0.07-1.7
  s;
* **term-by-term ablation over a month** (`--runs 0 --null-runs 0 --ablation-runs 1 --terms T`; each term left
  out of the filter, the truth keeps it):

* troposphere: false alarms: 10 in 30 days; worst post-fit RMS: 1.35 m; what it means: the largest source of
  false alarms
* light time: false alarms: 2 in 30 days; worst post-fit RMS: 3.9 m; what it means: few alarms only because each
  station's sigma is scaled to its 3.9 m residuals: the detector goes blind (a 1 cm/s maneuver is a few cm)
* plate motion: false alarms: 3 in 3 days (`--days 3`; a month was not run); worst post-fit RMS: 91 mm
* eccentricity: false alarms: 12 in 30 days (3 in 7 days); worst post-fit RMS: 120 mm
* solid tides: false alarms: 3 in 7 days (the cap: 3 per arc); worst post-fit RMS: 78 mm
* Shapiro delay: false alarms: 1 in 30 days (0 in 7 days); worst post-fit RMS: 3.3 mm; what it means: at the
  noise level; the one alarm is at the budget's rate

Every term but the Shapiro delay matters at 3 mm normal points. The month without light time used to make the
fit diverge (overflow); the batch fit now halves a Gauss-Newton step that raises the cost (Dennis & Schnabel
1983 §6.3) and converges. Solid tides were run on one 7-day arc only (time); three alarms per arc is the
`--max-maneuvers` cap. `python benchmarks/bench_slr_lageos.py --days 30` writes its figures to
`docs/results/bench_slr_lageos.txt`.

A 30-day run takes about 2 minutes of one core (simulation 20 s, five 7-day arcs).

Plausibility (`abrupt.pipelines.laser_plausibility`). Before the fit, each station's one-way ranges are compared
with the geometric ranges from its site to the a-priori ephemeris: a median ratio more than 1 % from 1 (ranges
×0.001 or ×6, or the a-priori of another satellite) is an error naming the station and the ratio. The CRD `C0`
wavelength sets the troposphere of each range (Mendes & Pavlis 2004 dispersion: 1064 nm gives 0.955 of the 532
nm delay); a wavelength outside 300-1200 nm is an error naming the line. After the fit, a range bias beyond 1 m
or a force scale outside its physical range (radiation pressure 0.66-2.2 of the a-priori C_R·A/m: C_R between 1
and 2, A/m within 25 %; drag 0.33-3) means the fit absorbs what its model cannot explain: the arc's detections
are reported as kind `unknown` with the parameters named, not as maneuvers. A passive satellite (CRD target
name, or `--no-propulsion`) has every detection judged against the ΔV radiation pressure and albedo can
accumulate over the longest gap between ranges: within it dropped, above it kind `unknown`, never a burn.

Limitations
-----------

* Cross-track burns fix only the new orbit plane (node line and tilt r·Δv/h): epochs half an orbit apart fit
  almost equally and the Δv scales with r(τ). The GLRT reports the alternative epoch and Δv (`alternative_*`
  columns); with one near-equatorial station the primary solution's magnitude error is 18–32 % (median), the
  best of the reported set 3–11 %. A satellite without propulsion (`detect laser` without `--propulsion`
  for the passive geodetic satellites, or `--no-propulsion`) gets no alternative epochs: they choose a burn's
  epoch, not whether there is a detection.
* Below ~0.5 cm/s detections are real (no false alarms in null arcs) but magnitude estimates are poor (median
  error 36–260 % at 0.2 cm/s).
* `detect tracking` runs the batch GLRT on the whole file (one arc); `detect laser` cuts long files into
  overlapping arcs (above). At most `--max-maneuvers` impulses per arc; burns are modelled as impulses (finite
  burns of 100 s are well represented; long low-thrust arcs are not).
* `detect tracking` (TDM, .aer) with a real-data set-up applies two-way light time (first order in v/c: within 5
  mm of the iterative solution for a GTO, `tests/test_tracking_light_time.py`), the Saastamoinen troposphere in
  the standard atmosphere (no meteorology comes with radio files) and refraction; no ionosphere (a few metres at
  S-band for low elevations); station biases absorb the constant parts. Simulation set-ups (no
  central/third-body keys) keep the thesis's instantaneous model.
* Time biases: `BatchFitConfig(estimate_time_bias=...)` estimates a per-station offset of the range time tags
  (∂ρ/∂δt = −ρ̇); a common offset of all stations is an along-track shift of the orbit and cannot be seen, so
  with all stations estimated the one with the most ranges is the time reference (its offset fixed at zero;
  estimating all four of a LAGEOS day made the normal matrix singular, offsets of −13 s ± 470 s). `abrupt detect
  laser --time-biases` switches it on; `detect tracking` does not.
* The EKF follows the thesis literally (Q = 0 below Ψ = 10⁵), so on real data with unmodelled forces its Ψ is
  inflated; use the GLRT and the fit's acceleration for real data.
* The K–Δv calibration is scenario specific (thesis §4.2); the default calibration (thesis apogee transverse log
  fit) is only meaningful for that scenario.
* TDM: KVN only (no XML), AZEL angles only, range in km only.
"""
