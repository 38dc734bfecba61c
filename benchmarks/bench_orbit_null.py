"""False alarms of ``abrupt detect orbit`` on every complete real ephemeris in ``../shared/data/sp3``
(every satellite of the multi-satellite files), at the default budget of one per week: events per
satellite-day against the stated rate with a Poisson interval, pooled per orbit class (LEO, GNSS,
geodetic), and the 90 %-detectable ΔV per file.

Every file of the folder and of ``orekit-corpus/`` is read as a user would (``parse_sp3``; files the
reader refuses are listed with their one-line error). A satellite is analysed when it has an arc the
detector can calibrate itself on; shorter ones are counted as "too short" and add no exposure. Every
event found on these products is treated as false: the two DORIS arcs have no manoeuvre, the GNSS
day has been checked against no list (a BeiDou GEO/IGSO station-keeping burn is possible; any event is
printed with its time so that it can be looked up).

A multi-satellite file is run as ``detect orbit --all-satellites`` runs it
(:func:`abrupt.pipelines.orbit_product.detect_orbit_product`: each satellite's threshold from the other
satellites of the file, leave-one-satellite-out); ``--no-pooled`` calibrates each arc on its own. The
exposure is the searched time (epochs where the event statistic is defined: the filters' settling time at
each end of an arc, up to 6 h, cannot raise an event); the files' span is printed beside it.

Pass rule per class (acceptance): the observed count is inside the two-sided 95 % Poisson interval of the
count expected at the stated rate, and the observed rate is at most 2 × the stated one. The realised
rate is printed with its exact (Garwood) 95 % interval beside the stated rate.

The two ILRS CPF predictions of ``../shared/data/tracking/ilrs-corpus`` (LAGEOS-1, Galileo 212; real,
positions only) are added to their classes. No long geodetic (passive laser-ranging) SP3 arc is in
``../shared``; two daily-arc products are simulated
(:mod:`abrupt.simulate.products`, seeds other than those the boundary rule was developed on) and
pooled as their own class, labelled as simulated.

Held out: nothing in the detector was tuned on the GNSS or geodetic files; the self-calibration rules
were set on Sentinel-3A (docs/orbit.md), so Sentinel-3A is in-sample and every other file held out. The
boundary rule was developed on simulated products with seeds 0 and 1, and its pattern level relaxed from
10⁻³ to 5 % after seeds 3 and 4 (the Etalon-like seed 4 kept 2 boundary events); the benchmark now uses
seeds 5 and 6, not seen before.

    nice python benchmarks/bench_orbit_null.py [--max-sats N] [--budget 1/week] [--no-pooled]

False alarms on every real product, burn pairs, day boundaries
--------------------------------------------------------------

`nice python benchmarks/bench_orbit_null.py` reads every SP3 file in `../shared/data/sp3` and its Orekit corpus
(every satellite), runs `detect orbit` at its defaults (1/week) on each arc of at least 6 hours — a
multi-satellite file as `detect orbit --all-satellites` does (thresholds from the other satellites,
`--no-pooled`: each arc on its own) — counts events per **searched** satellite-day (the epochs where the event
statistic is defined; the files' span is printed beside it) against the stated rate and prints the 90
%-detectable ΔV per file. Arcs shorter than 6 hours (most of the corpus: 1-91 epochs) are counted as too short;
the two real ILRS CPF predictions of `../shared/data/tracking/ilrs-corpus` are added to their classes, and two
simulated daily-arc products (seeds 5 and 6, not used in development) form a class of their own. The run writes
`docs/results/bench_orbit_null.txt` (172 s wall, load ~10 on two shared cores):

* GNSS (gbm18432: 71 satellites, 300 s, 1 day, leave-one-satellite-out; Galileo CPF): satellites: 72; searched
  sat-days (span): 36.64 (72.75); events: 6; expected at 1/week: 5.23; 95 % of expected: [1, 10]; realised rate
  [95 %]: 0.164 [0.060, 0.36]; pass: yes
* LEO (Sentinel-3A, Jason-1, 60 s): satellites: 2; searched sat-days (span): 18.48 (19.04); events: 0; expected
  at 1/week: 2.64; 95 % of expected: [0, 6]; realised rate [95 %]: 0 [0, 0.20]; pass: yes
* geodetic, real (LAGEOS-1 CPF, 300 s): satellites: 1; searched sat-days (span): 1.52 (2.02); events: 0;
  expected at 1/week: 0.22; 95 % of expected: [0, 1]; realised rate [95 %]: 0 [0, 2.4]; pass: yes
* geodetic, simulated daily arcs (2 min / 4 d; 15 min / 7 d): satellites: 2; searched sat-days (span): 9.89
  (11.00); events: 1; expected at 1/week: 1.41; 95 % of expected: [0, 4]; realised rate [95 %]: 0.10 [0.003,
  0.56]; pass: yes

The stated rate is 0.143 per day. The GNSS class realises it: 0.164 per searched satellite-day (6 events; 5 in
the run before the burn-sequence change that resolves burns more than one GLR window apart), where the per-arc
rule gave 1 event (0.014 per span-day, 0.027 per searched day). The events are the file's null as the
calibration sees it: four GPS Earth-shadow crossings (G09 14:27, G15 06:57, G23 13:32, G28 15:47 UTC, each
inside the satellite's computed eclipse), the sequence scan's second G15 "burn" at 07:57 (one GLR window after
the first: the residual of taking the shadow crossing out as an impulse; the same two events on main before the
shadow-passage work, checked), and Galileo E14 at the product's common 12:00 feature, 0.09-0.16 mm/s, at the
detection limit. The pooled thresholds hold the shadow passages in their null, so they are not treated again as
nuisance there. Each satellite's threshold comes from the other 70 (held out by construction); nothing in the
rule was tuned on this file. The 90 %-detectable

0.235 mm/s, Jason-1 0.155, Galileo CPF 0.066, LAGEOS-1 CPF 0.10, simulated LAGEOS-like 0.0009 and Etalon-like
0.033 mm/s (smooth simulated products). Single-satellite files are unchanged (LEO, geodetic: 0 events as
before). Before the boundary treatment the simulated products raised 3 of 3 and 4 of 6 boundaries as events.
Held out: every file except Sentinel-3A (on which the self-calibration rules were set earlier); the boundary
rule's pattern level was relaxed from 10⁻³ to 5 % after simulated seeds 3-4, and the sequence scans were made to
keep the first scan's thresholds after seed 4 (a removed boundary "burn" changed the re-calibrated threshold and
let another boundary through), so seeds 3-4 are in-sample and 5-6 held out.

**Simulated null products** (`nice python benchmarks/bench_orbit_null_simulated.py --sats 10`, writes
`docs/results/bench_orbit_null_simulated.txt`): 10 satellites per product from abrupt's own simulator (EGM2008
40×40, Sun, Moon, SRP with a conical shadow, drag in LEO; 1 cm / 0.01 mm/s white noise; the filter has no SRP).
First-scan exceedance episodes over the searched time, realised against stated; "+nuisance": the
single-satellite detector as a user runs it (per-arc rule with day boundaries and Earth-shadow passages judged
as nuisance, first-scan events). These seeds are held out for the shadow-passage treatment (developed on
`--seed-base=6000`, `bench_orbit_null_simulated_dev.txt`):

* LEO 800 km, 30 s, 0.5 d: searched sat-days: 3.61; 1/day: expected [95 %]: 3.61 [0, 8]; per-arc: 0;
  per-arc+nuisance: 0; leave-one-satellite-out: 4; 1/week: expected [95 %]: 0.52 [0, 2]; per-arc: 0;
  per-arc+nuisance: 0; leave-one-out: (too few others)
* geodetic 5900 km, 5 min, 2 d: searched sat-days: 15.03; 1/day: expected [95 %]: 15.03 [8, 23]; per-arc: 2;
  per-arc+nuisance: 0; leave-one-satellite-out: 17; 1/week: expected [95 %]: 2.15 [0, 5]; per-arc: 0;
  per-arc+nuisance: 0; leave-one-out: (too few others)
* GNSS 20 200 km, 5 min, 1 d: searched sat-days: 5.00; 1/day: expected [95 %]: 5.00 [1, 10]; per-arc: 0;
  per-arc+nuisance: 0; leave-one-satellite-out: 5; 1/week: expected [95 %]: 0.71 [0, 3]; per-arc: 0;
  per-arc+nuisance: 0; leave-one-out: (too few others)
* GNSS 20 200 km, 15 min, 3 d: searched sat-days: 23.85; 1/day: expected [95 %]: 23.85 [15, 34]; per-arc: 16;
  per-arc+nuisance: 7; leave-one-satellite-out: 24; 1/week: expected [95 %]: 3.41 [0, 7]; per-arc: **10**;
  per-arc+nuisance: **0**; leave-one-out: 5
* all: searched sat-days: 47.50; 1/day: expected [95 %]: 47.5; per-arc: 18 (0.38/day); per-arc+nuisance: 7
  (0.15/day); leave-one-satellite-out: **50 (1.05/day [0.78, 1.39])**; 1/week: expected [95 %]: 6.79; per-arc:
  10 (0.21/day); per-arc+nuisance: 0 (0 [0, 0.078]/day); leave-one-out: 5 (0.105/day [0.034, 0.25])

The product calibration gives the stated rate at every sampling and altitude (1/day: 1.05 per day against 1;
1/week: 0.105 against 0.143, interval containing it); where the others' exposure allows fewer than two episodes
(14 searched satellite-days at 1/week) it falls back to the per-arc rule. The per-arc rule alone was **too
liberal on the simulated 15-minute GNSS product at 1/week (10 against 3.4; every one a shadow passage of the SRP
the filter lacks)**; with the passages judged as nuisance ("Earth-shadow passages" above) the single-satellite
detector raises **0 against 3.4 (Poisson 95 % [0, 7]) on these held-out seeds**, and 3 (against 3.41) on the
development seeds. It is conservative: 7 episodes at 1/day where 23.9 were allowed on the 15-minute product
(below the interval [15, 34]) and 0.15 per day over all products against 1: a single coarse arc's own null still
places its level above the bulk (the χ²₃ floor, "Why the one-day GNSS files raised a tenth", item 1), and the
passage windows are taken out of the search.

`nice python benchmarks/bench_orbit_burn_pairs.py` (10 trials per arc, seed 7): two impulses 30-90 min apart,
1-2 cm/s each in random directions, injected into 12-hour sub-arcs of the real arcs. Both found within 120 s
with |ΔV| within 20 %: **Sentinel-3A 10/10** (max time error 0.9 s, max ΔV error 0.5 %), **Jason-1 9/10** (held
out; the nine within 0.7 s and 0.5 %). The miss: a pair 32 min apart straddling midnight, whose first scan
located one merged jump between the two burns (18 mm/s at 23:53, burns at 23:36 and 00:08); removing that merged
estimate does not separate them. A two-jump GLR would. Before (a single scan) the second burn of every pair was
merged into the first event.

Acceptance figures of the arcs kept: Sentinel-3A and Jason-1 raise 0 events on the whole arcs, and a 2 cm/s
along-track impulse injected into Sentinel-3A at 2018-12-26T06:00 is found at 06:00:00.34 with ΔV 0.019987 m/s
(one event; the sequence scan finds nothing more).
"""

from __future__ import annotations

import argparse
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy import stats

from abrupt.errors import InputError
from abrupt.pipelines.orbit import OrbitRun, detect_orbit
from abrupt.pipelines.orbit_product import detect_orbit_product
from abrupt.readers.ephemeris import read_ephemeris
from abrupt.readers.sp3 import parse_sp3
from abrupt.series.ephemeris import Ephemeris
from abrupt.simulate.products import DailyArcProduct, simulate_daily_arcs
from abrupt.thresholds import FalseAlarmBudget

DATA = Path(__file__).resolve().parents[1].parent / "shared/data/sp3"
GNSS_PREFIXES = ("G", "R", "E", "C", "J", "I")
SIMULATED = {
    "simulated LAGEOS-like, 4 days at 2 min": DailyArcProduct(days=4, step_s=120.0, seed=5),
    "simulated Etalon-like, 7 days at 15 min": DailyArcProduct(days=7, step_s=900.0, altitude_m=19.1e6, seed=6),
}
MIN_SPAN_H = 6.0  # shorter arcs: the filters settle for up to a few hours at each end


@dataclass
class ClassTally:
    sat_days: float = 0.0  # searched: epochs where the event statistic is evaluated (not the settling ends)
    span_days: float = 0.0
    methods: set[str] = field(default_factory=set)
    events: int = 0
    satellites: int = 0
    too_short: int = 0
    files: set[str] = field(default_factory=set)

    def count_whole_arc(self, eph: Ephemeris, run: OrbitRun) -> float:
        """Count one satellite run on its whole arc (span from the epochs); returns its searched days."""
        days = searched_days(run)
        self.span_days += float(eph.seconds[-1] - eph.seconds[0]) / 86400.0
        self.satellites += 1
        self.sat_days += days
        self.events += len(run.events)
        self.methods.add(run.summary.get("thresholds", {}).get("glr", {}).get("method", "-"))
        return days


def orbit_class(eph: Ephemeris) -> str:
    """LEO below 2000 km; GNSS: a GNSS system letter and a navigation-satellite altitude (MEO, IGSO, GEO);
    geodetic: the rest (passive laser-ranging satellites such as LAGEOS at 5900 km)."""
    alt_km = float(np.median(np.linalg.norm(eph.position_m, axis=1))) / 1e3 - 6378.137
    if alt_km < 2000.0:
        return "LEO"
    sid = eph.satellite.lower()
    named = sid.startswith(("galileo", "glonass", "gps", "beidou", "compass", "qzs", "irnss"))
    if alt_km > 15000.0 and (named or (eph.satellite[:1] in GNSS_PREFIXES and eph.satellite[1:].isdigit())):
        return "GNSS"
    return "geodetic"


def searched_days(run: OrbitRun) -> float:
    """Satellite-days the event search covered: epochs where the event statistic is defined (the filters'
    settling time at each end of an arc is not searched, up to 6 h each: half of a one-day file)."""
    an = run.analysis
    if an is None:
        return 0.0
    s = an.statistics[run.detector.statistic]
    return float(np.count_nonzero(np.isfinite(s))) * run.ephemeris.nominal_step_s / 86400.0


def garwood(n: int, alpha: float = 0.05) -> tuple[float, float]:
    lo = 0.0 if n == 0 else float(stats.chi2.ppf(alpha / 2, 2 * n)) / 2
    return lo, float(stats.chi2.ppf(1 - alpha / 2, 2 * n + 2)) / 2


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--max-sats", type=int, default=0, help="analyse at most N satellites per file (0: all)")
    parser.add_argument("--budget", default="1/week")
    parser.add_argument("--no-simulated", dest="simulated", action="store_false", help="skip the simulated products")
    parser.add_argument(
        "--no-pooled",
        dest="pooled",
        action="store_false",
        help="calibrate each satellite of a multi-satellite file on its own arc (the per-arc rule)",
    )
    args = parser.parse_args()
    budget = FalseAlarmBudget.parse(args.budget)
    files = sorted(p for p in DATA.rglob("*") if ".sp3" in p.name)
    tallies: dict[str, ClassTally] = {}
    seen: set[bytes] = set()
    print(f"{'file':44s} {'class':8s} {'sats':>5s} {'sat-days':>8s} {'events':>6s} {'expected':>8s}  ΔV90 (mm/s)")
    t_start = time.time()
    for path in files:
        try:
            content = parse_sp3(path)
        except InputError as exc:
            print(f"{path.name:44s} refused: {str(exc).split(': ', 1)[-1]}")
            continue
        per_class: dict[str, ClassTally] = {}
        dv90: list[float] = []
        notes: list[str] = []
        sats = list(content.ephemerides.items())
        if args.max_sats:
            sats = sats[:: max(1, len(sats) // args.max_sats)][: args.max_sats]
        todo: dict[str, Ephemeris] = {}
        for sid, eph in sats:
            tally = per_class.setdefault(orbit_class(eph), ClassTally())
            span_h = float(eph.seconds[-1] - eph.seconds[0]) / 3600.0 if len(eph) > 1 else 0.0
            key = eph.position_m.tobytes()  # corpus files repeat the same records under other names
            if span_h < MIN_SPAN_H or key in seen:
                tally.too_short += span_h < MIN_SPAN_H
                continue
            seen.add(key)
            todo[sid] = eph
        # a multi-satellite product: each satellite's threshold from the others (leave-one-satellite-out)
        if len(todo) > 1 and args.pooled:
            runs = detect_orbit_product(todo, budget=budget)
        else:
            runs = {sid: detect_orbit(eph, budget=budget) for sid, eph in todo.items()}
        for sid, run in runs.items():
            tally = per_class[orbit_class(run.ephemeris)]
            if "glr" not in run.summary.get("thresholds", {}):
                tally.too_short += 1
                continue
            tally.satellites += 1
            tally.sat_days += searched_days(run)
            tally.span_days += run.summary["span_days"]
            tally.events += len(run.events)
            tally.methods.add(run.summary["thresholds"]["glr"]["method"])
            for t, dv in zip(run.events["time_utc"], run.events["dv_mps"], strict=True):
                notes.append(f"{sid} {str(t)[:19]} {1e3 * dv:.3g} mm/s")
            if np.isfinite(run.summary.get("dv90_mps", np.nan)):
                dv90.append(1e3 * float(run.summary["dv90_mps"]))
        for cls, tally in per_class.items():
            total = tallies.setdefault(cls, ClassTally())
            total.sat_days += tally.sat_days
            total.span_days += tally.span_days
            total.methods |= tally.methods
            total.events += tally.events
            total.satellites += tally.satellites
            total.too_short += tally.too_short
            if tally.satellites:
                total.files.add(path.name)
            exp = budget.per_day * tally.sat_days
            dv_txt = f"{np.median(dv90):.3g} (median; {min(dv90):.3g}-{max(dv90):.3g})" if dv90 else "-"
            short = f"  [{tally.too_short} too short]" if tally.too_short else ""
            if tally.satellites:
                short += f"  [span {tally.span_days:.2f} d; thresholds: {', '.join(sorted(tally.methods))}]"
            print(
                f"{path.name:44s} {cls:8s} {tally.satellites:5d} {tally.sat_days:8.2f} {tally.events:6d} "
                f"{exp:8.2f}  {dv_txt}{short}"
            )
        for note in notes:
            print(f"    event: {note}")
    # real ILRS predictions (CPF, positions only) of a passive geodetic and a GNSS satellite: no SP3, but
    # real orbits of the two classes the SP3 folder holds only briefly
    for path in sorted((DATA.parent / "tracking" / "ilrs-corpus").glob("*_cpf_*")):
        eph = read_ephemeris(path)
        cls = orbit_class(eph)
        total = tallies.setdefault(cls, ClassTally())
        run = detect_orbit(eph, budget=budget)
        days = total.count_whole_arc(eph, run)
        dv90_one = 1e3 * float(run.summary.get("dv90_mps", np.nan))
        print(
            f"{path.name:44s} {cls:8s} {1:5d} {days:8.2f} {len(run.events):6d} {budget.per_day * days:8.2f}  "
            f"{dv90_one:.3g}  [ILRS CPF prediction, positions only]"
        )
    if args.simulated:
        # no long real geodetic arc is in ../shared: the daily-arc products that made the detector fail
        # on real ILRS orbits are simulated (abrupt.simulate.products) and pooled as their own class
        total = tallies.setdefault("geodetic (simulated daily arcs)", ClassTally())
        for name, cfg in SIMULATED.items():
            eph = simulate_daily_arcs(cfg)
            run = detect_orbit(eph, budget=budget)
            days = total.count_whole_arc(eph, run)
            nuisance = sum(not b["raised"] for b in run.summary.get("product_boundaries", []))
            dv90_one = 1e3 * float(run.summary.get("dv90_mps", np.nan))
            print(
                f"{name:44s} {'geodetic':8s} {1:5d} {days:8.2f} {len(run.events):6d} "
                f"{budget.per_day * days:8.2f}  {dv90_one:.3g}  [{nuisance} day boundaries treated as nuisance]"
            )
    print(f"\nstated rate {budget.per_day:.4g} per satellite-day ({args.budget}); {time.time() - t_start:.0f} s")
    print("sat-days: searched (the event statistic defined); in brackets the files' span")
    print(
        f"{'class':9s} {'sats':>5s} {'sat-days':>16s} {'events':>6s} {'expected':>8s} {'95% of expected':>16s} "
        f"{'realised rate (95%)':>26s}  pass  thresholds"
    )
    for cls, tally in sorted(tallies.items()):
        exp = budget.per_day * tally.sat_days
        lo_e, hi_e = (float(stats.poisson.ppf(0.025, exp)), float(stats.poisson.ppf(0.975, exp))) if exp else (0, 0)
        lo, hi = garwood(tally.events)
        rate = tally.events / tally.sat_days if tally.sat_days else float("nan")
        ok = lo_e <= tally.events <= hi_e and (tally.events == 0 or rate <= 2 * budget.per_day)
        realised = f"{rate:.3g} [{lo / tally.sat_days:.3g}, {hi / tally.sat_days:.3g}]" if tally.sat_days else "-"
        note = "  (below the interval: conservative)" if tally.events < lo_e else ""
        days_txt = f"{tally.sat_days:.2f} ({tally.span_days:.2f})"
        print(
            f"{cls:9s} {tally.satellites:5d} {days_txt:>16s} {tally.events:6d} {exp:8.2f} "
            f"{f'[{lo_e:.0f}, {hi_e:.0f}]':>16s} {realised:>26s}  {'PASS' if ok else 'FAIL'}  "
            f"{', '.join(sorted(tally.methods))}{note}"
        )


if __name__ == "__main__":
    from _results import variant, write_results

    with write_results("bench_orbit_null", variant({"--no-pooled": "per_arc", "--no-simulated": "real_only"})):
        main()
