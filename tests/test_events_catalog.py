"""Event schema and catalog: frozen columns, empty frames, no duplicates on re-run, exports."""

from __future__ import annotations

import math

import pandas as pd
import pytest

from abrupt.catalog import Catalog
from abrupt.events import EVENT_COLUMNS, Event, empty_frame, events_frame, read_events, write_events


def _event(t: str = "2026-01-01T00:10:00", detector: str = "attitude.glr") -> Event:
    return Event(
        spacecraft="sat-a",
        kind="strike",
        detector=detector,
        time_utc=t,
        statistic=7.0,
        threshold=5.0,
        false_alarms_per_day=1.0,
        run_id="r1",
        config_hash="c1",
        dH_N_x_Nms=0.03,
        dH_N_y_Nms=0.04,
        dH_N_z_Nms=0.0,
    )


def test_event_frame_has_the_design_columns_first_and_in_order() -> None:
    frame = events_frame([_event()], extra_columns=["note"])
    assert tuple(frame.columns[: len(EVENT_COLUMNS)]) == EVENT_COLUMNS
    assert frame.columns[-1] == "note"


def test_empty_frame_has_the_same_columns_as_a_full_one() -> None:
    assert list(empty_frame().columns) == list(events_frame([_event()]).columns)
    assert len(empty_frame()) == 0


def test_magnitude_is_filled_from_components_and_missing_values_are_empty() -> None:
    e = _event()
    assert e.dH_Nms == pytest.approx(0.05)
    assert math.isnan(e.dv_mps)


def test_event_ids_are_deterministic_and_distinguish_detectors() -> None:
    assert _event().event_id == _event().event_id
    assert _event().event_id != _event(detector="attitude.cusum").event_id


@pytest.mark.parametrize("bad", [{"kind": "meteor"}, {"spacecraft": ""}, {"time_sigma_s": -1.0}])
def test_invalid_events_are_rejected(bad: dict[str, object]) -> None:
    fields = {
        "spacecraft": "s",
        "kind": "strike",
        "detector": "d",
        "time_utc": "2026-01-01",
        "statistic": 1.0,
        "threshold": 1.0,
        "false_alarms_per_day": 1.0,
        "run_id": "r",
        "config_hash": "c",
    }
    fields.update(bad)
    with pytest.raises(ValueError):
        Event(**fields)  # type: ignore[arg-type]


def test_rerunning_the_same_events_adds_no_duplicates(tmp_path) -> None:  # type: ignore[no-untyped-def]
    cat = Catalog(tmp_path / "c.sqlite")
    frame = events_frame([_event(), _event("2026-01-01T01:00:00")])
    assert cat.add_events(frame) == 2
    assert cat.add_events(frame) == 0
    assert len(cat.events()) == 2


def test_catalog_accepts_sqlalchemy_urls_and_keeps_extra_columns(tmp_path) -> None:  # type: ignore[no-untyped-def]
    cat = Catalog(f"sqlite:///{tmp_path / 'u.sqlite'}")
    cat.add_events(events_frame([Event(**{**_event().__dict__, "extra": {"note": "x"}, "event_id": ""})]))
    out = cat.events()
    assert out.loc[0, "note"] == "x"


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_export_round_trips(tmp_path, suffix: str) -> None:  # type: ignore[no-untyped-def]
    cat = Catalog(tmp_path / "c.sqlite")
    cat.add_events(events_frame([_event()]))
    path = tmp_path / f"events{suffix}"
    assert cat.export(path) == 1
    back = read_events(str(path))
    pd.testing.assert_series_equal(back["dH_Nms"], cat.events()["dH_Nms"], check_names=False)


def test_write_events_rejects_unknown_suffix(tmp_path) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(ValueError, match=r"csv or \.parquet"):
        write_events(empty_frame(), str(tmp_path / "e.txt"))


def test_csv_round_trip_keeps_identifiers_as_text(tmp_path) -> None:  # type: ignore[no-untyped-def]
    e = Event(**{**_event().__dict__, "spacecraft": "007", "event_id": "12345e67", "extra": {}})
    path = tmp_path / "e.csv"
    write_events(events_frame([e]), str(path))
    back = read_events(str(path))
    assert back.loc[0, "event_id"] == "12345e67"
    assert back.loc[0, "spacecraft"] == "007"
    assert math.isnan(back.loc[0, "dv_mps"])
