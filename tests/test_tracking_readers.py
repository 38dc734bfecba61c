"""Readers of tracking data: Orekit .aer text, Orekit OD input (stations, a-priori orbit), CCSDS TDM."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from abrupt.errors import InputError, RepairLog
from abrupt.model.tracking_measurements import TrackingArrays
from abrupt.readers.aer import read_aer
from abrupt.readers.orekit_od_input import read_od_input, write_od_input
from abrupt.readers.tdm import read_tdm, write_tdm
from abrupt.simulate.tracking import TrackingScenario, simulate_tracking

GOOD_AER = """# comment
2010-11-02T03:00:13.3851   RANGE       Uralla         38014.9488
2010-11-02T03:00:50.5716   AZ_EL       Kumsan           211.1446   43.4099
"""


def _write(tmp_path: Path, name: str, text: str) -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


def test_aer_reader_converts_units_to_si(tmp_path: Path) -> None:
    m = read_aer(_write(tmp_path, "a.aer", GOOD_AER))
    assert len(m) == 2
    assert m["range_m"].iloc[0] == pytest.approx(38014948.8)
    assert m["azimuth_rad"].iloc[1] == pytest.approx(math.radians(211.1446))
    assert m["elevation_rad"].iloc[1] == pytest.approx(math.radians(43.4099))
    assert np.isnan(m["range_m"].iloc[1])


@pytest.mark.parametrize(
    ("line", "reason", "column"),
    [
        ("2010-11-02T03:00:13   RANGE   Uralla", "expected 'DATE TYPE STATION VALUE", None),
        ("2010-11-02T03:00:13   RANGE   Uralla   abc", "not a number", 4),
        ("2010-11-02T03:00:13   AZ_EL   Uralla   10.0", "needs 2 value", 4),
        ("2010-13-45T03:00:13   RANGE   Uralla   3800.0", "cannot parse date", 1),
        ("2010-11-02T03:00:13   PV      Uralla   1 2 3 4 5 6", "unsupported measurement type", 2),
        ("2010-11-02T03:00:13   AZ_EL   Uralla   10.0   95.0", "outside the plausible range", 5),
        ("2010-11-02T03:00:13   RANGE   Uralla   -5.0", "outside the plausible range", 4),
    ],
)
def test_aer_reader_rejects_malformed_lines_naming_line_and_column(
    tmp_path: Path, line: str, reason: str, column: int | None
) -> None:
    p = _write(tmp_path, "bad.aer", GOOD_AER + line + "\n")
    with pytest.raises(InputError) as err:
        read_aer(p)
    assert reason in str(err.value)
    assert err.value.line == 4
    assert err.value.column == column
    assert "bad.aer:4" in str(err.value)


def test_aer_reader_rejects_unknown_station(tmp_path: Path) -> None:
    p = _write(tmp_path, "a.aer", GOOD_AER + "2010-11-02T04:00:00   RANGE   Nowhere   38000.0\n")
    with pytest.raises(InputError, match="unknown station 'Nowhere'") as err:
        read_aer(p, known_stations=["Uralla", "Kumsan"])
    assert err.value.line == 4 and err.value.column == 3


def test_aer_reader_sorts_out_of_order_lines_and_counts_the_repair(tmp_path: Path) -> None:
    text = GOOD_AER + "2010-11-02T02:00:00.0   RANGE   Uralla   38100.0\n"
    log = RepairLog("a.aer")
    m = read_aer(_write(tmp_path, "a.aer", text), repairs=log)
    assert m["time_utc"].is_monotonic_increasing
    assert m["range_m"].iloc[0] == pytest.approx(38100e3)
    assert log.counts["out-of-order lines sorted by time"] == 1


def test_aer_reader_drops_identical_duplicates_and_rejects_conflicting_ones(tmp_path: Path) -> None:
    dup = GOOD_AER + "2010-11-02T03:00:13.3851   RANGE       Uralla         38014.9488\n"
    log = RepairLog("d.aer")
    m = read_aer(_write(tmp_path, "d.aer", dup), repairs=log)
    assert len(m) == 2 and log.counts["identical duplicated measurements dropped"] == 1
    conflict = GOOD_AER + "2010-11-02T03:00:13.3851   RANGE       Uralla         38015.0000\n"
    with pytest.raises(InputError, match="different value"):
        read_aer(_write(tmp_path, "c.aer", conflict))


def test_unknown_station_in_measurements_is_an_error_when_building_arrays() -> None:
    frame = pd.DataFrame(
        {
            "time_utc": [np.datetime64("2024-01-01T00:00")],
            "station": ["MARS"],
            "range_m": [1e6],
            "azimuth_rad": [np.nan],
            "elevation_rad": [np.nan],
            "range_rate_mps": [np.nan],
        }
    )
    with pytest.raises(InputError, match="unknown station 'MARS'"):
        TrackingArrays(frame, {}, source="x.tdm")


def test_od_input_reads_w3b_stations_and_apriori_orbit(shared_data: Path) -> None:
    setup = read_od_input(shared_data / "tracking" / "od_test_W3.in")
    assert sorted(setup.stations) == ["CastleRock", "Fucino", "Kumsan", "Pretoria", "Uralla"]
    fucino = setup.stations["Fucino"]
    assert fucino.latitude_deg == pytest.approx(41.9774962512)
    assert fucino.range_bias_m == pytest.approx(13468.956)
    assert fucino.sigma_azimuth_rad == pytest.approx(math.radians(0.02))
    assert setup.initial_state[0] == pytest.approx(-40517522.9)
    assert setup.refraction_correction
    assert all(setup.range_bias_estimated.values())
    m = read_aer(shared_data / "tracking" / "W3B.aer", known_stations=setup.stations)
    assert len(m) == 521 and m["time_utc"].is_monotonic_increasing
    assert m["range_m"].notna().sum() == 182


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        ("orbit.date = 2010-11-02T02:56:15\n", "no orbit"),
        ("orbit.date = 2010-11-02T02:56:15\norbit.cartesian.px = abc\n", "not a number"),
        ("orbit.date = 2010-11-02T02:56:15\nthis line has no equals\n", "expected 'key = value'"),
        ("orbit.cartesian.px = 1\n", "missing key orbit.date"),
    ],
)
def test_od_input_rejects_malformed_files(tmp_path: Path, text: str, reason: str) -> None:
    with pytest.raises(InputError, match=reason):
        read_od_input(_write(tmp_path, "bad.in", text))


def test_od_input_rejects_position_given_in_km(tmp_path: Path) -> None:
    text = "orbit.date = 2010-11-02T02:56:15\n" + "".join(
        f"orbit.cartesian.{k} = {v}\n"
        for k, v in zip(
            ("px", "py", "pz", "vx", "vy", "vz"), (-40517.5, -10003.1, 166.8, 0.76, -1.47, 0.05), strict=True
        )
    )
    with pytest.raises(InputError, match="inside the Earth"):
        read_od_input(_write(tmp_path, "km.in", text))


def test_tdm_round_trip_preserves_simulated_measurements(tmp_path: Path) -> None:
    sim = simulate_tracking(TrackingScenario(duration_s=900.0), seed=1)
    write_tdm(sim.measurements, tmp_path / "s.tdm")
    m = read_tdm(tmp_path / "s.tdm")
    cols = ["range_m", "azimuth_rad", "elevation_rad", "range_rate_mps"]
    assert (m["time_utc"].to_numpy() == sim.measurements["time_utc"].to_numpy()).all()
    np.testing.assert_allclose(m[cols].to_numpy(), sim.measurements[cols].to_numpy(), atol=1e-6)
    write_od_input(
        tmp_path / "s.in",
        epoch_utc=sim.epoch_utc,
        state=sim.initial_state,
        stations=list(sim.scenario.stations),
    )
    setup = read_od_input(tmp_path / "s.in")
    np.testing.assert_allclose(setup.initial_state, sim.initial_state, atol=1e-5)
    assert setup.stations["ASCENSION"].position_ecef_m == pytest.approx(
        sim.scenario.stations[0].position_ecef_m, abs=1e-3
    )


TDM_HEAD = """CCSDS_TDM_VERS = 2.0
META_START
TIME_SYSTEM = TAI
PARTICIPANT_1 = DSS-25
PARTICIPANT_2 = SAT
PATH = 1,2,1
RANGE_UNITS = km
ANGLE_TYPE = AZEL
META_STOP
DATA_START
RANGE = 2005-159T17:41:00 8000.0
ANGLE_1 = 2005-159T17:41:00 123.5
ANGLE_2 = 2005-159T17:41:00 45.0
RECEIVE_FREQ = 2005-159T17:41:00 8.4e9
"""


def test_tdm_reader_handles_doy_epochs_tai_two_way_range_and_skipped_keywords(tmp_path: Path) -> None:
    log = RepairLog("t.tdm")
    m = read_tdm(_write(tmp_path, "t.tdm", TDM_HEAD + "DATA_STOP\n"), repairs=log)
    assert len(m) == 1
    assert m["station"].iloc[0] == "DSS-25"
    assert m["time_utc"].iloc[0] == pd.Timestamp("2005-06-08T17:40:28")  # TAI − 32 s in 2005
    assert m["range_m"].iloc[0] == pytest.approx(4000e3)  # round trip halved
    assert m["azimuth_rad"].iloc[0] == pytest.approx(math.radians(123.5))
    assert log.counts["TDM data keyword RECEIVE_FREQ not used (skipped)"] == 1


@pytest.mark.parametrize(
    ("tail", "reason"),
    [
        ("", "missing DATA_STOP"),
        ("RANGE = 2005-159T17:42:00\nDATA_STOP\n", "needs 'EPOCH VALUE'"),
        ("RANGE = 2005-159T17:42:00 abc\nDATA_STOP\n", "not a number"),
        ("RANGE = 2005-400T17:42:00 8000\nDATA_STOP\n", "cannot parse epoch"),
        ("FOO = 2005-159T17:42:00 1\nDATA_STOP\n", "unknown TDM data keyword"),
        ("ANGLE_2 = 2005-159T17:42:00 120\nDATA_STOP\n", "outside"),
        ("RANGE = 2005-159T17:41:00 8000.5\nDATA_STOP\n", "different value"),
        ("no equals sign here\nDATA_STOP\n", "expected 'KEYWORD = value'"),
    ],
)
def test_tdm_reader_rejects_malformed_or_truncated_files(tmp_path: Path, tail: str, reason: str) -> None:
    with pytest.raises(InputError, match=reason) as err:
        read_tdm(_write(tmp_path, "bad.tdm", TDM_HEAD + tail))
    assert err.value.line is not None


def test_tdm_reader_rejects_unsupported_units_and_missing_header(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="RANGE_UNITS"):
        read_tdm(_write(tmp_path, "u.tdm", TDM_HEAD.replace("RANGE_UNITS = km", "RANGE_UNITS = RU") + "DATA_STOP\n"))
    with pytest.raises(InputError, match="CCSDS_TDM_VERS"):
        read_tdm(_write(tmp_path, "h.tdm", TDM_HEAD.replace("CCSDS_TDM_VERS = 2.0\n", "") + "DATA_STOP\n"))
