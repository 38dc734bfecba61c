"""Flight-telemetry pipeline: ingest and its bad inputs, leak scan, timetable, cleaning,
detection on a synthetic archive with known truth, chunked = whole, injection, thresholds."""

from __future__ import annotations

import gzip
import io
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from abrupt.clean.comb import CombConfig, comb_subtract, smooth_model
from abrupt.cli.main import main
from abrupt.detect.attitude.flight_glr import FlightGlrDetector
from abrupt.detect.base import detector_names
from abrupt.errors import ConfigError, InputError
from abrupt.model.flight_config import FlightChannel
from abrupt.model.spacecraft import load_spacecraft, spacecraft_from_dict
from abrupt.pipelines.flight import (
    DAY_NS,
    CleaningConfig,
    FlightRunConfig,
    chunk_spans,
    ingest_archives,
    process_chunk,
    run_flight,
)
from abrupt.readers.archive import read_archive, read_decoder
from abrupt.series.attitude import CleanedMomentum
from abrupt.series.timetable import channel_on_grid, continuous_quaternion, grid
from abrupt.simulate.injection import InjectedStrike, inject_strikes
from abrupt.store import TelemetryStore
from abrupt.thresholds import FalseAlarmBudget
from abrupt.thresholds.robust import gumbel_quantile_fit, robust_block_maxima_threshold
from flight_synth import REAL, make_archive

FAST = FlightRunConfig(cleaning=CleaningConfig(passes=2))
NS = 1_000_000_000


def _decoder(tmp: Path, extra: str = "") -> Path:
    p = tmp / "decoder.csv"
    p.write_text("real_name,pseudonym\nBIRD,SC-B\nBIRD.A,SC-B.ch01\nBIRD.B,SC-B.ch02\n" + extra)
    return p


def _archive(tmp: Path, body: str, name: str = "BIRD_dump.csv") -> Path:
    p = tmp / name
    p.write_text("time,mnemonic,value\n" + body)
    return p


# ---------------------------------------------------------------- ingest and its bad inputs


def test_archive_artifacts_removed_and_counted(tmp_path: Path) -> None:
    body = (
        "2026-03-10T00:00:00.000Z,BIRD.A,1.0\n"
        "\n"
        ",,\n"
        "2026-03-10T00:00:01.000Z,BIRD.A,\n"  # empty value
        "2026-03-10T00:00:02.000Z,BIRD.A,-999999\n"  # placeholder
        "2026-03-10T00:00:03.000Z,BIRD.A,NaN\n"  # placeholder text
        "2026-03-10T00:00:04.000Z,BIRD.A,4.0\n"
        "2026-03-10T00:00:04.000Z,BIRD.A,4.0\n"  # exact duplicate
        "2026-03-10T00:00:05.000Z,BIRD.A,5.0\n"
        "2026-03-10T00:00:05.000Z,BIRD.A,5.5\n"  # conflicting duplicate
        "2026-03-10T00:00:07.000Z,BIRD.B,7.0\n"
        "2026-03-10T00:00:06.000Z,BIRD.B,6.0\n"  # time reversal
    )
    dec = read_decoder(_decoder(tmp_path))
    chunk = read_archive(_archive(tmp_path, body), dec)
    rep = chunk.per_day[("SC-B", "2026-03-10")]
    assert rep.removed["empty values"] == 1
    assert rep.removed["placeholder values"] == 2
    assert rep.removed["exact duplicate rows"] == 1
    assert rep.reported["conflicting duplicates (first value kept)"] == 1
    assert rep.reported["time reversals (sorted)"] == 1
    assert chunk.file_counts["blank rows"] == 1
    s = chunk.samples
    a = s.loc[s["mnemonic"] == "SC-B.ch01", "value"].tolist()
    assert a == [1.0, 4.0, 5.0]  # first value of the conflict kept
    b = s.loc[s["mnemonic"] == "SC-B.ch02", "time"]
    assert b.is_monotonic_increasing


def test_times_without_zone_are_an_error_naming_the_line_or_read_as_utc(tmp_path: Path) -> None:
    body = "2026-03-10T00:00:00.000Z,BIRD.A,1\n2026-03-10T00:00:01.000,BIRD.A,2\n"
    dec = read_decoder(_decoder(tmp_path))
    with pytest.raises(InputError, match=r":3: column 'time': .*no time zone"):
        read_archive(_archive(tmp_path, body), dec)
    chunk = read_archive(_archive(tmp_path, body), dec, assume_utc=True)
    assert chunk.file_counts["times without zone read as UTC"] == 1
    assert len(chunk.samples) == 2


def test_name_missing_from_decoder_is_dropped_counted_and_never_printed(tmp_path: Path) -> None:
    body = "2026-03-10T00:00:00Z,BIRD.A,1\n2026-03-10T00:00:00Z,BIRD.SECRETCHAN,2\n"
    dec = read_decoder(_decoder(tmp_path))
    chunk = read_archive(_archive(tmp_path, body), dec)
    assert len(chunk.samples) == 1
    text = repr(chunk.file_counts) + repr({k: v.as_dict() for k, v in chunk.per_day.items()})
    assert "SECRETCHAN" not in text and "BIRD" not in text
    assert any(k.startswith("rows of a name not in the decoder (unknown-") for k in chunk.file_counts)


def test_two_spacecraft_in_one_archive_go_to_their_own_partitions(tmp_path: Path) -> None:
    dec = _decoder(tmp_path, "OWL,SC-C\nOWL.A,SC-C.ch01\n")
    body = "2026-03-10T00:00:00Z,BIRD.A,1\n2026-03-10T00:00:00Z,OWL.A,2\n2026-03-11T00:00:00Z,OWL.A,3\n"
    ingest_archives([_archive(tmp_path, body)], dec, tmp_path / "store")
    store = TelemetryStore(tmp_path / "store")
    assert store.spacecraft() == ["SC-B", "SC-C"]
    assert store.days("SC-C") == ["2026-03-10", "2026-03-11"]
    assert store.read_day("SC-B", "2026-03-10")["value"].tolist() == [1.0]
    # Re-ingesting the same archive does not duplicate rows.
    ingest_archives([_archive(tmp_path, body)], dec, tmp_path / "store")
    assert len(store.read_day("SC-C", "2026-03-10")) == 1


def test_wide_gzip_and_parquet_layouts(tmp_path: Path) -> None:
    dec = read_decoder(_decoder(tmp_path))
    wide = "time,BIRD.A,BIRD.B\n2026-03-10T00:00:00Z,1,\n2026-03-10T00:00:01Z,2,20\n"
    gz = tmp_path / "BIRD_wide.csv.gz"
    with gzip.open(gz, "wt") as fh:
        fh.write(wide)
    chunk = read_archive(gz, dec)
    assert sorted(chunk.samples["value"]) == [1.0, 2.0, 20.0]
    assert chunk.per_day[("SC-B", "2026-03-10")].removed["empty values"] == 1
    pq = tmp_path / "BIRD.parquet"
    pd.DataFrame(
        {
            "time": pd.to_datetime(["2026-03-10T00:00:00Z"] * 2, utc=True),
            "mnemonic": ["BIRD.A", "BIRD.B"],
            "value": [1.0, 2.0],
        }
    ).to_parquet(pq)
    assert len(read_archive(pq, dec).samples) == 2


def test_decoder_errors_name_the_line(tmp_path: Path) -> None:
    p = tmp_path / "dec.csv"
    p.write_text("real_name,pseudonym\nBIRD,SC-B\nBIRD.A,SC-Q.ch01\n")
    with pytest.raises(InputError, match=r"dec.csv:3:2: .*spacecraft pseudonym"):
        read_decoder(p)


# ---------------------------------------------------------------- the whole chain on a synthetic archive


@pytest.fixture(scope="module")
def synth(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, object]:
    d = tmp_path_factory.mktemp("flight")
    a = make_archive(
        d, hours=6.0, dump_at_s=9000.0, strikes=[(8640.0, [0.06, -0.05, 0.04]), (14400.0, [-0.01, 0.012, 0.008])]
    )
    ingest_archives([a.archive], a.decoder, d / "store")
    return d, a


def test_synthetic_strikes_found_with_their_size_and_no_false_alarm(synth: tuple[Path, object]) -> None:
    d, a = synth
    sc = load_spacecraft(a.spacecraft)  # type: ignore[attr-defined]
    res = run_flight(d / "store", sc, FAST)
    t_ev = (pd.to_datetime(res.events["time_utc"]).dt.tz_localize(None).to_numpy() - a.start) / np.timedelta64(1, "s")  # type: ignore[attr-defined]
    assert len(res.events) == 2
    for (ts, dh), t, (_, row) in zip(a.strikes, t_ev, res.events.iterrows(), strict=True):  # type: ignore[attr-defined]
        assert abs(t - ts) < 5.0
        est = row[["dH_N_x_Nms", "dH_N_y_Nms", "dH_N_z_Nms"]].to_numpy(float)
        assert np.linalg.norm(est - dh) < 0.1 * np.linalg.norm(dh) + 2e-3
    # The dump is masked by its flag: no event there.
    assert res.daily["event_masked_fraction"].iloc[0] > 0
    # Every event carries the registered detector that found it.
    assert set(res.events["detector"]) == {FlightGlrDetector.name}
    assert FlightGlrDetector.name in detector_names()


def test_flight_detector_on_cleaned_momentum_finds_the_step_with_its_size_and_time() -> None:
    """One 0.05 N·m·s step at 3 h in six hours of white momentum noise (1 Hz) and a gap."""
    rng = np.random.default_rng(2)
    n, k = 6 * 3600, 3 * 3600
    h = 1e-3 * rng.standard_normal((n, 3))
    step = np.array([0.03, -0.03, 0.028])
    h[k:] += step
    ok = np.ones(n, bool)
    ok[8000:9000] = False
    h[~ok] = np.nan
    t0 = int(np.datetime64("2026-05-01T00:00:00", "ns").astype(np.int64))
    series = CleanedMomentum(t0 + np.arange(n, dtype=np.int64) * 1_000_000_000, h, ok, 1.0, name="sat")
    result = FlightGlrDetector().detect(series, FalseAlarmBudget(1.0, "day"))
    ev = result.events
    assert len(ev) == 1 and ev["detector"].iloc[0] == "attitude.flight_glr"
    t_event = pd.Timestamp(str(ev["time_utc"].iloc[0])).tz_localize(None)
    # The step is between samples k-1 and k: the event time is their midpoint.
    assert abs((t_event - pd.Timestamp("2026-05-01T03:00:00")).total_seconds() + 0.5) <= 2.0
    est = ev[["dH_N_x_Nms", "dH_N_y_Nms", "dH_N_z_Nms"]].to_numpy(float)[0]
    assert np.linalg.norm(est - step) < 0.1 * np.linalg.norm(step)
    assert result.diagnostics[0].threshold is not None and ev["statistic"].iloc[0] > ev["threshold"].iloc[0]


def test_orbit_period_estimated_from_the_attitude_when_the_file_has_none(
    synth: tuple[Path, object], tmp_path: Path
) -> None:
    d, a = synth
    text = Path(a.spacecraft).read_text()  # type: ignore[attr-defined]
    no_orbit = tmp_path / "no_orbit.toml"
    no_orbit.write_text(text.replace("[orbit]\nperiod_s = 5400.0\n", ""))
    sc = load_spacecraft(no_orbit)
    assert sc.orbit is None
    res = run_flight(d / "store", sc, FAST)
    note = next(w for w in res.warnings if "orbit period estimated" in w)
    period = float(note.rsplit(":", 1)[1].split()[0])
    assert period == pytest.approx(5400.0, rel=0.01)  # the generator turns the body once per 5400 s
    assert len(res.events) == len(a.strikes)  # type: ignore[attr-defined]


@pytest.mark.slow
def test_chunked_six_hour_chunks_equal_the_whole_run(tmp_path: Path) -> None:
    a = make_archive(
        tmp_path, hours=18.0, period_s=5400.0, strikes=[(20000.0, [0.05, 0.02, -0.03]), (43300.0, [0.0, -0.04, 0.03])]
    )
    ingest_archives([a.archive], a.decoder, tmp_path / "store")
    sc = load_spacecraft(a.spacecraft)
    whole = run_flight(tmp_path / "store", sc, FAST)
    chunked = run_flight(tmp_path / "store", sc, FlightRunConfig(cleaning=CleaningConfig(passes=2), chunk_s=6 * 3600.0))
    t_ev = (pd.to_datetime(whole.events["time_utc"]).dt.tz_localize(None).to_numpy() - a.start) / np.timedelta64(1, "s")
    assert all(np.min(np.abs(t_ev - ts)) < 5.0 for ts, _ in a.strikes)
    # Equal to rounding: sums over a chunk start at another element (SIMD and cumulative-sum order).
    assert chunked.threshold.value == pytest.approx(whole.threshold.value, rel=1e-7)
    assert chunked.events["time_utc"].tolist() == whole.events["time_utc"].tolist()
    np.testing.assert_allclose(chunked.events["statistic"], whole.events["statistic"], rtol=1e-6)
    np.testing.assert_allclose(chunked.events["dH_Nms"], whole.events["dH_Nms"], rtol=1e-6)


def test_kestrel_six_hour_chunks_give_the_events_of_the_whole_run(shared_data: Path, tmp_path: Path) -> None:
    """On the shared flight-like data: 6-hour chunks (each with its margin) against one
    chunk of both days; the events are the same and are the truth's strikes."""

    data = shared_data / "flight-like"
    if not data.is_dir():
        pytest.skip("flight-like data not found")
    ingest_archives(sorted((data / "telemetry").glob("*.csv.gz")), data / "decoder.csv", tmp_path / "store")
    sc = load_spacecraft(Path(__file__).resolve().parent.parent / "examples" / "spacecraft" / "kestrel.toml")
    whole = run_flight(tmp_path / "store", sc, FlightRunConfig(chunk_s=2 * 86_400.0))
    chunked = run_flight(tmp_path / "store", sc, FlightRunConfig(chunk_s=6 * 3600.0))
    # Equal to rounding: sums over a chunk start at another element (SIMD and cumulative-sum order).
    assert chunked.threshold.value == pytest.approx(whole.threshold.value, rel=1e-7)
    assert chunked.events["time_utc"].tolist() == whole.events["time_utc"].tolist()
    np.testing.assert_allclose(chunked.events["statistic"], whole.events["statistic"], rtol=1e-6)
    np.testing.assert_allclose(chunked.events["dH_Nms"], whole.events["dH_Nms"], rtol=1e-6, atol=1e-9)
    # Every peak, not only those above the threshold (what the calibration and reports see).
    assert sorted(round(p.time_ns / 1e9, 3) for p in chunked.peaks) == sorted(
        round(p.time_ns / 1e9, 3) for p in whole.peaks
    )
    # And they are the strikes: all of >= 0.1 N m s within 10 s (the truth, not the pipeline, decides).
    t0 = np.datetime64("2026-03-10T00:00:00", "ns")
    t_ev = (pd.to_datetime(whole.events["time_utc"]).dt.tz_localize(None).to_numpy() - t0) / np.timedelta64(1, "s")
    strikes = json.loads((data / "truth_strikes.json").read_text())["strikes"]
    big = [s["time_s"] for s in strikes if s["H_mag_Nms"] >= 0.1]
    assert len(big) >= 5
    assert all(np.min(np.abs(t_ev - ts)) <= 10.0 for ts in big)


def test_leak_scan_of_every_output_of_the_chain(
    synth: tuple[Path, object], tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:

    _, a = synth
    out = tmp_path / "out"
    out.mkdir()
    store = out / "store"
    main(["-v", "ingest", str(a.archive), "--decoder", str(a.decoder), "--store", str(store)])  # type: ignore[attr-defined]
    main(
        [
            "detect",
            "attitude",
            "--store",
            str(store),
            "--spacecraft",
            str(a.spacecraft),  # type: ignore[attr-defined]
            "--out",
            str(out / "events.csv"),
            "--catalog",
            str(out / "catalog.sqlite"),
            "--report",
            str(out / "report.html"),
        ]
    )
    logs = capfd.readouterr()
    (out / "logs.txt").write_text(logs.out + logs.err)
    real_names = read_decoder(a.decoder).real_names  # type: ignore[attr-defined]
    assert REAL in real_names
    files = [p for p in out.rglob("*") if p.is_file()]
    assert len(files) >= 6
    hits = [(p.name, n) for p in files for n in real_names if n.encode() in p.read_bytes()]
    assert hits == []
    assert pd.read_csv(out / "events.csv")["spacecraft"].unique().tolist() == ["SC-Z"]


def test_channel_that_stops_for_a_day_and_unknown_mnemonic(tmp_path: Path) -> None:
    a = make_archive(tmp_path, hours=5.0, start="2026-01-05T21:00:00", strikes=[(3600.0, [0.05, 0.05, 0.0])])
    frame = pd.read_csv(a.archive)
    stop = (frame["mnemonic"] == f"{REAL}.ACS.RW3_SPD") & (frame["time"] >= "2026-01-06")
    frame.loc[~stop].to_csv(a.archive, index=False)
    ingest_archives([a.archive], a.decoder, tmp_path / "store")
    sc = load_spacecraft(a.spacecraft)
    res = run_flight(tmp_path / "store", sc, FAST)
    day1, day2 = res.daily.iloc[0], res.daily.iloc[1]
    assert day1["analysed_fraction"] > 0.1 and day1["events"] >= 1
    assert day2["analysed_fraction"] == 0.0  # the stopped wheel leaves the whole day unanalysed, no crash
    # A spacecraft file naming a mnemonic that the store does not hold: reported missing, not a crash.
    text = a.spacecraft.read_text().replace('"SC-Z.ch09"', '"SC-Z.ch99"')
    bad = tmp_path / "unknown.toml"
    bad.write_text(text)
    with pytest.raises(InputError, match="too little analysable telemetry"):
        run_flight(tmp_path / "store", load_spacecraft(bad), FAST, days=["2026-01-05"])
    res2 = run_flight(tmp_path / "store", load_spacecraft(bad), FAST, days=["2026-01-05"], threshold=res.threshold)
    assert "SC-Z.ch99" in res2.daily["missing_channels"].iloc[0] and res2.daily["analysed_fraction"].iloc[0] == 0.0


def test_rpm_declared_as_rad_s_is_caught_by_the_tachometer_quantum(synth: tuple[Path, object], tmp_path: Path) -> None:
    d, a = synth
    bad = tmp_path / "radps.toml"
    bad.write_text(a.spacecraft.read_text().replace('unit = "rpm"', 'unit = "rad/s"'))  # type: ignore[attr-defined]
    sc = load_spacecraft(bad)
    t0 = int(a.start.astype(np.int64))  # type: ignore[attr-defined]
    with pytest.raises(ConfigError, match=r"flight\.channels\[7\]\.unit.*tachometer quantum in .rpm"):
        process_chunk(TelemetryStore(d / "store"), sc, t0, t0 + 3 * 3600 * NS, FAST)


def test_injected_strike_changes_momentum_by_its_size_in_native_units(synth: tuple[Path, object]) -> None:

    d, a = synth
    sc = load_spacecraft(a.spacecraft)  # type: ignore[attr-defined]
    store = TelemetryStore(d / "store")
    t0 = int(a.start.astype(np.int64))  # type: ignore[attr-defined]
    t_inj = t0 + 4000 * NS + NS // 3
    dh = np.array([0.03, -0.02, 0.025])
    base = process_chunk(store, sc, t0 + 3000 * NS, t0 + 5000 * NS, FAST, keep_series=True)
    hooked = process_chunk(
        store,
        sc,
        t0 + 3000 * NS,
        t0 + 5000 * NS,
        FAST,
        keep_series=True,
        samples_hook=lambda s: inject_strikes(s, sc, [InjectedStrike(t_inj, dh)]),
    )
    assert base.series is not None and hooked.series is not None
    diff = hooked.series["H_N_raw"] - base.series["H_N_raw"]
    t = (base.series["time_ns"] - t_inj) / NS
    # ᴺH conserved through the simulated control transient and after it (wheels hold [BN(t)]ΔH_N).
    for window in ((t > 15) & (t < 300), (t > 300) & (t < 900)):
        np.testing.assert_allclose(np.nanmean(diff[window], axis=0), dh, atol=2e-3)
    np.testing.assert_allclose(
        diff[(t > 15) & (t < 900)], np.broadcast_to(dh, diff[(t > 15) & (t < 900)].shape), atol=5e-3
    )
    assert np.nanmax(np.abs(diff[t < -15])) < 1e-9  # Savitzky-Golay (11 s) spreads the wheel step back
    ev = [p for p in hooked.peaks if abs(p.time_ns - t_inj) < 5 * NS and p.value > 10]
    assert ev and np.linalg.norm(ev[0].dH_N_Nms - dh) < 3e-3
    # Wheel speeds stay on the tachometer grid (0.9375 rpm).
    samples = store.read_day(sc.name, "2026-01-05")
    injected = inject_strikes(samples, sc, [InjectedStrike(t_inj, dh)])
    wheel = (samples["mnemonic"] == "SC-Z.ch08").to_numpy()
    q = injected["value"].to_numpy()[wheel] / (60.0 / 64.0)
    np.testing.assert_allclose(q, np.round(q), atol=1e-9)
    assert not np.array_equal(injected["value"].to_numpy()[wheel], samples["value"].to_numpy()[wheel])


# ---------------------------------------------------------------- timetable, comb, thresholds, schema


def test_timetable_methods() -> None:
    q = np.array([[0.1, 0.7, 0.7, 0.1], [-0.09, -0.7, -0.7, -0.12], [0.08, 0.7, 0.7, 0.13]])
    c = continuous_quaternion(q)
    assert np.all(np.einsum("ij,ij->i", c[1:], c[:-1]) > 0)
    g = grid(0, 100 * NS, 1.0)
    t = np.arange(0, 100, 5, dtype=np.int64) * NS
    ang = np.degrees(0.01 * t / NS) % 360.0 + 355.0 * (t == t)  # wraps
    ang = ang % 360.0
    ch = FlightChannel("x", "appendage_angle", unit="deg", method="unwrap_rate", rate_hz=0.2, appendage="a")
    v, ok = channel_on_grid(ch, t, ang, g, NS, 2.5)
    np.testing.assert_allclose(v[ok], 0.01, rtol=1e-9)
    # Gaps stay gaps: remove 30 s of samples.
    keep = (t < 40 * NS) | (t > 70 * NS)
    lin = FlightChannel("y", "body_rate", unit="rad/s", method="linear", rate_hz=0.2)
    v, ok = channel_on_grid(lin, t[keep], np.ones(keep.sum()), g, NS, 2.5)
    assert not ok[(g > 41 * NS) & (g < 74 * NS)].any() and ok[(g > 5 * NS) & (g < 35 * NS)].all()
    hold = FlightChannel("f", "event_flag", unit="flag", method="hold")
    v, _ = channel_on_grid(hold, np.array([10, 20]) * NS, np.array([1.0, 0.0]), g, NS, 2.5)
    assert v[5] == 0 and v[15] == 1 and v[25] == 0


def test_comb_removes_orbit_harmonics_and_keeps_a_candidate_step() -> None:
    t = np.arange(0.0, 30000.0, 2.0)
    p = 5000.0
    x = 0.05 * np.sin(2 * np.pi * t / p) + 0.02 * np.cos(4 * np.pi * t / p + 0.3)
    np.testing.assert_allclose(comb_subtract(x, t, p, 4), 0.0, atol=1e-12)  # Harris Eqs. 1-2
    rng = np.random.default_rng(0)
    h = np.column_stack([x, -x, 1e-5 * t]) + 1e-3 * rng.normal(size=(t.size, 3))
    step = np.array([0.03, -0.02, 0.01])
    h += np.outer(t >= 15001.0, step)
    ok = np.ones(t.size, bool)
    model, info = smooth_model(h, t, ok, p, CombConfig(), np.array([15000.5]))
    r = h - model
    after = r[(t > 15100) & (t < 16000)].mean(axis=0) - r[(t > 14000) & (t < 14900)].mean(axis=0)
    np.testing.assert_allclose(after, step, atol=1e-3)
    assert np.std(r[t < 14000] - r[t < 14000].mean(axis=0), axis=0).max() < 1.5e-3
    assert info["harmonics_mean"] >= 2


def test_binned_comb_fit_equals_the_per_sample_fit_to_a_small_fraction_of_the_noise() -> None:
    """10-s bin means (weighted) against every sample: the reference is the per-sample least squares."""
    t = 1.7e9 + np.arange(0.0, 40000.0, 1.0)
    p = 5926.4
    rng = np.random.default_rng(3)
    sig = 4e-3
    x = 0.05 * np.sin(2 * np.pi * t / p) + 0.02 * np.cos(6 * np.pi * t / p + 0.3)
    h = np.column_stack([x, -x, 1e-5 * (t - t[0])]) + sig * rng.normal(size=(t.size, 3))
    h += np.outer(t >= t[0] + 20000.3, [0.03, -0.02, 0.01])
    ok = np.ones(t.size, bool)
    ok[5000:5400] = False  # a masked interval (free step) inside a bin boundary
    ok[12345:12352] = False
    steps = np.array([t[0] + 20000.3])
    cached: dict[tuple[float, ...], Any] = {}
    m_bins, _ = smooth_model(h, t, ok, p, CombConfig(bin_s=10.0), steps, cache=cached)
    m_all, _ = smooth_model(h, t, ok, p, CombConfig(bin_s=0.0), steps)
    both = np.isfinite(m_bins).all(axis=1) & np.isfinite(m_all).all(axis=1)
    assert both.mean() > 0.9
    assert np.max(np.abs(m_bins[both] - m_all[both])) < 0.1 * sig
    # A second pass from the cache gives the same model.
    m_again, _ = smooth_model(h, t, ok, p, CombConfig(bin_s=10.0), steps, cache=cached)
    np.testing.assert_array_equal(m_again, m_bins)


def test_chunk_spans_cover_the_days_once() -> None:

    days = ["2026-03-10", "2026-03-11", "2026-03-12", "2026-03-13", "2026-03-20"]
    d0 = int(np.datetime64("2026-03-10", "D").astype("datetime64[ns]").astype(np.int64))
    spans = chunk_spans(days, 3 * 86_400.0)
    assert spans == [(d0, d0 + 3 * DAY_NS), (d0 + 3 * DAY_NS, d0 + 4 * DAY_NS), (d0 + 10 * DAY_NS, d0 + 11 * DAY_NS)]
    six = chunk_spans(days[:1], 6 * 3600.0)
    assert six == [(d0 + k * DAY_NS // 4, d0 + (k + 1) * DAY_NS // 4) for k in range(4)]


def test_robust_gumbel_threshold_against_scipy() -> None:
    mu, beta = 5.0, 0.7
    x = stats.gumbel_r.rvs(loc=mu, scale=beta, size=4000, random_state=1)
    m, b = gumbel_quantile_fit(x)
    assert m == pytest.approx(mu, abs=0.05) and b == pytest.approx(beta, rel=0.08)
    contaminated = np.concatenate([x, np.full(40, 500.0)])  # 1% of blocks with strikes
    thr = robust_block_maxima_threshold(contaminated, block_s=600.0, budget=FalseAlarmBudget(1.0, "day"))
    expected = stats.gumbel_r.isf(600.0 / 86400.0, loc=mu, scale=beta)
    assert thr.value == pytest.approx(expected, rel=0.03)


def test_spacecraft_flight_schema_errors_name_the_key(tmp_path: Path) -> None:
    sc = load_spacecraft(Path(__file__).resolve().parent.parent / "examples" / "spacecraft" / "kestrel.toml")
    assert sc.flight is not None and len(sc.flight.of("wheel_speed")) == 4
    assert sc.appendages[0].drive_inertia_kgm2 == 18.0 and sc.orbit is not None
    base = {
        "name": "X",
        "inertia_kgm2": [1.0, 1.0, 1.0],
        "wheels": [
            {"axis": ax, "spin_inertia_kgm2": 0.1, "max_torque_Nm": 0.1} for ax in ([1, 0, 0], [0, 1, 0], [0, 0, 1])
        ],
        "orbit": {"altitude_km": 700.0},
        "flight": {
            "channels": [{"mnemonic": f"X.q{k}", "quantity": "quaternion", "component": k} for k in range(4)]
            + [{"mnemonic": f"X.w{k}", "quantity": "body_rate", "component": k, "unit": "deg/s"} for k in range(3)]
            + [{"mnemonic": f"X.r{k}", "quantity": "wheel_speed", "component": k, "unit": "rpm"} for k in range(3)]
        },
    }
    ok = spacecraft_from_dict(base)
    assert ok.orbit is not None and ok.orbit.period_s == pytest.approx(5926.0, abs=5.0)  # Kepler at 700 km
    bad = {
        **base,
        "flight": {
            "channels": [
                *base["flight"]["channels"][:-1],
                {"mnemonic": "X.r2", "quantity": "wheel_speed", "component": 2, "unit": "furlongs"},
            ]
        },
    }
    with pytest.raises(ConfigError, match=r"flight\.channels\[9\]\.unit"):
        spacecraft_from_dict(bad)
    bad2 = {**base, "flight": {"channels": base["flight"]["channels"][:-1]}}
    with pytest.raises(ConfigError, match=r"wheel_speed needs exactly one channel per component"):
        spacecraft_from_dict(bad2)
    assert math.isfinite(ok.orbit.period_s)


def test_injection_recovery_reports_its_detection_passes_with_their_total(
    synth: tuple[Path, object], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The recovery is minutes of work on real days: it shows a task whose total is the number of
    detection passes it then runs (counted here at the detector's door)."""
    from abrupt import progress
    from abrupt.pipelines import flight_injection

    d, a = synth
    sc = load_spacecraft(a.spacecraft)  # type: ignore[attr-defined]
    threshold = run_flight(d / "store", sc, FAST).threshold
    calls: list[int] = []
    real_chunk = flight_injection.process_chunk

    def counted(*args: object, **kwargs: object) -> object:
        calls.append(1)
        return real_chunk(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(flight_injection, "process_chunk", counted)
    seen: list[tuple[str, int | None]] = []
    finished: list[int] = []

    class Recorder(progress.Reporter):
        def opened(self, task: progress.Task, bar: bool) -> None:
            seen.append((task.desc, task.total))
            super().opened(task, bar)

        def closed(self, task: progress.Task) -> None:
            finished.append(task.done)
            super().closed(task)

    previous = progress.install(Recorder("abrupt inject attitude", "log", stream=io.StringIO()))
    try:
        flight_injection.injection_recovery(d / "store", sc, FAST, threshold, per_run=3, runs_per_day=1)
    finally:
        progress.install(previous)
    totals = [total for desc, total in seen if desc == "injection recovery"]
    assert totals == [len(calls)] and len(calls) >= 2
    assert finished[-1] == len(calls)
