"""Self-calibrated thresholds (upper confidence bound of the GPD return level) and the interval ΔV estimate."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from abrupt.detect.orbit.analysis import OrbitDetectorConfig, analyse
from abrupt.detect.orbit.calibration import self_calibrate
from abrupt.detect.orbit.events import find_events
from abrupt.detect.orbit.tuning import auto_tune

SP3 = "sp3/ssas3a20.b18358.e19003.DG_.sp3"


def _real_config(eph: object) -> OrbitDetectorConfig:
    fc, s_pos, s_vel = auto_tune(eph)  # type: ignore[arg-type]
    return OrbitDetectorConfig(
        filter=fc,
        sigma_pos_m=s_pos,
        sigma_vel_mps=s_vel,
        statistic="glr",
        settle_s=max(20.0 * fc.tau_s, 30.0 * eph.nominal_step_s),  # type: ignore[attr-defined]
        orbital_constants=False,
    )


def test_real_arc_without_maneuver_gives_at_most_one_false_alarm_per_week_threshold(shared_data: Path) -> None:
    from abrupt.readers.sp3 import read_sp3

    eph = read_sp3(shared_data / SP3, "L74").to_frame("GCRF")
    an = analyse(eph, _real_config(eph))
    events = find_events(an, self_calibrate(an, names=("glr",)))
    assert len(events) <= 1  # 9.1 days: 1.3 expected at exactly one per week


def test_interval_dv_recovers_injected_impulses_on_real_data_within_five_percent(shared_data: Path) -> None:
    """With the full force model (EGM2008 40×40, Sun, Moon) the interval estimate is within 5 % of 5 mm/s
    (it was within 20 % and better than TS1 with J2-J4; with the full model TS1 is as good)."""
    from dataclasses import replace

    from abrupt.readers.sp3 import read_sp3
    from abrupt.simulate.orbit import inject_impulse

    full = read_sp3(shared_data / SP3, "L74").to_frame("GCRF")
    rng = np.random.default_rng(7)
    err_interval, err_fb = [], []
    for start in (0, 3000, 6000, 9000):
        eph = full.select((np.arange(len(full)) >= start) & (np.arange(len(full)) < start + 1440))  # one day
        t_imp = eph.times_utc[int(rng.integers(600, 840))] + np.timedelta64(int(rng.integers(1, 59)), "s")
        d = rng.normal(size=3)
        dv = 0.005 * d / np.linalg.norm(d)  # orbit frame at the impulse
        injected = inject_impulse(eph, t_imp, dv)
        an = analyse(injected, _real_config(injected))
        thresholds = self_calibrate(an, names=("glr",))
        events = find_events(an, thresholds)
        dt = (pd.to_datetime(events["time_utc"]).dt.tz_localize(None) - pd.Timestamp(t_imp)).dt.total_seconds().abs()
        best = int(np.argmin(dt.to_numpy()))
        assert dt.iloc[best] <= 120.0
        fb = find_events(replace(an, config=replace(an.config, dv_estimate="fb")), thresholds)
        cols = ["dv_r_mps", "dv_t_mps", "dv_n_mps"]
        err_interval.append(np.linalg.norm(events[cols].iloc[best].to_numpy() - dv))
        err_fb.append(np.linalg.norm(fb[cols].iloc[best].to_numpy() - dv))
    assert max(err_interval) < 0.05 * 0.005
    assert max(err_fb) < 0.2 * 0.005


def test_cli_threshold_confidence_zero_gives_the_lower_point_estimate_threshold(
    shared_data: Path, tmp_path: Path
) -> None:
    from click.testing import CliRunner

    import abrupt.cli.orbit  # noqa: F401  (registers the orbit commands)
    from abrupt.cli.groups import cli
    from abrupt.events import read_events
    from abrupt.readers.navigation_csv import write_navigation_csv
    from abrupt.readers.sp3 import read_sp3
    from abrupt.simulate.orbit import inject_impulse

    eph = read_sp3(shared_data / SP3, "L74")
    eph = eph.select(np.arange(len(eph)) < 1440)
    injected = inject_impulse(eph, eph.times_utc[700] + np.timedelta64(17, "s"), np.array([0.0, 0.01, 0.0]))
    write_navigation_csv(injected, tmp_path / "inj.csv")
    thresholds = []
    for z in ("1", "0"):
        out = tmp_path / f"events_{z}.csv"
        args = ["detect", "orbit", str(tmp_path / "inj.csv"), "--out", str(out), "--threshold-confidence", z]
        res = CliRunner().invoke(cli, [*args, "--catalog", str(tmp_path / "c.sqlite")])
        assert res.exit_code == 0, res.output
        events = read_events(str(out))
        assert len(events) >= 1
        thresholds.append(float(events["threshold"].iloc[0]))
    # the glr threshold may sit on its χ²-median floor (the same for both); the tail-fit level is lower
    assert thresholds[1] <= thresholds[0]
    from abrupt.pipelines.orbit import detect_orbit

    levels = [detect_orbit(injected, confidence_z=z).thresholds["mcr_w"].value for z in (1.0, 0.0)]
    assert levels[1] < levels[0]
