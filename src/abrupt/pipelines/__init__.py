"""Pipelines: the orchestration of one capability, read → series → clean → model → detect → events.

One module per capability (``attitude``, ``tracking``, ...), with no click inside: the command line
(:mod:`abrupt.cli`) parses options, calls a pipeline and writes its outputs, and the Python API calls
the same functions.

Flight telemetry (:mod:`abrupt.pipelines.flight`): the stages
-------------------------------------------------------------

1. **Ingest** (`abrupt.readers.archive`, `abrupt.store`): long (`time,mnemonic,value`) or wide tables, CSV /
   CSV.gz / Parquet. Names are replaced by the decoder's pseudonyms before anything else; the decoder is read
   only here. Removed and counted per day: blank rows, `,,` rows, empty values, placeholders (`-999999`, `NaN`),
   exact duplicates. Reported: conflicting duplicates (first value kept), time reversals (sorted). A name
   missing from the decoder is dropped and counted under a salted hash (`unknown-3f9a1c`), never printed. Times
   need a zone (`Z`); `--assume-utc` reads zone-less times as UTC (counted). Two spacecraft in one archive go to
   their own partitions `STORE/spacecraft=SC-A/day=YYYY-MM-DD/samples.parquet` with `ingest.json` beside it.
   With `--spacecraft FILE`, values beyond the physical bounds of its `[flight]` channels (quaternion component
   1.1, body rate 2 rad/s, 1.5 × each wheel's limit, in the declared units) are removed and counted per day
   (`values beyond the spacecraft file's physical bounds`).
2. **Timetable** (`abrupt.series.timetable`): one grid (absolute multiples of 1/`grid_hz`), a method per channel
   from the spacecraft file: `linear`, `mean` (oversampled gyro), `hold` (flags written on change), `savgol`
   (tachometer speeds, Harris §3.4.1; tachometer gate means are moved to the gate centre), `unwrap_rate`
   (appendage angle → rate), `quaternion` (sign continuity, nlerp). Gaps stay gaps.
3. **Momentum** (`abrupt.series.timetable_momentum`): ᴮH = Jω + Σ J_s Ω ĝ + Σ I_a θ̇ â, ᴺH = [BN]ᵀ ᴮH; wheel
   speeds in rad/s, rpm, rps or tachometer counts. A wheel unit that contradicts the tachometer quantum (rpm
   declared as rad/s) is an error naming `flight.channels[k].unit`. Each channel is checked against another that
   measures the same motion (`abrupt.pipelines.flight_checks`, in `detect attitude` and `estimate inertia` on a
   store), and the error names the channel that disagrees: the **gyro** against the star tracker's quaternion
   (median |ω_gyro| / 2|q̇| outside [0.13, 7.6], the geometric midpoints between the declared unit and the
   nearest other rate unit, when the attitude moves at least 5× the quaternion rate's scatter; deg/s declared as
   rad/s gives 57.3; a gyro bias step as large as a slow body rate moves the ratio to 2-3 with no unit wrong, so
   the bounds are not tighter); an **appendage angle** declared `rad` that goes beyond 2π (+2 %: degrees read as
   radians); then the **wheels** against conservation of ᴺH and the tachometer quantum (so that a wrong gyro is
   not blamed on the wheels).
4. **Cleaning** (`abrupt.clean`), each switchable (`--no-clean`): event-flag masks with the channel's margins;
   slew masks from the gyro (attitude departs > 1° in a minute from its nominal motion; a strike of ≤ 3 N·m·s
   moves it ≤ ~0.3°), confirmed by the star tracker's rate where it has attitudes (a gyro bias step is no slew);
   the **trend** (quadratic: the slow real external torque, so a constant-ᴺH null is not assumed) and the
   **comb** (orbit harmonics, Harris Eqs. 1-2, K chosen per fit by BIC) fitted locally (±1 orbit, anchors every
   ¼ orbit, blended), every masked interval a free step, and — in 3 passes — every GLR peak above 8σ a free step
   that is kept in the data, so strikes are not absorbed by the smooth model. The fits run on 10-s bin means of
   the valid samples (bins anchored at absolute times, weighted by counts; for harmonics of period ≥ P/6 the
   coefficients differ from the per-sample fit by ~1e-4 relative) and a pass refits only the anchors whose
   windows gained or lost a candidate step. The inertia stage is the spacecraft file itself (give a file with an
   estimated inertia; `abrupt estimate inertia`, abrupt.massprops, writes one). **Orbit period**: from `[orbit]`
   in the spacecraft file; without it, from the data of the run's first day — an Earth-pointing spacecraft turns
   once per orbit, so P = 2π / median rotation rate between star-tracker attitudes 300 s apart (kestrel: 5942 s
   against the file's Keplerian 5926 s), else the strongest period of ᴺH (Lomb-Scargle). The run's warnings say
   which.
5. **Detection**: the registered detector `attitude.flight_glr` (`abrupt.detect.attitude.flight_glr`, 300 s
   windows, 20 s guard) on cleaned ᴺH: the GLR statistic of `attitude.glr` on each gap-free run, local peaks
   above a floor, event time from the maximum of a 30-sample mean difference, ΔH from a local step +
   linear-trend fit. **Threshold** on the spacecraft's own statistic: block maxima (10 min) fitted by a Gumbel
   law through their quartiles (`abrupt.thresholds.robust`), which tolerates the few blocks a strike
   contaminates, at the stated false-alarm rate per day. It differs from `attitude.glr` in its peaks, step fit
   and threshold (not by one setting), so it is its own detector; its events carry its name.
6. **Chunks**: runs of up to 3 consecutive days (`FlightRunConfig.chunk_s`; shorter values cut days into pieces)
   with the margin of `chunk_margin_s` on each side (every stage is local and anchored at absolute times), so
   memory is bounded by one chunk and does not grow with the number of days. Chunks are independent tasks:
   `run_flight(..., executor=Executor(workers=2))` runs them on worker processes (`abrupt.scale`). 6-hour chunks
   give the events of one whole-run chunk (test on kestrel).
7. **Injection** (`abrupt.simulate.injection`, Harris §3.5): the closed-loop simulator
   (`abrupt.simulate.pointing.simulate_pointing`: rigid body + wheels, MRP tracking law) follows the telemetry's
   own attitude with and without the strike for 300 s; the difference (body rate, attitude error, wheel speeds)
   is added, then the wheels hold [BN(t)]ΔH_N (ᴺH conserved). Written back in native units with tachometer
   counts regenerated from the archive's own pulse phase (its fraction estimated from the counts, all injections
   quantised once; samples no injection changes come back bit for bit: `requantised_wheel`,
   abrupt.detect.attitude.attribution). The controller gains are the simulator's (a spacecraft file does not
   carry them); detection on ᴺH depends on them only through the first seconds. `response="linear"` keeps the
   earlier analytic stand-in.
8. **Daily statistics**: analysed, gap and masked fractions, noise floor, events, budget, threshold (and ΔH90
   from `--recovery`), in the report and with `detect attitude --store`.
"""
