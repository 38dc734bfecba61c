r"""Maneuver detectors on TLE and OMM histories (mean-element steps, GEO station keeping).

Command line
------------

* `abrupt detect tle FILE` reads TLE/3LE or OMM (XML, KVN, JSON, CSV; chosen by content). A file of many
  satellites (a catalogue extract, an OMM batch) is split by catalogue number and each satellite is processed in
  the same run; names come from 3LE name lines or `OBJECT_NAME`. The detector is chosen by the orbit:
  `tle.geo_station_keeping` when the median mean motion is 0.9-1.1 rev/day and e < 0.1, `tle.mean_elements`
  otherwise (`--detector` forces one). Options: `--false-alarms TEXT` the budget (`1/year` per satellite-year by
  default; `/week`, `/day`; `--false-alarms-per-year N` is kept as an alias); `--threshold` fixes the threshold;
  `--norad N` keeps one satellite; `--name` sets the spacecraft name (one satellite only); `--all-candidates`
  also writes sub-threshold local peaks (rows with `statistic >= threshold` are the detections) so recall can be
  measured at any false-alarm rate; `--strict` makes a malformed element set an error instead of skipping it;
  `--null-seeds N` (default 2, 0 skips) sets the check of the budget on the satellite's own noise ("A rate per
  satellite" below): era by era by default (`--null-eras`: each null spans the history, one line per calendar
  year), or pooled (`--null-pooled`, `--null-years Y` of noise, default 4). Printed per satellite: the
  maneuvers and campaigns found, the smallest detectable in-track and cross-track ΔV of the whole history and
  **of each calendar year** (its own step noise and threshold), and the **realised false-alarm rate on
  bootstrapped histories of its own quiet noise** beside the budget, per year, with its exact 95 % interval
  (also in the run record's `noise_model`: `detectable_by_year`, `own_null_by_year` or `own_null`). Events have
  the event columns of the README plus `maneuver_type` (LEO: in-track / radial / cross-track; GEO: east-west /
  north-south), `regime`, `dv_t_sigma_mps`, `dv_n_sigma_mps` (1σ), `campaign_id`/`campaign_size` (detections less
  than 3 days apart), `burn_count` (1 for a maneuver; see campaign events below), `interval_start_utc` /
  `interval_end_utc` (the interval the burn or burns behind the step fall in) and `burns_max` (how many burns that
  interval may hold), `z_a`, `z_e`, `z_n`, `delta_a_m`, the bracketing element-set epochs and `time_method`. The run
  record in the catalog holds, per satellite, the
  repairs, the skipped lines and the noise model. **Campaign events**: beside its maneuvers, every chain of
  detections (each within 7 days or 6 element sets of the previous one) is also one event of kind
  `maneuver_campaign`, at its first member's time, with `burn_count` (how many burns its element sets show),
  `campaign_size` (its member maneuvers), the net in-track ΔV across the campaign (`dv_t_mps`), the members'
  summed cross-track ΔV and the interval of all its burns ("Campaigns" below). One-to-one scoring (`abrupt
  score`, `abrupt.score`) leaves these rows out: they summarise maneuvers already listed.
* `abrupt score EVENTS --truth TRUTH` matches detections one-to-one to an operator file (IDS `*man.txt`, Fengyun
  `.fy`, or another events file) within `--tolerance-days` (default 1), truth limited to the span of
  `--elements`; prints precision, recall, F1 and recall at each `--false-alarms-per-year`. With `--elements` and
  a truth file that states ΔV, it also counts the truth burns below the smallest ΔV the element sets resolve in
  their year (in-track and cross-track both below, at the events' budget) and **flags the history** when most
  are: its recall then measures the element sets, not the detector (`FLAG: most listed burns cannot be seen in
  these element sets`). When the events state intervals (`interval_start_utc`/`interval_end_utc`, as `abrupt
  detect tle` writes them), it also prints the score **with the stated intervals**: a truth inside an event's
  interval pairs with it however far from the event's time (still one-to-one, nearest first; `score_events(...,
  intervals=True)`; "Timing intervals" below).
* `abrupt inject tle FILE [--maneuvers KNOWN] [--seeds 4] [--years 6] [--out burns.csv] [--report FIG]` answers
  "what would the detector see on this satellite?" without its truth: blocks of the history's own quiet noise
  (away from the operator's maneuvers, or, without `--maneuvers`, from the detector's own detections) are laid
  on a fresh orbit, burns at 1/4 to 8 times the ΔV the detector states it finds half the time are injected every
  30-50 days (in-track and cross-track; GEO east-west and north-south; `abrupt.simulate.tle_injection`), and the
  detector runs at `--false-alarms`. It prints found/injected per ΔV, the stated size, the smallest ΔV found at
  least 90 % of the time and the false alarms per satellite-year of those histories ("Injected burns" below);
  `--report` draws recall against ΔV per kind with the stated size (log axis, Wilson 68 % intervals). Measured
  (`abrupt inject tle Jason-3.tle --maneuvers ja3man.txt`, 3 s):

```console NORAD-41240 (LEO): 4 histories of its own noise (quiet = away from 43 maneuvers of ja3man.txt), 11.0
satellite-years, budget 1/year in-track: 0.015 cm/s 0/10, 0.03 cm/s 0/11, 0.059 cm/s 8/12, 0.12 cm/s 9/9, 0.24
cm/s 12/12, 0.47 cm/s 14/14; stated 50 % size 0.055 cm/s (real history 0.059), found >= 90 % from 0.12 cm/s
cross-track: 13 cm/s 0/12, 27 cm/s 0/5, 53 cm/s 5/11, 110 cm/s 14/15, 210 cm/s 14/14, 420 cm/s 8/8; stated 50 %
size 61 cm/s (real history 53), found >= 90 % from 110 cm/s false alarms: 1 in 11.0 satellite-years (0.09 per
year; 1 within 3 days of a burn) ```

CryoSat-2: in-track 0.84 cm/s (its stated size) 3/4, from 1.7 cm/s all; Fengyun-2D (no `--maneuvers`): east-west
2.6 cm/s 0/6, from 5.3 cm/s (1.5× its stated 3.5) all. A history of fewer than 30 element sets, or one without
12 consecutive quiet sets, is a one-line error.
* `abrupt report tle FILE` draws the series the detector tests (for GEO the equinoctial eccentricity vector and
  the inclination vector) and the step statistic with its threshold, with detections (green: matched, red: not)
  and operator maneuvers (triangles).

Python:

::

    from abrupt.detect.base import get_detector
    from abrupt.pipelines.tle import detect_tle_file
    from abrupt.readers.omm import read_element_histories
    from abrupt.thresholds import FalseAlarmBudget

    run = detect_tle_file("catalogue.3le", FalseAlarmBudget.parse("1/year"))   # all satellites
    for sat in run.satellites:
        print(sat.history.name, sat.detector, len(sat.events), sat.noise_model["min_detectable_dv_t_mps"])

    history = read_element_histories("Jason-3.tle")[0]
    result = get_detector("tle.mean_elements")().detect(history, FalseAlarmBudget(1, "year"))
    result.events; result.diagnostics[0].statistic; result.diagnostics[0].threshold

Reading long histories
----------------------

TLE lines are checked one by one: 69 characters (after trailing blanks), line number, modulo-10 checksum,
catalogue numbers equal on both lines, readable numeric fields. Tolerated as written: explicit `+` signs
(`+.00000062`, `+00000-0`), non-breaking spaces (read as spaces), trailing blanks and tabs, `\r\n`, 3LE name
lines with or without `0 `, **Alpha-5 catalogue numbers** (`A0001` = 100001; letters without I and O). A
**malformed element set** (bad field, bad checksum, truncated line, a line 1 without its line 2, a B* written
`+0153801` with no exponent sign) is **skipped, counted** (`malformed element sets skipped`) **and reported with
its file, line and column** (`Jason-3.tle:8123:69: checksum error ...`, printed by the CLI and stored in the run
record); the rest of the file is analysed. `--strict` / `strict=True` raises the first one instead. Other
counted repairs: exact duplicate sets dropped; same-epoch re-issues resolved to the highest element-set number;
epochs sorted. OMM: required keywords, numbers, `TIME_SYSTEM = UTC`, `MEAN_ELEMENT_THEORY = SGP4`; a malformed
record is skipped and counted like a TLE set (its line, and for JSON/XML its record number, are named); a
malformed document (broken XML/JSON) is an error.

**Operator files.** IDS (`*man.txt`): one line per maneuver window with its burns; burn epochs are year, day of
year and time in **TAI**, converted to UTC with astropy/ERFA's leap-second table; a window's burns form one
truth maneuver at the first burn's epoch with summed components (component order by parameter type: 007 Jason
Q,S,W = radial, along-track, cross-track; 006 Sentinel/CryoSat radial, along-track, cross-track; 005 SPOT
T,R,L). The benchmark dataset's derived lists are one day late (PROVENANCE.md); abrupt reads the operator files.
**Fengyun `.fy`**: `TYPE COSPAR "start CST" "end CST"`, China Standard Time (UTC+8, no daylight saving) → UTC by
−8 h; the truth time is the window start; no ΔV. One end time in the FY-2E file is written
`2015/12/23T23:59:59`: read, counted as `dates with '/' separators read`.

Property tests (hypothesis) feed arbitrary bytes and mutated valid files (characters replaced, lines deleted,
duplicated, cut, swapped, bytes inserted, `+`/NBSP injected) to the TLE, OMM (KVN, JSON), IDS and `.fy` readers:
each input parses or raises `InputError` naming the file and a line.

Method
------

Times are elapsed SI seconds (TAI−UTC from ERFA's leap-second table): a plain UTC difference is one second short
across 2016-12-31, a 7 km along-track jump that every LEO history showed as its largest phase innovation.

Series from SGP4-consistent mean elements (each set initialises an `sgp4` record, WGS-72; Hoots & Roehrich 1980,
Vallado et al. 2006): the Brouwer mean semi-major axis `a`, and

* LEO: the eccentricity vector `e(cos ω, sin ω)`, the orbit normal (`i`, and `sin i` × RAAN minus the SGP4
  secular J2 drift, accumulated set to set) and the **along-track phase** `U` (m): the set-to-set innovation of
  the mean argument of latitude u = ω + M, `δu_k = wrap(u_{k+1} − u_k − ½(u̇_k + u̇_{k+1}) Δt_k)` with u̇ the
  SGP4 secular rate as a running median over five sets (keeps a burn's step in the rate, removes a lone bad
  set's, whose rate error would integrate into a permanent phase step), summed and multiplied by `a`. `U` is
  flat under the null; a pair of opposed in-track burns Δt_s apart leaves `a` and e unchanged but moves `U` by
  `3 Δv Δt_s` (the phasing such pairs are made for);
* GEO: the equinoctial vectors that stay defined at small inclination (Soop 1994 §3): `e(cos ϖ, sin ϖ)` with ϖ =
  Ω + ω, and the inclination vector `i(sin Ω, −cos Ω)`. East-west burns move `a` (the longitude drift rate) and
  the e-vector, north-south burns the i-vector.

1. **Robust two-sided step test at every gap** between consecutive sets: 6 sets each side (within 20 days); a
   common local trend (Theil-Sen slope, Sen 1968, pooled from pairs within each side over 12 sets, so a step
   does not bias it) absorbs the smooth drag decay of `a`, J3/frozen-orbit e-vector motion and luni-solar
   inclination drift; the step is the difference of the two sides' medians of the detrended values.
2. **Per-satellite noise model, learned from the history without its truth.** (a) White fit noise per element:
   rolling 1.4826·MAD of set-to-set differences detrended by the rolling median rate × gap (Hampel 1974); (b) a
   random-walk rate `q` per element from the difference of robust variances of long and short gaps (`Var = 2σ² +
   q·Δt`) — unmodelled drag and luni-solar wander — so **the step's uncertainty grows with the gap** (`σ² =
   σ²(π/2)(1/n₁+1/n₂) + q·Δt_gap`); (c) TLE differences are heavy-tailed (kurtosis 38-2085 on the shared
   histories), and adjacent sets' errors are correlated, so each group's z-scores are rescaled by a robust scale
   learned by iterated rejection: the median over gaps further than 8 gaps from any peak above 6 robust σ (three
   passes; a quarter of CryoSat-2's gaps are flanks of its 164 burns, which a high quantile would count as
   noise). Groups: `z_a` (in-track), `z_e` (|Δ e-vector|, χ₂), `z_n` (|Δ normal|, χ₂) and, LEO only, `z_u`: the
   step of `U` that the step in `a` cannot explain. An in-track burn at t_b moves `U` by `Δn·a·(Δt/2 − (t_b −
   t_g))`, at most `(3/4) n |Δa| (Δt + 1 day)` for any burn from one TLE lag before the gap to its end; only the
   excess counts (`delta_u_m`), so `z_u` is a second look at phasing, not a duplicate of `z_a`.
3. **Combined statistic**: the maximum over groups of normal-equivalent scores (a χ₂ magnitude is mapped to the
   two-sided normal deviate of equal tail probability), the e and n groups multiplied by a gain γ = 0.2 (tuned
   leave-one-satellite-out, below; `group_gain=None` sets γ_k = T_a/T_k from each group's own null tail,
   `group_thresholds`: LOSO never picks it, `bench_tle_timing_own_null.txt`); `z_u` with gain 1 like `z_a`.
   An event where only `z_u` is significant is typed `along-track phasing` (ΔV unobservable: the phase step
   is `3 Δv Δt_s` with unknown spacing) and timed at its gap. An in-track burn of a few cm/s is a 10-100σ step
   in `a` while e-vector and normal noise is heavier-tailed; a maximum is not diluted by quiet groups.
4. **Threshold from the false-alarm budget** (`FalseAlarmBudget(1, "year")`; per year-long block of the history,
   "A rate per satellite" below): per-gap probability = budget per year / gaps per year (`per_test`); a
   generalised Pareto tail (`abrupt.thresholds.fit_threshold`, method `gpd`) of the statistic on its event-free
   gaps, floored at the Bonferroni level of three Gaussian groups. When fewer than 50 gaps are left away from
   maneuvers (sparse sets and many burns: the burns' test windows cover the history) no tail is fitted and the
   threshold is the larger of that floor and the largest event-free value (a quantile of the whole statistic sat
   on the maneuvers' own plateaus: a synthetic history with sets every 3 days and seven 2-5 cm/s burns had 0
   found, now 6). Realised false alarms per satellite-year on the five shared histories (held out): 0.15-1.31,
   pooled 0.23 (LEO) and 1.01 (GEO); of the 12 GEO false alarms, 9 are orbit changes the operator files leave
   out or date more than a day from the sets (below, "GEO false alarms one by one"). On maneuver-free histories
   (simulated and bootstrapped, "Null calibration" below) the realised rate is 0.58 (LEO, pooled) and 0.52 (GEO)
   per satellite-year at a budget of 1, every cell at most 1.2 (bootstraps of the five satellites' own noise:
   0-0.33); strong, varying drag with dense sets needs the drag-consistent trend (below).
5. **Segmentation and campaigns.** The strongest gap above threshold is accepted, moved to the best split among
   ±2 gaps (least-absolute-deviation change point, Bai 1995), and the windows of its neighbours are cut there
   and re-tested, so one maneuver's flanks are not false alarms while a second burn days later still is tested
   on its own side; repeat. Detections less than 3 days apart are labelled one **campaign** (`campaign_id`,
   `campaign_size`). Between two accepted maneuvers a side of `campaign_min_side_sets` sets is enough (LEO 2:
   orbit-raising and frozen-orbit campaigns put burns two daily sets apart; GEO 3: station-keeping burns are
   weeks apart and GEO sets are sparser; on the shared histories every LEO satellite scores the same or better
   with 2, every GEO satellite the same or better with 3). A side of **one set** (`campaign_min_side_sets=1`)
   also tests the gaps next to an accepted step, on the single set between them: burns in consecutive gaps
   (synthetic histories: both found, `test_burns_in_consecutive_gaps_are_two_events_with_a_one_set_side`). It is
   in the benchmark's LEO leave-one-satellite-out grid and never chosen (below). **Blends or two burns? The sets
   between two steps.** Steps one or two gaps apart are either two burns or one burn whose first sets after it
   were fitted across it (a compromise mean motion: `a` steps over several gaps: CryoSat-2's 1.6 cm/s burn of 28
   July 2011 reaches `a` over four sets). The along-track position tells which: one impulse bends the
   along-track angle once (`c₀ + c₁τ + c₂τ² + β·max(0, t − t_b)`), a second burn after the middle sets bends it
   again. The one-burn model is fitted (least squares for each hinge time on a coarse then a fine grid, the
   hinge chosen by the smallest L1 residual) to the window's sets except the middle ones (`middle_set_phase_z`),
   and the middle sets' largest deviation from it, over the satellite's own per-set phase noise, is compared
   with the detection threshold: below it the weaker step is merged into the stronger and the event is timed by
   that one-burn trajectory; above it both stay (two burns a day apart move the middle set by ~`Δn·Δt·a`,
   kilometres for 5 cm/s). Without enough sets inside the segment (three before, two after) the earlier rules
   decide: steps whose times run against the gaps' order are merged, and a step next to a stronger one (side of
   one set) is kept only if its along-track time falls between the satellite's TLE lag before its gap and the
   set after it. On synthetic histories whose first set after each burn carries 30-50 % of its Δa, every burn is
   one event (`test_a_set_fitted_across_a_burn_leaves_one_event`; without the test a second, false event appears
   beside some of them and it fails); on the shared LEO histories false alarms at the budget fell from 8 to 6
   (table below). **Campaign events.** Burns inside one gap between element sets cannot be told apart from the
   elements (one step in `a` whose ΔV is their sum), and a set fitted across a burn spreads one burn over two
   gaps. So every event states the interval its burn or burns fall in, `interval_start_utc`-`interval_end_utc`:
   from the history's own TLE lag before the set that precedes the step (the predictive 0.82 bound of how far
   the isolated detections' hinges fall before that set, or the event's own when longer; `abrupt.detect.tle.intervals`)
   to the set after it, widened over candidates merged into it; and how many burns it may
   hold, `burns_max = 1 + ⌊interval / cadence⌋`, the cadence being the median spacing of the satellite's own
   detections inside campaigns (no campaign: 1).
6. **Burn time by along-track continuity.** The along-track angle (LEO: ω + M; GEO: the mean longitude Ω + ω +
   M) of ±8 sets is compared with the prediction of the set before the step; `c₀ + c₁τ + c₂τ² + β·max(0, t −
   t_m)` is fitted in L1 for `t_m` on a grid from three sets before the step to the set after it (vectorised).
   The first sets after a burn are often still fitted to pre-burn tracking (FY-2E: a set 5 h after a burn still
   shows the old `a`; CryoSat-2: the step in `a` spreads over 3 sets), so the step appears late; the drift-rate
   kink does not. In LEO the fit and the search stay between the neighbouring accepted maneuvers when at least
   three sets before and two after remain (else the whole window is used): a campaign burn's hinge was found at
   the previous burn, days early (CryoSat-2 July 2020, June 2022). With fewer sets inside the segment
   (campaigns) the burn is timed from **the two sets that bracket its step** alone: the phase innovation across
   the gap is `δ = −Δu̇ (t_b − t_g − Δt/2)` for one impulse, so `t_b = t_g + Δt/2 − δ/Δu̇` (after removing the
   median innovation rate of the quiet neighbouring gaps; accepted from three sets before the step to the set
   after it). Candidates closer than the median gap between sets are merged as before, and so are steps in
   neighbouring gaps (≤ 2 apart) whose burn times run against the gaps' order: a set fitted across one burn
   carries a partial mean motion, which times the later step before the earlier one (CryoSat-2 June 2010).
   Median |Δt| of matched maneuvers: 1-3 h LEO, 4-5 h GEO (operator windows are 1 h long).
7. **ΔV with uncertainty** (Gauss variational equations, near-circular, Vallado 2013 §9.3): in-track `Δv_t = v
   Δa/(2a)` with 1σ `v σ_Δa/(2a)`, σ_Δa the step noise of item 2 (robust scale included); cross-track `|Δv_n| =
   v |Δ normal|` with 1σ `v σ_n`; radial from the e-vector change not explained in-track. A component whose z is
   below 5 is reported as 0.
8. **Smallest detectable ΔV per satellite** (in the CLI summary and `noise_model`): the step that reaches the
   threshold at the median gap, `Δa = T σ_a/(γ_a w_a)` → `v Δa/(2a)`, and the normal rotation whose score
   reaches `T/γ_n`; a 50 %-detection size. Tested: synthetic burns at 3× it are all found, at 0.3× none
   (`tests/test_tle_detectors.py`).

Drag-consistent trend for `a` in low LEO
----------------------------------------

**Method** (`TleDetectorConfig.drag_trend = "ndot"`, the default; `"none"` is the previous detector). Every
element set states the decay the tracking saw: the TLE's first-derivative field is ṅ/2, the mean-motion rate
fitted with the set (Hoots & Roehrich 1980; Vallado 2013 §2.2, §9.6). Kepler's third law turns it into the set's
rate of the mean semi-major axis, ȧ = −(2/3)·a·ṅ/n (`stated_decay_m_s`). The detector integrates the stated
rates across the gaps (trapezoid, over a running median of 5 sets so that a set whose ndot absorbed a burn or a
bad fit does not bend it; `drag_trend_m`) and runs its step test on `a` minus that integral. What the local
Theil-Sen slope has left to absorb is the stated rate's bias, which is constant over a window; the drag's
changes with the 27-day solar rotation, geomagnetic storms and the solar cycle are carried by the sets
themselves instead of a straight line across 24 sets. A burn is not removed: it is a step in `a`, and the one or
two sets fitted across it, whose ndot carries it as a rate, are outvoted by the running median.

**Where it is used.** Only where `a` decays at least `drag_min_decay_m_day` = 2 m/day (median of the set-to-set
rates of the history's own `a`; ~below 600 km at mean solar activity) and the median stated decay agrees with it
within a factor of two. At 2 m/day the change of the decay rate over a test window (15 % in a few days) times
the window's length starts to rival the 0.2 m noise of `a`. Above that the ndot field is fit noise and bias:
against the rate of `a` itself, the shared histories' sets state +0.39 m/day (Jason-3, 1336 km, observed −0.08),
+0.01 (Sentinel-3A, 800 km, observed −0.31) and −0.32 (CryoSat-2, 716 km, observed −0.49), with a robust scatter
of 0.1-0.4 m/day, so none of them uses the trend and their figures are unchanged. Without the gate the trend
cost them (held out, `bench_tle_vs_maneuver_detect.py`): LEO pooled TP/FP/FN 222/65/41, F1 0.81, 2.53 false
alarms per year with a 5-set median; 217/46/46, F1 0.83, 1.79 with a 15-set median; against 194/6/69, F1 0.84,
0.23 with none.

**The null generator states its drag** (`abrupt.simulate.tle_null`): each LEO set's ndot is the simulated rate
of `a` × (1 ± up to 20 %, per history) ± up to 0.3 m/day bias (per history) + Student-t noise of robust σ 0.1
m/day + 10 % of the rate per set, and the bad sets' ndot a gross error too; the bootstrap carries the real sets'
ndot residuals (about a 31-set running median, in the same blocks) and the real history's bias of stated against
observed decay. (An ndot of 0 would read as "no stated decay" to the gate, which turns the trend off.)

Null study, budget 1 per satellite-year, false alarms per satellite-year (10 satellite-years per cell;
`OMP_NUM_THREADS=1 python benchmarks/bench_tle_null_calibration.py`, 68 s):

* 450 km, 0.3 sets/day: before (`drag_trend="none"`): 0.3 / 0.0; with the drag trend: 0.8 / 0.1
* 450 km, 1 set/day: before (`drag_trend="none"`): 0.8 / 0.0; with the drag trend: 1.1 / 0.5
* **450 km, 3 sets/day**: before (`drag_trend="none"`): **7.2** / 1.6; with the drag trend: **1.0** / 1.0
* 800 and 1300 km, GEO, all bootstraps: before (`drag_trend="none"`): 0-1.1; with the drag trend: unchanged
  (trend off)
* parametric LEO pooled (18 cells): before (`drag_trend="none"`): 0.88 (0.75-1.03); with the drag trend:
  **0.58** (0.47-0.70)
* cells: largest ratio to the budget: before (`drag_trend="none"`): 7.2; with the drag trend: **1.1**
* budget 12/yr: 450 km, 3/day, ×1; LEO pooled: before (`drag_trend="none"`): 24.7; 3.37; with the drag trend:
  3.7; 2.18

Real histories, held out (`OMP_NUM_THREADS=1 python benchmarks/bench_tle_vs_maneuver_detect.py`, 30 s):

* LEO pooled TP/FP/FN, F1, false alarms per year: before: 194/6/69, 0.84, 0.23; with the drag trend: 194/6/69,
  0.84, 0.23 (trend off on all three)
* LEO burns ≥ 5 cm/s, recall at 1 FA/yr: before: 0.70; with the drag trend: 0.70
* GEO pooled F1: before: 0.88; with the drag trend: 0.88 (LEO only)

At 450 and 600 km (2 × 5 years per cell, budget 1/yr; a sweep outside the benchmark) the running median's length
hardly matters beyond one set: pooled over the 12 cells 1.07 false alarms per year without the trend, 2.57 with
the raw per-set rates (1 set: the stated noise integrates into a random walk), 0.63 / 0.59 / 0.54 with 3 / 5 / 9
sets; 5 is kept. The price is at sparse cadence: at 0.3-1 set per day the 450 km cells go from 0-0.8 to 0.1-1.1
per year (the 5-set median spans 5-15 days there and smooths part of the 27-day term), still within the budget.

Test (`tests/test_tle_drag_trend.py`, default suite, ~6 s): the trend integrates a constant stated rate exactly
and ignores one set's burn-absorbing ndot; the generator's stated decay matches the decay of its own `a`
(Kepler's third law, within the stated scale error and bias); ten maneuver-free satellite-years at 450 km, 3
sets/day give at most twice the budget with the trend (measured 0.3 per year) and more than twice without it
(4.1); a 5 cm/s in-track burn in three of those histories (its first set's ndot carrying the step) is found
within a day with its ΔV within 20 % (measured 4.92-5.00 cm/s).

**Not measured here:** real low-LEO histories (ISS, Starlink, CubeSats): their ndot is the tracking's, and ISS
reboosts and Starlink's continuous thrust put thrust into ndot over several sets, which the 5-set median only
partly removes.

A rate per satellite: block thresholds and its own null
-------------------------------------------------------

The budget is a promise per satellite-year, so the threshold is set on each satellite's own null and the
realised rate is checked on its own noise.

**Threshold per block of the history** (`threshold_follow`, default `"raise"`;
`abrupt.detect.tle.noise.block_thresholds`). Cadence, drag and noise change over a mission (commissioning, solar
maximum, end of life, a catalogue that switches to denser sets). The history is cut into blocks of one year
(`threshold_block_days`); each block's threshold is the generalised Pareto tail fit of the event-free statistic
within half a year of the block (`threshold_reach_days`; maneuver footprints found on the whole history), for
the per-gap probability the budget gives **at that block's own cadence** (budget per year / the block's gaps per
year), floored at the Gaussian Bonferroni level. One cut on the statistic holds each block's threshold (the
statistic is scaled by whole-history threshold / block threshold). `"raise"` never lowers a block below the
whole-history threshold; `"follow"` uses each block's own (measured below: more false alarms, so not the
default); `"none"` is the single threshold of before. Per-block thresholds are in `detectable_by_year`.

**Not on its own candidates.** A block's tail is fitted away from the robust outliers of the statistic (median +
8 robust σ) *and* from every peak at or above the whole-history threshold: the candidates the block threshold is
about to judge. Fitted with them, a block whose small maneuvers sit just above the threshold raised its own
threshold over them: Jason-3's first year had event-free peaks of S 5.5 and 4.8 (14 and 26 July 2016; the second
is the operator's 24 Jul 2016 maneuver) against the whole-history 4.49, and its block threshold came out 5.43
(5.41 the next year, whose half-year reach holds July 2016), losing that maneuver; CryoSat-2 lost a 0.8 cm/s one
(13 Dec 2018, S 10.40 against a block's 10.4). Without its candidates every block of the shared LEO histories
fits at or below the whole-history threshold (Jason-3 3.3-3.9, CryoSat-2 5.8-9.8 against 4.49 and 10.15), so
`"raise"` keeps the whole-history threshold there. Tested:
`test_block_threshold_is_not_fitted_on_the_candidates_it_judges` (a half-normal statistic with twelve S 5-6
steps in one year: fitted with them that year's threshold is above 1.2× the half-normal quantile; without them
it is the quantile within 12 %). **What it costs**: on all 21 histories of the benchmark below, raise and one
threshold now give the same figures: the four parametric false alarms the block threshold removed come back
(pooled 0.48 → 0.55 per year; the 1000 km, 5 sets a day, ×8 noise history at 2.0 per year, at the edge of
"within 2×"), and Sentinel-3A's 11 Mar 2016 false alarm (its first 90 days) too. The block threshold now binds
only where a block's null tail below the whole-history threshold is heavier; none of the measured histories has
one.

**Its own null** (`abrupt.simulate.tle_own_null.own_null_rate`, printed by `abrupt detect tle`): blocks of 60
consecutive quiet sets (3 days before to 12 days after every detection away, no truth used) are laid on a fresh
maneuver-free orbit with their real gaps (`bootstrap_null_history`); the detector runs at the same budget and
settings, and every detection at a gap whose test holds no junction between blocks is a false alarm. The rate,
its exact Poisson interval (Garwood) and its ratio to the budget are printed beside the budget. **Era by era**
(the default of `detect tle`; `own_null_by_year`): each null spans the history and every block is drawn from the
quiet sets within half a year of its own time, so each calendar year has its own cadence and noise; the
detector runs once per null (its block thresholds fitted as on the real history) and the false alarms and
exposure are counted per year. Four nulls per shared history (`python benchmarks/bench_tle_own_null_by_year.py`,
`docs/results/bench_tle_own_null_by_year.txt`): Jason-1 4 in 15.7 satellite-years (highest year 2005: 2 in 1.44,
1.39 a year, 95 % 0.17-5.0), Jason-3 1 in 9.5 (0.68), Sentinel-3A 0 in 5.8, CryoSat-2 0 in 13.2, Fengyun-2D 0 in
3.2, Fengyun-2E 0 in 3.6 (2011-2014 barely exposed: few quiet sets); every history well below the stated 1 a year
(the threshold is conservative, as below), one Jason-1 year above it within its interval.

Measured (`python benchmarks/bench_tle_own_null.py --seeds 2`, 241 s at load 17; budget 1/year;
`docs/results/bench_tle_own_null_seeds2.txt`). *Realised*: unmatched detections per satellite-year (shared
satellites, default settings: against the operator file and the unlisted orbit changes; simulated histories are
maneuver-free, so every detection); *own null*: as `detect tle` prints it. The block threshold fitted with its
candidates in brackets where it differs.

* Jason-3: years: 6.7; realised, block threshold: 0.30; realised, one threshold: 0.30; own null (95 %): 0.66
  (0.21-1.53) [0.39]
* Sentinel-3A: years: 6.6; realised, block threshold: 0.15 [0.00]; realised, one threshold: 0.15; own null (95
  %): 0.56 (0.15-1.43) [0.43]
* CryoSat-2: years: 12.4; realised, block threshold: 0.24; realised, one threshold: 0.24; own null (95 %): 0.29
  (0.04-1.05) [0.15]
* Fengyun-2D: years: 4.2; realised, block threshold: 0.24; realised, one threshold: 0.24; own null (95 %): 0.00
  (0-0.62)
* Fengyun-2E: years: 7.6; realised, block threshold: 0.66; realised, one threshold: 0.66; own null (95 %): 0.00
  (0-0.66)
* 12 parametric histories never tuned on (LEO 550/650/1000 km, 0.5-5 sets/day, noise ×0.5-×8; GEO 0.5 and 2
  sets/day), pooled: years: 60; realised, block threshold: 0.55 (0.38-0.77) [0.48]; realised, one threshold:
  0.55; own null (95 %): 0.27 (0.15-0.47)
* of which LEO 1000 km, 5 sets/day, noise ×8 (two histories): years: 10; realised, block threshold: 2.00, 1.80
  [1.80, 1.80]; realised, one threshold: 2.00, 1.80; own null (95 %): 0.26, 1.03
* 4 histories whose noise (×6 in the last year) or cadence (0.5 → 3 sets/day) changes inside: years: 19.7;
  realised, block threshold: 0.36; realised, one threshold: 0.36; own null (95 %): 0.32

Against the acceptance (each shared satellite left out: unmatched within 2× of the budget, own null
within 1.5×): the held-out rates of the LOSO benchmark (`bench_tle_vs_maneuver_detect.py`: 0.30, 0.15, 0.24,
0.47, 1.31 per satellite-year; FY-2E with its LOSO gain 0.5) and the own-null rates above are all **at or
below** the budget: every satellite meets "within 2×" and "within 1.5×" as upper bounds. They are not two-sided:
the realised rates are up to 4× *below* the budget on LEO (pooled 0.19 LEO, 1.01 GEO held out), so the threshold
is conservative there, and the own null's interval holds the budget for 2 of the 5 only. On the 12 unseen
parametric histories every realised rate is within 2× (largest 1.8 per year: 1000 km at 5 sets a day with 8×
noise; one threshold gave 2.0 there) and the pooled rate is 0.48. The own null **under-predicts** the dense,
noisy cell (0.26 and 1.03 against 1.8 realised): blocks of 60 sets are 12 days at 5 sets a day, shorter than the
noise's correlation, and the junctions between blocks are left out of the count. The block threshold did not
change the cells whose noise changes inside the history (the step test's rolling noise scale already follows a
noise level; the block threshold follows a change of the tail or the cadence); it removed one false alarm on
Sentinel-3A (its first months, 11 Mar 2016) and four on the parametric histories.

Shared-data figures (`bench_tle_vs_maneuver_detect.py`, LOSO): one threshold (`"none"`) LEO pooled 194/6/69 F1
**0.838**; block threshold fitted with its candidates 192/5/71 F1 0.835 (Jason-3 lost its 24 Jul 2016 maneuver,
CryoSat-2 its 13 Dec 2018 one, Sentinel-3A its 11 Mar 2016 false alarm); the default (block threshold without
its candidates) 194/6/69 F1 **0.838** again; GEO 64/12/6 F1 0.88 throughout. `"follow"` (each block's own
threshold, lower in quiet years): LEO 199/14/64 F1 0.836, 0.54 false alarms per year; GEO 0.86.

**Leave one regime out** (same benchmark, printed last): the gain chosen on the two GEO satellites plus one LEO
satellite, the held-out LEO satellite scored with it. Every choice is γ = 0.2 (as LOSO); held-out unmatched
rates 0.30 (Jason-3), 0.00 (Sentinel-3A), 0.24 (CryoSat-2) per satellite-year: 0.0-0.3× the budget, whichever
LEO satellite joins the training set.

Campaigns: `maneuver_campaign` events
-------------------------------------

Orbit acquisition, formation flying and frozen-orbit control put several burns within a few element sets.
One-to-one matching then leaves burns over (a step holds several) and counts the detections of a campaign that
it cannot pair as false alarms. Each chain of detections (each less than `campaign_chain_days` = 7 days or
`window_sets` = 6 sets after the previous one; detections below a fiftieth of the chain's largest ΔV do not
extend it but join it when they lie between its first and last step) is also reported as one event of kind
`maneuver_campaign` (`abrupt.detect.tle.campaigns`):

* **Total ΔV**: the step of the mean semi-major axis from the 6 sets before the campaign's first step to the 6
  after its last (one gap wider each side: a step inside a campaign is localised within a gap of its burn; never
  over a neighbouring detection), each side's median about a common Theil-Sen slope (the smaller in magnitude of
  the two sides': a burn inside a side steepens it), `Δv_t = v Δa/(2a)`: the net in-track ΔV, the total when the
  burns share a sign. Members' sides of two sets hold the neighbours' levels, so their ΔV sum is off by tens of
  per cent; this one is not.
* **Burn count**: the gaps inside the campaign whose set-to-set step in `a` (drift removed) passes the detection
  threshold times `√2 σ_a` and a tenth of the campaign's largest step carry burns, one each or two. A single
  in-track burn at argument of latitude `u` moves the eccentricity vector by `(2Δv_t/v)(cos u, sin u)`, so `|Δe|
  = |Δa|/a` (Gauss's equations); burns at different `u` in one gap give `|Δe| < |Δa|/a`. A gap counts two when
  the shortfall `|Δa|/a − |Δe|` (the e-vector's own drift across the gap removed: the sides' Theil-Sen slopes)
  exceeds 6 times its noise (`√2` × the satellite's rolling set-to-set scale of `e`, with that of `a`/a): a test
  of the satellite's own noise, not of a fixed ratio. Never fewer than the member maneuvers. Burns in one gap at
  nearly the same `u` are one step of their summed ΔV and are counted as one.

The members stay maneuvers (one-to-one scoring is unchanged: `abrupt.score` leaves `maneuver_campaign` rows
out); the campaign row states what the element sets say about the whole. With `campaign_step_fraction` (off
by default; `abrupt.detect.tle.campaign_steps`) every carrying gap over the history's own set-to-set null is a
maneuver of its own, a member a gap off its step moved to it.

**Simulated acquisition phases in the real quiet noise of each shared LEO satellite** (`python
benchmarks/bench_tle_campaigns.py`, 29 s; `abrupt.simulate.tle_campaign`): six in-track burns of 0.5-3 m/s (one
sign) at uniform times within ten days, random arguments of latitude, in a 1.5-year history made of blocks of
the satellite's quiet noise; default settings, budget 1/year. Success = one campaign overlapping the burns, burn
count within ±1, in-track ΔV within 20 % of the sum, and no event within ±10 days other than the campaign and
the maneuvers inside its interval, counted at gaps whose test holds no junction between the bootstrap's noise
blocks (the rule of the own-null and injection checks: a junction joins two unrelated stretches of real noise, a
step no real history has; `others_at_junctions` counts the rest). The counting rule was developed on seeds 0-19;
the figures are for seeds 20-29 (held out; `docs/results/bench_tle_campaigns.txt`):

* Jason-3: trials met: **10 / 10**; burn count error (max): 1; campaign ΔV / true sum: 1.001-1.002; other events
  within ±10 days: 0; met, counting events at junctions too: 10 / 10
* Sentinel-3A: trials met: **9 / 10**; burn count error (max): 2; campaign ΔV / true sum: 1.001-1.002; other
  events within ±10 days: 0; met, counting events at junctions too: 7 / 10
* CryoSat-2: trials met: **9 / 10**; burn count error (max): 3; campaign ΔV / true sum: 1.001-1.002; other
  events within ±10 days: 0; met, counting events at junctions too: 9 / 10

Target ≥ 9 of 10 per satellite: **met** on every satellite (28 of 30; development seeds 0-19: 20, 20 and 19 of
20, `bench_tle_campaigns_dev_seeds.txt`). With the older rule (below): 9, 7 and 8 of 10. The total ΔV is right
in every trial (within 0.2 %). What was wrong, trial by trial (the 11 failures of the older rule on seeds 0-29):
6 were burn counts, 4 other events, 1 both. The counts: two burns in one gap whose e-vector shortfall was clear
(`r = a|Δe|/|Δa|` of 0.74-0.92) were counted as one by the fixed `r < 0.7` rule, and the size rule ("a gap whose
step is 1.75 times another gap's single burn holds round(k) burns") counted a 3.1 m/s gap beside 0.7 m/s single
burns as four (burns of 0.5-3 m/s are not of similar size). On the development seeds, single burns reach a
shortfall of at most 5.1 σ of the satellite's e-vector noise (one, in a gap that is also a junction, 23 σ); of
the 34 gaps holding two burns with `r ≥ 0.7`, 29 are at 6.5-650 σ and 5 below 6 (their `u` nearly agree): hence
the 6 σ rule, and no size rule. The other events of the failing trials (development seeds Jason-3 9, CryoSat-2
14 and 18; held out Sentinel-3A 22 and 29) were steps of the e-vector or the normal (in-track ΔV at most 3 mm/s)
within the reach of a junction between noise blocks. Counted anyway (last column), Sentinel-3A's held-out figure
is 7 of 10.

The older rule, for comparison: `r < 0.7` counted two, and a gap whose step was `k ≥ 1.75` times the largest
single-burn step of the campaign counted `round(k)`; with it the held-out trials met were 9, 7 and 8 of 10.
Dropping small detections near a campaign (below a fiftieth of its largest burn, within the test windows' reach)
was tried then: it lost real trim burns on the shared histories (LOSO LEO F1 0.835 → 0.82, GEO 0.88 → 0.87), so
it is not used.

On the shared histories (`bench_tle_vs_maneuver_detect.py`, column `recall_big_with_campaign_events_at_1fa`):
crediting each campaign event with up to its `burn_count` operator maneuvers inside its interval (at the same 1
FA/yr cut, false alarms unchanged) finds **0.90** of the 61 LEO burns ≥ 5 cm/s (Jason-3 1.00, Sentinel-3A 0.88,
CryoSat-2 0.88), against 0.84 with the members' own intervals and `burns_max` alone and 0.70 one maneuver per
event.

Timing intervals and the score
------------------------------

Every maneuver event states the time of its burn (`time_utc`: the along-track hinge fit, or the two-set estimate
inside campaigns, method item 6) and the **interval** the burn lies in (`interval_start_utc`-`interval_end_utc`,
with `time_sigma_s` its uniform-equivalent 1σ): from the set before the step, moved earlier by the history's
own TLE lag (the predictive 0.82 bound of how far its isolated detections' hinges fall before that set, or the event's
own lag when longer; `abrupt.detect.tle.intervals`, whose docstring gives the model, the leave-one-out choice
of the level and the coverage measured on all six shared histories), to the set after the step, widened over
candidates merged into the event. Campaign events state the union of their members'.

`abrupt score` (and `score_events(..., intervals=True)`) uses it: a truth inside an event's interval may pair
with that event even beyond `--tolerance-days`; pairs stay one-to-one and the nearest times win. The ±1 day
score stays the headline (it is the benchmark's definition); the interval score is printed beside it.

Measured coverage (a matched truth inside its event's interval): on simulated LEO histories with in-track burns
of 3-30 cm/s every 35-50 days (3 × 3 years at 1 and at 0.4 sets per day; test
`tests/test_tle_timing_interval.py`) **76 of 76** at both cadences, median interval 1.08 days at a median gap of
0.92 days and 3.0 days at 2.3 (the simulated sets carry no TLE lag, so the set before the step already bounds
the burn); on the shared histories (held out, column `in_interval` of `bench_tle_vs_maneuver_detect.py`) 1.00
(Jason-3), 0.94 (Sentinel-3A), 0.89 (CryoSat-2), 0.85 (Fengyun-2D), 0.93 (Fengyun-2E): about the nominal 90 %.
Scored with the intervals (column `f1_intervals`, LOSO, same events): Jason-3 0.89 (0.86 at ±1 day), Sentinel-3A
0.94 (0.94), CryoSat-2 0.79 (0.79), Fengyun-2D 0.91 (0.91), Fengyun-2E 0.90 (0.86); pooled LEO 0.84 (0.838), GEO
0.90 (0.88): events more than a day from the operator's time whose interval holds it (which ones is not itemised
here; on GEO the stale sets of "GEO false alarms one by one" are candidates).

Older catalogue eras: blended sets, outlier sets, arcs
------------------------------------------------------

In the older public catalogue each element set was fitted over several days of tracking, so a burn reaches the
sets over days: the sets whose fit spans contain it carry part of the change (a **blend**), later sets all of
it, and the step the detector sees lies in the gap where most of the change arrives, one to three sets after the
burn. Timed at that step, burns came out late, and the segmentation could accept the blend's gaps as two or
three burns (`abrupt.detect.tle.response`; `ramp_times`, `in_blend` in `abrupt.detect.tle.maneuvers`):

* **A set as a fit over its span.** A set fitted by a straight line in time to the along-track angle over `[t_k
  − S, t_k]` carries, of a burn's mean-motion change at `t_b`, the fraction `f = 3ρ² − 2ρ³`, `ρ = (t_k − t_b)/S`
  clipped to [0, 1] (the least-squares slope through a hinge; checked against numerical least-squares fits,
  `tests/test_tle_response.py`). Around every in-track step the sets are split into an old level of `a`, up to
  three blends (each carrying 0.1-0.9 of the change, rising with time) and a new level, by least squares with a
  penalty of 25 (5 σ) per blend; a blend is looked for only when the step is 20 σ of the window's own scatter of
  `a` away from the step (a fraction resolved to about ±1/4). The window reaches over weaker accepted steps
  within four gaps (they may be the same burn's blend).
* **The fit span of an era.** Each step with two or more blends gives the span `S` that fits its `a` best; the
  span at a time is the median of those within half a year (at least three; else that era's sets do not blend
  and its burns keep the along-track time of method item 6), their smallest and largest its uncertainty. Jason-3
  and Sentinel-3A have no such era; CryoSat-2 has one, 2010-06 to 2012-06, with spans of 3.0-6.0 days (and
  isolated ramps later).
* **Time and interval.** A step with a blend is timed by fitting `a_k = c₀ + c₁τ_k + Δa·f` for every burn time
  inside the first blend's span; the least cost is the time. The profile interval (times within `κ·χ²₁(0.9)` of
  the least cost, `κ` the median reduced χ² of the history's fits, at the era's median, smallest and largest
  span) held 43 % of Jason-1's operator epochs; the event states the TLE-lag interval like every other.
* **One burn, one event.** In an era whose sets blend, a weaker step inside a stronger step's blend (between its
  last old and first new set) is merged into it. Elsewhere two burns in consecutive gaps look the same in `a`,
  so the rule is not applied (it cost Jason-3 and CryoSat-2 burns of their campaigns when it was).
* **The along-track angle as the sets show it** (`timing.smoothed_hinge_d`). A small burn's step in `a` is too
  weak for the blend test, but a set fitted as a line over `[t_k − S, t_k]` shows the kinked track `β·max(0, t −
  t_b)` at its epoch as `β·S·(2ρ² − ρ³)`, `ρ = (t_k − t_b)/S` (checked against numerical least-squares fits,
  `tests/test_tle_response.py`); a sharp hinge fitted to such sets lands inside the ramp, a day or more late.
  Every in-track candidate is fitted for spans of 0 (sharp), 1, 2, 3, 4, 6 and 8 days; the **era's span** is
  the median best span of the detections within half a year (at least three, else sharp), and each burn is
  timed at it. Learned from the sets alone: Sentinel-3A 0-0.25 days, Jason-3 0-2.5, CryoSat-2 4 in 2011 (the
  blend test's era) and 0-2 otherwise, Jason-1 6-8 in 2001-2005. A detection where only the phase moved is
  timed by this hinge when its phase bends rather than jumps (`timing.phase_kinks`: smaller L1 residual than a
  jump): an opposed pair jumps, a burn whose `a` ramps over many sets bends. The era is learned from
  detections with no other within `campaign_days` (a hinge fit reaching over a neighbouring burn is bent by it).
  Jason-1 (held out), `bench_tle_timing.py`: precision 0.58 → 0.69, recall 0.35 → 0.41, median |Δt| 0.535 →
  0.42 days, more than a day late 16 → 9, unmatched 2.53 → 1.83 a year; the three other LEO histories keep
  precision, recall and F1. Tried and not kept: merging a later same-sign step within the era's span into the
  earlier detection (Jason-1 precision 0.76, but a simulated six-burn campaign became one maneuver, and a
  one-burn ramp fit of `a` preferred two burns for every merged Jason-1 pair, so the rule had no physical check).
* **Outlier sets** (`abrupt.detect.tle.outliers`): a set 30 robust σ off the line through both its neighbours,
  the neighbours agreeing (`|y_{k+1} − y_{k−1}| ≤ |r|/2`), the sets beyond them on that line, and no step of `a`
  over the five sets, is counted (`noise_model["outlier_sets"]`, `outlier_epochs_utc`) and printed by `detect
  tle` (6, 5, 3, 51 and 61 sets on Jason-3, Sentinel-3A, CryoSat-2, Fengyun-2D, Fengyun-2E; at 10 σ the LEO
  histories flagged 2-5 % of their sets, campaign sets among them). In GEO the outliers are left out of the
  detection (FY-2D F1 0.909 → 0.930: two false alarms gone). In LEO they stay in: the RAAN residual and the
  along-track phase integrate each set's own secular rates from set to set, so taking a set out changes every
  later value (on the simulated 450 km null histories of `tests/test_tle_drag_trend.py` false alarms rose from 3
  to 23, all at the removed sets; suppressing the steps next to an outlier instead lost four real Fengyun-2E
  burns); the median step test is robust to one set (a 2 km bad set makes no event,
  `tests/test_tle_outliers.py`).
* **Arcs.** A gap between sets longer than `max_bridge_days` (20, the reach of the step test's windows) ends one
  analysed arc and starts another; each arc is detected on its own (noise, threshold, outliers) and no event is
  stated inside the gap (`noise_model["arcs"]`, `["unbridged_gaps"]`; `detect tle` prints each gap). Tested with
  a 2 m/s burn inside a 300-day gap (`tests/test_tle_outliers.py`).
* **Records outside the physical envelope** (`abrupt.readers.tle_checks.check_orbit_envelope`): a set whose
  perigee `a(1 − e)` is inside the Earth (e = 0.9999999), whose apogee is beyond the Moon's distance or whose
  epoch is more than a day in the future (2056) is a malformed record: skipped and counted, or an error naming
  file and line with `--strict`. A kilobytes-long 3LE name line is a one-line error naming the line (it used to
  hide the file's format: "not an OMM file").

`abrupt score` with `--elements` prints, beside the full recall, the **recall above the stated floor** (operator
burns whose in-track or cross-track ΔV reaches the smallest detectable ΔV the run states for their year; a file
without ΔV counts every burn) and the **unmatched detections per calendar year** beside the stated rate. `abrupt
detect tle` prints each year's smallest detectable ΔV and threshold (as before).

**Measured** (`python benchmarks/bench_tle_timing.py`; default settings, budget 1/year, ±1 day one-to-one;
offsets and interval coverage over the pairs within ±3 days). Jason-1 (2001-2013) is held out: every choice
above was made on the other five histories and on simulated histories, and Jason-1 was run **once**, at commit
`da6fc98` (response timing, outliers, arcs; before the span uncertainty of the intervals and the one-burn merge,
which were made afterwards on CryoSat-2 and the simulated 4-day-span history and not run on Jason-1).
`docs/results/bench_tle_timing.txt` and the figure are that run. Before → after (training histories: final
code):

* **Jason-1 (held out, at `da6fc98`)**: P: 0.53 → 0.60; R: 0.33 → 0.37; F1: 0.41 → 0.45; R burns ≥ 2 cm/s: 0.30
  → 0.30 (44); R above floor: 0.44 → 0.50; median |Δt| (d): 0.78 → 0.57; > 1 d late: 21 → 15 of 57; coverage:
  0.71 → 0.51; unmatched / yr: 2.97 → 2.44
* Jason-3: P: 0.94; R: 0.80; F1: 0.865; R burns ≥ 2 cm/s: 0.62 (13); R above floor: 0.82; median |Δt| (d):
  0.085; > 1 d late: 0; coverage: 1.00; unmatched / yr: 0.30
* Sentinel-3A: P: 0.98; R: 0.90; F1: 0.938; R burns ≥ 2 cm/s: 0.85 (26); R above floor: 0.90; median |Δt| (d):
  0.042; > 1 d late: 0; coverage: 0.94; unmatched / yr: 0.15
* CryoSat-2: P: 0.973 → 0.964; R: 0.665 → 0.659; F1: 0.790 → 0.783; R burns ≥ 2 cm/s: 0.66 → 0.66 (58); R above
  floor: 0.83; median |Δt| (d): 0.125 → 0.104; > 1 d late: 2; coverage: 0.87 → 0.93; unmatched / yr: 0.24 → 0.32
* Fengyun-2D: P: 0.91 → 0.95; R: 0.91; F1: 0.909 → 0.930; R burns ≥ 2 cm/s: (no ΔV); R above floor: 0.91; median
  |Δt| (d): 0.197 → 0.162; > 1 d late: 0; coverage: 0.85; unmatched / yr: 0.47 → 0.24
* Fengyun-2E: P: 0.83; R: 0.92; F1: 0.871; R burns ≥ 2 cm/s: (no ΔV); R above floor: 0.92; median |Δt| (d):
  0.183 → 0.165; > 1 d late: 3 → 2; coverage: 0.915 → 0.935; unmatched / yr: 1.18

![Offset from the operator epoch per shared history](tle_timing.png)

*Offsets (event − operator epoch) of the one-to-one pairs within ±3 days; each title gives the median |Δt|, the
interval coverage of the operator epochs, the full recall and the recall above the stated floor (run at
`da6fc98`).*

**Final code on all six** (`python benchmarks/bench_tle_timing.py`, Jason-1 run with it, once per change below
and reported either way): every event's time lies inside its interval (was 94-98 %: merged or retimed events and
bounds rounded to the microsecond); the TLE lag is learned from isolated detections only (a hinge inside a
campaign is pulled to its neighbour burn): coverage Jason-3 1.00 → 0.94, CryoSat-2 0.93 → 0.92, Fengyun-2E
0.935 → 0.91, Sentinel-3A 0.94, Fengyun-2D 0.85, Jason-1 0.71 (P 0.58, R 0.35, median |Δt| 0.53 d, 16 of 58
more than a day late), detections unchanged. Jason-1's sets lag: the operator epoch lies a median 1.6 days
(p90 2.9) before the last set still on the old orbit (Jason-3 0.0 / 0.6); the hinge lags with them. Of its 44
operator lines ≥ 2 cm/s, 25 are opposite cross-track burn pairs whose components sum to zero (the sets show
1-4 mdeg a day where 4.5 m/s would turn the orbit normal 36 mdeg); by net ΔV 19 lines, recall 0.37. Tried and
left out: bounding a ramp-timed burn by the last set on the old level (Jason-1 P 0.58 → 0.59, coverage
0.71 → 0.69, CryoSat-2 coverage 0.93 → 0.89: the catalogue's lag puts burns before such sets).

The leave-one-satellite-out benchmark (`python benchmarks/bench_tle_vs_maneuver_detect.py --no-baseline`, final
code): LEO pooled TP/FP/FN 192/8/71, F1 0.83 (before: 194/6/69, 0.838; CryoSat-2 0.79 → 0.78 with 0.40 unmatched
per year), GEO 64/10/6, F1 0.89 (before: 64/12/6, 0.88); the table of "Measured figures" above is the earlier
run.

CryoSat-2's first era shows what the response model does: nine burns of 2011-05 to 2012-05 that were timed
0.4-0.9 days late are now 0.0-0.3 days late; one burn of October 2012, after the era's sets stopped blending but
within half a year of its last ramps, is timed 1.5 days early (the cost in F1 above). On a simulated 800 km
history whose sets are least-squares fits over 4 days (eight 10-20 cm/s burns; `tests/test_tle_response.py`)
every burn is one event, timed within 0.02 days, its interval holding the burn.

**What does not hold.** On Jason-1 the acceptance asks for a median |Δt| under 0.3 days, precision ≥ 0.85 and
recall ≥ 0.8 of burns ≥ 2 cm/s at ±1 day, and the interval coverage of every history within 85-95 %: measured on
the current code 0.41 days, 0.73, 0.23 and 0.79 — none holds; 17 of
its 44 lines ≥ 2 cm/s lie above the stated floor, 8 found (`benchmarks/bench_tle_floor.py`). The predictive lag
bound (level 0.82, chosen on the five modern histories) keeps every one of them inside 85-95 % leave-one-out.
Jason-1's own null: 2 false alarms in 15.7 satellite-years, 0.69 a year in 2005 (`bench_tle_own_null_by_year.py`).

What the element sets cannot see
--------------------------------

`abrupt detect tle` prints, per satellite and per calendar year, the in-track and cross-track ΔV a step must
have to reach that year's threshold at the median gap (`detectable_by_year` in the noise model: the year's
median step noise of `a` and of the orbit normal, the satellite's group weights and gains, and the year's block
threshold; 50 %-detection sizes as in method item 8). Jason-3's first year needs 0.16 cm/s in-track against
0.053-0.069 cm/s later (commissioning noise and the raised block threshold); CryoSat-2 0.82-0.98 cm/s every
year. `abrupt score` with `--elements` compares the truth file's burns with their year's sizes: a burn is below
when both its in-track and cross-track |ΔV| are. Jason-3: 2 of 40 below; CryoSat-2: 38 of 164 below (its
sub-cm/s trims), neither flagged; a history whose listed burns are mostly below is flagged
(`test_history_whose_burns_are_below_what_its_sets_resolve_is_flagged`: burns at a tenth of the stated size
flagged, at ten times not).

Limitations
-----------

* The own-null check (`detect tle`) under-predicts the false-alarm rate of dense, noisy histories (5 sets a day,
  8× noise: 0.26-1.03 predicted, 1.8 realised): its 60-set blocks are shorter than the noise's correlation
  there. On LEO the realised rate is well below the budget (0.19 per satellite-year held out): the threshold is
  conservative, not calibrated two-sided.
* Campaign burn counts: burns in one gap at nearly the same argument of latitude look like one burn (their
  e-vector change is that of one), and three or more burns in one gap count two (28 of 30 held-out acquisition
  trials met all criteria; the total ΔV was within 0.2 % in all). The simulated campaigns have no TLE lag: on
  real histories a set fitted across a burn spreads it over two gaps, each counted.

* Burns inside one gap between element sets cannot be separated; a campaign is reported as one detection
  (labelled with its campaign) whose ΔV is the sum, with the interval it covers and `burns_max`. Inside a
  campaign the step is a median over sides of two or three sets that may hold the neighbouring burn's level: ΔV
  of a campaign burn can be off by half a neighbour's ΔV (synthetic campaign test: −145 m for a −97 m step).
  Burns two element sets apart are found (segmentation) and timed from their own two sets; burns one set apart
  only with a side of one set (not the default: on real histories TLE convergence over several sets adds false
  alarms). A set fitted across a burn can still make a second, duplicate event where the segment is too short
  for the middle-set test (fewer than three sets before or two after) and the partial mean motion does not
  reverse the order of the two times.
* The middle-set test compares a set's along-track deviation with the phase series' set-to-set noise; a
  calibration of that scale on the history's quiet sets (as for the element groups) was tried and lowered
  CryoSat-2's F1 (more blends kept as two burns), so it is not used.
* Along-track phasing pairs are found when their phase step stands out of the satellite's own phase noise
  (CryoSat-2: 4.9 km found, 0.5 km not); their ΔV is not observable and reported as 0.
* TLE inclination that ramps over the producer's fit span instead of stepping (Sentinel-3A's first weeks) is not
  seen: no ramp-shaped test.
* Radial ΔV and the signs of radial and cross-track ΔV are poorly observable from mean elements; two-burn
  in-track pairs half an orbit apart that leave `a` unchanged are seen only in the e-vector (which the gain γ =
  0.2 de-emphasises) and in the along-track phase (3 Δv × half a period: small).
* **Burns closer than ~15 element sets apart throughout a history** break the per-satellite noise model: the
  first pass tests every gap with windows of 6 sets each side that reach over the neighbouring burns, so most
  gaps are burn flanks (the group weights come out small and the threshold lands on the flanks). Measured on
  injected ±5 cm/s burns at 800 km (4 histories of 3 years each, `simulate_null_history`): at 0.3 sets per day,
  burns every 30 days (9 sets) all missed, every 45 days (14 sets) 44 of 92 missed (the threshold runs to
  141-150 on two of the four), every 60 days (18 sets) or more all found; at 1 set per day, every 30 days all
  found. Campaigns (several burns within days, then weeks of quiet, as CryoSat-2's) are not affected: the
  medians behind the weights ignore them. A second pass that re-learns the weights and the threshold from the
  segmented statistic when fewer than 50 gaps are free of flanks was tried and did not help (misses unchanged,
  false alarms up); not kept.
* Near-circular formulas: for eccentric orbits ΔV magnitudes are approximate.
* GEO north-south burns: the shared files hold two (one each); both are found, but the GEO cross-track
  sensitivity (smallest detectable ≈ 0.9-1.3 m/s from the i-vector noise) is untested beyond them.
* The threshold's false-alarm rate is extrapolated from a few hundred gaps per year; short histories (< 1 year)
  scatter by a factor of 2. Null calibration (above): within 2× of a budget of 1 per satellite-year on every
  simulated LEO and GEO history (largest cell 1.1 per year); the one cell that failed, strong varying drag with
  dense sets (450 km, 3 sets/day: 7.2 per year with the local straight-line trend alone), is fixed by the
  drag-consistent trend (1.0 per year), which no real low-LEO history has checked yet (ISS reboosts and
  continuous low thrust put thrust into the sets' ndot, which the 5-set median only partly removes); budgets
  above ~1 per 2 months are conservative (the threshold's floor of 3 and clustered exceedances: 1/month gives
  0.02-0.3 of it).
* GEO: element sets still on the pre-burn orbit for 1-10 days after a burn (stale sets) and gross single sets
  after a burn move the event later than the burn (4 of 70 operator windows more than a day off) and can split
  one burn into two events; what was tried against them is listed in "GEO false alarms one by one".
* Epochs are UTC (as SGP4 defines them); OMM in another time system is rejected.
* Tuning: the five shared satellites; held-out figures above. The detector will be judged on other satellites of
  the same benchmark: nothing refers to these files.
"""
